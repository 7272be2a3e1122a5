#include "MonotoneSibsonSurface.h"

#include "BezierSpline.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>

namespace topospline
{
//------------------------------------------------------------------------------------------
// Boundary curves
bool SubdivideSide(const BezierSide& side, int targetCount, BezierSide& result)
{
  result.clear();
  const int count = static_cast<int>(side.size());
  if (count == 0 || targetCount < count || targetCount % count != 0)
  {
    return false;
  }
  const int pieces = targetCount / count;
  result.resize(targetCount);
  for (int j = 0; j < count; ++j)
  {
    // CubicHeightSegment is 4 contiguous doubles, and a vector of them is contiguous too.
    CubicBezierSpline::SplitEvenly(side[j].data(), 1, pieces, result[j * pieces].data(), DeCasteljauStep::Weighted);
  }
  return true;
}

bool SubdivideBoundary(const MonotoneSurfaceBoundary& boundary, int targetCount, MonotoneSurfaceBoundary& result)
{
  return SubdivideSide(boundary.Bottom, targetCount, result.Bottom) &&
    SubdivideSide(boundary.Right, targetCount, result.Right) && SubdivideSide(boundary.Top, targetCount, result.Top) &&
    SubdivideSide(boundary.Left, targetCount, result.Left);
}

int CommonSegmentCount(const BezierSide& bottom, const BezierSide& right, const BezierSide& top, const BezierSide& left)
{
  long long common = 1;
  for (const BezierSide* side : { &bottom, &right, &top, &left })
  {
    const long long count = static_cast<long long>(side->size());
    if (count == 0)
    {
      return 0;
    }
    common = common / std::gcd(common, count) * count;
  }
  return common > std::numeric_limits<int>::max() ? 0 : static_cast<int>(common);
}

//------------------------------------------------------------------------------------------
// Surface
namespace
{
// Isotonic (non-decreasing) least-squares fit by pooling adjacent violators.
void PoolAdjacentViolators(std::vector<double>& values)
{
  std::vector<double> blockMean;
  std::vector<int> blockSize;
  blockMean.reserve(values.size());
  blockSize.reserve(values.size());
  for (double v : values)
  {
    blockMean.push_back(v);
    blockSize.push_back(1);
    while (blockMean.size() > 1 && blockMean[blockMean.size() - 2] > blockMean.back())
    {
      const double m2 = blockMean.back();
      const int n2 = blockSize.back();
      blockMean.pop_back();
      blockSize.pop_back();
      const double total = blockMean.back() * blockSize.back() + m2 * n2;
      blockSize.back() += n2;
      blockMean.back() = total / blockSize.back();
    }
  }
  std::size_t k = 0;
  for (std::size_t b = 0; b < blockMean.size(); ++b)
  {
    for (int m = 0; m < blockSize[b]; ++m)
    {
      values[k++] = blockMean[b];
    }
  }
}

// Derivative of a segment at its ends with respect to its own parameter t, which is
// h d/dx along a side of the uniform grid.
double StartSlope(const CubicHeightSegment& c)
{
  return 3 * (c[1] - c[0]);
}

double EndSlope(const CubicHeightSegment& c)
{
  return 3 * (c[3] - c[2]);
}

// Averages the two sides' (or segments') version of a shared value and remembers the largest
// disagreement.
struct BoundaryReconciler
{
  double Mismatch = 0;
  double operator()(double a, double b)
  {
    this->Mismatch = std::max(this->Mismatch, std::abs(a - b));
    return 0.5 * (a + b);
  }
};

// Row of interior node (i, j) in the Laplace system of the m x m interior nodes.
int LaplaceUnknown(int m, int i, int j)
{
  return (j - 1) * m + (i - 1);
}

// Which derivatives of a node are free.
enum NodeKind : unsigned char
{
  Corner,   // none: both partials are tangential derivatives of a side
  Interior, // both
  CrossIsQ, // bottom and top sides: p tangential, q crosses
  CrossIsP  // left and right sides
};

// Checks that every control value is finite and returns the mismatch between sides allowed
// to be averaged away.
bool AllowedBoundaryMismatch(const MonotoneSurfaceBoundary& boundary, const MonotoneSurfaceOptions& options,
  double& allowedMismatch, std::string& error)
{
  double lowest = std::numeric_limits<double>::infinity();
  double highest = -lowest;
  for (const BezierSide* side : { &boundary.Bottom, &boundary.Right, &boundary.Top, &boundary.Left })
  {
    for (const CubicHeightSegment& segment : *side)
    {
      for (double c : segment)
      {
        if (!std::isfinite(c))
        {
          error = "a boundary control value is not finite";
          return false;
        }
        lowest = std::min(lowest, c);
        highest = std::max(highest, c);
      }
    }
  }
  const double range = highest - lowest;
  // Relative to the cell's range, but never below rounding: a nearly flat cell far from 0
  // (a constant field at 7.25 spread by 1e-11) has a range of a few thousand ulps only.
  const double magnitude = std::max(std::abs(lowest), std::abs(highest));
  allowedMismatch = std::max({ options.ConsistencyTolerance * (range > 0 ? range : 1.0),
    64 * std::numeric_limits<double>::epsilon() * magnitude,
    std::min(options.RoundingTolerance * magnitude, options.RoundingShareOfRange * range) });
  return true;
}
} // namespace

// A (1,1)-diagonal of the grid: nodes (I0 + c, J0 + c), c = 0..Length; its cells are the ones
// whose lower-left corner is one of its nodes except the last.
struct MonotoneSibsonSurface::GridDiagonal
{
  int I0 = 0;
  int J0 = 0;
  int Length = 0;
};

// The derivatives being chosen. Free are both partials at interior nodes and the cross
// derivative at the non-corner boundary nodes. Each free node gets a minimal choice (the one
// that leaves every diagonal the most room for (C2)/(C3): p = q = sigma/2 inside, p + q = 0 on
// the boundary, p + q = sigma - t where the tangential derivative t < sigma, so the gradient is
// never 0 there) and an estimate from the values (differences), and ends up at
//   minimal + lambda * (estimate - minimal),  lambda in [0, 1].
// Every condition is linear in the derivatives, so along lambda the requirement of a cell is
// convex: limiting lambda is a 1D search.
struct MonotoneSibsonSurface::Construction
{
  explicit Construction(const MonotoneSurfaceOptions& options)
    : Options(options)
  {
  }

