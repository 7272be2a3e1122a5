// Unit tests of the modified Sibson element and the monotone surface on the unit square
// (stage 4). The formulas of algorithms.md section 1 are a derivation, not a quote: every one
// used is proven here numerically (interpolation, C1 continuity, the D_(1,1)F coefficient
// table, sufficiency of (C0)-(C3), and that violations show up).
#include "MonotoneSibsonSurface.h"
#include "DeterministicRandom.h"
#include "TestHarness.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

using namespace topospline;

namespace
{
// Deterministic cases: every run tests the same ones.
using Random = DeterministicRandom;

SibsonCellData RandomCell(Random& random)
{
  SibsonCellData cell;
  for (int v = 0; v < 4; ++v)
  {
    cell.Z[v] = random.Uniform(-1, 1);
    cell.P[v] = random.Uniform(-2, 2);
    cell.Q[v] = random.Uniform(-2, 2);
  }
  return cell;
}

double CubicValue(const CubicHeightSegment& c, double t)
{
  const double r = 1 - t;
  return r * r * r * c[0] + 3 * r * r * t * c[1] + 3 * r * t * t * c[2] + t * t * t * c[3];
}

double SideValue(const BezierSide& side, double t)
{
  const int n = static_cast<int>(side.size());
  const int k = std::min(static_cast<int>(t * n), n - 1);
  return CubicValue(side[k], t * n - k);
}

const SibsonTriangle AllTriangles[4] = { SibsonTriangle::South, SibsonTriangle::East, SibsonTriangle::North,
  SibsonTriangle::West };

// D_(1,1)F sampled densely over the open cell: a regular grid, both diagonals, the lines
// through the centre, and points close to the corners and edges (down to `closest`). Returns
// the minimum. Where a cell only just satisfies the conditions, D_(1,1)F near a corner can be
// of the order of the squared distance times a tiny coefficient, below double rounding; the
// positivity tests therefore stop at 1e-6 from the boundary, the violation search goes closer.
double MinimumDiagonalDerivative(const MonotoneSibsonPatch& patch, double closest = 1e-6)
{
  double minimum = std::numeric_limits<double>::infinity();
  auto sample = [&](double X, double Y) {
    double value, gradient[2];
    patch.EvaluateWithGradient(X, Y, value, gradient);
    minimum = std::min(minimum, gradient[0] + gradient[1]);
  };
  const int n = 40;
  for (int a = 1; a < n; ++a)
  {
    const double t = static_cast<double>(a) / n;
    for (int b = 1; b < n; ++b)
    {
      sample(t, static_cast<double>(b) / n);
    }
    sample(t, t);
    sample(t, 1 - t);
  }
  for (double e : { closest, 1e-3, 1e-2, 3e-2 })
  {
    for (int a = 1; a < n; ++a)
    {
      const double t = static_cast<double>(a) / n;
      sample(t, e);
      sample(t, 1 - e);
      sample(e, t);
      sample(1 - e, t);
    }
    sample(e, e);
    sample(1 - e, e);
    sample(e, 1 - e);
    sample(1 - e, 1 - e);
    sample(e, 2 * e);
    sample(1 - e, 2 * e);
    sample(2 * e, 1 - e);
    sample(1 - 2 * e, 1 - e);
  }
  return minimum;
}

// Monotone boundary data in the layout stage 3 produces: node values increasing along each
// side, node slopes (h units) m_k >= 0 with m_k + m_{k+1} <= 3 * increment, so every segment
// has a non-decreasing control polygon; zero slope at the corners (g' = 0 at critical points).
enum class BoundaryFlavour
{
  Regular,
  Steep,           // one side rises 100 times more than the others
  Flat,            // two sides rise by 1e-3 only
  MiddleJunction,  // a node in the middle of a side has slope 0 (a junction point)
  ExtremeSlopes,   // slopes at their maximum: control polygons that rise in one third
  Lopsided,        // segment rises spread over 3 orders of magnitude, extreme slopes
  Count
};
const char* FlavourName(BoundaryFlavour f)
{
  static const char* names[] = { "regular", "steep", "flat", "junction", "extreme", "lopsided" };
  return names[static_cast<int>(f)];
}

BezierSide MakeSide(Random& random, int n, double start, double end, BoundaryFlavour flavour, bool junction)
{
  std::vector<double> weights(n), values(n + 1), slopes(n + 1, 0.0);
  double total = 0;
  for (double& w : weights)
  {
    w = flavour == BoundaryFlavour::Lopsided ? std::exp(random.Uniform(-7, 0)) : random.Uniform(0.05, 1.0);
    total += w;
  }
  values[0] = start;
  for (int k = 0; k < n; ++k)
  {
    values[k + 1] = values[k] + (end - start) * weights[k] / total;
  }
  values[n] = end;
  for (int k = 1; k < n; ++k)
  {
    const double room = 1.5 * std::min(values[k] - values[k - 1], values[k + 1] - values[k]);
    const bool extreme = flavour == BoundaryFlavour::ExtremeSlopes ||
      (flavour == BoundaryFlavour::Lopsided && random.Uniform() < 0.5);
    slopes[k] = extreme ? room : random.Uniform(0, 1) * room;
  }
  if (junction && n >= 2)
  {
    slopes[n / 2] = 0;
  }
  BezierSide side(n);
  for (int k = 0; k < n; ++k)
  {
    side[k] = { { values[k], values[k] + slopes[k] / 3, values[k + 1] - slopes[k + 1] / 3, values[k + 1] } };
  }
  return side;
}

MonotoneSurfaceBoundary MakeBoundary(Random& random, int n, BoundaryFlavour flavour)
{
  double rises[4]; // bottom, right, left, top
  for (double& r : rises)
  {
    r = random.Uniform(0.2, 1.0);
  }
  if (flavour == BoundaryFlavour::Steep)
  {
    rises[random.Integer(4)] *= 100;
  }
  if (flavour == BoundaryFlavour::Flat)
  {
    const int a = random.Integer(4);
    rises[a] = 1e-3;
    rises[(a + 1 + random.Integer(3)) % 4] = 1e-3;
  }
  const double minimum = random.Uniform(-1, 1);
  const double saddleX = minimum + rises[0];        // at (1,0)
  const double saddleY = minimum + rises[2];        // at (0,1)
  const double maximum = std::max(saddleX + rises[1], saddleY + rises[3]);
  const int junctionSide = flavour == BoundaryFlavour::MiddleJunction ? random.Integer(4) : -1;
  MonotoneSurfaceBoundary b;
  b.Bottom = MakeSide(random, n, minimum, saddleX, flavour, junctionSide == 0);
  b.Right = MakeSide(random, n, saddleX, maximum, flavour, junctionSide == 1);
  b.Left = MakeSide(random, n, minimum, saddleY, flavour, junctionSide == 2);
  b.Top = MakeSide(random, n, saddleY, maximum, flavour, junctionSide == 3);
  return b;
}

// Dense check of a surface over the open unit square: minimum of D_(1,1)F and of |grad F|.
void SurfaceMinima(const MonotoneSibsonSurface& surface, double& minimumDiagonal, double& minimumNorm)
{
  minimumDiagonal = minimumNorm = std::numeric_limits<double>::infinity();
  auto sample = [&](double u, double v) {
    double value, g[2];
    surface.EvaluateWithGradient(u, v, value, g);
    minimumDiagonal = std::min(minimumDiagonal, g[0] + g[1]);
    minimumNorm = std::min(minimumNorm, std::hypot(g[0], g[1]));
  };
  const int n = surface.GetGridSize();
  const int m = 16 * n; // grid lines and cell diagonals are sampled too (multiples of 1/(2n))
  for (int a = 1; a < m; ++a)
  {
    for (int b = 1; b < m; ++b)
    {
      sample(static_cast<double>(a) / m, static_cast<double>(b) / m);
    }
  }
  for (int a = 0; a <= m; ++a)
  {
    const double t = (a + 0.5) / (m + 1);
    for (double e : { 1e-7, 1e-4 })
    {
      sample(t, e);
      sample(t, 1 - e);
      sample(e, t);
      sample(1 - e, t);
    }
  }
}

double MaximumBoundaryError(const MonotoneSibsonSurface& surface, const MonotoneSurfaceBoundary& b)
{
  double error = 0;
  const int samples = 997;
  for (int a = 0; a <= samples; ++a)
  {
    const double t = static_cast<double>(a) / samples;
    error = std::max(error, std::abs(surface.Evaluate(t, 0) - SideValue(b.Bottom, t)));
    error = std::max(error, std::abs(surface.Evaluate(t, 1) - SideValue(b.Top, t)));
    error = std::max(error, std::abs(surface.Evaluate(0, t) - SideValue(b.Left, t)));
    error = std::max(error, std::abs(surface.Evaluate(1, t) - SideValue(b.Right, t)));
  }
  return error;
}

// Values and gradients across every shared grid edge and every interior half-diagonal.
double MaximumContinuityJump(const MonotoneSibsonSurface& surface)
{
  const int n = surface.GetGridSize();
  double jump = 0;
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      const MonotoneSibsonPatch& patch = surface.GetPatch(i, j);
      for (int a = 0; a <= 20; ++a)
      {
        const double t = a / 20.0;
        double v1, g1[2], v2, g2[2];
        if (i + 1 < n)
        {
          patch.EvaluateTriangle(SibsonTriangle::East, 1, t, v1, g1);
          surface.GetPatch(i + 1, j).EvaluateTriangle(SibsonTriangle::West, 0, t, v2, g2);
          jump = std::max({ jump, std::abs(v1 - v2), std::abs(g1[0] - g2[0]), std::abs(g1[1] - g2[1]) });
        }
        if (j + 1 < n)
        {
          patch.EvaluateTriangle(SibsonTriangle::North, t, 1, v1, g1);
          surface.GetPatch(i, j + 1).EvaluateTriangle(SibsonTriangle::South, t, 0, v2, g2);
          jump = std::max({ jump, std::abs(v1 - v2), std::abs(g1[0] - g2[0]), std::abs(g1[1] - g2[1]) });
        }
      }
    }
  }
  return jump;
}
} // namespace

