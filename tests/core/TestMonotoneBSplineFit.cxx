// Tests of the strictly monotone height fits and planar curve fits of one 1-cell piece
// (MonotoneBSplineFit): strictly monotone L1 fits on seeded random synthetic data (checked on
// the cubic Bezier coefficients), end values interpolated exactly, C1 continuity, optimality
// against brute force on tiny cases, the unconstrained fit as a lower bound, the dual program
// against the primal one, degenerate and bad input, planar least-squares curves, thread
// safety, and timings.
//
// Usage: TestMonotoneBSplineFit
// Prints the fit errors and timings, then "N passed, N failed"; returns nonzero on failure.
#include "MonotoneBSplineFit.h"
#include "TestHarness.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

using namespace topospline;

namespace
{
const int SegmentCounts[] = { 2, 3, 4, 7, 12 };
const int SampleCounts[] = { 5, 10, 50, 200, 500 };

struct Samples
{
  std::vector<double> Parameters;
  std::vector<double> Values;
  double Start = 0;
  double End = 1;
};

// Non-uniform arc length parameters (random steps) and a field along them.
std::vector<double> RandomParameters(int n, std::mt19937& random)
{
  std::uniform_real_distribution<double> step(0.2, 1.8);
  std::vector<double> t(n + 1, 0.0);
  for (int i = 1; i <= n; ++i)
  {
    t[i] = t[i - 1] + step(random);
  }
  for (int i = 1; i < n; ++i)
  {
    t[i] /= t[n];
  }
  t[n] = 1.0;
  return t;
}

enum class Shape
{
  NoisyRamp,   // ramp plus sine noise plus random noise
  Decreasing,  // the data go the wrong way
  Constant,    // all samples equal
  Step,        // a jump in the middle
  Outliers,    // ramp with a few wild samples
  HugeOffset   // noisy ramp at 1e6 with a rise of 0.01: units must not matter
};
const Shape AllShapes[] = { Shape::NoisyRamp, Shape::Decreasing, Shape::Constant, Shape::Step, Shape::Outliers,
  Shape::HugeOffset };

Samples MakeSamples(Shape shape, int n, std::mt19937& random)
{
  Samples s;
  s.Parameters = RandomParameters(n, random);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double phase = 3.0 * unit(random);
  s.Start = -0.3;
  s.End = 1.7;
  for (int i = 0; i <= n; ++i)
  {
    const double t = s.Parameters[i];
    const double ramp = s.Start + (s.End - s.Start) * t;
    double f = 0;
    switch (shape)
    {
      case Shape::NoisyRamp:
        f = ramp + 0.35 * std::sin(9.0 * t + phase) + 0.05 * unit(random);
        break;
      case Shape::Decreasing:
        f = s.End - (s.End - s.Start) * t + 0.05 * unit(random);
        break;
      case Shape::Constant:
        f = 0.4;
        break;
      case Shape::Step:
        f = t < 0.5 ? s.Start + 0.1 : s.End - 0.1;
        break;
      case Shape::Outliers:
        f = ramp + ((i % 7 == 3) ? 5.0 * unit(random) : 0.02 * unit(random));
        break;
      case Shape::HugeOffset:
        f = 1e6 + 0.01 * (t + 0.35 * std::sin(9.0 * t + phase) + 0.05 * unit(random));
        break;
    }
    s.Values.push_back(f);
  }
  if (shape == Shape::HugeOffset)
  {
    s.Start = 1e6;
    s.End = 1e6 + 0.01;
  }
  return s;
}

// The checks every monotone height must pass, on its B-spline and its cubic Beziers.
void CheckMonotoneHeight(const HeightFit& fit, const Samples& s, int k, std::map<std::string, int>& failures)
{
  auto check = [&failures](bool ok, const char* what) {
    if (!ok)
    {
      ++failures[what];
    }
  };
  const UniformQuadraticBSpline& g = fit.Spline;
  const std::vector<double>& alpha = g.Coefficients;
  const double magnitude = std::max(std::abs(s.Start), std::abs(s.End));
  check(g.Segments == k && static_cast<int>(alpha.size()) == k + 2, "coefficient count");
  check(alpha[0] == s.Start && alpha[1] == s.Start, "alpha_0 = alpha_1 = a exactly");
  check(alpha[k] == s.End && alpha[k + 1] == s.End, "alpha_k = alpha_k+1 = b exactly");
  for (int j = 1; j < k; ++j)
  {
    check(alpha[j + 1] > alpha[j], "alpha strictly increasing on 1..k");
    // delta is met in normalized values; going back to field units rounds at |b|.
    check(alpha[j + 1] - alpha[j] >= fit.MinimumStep - 1e-15 * magnitude, "steps >= delta");
  }
  check(g.Value(0.0) == s.Start && g.Value(1.0) == s.End, "g(0) = a and g(1) = b exactly");

  const CubicBezierSpline cubic = g.ToCubicBezier();
  check(cubic.Segments == k && cubic.ControlPoints.size() == static_cast<std::size_t>(4 * k), "cubic layout");
  const double scale = s.End - s.Start;
  for (int j = 0; j < k; ++j)
  {
    const double* c = cubic.Segment(j);
    for (int m = 0; m < 3; ++m)
    {
      const double rise = c[m + 1] - c[m];
      const bool end = (j == 0 && m == 0) || (j == k - 1 && m == 2);
      if (end)
      {
        check(rise == 0.0, "zero end derivative: 3 (c1 - c0) = 0 first, 3 (c3 - c2) = 0 last");
      }
      else
      {
        check(rise > 0.0, "cubic Bezier coefficients strictly increasing");
      }
    }
    if (j + 1 < k)
    {
      const double* next = cubic.Segment(j + 1);
      check(c[3] == next[0], "C0 between segments (exact)");
      check(std::abs(3 * (c[3] - c[2]) - 3 * (next[1] - next[0])) <= 1e-12 * scale + 1e-14 * magnitude,
        "C1 between segments");
    }
  }
  check(cubic.Segment(0)[0] == s.Start && cubic.Segment(k - 1)[3] == s.End, "cubic end values exact");
  check(g.Slope(0.0) == 0.0 && g.Slope(1.0) == 0.0, "g'(0) = g'(1) = 0");
  for (int i = 1; i < 2000; ++i)
  {
    const double t = i / 2000.0;
    check(g.Slope(t) > 0.0, "g' > 0 inside (0, 1) (B-spline)");
    check(cubic.Slope(t) > 0.0, "g' > 0 inside (0, 1) (cubic Beziers)");
  }
}

double L1ErrorBruteForceK3(const Samples& s, double lower, double upper)
{
  // k = 3: one free coefficient alpha_2, the objective is convex piecewise linear in it, so
  // its minimum over [lower, upper] is at a breakpoint or a bound.
  const int k = 3;
  std::vector<double> residualBase;
  std::vector<double> weight;
  for (std::size_t i = 1; i + 1 < s.Parameters.size(); ++i)
  {
    int first = 0;
    double w[3];
    UniformQuadraticBSpline::BasisWeights(k, s.Parameters[i], first, w);
    const double alpha[5] = { s.Start, s.Start, 0.0, s.End, s.End };
    double fixed = 0;
    double free = 0;
    for (int m = 0; m < 3; ++m)
    {
      if (first + m == 2)
      {
        free = w[m];
      }
      else
      {
        fixed += w[m] * alpha[first + m];
      }
    }
    residualBase.push_back(s.Values[i] - fixed);
    weight.push_back(free);
  }
  auto objective = [&](double x) {
    double e = 0;
    for (std::size_t i = 0; i < weight.size(); ++i)
    {
      e += std::abs(residualBase[i] - weight[i] * x);
    }
    return e;
  };
  std::vector<double> candidates;
  if (std::isfinite(lower))
  {
    candidates.push_back(lower);
  }
  if (std::isfinite(upper))
  {
    candidates.push_back(upper);
  }
  for (std::size_t i = 0; i < weight.size(); ++i)
  {
    if (weight[i] != 0)
    {
      candidates.push_back(std::min(std::max(residualBase[i] / weight[i], lower), upper));
    }
  }
  double best = std::numeric_limits<double>::infinity();
  for (double x : candidates)
  {
    best = std::min(best, objective(x));
  }
  if (candidates.empty())
  {
    best = objective(0.0);
  }
  return best;
}
} // namespace

