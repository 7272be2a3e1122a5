#include "MonotoneSibsonPatch.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

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

//------------------------------------------------------------------------------------------
void SplitCubicSegment(const CubicHeightSegment& c, double s, CubicHeightSegment& left, CubicHeightSegment& right)
{
  const double r = 1 - s;
  const double c01 = r * c[0] + s * c[1];
  const double c12 = r * c[1] + s * c[2];
  const double c23 = r * c[2] + s * c[3];
  const double c012 = r * c01 + s * c12;
  const double c123 = r * c12 + s * c23;
  const double c0123 = r * c012 + s * c123;
  left = { { c[0], c01, c012, c0123 } };
  right = { { c0123, c123, c23, c[3] } };
}

bool SubdivideSide(const BezierSide& side, int targetCount, BezierSide& result)
{
  result.clear();
  const int count = static_cast<int>(side.size());
  if (count == 0 || targetCount < count || targetCount % count != 0)
  {
    return false;
  }
  const int pieces = targetCount / count;
  result.reserve(targetCount);
  for (const CubicHeightSegment& segment : side)
  {
    // Peel off pieces of equal length of the original parameter: the k-th cut of the
    // remainder [k/m, 1] is at local parameter 1/(m - k).
    CubicHeightSegment remainder = segment;
    for (int k = 0; k < pieces - 1; ++k)
    {
      CubicHeightSegment left, right;
      SplitCubicSegment(remainder, 1.0 / (pieces - k), left, right);
      result.push_back(left);
      remainder = right;
    }
    result.push_back(remainder);
  }
  return true;
}

int CommonSegmentCount(const BezierSide& bottom, const BezierSide& left, const BezierSide& top, const BezierSide& right)
{
  long long common = 1;
  for (const BezierSide* side : { &bottom, &left, &top, &right })
  {
    const long long count = static_cast<long long>(side->size());
    if (count == 0)
    {
      return 0;
    }
    common = common / std::gcd(common, count) * count;
  }
  return common > std::numeric_limits<int>::max() ? 0 : static_cast<int>(common);
}

//------------------------------------------------------------------------------------------
namespace
{
// A (1,1)-diagonal of the grid: nodes (I0 + c, J0 + c), c = 0..Length; its cells are the ones
// whose lower-left corner is one of its nodes except the last.
struct Diagonal
{
  int I0 = 0;
  int J0 = 0;
  int Length = 0;
};

std::vector<Diagonal> GridDiagonals(int n)
{
  std::vector<Diagonal> diagonals;
  for (int d = -(n - 1); d <= n - 1; ++d)
  {
    Diagonal diagonal;
    diagonal.I0 = std::max(d, 0);
    diagonal.J0 = std::max(-d, 0);
    diagonal.Length = n - std::abs(d);
    diagonals.push_back(diagonal);
  }
  return diagonals;
}

// Isotonic (non-decreasing) least-squares fit by pooling adjacent violators.
void PoolAdjacentViolators(std::vector<double>& values)
{
  std::vector<double> blockMean;
  std::vector<int> blockSize;
  for (double v : values)
  {
    blockMean.push_back(v);
    blockSize.push_back(1);
    while (blockMean.size() > 1 && blockMean[blockMean.size() - 2] > blockMean.back())
    {
      const double m2 = blockMean.back();
      const int n2 = blockSize.back();
      blockMean.pop_back();
      blockSize.pop_back();
      const double total = blockMean.back() * blockSize.back() + m2 * n2;
      blockSize.back() += n2;
      blockMean.back() = total / blockSize.back();
    }
  }
  std::size_t k = 0;
  for (std::size_t b = 0; b < blockMean.size(); ++b)
  {
    for (int m = 0; m < blockSize[b]; ++m)
    {
      values[k++] = blockMean[b];
    }
  }
}
} // namespace

SibsonCellData MonotoneSibsonSurface::GetCellData(int i, int j) const
{
  SibsonCellData cell;
  const int nodes[4] = { this->Node(i, j), this->Node(i + 1, j), this->Node(i + 1, j + 1), this->Node(i, j + 1) };
  for (int v = 0; v < 4; ++v)
  {
    cell.Z[v] = this->Z[nodes[v]];
    cell.P[v] = this->P[nodes[v]];
    cell.Q[v] = this->Q[nodes[v]];
  }
  return cell;
}

