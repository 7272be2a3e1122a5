// Stage 4 of the paper (section 5.2): a C1 piecewise cubic surface on the unit square that
// interpolates four monotone boundary curves and has no critical point inside, built from
// "modified Sibson" elements on a uniform N x N grid (reference [2] of the paper, Allemand-
// Giorgis, Bonneau, Hahmann, Vivodtzev 2014; reconstructed in algorithms.md section 1).
//
// The element (one grid cell, local coordinates X, Y in [0,1], corners V00, V10, V11, V01,
// centre C) is cut by both diagonals into the cubic Bezier triangles
//   South (V00, V10, C), East (V10, V11, C), North (V11, V01, C), West (V01, V00, C).
// It is fixed by the value z and the scaled partials p = h dz/dx, q = h dz/dy at the corners.
// Every ordinate follows from C1 continuity except one per outer edge (b111), which is chosen
// so that the derivative D_(1,1)F = F_x + F_y is linear along every outer edge: the element is
// then C1 across grid edges, and h D_(1,1)F is a quadratic whose Bernstein coefficients are
// linear in the data. Their non-negativity gives the sufficient conditions (s = p + q,
// Delta = z11 - z00):
//   (C0) Delta > 0;
//   (C1) s >= 0 at the four corners (the surface builder asks s > 0 at interior grid nodes);
//   (C2) (5 p00 + q00)/4 + s10/2 + (p11 + 5 q11)/4 <= 3 Delta;
//   (C3) (p00 + 5 q00)/4 + s01/2 + (5 p11 + q11)/4 <= 3 Delta;
//   and (C2) or (C3) strict, which makes the coefficient at the centre positive.
// Under them D_(1,1)F > 0 on the open cell, so the gradient never vanishes there. The unit
// tests prove all of this numerically; nothing here is quoted from [2].
#pragma once

#include "CoreTypes.h"

#include <array>
#include <string>
#include <vector>

namespace topospline
{
// Ordinates of a cubic Bezier triangle (A, B, C), b_ijk with i <-> A, j <-> B, k <-> C, stored
// in the order b300 b210 b201 b120 b111 b102 b030 b021 b012 b003.
constexpr int BezierOrdinateIndex(int i, int j)
{
  return (3 - i) * (4 - i) / 2 + (3 - i - j);
}
using CubicTriangleOrdinates = std::array<double, 10>;

// Corner data of one grid cell, corners in the order V00, V10, V11, V01 (counterclockwise).
struct SibsonCellData
{
  std::array<double, 4> Z = { { 0, 0, 0, 0 } };
  std::array<double, 4> P = { { 0, 0, 0, 0 } }; // h * dz/dx
  std::array<double, 4> Q = { { 0, 0, 0, 0 } }; // h * dz/dy
};

enum class SibsonTriangle
{
  South = 0,
  East = 1,
  North = 2,
  West = 3
};

// Which sufficient condition a cell violates (the first one, in this order).
enum class MonotonicityCondition
{
  Satisfied = 0,
  C0,              // z11 <= z00
  C1,              // p + q < 0 at a corner
  C2,              // (C2) fails
  C3,              // (C3) fails
  CentreNotPositive // (C2) and (C3) both hold with equality: D_(1,1)F(C) = 0
};
const char* MonotonicityConditionName(MonotonicityCondition condition);

// Left-hand sides of (C2) and (C3), to be compared with 3 (z11 - z00).
double ConditionC2LeftSide(const SibsonCellData& cell);
double ConditionC3LeftSide(const SibsonCellData& cell);

// Checks (C0)-(C3) of one cell; `tolerance` loosens every inequality by that amount (0: exact).
MonotonicityCondition CheckMonotonicityConditions(const SibsonCellData& cell, double tolerance = 0);

class MonotoneSibsonPatch
{
public:
  MonotoneSibsonPatch() = default;
  explicit MonotoneSibsonPatch(const SibsonCellData& cell) { this->SetData(cell); }

  // Computes the 40 ordinates (25 distinct) of the modified element.
  void SetData(const SibsonCellData& cell);
  const SibsonCellData& GetData() const { return this->Data; }

  const CubicTriangleOrdinates& GetOrdinates(SibsonTriangle t) const
  {
    return this->Ordinates[static_cast<int>(t)];
  }
  // Vertices A, B, C of a sub-triangle in local coordinates.
  static void GetTriangleVertices(SibsonTriangle t, double vertices[3][2]);
  // The sub-triangle that owns (X, Y) (points on a diagonal go to either; both agree).
  static SibsonTriangle LocateTriangle(double X, double Y);

  // Value at (X, Y) in [0,1]^2, and its gradient with respect to the local coordinates
  // (that is h * grad F: divide by h for the gradient in the grid's units).
  double Evaluate(double X, double Y) const;
  void EvaluateWithGradient(double X, double Y, double& value, double localGradient[2]) const;
  // The same restricted to one sub-triangle (extended polynomially outside it), so that both
  // sides of an interior half-diagonal can be compared.
  void EvaluateTriangle(SibsonTriangle t, double X, double Y, double& value, double localGradient[2]) const;

