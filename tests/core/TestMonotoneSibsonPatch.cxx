// Unit tests of the modified Sibson element, one cell of the monotone surface (stage 4). The
// formulas of docs/Algorithms.md, 1 are a derivation, not a quote: every one used is proven
// here numerically (interpolation, C1 continuity, the D_(1,1)F coefficient table, sufficiency
// of (C0)-(C3), and that violations show up). The surface has its own test,
// TestMonotoneSibsonSurface.
#include "MonotoneSibsonPatch.h"
#include "DeterministicRandom.h"
#include "SibsonPatchSampling.h"
#include "TestHarness.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace topospline;
using topospline_test::MinimumDiagonalDerivative;
using topospline_test::RandomBarycentric;

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

const SibsonTriangle AllTriangles[4] = { SibsonTriangle::South, SibsonTriangle::East, SibsonTriangle::North,
  SibsonTriangle::West };
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
  // table of docs/Algorithms.md, 1.3: corners s, outer-edge midpoints (s_A + s_B)/2, V10-C and V01-C
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
        double l0, l1, l2;
        RandomBarycentric(random, l0, l1, l2);
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

int main()
{
  return testing_harness::RunAll();
}
