#include "MonotoneBSplineFit.h"

#include "GlpkLinearProgram.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace topospline
{
namespace
{
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

// A weighted L1 problem over p unknowns:
//   minimize sum_r Weight_r |Target_r - a_r . x| subject to c_s . x >= Target_s,
// with rows of at most 3 entries (B-spline weights or coefficient differences).
struct SparseRow
{
  int Count = 0;
  int Index[3] = { 0, 0, 0 };
  double Coefficient[3] = { 0, 0, 0 };
  double Target = 0;
  double Weight = 1;

  double Dot(const std::vector<double>& x) const
  {
    double sum = 0;
    for (int e = 0; e < this->Count; ++e)
    {
      sum += this->Coefficient[e] * x[this->Index[e]];
    }
    return sum;
  }
};

struct L1Program
{
  int Unknowns = 0;
  std::vector<SparseRow> Residuals;
  std::vector<SparseRow> Constraints;

  double Objective(const std::vector<double>& x) const
  {
    double sum = 0;
    for (const SparseRow& row : this->Residuals)
    {
      sum += row.Weight * std::abs(row.Target - row.Dot(x));
    }
    return sum;
  }
};

// The primal program: the paper's, with each residual split into two non-negative parts
// and one equality row per residual (with GLPK's primal simplex, as CGAL runs it, this was
// measured 2 to 2.5 times faster than the inequality form with two rows per residual).
bool SolvePrimal(const L1Program& l1, std::vector<double>& x, int& variables, int& constraints, std::string& error)
{
  LinearProgram program;
  const double infinity = LinearVariable::infinity();
  std::vector<LinearVariable*> unknowns;
  for (int q = 0; q < l1.Unknowns; ++q)
  {
    unknowns.push_back(program.create_variable(LinearVariable::CONTINUOUS, -infinity, infinity));
  }
  auto* objective = program.create_objective(CGAL::Linear_objective<double>::MINIMIZE);
  for (const SparseRow& row : l1.Residuals)
  {
    // a . x + over - under = target.
    LinearVariable* over = program.create_variable(LinearVariable::CONTINUOUS, 0.0, infinity);
    LinearVariable* under = program.create_variable(LinearVariable::CONTINUOUS, 0.0, infinity);
    objective->add_coefficient(over, row.Weight);
    objective->add_coefficient(under, row.Weight);
    LinearConstraint* equation = program.create_constraint(row.Target, row.Target);
    equation->add_coefficient(over, 1.0);
    equation->add_coefficient(under, -1.0);
    for (int e = 0; e < row.Count; ++e)
    {
      equation->add_coefficient(unknowns[row.Index[e]], row.Coefficient[e]);
    }
  }
  for (const SparseRow& row : l1.Constraints)
  {
    LinearConstraint* constraint = program.create_constraint(row.Target, infinity);
    for (int e = 0; e < row.Count; ++e)
    {
      constraint->add_coefficient(unknowns[row.Index[e]], row.Coefficient[e]);
    }
  }
  variables = static_cast<int>(program.number_of_variables());
  constraints = static_cast<int>(program.number_of_constraints());
  std::string solverError;
  if (!SolveLinearProgram(program, solverError))
  {
    error = "the linear program of the height fit failed: " + solverError;
    return false;
  }
  x.resize(l1.Unknowns);
  for (int q = 0; q < l1.Unknowns; ++q)
  {
    x[q] = program.solution()[unknowns[q]->index()];
  }
  return true;
}

// GLPK starts from its standard basis, where every d_r sits at a bound, and each sign it has
// to flip costs an iteration. The dual is started instead from the signs of the residuals of
// the least-squares fit (close to those of the L1 fit for most samples): d_r = sign_r + z_r
// with z_r in [-1 - sign_r, 1 - sign_r], whose bound of smaller magnitude is z_r = 0.
std::vector<double> LeastSquaresResidualSigns(const L1Program& l1)
{
  const int p = l1.Unknowns;
  std::vector<double> sign(l1.Residuals.size(), 1.0);
  Eigen::MatrixXd normal = Eigen::MatrixXd::Identity(p, p) * 1e-9;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(p);
  for (const SparseRow& row : l1.Residuals)
  {
    for (int e = 0; e < row.Count; ++e)
    {
      for (int f = 0; f < row.Count; ++f)
      {
        normal(row.Index[e], row.Index[f]) += row.Weight * row.Coefficient[e] * row.Coefficient[f];
      }
      rhs(row.Index[e]) += row.Weight * row.Coefficient[e] * row.Target;
    }
  }
  const Eigen::VectorXd guess = normal.ldlt().solve(rhs);
  if (guess.allFinite())
  {
    const std::vector<double> start(guess.data(), guess.data() + p);
    for (std::size_t r = 0; r < l1.Residuals.size(); ++r)
    {
      sign[r] = l1.Residuals[r].Target - l1.Residuals[r].Dot(start) >= 0 ? 1.0 : -1.0;
    }
  }
  return sign;
}

// The dual program of an L1Program, with d_r = Sign_r + z_r (see LeastSquaresResidualSigns).
struct DualProgram
{
  LinearProgram Program;
  std::vector<double> Sign;
  std::vector<LinearVariable*> ResidualDuals;   // z_r
  std::vector<LinearVariable*> ConstraintDuals; // mu_s
  double Scale = 1.0;                           // 1 + sum_r Weight_r |Target_r|

  double ResidualDual(const std::vector<double>& solution, std::size_t r) const
  {
    return this->Sign[r] + solution[this->ResidualDuals[r]->index()];
  }
  double ConstraintDual(const std::vector<double>& solution, std::size_t s) const
  {
    return solution[this->ConstraintDuals[s]->index()];
  }
};

void BuildDualProgram(const L1Program& l1, DualProgram& dual)
{
  const int p = l1.Unknowns;
  LinearProgram& program = dual.Program;
  const std::vector<double>& sign = dual.Sign;
  const double infinity = LinearVariable::infinity();
  auto* objective = program.create_objective(CGAL::Linear_objective<double>::MAXIMIZE);
  std::vector<double> rowTargets(static_cast<std::size_t>(p), 0.0);
  for (std::size_t r = 0; r < l1.Residuals.size(); ++r)
  {
    const SparseRow& row = l1.Residuals[r];
    for (int e = 0; e < row.Count; ++e)
    {
      rowTargets[row.Index[e]] -= row.Weight * row.Coefficient[e] * sign[r];
    }
  }
  std::vector<LinearConstraint*> rows;
  for (int q = 0; q < p; ++q)
  {
    rows.push_back(program.create_constraint(rowTargets[q], rowTargets[q]));
  }
  for (std::size_t r = 0; r < l1.Residuals.size(); ++r)
  {
    const SparseRow& row = l1.Residuals[r];
    LinearVariable* z = program.create_variable(LinearVariable::CONTINUOUS, -1.0 - sign[r], 1.0 - sign[r]);
    objective->add_coefficient(z, row.Weight * row.Target);
    for (int e = 0; e < row.Count; ++e)
    {
      rows[row.Index[e]]->add_coefficient(z, row.Weight * row.Coefficient[e]);
    }
    dual.ResidualDuals.push_back(z);
    dual.Scale += row.Weight * std::abs(row.Target);
  }
  for (const SparseRow& row : l1.Constraints)
  {
    LinearVariable* mu = program.create_variable(LinearVariable::CONTINUOUS, 0.0, infinity);
    objective->add_coefficient(mu, row.Target);
    for (int e = 0; e < row.Count; ++e)
    {
      rows[row.Index[e]]->add_coefficient(mu, row.Coefficient[e]);
    }
    dual.ConstraintDuals.push_back(mu);
  }
}

// Complementary slackness: x solves the equations of the rows whose dual is strictly inside
// (|d_r| < 1: residual r is zero; mu_s > 0: constraint s is tight). Sets the dual's objective;
// false when those rows do not determine x.
bool RecoverPrimalSolution(const L1Program& l1, const DualProgram& dual, const std::vector<double>& solution,
  std::vector<double>& x, double& dualObjective)
{
  const int p = l1.Unknowns;
  std::vector<const SparseRow*> tight;
  dualObjective = 0;
  for (std::size_t r = 0; r < l1.Residuals.size(); ++r)
  {
    const double d = dual.ResidualDual(solution, r);
    dualObjective += l1.Residuals[r].Weight * l1.Residuals[r].Target * d;
    if (d > -1.0 && d < 1.0)
    {
      tight.push_back(&l1.Residuals[r]);
    }
  }
  for (std::size_t s = 0; s < l1.Constraints.size(); ++s)
  {
    const double mu = dual.ConstraintDual(solution, s);
    dualObjective += l1.Constraints[s].Target * mu;
    if (mu > 0.0)
    {
      tight.push_back(&l1.Constraints[s]);
    }
  }
  if (static_cast<int>(tight.size()) < p)
  {
    return false;
  }
  Eigen::MatrixXd equations = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(tight.size()), p);
  Eigen::VectorXd targets(static_cast<Eigen::Index>(tight.size()));
  for (std::size_t r = 0; r < tight.size(); ++r)
  {
    for (int e = 0; e < tight[r]->Count; ++e)
    {
      equations(static_cast<Eigen::Index>(r), tight[r]->Index[e]) += tight[r]->Coefficient[e];
    }
    targets(static_cast<Eigen::Index>(r)) = tight[r]->Target;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> factorization(equations);
  if (factorization.rank() < p)
  {
    return false;
  }
  const Eigen::VectorXd solved = factorization.solve(targets);
  x.assign(solved.data(), solved.data() + p);
  return true;
}

// The certificate: P(x) - D(d, mu) = sum_r Weight_r (|res_r| - d_r res_r)
//   + sum_s mu_s (c_s . x - Target_s) - x . e,
// every term >= 0 but the last. GLPK meets the dual's rows only to its tolerance (row
// residual e = sum_r Weight_r d_r a_r + sum_s mu_s c_s) and stops when the reduced costs
// (here: residuals whose sign disagrees with d_r) are below 1e-7, so it leaves gaps of
// about 1e-7 even at its optimum; a wrong active set leaves gaps of the size of the
// residuals. Accept x when the gap is below x . e + 1e-7 * (1 + sum_r Weight_r |Target_r|):
// optimal to GLPK's own tolerance, in units of b - a.
bool HasOptimalityCertificate(const L1Program& l1, const DualProgram& dual, const std::vector<double>& solution,
  const std::vector<double>& x, double dualObjective)
{
  const int p = l1.Unknowns;
  std::vector<double> rowResidual(static_cast<std::size_t>(p), 0.0);
  for (std::size_t r = 0; r < l1.Residuals.size(); ++r)
  {
    const SparseRow& row = l1.Residuals[r];
    const double d = dual.ResidualDual(solution, r);
    for (int e = 0; e < row.Count; ++e)
    {
      rowResidual[row.Index[e]] += row.Weight * d * row.Coefficient[e];
    }
  }
  for (std::size_t s = 0; s < l1.Constraints.size(); ++s)
  {
    const SparseRow& row = l1.Constraints[s];
    const double mu = dual.ConstraintDual(solution, s);
    for (int e = 0; e < row.Count; ++e)
    {
      rowResidual[row.Index[e]] += mu * row.Coefficient[e];
    }
  }
  double perturbation = 0;
  for (int q = 0; q < p; ++q)
  {
    if (!(std::abs(rowResidual[q]) <= 1e-6))
    {
      return false;
    }
    perturbation += std::abs(x[q] * rowResidual[q]);
  }
  for (const SparseRow& row : l1.Constraints)
  {
    if (row.Dot(x) < row.Target - 1e-9)
    {
      return false;
    }
  }
  return l1.Objective(x) <= dualObjective + perturbation + 1e-7 * dual.Scale;
}

// The same optimum through the dual program, which has one row per unknown (k - 2) instead
// of one per sample, so the simplex needs a few pivots instead of about as many as there are
// samples (measured about 10 times faster for n = 200, k = 7):
//   maximize sum_r Weight_r Target_r d_r + sum_s Target_s mu_s
//   subject to sum_r Weight_r d_r a_r + sum_s mu_s c_s = 0, -1 <= d_r <= 1, mu_s >= 0.
// CGAL's interface returns only the dual's variables, so x comes from complementary
// slackness. The x is accepted only with a certificate (feasible, and its objective equals
// the dual's, so it is optimal by weak duality); otherwise (degenerate programs, e.g. many
// equal samples) false without an error and the caller solves the primal.
bool SolveThroughDual(const L1Program& l1, std::vector<double>& x, int& variables, int& constraints)
{
  DualProgram dual;
  dual.Sign = LeastSquaresResidualSigns(l1);
  BuildDualProgram(l1, dual);
  variables = static_cast<int>(dual.Program.number_of_variables());
  constraints = static_cast<int>(dual.Program.number_of_constraints());
  std::string ignored;
  if (!SolveLinearProgram(dual.Program, ignored))
  {
    return false; // leave it to the primal
  }
  const std::vector<double>& solution = dual.Program.solution();
  double dualObjective = 0;
  return RecoverPrimalSolution(l1, dual, solution, x, dualObjective) &&
    HasOptimalityCertificate(l1, dual, solution, x, dualObjective);
}
// The height program of FitHeight in normalized values (a -> 0, b -> 1): its coefficients are
// then of order one whatever the units of the field, which GLPK (run unscaled by CGAL) needs.
struct NormalizedHeightProgram
{
  int Segments = 0;          // k
  bool Monotone = false;
  double MinimumStep = 0;    // delta, 0 when not monotone
  double EvenStep = 0;       // 1 / (k - 1)
  double TieBreakWeight = 0;
  std::vector<double> Alpha; // alpha_0 .. alpha_k+1; alpha_0 = alpha_1 = 0, alpha_k = alpha_k+1 = 1

  // Unknowns x_q = alpha_q+2 (q = 0..k-3); the fixed alpha_0, alpha_1, alpha_k, alpha_k+1
  // move to the targets.
  void AddTerm(SparseRow& row, int coefficient, double weight) const
  {
    if (coefficient >= 2 && coefficient < this->Segments)
    {
      row.Index[row.Count] = coefficient - 2;
      row.Coefficient[row.Count] = weight;
      ++row.Count;
    }
    else
    {
      row.Target -= weight * this->Alpha[coefficient];
    }
  }

  // The paper's L1 objective (section 4, step 2) over the interior samples, the monotonicity
  // constraints alpha_j+1 - alpha_j >= delta and the tie-break residuals.
  L1Program Build(
    const std::vector<double>& parameters, const std::vector<double>& values, double startValue, double range) const
  {
    const int k = this->Segments;
    L1Program program;
    program.Unknowns = k - 2;
    for (std::size_t i = 1; i + 1 < parameters.size(); ++i)
    {
      int first = 0;
      double w[3];
      UniformQuadraticBSpline::BasisWeights(k, parameters[i], first, w);
      SparseRow row;
      row.Target = (values[i] - startValue) / range;
      for (int m = 0; m < 3; ++m)
      {
        if (w[m] != 0.0)
        {
          this->AddTerm(row, first + m, w[m]);
        }
      }
      if (row.Count > 0) // else a sample at t = 0 or 1: nothing to fit
      {
        program.Residuals.push_back(row);
      }
    }
    if (this->Monotone)
    {
      // alpha_j+1 - alpha_j >= delta for j = 1..k-1.
      for (int j = 1; j < k; ++j)
      {
        SparseRow step;
        step.Target = this->MinimumStep;
        this->AddTerm(step, j + 1, 1.0);
        this->AddTerm(step, j, -1.0);
        program.Constraints.push_back(step);
      }
      if (this->TieBreakWeight > 0)
      {
        // TieBreakWeight * |evenStep - (alpha_j+1 - alpha_j)| for j = 1..k-1.
        for (int j = 1; j < k; ++j)
        {
          SparseRow spread;
          spread.Weight = this->TieBreakWeight;
          spread.Target = this->EvenStep;
          this->AddTerm(spread, j + 1, 1.0);
          this->AddTerm(spread, j, -1.0);
          program.Residuals.push_back(spread);
        }
      }
    }
    return program;
  }

  // GLPK meets constraints to its feasibility tolerance (1e-7), not exactly: restore every
  // step >= delta. Forward then backward keeps alpha_j >= (j - 1) delta and gives alpha_j <=
  // alpha_j+1 - delta, hence both, because (k - 1) delta < 1 (it changes nothing when the
  // solution is already feasible).
  void RestoreMinimumSteps()
  {
    const int k = this->Segments;
    std::vector<double>& alpha = this->Alpha;
    for (int j = 2; j < k; ++j)
    {
      alpha[j] = std::max(alpha[j], alpha[j - 1] + this->MinimumStep);
    }
    for (int j = k - 1; j >= 2; --j)
    {
      alpha[j] = std::min(alpha[j], alpha[j + 1] - this->MinimumStep);
    }
  }
};
// Solves the program of `height` (through the dual when asked, else or when the dual gives
// no certificate through the primal) into height.Alpha.
bool SolveHeightProgram(NormalizedHeightProgram& height, const std::vector<double>& parameters,
  const std::vector<double>& values, double startValue, double range, bool useDualProgram, HeightFit& fit,
  std::string& error)
{
  const int k = height.Segments;
  std::vector<double>& alpha = height.Alpha;
  const L1Program program = height.Build(parameters, values, startValue, range);
  std::vector<double> x;
  bool solved = false;
  if (useDualProgram)
  {
    solved = SolveThroughDual(program, x, fit.ProgramVariables, fit.ProgramConstraints);
    fit.SolvedThroughDual = solved;
  }
  if (!solved && !SolvePrimal(program, x, fit.ProgramVariables, fit.ProgramConstraints, error))
  {
    return false;
  }
  for (int j = 2; j < k; ++j)
  {
    alpha[j] = x[j - 2];
    if (!std::isfinite(alpha[j]))
    {
      error = "the linear program of the height fit returned a non-finite coefficient";
      return false;
    }
  }
  if (height.Monotone)
  {
    height.RestoreMinimumSteps();
  }
  return true;
}

// Back to field units; the ends are set, not computed, so they are exact. False when a
// monotone fit lost its strict steps to rounding.
bool StoreInFieldUnits(const std::vector<double>& alpha, double startValue, double endValue, bool monotone,
  UniformQuadraticBSpline& spline, std::string& error)
{
  const int k = static_cast<int>(alpha.size()) - 2;
  const double range = endValue - startValue;
  spline.Segments = k;
  spline.Dimension = 1;
  spline.Coefficients.resize(static_cast<std::size_t>(k + 2));
  spline.Coefficients[0] = spline.Coefficients[1] = startValue;
  spline.Coefficients[k] = spline.Coefficients[k + 1] = endValue;
  for (int j = 2; j < k; ++j)
  {
    spline.Coefficients[j] = startValue + range * alpha[j];
  }
  if (monotone)
  {
    for (int j = 1; j < k; ++j)
    {
      if (!(spline.Coefficients[j + 1] > spline.Coefficients[j]))
      {
        error = "the end values of the 1-cell piece are too close for a strictly increasing fit in double precision";
        return false;
      }
    }
  }
  return true;
}

// The normal equations of the planar curve fit for its free coefficients c_1..c_k (unknown
// j - 1), in coordinates relative to `origin`; c_0 and c_k+1 are the end points.
void AccumulateCurveNormalEquations(const std::vector<double>& parameters, const std::vector<double>& points,
  const double origin[2], int k, Eigen::MatrixXd& normal, Eigen::MatrixXd& rhs)
{
  const std::size_t count = parameters.size();
  const double end[2] = { points[2 * count - 2] - origin[0], points[2 * count - 1] - origin[1] };
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
}

// A ridge of 1e-6 of the mean diagonal pulls c_j towards the polyline at its Greville
// abscissa (j - 1/2) / k (see FitPlanarCurve in the header).
void AddGrevilleRidge(const std::vector<double>& parameters, const std::vector<double>& points,
  const double origin[2], int k, Eigen::MatrixXd& normal, Eigen::MatrixXd& rhs)
{
  const std::size_t count = parameters.size();
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
}
} // namespace

//------------------------------------------------------------------------------
void MonotoneBSplineFit::MeasureHeightErrors(
  const std::vector<double>& parameters, const std::vector<double>& values, HeightFit& fit)
{
  fit.L1Error = 0;
  fit.MaximumError = 0;
  for (std::size_t i = 1; i + 1 < parameters.size(); ++i)
  {
    const double e = std::abs(values[i] - fit.Spline.Value(parameters[i]));
    fit.L1Error += e;
    fit.MaximumError = std::max(fit.MaximumError, e);
  }
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

std::vector<double> MonotoneBSplineFit::ArcLengthAndRise(const std::vector<double>& points,
  const std::vector<double>& values, double startValue, double endValue, double maximumRiseRatio)
{
  std::vector<double> parameters = NormalizedArcLength(points);
  const std::size_t count = parameters.size();
  const double rise = endValue - startValue;
  if (count < 3 || values.size() != count || !(rise > 0) || !std::isfinite(rise))
  {
    return parameters;
  }
  // Each step's rise counts at most maximumRiseRatio times its share of the length: the
  // curve's speed then stays within a small factor of the path's, a jump of the values (noise
  // past the end value) leaves no long parameter gap without samples, where the planar curve
  // would be free to loop.
  std::vector<double> combined(count, 0.0);
  double highest = 0;
  for (std::size_t i = 1; i < count; ++i)
  {
    const double next = std::max(highest, std::clamp((values[i] - startValue) / rise, 0.0, 1.0));
    const double length = parameters[i] - parameters[i - 1];
    combined[i] = combined[i - 1] + length + std::min(next - highest, maximumRiseRatio * length);
    highest = next;
  }
  const double total = combined.back();
  if (!(total > 0))
  {
    return parameters;
  }
  for (std::size_t i = 1; i + 1 < count; ++i)
  {
    parameters[i] = combined[i] / total;
  }
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

  NormalizedHeightProgram height;
  height.Segments = k;
  height.Monotone = monotone;
  height.Alpha.assign(static_cast<std::size_t>(k + 2), 0.0);
  for (int j = k; j <= k + 1; ++j)
  {
    height.Alpha[j] = 1.0;
  }
  const double delta = monotone ? this->MinimumSlopeFraction / k : 0.0;
  height.MinimumStep = delta;
  height.EvenStep = 1.0 / (k - 1);
  height.TieBreakWeight = this->TieBreakWeight;
  fit.MinimumStep = delta * range;
  fit.ProgramVariables = 0;
  fit.ProgramConstraints = 0;
  fit.SolvedThroughDual = false;
  if (monotone && !(delta > 0 && delta * (k - 1) < 1.0))
  {
    error = "MinimumSlopeFraction must be in (0, k / (k - 1))";
    return false;
  }

  std::vector<double>& alpha = height.Alpha;
  if (k == 2)
  {
    // alpha_0 = alpha_1 = a, alpha_2 = alpha_3 = b: nothing left to fit.
  }
  else if (interiorCount == 0)
  {
    // No data between the ends: the evenly spaced coefficients (what the tie-break picks).
    for (int j = 2; j < k; ++j)
    {
      alpha[j] = (j - 1) * height.EvenStep;
    }
  }
  else if (!SolveHeightProgram(height, parameters, values, startValue, range, this->UseDualProgram, fit, error))
  {
    return false;
  }

  if (!StoreInFieldUnits(alpha, startValue, endValue, monotone, fit.Spline, error))
  {
    return false;
  }
  MeasureHeightErrors(parameters, values, fit);
  return true;
}

//------------------------------------------------------------------------------
bool MonotoneBSplineFit::FitPlanarCurve(
  const std::vector<double>& parameters, const std::vector<double>& points, PlanarCurveFit& fit,
  std::string& error) const
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

  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(k, k);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(k, 2);
  AccumulateCurveNormalEquations(parameters, points, origin, k, normal, rhs);
  AddGrevilleRidge(parameters, points, origin, k, normal, rhs);
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
