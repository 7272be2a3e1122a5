// Tests of the spline vocabulary (BezierSpline): B-spline to Bezier conversion against an
// independent Cox-de Boor evaluation, de Casteljau subdivision reproducing the curve, and the
// arithmetic of the conversion and subdivision against their formulas written out here.
//
// Usage: TestBezierSpline
// Prints the conversion error, then "N passed, N failed"; returns nonzero on failure.
#include "BezierSpline.h"
#include "TestHarness.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace topospline;

namespace
{
// An independent evaluation: Cox-de Boor on the clamped knot vector
// U = {0, 0, 0, 1/k, ..., (k-1)/k, 1, 1, 1}; the paper's N_i^2 is the standard N_i,2 on U.
struct CoxDeBoor
{
  std::vector<double> Knots;
  explicit CoxDeBoor(int k)
  {
    this->Knots = { 0.0, 0.0 };
    for (int j = 0; j <= k; ++j)
    {
      this->Knots.push_back(static_cast<double>(j) / k);
    }
    this->Knots.push_back(1.0);
    this->Knots.push_back(1.0);
  }
  double Basis(int i, int p, double t) const
  {
    const std::vector<double>& u = this->Knots;
    if (p == 0)
    {
      if (u[i] <= t && t < u[i + 1])
      {
        return 1.0;
      }
      // t = 1 belongs to the last non-empty interval.
      return (t == u.back() && u[i] < u[i + 1] && u[i + 1] == u.back()) ? 1.0 : 0.0;
    }
    double value = 0;
    if (u[i + p] > u[i])
    {
      value += (t - u[i]) / (u[i + p] - u[i]) * this->Basis(i, p - 1, t);
    }
    if (u[i + p + 1] > u[i + 1])
    {
      value += (u[i + p + 1] - t) / (u[i + p + 1] - u[i + 1]) * this->Basis(i + 1, p - 1, t);
    }
    return value;
  }
  double BasisDerivative(int i, double t) const
  {
    const std::vector<double>& u = this->Knots;
    double value = 0;
    if (u[i + 2] > u[i])
    {
      value += 2.0 / (u[i + 2] - u[i]) * this->Basis(i, 1, t);
    }
    if (u[i + 3] > u[i + 1])
    {
      value -= 2.0 / (u[i + 3] - u[i + 1]) * this->Basis(i + 1, 1, t);
    }
    return value;
  }
  void Evaluate(const std::vector<double>& coefficients, int dimension, double t, double* value, bool derivative) const
  {
    const int count = static_cast<int>(coefficients.size()) / dimension;
    for (int d = 0; d < dimension; ++d)
    {
      value[d] = 0;
    }
    for (int i = 0; i < count; ++i)
    {
      const double n = derivative ? this->BasisDerivative(i, t) : this->Basis(i, 2, t);
      for (int d = 0; d < dimension; ++d)
      {
        value[d] += n * coefficients[i * dimension + d];
      }
    }
  }
};
} // namespace

//------------------------------------------------------------------------------
TEST_CASE(ConversionMatchesCoxDeBoor)
{
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double worst = 0;
  for (int k : { 2, 3, 4, 5, 7, 12, 31 })
  {
    const CoxDeBoor reference(k);
    for (int dimension : { 1, 2 })
    {
      UniformQuadraticBSpline spline;
      spline.Segments = k;
      spline.Dimension = dimension;
      for (int i = 0; i < (k + 2) * dimension; ++i)
      {
        spline.Coefficients.push_back(unit(random));
      }
      const CubicBezierSpline cubic = spline.ToCubicBezier();
      const std::vector<double> quadratic = spline.ToQuadraticBezier();
      for (int i = 0; i <= 200; ++i)
      {
        const double t = i / 200.0;
        double expected[2], bspline[2], bezier[2], quad[2], expectedSlope[2], bsplineSlope[2], bezierSlope[2];
        reference.Evaluate(spline.Coefficients, dimension, t, expected, false);
        reference.Evaluate(spline.Coefficients, dimension, t, expectedSlope, true);
        spline.Evaluate(t, bspline);
        spline.EvaluateDerivative(t, bsplineSlope);
        cubic.Evaluate(t, bezier);
        cubic.EvaluateDerivative(t, bezierSlope);
        double s = 0;
        const int j = UniformQuadraticBSpline::LocateSegment(k, t, s);
        for (int d = 0; d < dimension; ++d)
        {
          const double* b = quadratic.data() + 3 * j * dimension;
          quad[d] = (1 - s) * (1 - s) * b[d] + 2 * s * (1 - s) * b[dimension + d] + s * s * b[2 * dimension + d];
          worst = std::max(worst, std::abs(bezier[d] - expected[d]));
          CHECK(std::abs(bspline[d] - expected[d]) <= 1e-12);
          CHECK(std::abs(bezier[d] - expected[d]) <= 1e-12);
          CHECK(std::abs(quad[d] - expected[d]) <= 1e-12);
          CHECK(std::abs(bsplineSlope[d] - expectedSlope[d]) <= 1e-10 * k);
          CHECK(std::abs(bezierSlope[d] - expectedSlope[d]) <= 1e-10 * k);
        }
      }
      // Partition of unity of the basis weights.
      for (int i = 0; i <= 50; ++i)
      {
        int first = 0;
        double w[3];
        UniformQuadraticBSpline::BasisWeights(k, i / 50.0, first, w);
        CHECK(std::abs(w[0] + w[1] + w[2] - 1.0) <= 1e-15);
        CHECK(first >= 0 && first + 2 <= k + 1);
      }
    }
  }
  std::printf("  conversion: max |cubic Bezier - Cox-de Boor| = %.2e over 201 parameters\n", worst);
}

