// MonotoneSibsonSurface::FitToSamples: the data-fitted interior of a 2-cell (the faithful-surface
// extension of the paper's section 5.2; docs/Reconstruction.md, "Fitted interiors").
// The element is linear in its corner data (z, p, q), so F at a sample, the thin-plate energy and
// every monotonicity condition are linear or quadratic in the free ordinates: a small quadratic
// program per cell (ConstrainedLeastSquares), started from the paper's surface.
#include "MonotoneSibsonSurface.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <vector>

namespace topospline
{
namespace
{
// A cell's 12 corner data as one vector: z of V00 V10 V11 V01, then p, then q.
constexpr int LocalData = 12;
using LocalVector = Eigen::Matrix<double, LocalData, 1>;
using LocalMatrix = Eigen::Matrix<double, LocalData, LocalData>;

SibsonCellData UnitData(int m)
{
  SibsonCellData data;
  (m < 4 ? data.Z : m < 8 ? data.P : data.Q)[m % 4] = 1;
  return data;
}

// The element with one corner datum 1 and the others 0, for each of the 12: F of any cell is
// their combination with the cell's data as weights.
const std::array<MonotoneSibsonPatch, LocalData>& UnitPatches()
{
  static const std::array<MonotoneSibsonPatch, LocalData> patches = []() {
    std::array<MonotoneSibsonPatch, LocalData> result;
    for (int m = 0; m < LocalData; ++m)
    {
      result[m].SetData(UnitData(m));
    }
    return result;
  }();
  return patches;
}

// Thin-plate energy of one element in its local coordinates, int F_XX^2 + 2 F_XY^2 + F_YY^2,
// as a quadratic form of the corner data. The second derivatives of a cubic are linear on each
// sub-triangle, so the edge-midpoint rule (exact for quadratics) integrates the squares exactly,
// and central differences of the (quadratic) gradient give them exactly up to rounding.
const LocalMatrix& ThinPlateEnergy()
{
  static const LocalMatrix energy = []() {
    const auto& patches = UnitPatches();
    LocalMatrix k = LocalMatrix::Zero();
    const double step = 1e-3;
    for (int t = 0; t < 4; ++t)
    {
      const auto triangle = static_cast<SibsonTriangle>(t);
      double v[3][2];
      MonotoneSibsonPatch::GetTriangleVertices(triangle, v);
      for (int e = 0; e < 3; ++e)
      {
        const double x = 0.5 * (v[e][0] + v[(e + 1) % 3][0]);
        const double y = 0.5 * (v[e][1] + v[(e + 1) % 3][1]);
        Eigen::Matrix<double, 3, LocalData> hessians; // F_XX, sqrt(2) F_XY, F_YY per datum
        for (int m = 0; m < LocalData; ++m)
        {
          double value, gxPlus[2], gxMinus[2], gyPlus[2], gyMinus[2];
          patches[m].EvaluateTriangle(triangle, x + step, y, value, gxPlus);
          patches[m].EvaluateTriangle(triangle, x - step, y, value, gxMinus);
          patches[m].EvaluateTriangle(triangle, x, y + step, value, gyPlus);
          patches[m].EvaluateTriangle(triangle, x, y - step, value, gyMinus);
          hessians(0, m) = (gxPlus[0] - gxMinus[0]) / (2 * step);
          hessians(1, m) = std::sqrt(2.0) * 0.5 * ((gxPlus[1] - gxMinus[1]) + (gyPlus[0] - gyMinus[0])) / (2 * step);
          hessians(2, m) = (gyPlus[1] - gyMinus[1]) / (2 * step);
        }
        // Every sub-triangle has area 1/4; three points of weight 1/3 each.
        k += (0.25 / 3.0) * hessians.transpose() * hessians;
      }
    }
    return k;
  }();
  return energy;
}

// The 12 weights of F at local (X, Y): F = sum_m weight_m * datum_m.
LocalVector EvaluationWeights(double X, double Y)
{
  LocalVector weights;
  MonotoneSibsonPatch::EvaluateMany(UnitPatches().data(), LocalData, X, Y, weights.data());
  return weights;
}

// Linear forms of the conditions of one cell in its 12 data: (C0) z11 - z00, and 3 (z11 - z00)
// minus the left sides of (C2) and (C3), taken from the patch's own definitions (all linear,
// so their values on the unit data are the coefficients).
std::array<LocalVector, 3> CellConditionForms()
{
  std::array<LocalVector, 3> forms;
  for (int m = 0; m < LocalData; ++m)
  {
    const SibsonCellData unit = UnitData(m);
    const double rise = unit.Z[2] - unit.Z[0];
    forms[0][m] = rise;
    forms[1][m] = 3 * rise - ConditionC2LeftSide(unit);
    forms[2][m] = 3 * rise - ConditionC3LeftSide(unit);
  }
  return forms;
}
} // namespace

// Per node, the unknown holding its z, p and q, or -1 where the boundary fixes it.
struct MonotoneSibsonSurface::FreeOrdinates
{
  std::vector<int> Z, P, Q;
  int Count = 0;
};

MonotoneSibsonSurface::FreeOrdinates MonotoneSibsonSurface::NumberFreeOrdinates() const
{
  FreeOrdinates free;
  const int n = this->N;
  const int nodes = (n + 1) * (n + 1);
  free.Z.assign(nodes, -1);
  free.P.assign(nodes, -1);
  free.Q.assign(nodes, -1);
  for (int j = 0; j <= n; ++j)
  {
    for (int i = 0; i <= n; ++i)
    {
      const int k = this->Node(i, j);
      const bool bottomOrTop = j == 0 || j == n;
      const bool leftOrRight = i == 0 || i == n;
      if (!bottomOrTop && !leftOrRight)
      {
        free.Z[k] = free.Count++;
        free.P[k] = free.Count++;
        free.Q[k] = free.Count++;
      }
      else if (bottomOrTop && !leftOrRight)
      {
        free.Q[k] = free.Count++; // p runs along the side
      }
      else if (leftOrRight && !bottomOrTop)
      {
        free.P[k] = free.Count++;
      }
    }
  }
  return free;
}

void MonotoneSibsonSurface::MeasureResiduals(
  const std::vector<SurfaceSample>& samples, double& maximum, double& rms) const
{
  maximum = rms = 0;
  std::vector<double> values;
  this->EvaluateSamples(samples, values);
  for (std::size_t k = 0; k < samples.size(); ++k)
  {
    const double residual = values[k] - samples[k].Value;
    maximum = std::max(maximum, std::abs(residual));
    rms += residual * residual;
  }
  rms = samples.empty() ? 0 : std::sqrt(rms / samples.size());
}

// The quadratic program of one fit, assembled in the free ordinates: an objective
// 1/2 x^T H x - g^T x (from triplets) and rows form . x + constant >= target.
struct MonotoneSibsonSurface::FitProblem
{
  std::vector<Eigen::Triplet<double>> HessianEntries;
  Eigen::VectorXd Gradient;
  Eigen::VectorXd Feasible; // the paper's surface
  std::vector<Eigen::Triplet<double>> RowEntries;
  std::vector<double> RowConstant, RowTarget;
  std::vector<char> RowEssential; // held exactly (the sufficient conditions), or only aimed at