//------------------------------------------------------------------------------------------
TEST_CASE(ElementInterpolatesCornerData)
{
  Random random(1);
  const double corners[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
  double worst = 0;
  for (int trial = 0; trial < 500; ++trial)
  {
    const SibsonCellData cell = RandomCell(random);
    const MonotoneSibsonPatch patch(cell);
    for (int v = 0; v < 4; ++v)
    {
      // From every sub-triangle (the polynomial pieces meeting at a corner all agree there).
      for (SibsonTriangle t : AllTriangles)
      {
        double vertices[3][2];
        MonotoneSibsonPatch::GetTriangleVertices(t, vertices);
        const bool incident = (vertices[0][0] == corners[v][0] && vertices[0][1] == corners[v][1]) ||
          (vertices[1][0] == corners[v][0] && vertices[1][1] == corners[v][1]);
        if (!incident)
        {
          continue;
        }
        double value, gradient[2];
        patch.EvaluateTriangle(t, corners[v][0], corners[v][1], value, gradient);
        worst = std::max({ worst, std::abs(value - cell.Z[v]), std::abs(gradient[0] - cell.P[v]),
                           std::abs(gradient[1] - cell.Q[v]) });
      }
    }
  }
  std::printf("  corner interpolation: max error %.2e\n", worst);
  CHECK(worst < 1e-13);
}

TEST_CASE(ElementReproducesLinearFunctions)
{
  // Linear data gives the linear function itself (the element has linear precision).
  Random random(2);
  double worst = 0;
  for (int trial = 0; trial < 100; ++trial)
  {
    const double a = random.Uniform(-1, 1), bx = random.Uniform(-2, 2), by = random.Uniform(-2, 2);
    SibsonCellData cell;
    const double corners[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
    for (int v = 0; v < 4; ++v)
    {
      cell.Z[v] = a + bx * corners[v][0] + by * corners[v][1];
      cell.P[v] = bx;
      cell.Q[v] = by;
    }
    const MonotoneSibsonPatch patch(cell);
    for (int s = 0; s < 200; ++s)
    {
      const double X = random.Uniform(), Y = random.Uniform();
      double value, gradient[2];
      patch.EvaluateWithGradient(X, Y, value, gradient);
      worst = std::max({ worst, std::abs(value - (a + bx * X + by * Y)), std::abs(gradient[0] - bx),
                         std::abs(gradient[1] - by) });
    }
  }
  CHECK(worst < 1e-13);
}

TEST_CASE(ElementIsC1AcrossHalfDiagonals)
{
  Random random(3);
  double worst = 0;
  for (int trial = 0; trial < 500; ++trial)
  {
    const MonotoneSibsonPatch patch(RandomCell(random));
    // Half-diagonal from corner V_t to C is shared by triangles t (edge A-C) and t-1 (edge B-C).
    const double corners[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
    for (int t = 0; t < 4; ++t)
    {
      for (int a = 0; a <= 50; ++a)
      {
        const double s = a / 50.0;
        const double X = (1 - s) * corners[t][0] + s * 0.5;
        const double Y = (1 - s) * corners[t][1] + s * 0.5;
        double v1, g1[2], v2, g2[2];
        patch.EvaluateTriangle(AllTriangles[t], X, Y, v1, g1);
        patch.EvaluateTriangle(AllTriangles[(t + 3) % 4], X, Y, v2, g2);
        worst = std::max({ worst, std::abs(v1 - v2), std::abs(g1[0] - g2[0]), std::abs(g1[1] - g2[1]) });
      }
    }
  }
  std::printf("  half-diagonal jump (value, gradient): %.2e\n", worst);
  CHECK(worst < 1e-10);
}

TEST_CASE(ElementsAreC1AcrossGridEdges)
{
  // A 5 x 5 grid of arbitrary (not monotone) node data: neighbouring cells must agree in value
  // and gradient along their shared edge, which holds only if the cross-boundary derivative of
  // the modified element depends on the edge's end data alone.
  Random random(4);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial)
  {
    const int n = 5;
    std::vector<double> z((n + 1) * (n + 1)), p(z.size()), q(z.size());
    for (std::size_t k = 0; k < z.size(); ++k)
    {
      z[k] = random.Uniform(-1, 1);
      p[k] = random.Uniform(-2, 2);
      q[k] = random.Uniform(-2, 2);
    }
    auto patchAt = [&](int i, int j) {
      SibsonCellData cell;
      const int nodes[4] = { j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i };
      for (int v = 0; v < 4; ++v)
      {
        cell.Z[v] = z[nodes[v]];
        cell.P[v] = p[nodes[v]];
        cell.Q[v] = q[nodes[v]];
      }
      return MonotoneSibsonPatch(cell);
    };
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        const MonotoneSibsonPatch here = patchAt(i, j);
        for (int a = 0; a <= 40; ++a)
        {
          const double t = a / 40.0;
          double v1, g1[2], v2, g2[2];
          if (i + 1 < n)
          {
            here.EvaluateTriangle(SibsonTriangle::East, 1, t, v1, g1);
            patchAt(i + 1, j).EvaluateTriangle(SibsonTriangle::West, 0, t, v2, g2);
            worst = std::max({ worst, std::abs(v1 - v2), std::abs(g1[0] - g2[0]), std::abs(g1[1] - g2[1]) });
          }
          if (j + 1 < n)
          {
            here.EvaluateTriangle(SibsonTriangle::North, t, 1, v1, g1);
            patchAt(i, j + 1).EvaluateTriangle(SibsonTriangle::South, t, 0, v2, g2);
            worst = std::max({ worst, std::abs(v1 - v2), std::abs(g1[0] - g2[0]), std::abs(g1[1] - g2[1]) });
          }
        }
      }
    }
  }
  std::printf("  grid-edge jump (value, gradient): %.2e\n", worst);
  CHECK(worst < 1e-10);
}

