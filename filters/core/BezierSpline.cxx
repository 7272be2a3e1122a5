#include "BezierSpline.h"

#include <algorithm>
#include <cmath>

namespace topospline
{
namespace
{
// Bernstein polynomials of degree 2 and 3 at s.
void QuadraticBernstein(double s, double b[3])
{
  const double r = 1.0 - s;
  b[0] = r * r;
  b[1] = 2.0 * r * s;
  b[2] = s * s;
}

void CubicBernstein(double s, double b[4])
{
  const double r = 1.0 - s;
  b[0] = r * r * r;
  b[1] = 3.0 * r * r * s;
  b[2] = 3.0 * r * s * s;
  b[3] = s * s * s;
}

// The one component of a spline of Dimension 1 at t, through one of its evaluations.
template <typename Spline>
double ScalarAt(const Spline& spline, void (Spline::*evaluate)(double, double*) const, double t)
{
  double value = 0;
  (spline.*evaluate)(t, &value);
  return value;
}
} // namespace

//------------------------------------------------------------------------------
void CubicBezierSpline::EvaluateSegment(const double* control, int dimension, double s, double* value)
{
  double b[4];
  CubicBernstein(s, b);
  for (int d = 0; d < dimension; ++d)
  {
    value[d] = b[0] * control[d] + b[1] * control[dimension + d] + b[2] * control[2 * dimension + d] +
      b[3] * control[3 * dimension + d];
  }
}

//------------------------------------------------------------------------------
void CubicBezierSpline::EvaluateSegmentDerivative(const double* control, int dimension, double s, double* derivative)
{
  double b[3];
  QuadraticBernstein(s, b);
  for (int d = 0; d < dimension; ++d)
  {
    derivative[d] = 3.0 *
      (b[0] * (control[dimension + d] - control[d]) + b[1] * (control[2 * dimension + d] - control[dimension + d]) +
        b[2] * (control[3 * dimension + d] - control[2 * dimension + d]));
  }
}

//------------------------------------------------------------------------------
void CubicBezierSpline::Subdivide(
  const double* control, int dimension, double s, double* left, double* right, DeCasteljauStep step)
{
  const double r = 1.0 - s;
  auto between = [step, r, s](double a, double b) {
    return step == DeCasteljauStep::FromStart ? a + s * (b - a) : r * a + s * b;
  };
  for (int d = 0; d < dimension; ++d)
  {
    const double p0 = control[d];
    const double p1 = control[dimension + d];
    const double p2 = control[2 * dimension + d];
    const double p3 = control[3 * dimension + d];
    const double p01 = between(p0, p1);
    const double p12 = between(p1, p2);
    const double p23 = between(p2, p3);
    const double p012 = between(p01, p12);
    const double p123 = between(p12, p23);
    const double p0123 = between(p012, p123);
    left[d] = p0;
    left[dimension + d] = p01;
    left[2 * dimension + d] = p012;
    left[3 * dimension + d] = p0123;
    right[d] = p0123;
    right[dimension + d] = p123;
    right[2 * dimension + d] = p23;
    right[3 * dimension + d] = p3;
  }
}

//------------------------------------------------------------------------------
void CubicBezierSpline::SplitEvenly(const double* control, int dimension, int parts, double* pieces, DeCasteljauStep step)
{
  // Peel off pieces of equal length of the original parameter: the k-th cut of the remainder
  // [k/m, 1] is at its local parameter 1/(m - k).
  std::vector<double> remainder(control, control + 4 * dimension), right(4 * dimension);
  for (int k = 0; k + 1 < parts; ++k)
  {
    Subdivide(remainder.data(), dimension, 1.0 / (parts - k), pieces + 4 * k * dimension, right.data(), step);
    remainder.swap(right);
  }
  std::copy(remainder.begin(), remainder.end(), pieces + 4 * (parts - 1) * dimension);
}

CubicBezierSpline CubicBezierSpline::SplitEvenly(int parts, DeCasteljauStep step) const
{
  CubicBezierSpline split;
  split.Segments = this->Segments * parts;
  split.Dimension = this->Dimension;
  split.ControlPoints.resize(this->ControlPoints.size() * static_cast<std::size_t>(parts));
  for (int j = 0; j < this->Segments; ++j)
  {
    SplitEvenly(this->Segment(j), this->Dimension, parts, split.ControlPoints.data() + 4 * j * parts * this->Dimension, step);
  }
  return split;
}

//------------------------------------------------------------------------------
void CubicBezierSpline::Evaluate(double t, double* value) const
{
  double s = 0;
  const int j = UniformQuadraticBSpline::LocateSegment(this->Segments, t, s);
  CubicBezierSpline::EvaluateSegment(this->Segment(j), this->Dimension, s, value);
}

//------------------------------------------------------------------------------
void CubicBezierSpline::EvaluateDerivative(double t, double* derivative) const
{
  double s = 0;
  const int j = UniformQuadraticBSpline::LocateSegment(this->Segments, t, s);
  CubicBezierSpline::EvaluateSegmentDerivative(this->Segment(j), this->Dimension, s, derivative);
  // ds/dt = k on every segment.
  for (int d = 0; d < this->Dimension; ++d)
  {
    derivative[d] *= this->Segments;
  }
}

//------------------------------------------------------------------------------
double CubicBezierSpline::Value(double t) const
{
  return ScalarAt(*this, &CubicBezierSpline::Evaluate, t);
}

//------------------------------------------------------------------------------
double CubicBezierSpline::Slope(double t) const
{
  return ScalarAt(*this, &CubicBezierSpline::EvaluateDerivative, t);
}

//------------------------------------------------------------------------------
int UniformQuadraticBSpline::LocateSegment(int segments, double t, double& s)
{
  const double x = std::min(std::max(t, 0.0), 1.0) * segments;
  int j = static_cast<int>(std::floor(x));
  j = std::min(std::max(j, 0), segments - 1);
  s = x - j;
  return j;
}

//------------------------------------------------------------------------------
void UniformQuadraticBSpline::BasisWeights(int segments, double t, int& first, double weights[3])
{
  // Through the Bezier form of segment j (docs/Algorithms.md, 2.4): b0 = alpha_j on the first
  // segment and (alpha_j + alpha_j+1) / 2 elsewhere, b1 = alpha_j+1, b2 = alpha_k+1 on the
  // last segment and (alpha_j+1 + alpha_j+2) / 2 elsewhere.
  double s = 0;
  first = UniformQuadraticBSpline::LocateSegment(segments, t, s);
  double b[3];
  QuadraticBernstein(s, b);
  const double left = first == 0 ? 1.0 : 0.5;
  const double right = first == segments - 1 ? 1.0 : 0.5;
  weights[0] = b[0] * left;
  weights[1] = b[0] * (1.0 - left) + b[1] + b[2] * (1.0 - right);
  weights[2] = b[2] * right;
}

//------------------------------------------------------------------------------
void UniformQuadraticBSpline::Evaluate(double t, double* value) const
{
  int first = 0;
  double w[3];
  UniformQuadraticBSpline::BasisWeights(this->Segments, t, first, w);
  const int dim = this->Dimension;
  const double* alpha = this->Coefficients.data() + first * dim;
  for (int d = 0; d < dim; ++d)
  {
    value[d] = w[0] * alpha[d] + w[1] * alpha[dim + d] + w[2] * alpha[2 * dim + d];
  }
}

//------------------------------------------------------------------------------
void UniformQuadraticBSpline::EvaluateDerivative(double t, double* derivative) const
{
  // g'(t) = 2k [(b1 - b0)(1 - s) + (b2 - b1) s] on segment j, with b1 - b0 = left *
  // (alpha_j+1 - alpha_j) and b2 - b1 = right * (alpha_j+2 - alpha_j+1).
  double s = 0;
  const int k = this->Segments;
  const int j = UniformQuadraticBSpline::LocateSegment(k, t, s);
  const double left = j == 0 ? 1.0 : 0.5;
  const double right = j == k - 1 ? 1.0 : 0.5;
  const int dim = this->Dimension;
  const double* alpha = this->Coefficients.data() + j * dim;
  for (int d = 0; d < dim; ++d)
  {
    derivative[d] = 2.0 * k *
      (left * (1.0 - s) * (alpha[dim + d] - alpha[d]) + right * s * (alpha[2 * dim + d] - alpha[dim + d]));
  }
}

//------------------------------------------------------------------------------
double UniformQuadraticBSpline::Value(double t) const
{
  return ScalarAt(*this, &UniformQuadraticBSpline::Evaluate, t);
}

//------------------------------------------------------------------------------
double UniformQuadraticBSpline::Slope(double t) const
{
  return ScalarAt(*this, &UniformQuadraticBSpline::EvaluateDerivative, t);
}

//------------------------------------------------------------------------------
std::vector<double> UniformQuadraticBSpline::ToQuadraticBezier() const
{
  const int k = this->Segments;
  const int dim = this->Dimension;
  std::vector<double> quadratic(static_cast<std::size_t>(3 * k * dim));
  for (int j = 0; j < k; ++j)
  {
    const double* alpha = this->Coefficients.data() + j * dim;
    double* b = quadratic.data() + 3 * j * dim;
    for (int d = 0; d < dim; ++d)
    {
      // The blossom values g[u_j, u_j] (a double knot at u_j), g[u_j, u_j+1], g[u_j+1, u_j+1].
      b[d] = j == 0 ? alpha[d] : 0.5 * (alpha[d] + alpha[dim + d]);
      b[dim + d] = alpha[dim + d];
      b[2 * dim + d] = j == k - 1 ? alpha[2 * dim + d] : 0.5 * (alpha[dim + d] + alpha[2 * dim + d]);
    }
  }
  return quadratic;
}

//------------------------------------------------------------------------------
CubicBezierSpline ElevateQuadraticBezier(const std::vector<double>& quadratic, int segments, int dimension)
{
  CubicBezierSpline cubic;
  cubic.Segments = segments;
  cubic.Dimension = dimension;
  cubic.ControlPoints.resize(static_cast<std::size_t>(4 * segments * dimension));
  for (int j = 0; j < segments; ++j)
  {
    const double* b = quadratic.data() + 3 * j * dimension;
    double* c = cubic.ControlPoints.data() + 4 * j * dimension;
    for (int d = 0; d < dimension; ++d)
    {
      const double b0 = b[d];
      const double b1 = b[dimension + d];
      const double b2 = b[2 * dimension + d];
      c[d] = b0;
      // Written as offsets from the ends so that b1 = b0 (b1 = b2) gives c1 = c0 (c2 = c3)
      // exactly: the zero end derivatives survive rounding.
      c[dimension + d] = b0 + 2.0 * (b1 - b0) / 3.0;
      c[2 * dimension + d] = b2 + 2.0 * (b1 - b2) / 3.0;
      c[3 * dimension + d] = b2;
    }
  }
  return cubic;
}

//------------------------------------------------------------------------------
CubicBezierSpline UniformQuadraticBSpline::ToCubicBezier() const
{
  return ElevateQuadraticBezier(this->ToQuadraticBezier(), this->Segments, this->Dimension);
}
} // namespace topospline