  // p, q of node k from its lambda.
  void ApplyLambda(int k)
  {
    this->ChosenP[k] = this->MinimalP[k] + this->Lambda[k] * (this->EstimatedP[k] - this->MinimalP[k]);
    this->ChosenQ[k] = this->MinimalQ[k] + this->Lambda[k] * (this->EstimatedQ[k] - this->MinimalQ[k]);
  }

  const MonotoneSurfaceOptions& Options;
  std::vector<GridDiagonal> Diagonals;
  std::vector<double> Rise;        // per diagonal: value at its end minus value at its start
  std::vector<double> BestRoom;    // per diagonal: Rise minus the requirement of the minimal choice
  std::vector<unsigned char> Kind; // NodeKind per node
  std::vector<double> MinimalP, MinimalQ;
  std::vector<double> EstimatedP, EstimatedQ;
  std::vector<double> Lambda;
  std::vector<double> ChosenP, ChosenQ;
  bool Feasible = true;
};

SibsonCellData MonotoneSibsonSurface::GetCellData(int i, int j) const
{
  SibsonCellData cell;
  const int nodes[4] = { this->Node(i, j), this->Node(i + 1, j), this->Node(i + 1, j + 1), this->Node(i, j + 1) };
  for (int v = 0; v < 4; ++v)
  {
    cell.Z[v] = this->Z[nodes[v]];
    cell.P[v] = this->P[nodes[v]];
    cell.Q[v] = this->Q[nodes[v]];
  }
  return cell;
}

void MonotoneSibsonSurface::CellNodes(int i, int j, int nodes[4]) const
{
  nodes[0] = this->Node(i, j);
  nodes[1] = this->Node(i + 1, j);
  nodes[2] = this->Node(i + 1, j + 1);
  nodes[3] = this->Node(i, j + 1);
}

bool MonotoneSibsonSurface::Build(
  const MonotoneSurfaceBoundary& boundary, std::string& error, const MonotoneSurfaceOptions& options)
{
  error.clear();
  this->BuildReport = MonotoneSurfaceReport();
  this->Fit = MonotoneSurfaceFitReport();
  const int n = static_cast<int>(boundary.Bottom.size());
  this->N = 0;
  if (n == 0 || boundary.Right.size() != boundary.Bottom.size() || boundary.Top.size() != boundary.Bottom.size() ||
    boundary.Left.size() != boundary.Bottom.size())
  {
    error = "the four sides must have the same, non-zero number of segments (see SubdivideSide)";
    return false;
  }
  double allowedMismatch = 0;
  if (!AllowedBoundaryMismatch(boundary, options, allowedMismatch, error))
  {
    return false;
  }
  this->N = n;
  const int nodeCount = (n + 1) * (n + 1);
  this->Z.assign(nodeCount, 0.0);
  this->P.assign(nodeCount, 0.0);
  this->Q.assign(nodeCount, 0.0);
  Construction construction(options);
  if (!this->SetBoundaryNodes(boundary, allowedMismatch, error) || !this->ComputeDiagonalRises(construction, error))
  {
    this->N = 0;
    return false;
  }

  // Values: the Laplace equation, then the paper's fallback where it does not increase.
  this->SolveLaplaceValues();
  // Kept for the report only (MaximumValueShift), not with the surface: half a million noise
  // cells held a copy each.
  const std::vector<double> laplaceZ = this->Z;
  this->LinearizeNonIncreasingDiagonals(construction);

  // Derivatives, from minimal choice and estimates, limited per cell then per diagonal.
  this->ClassifyNodes(construction);
  this->ChooseMinimumSlope(construction);
  this->EstimateDerivatives(construction);
  this->LimitDerivativesPerCell(construction);
  this->LimitDerivativesPerDiagonal(construction);
  for (int k = 0; k < nodeCount; ++k)
  {
    if (construction.Lambda[k] < 1 &&
      (construction.EstimatedP[k] != construction.MinimalP[k] || construction.EstimatedQ[k] != construction.MinimalQ[k]))
    {
      ++this->BuildReport.LimitedNodes;
    }
  }
  this->P = construction.ChosenP;
  this->Q = construction.ChosenQ;

  // Values again, where the chosen derivatives need more rise than they have.
  this->AdjustDiagonalValues(construction);
  for (int k = 0; k < nodeCount; ++k)
  {
    this->BuildReport.MaximumValueShift =
      std::max(this->BuildReport.MaximumValueShift, std::abs(this->Z[k] - laplaceZ[k]));
  }

  this->BuildReport.ViolatingCells = this->CountViolatingCells();
  if (!construction.Feasible || this->BuildReport.ViolatingCells > 0)
  {
    error = "the sufficient monotonicity conditions cannot all hold for this boundary data (" +
      std::to_string(this->BuildReport.ViolatingCells) + " cells violate them)";
    return false;
  }
  return true;
}

// Boundary nodes: the Bezier end points and end derivatives, averaged where two segments or
// two sides meet.
bool MonotoneSibsonSurface::SetBoundaryNodes(
  const MonotoneSurfaceBoundary& boundary, double allowedMismatch, std::string& error)
{
  const int n = this->N;
  BoundaryReconciler reconcile;
  const BezierSide& bottom = boundary.Bottom;
  const BezierSide& right = boundary.Right;
  const BezierSide& top = boundary.Top;
  const BezierSide& left = boundary.Left;
  for (int k = 1; k < n; ++k)
  {
    this->Z[this->Node(k, 0)] = reconcile(bottom[k - 1][3], bottom[k][0]);
    this->P[this->Node(k, 0)] = reconcile(EndSlope(bottom[k - 1]), StartSlope(bottom[k]));
    this->Z[this->Node(n, k)] = reconcile(right[k - 1][3], right[k][0]);
    this->Q[this->Node(n, k)] = reconcile(EndSlope(right[k - 1]), StartSlope(right[k]));
    this->Z[this->Node(k, n)] = reconcile(top[k - 1][3], top[k][0]);
    this->P[this->Node(k, n)] = reconcile(EndSlope(top[k - 1]), StartSlope(top[k]));
    this->Z[this->Node(0, k)] = reconcile(left[k - 1][3], left[k][0]);
    this->Q[this->Node(0, k)] = reconcile(EndSlope(left[k - 1]), StartSlope(left[k]));
  }
  // Corners: both partials are tangential derivatives of a side.
  this->Z[this->Node(0, 0)] = reconcile(bottom[0][0], left[0][0]);
  this->P[this->Node(0, 0)] = StartSlope(bottom[0]);
  this->Q[this->Node(0, 0)] = StartSlope(left[0]);
  this->Z[this->Node(n, 0)] = reconcile(bottom[n - 1][3], right[0][0]);
  this->P[this->Node(n, 0)] = EndSlope(bottom[n - 1]);
  this->Q[this->Node(n, 0)] = StartSlope(right[0]);
  this->Z[this->Node(n, n)] = reconcile(top[n - 1][3], right[n - 1][3]);
  this->P[this->Node(n, n)] = EndSlope(top[n - 1]);
  this->Q[this->Node(n, n)] = EndSlope(right[n - 1]);
  this->Z[this->Node(0, n)] = reconcile(left[n - 1][3], top[0][0]);
  this->P[this->Node(0, n)] = StartSlope(top[0]);
  this->Q[this->Node(0, n)] = EndSlope(left[n - 1]);
  // Tangential derivatives that are negative only by rounding noise (e.g. a zero end slope of
  // a rescaled curve) are zero: (C1) at corners and boundary nodes is judged on them.
  for (int k = 0; k <= n; ++k)
  {
    for (double* slope : { &this->P[this->Node(k, 0)], &this->Q[this->Node(n, k)], &this->P[this->Node(k, n)],
           &this->Q[this->Node(0, k)] })
    {
      if (*slope < 0 && *slope >= -allowedMismatch)
      {
        *slope = 0;
      }
    }
  }
  if (reconcile.Mismatch > allowedMismatch)
  {
    char text[64];
    std::snprintf(text, sizeof(text), "%.3g of %.3g allowed", reconcile.Mismatch, allowedMismatch);
    error = std::string("the boundary segments do not join with common values and derivatives (mismatch ") + text + ")";
    return false;
  }
  return true;
}

// Every node lies on one diagonal, which runs from the bottom or left side to the right or top
// one: its boundary values must increase, or no monotone surface exists.
bool MonotoneSibsonSurface::ComputeDiagonalRises(Construction& construction, std::string& error)
{
  const int n = this->N;
  for (int d = -(n - 1); d <= n - 1; ++d)
  {
    GridDiagonal diagonal;
    diagonal.I0 = std::max(d, 0);
    diagonal.J0 = std::max(-d, 0);
    diagonal.Length = n - std::abs(d);
    construction.Diagonals.push_back(diagonal);
  }
  construction.Rise.resize(construction.Diagonals.size());
  for (std::size_t d = 0; d < construction.Diagonals.size(); ++d)
  {
    const GridDiagonal& g = construction.Diagonals[d];
    const double start = this->Z[this->Node(g.I0, g.J0)];
    const double end = this->Z[this->Node(g.I0 + g.Length, g.J0 + g.Length)];
    construction.Rise[d] = end - start;
    // Sides that rise by less than their values' rounding over a few grid steps (a DEM's
    // plateau broken by 1e-9 of its integer heights, a grid of 299 along it) can tie at a
    // corner: such a diagonal is flat, and its cells are built as well as they can be and
    // counted as violating, rather than the whole 2-cell left out.
    if (!(construction.Rise[d] > 0) &&
      construction.Rise[d] >= -64 * std::numeric_limits<double>::epsilon() * std::max(std::abs(start), std::abs(end)))
    {
      construction.Rise[d] = 0;
      construction.Feasible = false;
      ++this->BuildReport.FlatDiagonals;
      continue;
    }
    if (!(construction.Rise[d] > 0))
    {
      error = "the boundary values do not increase along the grid diagonal from node (" + std::to_string(g.I0) +
        "," + std::to_string(g.J0) + "): no monotone surface can interpolate them";
      return false;
    }
  }
  return true;
}

namespace
{
// The 5-point Laplacian of the m x m interior nodes of a Sibson grid, factored. It depends on m
// alone, and every cell of uniform noise solves one of a handful of sizes: building, ordering and
// factoring it per cell was 8 % of stage 4 on 1000 x 1000 noise. Factorizations of grids up to
// CachedLaplaceSide are made once per process and shared (solving through a const
// factorization is safe from several threads); larger ones (a few cells of a terrain) are made
// per call. The same matrix gives the same ordering and factor, so the values are the same.
using LaplaceFactorization = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>;
constexpr int CachedLaplaceSide = 64;

std::unique_ptr<LaplaceFactorization> FactorGridLaplacian(int m)
{
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(5 * static_cast<std::size_t>(m) * m);
  for (int j = 1; j <= m; ++j)
  {
    for (int i = 1; i <= m; ++i)
    {
      const int row = LaplaceUnknown(m, i, j);
      entries.emplace_back(row, row, 4.0);
      const int neighbours[4][2] = { { i - 1, j }, { i + 1, j }, { i, j - 1 }, { i, j + 1 } };
      for (const auto& nb : neighbours)
      {
        if (nb[0] >= 1 && nb[0] <= m && nb[1] >= 1 && nb[1] <= m)
        {
          entries.emplace_back(row, LaplaceUnknown(m, nb[0], nb[1]), -1.0);
        }
      }
    }
  }
  Eigen::SparseMatrix<double> laplacian(m * m, m * m);
  laplacian.setFromTriplets(entries.begin(), entries.end());
  return std::make_unique<LaplaceFactorization>(laplacian);
}

// The shared factorization of side m <= CachedLaplaceSide, made by its first caller.
const LaplaceFactorization& CachedGridLaplacian(int m)
{
  static std::mutex mutex;
  static std::array<std::unique_ptr<LaplaceFactorization>, CachedLaplaceSide + 1> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  if (!cache[m])
  {
    cache[m] = FactorGridLaplacian(m);
  }
  return *cache[m];
}
} // namespace

// Interior values: discrete Laplace equation (5-point stencil) with the boundary values.
void MonotoneSibsonSurface::SolveLaplaceValues()
{
  const int n = this->N;
  const int m = n - 1;
  if (m <= 0)
  {
    return;
  }
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m * m);
  for (int j = 1; j < n; ++j)
  {
    for (int i = 1; i < n; ++i)
    {
      const int row = LaplaceUnknown(m, i, j);
      const int neighbours[4][2] = { { i - 1, j }, { i + 1, j }, { i, j - 1 }, { i, j + 1 } };
      for (const auto& nb : neighbours)
      {
        if (nb[0] == 0 || nb[0] == n || nb[1] == 0 || nb[1] == n)
        {
          rhs[row] += this->Z[this->Node(nb[0], nb[1])];
        }
      }
    }
  }
  std::unique_ptr<LaplaceFactorization> own;
  if (m > CachedLaplaceSide)
  {
    own = FactorGridLaplacian(m);
  }
  const LaplaceFactorization& solver = own ? *own : CachedGridLaplacian(m);
  const Eigen::VectorXd solution = solver.solve(rhs);
  for (int j = 1; j < n; ++j)
  {
    for (int i = 1; i < n; ++i)
    {
      this->Z[this->Node(i, j)] = solution[LaplaceUnknown(m, i, j)];
    }
  }
}

