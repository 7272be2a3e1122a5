// Stage 4 of the paper (section 5.2): a C1 piecewise cubic surface on the unit square that
// interpolates four monotone boundary curves and has no critical point inside, built from
// "modified Sibson" elements (MonotoneSibsonPatch.h) on a uniform N x N grid: the boundary
// Beziers fix the values and tangential derivatives at the boundary nodes, a Laplace equation
// the interior values, and the free derivatives are chosen (and values moved where needed) so
// that every cell meets the patch's sufficient monotonicity conditions (docs/Algorithms.md, 1.4).
#pragma once

#include "ConstrainedLeastSquares.h"
#include "MonotoneSibsonPatch.h"

#include <array>
#include <string>
#include <vector>

namespace topospline
{
// One cubic Bezier segment of a boundary height function: control values c0..c3.
using CubicHeightSegment = std::array<double, 4>;
using BezierSide = std::vector<CubicHeightSegment>;

// Splits every segment of `side` into targetCount / side.size() equal parameter pieces, so that
// the side has `targetCount` segments describing exactly the same function. The grid is
// uniform, so the split must be uniform too (otherwise the parameter speed, hence the
// tangential derivative at the grid nodes, would jump): targetCount must be a multiple of
// side.size(). Returns false (and leaves `result` empty) otherwise.
bool SubdivideSide(const BezierSide& side, int targetCount, BezierSide& result);

// The smallest count all four sides can be uniformly subdivided to: the least common multiple
// of their segment counts (0 if a side is empty).
int CommonSegmentCount(const BezierSide& bottom, const BezierSide& right, const BezierSide& top,
  const BezierSide& left);

// Boundary of the unit square; every side is oriented from its lower corner to its upper one
// and has the same number N of segments, segment j covering [j/N, (j+1)/N]:
//   Bottom (0,0)->(1,0), Right (1,0)->(1,1), Top (0,1)->(1,1), Left (0,0)->(0,1)
// (listed in the order of TwoCellSides, counter-clockwise, though Top and Left run against it).
// Corners: minimum (0,0), saddles (1,0) and (0,1), maximum (1,1). Consecutive segments must
// share their end value and (scaled) end derivative, 3 (c3 - c2) = 3 (c1' - c0'), and the
// sides must agree at the corners.
struct MonotoneSurfaceBoundary
{
  BezierSide Bottom;
  BezierSide Right;
  BezierSide Top;
  BezierSide Left;
};

// SubdivideSide on all four sides (a side already at targetCount is copied as it is).
bool SubdivideBoundary(const MonotoneSurfaceBoundary& boundary, int targetCount, MonotoneSurfaceBoundary& result);

struct MonotoneSurfaceOptions
{
  // Mismatches between the sides at shared points (values and scaled derivatives) up to this
  // fraction of the value range are averaged away; larger ones are an error.
  double ConsistencyTolerance = 1e-9;
  // ... and up to this fraction of the largest |value| on the boundary (rounding, which a
  // nearly flat cell's own range does not bound), as long as that stays within
  // RoundingShareOfRange of the range: in a field that varies by 1e-13 of its magnitude the
  // sides differ by real values, not rounding. 64 ulps are always allowed.
  double RoundingTolerance = 0;
  double RoundingShareOfRange = 0.1;
  // Lower bound sigma of p + q at interior nodes (and at boundary nodes whose tangential
  // derivative is below sigma), as this fraction of the smallest per-cell spare rise.
  double MinimumSlopeFraction = 0.1;
  // Fraction of the rise of each cell kept free when limiting derivatives (per cell, then per
  // diagonal relative to the best achievable spare rise).
  double LimiterMargin = 0.1;
  // Share of a diagonal's spare rise that every cell of it gets on top of its requirement
  // when values have to be moved.
  double RiseShare = 0.05;
  // Rounds of the per-cell derivative limiter (keeps the Laplace values where it can) and of
  // the per-diagonal one (makes every diagonal fixable); if the latter does not settle, all
  // free derivatives take the minimal choice, which always works when anything does.
  int CellLimiterSweeps = 8;
  // Cross-boundary derivatives: 0 (a flat valley floor or ridge top along the 1-cells, as a
  // smooth field has there; raised only where the tangential derivative vanishes) instead of
  // the one-sided difference into the interior values, which makes a crease whose sampling
  // shows spurious critical points along the 1-cells.
  bool FlatAcrossBoundary = false;
  int DiagonalLimiterRounds = 8;
};

// What the construction had to do, for the filter's reports.
struct MonotoneSurfaceReport
{
  int LinearizedDiagonals = 0;  // the paper's fallback: Laplace values not increasing
  int FlatDiagonals = 0;        // diagonals whose boundary ends tie within rounding (infeasible, built flat)
  int LimitedNodes = 0;         // nodes whose estimated derivatives were scaled down
  int AdjustedDiagonals = 0;    // diagonals whose interior values were moved
  int GlobalFallback = 0;       // 1 when all free derivatives had to take the minimal choice
  double MinimumSlope = 0;      // sigma, in h units
  int ViolatingCells = 0;       // cells failing (C0)-(C3) in the end (0 unless infeasible)
  double MaximumValueShift = 0; // largest change of an interior value from the Laplace one
};

// One input sample mapped into the square: (U, V) = Phi(x, y) and the input value at (x, y).
struct SurfaceSample
{
  double U = 0;
  double V = 0;
  double Value = 0;
};

// The data-fitted interior (FitToSamples).
struct MonotoneSurfaceFitOptions
{
  // Weight of the thin-plate energy of F on the square, per sample: it decides the free
  // ordinates that no sample pins down (a grid cell without samples) and keeps the fit from
  // chasing noise between samples.
  double Smoothness = 1e-7;
  // Every monotonicity row (p + q at the nodes with a free derivative, (C0), (C2), (C3)) is
  // asked to be at least this fraction of the square's rise per grid step, R / N: a strictly
  // increasing F whose samples have no flat spots where the kinks of Phi could make critical
  // points. The paper's surface, which the fit starts from, bounds what is asked where it has
  // less.
  double MarginFraction = 0.02;
  // Also aim at p >= 0 and q >= 0 (F increasing along u and v, as its sides are), not enforced
  // exactly (see FitToSamples); TwoCellReconstruction::AxisAimTrigger turns it off in the cells
  // it holds off the data.
  bool IncreasingAlongAxes = true;
  // Spots of the square where an earlier fit, sampled at the input vertices, had a critical
  // point that no node of the complex explains (TwoCellReconstruction's stiffening): the
  // thin-plate weight of every grid cell within StiffRadius grid steps of a spot is multiplied
  // by the spot's factor (the largest one, where spots overlap).
  struct StiffSpot
  {
    double U = 0;
    double V = 0;
    double Factor = 1;
  };
  std::vector<StiffSpot> StiffSpots;
  double StiffRadius = 1.5;
  // Orders between two of the samples, aimed at (not enforced exactly): F(Upper) - F(Lower) >=
  // Margin, Lower and Upper indices into the samples fitted. TwoCellReconstruction gives them
  // around input vertices where an earlier fit, sampled at the vertices, had a critical point
  // that no node of the complex explains: one arc of the vertex's link above it, the rest below,
  // which is what a regular vertex's link is.
  struct SampleOrder
  {
    int Lower = 0;
    int Upper = 0;
    double Margin = 0;
  };
  std::vector<SampleOrder> SampleOrders;
  // The fit replaces the surface it starts from (the paper's, or an earlier fit) only if its
  // RMS residual is at most this times the starting surface's.
  double AcceptedResidualGrowth = 1;
  ConstrainedLeastSquaresOptions Solver;
};

struct MonotoneSurfaceFitReport
{
  bool Fitted = false;        // false: the paper's interior was kept (no sample, or no gain)
  int Samples = 0;
  int Unknowns = 0;           // free ordinates: (N-1)^2 (z, p, q) + 4 (N-1) cross derivatives
  int Rows = 0;               // monotonicity rows
  double MaximumResidual = 0; // |F(u, v) - value| over the samples, after the fit
  double RMSResidual = 0;
  double PaperMaximumResidual = 0; // the same for the paper's boundary-only interior
  double PaperRMSResidual = 0;
  ConstrainedLeastSquaresReport Solver;
};

// A cubic Bezier triangle of the output, control points (x, y, z) with (x, y) in the unit
// square, in the ordinate order of BezierOrdinateIndex.
struct SurfaceBezierTriangle
{
  std::array<std::array<double, 3>, 10> Points;
};

class MonotoneSibsonSurface
{
public:
  // Builds the surface. Returns false with a message when the input is malformed or the
  // sufficient conditions cannot hold for it (then the surface is still built, best effort,
  // and Report().ViolatingCells says how many cells fail).
  bool Build(const MonotoneSurfaceBoundary& boundary, std::string& error,
    const MonotoneSurfaceOptions& options = MonotoneSurfaceOptions());

