// The quadratic program behind the data-fitted 2-cell interiors (stage 4, MonotoneSibsonSurface::
// FitToSamples): minimize 1/2 x^T H x - g^T x subject to linear inequalities C x >= d, with H
// symmetric positive definite (a least-squares fit A^T A plus a smoothness energy plus a small
// ridge) and a point x_f known to satisfy every row (the paper's boundary-only surface).
//
// Solver: the alternating direction method of multipliers in the splitting of OSQP (Stellato et
// al., Math. Prog. Comp. 12, 2020): one sparse LDLT factorization of H + sigma I + rho C^T C
// (Eigen's SimplicialLDLT), then cheap iterations from x_f, rho rebalanced (and refactored) a few
// times.
// ADMM satisfies the rows only up to a tolerance, so the answer is then pulled towards x_f:
// x = x_f + t (x_admm - x_f) with the largest t in [0, 1] that keeps every row at or above its
// bound. The rows are linear, so t is a minimum over rows in closed form, and the result is
// feasible whatever the solver did (docs/Reconstruction.md, "Fitted interiors"). Rows the ADMM
// answer leaves below their bounds are first weighted and iterated on until they meet them
// (BoundRepairs), so that the pull is a rounding matter, not a loss of the fit. GLPK,
// the project's LP solver, has no quadratic objective, and an L1 fit as an LP with one slack per
// sample took 0.6 - 11 s per cell on this machine kind, against milliseconds here.
#pragma once

#include <Eigen/Sparse>

#include <string>
#include <vector>

namespace topospline
{
struct ConstrainedLeastSquaresOptions
{
  int MaximumIterations = 300;

  // Stop when every row is violated by at most this (in the row's own units, after rows are
  // scaled to unit norm) and the dual residual is small.
  double PrimalTolerance = 1e-5;
  double DualTolerance = 1e-5;

  // Iterations at which rho is rebalanced (when the residuals are out of balance by more than
  // 5x): the first, then every interval after it. Multiples of 10, when the residuals are read.
  int FirstRhoUpdate = 10;
  int RhoUpdateInterval = 30;

  // Rounds in which the rows the answer leaves below their bounds get BoundRepairWeight times
  // their rho and the iterations go on (at most BoundRepairIterations more each, until every
  // row meets its bound), before the pull towards x_f.
  int BoundRepairs = 3;
  int BoundRepairIterations = 100;
  double BoundRepairWeight = 10;

  // Return the starting point when the answer's objective is higher. Off when rows that are
  // only aimed at matter more than the objective (they are not in it).
  bool KeepStartIfLower = true;
};

struct ConstrainedLeastSquaresReport
{
  int Iterations = 0;
  bool Converged = false;       // the ADMM tolerances were met
  bool UnconstrainedFeasible = false; // the unconstrained minimizer met every row: it is the answer
  int BoundRepairs = 0;         // rounds that weighted rows left below their bounds (options' BoundRepairs)
  double PulledBack = 0;        // 1 - t: how far the answer was pulled towards x_f
  double Objective = 0;         // at the returned x
  double FeasibleObjective = 0; // at x_f
};

// Minimizes as above. `feasible` must satisfy every row (C feasible >= bounds); the returned x
// does too. ADMM aims at `targets` (>= bounds, row by row): the gap between the two absorbs its
// tolerance, so that the pull towards x_f is small. Returns false with a message on malformed
// input (sizes, a non-finite entry, an infeasible start, H not positive definite).
bool SolveConstrainedLeastSquares(const Eigen::SparseMatrix<double>& hessian, const Eigen::VectorXd& gradient,
  const Eigen::SparseMatrix<double>& constraints, const Eigen::VectorXd& bounds, const Eigen::VectorXd& targets,
  const Eigen::VectorXd& feasible,
  Eigen::VectorXd& solution, ConstrainedLeastSquaresReport& report, std::string& error,
  const ConstrainedLeastSquaresOptions& options = ConstrainedLeastSquaresOptions());
} // namespace topospline