// The paper's fallback for (C0): where the Laplace values do not increase strictly along a
// diagonal, interpolate linearly between its (boundary) end points.
void MonotoneSibsonSurface::LinearizeNonIncreasingDiagonals(const Construction& construction)
{
  for (std::size_t d = 0; d < construction.Diagonals.size(); ++d)
  {
    const GridDiagonal& g = construction.Diagonals[d];
    bool increasing = true;
    for (int c = 0; c < g.Length; ++c)
    {
      increasing = increasing &&
        this->Z[this->Node(g.I0 + c + 1, g.J0 + c + 1)] > this->Z[this->Node(g.I0 + c, g.J0 + c)];
    }
    if (!increasing)
    {
      const double start = this->Z[this->Node(g.I0, g.J0)];
      for (int c = 1; c < g.Length; ++c)
      {
        this->Z[this->Node(g.I0 + c, g.J0 + c)] = start + construction.Rise[d] * c / g.Length;
      }
      ++this->BuildReport.LinearizedDiagonals;
    }
  }
}

void MonotoneSibsonSurface::ClassifyNodes(Construction& construction) const
{
  const int n = this->N;
  construction.Kind.resize((n + 1) * (n + 1));
  for (int j = 0; j <= n; ++j)
  {
    for (int i = 0; i <= n; ++i)
    {
      const bool sideX = i == 0 || i == n;
      const bool sideY = j == 0 || j == n;
      construction.Kind[this->Node(i, j)] = sideX && sideY ? Corner : sideY ? CrossIsQ : sideX ? CrossIsP : Interior;
    }
  }
}

