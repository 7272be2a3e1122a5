// Unit tests of the monotone surface on the unit square (stage 4): a grid of modified Sibson
// elements built from four monotone boundary curves. Besides the construction's own checks
// (CountViolatingCells, the patches' D_(1,1)F), oracles that only evaluate the surface: values
// increasing along every (1,1) line, the boundary Beziers interpolated with their derivatives,
// and one-sided difference quotients that agree across patch edges (C1).
#include "MonotoneSibsonSurface.h"
#include "DeterministicRandom.h"
#include "SibsonPatchSampling.h"
#include "TestHarness.h"
#include "TestSupport.h" // ThreadedFor

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

using namespace topospline;
using topospline_test::MinimumDiagonalDerivative;
using topospline_test::RandomBarycentric;

namespace
{
// Deterministic cases: every run tests the same ones.
using Random = DeterministicRandom;

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
  double rises[4]; // bottom, right, top, left
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
  const double saddleY = minimum + rises[3];        // at (0,1)
  const double maximum = std::max(saddleX + rises[1], saddleY + rises[2]);
  const int junctionSide = flavour == BoundaryFlavour::MiddleJunction ? random.Integer(4) : -1;
  MonotoneSurfaceBoundary b;
  b.Bottom = MakeSide(random, n, minimum, saddleX, flavour, junctionSide == 0);
  b.Right = MakeSide(random, n, saddleX, maximum, flavour, junctionSide == 1);
  b.Top = MakeSide(random, n, saddleY, maximum, flavour, junctionSide == 2);
  b.Left = MakeSide(random, n, minimum, saddleY, flavour, junctionSide == 3);
  return b;
}

// Surface number `trial` of a seeded series that cycles through the grid sizes 1..8 and the
// flavours; returns the value range of its boundary.
double BuildSeriesSurface(Random& random, int trial, MonotoneSurfaceBoundary& b, MonotoneSibsonSurface& surface)
{
  const int n = 1 + trial % 8;
  const auto flavour = static_cast<BoundaryFlavour>(trial % static_cast<int>(BoundaryFlavour::Count));
  b = MakeBoundary(random, n, flavour);
  std::string error;
  CHECK(surface.Build(b, error));
  return b.Top.back()[3] - b.Bottom.front()[0];
}

// d/dt of a side at t in [0, 1] (its own parameter, so n times the segment's derivative).
double SideDerivative(const BezierSide& side, double t)
{
  const int n = static_cast<int>(side.size());
  const int k = std::min(static_cast<int>(t * n), n - 1);
  const CubicHeightSegment& c = side[k];
  const double s = t * n - k, r = 1 - s;
  return n * 3 * (r * r * (c[1] - c[0]) + 2 * r * s * (c[2] - c[1]) + s * s * (c[3] - c[2]));
}

// Largest decrease of the surface's values between consecutive samples along lines of direction
// (1, 1) (where D_(1,1)F > 0 makes them increase), relative to the value range; 0 if none.
double LargestDiagonalDecrease(const MonotoneSibsonSurface& surface, double range)
{
  double decrease = 0;
  const int lines = 40, samples = 200;
  for (int a = -lines + 1; a < lines; ++a)
  {
    const double offset = static_cast<double>(a) / lines; // the line v = u - offset
    double previous = std::numeric_limits<double>::quiet_NaN();
    for (int b = 0; b <= samples; ++b)
    {
      const double u = std::max(offset, 0.0) + (1 - std::abs(offset)) * b / samples;
      const double value = surface.Evaluate(u, u - offset);
      if (b > 0)
      {
        decrease = std::max(decrease, (previous - value) / range);
      }
      previous = value;
    }
  }
  return decrease;
}

// Largest difference between the one-sided difference quotients of the values at points on the
// grid lines (across them: x on vertical lines, y on horizontal ones) and on the cells'
// half-diagonals (across them), in units of the value range. A C1 surface has O(delta) there,
// a crease O(1).
double LargestDerivativeJump(const MonotoneSibsonSurface& surface, double delta, double range)
{
  const int n = surface.GetGridSize();
  double jump = 0;
  auto across = [&](double u, double v, double du, double dv) {
    const double before = surface.Evaluate(u, v) - surface.Evaluate(u - delta * du, v - delta * dv);
    const double after = surface.Evaluate(u + delta * du, v + delta * dv) - surface.Evaluate(u, v);
    jump = std::max(jump, std::abs(after - before) / delta / range);
  };
  const int samples = 7;
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      for (int a = 1; a <= samples; ++a)
      {
        const double t = (static_cast<double>(a) - 0.5) / samples; // avoids corners and centre
        if (i > 0)
        {
          across(static_cast<double>(i) / n, (j + t) / n, 1, 0);
        }
        if (j > 0)
        {
          across((i + t) / n, static_cast<double>(j) / n, 0, 1);
        }
        across((i + t) / n, (j + t) / n, 1, -1);      // diagonal V00-V11
        across((i + t) / n, (j + 1 - t) / n, 1, 1);   // diagonal V10-V01
      }
    }
  }
  return jump;
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
    error = std::max(error, std::abs(surface.Evaluate(1, t) - SideValue(b.Right, t)));
    error = std::max(error, std::abs(surface.Evaluate(t, 1) - SideValue(b.Top, t)));
    error = std::max(error, std::abs(surface.Evaluate(0, t) - SideValue(b.Left, t)));
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