TEST_CASE(DiagonalDerivativeCoefficientTable)
{
  // The Bernstein coefficients of h D_(1,1)F (first proven to represent F_x + F_y) equal the
  // table of algorithms.md 1.3: corners s, outer-edge midpoints (s_A + s_B)/2, V10-C and V01-C
  // midpoints 3 Delta - LHS(C2) and 3 Delta - LHS(C3), centre their average.
  Random random(5);
  double representation = 0, table = 0;
  for (int trial = 0; trial < 500; ++trial)
  {
    const SibsonCellData c = RandomCell(random);
    const MonotoneSibsonPatch patch(c);
    double s[4];
    for (int v = 0; v < 4; ++v)
    {
      s[v] = c.P[v] + c.Q[v];
    }
    const double delta = c.Z[2] - c.Z[0];
    const double mid10 = 3 * delta - ConditionC2LeftSide(c);
    const double mid01 = 3 * delta - ConditionC3LeftSide(c);
    const double centre = 3 * delta - 0.75 * (s[0] + s[2]) - 0.25 * (s[1] + s[3]);
    const double mid00 = s[0] / 2 + (s[1] + s[3]) / 4;
    const double mid11 = s[2] / 2 + (s[1] + s[3]) / 4;
    // Expected (c200, c110, c101, c020, c011, c002) per triangle (A, B, C).
    const double expected[4][6] = {
      { s[0], (s[0] + s[1]) / 2, mid00, s[1], mid10, centre }, // South (V00, V10, C)
      { s[1], (s[1] + s[2]) / 2, mid10, s[2], mid11, centre }, // East (V10, V11, C)
      { s[2], (s[2] + s[3]) / 2, mid11, s[3], mid01, centre }, // North (V11, V01, C)
      { s[3], (s[3] + s[0]) / 2, mid01, s[0], mid00, centre }, // West (V01, V00, C)
    };
    for (int t = 0; t < 4; ++t)
    {
      const std::array<double, 6> k = patch.DiagonalDerivativeCoefficients(AllTriangles[t]);
      for (int m = 0; m < 6; ++m)
      {
        table = std::max(table, std::abs(k[m] - expected[t][m]));
      }
      CHECK(std::abs(centre - 0.5 * (mid10 + mid01)) < 1e-12);
      double vertices[3][2];
      MonotoneSibsonPatch::GetTriangleVertices(AllTriangles[t], vertices);
      for (int sample = 0; sample < 20; ++sample)
      {
        double l1 = random.Uniform(), l2 = random.Uniform();
        if (l1 + l2 > 1)
        {
          l1 = 1 - l1;
          l2 = 1 - l2;
        }
        const double l0 = 1 - l1 - l2;
        const double X = l0 * vertices[0][0] + l1 * vertices[1][0] + l2 * vertices[2][0];
        const double Y = l0 * vertices[0][1] + l1 * vertices[1][1] + l2 * vertices[2][1];
        double value, g[2];
        patch.EvaluateTriangle(AllTriangles[t], X, Y, value, g);
        const double bernstein = k[0] * l0 * l0 + 2 * k[1] * l0 * l1 + 2 * k[2] * l0 * l2 + k[3] * l1 * l1 +
          2 * k[4] * l1 * l2 + k[5] * l2 * l2;
        representation = std::max(representation, std::abs(bernstein - (g[0] + g[1])));
      }
    }
  }
  std::printf("  D11 Bernstein form vs gradient: %.2e, vs table: %.2e\n", representation, table);
  CHECK(representation < 1e-12);
  CHECK(table < 1e-12);
}

