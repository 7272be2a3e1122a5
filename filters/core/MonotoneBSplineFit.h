// Stage 3 of the paper (section 4, step 2 and 3), for one piece of a 1-cell between two
// consecutive critical/junction points: a strictly increasing height function and a smooth
// planar curve, both uniform quadratic B-splines with k segments on [0, 1]. The splines, their
// conventions (knots, coefficients, layout) and their conversion into k cubic Bezier segments
// are in BezierSpline.h.
#pragma once

#include "BezierSpline.h"

#include <cstddef>
#include <string>
#include <vector>

namespace topospline
{
// The height fitted along one piece.
struct HeightFit
{
  UniformQuadraticBSpline Spline; // Dimension 1
  double L1Error = 0;             // sum over the interior samples of |f_i - g(t_i)|
  double MaximumError = 0;        // max over the interior samples of |f_i - g(t_i)|
  double MinimumStep = 0;         // delta: alpha_j+1 - alpha_j >= delta for j = 1..k-1 (0 if unconstrained)
  int ProgramVariables = 0;       // size of the linear program solved last (0 when none was needed)
  int ProgramConstraints = 0;
  bool SolvedThroughDual = false; // x came from the dual program (see UseDualProgram)
};

// The planar curve fitted along one piece.
struct PlanarCurveFit
{
  UniformQuadraticBSpline Spline; // Dimension 2
  double RootMeanSquareError = 0; // over all samples, of |x_i - c(t_i)|
  double MaximumError = 0;
};

class MonotoneBSplineFit
{
public:
  // k, the number of segments (the paper's "Curve Segments"; it uses 4 and 7). k = 2 leaves
  // no freedom (alpha_1 = a, alpha_2 = b); k = 1 would force a constant, so k >= 2.
  int Segments = 4;
  static constexpr int MaximumSegments = 1000;

  // Strictness: alpha_j+1 - alpha_j >= delta for j = 1..k-1 with
  //   delta = MinimumSlopeFraction * (b - a) / k.
  // g' is piecewise linear and equals k (alpha_j+1 - alpha_j) at the interior knots, so the
  // slope at every interior knot is at least MinimumSlopeFraction times the mean slope
  // (b - a) of the piece, and g' > 0 on the open interval (0, 1). The k - 1 steps sum to
  // b - a, so any fraction below k / (k - 1) is feasible; 1% keeps the fit free to follow
  // plateaus in the data while staying far above double-precision resolution.
  double MinimumSlopeFraction = 0.01;

  // L1 fits are often not unique (e.g. a segment without samples leaves its coefficients
  // free). The monotone fit adds TieBreakWeight * sum_j |(alpha_j+1 - alpha_j) - (b - a) /
  // (k - 1)| / (b - a) to the objective (whose residuals are also measured in units of
  // b - a), which picks the most evenly spaced optimum. It can raise the L1 error by at
  // most 2 * TieBreakWeight * (b - a); 1e-5 is 100 times GLPK's optimality tolerance, so
  // the tie-break is effective. 0 disables it. The unconstrained fit never uses it, so its
  // error is a true lower bound for the monotone one.
  double TieBreakWeight = 1e-5;

  // How the L1 program is solved (both with GLPK through CGAL's solver interface). The
  // primal has one row per interior sample and GLPK's primal simplex needs about as many
  // pivots, so it grows like n^2 (about 4 ms for n = 200, k = 7). The dual has one row per free
  // coefficient (k - 2); the coefficients are recovered from its solution by complementary
  // slackness and accepted only with an optimality certificate (feasible, zero duality
  // gap), else the primal is solved instead (degenerate data such as constant samples).
  // Same optimum either way; false always solves the primal.
  bool UseDualProgram = true;

  // Height g along the piece, fitted in the L1 sense (He & Shi) to the samples
  // (parameters[i], values[i]), i = 0..n (n >= 1), parameters non-decreasing in [0, 1]:
  // g(0) = startValue < g(1) = endValue exactly, g'(0) = g'(1) = 0 (alpha_0 = alpha_1,
  // alpha_k = alpha_k+1), and only the interior samples 1..n-1 enter the objective (the
  // end values come from the junction program, not from values[0] and values[n]).
  // monotone = true adds alpha_j+1 - alpha_j >= delta (strictly increasing g); false gives
  // the unconstrained L1 fit with the same end conditions, for comparison.
  // Returns false with a message for bad input (k out of range, startValue >= endValue,
  // sizes, non-finite numbers) or a solver failure.
  bool FitHeight(const std::vector<double>& parameters, const std::vector<double>& values, double startValue,
    double endValue, bool monotone, HeightFit& fit, std::string& error) const;

  // Least-squares planar curve c(t) = sum c_i N_i^2(t) through the polyline points
  // (points[2 i], points[2 i + 1]) at parameters[i], i = 0..n: c_0 = first point and
  // c_k+1 = last point exactly (so c(0), c(1) are the critical/junction points), c_1..c_k
  // free (the paper does not fix the end tangents). A ridge term of 1e-6 of the mean
  // diagonal of the normal matrix pulls c_1..c_k towards the polyline at the Greville
  // abscissae (j - 1/2) / k: negligible for well-sampled pieces, it keeps pieces with fewer
  // samples than coefficients well-posed (and reproduces a straight polyline exactly).
  bool FitPlanarCurve(const std::vector<double>& parameters, const std::vector<double>& points,
    PlanarCurveFit& fit, std::string& error) const;

  // fit.L1Error and fit.MaximumError of fit.Spline against (parameters[i], values[i]) over the
  // interior samples (FitHeight measures its fits so; another set of values measures a fit
  // against them).
  static void MeasureHeightErrors(const std::vector<double>& parameters, const std::vector<double>& values,
    HeightFit& fit);

  // Normalized arc length of a polyline (x, y pairs): t_0 = 0, t_n = 1. A polyline of zero
  // length gets uniform parameters i / n.
  static std::vector<double> NormalizedArcLength(const std::vector<double>& points);

  // The parameters a height fit can follow: the normalized arc length plus the normalized
  // rise, the running maximum of the values clamped to [startValue, endValue] (so noise that
  // goes down and up again adds nothing), each step's rise at most `maximumRiseRatio` times
  // its share of the length; normalized again. A profile that falls steeply and
  // then flattens gets as many uniform knots on the fall as on the flat (uniform in arc
  // length, k = 4 put one segment on a fall of 15 % of the range). Arc length alone when
  // the values do not rise (endValue <= startValue, or a flat profile).
  static std::vector<double> ArcLengthAndRise(const std::vector<double>& points, const std::vector<double>& values,
    double startValue, double endValue, double maximumRiseRatio);

private:
  bool CheckSamples(const std::vector<double>& parameters, std::size_t valuesPerSample,
    const std::vector<double>& values, std::string& error) const;
};
} // namespace topospline