//------------------------------------------------------------------------------
TEST_CASE(DeCasteljauSubdivision)
{
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial)
  {
    double control[8];
    for (double& c : control)
    {
      c = unit(random);
    }
    for (double split : { 0.5, 0.25, 1.0 / 3.0, 0.9 })
    {
      double left[8], right[8];
      CubicBezierSpline::Subdivide(control, 2, split, left, right);
      for (int i = 0; i <= 50; ++i)
      {
        const double u = i / 50.0;
        double whole[2], part[2];
        CubicBezierSpline::EvaluateSegment(left, 2, u, part);
        CubicBezierSpline::EvaluateSegment(control, 2, split * u, whole);
        CHECK(std::abs(part[0] - whole[0]) <= 1e-14 && std::abs(part[1] - whole[1]) <= 1e-14);
        CubicBezierSpline::EvaluateSegment(right, 2, u, part);
        CubicBezierSpline::EvaluateSegment(control, 2, split + (1 - split) * u, whole);
        CHECK(std::abs(part[0] - whole[0]) <= 1e-14 && std::abs(part[1] - whole[1]) <= 1e-14);
      }
      CHECK(left[0] == control[0] && right[6] == control[6] && left[6] == right[0]);
    }
  }
}

//------------------------------------------------------------------------------
// A spline whose segments are cut evenly is the same curve, still uniform in t: at every t the
// split spline (m k segments) and the whole one (k segments) agree, and the split one's
// segment boundaries are the whole one's points at j / (m k).
TEST_CASE(EvenSplitKeepsTheCurve)
{
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double worst = 0;
  for (int segments : { 1, 3, 4 })
  {
    for (int parts : { 1, 2, 3, 5 })
    {
      CubicBezierSpline whole;
      whole.Segments = segments;
      whole.Dimension = 2;
      for (int j = 0; j < segments; ++j)
      {
        for (int m = 0; m < 8; ++m)
        {
          whole.ControlPoints.push_back(unit(random));
        }
      }
      const CubicBezierSpline split = whole.SplitEvenly(parts);
      CHECK(split.Segments == segments * parts && split.Dimension == 2 &&
        split.ControlPoints.size() == whole.ControlPoints.size() * parts);
      for (int i = 0; i <= 600; ++i)
      {
        const double t = i / 600.0;
        double a[2], b[2];
        whole.Evaluate(t, a);
        split.Evaluate(t, b);
        worst = std::max({ worst, std::abs(a[0] - b[0]), std::abs(a[1] - b[1]) });
      }
      for (int j = 0; j < segments * parts; ++j)
      {
        double a[2];
        whole.Evaluate(static_cast<double>(j) / (segments * parts), a);
        const double* start = split.Segment(j);
        worst = std::max({ worst, std::abs(a[0] - start[0]), std::abs(a[1] - start[1]) });
      }
    }
  }
  std::printf("  even split: max |split - whole| = %.2e\n", worst);
  CHECK(worst < 1e-13);
}