TEST_CASE(ConditionsImplyNoCriticalPoint)
{
  // Random cells that satisfy (C0)-(C3) (some with (C1) or (C2) tight): D_(1,1)F > 0 at every
  // dense sample of the open cell.
  Random random(6);
  int satisfying = 0, positive = 0, tight = 0;
  for (int trial = 0; trial < 4000; ++trial)
  {
    SibsonCellData c = RandomCell(random);
    for (int v = 0; v < 4; ++v)
    {
      if (c.P[v] + c.Q[v] < 0 || random.Uniform() < 0.15)
      {
        c.Q[v] = -c.P[v] + (random.Uniform() < 0.5 ? 0.0 : random.Uniform(0, 0.5)); // s = 0 sometimes
      }
    }
    const double needed = std::max(ConditionC2LeftSide(c), ConditionC3LeftSide(c)) / 3;
    const int mode = random.Integer(3);
    const double rise = mode == 0 ? std::max(needed, 0.0) + 1e-7 : std::max(needed, 0.0) + random.Uniform(0, 1);
    if (mode == 0 && needed > 0)
    {
      ++tight;
    }
    c.Z[2] = c.Z[0] + rise;
    if (CheckMonotonicityConditions(c) != MonotonicityCondition::Satisfied)
    {
      continue;
    }
    ++satisfying;
    positive += MinimumDiagonalDerivative(MonotoneSibsonPatch(c)) > 0 ? 1 : 0;
  }
  // A cell where (C2) holds with equality, (C3) strictly, and s = 0 at V10: still positive.
  SibsonCellData c;
  c.P = { { 0.7, 0.4, 0.3, 0.2 } };
  c.Q = { { 0.1, -0.4, 0.5, 0.3 } };
  c.Z[0] = 0;
  c.Z[2] = ConditionC2LeftSide(c) / 3;
  CHECK(CheckMonotonicityConditions(c) == MonotonicityCondition::Satisfied);
  CHECK(ConditionC3LeftSide(c) < 3 * c.Z[2]);
  CHECK(MinimumDiagonalDerivative(MonotoneSibsonPatch(c)) > 0);

  std::printf("  %d satisfying cells (%d nearly tight), D11F > 0 on all samples in %d\n", satisfying, tight, positive);
  CHECK(satisfying > 1000);
  CHECK(positive == satisfying);
}

