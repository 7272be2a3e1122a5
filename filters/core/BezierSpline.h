// The spline vocabulary of the core: curves made of k cubic Bezier segments, uniform
// quadratic B-splines on [0, 1], and their exact conversion into cubic Beziers (knot
// insertion, then degree elevation). The paper's 1-cells (section 4) and the boundaries of
// its 2-cells (section 5) are such curves.
//
// Conventions of the B-splines (docs/Algorithms.md, 2.2-2.4):
// - knots 0 = u_-2 = u_-1 = u_0 < u_1 < ... < u_k = u_k+1 = u_k+2 = 1, u_j = j / k;
// - coefficients alpha_0 .. alpha_k+1 (k + 2 of them); segment j covers [j / k, (j + 1) / k]
//   and depends on alpha_j, alpha_j+1, alpha_j+2 only;
// - multi-component splines (the planar curve) store coefficient i, component d at
//   [i * Dimension + d].
#pragma once

#include <vector>

namespace topospline
{
// The arithmetic of one de Casteljau step between control values a and b at s. Both give the
// same point up to rounding, but not the same bits: a caller keeps the one its results were
// computed with.
enum class DeCasteljauStep
{
  FromStart, // a + s (b - a)
  Weighted   // (1 - s) a + s b, with 1 - s computed once per split
};

// k cubic Bezier segments of a curve on [0, 1], segment j on [j / k, (j + 1) / k]. Every
// segment stores its own 4 control points (the end point of segment j repeats as the start
// point of segment j + 1), which is the layout of one VTK_BEZIER_CURVE cell per segment.
struct CubicBezierSpline
{
  int Segments = 0;
  int Dimension = 1;
  // Segment j, control point m (0..3), component d at [(j * 4 + m) * Dimension + d].
  std::vector<double> ControlPoints;

  const double* Segment(int j) const { return this->ControlPoints.data() + 4 * j * this->Dimension; }

  // Value and derivative with respect to the global parameter t in [0, 1].
  void Evaluate(double t, double* value) const;
  void EvaluateDerivative(double t, double* derivative) const;
  // Shortcuts for Dimension == 1.
  double Value(double t) const;
  double Slope(double t) const;

  // One cubic (4 control points of `dimension` components) at its local parameter s.
  static void EvaluateSegment(const double* control, int dimension, double s, double* value);
  // d/ds of one cubic.
  static void EvaluateSegmentDerivative(const double* control, int dimension, double s, double* derivative);
  // de Casteljau split of one cubic at s: `left` covers [0, s], `right` [s, 1], each 4 points.
  // Component d of a point is written only after that component of every input point has been
  // read, so `left` or `right` may be `control` itself.
  static void Subdivide(const double* control, int dimension, double s, double* left, double* right,
    DeCasteljauStep step = DeCasteljauStep::FromStart);
  // One cubic cut into `parts` cubics of equal parameter length, written one after the other
  // to `pieces` (4 * parts points); the same curve.
  static void SplitEvenly(const double* control, int dimension, int parts, double* pieces,
    DeCasteljauStep step = DeCasteljauStep::FromStart);
  // The same curve with every segment cut into `parts` of equal parameter length: Segments *
  // parts segments, still uniform in t.
  CubicBezierSpline SplitEvenly(int parts, DeCasteljauStep step = DeCasteljauStep::FromStart) const;
};

// A clamped uniform quadratic B-spline on [0, 1] with k segments (see the conventions above).
struct UniformQuadraticBSpline
{
  int Segments = 0;  // k
  int Dimension = 1; // 1 for a height, 2 for a planar curve
  std::vector<double> Coefficients; // (k + 2) * Dimension

  void Evaluate(double t, double* value) const;
  void EvaluateDerivative(double t, double* derivative) const;
  double Value(double t) const; // Dimension == 1
  double Slope(double t) const; // Dimension == 1

  // The weights of alpha_first, alpha_first+1, alpha_first+2 in the value at t, i.e.
  // N_first^2(t), N_first+1^2(t), N_first+2^2(t); first is the segment that holds t.
  static void BasisWeights(int segments, double t, int& first, double weights[3]);
  // The segment j that holds t (the last one for t = 1) and the local parameter s in [0, 1].
  static int LocateSegment(int segments, double t, double& s);

  // Knot insertion (every interior knot to multiplicity 2): k quadratic Bezier segments,
  // segment j, control point m (0..2), component d at [(j * 3 + m) * Dimension + d].
  std::vector<double> ToQuadraticBezier() const;
  // Knot insertion then degree elevation: the same curve as k cubic Bezier segments.
  CubicBezierSpline ToCubicBezier() const;
};

// Degree elevation of quadratic Bezier segments (3 control points each, as produced by
// UniformQuadraticBSpline::ToQuadraticBezier) to cubic ones: c0 = b0, c1 = (b0 + 2 b1) / 3,
// c2 = (2 b1 + b2) / 3, c3 = b2 (evaluated as b0 + 2 (b1 - b0) / 3 and b2 + 2 (b1 - b2) / 3,
// so that a zero end derivative stays exactly zero).
CubicBezierSpline ElevateQuadraticBezier(const std::vector<double>& quadratic, int segments, int dimension);
} // namespace topospline