// The minimal choice of the free derivatives for the lower bound sigma of p + q.
void MonotoneSibsonSurface::SetMinimalDerivatives(Construction& construction, double sigma) const
{
  const bool flat = construction.Options.FlatAcrossBoundary;
  const int nodeCount = static_cast<int>(construction.Kind.size());
  for (int k = 0; k < nodeCount; ++k)
  {
    if (construction.Kind[k] == Interior)
    {
      construction.MinimalP[k] = construction.MinimalQ[k] = 0.5 * sigma;
    }
    else if (construction.Kind[k] == CrossIsQ)
    {
      const double t = this->P[k];
      construction.MinimalQ[k] = t < sigma ? sigma - 2 * t : (flat ? 0.0 : -t);
    }
    else if (construction.Kind[k] == CrossIsP)
    {
      const double t = this->Q[k];
      construction.MinimalP[k] = t < sigma ? sigma - 2 * t : (flat ? 0.0 : -t);
    }
  }
}

// sigma: a fraction of the smallest per-cell room left by the minimal choice with sigma = 0.
// With it, the minimal choice and the room it leaves each diagonal.
void MonotoneSibsonSurface::ChooseMinimumSlope(Construction& construction)
{
  const std::vector<GridDiagonal>& diagonals = construction.Diagonals;
  construction.MinimalP = this->P;
  construction.MinimalQ = this->Q;
  this->SetMinimalDerivatives(construction, 0);
  double smallestRoom = std::numeric_limits<double>::infinity();
  double smallestAverageRise = std::numeric_limits<double>::infinity();
  for (std::size_t d = 0; d < diagonals.size(); ++d)
  {
    const double room =
      construction.Rise[d] - this->DiagonalRequirement(diagonals[d], construction.MinimalP, construction.MinimalQ);
    if (room > 0)
    {
      smallestRoom = std::min(smallestRoom, room / diagonals[d].Length);
    }
    smallestAverageRise = std::min(smallestAverageRise, construction.Rise[d] / diagonals[d].Length);
  }
  const double sigma = std::isfinite(smallestRoom) ? construction.Options.MinimumSlopeFraction * smallestRoom
                                                   : 1e-3 * smallestAverageRise;
  this->BuildReport.MinimumSlope = sigma;
  this->SetMinimalDerivatives(construction, sigma);
  construction.BestRoom.resize(diagonals.size());
  for (std::size_t d = 0; d < diagonals.size(); ++d)
  {
    construction.BestRoom[d] =
      construction.Rise[d] - this->DiagonalRequirement(diagonals[d], construction.MinimalP, construction.MinimalQ);
    construction.Feasible = construction.Feasible && construction.BestRoom[d] >= 0;
  }
}