  // One grid cell's part of a row: form . (cell data), the data given as unknown indices (-1:
  // fixed, with the value in `Fixed`).
  struct CellTerm
  {
    const int* Unknown;
    const double* Fixed;
    const LocalVector& Form;
  };

  // Adds the row: the sum of the terms >= target. A row without unknowns is a constant: left out.
  void AddRow(std::initializer_list<CellTerm> terms, double target, bool essential)
  {
    double constant = 0;
    bool anyUnknown = false;
    const int row = static_cast<int>(this->RowConstant.size());
    for (const CellTerm& term : terms)
    {
      for (int m = 0; m < LocalData; ++m)
      {
        if (term.Form[m] == 0)
        {
          continue;
        }
        if (term.Unknown[m] >= 0)
        {
          this->RowEntries.emplace_back(row, term.Unknown[m], term.Form[m]); // repeated entries add up
          anyUnknown = true;
        }
        else
        {
          constant += term.Form[m] * term.Fixed[m];
        }
      }
    }
    if (anyUnknown)
    {
      this->RowConstant.push_back(constant);
      this->RowTarget.push_back(target);
      this->RowEssential.push_back(essential ? 1 : 0);
    }
  }
};

void MonotoneSibsonSurface::AssembleFit(const FreeOrdinates& free, const std::vector<SurfaceSample>& samples,
  const MonotoneSurfaceFitOptions& options, FitProblem& problem) const
{
  const int n = this->N;
  // Per grid cell: the normal equations of its samples in its 12 data.
  std::vector<LocalMatrix> normal(static_cast<std::size_t>(n) * n, LocalMatrix::Zero());
  std::vector<LocalVector> moment(static_cast<std::size_t>(n) * n, LocalVector::Zero());
  for (const SurfaceSample& sample : samples)
  {
    int i, j;
    double X, Y;
    this->Locate(sample.U, sample.V, i, j, X, Y);
    const LocalVector w = EvaluationWeights(X, Y);
    normal[j * n + i].selfadjointView<Eigen::Lower>().rankUpdate(w);
    moment[j * n + i] += sample.Value * w;
  }
  // The thin-plate energy in (u, v) is N^2 times the sum of the local ones; its weight is per
  // sample, so that the balance with the data does not depend on how many the cell has.
  const LocalMatrix& energy = ThinPlateEnergy();
  const double mu = options.Smoothness * static_cast<double>(samples.size()) * n * n;
  std::vector<double> stiffness(static_cast<std::size_t>(n) * n, 1.0);
  for (const MonotoneSurfaceFitOptions::StiffSpot& spot : options.StiffSpots)
  {
    const double r = options.StiffRadius;
    const double x = spot.U * n, y = spot.V * n;
    for (int j = std::max(0, static_cast<int>(std::floor(y - r))); j < std::min(n, static_cast<int>(std::ceil(y + r))); ++j)
    {
      for (int i = std::max(0, static_cast<int>(std::floor(x - r))); i < std::min(n, static_cast<int>(std::ceil(x + r))); ++i)
      {
        if (std::hypot(i + 0.5 - x, j + 0.5 - y) <= r)
        {
          stiffness[j * n + i] = std::max(stiffness[j * n + i], spot.Factor);
        }
      }
    }
  }
  const std::array<LocalVector, 3> conditions = CellConditionForms();
  const double rise = this->Z[this->Node(n, n)] - this->Z[this->Node(0, 0)];
  const double margin = options.MarginFraction * std::max(0.0, rise) / n;
  problem.Gradient = Eigen::VectorXd::Zero(free.Count);
  problem.Feasible.resize(free.Count);
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      // The cell's data as d = E x + d0: E picks unknowns, d0 holds the fixed data.
      int unknown[LocalData];
      double fixed[LocalData];
      this->CellUnknowns(free, i, j, unknown, fixed);
      LocalVector d0;
      for (int m = 0; m < LocalData; ++m)
      {
        d0[m] = unknown[m] >= 0 ? 0.0 : fixed[m];
        if (unknown[m] >= 0)
        {
          problem.Feasible[unknown[m]] = fixed[m];
        }
      }
      // (E x + d0)^T (M + mu K) (E x + d0) - 2 b^T (E x + d0), M and b the normal equations.
      const LocalMatrix cellMatrix =
        LocalMatrix(normal[j * n + i].selfadjointView<Eigen::Lower>()) + mu * stiffness[j * n + i] * energy;
      const LocalVector cellGradient = moment[j * n + i] - cellMatrix * d0;
      for (int a = 0; a < LocalData; ++a)
      {
        if (unknown[a] < 0)
        {
          continue;
        }
        problem.Gradient[unknown[a]] += cellGradient[a];
        for (int b = 0; b < LocalData; ++b)
        {
          if (unknown[b] >= 0 && cellMatrix(a, b) != 0)
          {
            problem.HessianEntries.emplace_back(unknown[a], unknown[b], cellMatrix(a, b));
          }
        }
      }
      for (const LocalVector& form : conditions)
      {
        problem.AddRow({ { unknown, fixed, form } }, margin, true);
      }
    }
  }
  this->AddNodeRows(free, margin, options.IncreasingAlongAxes, problem);
  // The orders between samples: F(upper) - F(lower), a row over the two samples' grid cells.
  for (const MonotoneSurfaceFitOptions::SampleOrder& order : options.SampleOrders)
  {
    if (order.Lower < 0 || order.Upper < 0 || order.Lower >= static_cast<int>(samples.size()) ||
      order.Upper >= static_cast<int>(samples.size()))
    {
      continue;
    }
    int unknown[2][LocalData];
    double fixed[2][LocalData];
    LocalVector form[2];
    const int ends[2] = { order.Upper, order.Lower };
    for (int e = 0; e < 2; ++e)
    {
      int i, j;
      double X, Y;
      this->Locate(samples[ends[e]].U, samples[ends[e]].V, i, j, X, Y);
      this->CellUnknowns(free, i, j, unknown[e], fixed[e]);
      form[e] = (e == 0 ? 1.0 : -1.0) * EvaluationWeights(X, Y);
    }
    problem.AddRow({ { unknown[0], fixed[0], form[0] }, { unknown[1], fixed[1], form[1] } }, order.Margin, false);
  }
}