//------------------------------------------------------------------------------
TEST_CASE(MonotoneFitsOnSyntheticData)
{
  std::mt19937 random(2015);
  std::map<std::string, int> failures;
  // Per (n, k) on the noisy ramp: mean absolute error of the monotone and unconstrained fits.
  std::map<std::pair<int, int>, std::array<double, 3>> table;
  int fits = 0;
  int lowerBoundViolations = 0;
  int throughDual = 0;
  int dualMismatches = 0;
  double worstGap = 0;
  for (Shape shape : AllShapes)
  {
    for (int n : SampleCounts)
    {
      for (int k : SegmentCounts)
      {
        for (int trial = 0; trial < 3; ++trial)
        {
          const Samples s = MakeSamples(shape, n, random);
          MonotoneBSplineFit fitter;
          fitter.Segments = k;
          HeightFit monotone, free;
          std::string error;
          const bool ok = fitter.FitHeight(s.Parameters, s.Values, s.Start, s.End, true, monotone, error);
          CHECK(ok);
          if (!ok)
          {
            std::printf("  fit failed (n=%d k=%d): %s\n", n, k, error.c_str());
            continue;
          }
          CHECK(fitter.FitHeight(s.Parameters, s.Values, s.Start, s.End, false, free, error));
          ++fits;
          throughDual += monotone.SolvedThroughDual;
          throughDual += free.SolvedThroughDual;
          {
            // The dual program with its recovered coefficients and the primal program reach
            // the same optimum (up to the tie-break and GLPK's tolerances).
            MonotoneBSplineFit primal = fitter;
            primal.UseDualProgram = false;
            HeightFit monotonePrimal, freePrimal;
            CHECK(primal.FitHeight(s.Parameters, s.Values, s.Start, s.End, true, monotonePrimal, error));
            CHECK(primal.FitHeight(s.Parameters, s.Values, s.Start, s.End, false, freePrimal, error));
            CHECK(!monotonePrimal.SolvedThroughDual && !freePrimal.SolvedThroughDual);
            const double same = 2 * fitter.TieBreakWeight * (s.End - s.Start) + 1e-7 * (s.End - s.Start) * n +
              1e-14 * n * std::abs(s.End);
            const double gap = std::max(
              std::abs(monotone.L1Error - monotonePrimal.L1Error), std::abs(free.L1Error - freePrimal.L1Error));
            worstGap = std::max(worstGap, gap / (s.End - s.Start));
            if (!(gap <= same))
            {
              ++dualMismatches;
              std::printf("  dual/primal differ: shape %d n=%d k=%d: %.12g/%.12g and %.12g/%.12g\n",
                static_cast<int>(shape), n, k, monotone.L1Error, monotonePrimal.L1Error, free.L1Error,
                freePrimal.L1Error);
            }
          }
          CheckMonotoneHeight(monotone, s, k, failures);
          // The unconstrained optimum is a lower bound; GLPK's tolerances allow a little slack.
          const double range = s.End - s.Start;
          const double slack = 1e-7 * range * n;
          if (!(monotone.L1Error >= free.L1Error - slack))
          {
            ++lowerBoundViolations;
            std::printf(
              "  monotone error %.9g < unconstrained %.9g (n=%d k=%d)\n", monotone.L1Error, free.L1Error, n, k);
          }
          // The unconstrained fit keeps the end conditions too.
          CHECK(free.Spline.Coefficients[0] == s.Start && free.Spline.Coefficients[1] == s.Start);
          CHECK(free.Spline.Coefficients[k] == s.End && free.Spline.Coefficients[k + 1] == s.End);
          if (k == 3)
          {
            const double lower = s.Start + monotone.MinimumStep;
            const double upper = s.End - monotone.MinimumStep;
            const double best = L1ErrorBruteForceK3(s, lower, upper);
            const double bestFree = L1ErrorBruteForceK3(
              s, -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
            const double tolerance = 2 * fitter.TieBreakWeight * range + 1e-7 * range * n;
            // (The brute force evaluates in field units: at 1e6 it rounds at 1e-10 per sample.)
            const double rounding = 1e-9 * range * n + 1e-15 * n * std::abs(s.End);
            const bool monotoneOptimal =
              monotone.L1Error <= best + tolerance + rounding && monotone.L1Error >= best - rounding;
            const bool freeOptimal = std::abs(free.L1Error - bestFree) <= 1e-7 * range * n + rounding;
            CHECK(monotoneOptimal);
            CHECK(freeOptimal);
            if (!monotoneOptimal || !freeOptimal)
            {
              std::printf("  k=3 brute force: shape %d n=%d monotone %.12g vs %.12g, free %.12g vs %.12g\n",
                static_cast<int>(shape), n, monotone.L1Error, best, free.L1Error, bestFree);
            }
          }
          if (shape == Shape::NoisyRamp)
          {
            auto& row = table[{ n, k }];
            row[0] += monotone.L1Error / (n - 1);
            row[1] += free.L1Error / (n - 1);
            row[2] += 1;
          }
        }
      }
    }
  }
  CHECK(lowerBoundViolations == 0);
  CHECK(dualMismatches == 0);
  std::printf("  %d of %d fits solved through the dual program (the others: primal); max |dual - primal| L1 error "
              "%.2e (b - a)\n", throughDual, 2 * fits, worstGap);
  for (const auto& f : failures)
  {
    std::printf("  FAILED %dx: %s\n", f.second, f.first.c_str());
    CHECK(f.first.empty());
  }
  std::printf("  %d monotone + %d unconstrained fits on 6 data shapes\n", fits, fits);
  std::printf("  noisy ramp (rise 2, sine noise 0.35): mean |f - g| per interior sample, monotone / unconstrained\n");
  for (int n : SampleCounts)
  {
    std::printf("    n=%3d:", n);
    for (int k : SegmentCounts)
    {
      const auto& row = table[{ n, k }];
      std::printf("  k=%-2d %.4f/%.4f", k, row[0] / row[2], row[1] / row[2]);
    }
    std::printf("\n");
  }
}

//------------------------------------------------------------------------------
// Parameters that follow the rise: 0 and 1 at the ends, non-decreasing, each step between
// half and (1 + the ratio) times its share of the arc length (so no long gap without
// samples), on seeded random paths and values; arc length when the values do not rise. A
// profile that rises steeply and then flattens is fitted closer with them.
TEST_CASE(ArcLengthAndRiseParameters)
{
  std::mt19937 random(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int badSteps = 0, badEnds = 0;
  for (int trial = 0; trial < 200; ++trial)
  {
    const int n = 3 + static_cast<int>(unit(random) * 300);
    std::vector<double> points(2 * n), values(n);
    double x = 0, y = 0;
    for (int i = 0; i < n; ++i)
    {
      x += 0.1 + unit(random);
      y += unit(random) - 0.5;
      points[2 * i] = x;
      points[2 * i + 1] = y;
      // noisy rise, sometimes past the end value, sometimes below the start
      values[i] = std::pow(static_cast<double>(i) / (n - 1), 1 + 6 * unit(random)) + 0.3 * (unit(random) - 0.5);
    }
    const double start = values.front(), end = values.back();
    const std::vector<double> arc = MonotoneBSplineFit::NormalizedArcLength(points);
    const double ratio = 1 + 9 * unit(random);
    const std::vector<double> t = MonotoneBSplineFit::ArcLengthAndRise(points, values, start, end, ratio);
    badEnds += t.front() != 0.0 || t.back() != 1.0 || t.size() != arc.size();
    for (int i = 1; i < n; ++i)
    {
      const double share = arc[i] - arc[i - 1];
      const double step = t[i] - t[i - 1];
      badSteps += !(step >= 0.5 * share * (1 - 1e-9) &&
        step <= (1 + ratio) * share * (1 + 1e-9) + 1e-15);
    }
    if (!(end > start))
    {
      badEnds += t != arc;
    }
  }
  CHECK(badSteps == 0);
  CHECK(badEnds == 0);
  // Falling values: arc length.
  const std::vector<double> line = { 0, 0, 1, 0, 3, 0, 4, 0 };
  CHECK((MonotoneBSplineFit::ArcLengthAndRise(line, { 1, 0.5, 0.2, 0 }, 1, 0, 3) ==
    MonotoneBSplineFit::NormalizedArcLength(line)));

  // Steep, then flat: v = 1 - (1 - s)^12 along a straight path of 200 samples, k = 4.
  const int n = 200;
  std::vector<double> points(2 * n), values(n);
  for (int i = 0; i < n; ++i)
  {
    const double s = static_cast<double>(i) / (n - 1);
    points[2 * i] = s;
    values[i] = 1 - std::pow(1 - s, 12);
  }
  MonotoneBSplineFit fitter;
  fitter.Segments = 4;
  const auto largestMiss = [&](const std::vector<double>& t) {
    HeightFit fit;
    std::string error;
    CHECK(fitter.FitHeight(t, values, 0.0, 1.0, true, fit, error));
    double miss = 0;
    for (int i = 0; i < n; ++i)
    {
      miss = std::max(miss, std::abs(fit.Spline.Value(t[i]) - values[i]));
    }
    return miss;
  };
  const double even = largestMiss(MonotoneBSplineFit::NormalizedArcLength(points));
  const double risen = largestMiss(MonotoneBSplineFit::ArcLengthAndRise(points, values, 0.0, 1.0, 3));
  std::printf("  steep-then-flat profile, k = 4: largest miss %.4f (arc length), %.4f (arc length and rise)\n",
    even, risen);
  CHECK(risen < 0.75 * even);
}

TEST_CASE(DegenerateHeightFits)
{
  MonotoneBSplineFit fitter;
  HeightFit fit;
  std::string error;
  std::map<std::string, int> failures;

  // k = 2: fully determined, no program.
  {
    std::mt19937 random(3);
    Samples s = MakeSamples(Shape::NoisyRamp, 20, random);
    fitter.Segments = 2;
    CHECK(fitter.FitHeight(s.Parameters, s.Values, s.Start, s.End, true, fit, error));
    CHECK(fit.ProgramVariables == 0);
    CHECK((fit.Spline.Coefficients == std::vector<double>{ s.Start, s.Start, s.End, s.End }));
    CheckMonotoneHeight(fit, s, 2, failures);
  }
  // No interior samples: evenly spaced coefficients.
  for (int k : SegmentCounts)
  {
    Samples s;
    s.Parameters = { 0.0, 1.0 };
    s.Values = { 5.0, -5.0 };
    s.Start = 2.0;
    s.End = 3.0;
    fitter.Segments = k;
    CHECK(fitter.FitHeight(s.Parameters, s.Values, s.Start, s.End, true, fit, error));
    CHECK(fit.L1Error == 0.0);
    CheckMonotoneHeight(fit, s, k, failures);
    for (int j = 1; j <= k; ++j)
    {
      CHECK(std::abs(fit.Spline.Coefficients[j] - (2.0 + (j - 1.0) / (k - 1))) <= 1e-15);
    }
    CHECK(fitter.FitHeight(s.Parameters, s.Values, s.Start, s.End, false, fit, error));
  }
  // All samples equal, equal to a, or sitting at the ends of the parameter range; few
  // samples with many segments (coefficients without data: the tie-break spaces them).
  for (int k : SegmentCounts)
  {
    fitter.Segments = k;
    for (double level : { 0.5, 0.0, 1.0, -7.0, 9.0 })
    {
      Samples s;
      s.Parameters = { 0.0, 0.1, 0.2, 0.5, 0.7, 1.0 };
      s.Values.assign(6, level);
      s.Start = 0.0;
      s.End = 1.0;
      CHECK(fitter.FitHeight(s.Parameters, s.Values, s.Start, s.End, true, fit, error));
      CheckMonotoneHeight(fit, s, k, failures);
    }
    Samples ends;
    ends.Parameters = { 0.0, 0.0, 0.0, 1.0, 1.0 };
    ends.Values = { 0.0, 3.0, -3.0, 4.0, 1.0 };
    CHECK(fitter.FitHeight(ends.Parameters, ends.Values, 0.0, 1.0, true, fit, error));
    CheckMonotoneHeight(fit, ends, k, failures);
    CHECK(std::abs(fit.L1Error - 9.0) <= 1e-12);

    Samples sparse;
    sparse.Parameters = { 0.0, 0.95, 1.0 };
    sparse.Values = { 0.0, 0.99, 1.0 };
    CHECK(fitter.FitHeight(sparse.Parameters, sparse.Values, 0.0, 1.0, true, fit, error));
    CheckMonotoneHeight(fit, sparse, k, failures);
    if (k >= 7)
    {
      // Only the last segments see the sample; the first steps are spread evenly, not
      // squeezed to delta.
      const double step = fit.Spline.Coefficients[2] - fit.Spline.Coefficients[1];
      CHECK(step > 10 * fit.MinimumStep);
    }
  }
  for (const auto& f : failures)
  {
    std::printf("  FAILED %dx: %s\n", f.second, f.first.c_str());
    CHECK(f.first.empty());
  }
}

//------------------------------------------------------------------------------
TEST_CASE(BadHeightInput)
{
  MonotoneBSplineFit fitter;
  HeightFit fit;
  std::string error;
  const std::vector<double> t = { 0.0, 0.5, 1.0 };
  const std::vector<double> f = { 0.0, 0.5, 1.0 };
  for (int k : { -1, 0, 1, 1001 })
  {
    fitter.Segments = k;
    error.clear();
    CHECK(!fitter.FitHeight(t, f, 0.0, 1.0, true, fit, error) && !error.empty());
  }
  fitter.Segments = 4;
  CHECK(!fitter.FitHeight(t, f, 1.0, 1.0, true, fit, error));
  CHECK(!fitter.FitHeight(t, f, 1.0, 0.0, true, fit, error));
  CHECK(!fitter.FitHeight(t, f, 0.0, std::nan(""), true, fit, error));
  CHECK(!fitter.FitHeight({ 0.0, 0.7, 0.5, 1.0 }, { 0, 0, 0, 0 }, 0.0, 1.0, true, fit, error));
  CHECK(!fitter.FitHeight({ 0.0, 1.5 }, { 0, 0 }, 0.0, 1.0, true, fit, error));
  CHECK(!fitter.FitHeight({ 0.0 }, { 0 }, 0.0, 1.0, true, fit, error));
  CHECK(!fitter.FitHeight(t, { 0.0, 1.0 }, 0.0, 1.0, true, fit, error));
  CHECK(!fitter.FitHeight(t, { 0.0, std::nan(""), 1.0 }, 0.0, 1.0, true, fit, error));
  // End values closer than double precision can separate into k steps.
  CHECK(!fitter.FitHeight(t, f, 1.0, std::nextafter(1.0, 2.0), true, fit, error));
  std::printf("  e.g. \"%s\"\n", error.c_str());
  CHECK(fitter.FitHeight(t, f, 1.0, 1.0 + 1e-9, true, fit, error));
  fitter.MinimumSlopeFraction = 2.0;
  CHECK(!fitter.FitHeight(t, f, 0.0, 1.0, true, fit, error));
}

//------------------------------------------------------------------------------
TEST_CASE(RepeatableAndThreadSafe)
{
  // CGAL's interface keys the rows by pointers in unordered maps, so the order in which GLPK
  // gets each row's entries may change from run to run; check the results do not.
  std::mt19937 random(99);
  std::vector<Samples> inputs;
  for (int i = 0; i < 64; ++i)
  {
    inputs.push_back(MakeSamples(i % 2 ? Shape::NoisyRamp : Shape::Outliers, 200, random));
  }
  MonotoneBSplineFit fitter;
  fitter.Segments = 7;
  std::vector<std::vector<double>> serial(inputs.size());
  std::string error;
  for (std::size_t i = 0; i < inputs.size(); ++i)
  {
    HeightFit fit;
    CHECK(fitter.FitHeight(inputs[i].Parameters, inputs[i].Values, inputs[i].Start, inputs[i].End, true, fit, error));
    serial[i] = fit.Spline.Coefficients;
  }
  double worst = 0;
  for (int repeat = 0; repeat < 2; ++repeat)
  {
    std::vector<std::vector<double>> parallel(inputs.size());
    std::vector<std::thread> threads;
    for (int w = 0; w < 4; ++w)
    {
      threads.emplace_back([&, w]() {
        for (std::size_t i = w; i < inputs.size(); i += 4)
        {
          HeightFit fit;
          std::string threadError;
          if (fitter.FitHeight(
                inputs[i].Parameters, inputs[i].Values, inputs[i].Start, inputs[i].End, true, fit, threadError))
          {
            parallel[i] = fit.Spline.Coefficients;
          }
        }
      });
    }
    for (auto& thread : threads)
    {
      thread.join();
    }
    for (std::size_t i = 0; i < inputs.size(); ++i)
    {
      CHECK(parallel[i].size() == serial[i].size());
      for (std::size_t j = 0; j < parallel[i].size() && j < serial[i].size(); ++j)
      {
        worst = std::max(worst, std::abs(parallel[i][j] - serial[i][j]));
      }
    }
  }
  std::printf("  4 threads x 64 fits, twice: max coefficient difference to the serial run %.2e\n", worst);
  CHECK(worst <= 1e-9);
}

//------------------------------------------------------------------------------
TEST_CASE(PlanarCurves)
{
  MonotoneBSplineFit fitter;
  PlanarCurveFit fit;
  std::string error;
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k : SegmentCounts)
  {
    fitter.Segments = k;
    // A straight polyline with uneven vertices: reproduced exactly (linear precision).
    {
      std::vector<double> points;
      double x = 0;
      for (int i = 0; i <= 30; ++i)
      {
        points.push_back(1000.0 + 3.0 * x);
        points.push_back(-50.0 + 2.0 * x);
        x += 0.5 + 0.5 * std::abs(unit(random));
      }
      const std::vector<double> t = MonotoneBSplineFit::NormalizedArcLength(points);
      CHECK(t.front() == 0.0 && t.back() == 1.0);
      CHECK(fitter.FitPlanarCurve(t, points, fit, error));
      CHECK(fit.MaximumError <= 1e-9);
    }
    // A noisy circular arc, n from 5 to 500; a polyline shorter than the coefficient count;
    // a polyline of two points; a polyline whose points all coincide.
    for (int n : SampleCounts)
    {
      std::vector<double> points;
      for (int i = 0; i <= n; ++i)
      {
        const double angle = 2.0 * i / n;
        const double noise = (i == 0 || i == n) ? 0.0 : 0.01 * unit(random);
        points.push_back(std::cos(angle) + noise);
        points.push_back(std::sin(angle) + noise);
      }
      const std::vector<double> t = MonotoneBSplineFit::NormalizedArcLength(points);
      CHECK(fitter.FitPlanarCurve(t, points, fit, error));
      const std::vector<double>& c = fit.Spline.Coefficients;
      CHECK(c[0] == points[0] && c[1] == points[1]);
      CHECK(c[2 * k + 2] == points[2 * n] && c[2 * k + 3] == points[2 * n + 1]);
      if (n >= 3 * k)
      {
        CHECK(fit.MaximumError <= 0.05);
      }
      CHECK(std::isfinite(fit.RootMeanSquareError));
      const CubicBezierSpline cubic = fit.Spline.ToCubicBezier();
      for (int j = 0; j + 1 < k; ++j)
      {
        const double* a = cubic.Segment(j);
        const double* b = cubic.Segment(j + 1);
        for (int d = 0; d < 2; ++d)
        {
          CHECK(a[6 + d] == b[d]);
          CHECK(std::abs((a[6 + d] - a[4 + d]) - (b[2 + d] - b[d])) <= 1e-12);
        }
      }
      double p[2];
      cubic.Evaluate(0.0, p);
      CHECK(p[0] == points[0] && p[1] == points[1]);
      cubic.Evaluate(1.0, p);
      CHECK(p[0] == points[2 * n] && p[1] == points[2 * n + 1]);
    }
    const std::vector<double> two = { 1.0, 2.0, 4.0, 6.0 };
    CHECK(fitter.FitPlanarCurve(MonotoneBSplineFit::NormalizedArcLength(two), two, fit, error));
    CHECK(fit.MaximumError <= 1e-12);
    double mid[2];
    fit.Spline.Evaluate(0.5, mid);
    CHECK(std::abs(mid[0] - 2.5) <= 1e-9 && std::abs(mid[1] - 4.0) <= 1e-9);
    const std::vector<double> same = { 1.0, 1.0, 1.0, 1.0, 1.0, 1.0 };
    const std::vector<double> t = MonotoneBSplineFit::NormalizedArcLength(same);
    CHECK((t == std::vector<double>{ 0.0, 0.5, 1.0 }));
    CHECK(fitter.FitPlanarCurve(t, same, fit, error));
    CHECK(fit.MaximumError == 0.0);
  }
  fitter.Segments = 1;
  CHECK(!fitter.FitPlanarCurve({ 0.0, 1.0 }, { 0, 0, 1, 1 }, fit, error));
  fitter.Segments = 4;
  CHECK(!fitter.FitPlanarCurve({ 0.0, 1.0 }, { 0, 0, 1 }, fit, error));
}

//------------------------------------------------------------------------------
TEST_CASE(Timings)
{
  std::mt19937 random(1);
  std::vector<Samples> inputs;
  for (int i = 0; i < 1000; ++i)
  {
    inputs.push_back(MakeSamples(Shape::NoisyRamp, 200, random));
  }
  MonotoneBSplineFit fitter;
  fitter.Segments = 7;
  std::string error;
  HeightFit fit;
  PlanarCurveFit curve;
  int failures = 0;
  auto time = [](auto&& body) {
    const auto start = std::chrono::steady_clock::now();
    body();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const double monotone = time([&]() {
    for (const Samples& s : inputs)
    {
      failures += !fitter.FitHeight(s.Parameters, s.Values, s.Start, s.End, true, fit, error);
    }
  });
  const double programSize[2] = { static_cast<double>(fit.ProgramVariables),
    static_cast<double>(fit.ProgramConstraints) };
  MonotoneBSplineFit primalOnly = fitter;
  primalOnly.UseDualProgram = false;
  const double primal = time([&]() {
    for (std::size_t i = 0; i < 100; ++i)
    {
      const Samples& s = inputs[i];
      failures += !primalOnly.FitHeight(s.Parameters, s.Values, s.Start, s.End, true, fit, error);
    }
  });
  const double unconstrained = time([&]() {
    for (const Samples& s : inputs)
    {
      failures += !fitter.FitHeight(s.Parameters, s.Values, s.Start, s.End, false, fit, error);
    }
  });
  std::vector<double> points;
  for (int i = 0; i <= 200; ++i)
  {
    points.push_back(std::cos(i / 100.0));
    points.push_back(std::sin(i / 100.0));
  }
  const std::vector<double> t = MonotoneBSplineFit::NormalizedArcLength(points);
  const double planar = time([&]() {
    for (int i = 0; i < 1000; ++i)
    {
      failures += !fitter.FitPlanarCurve(t, points, curve, error);
    }
  });
  const double conversion = time([&]() {
    double sum = 0;
    for (int i = 0; i < 1000; ++i)
    {
      sum += fit.Spline.ToCubicBezier().ControlPoints[1];
      sum += curve.Spline.ToCubicBezier().ControlPoints[1];
    }
    failures += !std::isfinite(sum);
  });
  CHECK(failures == 0);
  std::printf("  1000 monotone height fits, n=200, k=7 (%g variables, %g rows): %.3f s (%.2f ms each)\n",
    programSize[0], programSize[1], monotone, monotone);
  std::printf("  100 monotone height fits through the primal program only (UseDualProgram off): %.3f s "
              "(%.2f ms each)\n",
    primal, 10 * primal);
  std::printf("  1000 unconstrained height fits, n=200, k=7: %.3f s\n", unconstrained);
  std::printf("  1000 planar curve fits, n=200, k=7: %.3f s\n", planar);
  std::printf("  1000 x 2 conversions to cubic Beziers, k=7: %.4f s\n", conversion);
}

int main()
{
  return testing_harness::RunAll();
}