bool MonotoneSibsonSurface::Build(
  const MonotoneSurfaceBoundary& boundary, std::string& error, const MonotoneSurfaceOptions& options)
{
  error.clear();
  this->BuildReport = MonotoneSurfaceReport();
  this->Patches.clear();
  const int n = static_cast<int>(boundary.Bottom.size());
  this->N = 0;
  if (n == 0 || boundary.Left.size() != boundary.Bottom.size() || boundary.Top.size() != boundary.Bottom.size() ||
    boundary.Right.size() != boundary.Bottom.size())
  {
    error = "the four sides must have the same, non-zero number of segments (see SubdivideSide)";
    return false;
  }
  double lowest = std::numeric_limits<double>::infinity();
  double highest = -lowest;
  for (const BezierSide* side : { &boundary.Bottom, &boundary.Left, &boundary.Top, &boundary.Right })
  {
    for (const CubicHeightSegment& segment : *side)
    {
      for (double c : segment)
      {
        if (!std::isfinite(c))
        {
          error = "a boundary control value is not finite";
          return false;
        }
        lowest = std::min(lowest, c);
        highest = std::max(highest, c);
      }
    }
  }
  const double range = highest - lowest;
  // Relative to the cell's range, but never below rounding: a nearly flat cell far from 0
  // (a constant field at 7.25 spread by 1e-11) has a range of a few thousand ulps only.
  const double magnitude = std::max(std::abs(lowest), std::abs(highest));
  const double allowedMismatch = std::max(options.ConsistencyTolerance * (range > 0 ? range : 1.0),
    64 * std::numeric_limits<double>::epsilon() * magnitude);

  this->N = n;
  const int nodeCount = (n + 1) * (n + 1);
  this->Z.assign(nodeCount, 0.0);
  this->P.assign(nodeCount, 0.0);
  this->Q.assign(nodeCount, 0.0);

  // Boundary nodes: the Bezier end points and end derivatives (3 (c1 - c0) is d/dt of the
  // segment, t its own parameter, which is h d/dx along a side of the uniform grid).
  double mismatch = 0;
  auto reconcile = [&mismatch](double a, double b) {
    mismatch = std::max(mismatch, std::abs(a - b));
    return 0.5 * (a + b);
  };
  auto startSlope = [](const CubicHeightSegment& c) { return 3 * (c[1] - c[0]); };
  auto endSlope = [](const CubicHeightSegment& c) { return 3 * (c[3] - c[2]); };
  const BezierSide& bottom = boundary.Bottom;
  const BezierSide& left = boundary.Left;
  const BezierSide& top = boundary.Top;
  const BezierSide& right = boundary.Right;
  for (int k = 1; k < n; ++k)
  {
    this->Z[this->Node(k, 0)] = reconcile(bottom[k - 1][3], bottom[k][0]);
    this->P[this->Node(k, 0)] = reconcile(endSlope(bottom[k - 1]), startSlope(bottom[k]));
    this->Z[this->Node(k, n)] = reconcile(top[k - 1][3], top[k][0]);
    this->P[this->Node(k, n)] = reconcile(endSlope(top[k - 1]), startSlope(top[k]));
    this->Z[this->Node(0, k)] = reconcile(left[k - 1][3], left[k][0]);
    this->Q[this->Node(0, k)] = reconcile(endSlope(left[k - 1]), startSlope(left[k]));
    this->Z[this->Node(n, k)] = reconcile(right[k - 1][3], right[k][0]);
    this->Q[this->Node(n, k)] = reconcile(endSlope(right[k - 1]), startSlope(right[k]));
  }
  // Corners: both partials are tangential derivatives of a side.
  this->Z[this->Node(0, 0)] = reconcile(bottom[0][0], left[0][0]);
  this->P[this->Node(0, 0)] = startSlope(bottom[0]);
  this->Q[this->Node(0, 0)] = startSlope(left[0]);
  this->Z[this->Node(n, 0)] = reconcile(bottom[n - 1][3], right[0][0]);
  this->P[this->Node(n, 0)] = endSlope(bottom[n - 1]);
  this->Q[this->Node(n, 0)] = startSlope(right[0]);
  this->Z[this->Node(0, n)] = reconcile(left[n - 1][3], top[0][0]);
  this->P[this->Node(0, n)] = startSlope(top[0]);
  this->Q[this->Node(0, n)] = endSlope(left[n - 1]);
  this->Z[this->Node(n, n)] = reconcile(top[n - 1][3], right[n - 1][3]);
  this->P[this->Node(n, n)] = endSlope(top[n - 1]);
  this->Q[this->Node(n, n)] = endSlope(right[n - 1]);
  // Tangential derivatives that are negative only by rounding noise (e.g. a zero end slope of
  // a rescaled curve) are zero: (C1) at corners and boundary nodes is judged on them.
  for (int k = 0; k <= n; ++k)
  {
    for (double* slope : { &this->P[this->Node(k, 0)], &this->P[this->Node(k, n)], &this->Q[this->Node(0, k)],
           &this->Q[this->Node(n, k)] })
    {
      if (*slope < 0 && *slope >= -allowedMismatch)
      {
        *slope = 0;
      }
    }
  }
  if (mismatch > allowedMismatch)
  {
    char text[64];
    std::snprintf(text, sizeof(text), "%.3g of %.3g allowed", mismatch, allowedMismatch);
    error = std::string("the boundary segments do not join with common values and derivatives (mismatch ") + text + ")";
    this->N = 0;
    return false;
  }

  const std::vector<Diagonal> diagonals = GridDiagonals(n);
  std::vector<double> rise(diagonals.size());
  for (std::size_t d = 0; d < diagonals.size(); ++d)
  {
    const Diagonal& g = diagonals[d];
    rise[d] = this->Z[this->Node(g.I0 + g.Length, g.J0 + g.Length)] - this->Z[this->Node(g.I0, g.J0)];
    if (!(rise[d] > 0))
    {
      error = "the boundary values do not increase along the grid diagonal from node (" + std::to_string(g.I0) +
        "," + std::to_string(g.J0) + "): no monotone surface can interpolate them";
      this->N = 0;
      return false;
    }
  }

  // Interior values: discrete Laplace equation (5-point stencil) with the boundary values.
  const int m = n - 1;
  if (m > 0)
  {
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(5 * m * m);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m * m);
    auto unknown = [m](int i, int j) { return (j - 1) * m + (i - 1); };
    for (int j = 1; j < n; ++j)
    {
      for (int i = 1; i < n; ++i)
      {
        const int row = unknown(i, j);
        entries.emplace_back(row, row, 4.0);
        const int neighbours[4][2] = { { i - 1, j }, { i + 1, j }, { i, j - 1 }, { i, j + 1 } };
        for (const auto& nb : neighbours)
        {
          if (nb[0] == 0 || nb[0] == n || nb[1] == 0 || nb[1] == n)
          {
            rhs[row] += this->Z[this->Node(nb[0], nb[1])];
          }
          else
          {
            entries.emplace_back(row, unknown(nb[0], nb[1]), -1.0);
          }
        }
      }
    }
    Eigen::SparseMatrix<double> laplacian(m * m, m * m);
    laplacian.setFromTriplets(entries.begin(), entries.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(laplacian);
    const Eigen::VectorXd solution = solver.solve(rhs);
    for (int j = 1; j < n; ++j)
    {
      for (int i = 1; i < n; ++i)
      {
        this->Z[this->Node(i, j)] = solution[unknown(i, j)];
      }
    }
  }
  this->LaplaceZ = this->Z;

  // The paper's fallback for (C0): where the Laplace values do not increase strictly along a
  // diagonal, interpolate linearly between its (boundary) end points.
  for (std::size_t d = 0; d < diagonals.size(); ++d)
  {
    const Diagonal& g = diagonals[d];
    bool increasing = true;
    for (int c = 0; c < g.Length; ++c)
    {
      increasing = increasing &&
        this->Z[this->Node(g.I0 + c + 1, g.J0 + c + 1)] > this->Z[this->Node(g.I0 + c, g.J0 + c)];
    }
    if (!increasing)
    {
      const double start = this->Z[this->Node(g.I0, g.J0)];
      for (int c = 1; c < g.Length; ++c)
      {
        this->Z[this->Node(g.I0 + c, g.J0 + c)] = start + rise[d] * c / g.Length;
      }
      ++this->BuildReport.LinearizedDiagonals;
    }
  }

  // Derivatives. Free are both partials at interior nodes and the cross derivative at the
  // non-corner boundary nodes. Each free node gets a minimal choice (the one that leaves every
  // diagonal the most room for (C2)/(C3): p = q = sigma/2 inside, p + q = 0 on the boundary,
  // p + q = sigma - t where the tangential derivative t < sigma, so the gradient is never 0
  // there) and an estimate from the values (differences), and ends up at
  //   minimal + lambda * (estimate - minimal),  lambda in [0, 1].
  // Every condition is linear in the derivatives, so along lambda the requirement of a cell
  // is convex: limiting lambda is a 1D search.
  enum NodeKind
  {
    Corner,
    Interior,
    CrossIsQ, // bottom and top sides: p tangential, q crosses
    CrossIsP  // left and right sides
  };
  std::vector<unsigned char> kind(nodeCount);
  for (int j = 0; j <= n; ++j)
  {
    for (int i = 0; i <= n; ++i)
    {
      const bool sideX = i == 0 || i == n;
      const bool sideY = j == 0 || j == n;
      kind[this->Node(i, j)] = sideX && sideY ? Corner : sideY ? CrossIsQ : sideX ? CrossIsP : Interior;
    }
  }
  std::vector<double> pMin(this->P), qMin(this->Q);
  auto setMinimal = [&](double sigma) {
    for (int k = 0; k < nodeCount; ++k)
    {
      if (kind[k] == Interior)
      {
        pMin[k] = qMin[k] = 0.5 * sigma;
      }
      else if (kind[k] == CrossIsQ)
      {
        const double t = this->P[k];
        qMin[k] = t < sigma ? sigma - 2 * t : (options.FlatAcrossBoundary ? 0.0 : -t);
      }
      else if (kind[k] == CrossIsP)
      {
        const double t = this->Q[k];
        pMin[k] = t < sigma ? sigma - 2 * t : (options.FlatAcrossBoundary ? 0.0 : -t);
      }
    }
  };
  auto cellNodes = [this](int i, int j, int nodes[4]) {
    nodes[0] = this->Node(i, j);
    nodes[1] = this->Node(i + 1, j);
    nodes[2] = this->Node(i + 1, j + 1);
    nodes[3] = this->Node(i, j + 1);
  };
  // max(LHS(C2), LHS(C3), 0) / 3: the least rise z11 - z00 the cell needs.
  auto requirement = [&](int i, int j, const std::vector<double>& p, const std::vector<double>& q) {
    int nodes[4];
    cellNodes(i, j, nodes);
    SibsonCellData cell;
    for (int v = 0; v < 4; ++v)
    {
      cell.P[v] = p[nodes[v]];
      cell.Q[v] = q[nodes[v]];
    }
    return std::max({ ConditionC2LeftSide(cell), ConditionC3LeftSide(cell), 0.0 }) / 3;
  };
  auto diagonalRequirement = [&](const Diagonal& g, const std::vector<double>& p, const std::vector<double>& q) {
    double total = 0;
    for (int c = 0; c < g.Length; ++c)
    {
      total += requirement(g.I0 + c, g.J0 + c, p, q);
    }
    return total;
  };

  // sigma: a fraction of the smallest per-cell room left by the minimal choice with sigma = 0.
  setMinimal(0);
  double smallestRoom = std::numeric_limits<double>::infinity();
  double smallestAverageRise = std::numeric_limits<double>::infinity();
  for (std::size_t d = 0; d < diagonals.size(); ++d)
  {
    const double room = rise[d] - diagonalRequirement(diagonals[d], pMin, qMin);
    if (room > 0)
    {
      smallestRoom = std::min(smallestRoom, room / diagonals[d].Length);
    }
    smallestAverageRise = std::min(smallestAverageRise, rise[d] / diagonals[d].Length);
  }
  const double sigma = std::isfinite(smallestRoom) ? options.MinimumSlopeFraction * smallestRoom
                                                   : 1e-3 * smallestAverageRise;
  this->BuildReport.MinimumSlope = sigma;
  setMinimal(sigma);
  std::vector<double> bestRoom(diagonals.size());
  bool feasible = true;
  for (std::size_t d = 0; d < diagonals.size(); ++d)
  {
    bestRoom[d] = rise[d] - diagonalRequirement(diagonals[d], pMin, qMin);
    feasible = feasible && bestRoom[d] >= 0;
  }

  // Estimates: central differences inside, one-sided second-order differences across the
  // boundary; then moved into the admissible set (p + q >= sigma inside: the projection of the
  // thesis's Algorithm 1; cross derivative >= the minimal one on the boundary).
  std::vector<double> pEst(this->P), qEst(this->Q);
  auto z = [this](int i, int j) { return this->Z[this->Node(i, j)]; };
  for (int j = 0; j <= n; ++j)
  {
    for (int i = 0; i <= n; ++i)
    {
      const int k = this->Node(i, j);
      if (kind[k] == Interior)
      {
        pEst[k] = 0.5 * (z(i + 1, j) - z(i - 1, j));
        qEst[k] = 0.5 * (z(i, j + 1) - z(i, j - 1));
        const double s = pEst[k] + qEst[k];
        if (s < sigma)
        {
          pEst[k] += 0.5 * (sigma - s);
          qEst[k] += 0.5 * (sigma - s);
        }
      }
      else if (kind[k] == CrossIsQ)
      {
        const int inward = j == 0 ? 1 : -1;
        const double d = options.FlatAcrossBoundary ? 0.0 : 0.5 * (-3 * z(i, j) + 4 * z(i, j + inward) - z(i, j + 2 * inward));
        qEst[k] = std::max(inward * d, qMin[k]);
      }
      else if (kind[k] == CrossIsP)
      {
        const int inward = i == 0 ? 1 : -1;
        const double d = options.FlatAcrossBoundary ? 0.0 : 0.5 * (-3 * z(i, j) + 4 * z(i + inward, j) - z(i + 2 * inward, j));
        pEst[k] = std::max(inward * d, pMin[k]);
      }
    }
  }

  std::vector<double> lambda(nodeCount, 1.0);
  std::vector<double> p(nodeCount), q(nodeCount);
  auto applyLambda = [&](int k) {
    p[k] = pMin[k] + lambda[k] * (pEst[k] - pMin[k]);
    q[k] = qMin[k] + lambda[k] * (qEst[k] - qMin[k]);
  };
  for (int k = 0; k < nodeCount; ++k)
  {
    applyLambda(k);
  }

  // Pass 1, per cell (keeps the Laplace values wherever possible): scale the derivatives of
  // the cell's corners so that the requirement stays below (1 - margin) of the actual rise.
  // Both left sides are linear in the common factor gamma, so the largest admissible gamma is
  // explicit.
  const double keep = 1 - options.LimiterMargin;
  for (int sweep = 0; sweep < options.CellLimiterSweeps; ++sweep)
  {
    bool changed = false;
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        const double target = 3 * keep * (z(i + 1, j + 1) - z(i, j));
        if (requirement(i, j, p, q) * 3 <= target)
        {
          continue;
        }
        int nodes[4];
        cellNodes(i, j, nodes);
        SibsonCellData atZero, atOne;
        for (int v = 0; v < 4; ++v)
        {
          atZero.P[v] = pMin[nodes[v]];
          atZero.Q[v] = qMin[nodes[v]];
          atOne.P[v] = p[nodes[v]];
          atOne.Q[v] = q[nodes[v]];
        }
        double gamma = 1;
        const double lows[2] = { ConditionC2LeftSide(atZero), ConditionC3LeftSide(atZero) };
        const double highs[2] = { ConditionC2LeftSide(atOne), ConditionC3LeftSide(atOne) };
        for (int c = 0; c < 2; ++c)
        {
          if (highs[c] > target)
          {
            gamma = std::min(gamma, lows[c] >= target ? 0.0 : (target - lows[c]) / (highs[c] - lows[c]));
          }
        }
        gamma = std::max(0.0, std::min(gamma, 1.0));
        for (int v = 0; v < 4; ++v)
        {
          lambda[nodes[v]] *= gamma;
          applyLambda(nodes[v]);
        }
        changed = true;
      }
    }
    if (!changed)
    {
      break;
    }
  }

  // Pass 2, per diagonal (what is needed for the values to be fixable at all): the total
  // requirement of a diagonal must leave a share of the best achievable room.
  auto diagonalTouching = [&](const Diagonal& g, std::vector<int>& nodes) {
    nodes.clear();
    for (int c = 0; c < g.Length; ++c)
    {
      int corners[4];
      cellNodes(g.I0 + c, g.J0 + c, corners);
      nodes.insert(nodes.end(), corners, corners + 4);
    }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  };
  bool diagonalsOk = false;
  std::vector<int> touching;
  for (int round = 0; round < options.DiagonalLimiterRounds && !diagonalsOk; ++round)
  {
    diagonalsOk = true;
    for (std::size_t d = 0; d < diagonals.size(); ++d)
    {
      const double bound = rise[d] - options.LimiterMargin * std::max(bestRoom[d], 0.0);
      if (diagonalRequirement(diagonals[d], p, q) <= bound)
      {
        continue;
      }
      diagonalsOk = false;
      diagonalTouching(diagonals[d], touching);
      std::vector<double> base(touching.size());
      for (std::size_t k = 0; k < touching.size(); ++k)
      {
        base[k] = lambda[touching[k]];
      }
      auto trial = [&](double gamma) {
        for (std::size_t k = 0; k < touching.size(); ++k)
        {
          lambda[touching[k]] = gamma * base[k];
          applyLambda(touching[k]);
        }
        return diagonalRequirement(diagonals[d], p, q);
      };
      // Convex in gamma and admissible at 0 (all touching nodes minimal): bisection.
      double lo = 0, hi = 1;
      for (int iteration = 0; iteration < 50; ++iteration)
      {
        const double mid = 0.5 * (lo + hi);
        (trial(mid) <= bound ? lo : hi) = mid;
      }
      trial(lo);
    }
  }
  if (!diagonalsOk)
  {
    // The minimal choice everywhere satisfies every diagonal at once.
    std::fill(lambda.begin(), lambda.end(), 0.0);
    for (int k = 0; k < nodeCount; ++k)
    {
      applyLambda(k);
    }
    this->BuildReport.GlobalFallback = 1;
  }
  for (int k = 0; k < nodeCount; ++k)
  {
    if (lambda[k] < 1 && (pEst[k] != pMin[k] || qEst[k] != qMin[k]))
    {
      ++this->BuildReport.LimitedNodes;
    }
  }
  this->P = p;
  this->Q = q;

  // Values: per diagonal (a value only enters the conditions of its own diagonal's cells),
  // the least-squares closest values with rise_c >= requirement_c + share of the spare room:
  // with w_c = z_c - (sum of the needed rises before c), that is isotonic regression of w with
  // fixed ends, i.e. pooling adjacent violators and clamping.
  for (std::size_t d = 0; d < diagonals.size(); ++d)
  {
    const Diagonal& g = diagonals[d];
    if (g.Length < 2)
    {
      continue;
    }
    std::vector<double> needed(g.Length);
    double total = 0;
    for (int c = 0; c < g.Length; ++c)
    {
      needed[c] = requirement(g.I0 + c, g.J0 + c, p, q);
      total += needed[c];
    }
    if (total <= rise[d])
    {
      const double share = options.RiseShare * (rise[d] - total) / g.Length;
      for (double& r : needed)
      {
        r += share;
      }
    }
    else
    {
      feasible = false; // best effort: rises proportional to the requirements
      for (double& r : needed)
      {
        r *= rise[d] / total;
      }
    }
    std::vector<double> offset(g.Length + 1, 0.0);
    for (int c = 0; c < g.Length; ++c)
    {
      offset[c + 1] = offset[c] + needed[c];
    }
    const double wStart = z(g.I0, g.J0);
    const double wEnd = z(g.I0 + g.Length, g.J0 + g.Length) - offset[g.Length];
    std::vector<double> w(g.Length - 1), original(g.Length - 1);
    for (int c = 1; c < g.Length; ++c)
    {
      original[c - 1] = w[c - 1] = z(g.I0 + c, g.J0 + c) - offset[c];
    }
    PoolAdjacentViolators(w);
    bool moved = false;
    for (int c = 1; c < g.Length; ++c)
    {
      const double value = std::min(std::max(w[c - 1], wStart), std::max(wEnd, wStart));
      if (value != original[c - 1])
      {
        this->Z[this->Node(g.I0 + c, g.J0 + c)] = value + offset[c];
        moved = true;
      }
    }
    this->BuildReport.AdjustedDiagonals += moved ? 1 : 0;
  }
  for (int k = 0; k < nodeCount; ++k)
  {
    this->BuildReport.MaximumValueShift =
      std::max(this->BuildReport.MaximumValueShift, std::abs(this->Z[k] - this->LaplaceZ[k]));
  }

  this->Patches.resize(static_cast<std::size_t>(n) * n);
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      this->Patches[j * n + i].SetData(this->GetCellData(i, j));
    }
  }
  this->BuildReport.ViolatingCells = this->CountViolatingCells();
  if (!feasible || this->BuildReport.ViolatingCells > 0)
  {
    error = "the sufficient monotonicity conditions cannot all hold for this boundary data (" +
      std::to_string(this->BuildReport.ViolatingCells) + " cells violate them)";
    return false;
  }
  return true;
}

