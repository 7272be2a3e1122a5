// Unit tests of the data-fitted interior of the monotone surface (MonotoneSibsonSurface::
// FitToSamples). Oracles that only evaluate the surface: values strictly increasing along
// every (1,1) line on a dense lattice (no interior critical point), the boundary curves
// unchanged by the fit, and the residuals recomputed here against the sampled function.
#include "DeterministicRandom.h"
#include "MonotoneSibsonSurface.h"
#include "TestHarness.h"

#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

using namespace topospline;

namespace
{
using Function = std::function<void(double u, double v, double& f, double& fu, double& fv)>;

// 3t^2 - 2t^3: zero slope at both ends, as stage 3 gives at critical points.
double Step(double t)
{
  return t * t * (3 - 2 * t);
}
double StepSlope(double t)
{
  return 6 * t * (1 - t);
}

// The field g(u) + g(v) + a g(u) g(v): minimum (0,0), maximum (1,1), flat saddles at (1,0) and
// (0,1), strictly increasing along (1,1) inside; a shapes the cap.
Function Cap(double a)
{
  return [a](double u, double v, double& f, double& fu, double& fv) {
    f = Step(u) + Step(v) + a * Step(u) * Step(v);
    fu = StepSlope(u) * (1 + a * Step(v));
    fv = StepSlope(v) * (1 + a * Step(u));
  };
}

// The side from (u0, v0) in direction (du, dv) as n Hermite cubics of f (exact values and
// tangential derivatives at the nodes), which is what stage 3's Beziers are.
BezierSide HermiteSide(const Function& f, double u0, double v0, double du, double dv, int n)
{
  BezierSide side;
  auto at = [&](double t, double& value, double& slope) {
    double fu, fv;
    f(u0 + t * du, v0 + t * dv, value, fu, fv);
    slope = (fu * du + fv * dv) / n; // d/dt in the segment's own parameter
  };
  for (int k = 0; k < n; ++k)
  {
    double a, sa, b, sb;
    at(static_cast<double>(k) / n, a, sa);
    at(static_cast<double>(k + 1) / n, b, sb);
    side.push_back({ { a, a + sa / 3, b - sb / 3, b } });
  }
  return side;
}

MonotoneSurfaceBoundary BoundaryOf(const Function& f, int n)
{
  MonotoneSurfaceBoundary boundary;
  boundary.Bottom = HermiteSide(f, 0, 0, 1, 0, n);
  boundary.Right = HermiteSide(f, 1, 0, 0, 1, n);
  boundary.Top = HermiteSide(f, 0, 1, 1, 0, n);
  boundary.Left = HermiteSide(f, 0, 0, 0, 1, n);
  return boundary;
}

std::vector<SurfaceSample> Samples(const std::function<double(double, double)>& data, int count, std::uint64_t seed)
{
  DeterministicRandom random(seed);
  std::vector<SurfaceSample> samples;
  for (int i = 0; i < count; ++i)
  {
    const double u = random.Uniform(), v = random.Uniform();
    samples.push_back({ u, v, data(u, v) });
  }
  return samples;
}

// Smallest F(u + e, v + e) - F(u, v) over a lattice strictly inside the square.
double SmallestDiagonalIncrease(const MonotoneSibsonSurface& surface, int lattice)
{
  const double e = 0.25 / lattice;
  double smallest = 1e300;
  for (int j = 1; j < lattice; ++j)
  {
    for (int i = 1; i < lattice; ++i)
    {
      const double u = static_cast<double>(i) / lattice, v = static_cast<double>(j) / lattice;
      if (u + e < 1 && v + e < 1)
      {
        smallest = std::min(smallest, surface.Evaluate(u + e, v + e) - surface.Evaluate(u, v));
      }
    }
  }
  return smallest;
}

double LargestBoundaryChange(const MonotoneSibsonSurface& surface, const std::vector<double>& before)
{
  double largest = 0;
  int k = 0;
  for (int s = 0; s <= 400; ++s)
  {
    const double t = s / 400.0;
    for (const auto& uv : { std::array<double, 2>{ t, 0 }, { 1, t }, { t, 1 }, { 0, t } })
    {
      largest = std::max(largest, std::abs(surface.Evaluate(uv[0], uv[1]) - before[k++]));
    }
  }
  return largest;
}

std::vector<double> BoundaryValues(const MonotoneSibsonSurface& surface)
{
  std::vector<double> values;
  for (int s = 0; s <= 400; ++s)
  {
    const double t = s / 400.0;
    for (const auto& uv : { std::array<double, 2>{ t, 0 }, { 1, t }, { t, 1 }, { 0, t } })
    {
      values.push_back(surface.Evaluate(uv[0], uv[1]));
    }
  }
  return values;
}

void Residuals(const MonotoneSibsonSurface& surface, const std::vector<SurfaceSample>& samples, double& maximum,
  double& rms)
{
  maximum = rms = 0;
  for (const auto& s : samples)
  {
    const double r = surface.Evaluate(s.U, s.V) - s.Value;
    maximum = std::max(maximum, std::abs(r));
    rms += r * r;
  }
  rms = std::sqrt(rms / samples.size());
}

// Builds the paper's surface on f's boundary, fits it to `count` samples of f plus `bumps`
// sin(6 pi u) sin(6 pi v), and checks what any fit must give: no worse than the paper's
// interior, no violated condition, strictly increasing along (1,1), the boundary untouched.
// Returns the residuals (max, rms) before and after.
std::array<double, 4> FitAndCheck(const Function& f, double bumps, int n, int count, std::uint64_t seed)
{
  MonotoneSibsonSurface surface;
  std::string error;
  CHECK(surface.Build(BoundaryOf(f, n), error));
  const auto samples = Samples(
    [&](double u, double v) {
      double value, fu, fv;
      f(u, v, value, fu, fv);
      return value + bumps * std::sin(6 * M_PI * u) * std::sin(6 * M_PI * v);
    },
    count, seed);
  const std::vector<double> boundary = BoundaryValues(surface);
  std::array<double, 4> residuals;
  Residuals(surface, samples, residuals[0], residuals[1]);
  CHECK(surface.FitToSamples(samples, error));
  Residuals(surface, samples, residuals[2], residuals[3]);
  CHECK(surface.FitReport().Fitted);
  CHECK(std::abs(surface.FitReport().MaximumResidual - residuals[2]) < 1e-12);
  CHECK(residuals[3] <= residuals[1]);
  CHECK(surface.CountViolatingCells() == 0);
  CHECK(SmallestDiagonalIncrease(surface, 300) > 0);
  double top, fu, fv;
  f(1, 1, top, fu, fv);
  CHECK(LargestBoundaryChange(surface, boundary) < 1e-12 * top);
  return residuals;
}
} // namespace