TEST_CASE(ViolationsShowUp)
{
  // Random cells failing a condition: how often is D_(1,1)F negative somewhere? Always when
  // (C1) fails (D_(1,1)F = s at the corner) or when (C2)/(C3) fails at a cell with s = 0 at
  // V10/V01 (the half-diagonal there starts with coefficients 0, negative); often otherwise.
  Random random(7);
  int violating[6] = { 0 }, found[6] = { 0 };
  for (int trial = 0; trial < 4000; ++trial)
  {
    SibsonCellData c = RandomCell(random);
    for (int v = 0; v < 4; ++v)
    {
      if (random.Uniform() < 0.7 && c.P[v] + c.Q[v] < 0)
      {
        c.Q[v] = -c.P[v] + random.Uniform(0, 1);
      }
    }
    c.Z[2] = c.Z[0] + random.Uniform(0.0, 2.0);
    const MonotonicityCondition failed = CheckMonotonicityConditions(c);
    if (failed == MonotonicityCondition::Satisfied)
    {
      continue;
    }
    ++violating[static_cast<int>(failed)];
    found[static_cast<int>(failed)] += MinimumDiagonalDerivative(MonotoneSibsonPatch(c), 1e-9) < 0 ? 1 : 0;
  }
  for (int k = 1; k < 6; ++k)
  {
    if (violating[k] > 0)
    {
      std::printf("  violations of %-6s: %4d cells, negative D11F found in %4d (%.0f%%)\n",
        MonotonicityConditionName(static_cast<MonotonicityCondition>(k)), violating[k], found[k],
        100.0 * found[k] / violating[k]);
    }
  }
  const int c1 = static_cast<int>(MonotonicityCondition::C1);
  const int c2 = static_cast<int>(MonotonicityCondition::C2);
  const int c3 = static_cast<int>(MonotonicityCondition::C3);
  CHECK(violating[c1] > 200);
  CHECK(found[c1] == violating[c1]);
  const int c23 = violating[c2] + violating[c3];
  const int f23 = found[c2] + found[c3];
  CHECK(c23 > 200);
  CHECK(f23 > c23 / 5);

  // s = 0 at V10 (resp. V01) and (C2) (resp. (C3)) violated: always a negative value.
  int targeted = 0, targetedFound = 0;
  for (int trial = 0; trial < 1000; ++trial)
  {
    SibsonCellData cell = RandomCell(random);
    for (int v = 0; v < 4; ++v)
    {
      cell.Q[v] = -cell.P[v] + random.Uniform(0, 1);
    }
    const bool second = random.Uniform() < 0.5;
    const int corner = second ? 3 : 1;
    cell.Q[corner] = -cell.P[corner];
    const double left = second ? ConditionC3LeftSide(cell) : ConditionC2LeftSide(cell);
    if (left <= 0)
    {
      continue;
    }
    cell.Z[2] = cell.Z[0] + left / 3 * random.Uniform(0.5, 0.999);
    if (CheckMonotonicityConditions(cell) != (second ? MonotonicityCondition::C3 : MonotonicityCondition::C2) &&
      CheckMonotonicityConditions(cell) != MonotonicityCondition::C2)
    {
      continue;
    }
    ++targeted;
    targetedFound += MinimumDiagonalDerivative(MonotoneSibsonPatch(cell), 1e-9) < 0 ? 1 : 0;
  }
  std::printf("  targeted (s = 0 at the off-diagonal corner): %d of %d\n", targetedFound, targeted);
  CHECK(targeted > 300);
  CHECK(targetedFound == targeted);
}

TEST_CASE(ConditionCheckerNamesTheFailure)
{
  SibsonCellData c;
  c.Z = { { 0, 0.5, 1, 0.5 } };
  c.P = { { 0.2, 0.2, 0.2, 0.2 } };
  c.Q = { { 0.2, 0.2, 0.2, 0.2 } };
  CHECK(CheckMonotonicityConditions(c) == MonotonicityCondition::Satisfied);
  SibsonCellData d = c;
  d.Z[2] = 0;
  CHECK(CheckMonotonicityConditions(d) == MonotonicityCondition::C0);
  d = c;
  d.Q[1] = -0.3;
  CHECK(CheckMonotonicityConditions(d) == MonotonicityCondition::C1);
  d = c;
  d.P[0] = 3; // (5 p00 + q00)/4 large, (p00 + 5 q00)/4 small
  d.Q[0] = -0.5;
  CHECK(CheckMonotonicityConditions(d) == MonotonicityCondition::C2);
  d = c;
  d.P[0] = -0.5;
  d.Q[0] = 3;
  CHECK(CheckMonotonicityConditions(d) == MonotonicityCondition::C3);
  d = c;
  d.P = { { 0, 0, 0, 0 } };
  d.Q = { { 0, 0, 0, 0 } };
  d.P[1] = 1; // LHS(C2) = LHS(C3) = 0.5 = 3 Delta: the centre coefficient vanishes
  d.Q[1] = 0;
  d.P[3] = 1;
  d.Z[2] = 0.5 / 3;
  CHECK(std::abs(ConditionC2LeftSide(d) - 3 * d.Z[2]) < 1e-15);
  CHECK(CheckMonotonicityConditions(d) == MonotonicityCondition::CentreNotPositive ||
    CheckMonotonicityConditions(d) == MonotonicityCondition::C2);
  d.Z[2] = 0.5 / 3 * 1.01; // strict
  CHECK(CheckMonotonicityConditions(d) == MonotonicityCondition::Satisfied);
}

//------------------------------------------------------------------------------------------
TEST_CASE(SubdivisionKeepsTheCurve)
{
  Random random(8);
  double worst = 0;
  for (int trial = 0; trial < 100; ++trial)
  {
    BezierSide side(1 + random.Integer(4));
    double v = random.Uniform(-1, 1);
    for (auto& s : side)
    {
      s[0] = v;
      s[1] = v + random.Uniform(0, 1);
      s[2] = s[1] + random.Uniform(0, 1);
      s[3] = v = s[2] + random.Uniform(0, 1);
    }
    const int target = static_cast<int>(side.size()) * (1 + random.Integer(4));
    BezierSide fine;
    CHECK(SubdivideSide(side, target, fine));
    CHECK(static_cast<int>(fine.size()) == target);
    for (int a = 0; a <= 500; ++a)
    {
      const double t = a / 500.0;
      worst = std::max(worst, std::abs(SideValue(side, t) - SideValue(fine, t)));
    }
    // Pieces of equal length: the scaled end derivatives of consecutive pieces agree.
    for (std::size_t k = 0; k + 1 < fine.size(); ++k)
    {
      worst = std::max(worst, std::abs(fine[k][3] - fine[k + 1][0]));
      if ((k + 1) % (target / side.size()) != 0)
      {
        worst = std::max(worst, std::abs((fine[k][3] - fine[k][2]) - (fine[k + 1][1] - fine[k + 1][0])));
      }
    }
  }
  BezierSide none;
  CHECK(!SubdivideSide(BezierSide(3), 4, none));
  CHECK(CommonSegmentCount(BezierSide(2), BezierSide(3), BezierSide(4), BezierSide(2)) == 12);
  CHECK(worst < 1e-13);
}