//------------------------------------------------------------------------------
// The two arithmetics of a de Casteljau step, bit for bit: callers rely on them to reproduce
// earlier results exactly.
TEST_CASE(DeCasteljauStepArithmetic)
{
  std::mt19937 random(13);
  std::uniform_real_distribution<double> unit(-10.0, 10.0);
  std::uniform_real_distribution<double> parameter(0.0, 1.0);
  int mismatches = 0;
  for (int trial = 0; trial < 200; ++trial)
  {
    double c[4];
    for (double& value : c)
    {
      value = unit(random);
    }
    const double s = trial == 0 ? 0.5 : parameter(random);
    // a + s (b - a)
    const double f01 = c[0] + s * (c[1] - c[0]), f12 = c[1] + s * (c[2] - c[1]), f23 = c[2] + s * (c[3] - c[2]);
    const double f012 = f01 + s * (f12 - f01), f123 = f12 + s * (f23 - f12);
    const double f0123 = f012 + s * (f123 - f012);
    // (1 - s) a + s b
    const double r = 1 - s;
    const double w01 = r * c[0] + s * c[1], w12 = r * c[1] + s * c[2], w23 = r * c[2] + s * c[3];
    const double w012 = r * w01 + s * w12, w123 = r * w12 + s * w23;
    const double w0123 = r * w012 + s * w123;
    const double fromStart[8] = { c[0], f01, f012, f0123, f0123, f123, f23, c[3] };
    const double weighted[8] = { c[0], w01, w012, w0123, w0123, w123, w23, c[3] };

    double left[4], right[4];
    CubicBezierSpline::Subdivide(c, 1, s, left, right);
    double inPlace[4] = { c[0], c[1], c[2], c[3] }, inPlaceRight[4];
    CubicBezierSpline::Subdivide(inPlace, 1, s, inPlace, inPlaceRight, DeCasteljauStep::FromStart);
    for (int m = 0; m < 4; ++m)
    {
      mismatches += left[m] != fromStart[m] || right[m] != fromStart[4 + m];
      mismatches += inPlace[m] != fromStart[m] || inPlaceRight[m] != fromStart[4 + m];
    }
    CubicBezierSpline::Subdivide(c, 1, s, left, right, DeCasteljauStep::Weighted);
    for (int m = 0; m < 4; ++m)
    {
      mismatches += left[m] != weighted[m] || right[m] != weighted[4 + m];
    }
    // Two components, interleaved: each one split as if alone.
    double pair[8], pairLeft[8], pairRight[8];
    for (int m = 0; m < 4; ++m)
    {
      pair[2 * m] = c[m];
      pair[2 * m + 1] = -c[3 - m];
    }
    CubicBezierSpline::Subdivide(pair, 2, s, pairLeft, pairRight, DeCasteljauStep::Weighted);
    for (int m = 0; m < 4; ++m)
    {
      mismatches += pairLeft[2 * m] != weighted[m] || pairRight[2 * m] != weighted[4 + m];
    }
  }
  CHECK(mismatches == 0);
}

//------------------------------------------------------------------------------
// Knot insertion and degree elevation against their formulas: the blossom values of each
// segment, then c1 = b0 + 2 (b1 - b0) / 3, c2 = b2 + 2 (b1 - b2) / 3.
TEST_CASE(ConversionFormulas)
{
  std::mt19937 random(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k : { 2, 3, 5, 8 })
  {
    UniformQuadraticBSpline spline;
    spline.Segments = k;
    spline.Dimension = 1;
    for (int i = 0; i < k + 2; ++i)
    {
      spline.Coefficients.push_back(unit(random));
    }
    const std::vector<double>& alpha = spline.Coefficients;
    const std::vector<double> quadratic = spline.ToQuadraticBezier();
    const CubicBezierSpline cubic = spline.ToCubicBezier();
    CHECK(quadratic.size() == static_cast<std::size_t>(3 * k));
    CHECK(cubic.Segments == k && cubic.Dimension == 1 && cubic.ControlPoints.size() == static_cast<std::size_t>(4 * k));
    for (int j = 0; j < k; ++j)
    {
      const double b0 = j == 0 ? alpha[0] : 0.5 * (alpha[j] + alpha[j + 1]);
      const double b1 = alpha[j + 1];
      const double b2 = j == k - 1 ? alpha[k + 1] : 0.5 * (alpha[j + 1] + alpha[j + 2]);
      CHECK(quadratic[3 * j] == b0 && quadratic[3 * j + 1] == b1 && quadratic[3 * j + 2] == b2);
      const double* c = cubic.Segment(j);
      CHECK(c[0] == b0 && c[3] == b2);
      CHECK(c[1] == b0 + 2.0 * (b1 - b0) / 3.0 && c[2] == b2 + 2.0 * (b1 - b2) / 3.0);
    }
    // The ends of the curve are the end coefficients.
    CHECK(cubic.Value(0.0) == alpha[0] && cubic.Value(1.0) == alpha[k + 1]);
  }
}

int main()
{
  return testing_harness::RunAll();
}
