#include "MonotoneBSplineFit.h"

#ifndef CGAL_USE_GLPK
#error "MonotoneBSplineFit needs GLPK through CGAL's solver interface: define CGAL_USE_GLPK and link glpk"
#endif
#include <CGAL/GLPK_mixed_integer_program_traits.h>
#include <glpk.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace topospline
{
namespace
{
using LinearProgram = CGAL::GLPK_mixed_integer_program_traits<double>;
using LinearVariable = CGAL::Variable<double>;
using LinearConstraint = CGAL::Linear_constraint<double>;

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

bool AllFinite(const std::vector<double>& values)
{
  for (double v : values)
  {
    if (!std::isfinite(v))
    {
      return false;
    }
  }
  return true;
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
void CubicBezierSpline::Subdivide(const double* control, int dimension, double s, double* left, double* right)
{
  for (int d = 0; d < dimension; ++d)
  {
    const double p0 = control[d];
    const double p1 = control[dimension + d];
    const double p2 = control[2 * dimension + d];
    const double p3 = control[3 * dimension + d];
    const double p01 = p0 + s * (p1 - p0);
    const double p12 = p1 + s * (p2 - p1);
    const double p23 = p2 + s * (p3 - p2);
    const double p012 = p01 + s * (p12 - p01);
    const double p123 = p12 + s * (p23 - p12);
    const double p0123 = p012 + s * (p123 - p012);
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
  double value = 0;
  this->Evaluate(t, &value);
  return value;
}

//------------------------------------------------------------------------------
double CubicBezierSpline::Slope(double t) const
{
  double slope = 0;
  this->EvaluateDerivative(t, &slope);
  return slope;
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
  // Through the Bezier form of segment j (algorithms.md 2.4): b0 = alpha_j on the first
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
  double value = 0;
  this->Evaluate(t, &value);
  return value;
}

//------------------------------------------------------------------------------
double UniformQuadraticBSpline::Slope(double t) const
{
  double slope = 0;
  this->EvaluateDerivative(t, &slope);
  return slope;
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
      c[dimension + d] = (b0 + 2.0 * b1) / 3.0;
      c[2 * dimension + d] = (2.0 * b1 + b2) / 3.0;
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

//------------------------------------------------------------------------------
std::vector<double> MonotoneBSplineFit::NormalizedArcLength(const std::vector<double>& points)
{
  const std::size_t count = points.size() / 2;
  std::vector<double> parameters(count, 0.0);
  if (count < 2)
  {
    return parameters;
  }
  for (std::size_t i = 1; i < count; ++i)
  {
    const double dx = points[2 * i] - points[2 * i - 2];
    const double dy = points[2 * i + 1] - points[2 * i - 1];
    parameters[i] = parameters[i - 1] + std::sqrt(dx * dx + dy * dy);
  }
  const double length = parameters.back();
  for (std::size_t i = 1; i < count; ++i)
  {
    parameters[i] = length > 0 ? parameters[i] / length : static_cast<double>(i) / (count - 1);
  }
  // Exactly 1 at the end, whatever the rounding of the division.
  parameters.back() = 1.0;
  return parameters;
}

//------------------------------------------------------------------------------
bool MonotoneBSplineFit::CheckSamples(const std::vector<double>& parameters, std::size_t valuesPerSample,
  const std::vector<double>& values, std::string& error) const
{
  if (this->Segments < 2 || this->Segments > MonotoneBSplineFit::MaximumSegments)
  {
    error = "the number of curve segments must be between 2 and " +
      std::to_string(MonotoneBSplineFit::MaximumSegments) + ", got " + std::to_string(this->Segments);
    return false;
  }
  if (parameters.size() < 2)
  {
    error = "a 1-cell piece needs at least its two end samples";
    return false;
  }
  if (values.size() != valuesPerSample * parameters.size())
  {
    error = "the number of sample values does not match the number of parameters";
    return false;
  }
  if (!AllFinite(parameters) || !AllFinite(values))
  {
    error = "the samples contain non-finite numbers";
    return false;
  }
  // Arc length parameters: a little rounding outside [0, 1] is tolerated (and clamped by
  // the evaluation), a decreasing sequence is not.
  const double slack = 1e-9;
  for (std::size_t i = 0; i < parameters.size(); ++i)
  {
    if (parameters[i] < -slack || parameters[i] > 1.0 + slack || (i > 0 && parameters[i] < parameters[i - 1]))
    {
      error = "the sample parameters must be non-decreasing in [0, 1]";
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool MonotoneBSplineFit::FitHeight(const std::vector<double>& parameters, const std::vector<double>& values,
  double startValue, double endValue, bool monotone, HeightFit& fit, std::string& error) const
{
  if (!this->CheckSamples(parameters, 1, values, error))
  {
    return false;
  }
  if (!std::isfinite(startValue) || !std::isfinite(endValue) || !(startValue < endValue))
  {
    error = "the end values of a 1-cell piece must be finite and strictly increasing";
    return false;
  }

  const int k = this->Segments;
  const double range = endValue - startValue;
  const std::size_t interiorCount = parameters.size() - 2;

  // The program works in normalized values (a -> 0, b -> 1): its coefficients are then of
  // order one whatever the units of the field, which GLPK (run unscaled by CGAL) needs.
  std::vector<double> alpha(static_cast<std::size_t>(k + 2), 0.0);
  for (int j = k; j <= k + 1; ++j)
  {
    alpha[j] = 1.0;
  }
  const double delta = monotone ? this->MinimumSlopeFraction / k : 0.0;
  const double evenStep = 1.0 / (k - 1);
  fit.MinimumStep = delta * range;
  fit.ProgramVariables = 0;
  fit.ProgramConstraints = 0;
  if (monotone && !(delta > 0 && delta * (k - 1) < 1.0))
  {
    error = "MinimumSlopeFraction must be in (0, k / (k - 1))";
    return false;
  }

  if (k == 2)
  {
    // alpha_0 = alpha_1 = a, alpha_2 = alpha_3 = b: nothing left to fit.
  }
  else if (interiorCount == 0)
  {
    // No data between the ends: the evenly spaced coefficients (what the tie-break picks).
    for (int j = 2; j < k; ++j)
    {
      alpha[j] = (j - 1) * evenStep;
    }
  }
  else
  {
    LinearProgram program;
    const double infinity = LinearVariable::infinity();
    std::vector<LinearVariable*> free(static_cast<std::size_t>(k + 2), nullptr);
    for (int j = 2; j < k; ++j)
    {
      // Implied by the step constraints chained from both ends; as bounds they cost nothing.
      const double lower = monotone ? (j - 1) * delta : -infinity;
      const double upper = monotone ? 1.0 - (k - j) * delta : infinity;
      free[j] = program.create_variable(LinearVariable::CONTINUOUS, lower, upper);
    }
    auto* objective = program.create_objective(CGAL::Linear_objective<double>::MINIMIZE);

    // |f_i - g(t_i)| <= r_i as two rows; the fixed coefficients move to the right-hand side.
    for (std::size_t i = 1; i + 1 < parameters.size(); ++i)
    {
      int first = 0;
      double w[3];
      UniformQuadraticBSpline::BasisWeights(k, parameters[i], first, w);
      double fixedPart = 0;
      bool touchesFree = false;
      for (int m = 0; m < 3; ++m)
      {
        if (free[first + m])
        {
          touchesFree = touchesFree || w[m] != 0.0;
        }
        else
        {
          fixedPart += w[m] * alpha[first + m];
        }
      }
      if (!touchesFree)
      {
        continue; // a sample at t = 0 or 1: its residual does not depend on the program
      }
      const double target = (values[i] - startValue) / range - fixedPart;
      LinearVariable* residual = program.create_variable(LinearVariable::CONTINUOUS, 0.0, infinity);
      objective->add_coefficient(residual, 1.0);
      LinearConstraint* above = program.create_constraint(target, infinity);
      LinearConstraint* below = program.create_constraint(-target, infinity);
      above->add_coefficient(residual, 1.0);
      below->add_coefficient(residual, 1.0);
      for (int m = 0; m < 3; ++m)
      {
        if (free[first + m] && w[m] != 0.0)
        {
          above->add_coefficient(free[first + m], w[m]);
          below->add_coefficient(free[first + m], -w[m]);
        }
      }
    }

    if (monotone)
    {
      // Steps between two free coefficients; the steps next to the fixed ones are bounds.
      for (int j = 2; j + 1 < k; ++j)
      {
        LinearConstraint* step = program.create_constraint(delta, infinity);
        step->add_coefficient(free[j + 1], 1.0);
        step->add_coefficient(free[j], -1.0);
      }
      if (this->TieBreakWeight > 0)
      {
        // s_j >= |alpha_j+1 - alpha_j - evenStep| for j = 1..k-1.
        for (int j = 1; j < k; ++j)
        {
          LinearVariable* spread = program.create_variable(LinearVariable::CONTINUOUS, 0.0, infinity);
          objective->add_coefficient(spread, this->TieBreakWeight);
          const double fixedStep = (free[j + 1] ? 0.0 : alpha[j + 1]) - (free[j] ? 0.0 : alpha[j]);
          LinearConstraint* over = program.create_constraint(fixedStep - evenStep, infinity);
          LinearConstraint* under = program.create_constraint(evenStep - fixedStep, infinity);
          over->add_coefficient(spread, 1.0);
          under->add_coefficient(spread, 1.0);
          if (free[j + 1])
          {
            over->add_coefficient(free[j + 1], -1.0);
            under->add_coefficient(free[j + 1], 1.0);
          }
          if (free[j])
          {
            over->add_coefficient(free[j], 1.0);
            under->add_coefficient(free[j], -1.0);
          }
        }
      }
    }

    fit.ProgramVariables = static_cast<int>(program.number_of_variables());
    fit.ProgramConstraints = static_cast<int>(program.number_of_constraints());
    glp_term_out(GLP_OFF);
    if (!program.solve())
    {
      error = "the linear program of the height fit failed: " + program.error_message();
      return false;
    }
    const std::vector<double>& solution = program.solution();
    for (int j = 2; j < k; ++j)
    {
      alpha[j] = solution[free[j]->index()];
      if (!std::isfinite(alpha[j]))
      {
        error = "the linear program of the height fit returned a non-finite coefficient";
        return false;
      }
    }

    if (monotone)
    {
      // GLPK meets constraints to its feasibility tolerance (1e-7), not exactly: restore
      // every step >= delta. Forward then backward keeps alpha_j >= (j - 1) delta and gives
      // alpha_j <= alpha_j+1 - delta, hence both, because (k - 1) delta < 1 (it changes
      // nothing when the solution is already feasible).
      for (int j = 2; j < k; ++j)
      {
        alpha[j] = std::max(alpha[j], alpha[j - 1] + delta);
      }
      for (int j = k - 1; j >= 2; --j)
      {
        alpha[j] = std::min(alpha[j], alpha[j + 1] - delta);
      }
    }
  }

  // Back to field units; the ends are set, not computed, so they are exact.
  fit.Spline.Segments = k;
  fit.Spline.Dimension = 1;
  fit.Spline.Coefficients.resize(static_cast<std::size_t>(k + 2));
  fit.Spline.Coefficients[0] = fit.Spline.Coefficients[1] = startValue;
  fit.Spline.Coefficients[k] = fit.Spline.Coefficients[k + 1] = endValue;
  for (int j = 2; j < k; ++j)
  {
    fit.Spline.Coefficients[j] = startValue + range * alpha[j];
  }
  if (monotone)
  {
    for (int j = 1; j < k; ++j)
    {
      if (!(fit.Spline.Coefficients[j + 1] > fit.Spline.Coefficients[j]))
      {
        error = "the end values of the 1-cell piece are too close for a strictly increasing fit in double precision";
        return false;
      }
    }
  }

  fit.L1Error = 0;
  fit.MaximumError = 0;
  for (std::size_t i = 1; i + 1 < parameters.size(); ++i)
  {
    const double e = std::abs(values[i] - fit.Spline.Value(parameters[i]));
    fit.L1Error += e;
    fit.MaximumError = std::max(fit.MaximumError, e);
  }
  return true;
}

//------------------------------------------------------------------------------
bool MonotoneBSplineFit::FitPlanarCurve(
  const std::vector<double>& parameters, const std::vector<double>& points, PlanarCurveFit& fit, std::string& error) const
{
  if (!this->CheckSamples(parameters, 2, points, error))
  {
    return false;
  }
  const int k = this->Segments;
  const std::size_t count = parameters.size();
  // Relative to the start point: the solve then sees coordinates of the size of the piece,
  // not of the position of the piece in the domain.
  const double origin[2] = { points[0], points[1] };
  const double end[2] = { points[2 * count - 2] - origin[0], points[2 * count - 1] - origin[1] };

  // Normal equations for the free coefficients c_1..c_k (unknown j - 1).
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(k, k);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(k, 2);
  for (std::size_t i = 0; i < count; ++i)
  {
    int first = 0;
    double w[3];
    UniformQuadraticBSpline::BasisWeights(k, parameters[i], first, w);
    double residual[2] = { points[2 * i] - origin[0], points[2 * i + 1] - origin[1] };
    for (int m = 0; m < 3; ++m)
    {
      const int index = first + m;
      if (index == k + 1)
      {
        residual[0] -= w[m] * end[0];
        residual[1] -= w[m] * end[1];
      }
    }
    for (int m = 0; m < 3; ++m)
    {
      const int row = first + m - 1;
      if (row < 0 || row >= k || w[m] == 0.0)
      {
        continue;
      }
      for (int n = 0; n < 3; ++n)
      {
        const int column = first + n - 1;
        if (column >= 0 && column < k)
        {
          normal(row, column) += w[m] * w[n];
        }
      }
      rhs(row, 0) += w[m] * residual[0];
      rhs(row, 1) += w[m] * residual[1];
    }
  }

  // Ridge towards the polyline at the Greville abscissae (j - 1/2) / k of c_j.
  // (With no sample inside the piece the normal matrix is zero: the ridge alone decides.)
  const double meanDiagonal = normal.trace() / k;
  const double ridge = meanDiagonal > 0 ? 1e-6 * meanDiagonal : 1.0;
  for (int j = 1; j <= k; ++j)
  {
    const double tau = (j - 0.5) / k;
    const auto upper = std::upper_bound(parameters.begin(), parameters.end(), tau);
    std::size_t b = static_cast<std::size_t>(upper - parameters.begin());
    b = std::min(std::max<std::size_t>(b, 1), count - 1);
    const std::size_t a = b - 1;
    const double span = parameters[b] - parameters[a];
    const double u = span > 0 ? std::min(std::max((tau - parameters[a]) / span, 0.0), 1.0) : 0.0;
    for (int d = 0; d < 2; ++d)
    {
      const double target = (1.0 - u) * (points[2 * a + d] - origin[d]) + u * (points[2 * b + d] - origin[d]);
      rhs(j - 1, d) += ridge * target;
    }
    normal(j - 1, j - 1) += ridge;
  }

  const Eigen::LDLT<Eigen::MatrixXd> factorization(normal);
  const Eigen::MatrixXd solution = factorization.solve(rhs);
  if (factorization.info() != Eigen::Success || !solution.allFinite())
  {
    error = "the least-squares system of the planar curve could not be solved";
    return false;
  }

  fit.Spline.Segments = k;
  fit.Spline.Dimension = 2;
  fit.Spline.Coefficients.resize(static_cast<std::size_t>(2 * (k + 2)));
  fit.Spline.Coefficients[0] = points[0];
  fit.Spline.Coefficients[1] = points[1];
  for (int j = 1; j <= k; ++j)
  {
    fit.Spline.Coefficients[2 * j] = origin[0] + solution(j - 1, 0);
    fit.Spline.Coefficients[2 * j + 1] = origin[1] + solution(j - 1, 1);
  }
  fit.Spline.Coefficients[2 * k + 2] = points[2 * count - 2];
  fit.Spline.Coefficients[2 * k + 3] = points[2 * count - 1];

  double sumOfSquares = 0;
  fit.MaximumError = 0;
  for (std::size_t i = 0; i < count; ++i)
  {
    double c[2];
    fit.Spline.Evaluate(parameters[i], c);
    const double e = std::hypot(points[2 * i] - c[0], points[2 * i + 1] - c[1]);
    sumOfSquares += e * e;
    fit.MaximumError = std::max(fit.MaximumError, e);
  }
  fit.RootMeanSquareError = std::sqrt(sumOfSquares / count);
  return true;
}
} // namespace topospline