void MonotoneSibsonSurface::CellUnknowns(
  const FreeOrdinates& free, int i, int j, int unknown[LocalData], double fixed[LocalData]) const
{
  int nodes[4];
  this->CellNodes(i, j, nodes);
  for (int v = 0; v < 4; ++v)
  {
    const int k = nodes[v];
    const int unknowns[3] = { free.Z[k], free.P[k], free.Q[k] };
    const double values[3] = { this->Z[k], this->P[k], this->Q[k] };
    for (int c = 0; c < 3; ++c)
    {
      unknown[4 * c + v] = unknowns[c];
      fixed[4 * c + v] = values[c];
    }
  }
}

void MonotoneSibsonSurface::AddNodeRows(
  const FreeOrdinates& free, double margin, bool increasingAlongAxes, FitProblem& problem) const
{
  const int nodes = (this->N + 1) * (this->N + 1);
  // p + q at every node with a free derivative.
  for (int k = 0; k < nodes; ++k)
  {
    if (free.P[k] < 0 && free.Q[k] < 0)
    {
      continue;
    }
    const int unknown[LocalData] = { -1, -1, -1, -1, free.P[k], -1, -1, -1, free.Q[k], -1, -1, -1 };
    const double fixed[LocalData] = { 0, 0, 0, 0, this->P[k], 0, 0, 0, this->Q[k], 0, 0, 0 };
    LocalVector form = LocalVector::Zero();
    form[4] = form[8] = 1;
    problem.AddRow({ { unknown, fixed, form } }, margin, true);
  }
  // p >= 0 and q >= 0 at every free derivative: F increasing along u and along v, as its four
  // sides are (minimum at (0,0), saddles at (1,0) and (0,1), maximum at (1,1)). Not needed for
  // the guarantee, which the rows above give, so these rows are aimed at but not enforced
  // exactly: they keep the fit from troughs and ridges the data's noise would put across the
  // cell, which sampled at the vertices show as spurious critical points.
  for (int k = 0; increasingAlongAxes && k < nodes; ++k)
  {
    for (const int u : { free.P[k], free.Q[k] })
    {
      if (u >= 0)
      {
        const int unknown[LocalData] = { -1, -1, -1, -1, u, -1, -1, -1, -1, -1, -1, -1 };
        const double fixed[LocalData] = {};
        LocalVector form = LocalVector::Zero();
        form[4] = 1;
        problem.AddRow({ { unknown, fixed, form } }, 0.0, false);
      }
    }
  }
}