  // Bernstein coefficients of the quadratic h * D_(1,1)F on a sub-triangle, in the order
  // c200 c110 c101 c020 c011 c002 (i <-> A, j <-> B, k <-> C).
  std::array<double, 6> DiagonalDerivativeCoefficients(SibsonTriangle t) const;

private:
  SibsonCellData Data;
  std::array<CubicTriangleOrdinates, 4> Ordinates;
};

// One cubic Bezier segment of a boundary height function: control values c0..c3.
using CubicHeightSegment = std::array<double, 4>;
using BezierSide = std::vector<CubicHeightSegment>;

// de Casteljau split of one cubic at s in (0,1): `left` covers [0, s], `right` [s, 1].
void SplitCubicSegment(const CubicHeightSegment& control, double s, CubicHeightSegment& left,
  CubicHeightSegment& right);

// Splits every segment of `side` into targetCount / side.size() equal parameter pieces, so that
// the side has `targetCount` segments describing exactly the same function. The grid is
// uniform, so the split must be uniform too (otherwise the parameter speed, hence the
// tangential derivative at the grid nodes, would jump): targetCount must be a multiple of
// side.size(). Returns false (and leaves `result` empty) otherwise.
bool SubdivideSide(const BezierSide& side, int targetCount, BezierSide& result);

// The smallest count all four sides can be uniformly subdivided to: the least common multiple
// of their segment counts (0 if a side is empty).
int CommonSegmentCount(const BezierSide& bottom, const BezierSide& left, const BezierSide& top,
  const BezierSide& right);

// Boundary of the unit square; every side is oriented from its lower corner to its upper one
// and has the same number N of segments, segment j covering [j/N, (j+1)/N]:
//   Bottom (0,0)->(1,0), Left (0,0)->(0,1), Top (0,1)->(1,1), Right (1,0)->(1,1).
// Corners: minimum (0,0), saddles (1,0) and (0,1), maximum (1,1). Consecutive segments must
// share their end value and (scaled) end derivative, 3 (c3 - c2) = 3 (c1' - c0'), and the
// sides must agree at the corners.
struct MonotoneSurfaceBoundary
{
  BezierSide Bottom;
  BezierSide Left;
  BezierSide Top;
  BezierSide Right;
};

struct MonotoneSurfaceOptions
{
  // Mismatches between the sides at shared points (values and scaled derivatives) up to this
  // fraction of the value range are averaged away; larger ones are an error.
  double ConsistencyTolerance = 1e-9;
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
  int LimitedNodes = 0;         // nodes whose estimated derivatives were scaled down
  int AdjustedDiagonals = 0;    // diagonals whose interior values were moved
  int GlobalFallback = 0;       // 1 when all free derivatives had to take the minimal choice
  double MinimumSlope = 0;      // sigma, in h units
  int ViolatingCells = 0;       // cells failing (C0)-(C3) in the end (0 unless infeasible)
  double MaximumValueShift = 0; // largest change of an interior value from the Laplace one
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

  int GetGridSize() const { return this->N; }
  const MonotoneSurfaceReport& Report() const { return this->BuildReport; }

  // Node data on the (N+1) x (N+1) grid, node (i, j) at (i/N, j/N); P, Q are h * partials.
  double NodeValue(int i, int j) const { return this->Z[this->Node(i, j)]; }
  double NodeP(int i, int j) const { return this->P[this->Node(i, j)]; }
  double NodeQ(int i, int j) const { return this->Q[this->Node(i, j)]; }
  // The Laplace values before any correction (interior nodes), for diagnostics.
  double LaplaceValue(int i, int j) const { return this->LaplaceZ[this->Node(i, j)]; }
  SibsonCellData GetCellData(int i, int j) const;
  const MonotoneSibsonPatch& GetPatch(int i, int j) const { return this->Patches[j * this->N + i]; }

  // Checks (C0)-(C3) in every cell plus p + q > 0 at interior nodes; returns the number of
  // failing cells (an interior node with p + q <= 0 counts as a failure of its cells).
  int CountViolatingCells(double tolerance = 0) const;

  // F and its gradient with respect to (u, v) at a point of the unit square (clamped to it).
  double Evaluate(double u, double v) const;
  void EvaluateWithGradient(double u, double v, double& value, double gradient[2]) const;

  // All 4 N^2 Bezier triangles, cell by cell (row j, then column i), S, E, N, W in each.
  std::vector<SurfaceBezierTriangle> GetBezierTriangles() const;

private:
  int Node(int i, int j) const { return j * (this->N + 1) + i; }
  void Locate(double u, double v, int& i, int& j, double& X, double& Y) const;

  int N = 0;
  std::vector<double> Z, P, Q, LaplaceZ;
  std::vector<MonotoneSibsonPatch> Patches;
  MonotoneSurfaceReport BuildReport;
};
} // namespace topospline