  // Replaces the interior of the built surface (the paper's, from Build) by the one closest to
  // the samples in the least-squares sense, under the same sufficient monotonicity conditions
  // as linear rows: the free ordinates (z, p, q at the interior nodes, the cross derivative at
  // the boundary nodes) are the unknowns, the boundary curves stay exactly as built, C1 holds
  // inside by construction of the element. The paper's surface is the solver's feasible start,
  // so the result satisfies every condition exactly; it is kept only if it fits better.
  // Returns false with a message when the surface was not built or the fit's input is malformed
  // (the paper's interior is then kept).
  bool FitToSamples(const std::vector<SurfaceSample>& samples, std::string& error,
    const MonotoneSurfaceFitOptions& options = MonotoneSurfaceFitOptions());
  const MonotoneSurfaceFitReport& FitReport() const { return this->Fit; }
  // Largest and root-mean-square |F(u, v) - value| over samples.
  void MeasureResiduals(const std::vector<SurfaceSample>& samples, double& maximum, double& rms) const;
  // Evaluate(U, V) of every sample, bit for bit. Samples in input order mostly follow each
  // other within a grid cell, whose element (25 ordinates) is then made once for all of them.
  void EvaluateSamples(const std::vector<SurfaceSample>& samples, std::vector<double>& values) const;