bool MonotoneSibsonSurface::SolveFit(const FitProblem& problem, const MonotoneSurfaceFitOptions& options,
  Eigen::VectorXd& solution, std::string& error)
{
  const Eigen::Index count = problem.Gradient.size();
  Eigen::SparseMatrix<double> hessian(count, count);
  hessian.setFromTriplets(problem.HessianEntries.begin(), problem.HessianEntries.end());
  // A ridge far below the data and energy terms: positive definite whatever the samples.
  const double ridge = 1e-10 * std::max(1e-300, hessian.diagonal().cwiseAbs().maxCoeff());
  for (Eigen::Index u = 0; u < count; ++u)
  {
    hessian.coeffRef(u, u) += ridge;
  }
  const int rows = static_cast<int>(problem.RowConstant.size());
  this->Fit.Rows = rows;
  Eigen::SparseMatrix<double> constraints(rows, count);
  constraints.setFromTriplets(problem.RowEntries.begin(), problem.RowEntries.end());
  // Row values C x + constant: the solver aims at the target, or at what the paper's surface
  // has where that is less (the start must meet the targets, or they may be infeasible
  // together); the hard bound is half of it, room for the solver's tolerance. Rows only aimed
  // at have no bound.
  const Eigen::VectorXd atFeasible = constraints * problem.Feasible;
  Eigen::VectorXd bounds(rows), targets(rows);
  for (int r = 0; r < rows; ++r)
  {
    const double constant = problem.RowConstant[r];
    if (!problem.RowEssential[r])
    {
      targets[r] = problem.RowTarget[r] - constant;
      bounds[r] = -std::numeric_limits<double>::max();
      continue;
    }
    const double target = std::min(problem.RowTarget[r], atFeasible[r] + constant);
    targets[r] = target - constant;
    bounds[r] = (target > 0 ? 0.5 * target : target) - constant;
  }
  if (!SolveConstrainedLeastSquares(hessian, problem.Gradient, constraints, bounds, targets, problem.Feasible,
        solution, this->Fit.Solver, error, options.Solver))
  {
    error = "fit: " + error;
    return false;
  }
  return true;
}