// Estimates: central differences inside, one-sided second-order differences across the
// boundary; then moved into the admissible set (p + q >= sigma inside: the projection of the
// thesis's Algorithm 1; cross derivative >= the minimal one on the boundary). The derivatives
// start at the estimates (lambda = 1).
void MonotoneSibsonSurface::EstimateDerivatives(Construction& construction) const
{
  const int n = this->N;
  const int nodeCount = (n + 1) * (n + 1);
  const double sigma = this->BuildReport.MinimumSlope;
  const bool flat = construction.Options.FlatAcrossBoundary;
  std::vector<double>& pEst = construction.EstimatedP;
  std::vector<double>& qEst = construction.EstimatedQ;
  pEst = this->P;
  qEst = this->Q;
  for (int j = 0; j <= n; ++j)
  {
    for (int i = 0; i <= n; ++i)
    {
      const int k = this->Node(i, j);
      if (construction.Kind[k] == Interior)
      {
        pEst[k] = 0.5 * (this->NodeValue(i + 1, j) - this->NodeValue(i - 1, j));
        qEst[k] = 0.5 * (this->NodeValue(i, j + 1) - this->NodeValue(i, j - 1));
        const double s = pEst[k] + qEst[k];
        if (s < sigma)
        {
          pEst[k] += 0.5 * (sigma - s);
          qEst[k] += 0.5 * (sigma - s);
        }
      }
      else if (construction.Kind[k] == CrossIsQ)
      {
        const int inward = j == 0 ? 1 : -1;
        const double d = flat ? 0.0
                              : 0.5 *
            (-3 * this->NodeValue(i, j) + 4 * this->NodeValue(i, j + inward) - this->NodeValue(i, j + 2 * inward));
        qEst[k] = std::max(inward * d, construction.MinimalQ[k]);
      }
      else if (construction.Kind[k] == CrossIsP)
      {
        const int inward = i == 0 ? 1 : -1;
        const double d = flat ? 0.0
                              : 0.5 *
            (-3 * this->NodeValue(i, j) + 4 * this->NodeValue(i + inward, j) - this->NodeValue(i + 2 * inward, j));
        pEst[k] = std::max(inward * d, construction.MinimalP[k]);
      }
    }
  }
  construction.Lambda.assign(nodeCount, 1.0);
  construction.ChosenP.resize(nodeCount);
  construction.ChosenQ.resize(nodeCount);
  for (int k = 0; k < nodeCount; ++k)
  {
    construction.ApplyLambda(k);
  }
}