  int GetGridSize() const { return this->N; }
  const MonotoneSurfaceReport& Report() const { return this->BuildReport; }

  // Node data on the (N+1) x (N+1) grid, node (i, j) at (i/N, j/N); P, Q are h * partials.
  double NodeValue(int i, int j) const { return this->Z[this->Node(i, j)]; }
  double NodeP(int i, int j) const { return this->P[this->Node(i, j)]; }
  double NodeQ(int i, int j) const { return this->Q[this->Node(i, j)]; }
  SibsonCellData GetCellData(int i, int j) const;
  // The element of grid cell (i, j), made from the node data when asked: storing all N^2 of
  // them took 400 bytes per element, and a cell of a noisy field can need N in the hundreds.
  MonotoneSibsonPatch GetPatch(int i, int j) const;

  // Checks (C0)-(C3) in every cell plus p + q > 0 at interior nodes; returns the number of
  // failing cells (an interior node with p + q <= 0 counts as a failure of its cells).
  int CountViolatingCells(double tolerance = 0) const;

  // F and its gradient with respect to (u, v) at a point of the unit square (clamped to it).
  double Evaluate(double u, double v) const;
  void EvaluateWithGradient(double u, double v, double& value, double gradient[2]) const;

  // All 4 N^2 Bezier triangles, cell by cell (row j, then column i), S, E, N, W in each.
  std::vector<SurfaceBezierTriangle> GetBezierTriangles() const;

private:
  // A (1,1)-diagonal of the grid, and the state the steps of Build share (in the .cxx).
  struct GridDiagonal;
  struct Construction;

  int Node(int i, int j) const { return j * (this->N + 1) + i; }
  // Nodes of cell (i, j) in the corner order of SibsonCellData.
  void CellNodes(int i, int j, int nodes[4]) const;
  void Locate(double u, double v, int& i, int& j, double& X, double& Y) const;

  // The steps of Build, in the order they run (paper, section 5.2).
  bool SetBoundaryNodes(const MonotoneSurfaceBoundary& boundary, double allowedMismatch, std::string& error);
  bool ComputeDiagonalRises(Construction& construction, std::string& error);
  void SolveLaplaceValues();
  void LinearizeNonIncreasingDiagonals(const Construction& construction);
  void ClassifyNodes(Construction& construction) const;
  void ChooseMinimumSlope(Construction& construction);
  void SetMinimalDerivatives(Construction& construction, double sigma) const;
  void EstimateDerivatives(Construction& construction) const;
  void LimitDerivativesPerCell(Construction& construction) const;
  void LimitDerivativesPerDiagonal(Construction& construction);
  void AdjustDiagonalValues(Construction& construction);

  // max(LHS(C2), LHS(C3), 0) / 3 of cell (i, j) with derivatives p, q: the least rise
  // z11 - z00 the cell needs; and its sum over the cells of a diagonal.
  double CellRequirement(int i, int j, const std::vector<double>& p, const std::vector<double>& q) const;
  double DiagonalRequirement(
    const GridDiagonal& diagonal, const std::vector<double>& p, const std::vector<double>& q) const;
  // Scales the lambdas of the given nodes of a diagonal to gamma times `base`; returns the
  // diagonal's requirement then.
  double ScaleDiagonalDerivatives(Construction& construction, const GridDiagonal& diagonal,
    const std::vector<int>& touching, const std::vector<double>& base, double gamma) const;
  // The nodes of the cells of a diagonal, sorted, each once.
  void DiagonalCellNodes(const GridDiagonal& diagonal, std::vector<int>& nodes) const;

  // The steps of FitToSamples: the free ordinates' positions in the unknown vector (-1: fixed
  // by the boundary), the quadratic program (objective, condition rows per cell, then per
  // node), and its solution.
  struct FreeOrdinates;
  struct FitProblem;
  FreeOrdinates NumberFreeOrdinates() const;
  void AssembleFit(const FreeOrdinates& free, const std::vector<SurfaceSample>& samples,
    const MonotoneSurfaceFitOptions& options, FitProblem& problem) const;
  void AddNodeRows(const FreeOrdinates& free, double margin, bool increasingAlongAxes, FitProblem& problem) const;
  // Grid cell (i, j)'s 12 data (z, p, q of V00 V10 V11 V01) as unknown indices (-1: fixed) and
  // the surface's present values.
  void CellUnknowns(const FreeOrdinates& free, int i, int j, int unknown[12], double fixed[12]) const;
  bool SolveFit(const FitProblem& problem, const MonotoneSurfaceFitOptions& options, Eigen::VectorXd& solution,
    std::string& error);

  int N = 0;
  std::vector<double> Z, P, Q;
  MonotoneSurfaceFitReport Fit;
  MonotoneSurfaceReport BuildReport;
};
} // namespace topospline