bool MonotoneSibsonSurface::FitToSamples(
  const std::vector<SurfaceSample>& samples, std::string& error, const MonotoneSurfaceFitOptions& options)
{
  this->Fit = MonotoneSurfaceFitReport();
  this->Fit.Samples = static_cast<int>(samples.size());
  const int n = this->N;
  if (n < 1 || this->Z.size() != static_cast<std::size_t>(n + 1) * (n + 1))
  {
    error = "fit: the surface has not been built";
    return false;
  }
  for (const SurfaceSample& sample : samples)
  {
    if (!std::isfinite(sample.U) || !std::isfinite(sample.V) || !std::isfinite(sample.Value))
    {
      error = "fit: a sample is not finite";
      return false;
    }
  }
  this->MeasureResiduals(samples, this->Fit.PaperMaximumResidual, this->Fit.PaperRMSResidual);
  this->Fit.MaximumResidual = this->Fit.PaperMaximumResidual;
  this->Fit.RMSResidual = this->Fit.PaperRMSResidual;
  const FreeOrdinates free = this->NumberFreeOrdinates();
  this->Fit.Unknowns = free.Count;
  if (samples.empty() || free.Count == 0)
  {
    return true;
  }
  FitProblem problem;
  this->AssembleFit(free, samples, options, problem);
  Eigen::VectorXd solution;
  if (!this->SolveFit(problem, options, solution, error))
  {
    return false;
  }

  // Apply, and keep it only if it is at least as close to the samples and passes the check.
  const std::vector<double> paperZ = this->Z, paperP = this->P, paperQ = this->Q;
  for (int k = 0; k < (n + 1) * (n + 1); ++k)
  {
    for (const auto& [unknown, data] : { std::make_pair(&free.Z, &this->Z), std::make_pair(&free.P, &this->P),
           std::make_pair(&free.Q, &this->Q) })
    {
      if ((*unknown)[k] >= 0)
      {
        (*data)[k] = solution[(*unknown)[k]];
      }
    }
  }
  double maximum, rms;
  this->MeasureResiduals(samples, maximum, rms);
  if (this->CountViolatingCells() > 0 || !(rms <= options.AcceptedResidualGrowth * this->Fit.PaperRMSResidual))
  {
    this->Z = paperZ;
    this->P = paperP;
    this->Q = paperQ;
    return true;
  }
  this->Fit.Fitted = true;
  this->Fit.MaximumResidual = maximum;
  this->Fit.RMSResidual = rms;
  return true;
}
} // namespace topospline