// Pass 1, per cell (keeps the Laplace values wherever possible): scale the derivatives of the
// cell's corners so that the requirement stays below (1 - margin) of the actual rise. Both left
// sides are linear in the common factor gamma, so the largest admissible gamma is explicit.
void MonotoneSibsonSurface::LimitDerivativesPerCell(Construction& construction) const
{
  const int n = this->N;
  const double keep = 1 - construction.Options.LimiterMargin;
  for (int sweep = 0; sweep < construction.Options.CellLimiterSweeps; ++sweep)
  {
    bool changed = false;
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        const double target = 3 * keep * (this->NodeValue(i + 1, j + 1) - this->NodeValue(i, j));
        if (this->CellRequirement(i, j, construction.ChosenP, construction.ChosenQ) * 3 <= target)
        {
          continue;
        }
        int nodes[4];
        this->CellNodes(i, j, nodes);
        SibsonCellData atZero, atOne;
        for (int v = 0; v < 4; ++v)
        {
          atZero.P[v] = construction.MinimalP[nodes[v]];
          atZero.Q[v] = construction.MinimalQ[nodes[v]];
          atOne.P[v] = construction.ChosenP[nodes[v]];
          atOne.Q[v] = construction.ChosenQ[nodes[v]];
        }
        double gamma = 1;
        const double lows[2] = { ConditionC2LeftSide(atZero), ConditionC3LeftSide(atZero) };
        const double highs[2] = { ConditionC2LeftSide(atOne), ConditionC3LeftSide(atOne) };
        for (int c = 0; c < 2; ++c)
        {
          if (highs[c] > target)
          {
            gamma = std::min(gamma, lows[c] >= target ? 0.0 : (target - lows[c]) / (highs[c] - lows[c]));
          }
        }
        gamma = std::max(0.0, std::min(gamma, 1.0));
        for (int v = 0; v < 4; ++v)
        {
          construction.Lambda[nodes[v]] *= gamma;
          construction.ApplyLambda(nodes[v]);
        }
        changed = true;
      }
    }
    if (!changed)
    {
      break;
    }
  }
}