TEST_CASE(SmoothCapIsFittedFarCloserThanThePaperInterior)
{
  for (double a : { 0.0, 1.0, 3.0 })
  {
    for (int n : { 4, 8 })
    {
      const double range = 2 + a;
      const auto r = FitAndCheck(Cap(a), 0.0, n, 3000, 17 + n);
      std::printf("  cap a = %.0f, N = %d: paper %.4f / %.4f, fitted %.4f / %.4f (max / rms, of the range)\n", a, n,
        r[0] / range, r[1] / range, r[2] / range, r[3] / range);
      CHECK(r[2] < 0.01 * range);
    }
  }
}

TEST_CASE(NonMonotoneDataStaysMonotoneAndCloserThanThePaper)
{
  // Bumps of 10 % of the range that no monotone surface can follow: the fit must refuse them.
  for (int n : { 4, 8, 16 })
  {
    const auto r = FitAndCheck(Cap(1.0), 0.3, n, 4000, 99 + n);
    std::printf("  bumps, N = %d: rms paper %.4f, fitted %.4f\n", n, r[1], r[3]);
  }
}

TEST_CASE(SampleOrdersAreMetWhereTheFitFalls)
{
  // Data with bumps no monotone surface follows: the plain fit falls along u or v in places.
  // Orders between nearby samples, the upper one ahead in both u and v (a surface increasing
  // along u and v meets them), each where the plain fit has it lower: the refit meets them
  // with most of their margin, and keeps every guarantee of a fit.
  const Function cap = Cap(1.0);
  const int n = 8;
  const auto data = [&](double u, double v) {
    double value, fu, fv;
    cap(u, v, value, fu, fv);
    return value + 0.3 * std::sin(6 * M_PI * u) * std::sin(6 * M_PI * v);
  };
  const auto samples = Samples(data, 4000, 5);
  MonotoneSibsonSurface plain;
  std::string error;
  CHECK(plain.Build(BoundaryOf(cap, n), error));
  const std::vector<double> boundary = BoundaryValues(plain);
  MonotoneSibsonSurface ordered = plain;
  CHECK(plain.FitToSamples(samples, error));
  CHECK(plain.FitReport().Fitted);
  const double range = 3, margin = 2e-3 * range;
  MonotoneSurfaceFitOptions options;
  options.Solver.KeepStartIfLower = false;
  for (int a = 0; a < static_cast<int>(samples.size()) && options.SampleOrders.size() < 25; ++a)
  {
    for (int b = 0; b < static_cast<int>(samples.size()); ++b)
    {
      const double du = samples[b].U - samples[a].U, dv = samples[b].V - samples[a].V;
      if (du > 0.005 && dv > 0.005 && du < 0.04 && dv < 0.04 &&
        plain.Evaluate(samples[b].U, samples[b].V) < plain.Evaluate(samples[a].U, samples[a].V))
      {
        options.SampleOrders.push_back({ a, b, margin });
        break;
      }
    }
  }
  std::printf("  %zu orders the plain fit breaks\n", options.SampleOrders.size());
  CHECK(options.SampleOrders.size() >= 10);
  CHECK(ordered.FitToSamples(samples, error, options));
  CHECK(ordered.FitReport().Fitted);
  double weakest = 1e300;
  for (const auto& order : options.SampleOrders)
  {
    weakest = std::min(weakest, ordered.Evaluate(samples[order.Upper].U, samples[order.Upper].V) -
        ordered.Evaluate(samples[order.Lower].U, samples[order.Lower].V));
  }
  std::printf("  ordered fit: weakest order %.2f of its margin, RMS %.4f (plain %.4f)\n", weakest / margin,
    ordered.FitReport().RMSResidual, plain.FitReport().RMSResidual);
  CHECK(weakest >= 0.5 * margin);
  CHECK(ordered.CountViolatingCells() == 0);
  CHECK(SmallestDiagonalIncrease(ordered, 300) > 0);
  CHECK(LargestBoundaryChange(ordered, boundary) < 1e-12 * range);
  // Orders between samples out of range are ignored, not read.
  options.SampleOrders = { { -1, 3, margin }, { 0, static_cast<int>(samples.size()), margin } };
  MonotoneSibsonSurface outOfRange = plain;
  CHECK(outOfRange.FitToSamples(samples, error, options));
}

TEST_CASE(NoSamplesKeepsThePaperInterior)
{
  MonotoneSibsonSurface surface;
  std::string error;
  CHECK(surface.Build(BoundaryOf(Cap(0.5), 4), error));
  const double before = surface.Evaluate(0.3, 0.6);
  CHECK(surface.FitToSamples({}, error));
  CHECK(!surface.FitReport().Fitted);
  CHECK(surface.Evaluate(0.3, 0.6) == before);
  // A non-finite sample is refused, the surface untouched.
  CHECK(!surface.FitToSamples({ { 0.5, 0.5, std::nan("") } }, error));
  CHECK(surface.Evaluate(0.3, 0.6) == before);
  // Not built: refused.
  MonotoneSibsonSurface empty;
  CHECK(!empty.FitToSamples({ { 0.5, 0.5, 1.0 } }, error));
}

int main()
{
  return testing_harness::RunAll();
}