int MonotoneSibsonSurface::CountViolatingCells(double tolerance) const
{
  int violating = 0;
  for (int j = 0; j < this->N; ++j)
  {
    for (int i = 0; i < this->N; ++i)
    {
      const SibsonCellData cell = this->GetCellData(i, j);
      bool bad = CheckMonotonicityConditions(cell, tolerance) != MonotonicityCondition::Satisfied;
      const int corners[4][2] = { { i, j }, { i + 1, j }, { i + 1, j + 1 }, { i, j + 1 } };
      for (int v = 0; v < 4; ++v)
      {
        const int ci = corners[v][0], cj = corners[v][1];
        const bool interior = ci > 0 && ci < this->N && cj > 0 && cj < this->N;
        bad = bad || (interior && !(cell.P[v] + cell.Q[v] > 0));
      }
      violating += bad ? 1 : 0;
    }
  }
  return violating;
}

void MonotoneSibsonSurface::Locate(double u, double v, int& i, int& j, double& X, double& Y) const
{
  u = std::min(std::max(u, 0.0), 1.0);
  v = std::min(std::max(v, 0.0), 1.0);
  const double su = u * this->N, sv = v * this->N;
  i = std::min(static_cast<int>(su), this->N - 1);
  j = std::min(static_cast<int>(sv), this->N - 1);
  X = su - i;
  Y = sv - j;
}

