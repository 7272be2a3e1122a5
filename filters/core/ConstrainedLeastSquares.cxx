#include "ConstrainedLeastSquares.h"

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>

namespace topospline
{
namespace
{
double Objective(const Eigen::SparseMatrix<double>& h, const Eigen::VectorXd& g, const Eigen::VectorXd& x)
{
  return 0.5 * x.dot(h * x) - g.dot(x);
}

// The largest t in [0, 1] with C (x0 + t (x1 - x0)) >= d, given C x0 >= d.
double LargestFeasibleStep(const Eigen::VectorXd& atStart, const Eigen::VectorXd& atEnd, const Eigen::VectorXd& d)
{
  double t = 1;
  for (Eigen::Index r = 0; r < d.size(); ++r)
  {
    const double slack = atStart[r] - d[r];
    const double change = atEnd[r] - atStart[r];
    if (change < 0)
    {
      t = std::min(t, std::max(0.0, slack) / -change);
    }
  }
  return t;
}

// Whether row r of the scaled values `at` (C x, each row times rowScale) is below its bound.
bool BelowBound(const Eigen::VectorXd& at, const Eigen::VectorXd& rowScale, const Eigen::VectorXd& bounds, Eigen::Index r)
{
  return rowScale[r] > 0 && at[r] < rowScale[r] * bounds[r];
}

bool MeetsBounds(const Eigen::VectorXd& at, const Eigen::VectorXd& rowScale, const Eigen::VectorXd& bounds)
{
  for (Eigen::Index r = 0; r < at.size(); ++r)
  {
    if (BelowBound(at, rowScale, bounds, r))
    {
      return false;
    }
  }
  return true;
}

bool AllFinite(const Eigen::SparseMatrix<double>& m)
{
  for (Eigen::Index k = 0; k < m.nonZeros(); ++k)
  {
    if (!std::isfinite(m.valuePtr()[k]))
    {
      return false;
    }
  }
  return true;
}
} // namespace

bool SolveConstrainedLeastSquares(const Eigen::SparseMatrix<double>& hessian, const Eigen::VectorXd& gradient,
  const Eigen::SparseMatrix<double>& constraints, const Eigen::VectorXd& bounds, const Eigen::VectorXd& targets,
  const Eigen::VectorXd& feasible, Eigen::VectorXd& solution, ConstrainedLeastSquaresReport& report,
  std::string& error, const ConstrainedLeastSquaresOptions& options)
{
  report = ConstrainedLeastSquaresReport();
  const Eigen::Index n = hessian.rows();
  const Eigen::Index m = constraints.rows();
  if (hessian.cols() != n || gradient.size() != n || feasible.size() != n || constraints.cols() != n ||
    bounds.size() != m || targets.size() != m)
  {
    error = "constrained least squares: the sizes do not match";
    return false;
  }
  if (!AllFinite(hessian) || !AllFinite(constraints) || !gradient.allFinite() || !bounds.allFinite() ||
    !targets.allFinite() || !feasible.allFinite())
  {
    error = "constrained least squares: a non-finite entry";
    return false;
  }
  const Eigen::VectorXd atFeasible = constraints * feasible;
  if (m > 0 && (atFeasible - bounds).minCoeff() < 0)
  {
    error = "constrained least squares: the starting point violates a row";
    return false;
  }
  report.FeasibleObjective = Objective(hessian, gradient, feasible);

  // Rows scaled to unit norm, so that one rho and one tolerance fit them all.
  Eigen::VectorXd rowNorm = Eigen::VectorXd::Zero(m);
  for (Eigen::Index k = 0; k < constraints.outerSize(); ++k)
  {
    for (Eigen::SparseMatrix<double>::InnerIterator it(constraints, k); it; ++it)
    {
      rowNorm[it.row()] += it.value() * it.value();
    }
  }
  Eigen::VectorXd rowScale(m);
  for (Eigen::Index r = 0; r < m; ++r)
  {
    rowScale[r] = rowNorm[r] > 0 ? 1 / std::sqrt(rowNorm[r]) : 0;
  }
  const Eigen::SparseMatrix<double> c = rowScale.asDiagonal() * constraints;
  const Eigen::VectorXd lower = rowScale.cwiseProduct(targets.cwiseMax(bounds));

  // ADMM (OSQP's splitting): x-update through K = H + sigma I + rho C^T C, z = projection of
  // C x onto {z >= lower}, y the multipliers; over-relaxation alpha. It starts from x_f: starting
  // from the unconstrained minimizer cost a factorization of H per call and saved no iterations
  // (on the Rainier crop at 2 % it met every row in none of the 54 fits). It is tried at the end
  // instead, when no row is active at the ADMM answer: if it meets every row it is the answer.
  const auto tryUnconstrained = [&](Eigen::VectorXd& x) {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> unconstrained(hessian);
    if (unconstrained.info() != Eigen::Success)
    {
      error = "constrained least squares: the objective is not positive definite";
      return false;
    }
    const Eigen::VectorXd candidate = unconstrained.solve(gradient);
    if (m == 0 || (c * candidate - lower).minCoeff() >= 0)
    {
      x = candidate;
      report.UnconstrainedFeasible = report.Converged = true;
    }
    return true;
  };
  Eigen::VectorXd x = feasible;
  Eigen::VectorXd cx = c * x;
  if (m == 0)
  {
    if (!tryUnconstrained(x))
    {
      return false;
    }
  }
  else
  {
    const double scale = std::max(1e-300, hessian.diagonal().cwiseAbs().mean());
    const double sigma = 1e-6 * scale;
    const double alpha = 1.6;
    double rho = 0.1 * scale;
    Eigen::SparseMatrix<double> identity(n, n);
    identity.setIdentity();
    const Eigen::SparseMatrix<double> ct = c.transpose();
    // Each row's rho is rho times its weight (1 but where a bound repair raised it, below).
    Eigen::VectorXd weight = Eigen::VectorXd::Ones(m);
    Eigen::SparseMatrix<double> ctc = ct * c;
    // Every rho and weight gives the same pattern: one ordering and symbolic analysis serve all.
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> k;
    k.analyzePattern(hessian + sigma * identity + rho * ctc);
    auto factor = [&]() {
      k.factorize(hessian + sigma * identity + rho * ctc);
      return k.info() == Eigen::Success;
    };
    if (!factor())
    {
      error = "constrained least squares: the ADMM system is singular";
      return false;
    }
    Eigen::VectorXd z = cx.cwiseMax(lower);
    Eigen::VectorXd y = Eigen::VectorXd::Zero(m);
    const double tolerance = options.PrimalTolerance * std::max(1.0, lower.cwiseAbs().maxCoeff());
    // Iterations first to last (the count goes on across calls); false if a refactorization fails.
    bool boundsAsked = false; // converged only where every row meets its bound too
    const auto iterate = [&](int first, int last) {
      for (int iteration = first; iteration <= last; ++iteration)
      {
        report.Iterations = iteration;
        const Eigen::VectorXd xTilde = k.solve(sigma * x + gradient + ct * (rho * weight.cwiseProduct(z) - y));
        const Eigen::VectorXd zTilde = c * xTilde;
        x = alpha * xTilde + (1 - alpha) * x;
        const Eigen::VectorXd zRelaxed = alpha * zTilde + (1 - alpha) * z;
        const Eigen::VectorXd zNext = (zRelaxed + y.cwiseQuotient(rho * weight)).cwiseMax(lower);
        y += (rho * weight).cwiseProduct(zRelaxed - zNext);
        z = zNext;
        if (iteration % 10 != 0 && iteration != last)
        {
          continue;
        }
        cx = c * x;
        // OSQP's primal residual |C x - z|: it also asks that a row held by its multiplier be at
        // its bound. The violation alone let ADMM stop after 60 iterations 7e-3 above the optimum
        // on small random programs (TestConstrainedLeastSquares).
        const double primal = (cx - z).cwiseAbs().maxCoeff();
        const Eigen::VectorXd hx = hessian * x;
        const double dual = (hx - gradient + ct * y).cwiseAbs().maxCoeff();
        const double dualScale = std::max({ 1.0, gradient.cwiseAbs().maxCoeff(), hx.cwiseAbs().maxCoeff() });
        if (primal <= tolerance && dual <= options.DualTolerance * dualScale && (!boundsAsked || MeetsBounds(cx, rowScale, bounds)))
        {
          report.Converged = true;
          break;
        }
        // Residual balancing: rho up when the rows lag, down when optimality does. The first
        // rebalance comes early (a poor starting rho otherwise costs a hundred iterations), the
        // later ones every RhoUpdateInterval iterations, each a new factorization.
        const double primalRelative = primal / std::max({ 1e-300, cx.cwiseAbs().maxCoeff(), z.cwiseAbs().maxCoeff() });
        const double dualRelative = dual / dualScale;
        const double ratio = std::sqrt(primalRelative / std::max(1e-300, dualRelative));
        const bool rebalance = iteration == options.FirstRhoUpdate ||
          (iteration > options.FirstRhoUpdate && (iteration - options.FirstRhoUpdate) % options.RhoUpdateInterval == 0);
        if ((ratio > 5 || ratio < 0.2) && rebalance)
        {
          rho = std::clamp(rho * ratio, 1e-6 * scale, 1e6 * scale);
          if (!factor())
          {
            error = "constrained least squares: the ADMM system is singular";
            return false;
          }
        }
      }
      return true;
    };
    if (!iterate(1, options.MaximumIterations))
    {
      return false;
    }
    // ADMM meets the rows only to its tolerance, which scales with the largest row value: on a
    // terrain in metres, rows that mix free ordinates with fixed heights of thousands of metres
    // (z11 - z00 with z00 on the boundary) set it 1e3 times above the room between the bound and
    // the target of a row that the start meets with little to spare, and the answer then missed
    // that row's bound (a Saint Helens crop: two rows of 2 347, and the pull towards x_f gave
    // back 82 % of the fit). The rows left below their bounds get BoundRepairWeight times the
    // rho of the others (one factorization, the same pattern), and the iterations go on from
    // where they stopped until every row meets its bound too, a few rounds at most. (Aiming
    // such rows higher instead cut the start off where many rows bind, and the fit fell back on
    // it: 7 of 100 small programs of TestConstrainedLeastSquares's kind.)
    for (int repair = 0; repair < options.BoundRepairs; ++repair)
    {
      const Eigen::VectorXd at = c * x;
      bool missed = false;
      for (Eigen::Index r = 0; r < m; ++r)
      {
        if (BelowBound(at, rowScale, bounds, r))
        {
          weight[r] *= options.BoundRepairWeight;
          missed = true;
        }
      }
      if (!missed)
      {
        break;
      }
      ctc = ct * weight.asDiagonal() * c;
      if (!factor())
      {
        error = "constrained least squares: the ADMM system is singular";
        return false;
      }
      ++report.BoundRepairs;
      report.Converged = false;
      boundsAsked = true;
      if (!iterate(report.Iterations + 1, report.Iterations + options.BoundRepairIterations))
      {
        return false;
      }
    }
    if ((c * x - lower).minCoeff() > 0 && !tryUnconstrained(x))
    {
      return false;
    }
  }

  // Exactly feasible: pull towards the feasible start as little as every row allows.
  const Eigen::VectorXd atSolution = constraints * x;
  double t = m > 0 ? LargestFeasibleStep(atFeasible, atSolution, bounds) : 1.0;
  solution = feasible + t * (x - feasible);
  // Rounding in the step can leave a row a few ulps short: step back until none is.
  for (int attempt = 0; attempt < 8 && m > 0 && (constraints * solution - bounds).minCoeff() < 0; ++attempt)
  {
    t *= 0.5;
    solution = feasible + t * (x - feasible);
  }
  if (m > 0 && (constraints * solution - bounds).minCoeff() < 0)
  {
    t = 0;
    solution = feasible;
  }
  report.PulledBack = 1 - t;
  report.Objective = Objective(hessian, gradient, solution);
  if (options.KeepStartIfLower && report.Objective > report.FeasibleObjective)
  {
    solution = feasible;
    report.Objective = report.FeasibleObjective;
    report.PulledBack = 1;
  }
  return true;
}
} // namespace topospline