TEST_CASE(SurfaceOfLinearDataIsLinear)
{
  // Boundary of F = x + y: the Laplace values and difference derivatives are exact, nothing
  // needs correcting, and the surface is x + y.
  for (int n = 1; n <= 6; ++n)
  {
    MonotoneSurfaceBoundary b;
    const double h = 1.0 / n;
    for (int k = 0; k < n; ++k)
    {
      const double t0 = k * h;
      b.Bottom.push_back({ { t0, t0 + h / 3, t0 + 2 * h / 3, t0 + h } });
      b.Left.push_back(b.Bottom.back());
      b.Top.push_back({ { 1 + t0, 1 + t0 + h / 3, 1 + t0 + 2 * h / 3, 1 + t0 + h } });
      b.Right.push_back(b.Top.back());
    }
    MonotoneSibsonSurface surface;
    std::string error;
    CHECK(surface.Build(b, error));
    CHECK(surface.Report().MaximumValueShift < 1e-14);
    CHECK(surface.Report().LimitedNodes == 0);
    double worst = 0;
    for (int a = 0; a <= 50; ++a)
    {
      for (int c = 0; c <= 50; ++c)
      {
        const double u = a / 50.0, v = c / 50.0;
        double value, g[2];
        surface.EvaluateWithGradient(u, v, value, g);
        worst = std::max({ worst, std::abs(value - (u + v)), std::abs(g[0] - 1), std::abs(g[1] - 1) });
      }
    }
    CHECK(worst < 1e-12);
  }
}

TEST_CASE(RandomMonotoneSurfacesHaveNoInteriorCriticalPoint)
{
  Random random(9);
  int built = 0, total = 0;
  double worstBoundary = 0, worstJump = 0, worstCorner = 0;
  int adjusted = 0, limited = 0, linearized = 0, fallback = 0;
  for (int flavour = 0; flavour < static_cast<int>(BoundaryFlavour::Count); ++flavour)
  {
    double flavourMinimum = std::numeric_limits<double>::infinity();
    for (int n = 2; n <= 8; ++n)
    {
      for (int trial = 0; trial < 6; ++trial)
      {
        ++total;
        const MonotoneSurfaceBoundary b = MakeBoundary(random, n, static_cast<BoundaryFlavour>(flavour));
        MonotoneSibsonSurface surface;
        std::string error;
        const bool ok = surface.Build(b, error);
        if (!ok)
        {
          std::printf("  %s n=%d: %s\n", FlavourName(static_cast<BoundaryFlavour>(flavour)), n, error.c_str());
        }
        CHECK(ok);
        CHECK(surface.CountViolatingCells() == 0);
        built += ok ? 1 : 0;
        double minimumDiagonal, minimumNorm;
        SurfaceMinima(surface, minimumDiagonal, minimumNorm);
        CHECK(minimumDiagonal > 0);
        CHECK(minimumNorm > 0);
        flavourMinimum = std::min(flavourMinimum, minimumDiagonal);
        worstBoundary = std::max(worstBoundary, MaximumBoundaryError(surface, b));
        worstJump = std::max(worstJump, MaximumContinuityJump(surface));
        worstCorner = std::max({ worstCorner, std::abs(surface.Evaluate(0, 0) - b.Bottom[0][0]),
          std::abs(surface.Evaluate(1, 0) - b.Right[0][0]), std::abs(surface.Evaluate(0, 1) - b.Top[0][0]),
          std::abs(surface.Evaluate(1, 1) - b.Top.back()[3]) });
        // The corners are critical points (zero gradient), as the boundary data says.
        double value, g[2];
        surface.EvaluateWithGradient(0, 0, value, g);
        CHECK(g[0] == 0 && g[1] == 0);
        adjusted += surface.Report().AdjustedDiagonals;
        limited += surface.Report().LimitedNodes;
        linearized += surface.Report().LinearizedDiagonals;
        fallback += surface.Report().GlobalFallback;
      }
    }
    std::printf("  %-8s: min D11F over the open square %.3e\n", FlavourName(static_cast<BoundaryFlavour>(flavour)),
      flavourMinimum);
  }
  std::printf("  %d/%d built; boundary error %.2e, corner error %.2e, C1 jump %.2e\n", built, total, worstBoundary,
    worstCorner, worstJump);
  std::printf("  corrections: %d linearized diagonals, %d limited nodes, %d diagonals with moved values, %d global "
              "fallbacks\n",
    linearized, limited, adjusted, fallback);
  CHECK(built == total);
  CHECK(worstBoundary < 1e-12);
  CHECK(worstCorner < 1e-15);
  CHECK(worstJump < 1e-10);
}

