#include "MonotoneSibsonPatch.h"

namespace topospline
{
namespace
{
// Corners V00, V10, V11, V01 and the centre, in local coordinates.
constexpr double CornerPositions[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
constexpr double Centre[2] = { 0.5, 0.5 };

// Sub-triangle t is (V_t, V_{t+1}, C): South, East, North, West in this order, all
// counterclockwise. Its edge A-C is shared with triangle t-1, its edge B-C with t+1.
void TriangleVertices(int t, double vertices[3][2])
{
  const int a = t;
  const int b = (t + 1) % 4;
  vertices[0][0] = CornerPositions[a][0];
  vertices[0][1] = CornerPositions[a][1];
  vertices[1][0] = CornerPositions[b][0];
  vertices[1][1] = CornerPositions[b][1];
  vertices[2][0] = Centre[0];
  vertices[2][1] = Centre[1];
}

// Barycentric coordinates of a point, and of a direction (they sum to 0).
void Barycentric(const double v[3][2], double x, double y, double lambda[3])
{
  const double e1x = v[1][0] - v[0][0], e1y = v[1][1] - v[0][1];
  const double e2x = v[2][0] - v[0][0], e2y = v[2][1] - v[0][1];
  const double det = e1x * e2y - e1y * e2x;
  const double dx = x - v[0][0], dy = y - v[0][1];
  lambda[1] = (dx * e2y - dy * e2x) / det;
  lambda[2] = (e1x * dy - e1y * dx) / det;
  lambda[0] = 1.0 - lambda[1] - lambda[2];
}

void BarycentricDirection(const double v[3][2], double dx, double dy, double a[3])
{
  const double e1x = v[1][0] - v[0][0], e1y = v[1][1] - v[0][1];
  const double e2x = v[2][0] - v[0][0], e2y = v[2][1] - v[0][1];
  const double det = e1x * e2y - e1y * e2x;
  a[1] = (dx * e2y - dy * e2x) / det;
  a[2] = (e1x * dy - e1y * dx) / det;
  a[0] = -a[1] - a[2];
}

// Index of b_ijk (k = degree - i - j) in a degree-`degree` array ordered like
// BezierOrdinateIndex.
inline int OrdinateIndex(int degree, int i, int j)
{
  return (degree - i) * (degree - i + 1) / 2 + (degree - i - j);
}

// Two de Casteljau steps: the three degree-1 points, from which the value (sum lambda_m c_m)
// and every directional derivative (3 sum a_m c_m) follow.
void ReduceToLinear(const CubicTriangleOrdinates& b, const double lambda[3], double linear[3])
{
  double quadratic[6];
  for (int i = 0; i <= 2; ++i)
  {
    for (int j = 0; j <= 2 - i; ++j)
    {
      quadratic[OrdinateIndex(2, i, j)] = lambda[0] * b[OrdinateIndex(3, i + 1, j)] +
        lambda[1] * b[OrdinateIndex(3, i, j + 1)] + lambda[2] * b[OrdinateIndex(3, i, j)];
    }
  }
  linear[0] = lambda[0] * quadratic[OrdinateIndex(2, 2, 0)] + lambda[1] * quadratic[OrdinateIndex(2, 1, 1)] +
    lambda[2] * quadratic[OrdinateIndex(2, 1, 0)];
  linear[1] = lambda[0] * quadratic[OrdinateIndex(2, 1, 1)] + lambda[1] * quadratic[OrdinateIndex(2, 0, 2)] +
    lambda[2] * quadratic[OrdinateIndex(2, 0, 1)];
  linear[2] = lambda[0] * quadratic[OrdinateIndex(2, 1, 0)] + lambda[1] * quadratic[OrdinateIndex(2, 0, 1)] +
    lambda[2] * quadratic[OrdinateIndex(2, 0, 0)];
}
} // namespace

const char* MonotonicityConditionName(MonotonicityCondition condition)
{
  switch (condition)
  {
    case MonotonicityCondition::Satisfied:
      return "satisfied";
    case MonotonicityCondition::C0:
      return "C0";
    case MonotonicityCondition::C1:
      return "C1";
    case MonotonicityCondition::C2:
      return "C2";
    case MonotonicityCondition::C3:
      return "C3";
    case MonotonicityCondition::CentreNotPositive:
      return "centre";
  }
  return "unknown";
}

double ConditionC2LeftSide(const SibsonCellData& c)
{
  return (5 * c.P[0] + c.Q[0]) / 4 + (c.P[1] + c.Q[1]) / 2 + (c.P[2] + 5 * c.Q[2]) / 4;
}

double ConditionC3LeftSide(const SibsonCellData& c)
{
  return (c.P[0] + 5 * c.Q[0]) / 4 + (c.P[3] + c.Q[3]) / 2 + (5 * c.P[2] + c.Q[2]) / 4;
}

MonotonicityCondition CheckMonotonicityConditions(const SibsonCellData& cell, double tolerance)
{
  const double rise = cell.Z[2] - cell.Z[0];
  if (!(rise > -tolerance))
  {
    return MonotonicityCondition::C0;
  }
  for (int v = 0; v < 4; ++v)
  {
    if (!(cell.P[v] + cell.Q[v] >= -tolerance))
    {
      return MonotonicityCondition::C1;
    }
  }
  const double bound = 3 * rise;
  const double left2 = ConditionC2LeftSide(cell);
  const double left3 = ConditionC3LeftSide(cell);
  if (!(left2 <= bound + tolerance))
  {
    return MonotonicityCondition::C2;
  }
  if (!(left3 <= bound + tolerance))
  {
    return MonotonicityCondition::C3;
  }
  // The centre coefficient of h D_(1,1)F is 3 rise - (left2 + left3) / 2.
  if (!(bound - 0.5 * (left2 + left3) > -tolerance))
  {
    return MonotonicityCondition::CentreNotPositive;
  }
  return MonotonicityCondition::Satisfied;
}

//------------------------------------------------------------------------------------------
void MonotoneSibsonPatch::SetData(const SibsonCellData& cell)
{
  this->Data = cell;
  const auto& z = cell.Z;
  const auto& p = cell.P;
  const auto& q = cell.Q;
  double s[4];
  for (int v = 0; v < 4; ++v)
  {
    s[v] = p[v] + q[v];
  }

  // The one free ordinate per outer edge: b111 is chosen so that the Bernstein coefficients of
  // h D_(1,1)F along the edge (s_A, 6 (b111 - b210) or its mirror, s_B) are linear, i.e. the
  // middle one is (s_A + s_B) / 2. Then the cross-boundary derivative depends only on the
  // edge's end data, which is what makes neighbouring cells C1.
  double middle[4];
  middle[0] = z[0] + p[0] / 3 + (s[0] + s[1]) / 12; // South, on V00-V10
  middle[1] = z[2] - q[2] / 3 - (s[1] + s[2]) / 12; // East, on V10-V11
  middle[2] = z[2] - p[2] / 3 - (s[3] + s[2]) / 12; // North, on V11-V01
  middle[3] = z[0] + q[0] / 3 + (s[0] + s[3]) / 12; // West, on V01-V00
  const double centre = 0.25 * (middle[0] + middle[1] + middle[2] + middle[3]);

  for (int t = 0; t < 4; ++t)
  {
    const int a = t;
    const int b = (t + 1) % 4;
    const double ab[2] = { CornerPositions[b][0] - CornerPositions[a][0],
      CornerPositions[b][1] - CornerPositions[a][1] };
    const double ac[2] = { Centre[0] - CornerPositions[a][0], Centre[1] - CornerPositions[a][1] };
    const double bc[2] = { Centre[0] - CornerPositions[b][0], Centre[1] - CornerPositions[b][1] };
    CubicTriangleOrdinates& o = this->Ordinates[t];
    // Around each corner the ordinates lie in its tangent plane.
    o[BezierOrdinateIndex(3, 0)] = z[a];
    o[BezierOrdinateIndex(0, 3)] = z[b];
    o[BezierOrdinateIndex(2, 1)] = z[a] + (p[a] * ab[0] + q[a] * ab[1]) / 3;
    o[BezierOrdinateIndex(1, 2)] = z[b] - (p[b] * ab[0] + q[b] * ab[1]) / 3;
    o[BezierOrdinateIndex(2, 0)] = z[a] + (p[a] * ac[0] + q[a] * ac[1]) / 3;
    o[BezierOrdinateIndex(0, 2)] = z[b] + (p[b] * bc[0] + q[b] * bc[1]) / 3;
    o[BezierOrdinateIndex(1, 1)] = middle[t];
    // C1 across the half-diagonals: C is the midpoint of both diagonals, so the ordinate next
    // to a half-diagonal is the average of its two neighbours across it.
    o[BezierOrdinateIndex(1, 0)] = 0.5 * (middle[t] + middle[(t + 3) % 4]);
    o[BezierOrdinateIndex(0, 1)] = 0.5 * (middle[t] + middle[(t + 1) % 4]);
    o[BezierOrdinateIndex(0, 0)] = centre;
  }
}

void MonotoneSibsonPatch::GetTriangleVertices(SibsonTriangle t, double vertices[3][2])
{
  TriangleVertices(static_cast<int>(t), vertices);
}

SibsonTriangle MonotoneSibsonPatch::LocateTriangle(double X, double Y)
{
  if (Y <= X && Y <= 1 - X)
  {
    return SibsonTriangle::South;
  }
  if (Y >= X && Y >= 1 - X)
  {
    return SibsonTriangle::North;
  }
  return X >= 1 - Y ? SibsonTriangle::East : SibsonTriangle::West;
}

double MonotoneSibsonPatch::Evaluate(double X, double Y) const
{
  double value, gradient[2];
  this->EvaluateWithGradient(X, Y, value, gradient);
  return value;
}

void MonotoneSibsonPatch::EvaluateWithGradient(double X, double Y, double& value, double localGradient[2]) const
{
  this->EvaluateTriangle(LocateTriangle(X, Y), X, Y, value, localGradient);
}

void MonotoneSibsonPatch::EvaluateMany(
  const MonotoneSibsonPatch* patches, int count, double X, double Y, double* values)
{
  const int t = static_cast<int>(LocateTriangle(X, Y));
  double vertices[3][2];
  TriangleVertices(t, vertices);
  double lambda[3], linear[3];
  Barycentric(vertices, X, Y, lambda);
  for (int m = 0; m < count; ++m)
  {
    // As EvaluateTriangle computes the value.
    ReduceToLinear(patches[m].Ordinates[t], lambda, linear);
    values[m] = lambda[0] * linear[0] + lambda[1] * linear[1] + lambda[2] * linear[2];
  }
}

void MonotoneSibsonPatch::EvaluateTriangle(
  SibsonTriangle t, double X, double Y, double& value, double localGradient[2]) const
{
  double vertices[3][2];
  TriangleVertices(static_cast<int>(t), vertices);
  double lambda[3], ax[3], ay[3], linear[3];
  Barycentric(vertices, X, Y, lambda);
  BarycentricDirection(vertices, 1, 0, ax);
  BarycentricDirection(vertices, 0, 1, ay);
  ReduceToLinear(this->Ordinates[static_cast<int>(t)], lambda, linear);
  value = lambda[0] * linear[0] + lambda[1] * linear[1] + lambda[2] * linear[2];
  localGradient[0] = 3 * (ax[0] * linear[0] + ax[1] * linear[1] + ax[2] * linear[2]);
  localGradient[1] = 3 * (ay[0] * linear[0] + ay[1] * linear[1] + ay[2] * linear[2]);
}

std::array<double, 6> MonotoneSibsonPatch::DiagonalDerivativeCoefficients(SibsonTriangle t) const
{
  double vertices[3][2], a[3];
  TriangleVertices(static_cast<int>(t), vertices);
  BarycentricDirection(vertices, 1, 1, a);
  const CubicTriangleOrdinates& b = this->Ordinates[static_cast<int>(t)];
  std::array<double, 6> c;
  for (int i = 0; i <= 2; ++i)
  {
    for (int j = 0; j <= 2 - i; ++j)
    {
      c[OrdinateIndex(2, i, j)] = 3 *
        (a[0] * b[OrdinateIndex(3, i + 1, j)] + a[1] * b[OrdinateIndex(3, i, j + 1)] +
          a[2] * b[OrdinateIndex(3, i, j)]);
    }
  }
  return c;
}
} // namespace topospline