// Pass 2, per diagonal (what is needed for the values to be fixable at all): the total
// requirement of a diagonal must leave a share of the best achievable room. If the rounds do
// not settle, all free derivatives take the minimal choice, which satisfies every diagonal.
void MonotoneSibsonSurface::LimitDerivativesPerDiagonal(Construction& construction)
{
  const MonotoneSurfaceOptions& options = construction.Options;
  bool diagonalsOk = false;
  std::vector<int> touching;
  for (int round = 0; round < options.DiagonalLimiterRounds && !diagonalsOk; ++round)
  {
    diagonalsOk = true;
    for (std::size_t d = 0; d < construction.Diagonals.size(); ++d)
    {
      const GridDiagonal& g = construction.Diagonals[d];
      const double bound = construction.Rise[d] - options.LimiterMargin * std::max(construction.BestRoom[d], 0.0);
      if (this->DiagonalRequirement(g, construction.ChosenP, construction.ChosenQ) <= bound)
      {
        continue;
      }
      diagonalsOk = false;
      this->DiagonalCellNodes(g, touching);
      std::vector<double> base(touching.size());
      for (std::size_t k = 0; k < touching.size(); ++k)
      {
        base[k] = construction.Lambda[touching[k]];
      }
      // Convex in gamma and admissible at 0 (all touching nodes minimal): bisection.
      double lo = 0, hi = 1;
      for (int iteration = 0; iteration < 50; ++iteration)
      {
        const double mid = 0.5 * (lo + hi);
        (this->ScaleDiagonalDerivatives(construction, g, touching, base, mid) <= bound ? lo : hi) = mid;
      }
      this->ScaleDiagonalDerivatives(construction, g, touching, base, lo);
    }
  }
  if (!diagonalsOk)
  {
    std::fill(construction.Lambda.begin(), construction.Lambda.end(), 0.0);
    for (int k = 0; k < static_cast<int>(construction.Lambda.size()); ++k)
    {
      construction.ApplyLambda(k);
    }
    this->BuildReport.GlobalFallback = 1;
  }
}

// Values: per diagonal (a value only enters the conditions of its own diagonal's cells), the
// least-squares closest values with rise_c >= requirement_c + share of the spare room: with
// w_c = z_c - (sum of the needed rises before c), that is isotonic regression of w with fixed
// ends, i.e. pooling adjacent violators and clamping.
void MonotoneSibsonSurface::AdjustDiagonalValues(Construction& construction)
{
  for (std::size_t d = 0; d < construction.Diagonals.size(); ++d)
  {
    const GridDiagonal& g = construction.Diagonals[d];
    const double rise = construction.Rise[d];
    if (g.Length < 2)
    {
      continue;
    }
    std::vector<double> needed(g.Length);
    double total = 0;
    for (int c = 0; c < g.Length; ++c)
    {
      needed[c] = this->CellRequirement(g.I0 + c, g.J0 + c, construction.ChosenP, construction.ChosenQ);
      total += needed[c];
    }
    if (total <= rise)
    {
      const double share = construction.Options.RiseShare * (rise - total) / g.Length;
      for (double& r : needed)
      {
        r += share;
      }
    }
    else
    {
      construction.Feasible = false; // best effort: rises proportional to the requirements
      for (double& r : needed)
      {
        r *= rise / total;
      }
    }
    std::vector<double> offset(g.Length + 1, 0.0);
    for (int c = 0; c < g.Length; ++c)
    {
      offset[c + 1] = offset[c] + needed[c];
    }
    const double wStart = this->NodeValue(g.I0, g.J0);
    const double wEnd = this->NodeValue(g.I0 + g.Length, g.J0 + g.Length) - offset[g.Length];
    std::vector<double> w(g.Length - 1), original(g.Length - 1);
    for (int c = 1; c < g.Length; ++c)
    {
      original[c - 1] = w[c - 1] = this->NodeValue(g.I0 + c, g.J0 + c) - offset[c];
    }
    PoolAdjacentViolators(w);
    bool moved = false;
    for (int c = 1; c < g.Length; ++c)
    {
      const double value = std::min(std::max(w[c - 1], wStart), std::max(wEnd, wStart));
      if (value != original[c - 1])
      {
        this->Z[this->Node(g.I0 + c, g.J0 + c)] = value + offset[c];
        moved = true;
      }
    }
    this->BuildReport.AdjustedDiagonals += moved ? 1 : 0;
  }
}

MonotoneSibsonPatch MonotoneSibsonSurface::GetPatch(int i, int j) const
{
  MonotoneSibsonPatch patch;
  patch.SetData(this->GetCellData(i, j));
  return patch;
}

double MonotoneSibsonSurface::CellRequirement(
  int i, int j, const std::vector<double>& p, const std::vector<double>& q) const
{
  int nodes[4];
  this->CellNodes(i, j, nodes);
  SibsonCellData cell;
  for (int v = 0; v < 4; ++v)
  {
    cell.P[v] = p[nodes[v]];
    cell.Q[v] = q[nodes[v]];
  }
  return std::max({ ConditionC2LeftSide(cell), ConditionC3LeftSide(cell), 0.0 }) / 3;
}

double MonotoneSibsonSurface::DiagonalRequirement(
  const GridDiagonal& g, const std::vector<double>& p, const std::vector<double>& q) const
{
  double total = 0;
  for (int c = 0; c < g.Length; ++c)
  {
    total += this->CellRequirement(g.I0 + c, g.J0 + c, p, q);
  }
  return total;
}