TEST_CASE(StressManySurfacesAndLargerGrids)
{
  // Many more boundaries of every flavour, N up to 24: every cell must satisfy the conditions
  // (the construction enforces them; a coarser sampling double-checks D_(1,1)F > 0).
  Random random(15);
  int total = 0, failures = 0, sampledNegative = 0;
  double worstShift = 0;
  for (int trial = 0; trial < 2000; ++trial)
  {
    const int n = trial % 10 == 0 ? 9 + random.Integer(16) : 1 + random.Integer(8);
    const auto flavour = static_cast<BoundaryFlavour>(random.Integer(static_cast<int>(BoundaryFlavour::Count)));
    const MonotoneSurfaceBoundary b = MakeBoundary(random, n, flavour);
    MonotoneSibsonSurface surface;
    std::string error;
    ++total;
    if (!surface.Build(b, error) || surface.CountViolatingCells() != 0)
    {
      ++failures;
      std::printf("  %s n=%d: %s\n", FlavourName(flavour), n, error.c_str());
      continue;
    }
    const double range = b.Top.back()[3] - b.Bottom.front()[0];
    worstShift = std::max(worstShift, surface.Report().MaximumValueShift / range);
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        sampledNegative += MinimumDiagonalDerivative(surface.GetPatch(i, j), 1e-3) > 0 ? 0 : 1;
      }
    }
  }
  std::printf("  %d surfaces, %d failed, %d cells with a non-positive D11F sample; largest value correction "
              "%.3f of the range\n",
    total, failures, sampledNegative, worstShift);
  CHECK(failures == 0);
  CHECK(sampledNegative == 0);
}

TEST_CASE(EachSafeguardAloneSuffices)
{
  // The guarantee does not rest on the per-cell limiter: without it the per-diagonal limiter
  // and the value correction carry the conditions, and without both limiters the minimal
  // derivatives (algorithms.md 1.4's recipe) with corrected values do.
  Random random(16);
  MonotoneSurfaceOptions noCellLimiter;
  noCellLimiter.CellLimiterSweeps = 0;
  MonotoneSurfaceOptions minimalOnly = noCellLimiter;
  minimalOnly.DiagonalLimiterRounds = 0;
  int failures = 0, moved = 0, fallbacks = 0, total = 0;
  for (int trial = 0; trial < 600; ++trial)
  {
    const int n = 2 + random.Integer(8);
    const auto flavour = static_cast<BoundaryFlavour>(random.Integer(static_cast<int>(BoundaryFlavour::Count)));
    const MonotoneSurfaceBoundary b = MakeBoundary(random, n, flavour);
    for (const MonotoneSurfaceOptions* options : { &noCellLimiter, &minimalOnly })
    {
      ++total;
      MonotoneSibsonSurface surface;
      std::string error;
      const bool ok = surface.Build(b, error, *options);
      failures += ok && surface.CountViolatingCells() == 0 ? 0 : 1;
      moved += surface.Report().AdjustedDiagonals;
      fallbacks += surface.Report().GlobalFallback;
      double minimumDiagonal, minimumNorm;
      if (trial % 20 == 0)
      {
        SurfaceMinima(surface, minimumDiagonal, minimumNorm);
        CHECK(minimumDiagonal > 0);
      }
      if (ok && options == &noCellLimiter)
      {
        CHECK(MaximumBoundaryError(surface, b) < 1e-12);
      }
    }
  }
  std::printf("  %d builds, %d failed; %d diagonals with moved values, %d minimal-derivative builds\n", total,
    failures, moved, fallbacks);
  CHECK(failures == 0);
  CHECK(fallbacks >= total / 2);
  CHECK(moved > 0);
}

TEST_CASE(JunctionTangentGetsAPositiveCrossDerivative)
{
  // A boundary node with zero tangential derivative (a junction point) gets p + q > 0, so the
  // gradient does not vanish there.
  Random random(10);
  for (int trial = 0; trial < 20; ++trial)
  {
    const int n = 2 + random.Integer(6);
    const MonotoneSurfaceBoundary b = MakeBoundary(random, n, BoundaryFlavour::MiddleJunction);
    MonotoneSibsonSurface surface;
    std::string error;
    CHECK(surface.Build(b, error));
    for (int k = 1; k < n; ++k)
    {
      const int nodes[4][2] = { { k, 0 }, { k, n }, { 0, k }, { n, k } };
      for (const auto& node : nodes)
      {
        const double p = surface.NodeP(node[0], node[1]), q = surface.NodeQ(node[0], node[1]);
        CHECK(p + q >= 0);
        CHECK(std::hypot(p, q) > 0);
      }
    }
  }
}

TEST_CASE(UnevenSidesAreSubdividedToACommonCount)
{
  // The paper's situation: a junction point splits one side into two pieces (2 k segments,
  // zero slope at the junction) while the others have k; subdivide all to the common count.
  Random random(11);
  for (int trial = 0; trial < 20; ++trial)
  {
    const int k = 1 + random.Integer(4);
    MonotoneSurfaceBoundary coarse = MakeBoundary(random, k, BoundaryFlavour::Regular);
    const MonotoneSurfaceBoundary fine = MakeBoundary(random, 2 * k, BoundaryFlavour::MiddleJunction);
    // Replace the bottom by a 2k-segment side with the same end values.
    BezierSide bottom = fine.Bottom;
    const double a0 = bottom.front()[0], a1 = bottom.back()[3];
    const double b0 = coarse.Bottom.front()[0], b1 = coarse.Bottom.back()[3];
    for (auto& s : bottom)
    {
      for (double& c : s)
      {
        c = b0 + (c - a0) * (b1 - b0) / (a1 - a0);
      }
    }
    bottom.front()[0] = b0;
    bottom.back()[3] = b1;
    coarse.Bottom = bottom;
    const int common = CommonSegmentCount(coarse.Bottom, coarse.Right, coarse.Top, coarse.Left);
    CHECK(common == 2 * k);
    MonotoneSurfaceBoundary even;
    CHECK(SubdivideSide(coarse.Bottom, common, even.Bottom));
    CHECK(SubdivideSide(coarse.Left, common, even.Left));
    CHECK(SubdivideSide(coarse.Top, common, even.Top));
    CHECK(SubdivideSide(coarse.Right, common, even.Right));
    MonotoneSibsonSurface surface;
    std::string error;
    const bool ok = surface.Build(even, error);
    if (!ok)
    {
      std::printf("  k=%d: %s\n", k, error.c_str());
    }
    CHECK(ok);
    CHECK(MaximumBoundaryError(surface, coarse) < 1e-12);
    double minimumDiagonal, minimumNorm;
    SurfaceMinima(surface, minimumDiagonal, minimumNorm);
    CHECK(minimumDiagonal > 0);
  }
}