TEST_CASE(RoundingOfANearlyFlatCellIsAveragedAway)
{
  // A cell whose values all lie within 2e-11 at 0.12, as the value spreading of stage 3 leaves
  // them on noise: a join off by 3e-13 (its end slope then by 9e-13: under 1e-11 of the values,
  // but 4.5 % of the cell's own range) is rounding of the 1-cell fits. Refused by default; averaged away with a rounding
  // tolerance of 1e-10 of the values. A join off by half the range is refused either way: the
  // tolerance stays within RoundingShareOfRange of the range.
  Random random(31);
  MonotoneSurfaceBoundary b = MakeBoundary(random, 3, BoundaryFlavour::Regular);
  double lowest = 1e300, highest = -1e300;
  for (const auto* side : { &b.Bottom, &b.Right, &b.Top, &b.Left })
  {
    for (const auto& segment : *side)
    {
      lowest = std::min(lowest, *std::min_element(segment.begin(), segment.end()));
      highest = std::max(highest, *std::max_element(segment.begin(), segment.end()));
    }
  }
  const double range = 2e-11;
  for (auto* side : { &b.Bottom, &b.Right, &b.Top, &b.Left })
  {
    for (auto& segment : *side)
    {
      for (double& c : segment)
      {
        c = 0.12 + range * (c - lowest) / (highest - lowest);
      }
    }
  }
  MonotoneSurfaceBoundary rounded = b;
  rounded.Bottom[1][0] += 3e-13;
  MonotoneSurfaceBoundary real = b;
  real.Bottom[1][0] += 0.5 * range;
  MonotoneSibsonSurface surface;
  std::string error;
  CHECK(!surface.Build(rounded, error));
  CHECK(error.find("join") != std::string::npos);
  MonotoneSurfaceOptions options;
  options.RoundingTolerance = 1e-10;
  error.clear();
  surface.Build(rounded, error, options);
  CHECK(error.find("join") == std::string::npos);
  CHECK_EQ(surface.GetGridSize(), 3);
  CHECK(!surface.Build(real, error, options));
  CHECK(error.find("join") != std::string::npos);
}

TEST_CASE(SidesTiedByRoundingAtACornerAreBuiltFlat)
{
  // A DEM's plateau broken by 1e-9 of its integer heights: the sides meeting at the corner
  // (1, 0) rise by less than their values' rounding over a grid step, so the diagonal from
  // (n - 1, 0) to (n, 1) joins two equal values. No strictly monotone surface exists there,
  // but refusing the whole 2-cell left its region at the input's values (a Maunga Whau crop at
  // 2 %, grid 299): the surface is built, that diagonal flat, and the cell is reported
  // infeasible with its violating cells counted.
  const double s = 97 - 7.5e-10;
  // Sides through these node values, zero slopes at every node (C1, non-decreasing).
  auto side = [](const std::vector<double>& values) {
    BezierSide result;
    for (std::size_t k = 0; k + 1 < values.size(); ++k)
    {
      result.push_back({ { values[k], values[k], values[k + 1], values[k + 1] } });
    }
    return result;
  };
  MonotoneSurfaceBoundary b;
  b.Bottom = side({ 96, s, s, s, s });
  b.Right = side({ s, s, 96.9999999996, 96.9999999999, 97 });
  b.Left = side({ 96, 96.4, 96.9, 96.99, 96.9995 });
  b.Top = side({ 96.9995, 96.9998, 96.99999, 96.999999, 97 });
  MonotoneSibsonSurface surface;
  std::string error;
  const bool feasible = surface.Build(b, error);
  std::printf("  tied corner: %s; grid %d, flat diagonals %d, violating cells %d\n", error.c_str(), surface.GetGridSize(),
    surface.Report().FlatDiagonals, surface.Report().ViolatingCells);
  CHECK(!feasible);
  CHECK_EQ(surface.GetGridSize(), 4);
  CHECK_EQ(surface.Report().FlatDiagonals, 1);
  CHECK(MaximumBoundaryError(surface, b) <= 1e-9);
  // Bounded by the boundary's values (an oracle that needs no monotonicity: a Sibson patch is
  // a convex combination of its control values, which the construction keeps within them).
  double lowest = 1e300, highest = -1e300;
  for (int a = 0; a <= 200; ++a)
  {
    for (int c = 0; c <= 200; ++c)
    {
      const double value = surface.Evaluate(a / 200.0, c / 200.0);
      lowest = std::min(lowest, value);
      highest = std::max(highest, value);
    }
  }
  CHECK(std::isfinite(lowest) && std::isfinite(highest));
  CHECK(lowest >= 96 - 1e-6 && highest <= 97 + 1e-6);
  // A real fall (1e-6, far above rounding) is still refused.
  MonotoneSurfaceBoundary falling = b;
  falling.Right = side({ s, s - 1e-6, 96.9999999996, 96.9999999999, 97 });
  CHECK(!surface.Build(falling, error) && surface.GetGridSize() == 0);
}