double MonotoneSibsonSurface::ScaleDiagonalDerivatives(Construction& construction, const GridDiagonal& g,
  const std::vector<int>& touching, const std::vector<double>& base, double gamma) const
{
  for (std::size_t k = 0; k < touching.size(); ++k)
  {
    construction.Lambda[touching[k]] = gamma * base[k];
    construction.ApplyLambda(touching[k]);
  }
  return this->DiagonalRequirement(g, construction.ChosenP, construction.ChosenQ);
}

void MonotoneSibsonSurface::DiagonalCellNodes(const GridDiagonal& g, std::vector<int>& nodes) const
{
  nodes.clear();
  for (int c = 0; c < g.Length; ++c)
  {
    int corners[4];
    this->CellNodes(g.I0 + c, g.J0 + c, corners);
    nodes.insert(nodes.end(), corners, corners + 4);
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
}

int MonotoneSibsonSurface::CountViolatingCells(double tolerance) const
{
  int violating = 0;
  for (int j = 0; j < this->N; ++j)
  {
    for (int i = 0; i < this->N; ++i)
    {
      const SibsonCellData cell = this->GetCellData(i, j);
      bool bad = CheckMonotonicityConditions(cell, tolerance) != MonotonicityCondition::Satisfied;
      const int corners[4][2] = { { i, j }, { i + 1, j }, { i + 1, j + 1 }, { i, j + 1 } };
      for (int v = 0; v < 4; ++v)
      {
        const int ci = corners[v][0], cj = corners[v][1];
        const bool interior = ci > 0 && ci < this->N && cj > 0 && cj < this->N;
        bad = bad || (interior && !(cell.P[v] + cell.Q[v] > 0));
      }
      violating += bad ? 1 : 0;
    }
  }
  return violating;
}

void MonotoneSibsonSurface::Locate(double u, double v, int& i, int& j, double& X, double& Y) const
{
  u = std::min(std::max(u, 0.0), 1.0);
  v = std::min(std::max(v, 0.0), 1.0);
  const double su = u * this->N, sv = v * this->N;
  i = std::min(static_cast<int>(su), this->N - 1);
  j = std::min(static_cast<int>(sv), this->N - 1);
  X = su - i;
  Y = sv - j;
}

double MonotoneSibsonSurface::Evaluate(double u, double v) const
{
  double value, gradient[2];
  this->EvaluateWithGradient(u, v, value, gradient);
  return value;
}

void MonotoneSibsonSurface::EvaluateWithGradient(double u, double v, double& value, double gradient[2]) const
{
  int i, j;
  double X, Y;
  this->Locate(u, v, i, j, X, Y);
  this->GetPatch(i, j).EvaluateWithGradient(X, Y, value, gradient);
  gradient[0] *= this->N;
  gradient[1] *= this->N;
}

void MonotoneSibsonSurface::EvaluateSamples(
  const std::vector<SurfaceSample>& samples, std::vector<double>& values) const
{
  values.resize(samples.size());
  MonotoneSibsonPatch patch;
  int patchI = -1, patchJ = -1;
  for (std::size_t k = 0; k < samples.size(); ++k)
  {
    int i, j;
    double X, Y;
    this->Locate(samples[k].U, samples[k].V, i, j, X, Y);
    if (i != patchI || j != patchJ)
    {
      patch = this->GetPatch(i, j);
      patchI = i;
      patchJ = j;
    }
    values[k] = patch.Evaluate(X, Y);
  }
}

std::vector<SurfaceBezierTriangle> MonotoneSibsonSurface::GetBezierTriangles() const
{
  std::vector<SurfaceBezierTriangle> triangles;
  triangles.reserve(4 * static_cast<std::size_t>(this->N) * this->N);
  const double h = 1.0 / this->N;
  for (int j = 0; j < this->N; ++j)
  {
    for (int i = 0; i < this->N; ++i)
    {
      const MonotoneSibsonPatch patch = this->GetPatch(i, j);
      for (int t = 0; t < 4; ++t)
      {
        double vertices[3][2];
        MonotoneSibsonPatch::GetTriangleVertices(static_cast<SibsonTriangle>(t), vertices);
        const CubicTriangleOrdinates& o = patch.GetOrdinates(static_cast<SibsonTriangle>(t));
        SurfaceBezierTriangle triangle;
        for (int a = 0; a <= 3; ++a)
        {
          for (int b = 0; b <= 3 - a; ++b)
          {
            const int c = 3 - a - b;
            const int index = BezierOrdinateIndex(a, b);
            const double x = (a * vertices[0][0] + b * vertices[1][0] + c * vertices[2][0]) / 3;
            const double y = (a * vertices[0][1] + b * vertices[1][1] + c * vertices[2][1]) / 3;
            triangle.Points[index] = { { (i + x) * h, (j + y) * h, o[index] } };
          }
        }
        triangles.push_back(triangle);
      }
    }
  }
  return triangles;
}
} // namespace topospline