TEST_CASE(MalformedAndInfeasibleInputsAreReported)
{
  Random random(12);
  MonotoneSurfaceBoundary b = MakeBoundary(random, 3, BoundaryFlavour::Regular);
  MonotoneSibsonSurface surface;
  std::string error;

  MonotoneSurfaceBoundary uneven = b;
  uneven.Left.pop_back();
  CHECK(!surface.Build(uneven, error));
  CHECK(!error.empty());

  MonotoneSurfaceBoundary broken = b;
  broken.Bottom[1][0] += 0.1; // does not join the previous segment
  CHECK(!surface.Build(broken, error));
  CHECK(error.find("join") != std::string::npos);

  MonotoneSurfaceBoundary decreasing = b;
  for (auto* side : { &decreasing.Bottom, &decreasing.Left, &decreasing.Top, &decreasing.Right })
  {
    for (auto& s : *side)
    {
      for (double& c : s)
      {
        c = -c;
      }
    }
  }
  CHECK(!surface.Build(decreasing, error));
  CHECK(error.find("increase") != std::string::npos);

  // Non-zero derivatives at the minimum that no interior choice can compensate: (0,0) -> (1,1)
  // rises by 1 while q(0,0) = 2.7 needs (p + 5 q)/4 = 3.4 > 3. Reported, still evaluable.
  MonotoneSurfaceBoundary steep;
  steep.Bottom = { { { 0, 0.0, 0.1, 0.1 } } };
  steep.Left = { { { 0, 0.9, 0.9, 0.9 } } };
  steep.Right = { { { 0.1, 0.5, 0.9, 1.0 } } };
  steep.Top = { { { 0.9, 0.95, 0.98, 1.0 } } };
  CHECK(!surface.Build(steep, error));
  CHECK(surface.Report().ViolatingCells == 1);
  CHECK(std::abs(surface.Evaluate(1, 1) - 1.0) < 1e-15);
}

TEST_CASE(BezierTrianglesMatchTheSurface)
{
  Random random(13);
  const MonotoneSurfaceBoundary b = MakeBoundary(random, 4, BoundaryFlavour::Regular);
  MonotoneSibsonSurface surface;
  std::string error;
  CHECK(surface.Build(b, error));
  const std::vector<SurfaceBezierTriangle> triangles = surface.GetBezierTriangles();
  CHECK(triangles.size() == 4u * 16u);
  double worst = 0;
  for (const SurfaceBezierTriangle& t : triangles)
  {
    // Corners of the triangle are control points 0 (b300), 6 (b030), 9 (b003).
    const auto& A = t.Points[0];
    const auto& B = t.Points[6];
    const auto& C = t.Points[9];
    for (int s = 0; s < 10; ++s)
    {
      double l1 = random.Uniform(), l2 = random.Uniform();
      if (l1 + l2 > 1)
      {
        l1 = 1 - l1;
        l2 = 1 - l2;
      }
      const double l0 = 1 - l1 - l2;
      double value = 0;
      for (int i = 0; i <= 3; ++i)
      {
        for (int j = 0; j <= 3 - i; ++j)
        {
          const int k = 3 - i - j;
          const double factorial[4] = { 1, 1, 2, 6 };
          const double multinomial = 6.0 / (factorial[i] * factorial[j] * factorial[k]);
          const auto& point = t.Points[BezierOrdinateIndex(i, j)];
          // The control point sits at its domain point (i A + j B + k C) / 3.
          worst = std::max(worst, std::abs(point[0] - (i * A[0] + j * B[0] + k * C[0]) / 3));
          worst = std::max(worst, std::abs(point[1] - (i * A[1] + j * B[1] + k * C[1]) / 3));
          value += multinomial * std::pow(l0, i) * std::pow(l1, j) * std::pow(l2, k) * point[2];
        }
      }
      const double u = l0 * A[0] + l1 * B[0] + l2 * C[0];
      const double v = l0 * A[1] + l1 * B[1] + l2 * C[1];
      worst = std::max(worst, std::abs(value - surface.Evaluate(u, v)));
    }
  }
  CHECK(worst < 1e-12);
}

TEST_CASE(BuildTiming)
{
  Random random(14);
  const MonotoneSurfaceBoundary b = MakeBoundary(random, 7, BoundaryFlavour::Regular);
  MonotoneSibsonSurface surface;
  std::string error;
  const auto start = std::chrono::steady_clock::now();
  int ok = 0;
  for (int r = 0; r < 1000; ++r)
  {
    ok += surface.Build(b, error) ? 1 : 0;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("  7x7 surface built 1000 times in %.3f s (%.1f us each, %zu Bezier triangles)\n", seconds,
    1e6 * seconds / 1000, surface.GetBezierTriangles().size());
  CHECK(ok == 1000);
}

int main()
{
  return testing_harness::RunAll();
}