TEST_CASE(SurfaceOfLinearDataIsLinear)
{
  // Boundary of F = x + y: the Laplace values and difference derivatives are exact, nothing
  // needs correcting, and the surface is x + y.
  for (const int n : { 1, 2, 3, 4, 5, 6, 66 }) // 66: a Laplace system factored for itself alone
  {
    MonotoneSurfaceBoundary b;
    const double h = 1.0 / n;
    for (int k = 0; k < n; ++k)
    {
      const double t0 = k * h;
      b.Bottom.push_back({ { t0, t0 + h / 3, t0 + 2 * h / 3, t0 + h } });
      b.Right.push_back({ { 1 + t0, 1 + t0 + h / 3, 1 + t0 + 2 * h / 3, 1 + t0 + h } });
      b.Top.push_back(b.Right.back());
      b.Left.push_back(b.Bottom.back());
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

TEST_CASE(SurfacesBuiltOnManyThreadsEqualOneThread)
{
  // The Laplace systems of grids up to 64 interior nodes a side are factored once per process
  // and shared by every thread that builds a surface; larger ones are factored per surface.
  // Surfaces of both kinds built on four threads at once (first uses of the shared
  // factorizations included) must equal the same surfaces built one after the other, bit for bit.
  Random random(42);
  std::vector<MonotoneSurfaceBoundary> boundaries;
  for (int trial = 0; trial < 48; ++trial)
  {
    const int n = trial % 8 == 7 ? 64 + trial % 3 : 1 + random.Integer(40);
    const auto flavour = static_cast<BoundaryFlavour>(random.Integer(static_cast<int>(BoundaryFlavour::Count)));
    boundaries.push_back(MakeBoundary(random, n, flavour));
  }
  const auto evaluations = [](const MonotoneSurfaceBoundary& b) {
    MonotoneSibsonSurface surface;
    std::string error;
    std::vector<double> values;
    if (!surface.Build(b, error))
    {
      return values;
    }
    for (int a = 0; a <= 20; ++a)
    {
      for (int c = 0; c <= 20; ++c)
      {
        values.push_back(surface.Evaluate(a / 20.0, c / 20.0));
      }
    }
    return values;
  };
  std::vector<std::vector<double>> threaded(boundaries.size());
  ThreadedFor(0, static_cast<Index>(boundaries.size()), [&](Index begin, Index end) {
    for (Index t = begin; t < end; ++t)
    {
      threaded[t] = evaluations(boundaries[t]);
    }
  });
  int built = 0;
  for (std::size_t t = 0; t < boundaries.size(); ++t)
  {
    const std::vector<double> sequential = evaluations(boundaries[t]);
    built += sequential.empty() ? 0 : 1;
    CHECK(sequential == threaded[t]);
  }
  std::printf("  %d of %zu surfaces built, the same on four threads and on one\n", built, boundaries.size());
  CHECK(built == static_cast<int>(boundaries.size()));
}

TEST_CASE(EachSafeguardAloneSuffices)
{
  // The guarantee does not rest on the per-cell limiter: without it the per-diagonal limiter
  // and the value correction carry the conditions, and without both limiters the minimal
  // derivatives (the recipe of docs/Algorithms.md, 1.4) with corrected values do.
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
      const int nodes[4][2] = { { k, 0 }, { n, k }, { k, n }, { 0, k } };
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
    CHECK(SubdivideSide(coarse.Right, common, even.Right));
    CHECK(SubdivideSide(coarse.Top, common, even.Top));
    CHECK(SubdivideSide(coarse.Left, common, even.Left));
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

TEST_CASE(ValuesIncreaseAlongDiagonalLines)
{
  // No interior critical point because D_(1,1)F > 0: the values alone (no gradient of the
  // implementation) must increase along every line of direction (1, 1); along the sides they
  // increase in u (bottom, top) and v (left, right) as the boundary curves do.
  Random random(21);
  double worstDiagonal = 0, worstSide = 0;
  for (int trial = 0; trial < 60; ++trial)
  {
    MonotoneSurfaceBoundary b;
    MonotoneSibsonSurface surface;
    const double range = BuildSeriesSurface(random, trial, b, surface);
    worstDiagonal = std::max(worstDiagonal, LargestDiagonalDecrease(surface, range));
    for (int a = 0; a < 500; ++a)
    {
      const double t0 = a / 500.0, t1 = (a + 1) / 500.0;
      worstSide = std::max({ worstSide, surface.Evaluate(t0, 0) - surface.Evaluate(t1, 0),
        surface.Evaluate(1, t0) - surface.Evaluate(1, t1), surface.Evaluate(t0, 1) - surface.Evaluate(t1, 1),
        surface.Evaluate(0, t0) - surface.Evaluate(0, t1) });
    }
  }
  std::printf("  largest decrease along (1,1) lines %.2e of the range, along the sides %.2e\n", worstDiagonal,
    worstSide);
  CHECK(worstDiagonal <= 1e-14);
  CHECK(worstSide <= 0);
}

TEST_CASE(BoundaryBeziersAreInterpolatedWithTheirDerivatives)
{
  // Along each side the surface is the side's Bezier curve: values (the Bernstein sum in the
  // test) and tangential derivatives, also at the grid nodes where two segments meet.
  Random random(22);
  double worstValue = 0, worstDerivative = 0;
  for (int trial = 0; trial < 60; ++trial)
  {
    MonotoneSurfaceBoundary b;
    MonotoneSibsonSurface surface;
    const double range = BuildSeriesSurface(random, trial, b, surface);
    const int n = surface.GetGridSize();
    for (int a = 0; a <= 24 * n; ++a)
    {
      const double t = a / (24.0 * n);
      const double points[4][2] = { { t, 0 }, { 1, t }, { t, 1 }, { 0, t } };
      const BezierSide* sides[4] = { &b.Bottom, &b.Right, &b.Top, &b.Left };
      for (int side = 0; side < 4; ++side)
      {
        double value, gradient[2];
        surface.EvaluateWithGradient(points[side][0], points[side][1], value, gradient);
        const double tangential = side % 2 == 0 ? gradient[0] : gradient[1];
        worstValue = std::max(worstValue, std::abs(value - SideValue(*sides[side], t)) / range);
        worstDerivative =
          std::max(worstDerivative, std::abs(tangential - SideDerivative(*sides[side], t)) / (n * range));
      }
    }
  }
  std::printf("  boundary value error %.2e, tangential derivative error %.2e (of the range)\n", worstValue,
    worstDerivative);
  CHECK(worstValue < 1e-13);
  CHECK(worstDerivative < 1e-13);
}

TEST_CASE(C1AcrossPatchEdgesByDifferenceQuotients)
{
  // One-sided difference quotients of the values across grid edges and half-diagonals agree to
  // O(delta): halving delta halves the jump, which a crease (value-continuous only) would not.
  Random random(23);
  double worst = 0, worstHalf = 0;
  for (int trial = 0; trial < 24; ++trial)
  {
    const int n = 2 + trial % 6;
    const MonotoneSurfaceBoundary b = MakeBoundary(random, n, BoundaryFlavour::Regular);
    MonotoneSibsonSurface surface;
    std::string error;
    CHECK(surface.Build(b, error));
    const double range = b.Top.back()[3] - b.Bottom.front()[0];
    const double delta = 1e-4 / n;
    worst = std::max(worst, LargestDerivativeJump(surface, delta, range));
    worstHalf = std::max(worstHalf, LargestDerivativeJump(surface, 0.5 * delta, range));
  }
  std::printf("  largest jump of the difference quotients %.2e (delta 1e-4 h), %.2e (half)\n", worst, worstHalf);
  CHECK(worst < 1e-2);
  CHECK(worstHalf < 0.6 * worst);
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
  for (auto* side : { &decreasing.Bottom, &decreasing.Right, &decreasing.Top, &decreasing.Left })
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
  steep.Right = { { { 0.1, 0.5, 0.9, 1.0 } } };
  steep.Top = { { { 0.9, 0.95, 0.98, 1.0 } } };
  steep.Left = { { { 0, 0.9, 0.9, 0.9 } } };
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
      double l0, l1, l2;
      RandomBarycentric(random, l0, l1, l2);
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