double MonotoneSibsonSurface::Evaluate(double u, double v) const
{
  double value, gradient[2];
  this->EvaluateWithGradient(u, v, value, gradient);
  return value;
}

void MonotoneSibsonSurface::EvaluateWithGradient(double u, double v, double& value, double gradient[2]) const
{
  int i, j;
  double X, Y;
  this->Locate(u, v, i, j, X, Y);
  this->Patches[j * this->N + i].EvaluateWithGradient(X, Y, value, gradient);
  gradient[0] *= this->N;
  gradient[1] *= this->N;
}

std::vector<SurfaceBezierTriangle> MonotoneSibsonSurface::GetBezierTriangles() const
{
  std::vector<SurfaceBezierTriangle> triangles;
  triangles.reserve(4 * static_cast<std::size_t>(this->N) * this->N);
  const double h = 1.0 / this->N;
  for (int j = 0; j < this->N; ++j)
  {
    for (int i = 0; i < this->N; ++i)
    {
      const MonotoneSibsonPatch& patch = this->Patches[j * this->N + i];
      for (int t = 0; t < 4; ++t)
      {
        double vertices[3][2];
        TriangleVertices(t, vertices);
        const CubicTriangleOrdinates& o = patch.GetOrdinates(static_cast<SibsonTriangle>(t));
        SurfaceBezierTriangle triangle;
        for (int a = 0; a <= 3; ++a)
        {
          for (int b = 0; b <= 3 - a; ++b)
          {
            const int c = 3 - a - b;
            const int index = BezierOrdinateIndex(a, b);
            const double x = (a * vertices[0][0] + b * vertices[1][0] + c * vertices[2][0]) / 3;
            const double y = (a * vertices[0][1] + b * vertices[1][1] + c * vertices[2][1]) / 3;
            triangle.Points[index] = { { (i + x) * h, (j + y) * h, o[index] } };
          }
        }
        triangles.push_back(triangle);
      }
    }
  }
  return triangles;
}
} // namespace topospline
