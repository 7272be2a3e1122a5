// Stage 4 of the paper (section 5): the final field inside every 2-cell of the smoothed
// complex. Per cell: its four sides are assembled from the smoothed 1-cell pieces, the cell is
// parameterized onto the unit square (TwoCellParameterization: CGAL triangulation + mean value
// coordinates), and a monotone C1 Sibson surface F with no interior critical point is built on
// the square (MonotoneSibsonSurface). The reconstruction is F o Phi. Cells are independent and
// are built in parallel; every cell writes only its own slot, so the result does not depend on
// the number of threads.
//
// Corners of the square (the paper's section 5.1): minimum (0,0), maximum (1,1), the saddles of
// BoundaryOneCells[0..1] at (1,0) and of BoundaryOneCells[2..3] at (0,1):
//   Bottom (0,0)->(1,0): the descending 1-cell of saddle 0, Right (1,0)->(1,1): its ascending one,
//   Left (0,0)->(0,1): the descending 1-cell of saddle 1, Top (0,1)->(1,1): its ascending one.
// Where the two descending 1-cells merge before the minimum (they share their first pieces),
// the minimum is not on the cell's boundary: the junction where they split takes corner (0,0),
// as in the paper; likewise for the maximum. A pouch cell (one saddle twice) whose two sides are
// the same 1-cell keeps that 1-cell as a slit: the boundary runs out along it and back.
#pragma once

#include "CoreTypes.h"
#include "MonotoneSibsonSurface.h"
#include "MorseSmaleComplex.h"
#include "OneCellSmoothing.h"
#include "TriangleMeshTopology.h"
#include "TwoCellParameterization.h"

#include <array>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace topospline
{
// The pieces (positions in OneCellSmoothingResult::Pieces) along each side of one cell, every
// side oriented from its lower corner to its upper one (every piece runs from low to high).
struct TwoCellSides
{
  enum Side : int
  {
    Bottom = 0,
    Right = 1,
    Top = 2,
    Left = 3
  };
  std::array<std::vector<Index>, 4> Pieces;
  bool MinimumShifted = false; // corner (0,0) is a junction, not the minimum
  bool MaximumShifted = false; // corner (1,1) is a junction, not the maximum
  bool Slit = false;           // a pouch whose boundary runs out along a 1-cell and back
  // A saddle on the other saddle's 1-cell (the two 1-cells merge right at it) or on the
  // extremum's vertex (a 1-cell of one point) leaves a side empty: the cell has 3 corners (2
  // if it happens in both pairs). Bottom + Right and Left + Top are each a path from the lower
  // corner to the upper one, and an empty side takes half of its partner: SplitSides[0] is the
  // split side of the pair Bottom + Right, SplitSides[1] of Left + Top; -1: none.
  std::array<int, 2> SplitSides{ { -1, -1 } };
};

// Assembles the sides of `cell` (see the top of this file). Where the two descending 1-cells
// share their first pieces (a "stem" from the minimum to the junction where they split), the
// stem is either outside the cell, which then starts at the junction (mergeAtMinimum, the
// paper's rule), or inside it, with the minimum at the stem's tip: the cell then wraps around
// the stem, which stays on its boundary as a slit (mergeAtMinimum = false). Likewise at the
// maximum. A side that ends where it starts is no side (the cell has 3 corners) if it encloses
// at most `pointLikeLoopArea` (a loop through a few triangles round a boundary vertex), and a
// side otherwise (a 1-cell round the whole domain boundary). Returns false with a message when
// the cell cannot be mapped to a square (both sides of a pair empty, unknown pieces).
bool AssembleTwoCellSides(const TwoCell& cell, const OneCellSmoothingResult& smoothed, TwoCellSides& sides,
  std::string& error, bool mergeAtMinimum = true, bool mergeAtMaximum = true,
  double pointLikeLoopArea = std::numeric_limits<double>::infinity());

// The Bezier segments along one side, in order: planar control points (x0 y0 ... x3 y3) and
// height control values.
struct SideSegments
{
  std::vector<std::array<double, 8>> Curve;
  BezierSide Height;
  std::vector<int> Pieces; // segments of each piece along the side, in order (sum: Curve.size())
  std::vector<int> Samples; // boundary samples per Bezier segment of each piece (empty: the walk's default)
};

// The grid size N of a cell's surface and, per side and piece, how many grid segments each of
// the piece's Bezier segments covers. The grid is uniform, so within a piece the split must be
// uniform (its parameter speed must not jump); between pieces it need not be: pieces meet at
// junction points, where the heights have zero slope whatever the speed. So N need not be the
// least common multiple of the four sides' counts: any N that every side can reach as
// sum(k_i m_i), m_i >= 1, will do; the smallest one is taken. Returns 0 when none is at most
// maximum.
int ChooseGridLayout(const std::array<SideSegments, 4>& sides, int maximum, std::array<std::vector<int>, 4>& multipliers);

// The segments of the four sides (Bottom, Right, Top, Left), with an empty side made up from
// half of its partner (TwoCellSides::SplitSides), cut at the segment boundary nearest the middle
// (`cutOffset` segments past it, within the side), or with `exactHalves` at the exact middle of a
// partner of an odd count (every segment then cut in two). `samplesPerPiece` (indexed by smoothed
// piece; null: none) gives each piece its own boundary samples per Bezier segment.
std::array<SideSegments, 4> TwoCellSideSegments(const TwoCellSides& sides, const OneCellSmoothingResult& smoothed,
  bool exactHalves = false, int cutOffset = 0, const std::vector<int>* samplesPerPiece = nullptr);

// The piece counts of the four sides as TwoCellSideSegments lays them out (an empty side made up
// from half of its partner, cut at the segment boundary nearest the middle), each piece with
// countOf(piece) segments, and no geometry (zero control points): what ChooseGridLayout reads.
// Stage 3 asks it what grid a 2-cell would get if a piece had another count.
std::array<SideSegments, 4> TwoCellSideCounts(const TwoCellSides& sides, const std::function<int(Index)>& countOf);

// Boundary samples per Bezier segment of each smoothed piece: c (the paper's), or, on a piece
// whose 1-cells bound only 2-cells of fewer than `fewerVerticesThan` input vertices
// (TwoCell::NumberOfVertices), fewer where its segments are short: ceil(L / spacing) with L
// the longest control polygon of its segments (at least their arc length), at least 1 (the
// segment's start point alone: the walk then runs through the segment ends). spacing <= 0:
// c everywhere.
std::vector<int> BoundarySamplesPerPiece(const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed,
  int c, double spacing, Index fewerVerticesThan);

// One reconstructed 2-cell.
struct ReconstructedTwoCell
{
  bool Valid = false;  // parameterized and surface built (possibly with violations, see Surface)
  std::string Error;   // why not, when !Valid
  bool Negligible = false; // skipped: its boundary encloses no more than NegligibleArea
  bool MapFailed = false;  // not valid because no walk of it could be parameterized (not for its grid)
  bool Resampled = false;  // some of its pieces were sampled more densely (BoundaryDensifications)
  TwoCellSides Sides;
  int GridSize = 0;    // N: cubic segments per side of the square after subdivision
  double Bounds[4] = { 0, 0, 0, 0 }; // xmin, xmax, ymin, ymax of the boundary samples
  TwoCellParameterization Parameterization;
  MonotoneSibsonSurface Surface;
};

struct TwoCellReconstructionReport
{
  Index Cells = 0;
  Index FailedCells = 0;       // not reconstructed (see ReconstructedTwoCell::Error)
  Index NegligibleCells = 0;   // skipped for having no area
  Index SlitCells = 0;         // pouch cells parameterized with a slit
  Index OutsideSlitCells = 0;  // cells with slits outside their outer loop, left out of the walk
  Index PinchedCells = 0;      // cells whose boundary touches itself, opened there (TwoCellParameterization)
  Index ResampledCells = 0;    // cells whose boundary pieces were sampled more densely (DensifyFailedBoundaries)
  Index ShiftedCorners = 0;    // corners taken by junction points
  Index ViolatingPatches = 0;  // Sibson grid cells failing the monotonicity conditions (0 is the goal)
  Index LinearizedDiagonals = 0; // the paper's fallback for non-increasing Laplace values
  Index AdjustedDiagonals = 0;   // diagonals whose values were moved to meet the conditions
  Index FittedCells = 0;       // interiors fitted to the input samples (Interior == Fitted)
  Index RefinedCells = 0;      // of them, cells whose grid was refined beyond the sides' need
  Index StiffenedCells = 0;    // of them, cells whose fit was stiffened (StiffeningRounds)
  Index OrderedCells = 0;      // of them, cells whose fit orders samples around critical points (OrderingRounds)
  Index RemappedCells = 0;     // of them, cells fitted on an alternative map (AlternativeMapStrength)
  Index SmallFittedCells = 0;  // of them, small cells fitted where the paper's interior misses (SmallCellFitTrigger)
  Index AxisFreeCells = 0;     // of them, cells whose fit no longer aims at F rising along u and v (AxisAimTrigger)
  Index MeshTriangles = 0;     // triangles of all cell meshes
  Index CrowdedTriangles = 0;  // of them, flattened in (u, v) by rounding (TwoCellMesh::CrowdedTriangles)
  Index BezierTriangles = 0;   // 4 N^2 per cell
  int MaximumGridSize = 0;
  double ParameterizationSeconds = 0; // wall time: triangulation + mean value coordinates
  double SurfaceSeconds = 0;          // wall time: Sibson surfaces (with their fits)
};

// What decides a 2-cell's interior: the paper's construction from the boundary curves alone,
// or a least-squares fit to the input samples inside the cell under the same monotonicity
// conditions (MonotoneSibsonSurface::FitToSamples), with the grid refined where the data ask.
enum class TwoCellInterior : int
{
  Paper = 0,
  Fitted = 1
};

// A cubic Bezier triangle of the reconstruction in the plane: control points (x, y, height),
// ordinates in the order of BezierOrdinateIndex.
struct PlanarBezierTriangle
{
  std::array<std::array<double, 3>, 10> Points;
};

class TwoCellReconstruction
{
public:
  // c in the paper: samples per boundary Bezier segment.
  int BoundarySamples = 5;
  // A boundary sample spacing beyond which more samples show nothing (<= 0: c on every segment,
  // the paper's rule), kept on the pieces around small 2-cells (fewer than
  // SparseSamplesBelowVertices input vertices): their segments shorter than c times this get
  // fewer samples (BoundarySamplesPerPiece). On uniform noise at 5 % a 2-cell is a few grid
  // spacings across and its boundary 16 to 32 segments long, so c = 5 put its samples a tenth
  // of a spacing apart, and its triangulation and map (about 140 triangles, most of stage 4's
  // time) resolved the curves far below the spacing of the vertices evaluated in it. Larger
  // cells keep c: they are few, so their samples cost little, and their fitted interiors
  // follow their maps, which the short pieces' samples shape near the nodes (on a Shepard
  // field at 5 % the largest miss of a large cell went from 7.6 to 8.9 % of the range with
  // every short piece sampled half a grid edge apart).
  double BoundarySampleSpacing = 0;
  static constexpr Index SparseSamplesBelowVertices = 64;
  // A cell whose walk cannot be parameterized (its polygon crosses or touches itself, mostly
  // where two curves leave a node almost tangentially and one is sampled coarsely across the
  // other's bend) is tried again with its pieces sampled twice as densely, and so are the cells
  // that share those pieces (their common boundary stays one polyline), up to this many times
  // and up to MostDensifiedSamples per segment (never below BoundarySamples).
  int BoundaryDensifications = 3;
  static constexpr int MostDensifiedSamples = 64;
  // The grid of a cell's sides (ChooseGridLayout) is looked for up to this many segments, with
  // the split sides cut at their middle or off it; where none fits, the cell's own segment
  // boundaries are taken with a grid up to LargestGridSize, at that cell's cost (stage 3 raises
  // the pieces of a 1-cell that still crosses to hundreds of segments: four cells of seed 53
  // #79, 128² noise at 50 % with k = 2, need 544: about 1.5 s and 16 MB each). Cells beyond are
  // not reconstructed; the surfaces' memory estimate still refuses what would not fit.
  int MaximumGridSize = 512;
  int LargestGridSize = 1024;
  // A point outside every cell by at most this distance (the smoothed boundary differs from
  // the jagged one) takes the value of the nearest boundary point. <= 0: 1e-3 of the domain.
  double SnapDistance = 0;
  // Cell triangulations aim at the mean boundary sample spacing (the paper's choice), but at
  // no less than this (the filter passes twice the input's mean grid edge: finer triangles
  // only cost time).
  double MinimumMeshEdgeLength = 0;
  // Cells whose boundary encloses at most this area are skipped (the filter passes the square
  // of the mean grid edge: such a cell holds at most a vertex or two, which take the value of
  // the nearest cell boundary).
  double NegligibleArea = 0;
  TwoCellInterior Interior = TwoCellInterior::Paper;
  // Fitted interiors: the mean value map is one choice among many, and where a fit misses the
  // data most, another map often lets the same surface follow it better (the largest misses sit
  // next to wide corners, an extremum the cell wraps around, where the mean value map spreads
  // the data so that it falls along (1, 1)). The cell that misses most is fitted again on two
  // maps whose mean value weights are reweighted by the input's gradient
  // (TwoCellParameterization::WeightByFieldGradient with this strength, along its gradient and
  // along its level sets) and keeps the best fit (FitOnAlternativeMaps); then the next, while
  // each is improved and misses by more than AlternativeMapTrigger times SurfaceTolerance.
  // 0: the mean value map everywhere (the paper's).
  double AlternativeMapStrength = 0;
  static constexpr double AlternativeMapTrigger = 3;
  static constexpr double AlternativeMapGain = 0.9;
  static constexpr double AlternativeMapRMSGrowth = 1.1;
  // Fitted interiors: a cell's grid is doubled (its boundary Beziers split exactly) while its
  // largest residual exceeds this (in the field's units; <= 0: never), up to
  // MaximumRefinedGridSize, while every grid cell keeps a few samples and each doubling gains
  // at least 10 %; the best grid is kept (the spaces are not nested).
  double SurfaceTolerance = 0;
  int MaximumRefinedGridSize = 32;
  // Whether a fitted cell with this many samples may have this grid: every grid cell keeps 4 of
  // them, within MaximumRefinedGridSize (the refinement's rule; stage 3 asks it too before a
  // 1-cell's new count grows a cell's grid).
  bool GridHasSamplesFor(int gridSize, std::size_t samples) const
  {
    return gridSize <= this->MaximumRefinedGridSize &&
      static_cast<double>(samples) >= 4.0 * static_cast<double>(gridSize) * static_cast<double>(gridSize);
  }
  // Cells whose sides alone need a finer grid than this keep the paper's interior: their fit
  // has tens of thousands of unknowns (seconds per cell), and such grids come from long sides
  // around few samples, where the boundary curves already carry the data. So do cells with
  // fewer than 3 samples or than one per 64 grid cells (FitSizeOf).
  int MaximumFittedGridSize = 48;
  // Small cells (fewer than 8 samples or than one per 16 grid cells, but not too few) are
  // fitted only where the paper's interior misses their samples by more than
  // SmallCellFitTrigger times SurfaceTolerance (<= 0: never), the largest misses first, and no
  // more of them than SmallCellFitsPerRegularFit times the cells fitted as regular ones (at
  // least MinimumSmallCellFits): a fit costs about as much whatever its samples, and uniform
  // noise has thousands of such cells (fitting all of them on 300² noise took stage 4 ten times
  // as long, as many as the regular fits half as long again; terrains have a few: 28 on
  // ttk_happi at 2 %, none on the Rainier crop).
  double SmallCellFitTrigger = 0;
  static constexpr double SmallCellFitsPerRegularFit = 0.25;
  static constexpr std::size_t MinimumSmallCellFits = 32;
  MonotoneSurfaceFitOptions Fit;
  // Fitted interiors, given the input's mesh: a fit whose values at the cell's vertices have a
  // critical point two rings of vertices or more inside the cell (where no 1-cell passes, so
  // no node of the complex can explain it) is fitted again with the thin-plate weight around
  // such points multiplied by StiffeningFactor (compounding round after round, around the
  // points each round leaves, for up to StiffeningRounds rounds). The fit with the fewest such
  // points is kept; none whose RMS residual exceeds StiffeningResidualGrowth times the first
  // fit's (such a round is tried again with the square root of its step, down to 1.5).
  const TriangleMeshTopology* Mesh = nullptr;
  int StiffeningRounds = 5;
  double StiffeningFactor = 10;
  double StiffeningResidualGrowth = 1.25;
  // Where critical points are left after the stiffening rounds, up to OrderingRounds more fits
  // (from the first fit, with the kept stiffening) ask each such vertex's neighbours to be above
  // or below it by a linear order along the local rise, with a slope of OrderingSlope times
  // the cell's sample range per unit of the square (OrderWhereSamplingBreaks; 0 rounds: none).
  int OrderingRounds = 8;
  double OrderingSlope = 0.005;
  // A vertex whose ring lies in its cell but whose second ring does not also counts as inside
  // the cell for the stiffening and ordering rounds when it lies farther than this from the
  // cell's boundary (the smoothed 1-cells): on a grid, two rings of neighbours reach only two
  // spacings along the axes, so critical points 2-3 spacings from a 1-cell, which no node
  // explains either, went untreated. FieldReconstruction passes twice the grid spacing, the
  // distance beyond which its report calls a critical point far from the 1-cells. <= 0: the
  // two rings alone. The rounds treat these after the points two rings inside, and keep a fit
  // for them only if its largest residual is within BandResidualGrowth of the first fit's
  // (over the fidelity benchmark's 31 fitted runs: far points 57 -> 17 with 1.1, 39 with 1,
  // and without the bound 17 too, but a Rainier crop's largest error 2.05 -> 2.66 eps).
  double FarFromOneCells = 0;
  static constexpr double BandResidualGrowth = 1.1;
  // Fitted interiors, given the input's mesh: the fit aims at F rising along u and along v
  // (MonotoneSurfaceFitOptions::IncreasingAlongAxes), which keeps the data's noise from putting
  // troughs and ridges across a cell. Where the data itself falls across the square, from one
  // side to the opposite one (a 1-cell lower than the 1-cell facing it across a narrow cell:
  // on an integer DEM's plateaus stage 1 can route a ridge along the foot of a slope), that aim
  // holds the whole cell above the data. A cell whose fit misses by more than this times
  // SurfaceTolerance is fitted again without it, from the fit it has (F still rises along
  // (1, 1), which is what the guarantee needs), and keeps that fit if its largest residual falls
  // below AlternativeMapGain times the one before, its RMS residual does not grow, and it has no
  // more critical vertices two rings inside the cell (those of the stiffening) unless its RMS
  // residual falls below AxisAimRMSGain times the one before (a cell held 16 m off the data of a
  // Maunga Whau crop, RMS 8.7 % of the range, whose free fit has 0.7 % and 3 such points: the
  // data is worth more than points that topological sampling settles anyway); the stiffening
  // and ordering rounds then keep the aim off for that cell. <= 0: never.
  double AxisAimTrigger = 5;
  static constexpr double AxisAimRMSGain = 0.5;
  // Bytes the Sibson surfaces and their Bezier patches may take (<= 0: no limit). Checked
  // after the parameterization, when every cell's grid size N is known and before any surface
  // is built: the patches grow with the square of a cell's busiest side (4 N^2 triangles),
  // which a count of cells does not see.
  double MemoryBudget = 0;
  // Memory of a surface per Bezier triangle: its node data (z, p, q and the Laplace values, 4
  // doubles per grid node, 8 bytes per triangle) and its share of the construction's and the
  // Laplace solve's scratch. The elements themselves are made when asked (GetPatch); stored,
  // they took 180 bytes per triangle. Measured: 200^2 noise at 5 %, k 17 (stress case #85, 115
  // million triangles, grids up to 216): 3.9 GB peak for the whole pipeline. The planar patches
  // and their VTK output take about 600 bytes per triangle more
  // (FieldReconstruction::MaximumPatchTriangles bounds them).
  static constexpr double BytesPerBezierTriangle = 24;
  ParallelFor Parallel = SequentialFor;
  ProgressHooks Hooks;

  // Reconstructs every 2-cell of `complex` (the simplified complex that `smoothed` was made
  // from). `data`, the input field, is needed for fitted interiors (each vertex is data for the
  // smoothed cell that contains it; complex.TwoCellId only says where to look first); without
  // it the interiors are the paper's. Cells that fail are
  // reported (Report().FailedCells); the call fails only on malformed input or abort.
  bool Reconstruct(const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed, std::string& error,
    const PlanarScalarField* data = nullptr);

  Index NumberOfCells() const { return static_cast<Index>(this->Cells.size()); }
  const ReconstructedTwoCell& Cell(Index c) const { return *this->Cells[c]; }
  const TwoCellReconstructionReport& Report() const { return this->Summary; }

  struct Evaluation
  {
    double Value = 0;
    Index Cell = InvalidIndex; // InvalidIndex: no reconstructed cell near the point
    bool Inside = false;       // false: snapped to the nearest boundary point of Cell
  };
  // F o Phi at (x, y). `hint`: a cell likely to contain the point (e.g. the input vertex's
  // 2-cell), tried first; InvalidIndex if unknown.
  Evaluation Evaluate(double x, double y, Index hint = InvalidIndex) const;

  // The 4 N^2 Bezier triangles of cell c placed in the plane: heights are F's ordinates
  // (exact); the (x, y) of the control points are those of the cubic that interpolates
  // Phi^-1 at the 10 lattice points of each sub-triangle (Phi^-1 is piecewise linear, so the
  // placement, not the height, is approximated). Empty for an invalid cell.
  std::vector<PlanarBezierTriangle> PlanarBezierTriangles(Index c) const;

private:
  // samplesPerPiece: boundary samples per Bezier segment of each smoothed piece.
  void ParameterizeCell(const TwoCell& twoCell, const OneCellSmoothingResult& smoothed,
    const std::vector<int>& samplesPerPiece, ReconstructedTwoCell& cell, MonotoneSurfaceBoundary& boundary) const;
  // BoundaryDensifications: the pieces of every cell whose walk failed to parameterize get twice
  // the samples, and every cell on those pieces is parameterized again; a cell that was valid
  // and fails with the denser samples keeps its earlier map (its side of the shared piece then
  // differs from its neighbour's by slivers between samples).
  // samplesPerPiece: the counts of the first pass, doubled from there.
  void DensifyFailedBoundaries(const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed,
    std::vector<int> samplesPerPiece, std::vector<MonotoneSurfaceBoundary>& boundaries);
  // The cell's fit tried again on the alternative maps (AlternativeMapStrength), from the mean
  // value map's mesh, at the grid size its fit chose; each is kept, with its map and its
  // samples' (u, v), if its largest residual is below AlternativeMapGain times the best so far
  // and its RMS residual at most AlternativeMapRMSGrowth times. Returns whether one was kept.
  bool FitOnAlternativeMaps(ReconstructedTwoCell& cell, const MonotoneSurfaceBoundary& subdivided,
    const PiecewiseLinearField& field, const PlanarScalarField& data, const Index* vertices,
    std::vector<SurfaceSample>& samples) const;
  static void BuildSurface(ReconstructedTwoCell& cell, const MonotoneSurfaceBoundary& subdivided);
  // The finest grid FitSurface's refinement may reach from `gridSize` with `samples` input
  // samples in the cell: doubling while every grid cell keeps 4 samples, up to
  // MaximumRefinedGridSize (it stops earlier once the fit meets SurfaceTolerance or stops gaining).
  int FinestRefinedGridSize(int gridSize, std::size_t samples) const;
  // False, with the estimate, when the surfaces of these grids would exceed MemoryBudget.
  // firstVertex: the cells' input samples (LocateSamples; empty when not fitting).
  bool SurfacesFitInMemory(const std::vector<MonotoneSurfaceBoundary>& boundaries,
    const std::vector<Index>& firstVertex, std::string& error) const;
  // Where each input vertex lies: the cell containing it (hints: a likely cell per vertex) and
  // its (u, v) there; the vertices of cell c are vertices[firstVertex[c] .. firstVertex[c + 1]).
  void LocateSamples(const PlanarScalarField& data, const std::vector<Index>& hints, std::vector<Index>& firstVertex,
    std::vector<Index>& vertices, std::vector<double>& parameters, std::vector<Index>& cellOf) const;
  // The boundary walk with the split sides cut off their middle, where the cut at the middle
  // leaves no grid layout within MaximumGridSize; false if no cut does better.
  bool BuildBoundaryWalkCutOffMiddle(const TwoCellSides& sides, const OneCellSmoothingResult& smoothed,
    const std::vector<int>& samplesPerPiece, std::vector<double>& walk, std::vector<double>& parameters,
    MonotoneSurfaceBoundary& boundary) const;
  // Whether a cell with this many samples is fitted (Regular), fitted only where the paper's
  // interior misses them (Small, see SmallCellFitTrigger), or keeps the paper's interior.
  enum class FitSize
  {
    None,
    Small,
    Regular
  };
  FitSize FitSizeOf(const ReconstructedTwoCell& cell, std::size_t samples) const;
  // Fits the cell's interior, refining its grid (see SurfaceTolerance); returns whether refined.
  bool FitSurface(ReconstructedTwoCell& cell, const MonotoneSurfaceBoundary& subdivided,
    const std::vector<SurfaceSample>& samples) const;
  // The fit released from the aim at F rising along u and v where it misses most
  // (AxisAimTrigger), then the stiffening rounds (see StiffeningRounds), then the ordering
  // rounds (OrderingRounds), of a cell whose samples are those of `vertices` (ringInCell: per
  // input vertex, whether it and its ring of neighbours lie inside its cell; points: the input
  // vertices' (x, y)). Returns which kind of fit was kept (0: the first): AxisFreeFit,
  // StiffenedFit, OrderedFit, or several.
  enum
  {
    StiffenedFit = 1,
    OrderedFit = 2,
    AxisFreeFit = 4
  };
  class DeepCriticalVertices;
  int StiffenWhereSamplingBreaks(ReconstructedTwoCell& cell, const std::vector<SurfaceSample>& samples,
    const Index* vertices, const std::vector<char>& ringInCell, const std::vector<double>& points) const;
  // The fit of a cell that misses by more than AxisAimTrigger x SurfaceTolerance, tried again
  // without the aim at F rising along u and v; returns whether it was kept (`options` is then
  // without that aim).
  bool ReleaseAxisAim(ReconstructedTwoCell& cell, const std::vector<SurfaceSample>& samples,
    DeepCriticalVertices& deep, MonotoneSurfaceFitOptions& options) const;
  // The ordering rounds from `first` with the kept stiffening's options; returns whether an
  // ordered fit was kept.
  bool OrderWhereSamplingBreaks(ReconstructedTwoCell& cell, const MonotoneSibsonSurface& first,
    MonotoneSurfaceFitOptions options, DeepCriticalVertices& deep, const std::vector<SurfaceSample>& samples) const;
  void Summarize();
  void BuildCellLocator();
  // The cell containing (x, y) and the point's (u, v) in its square (Inside false: snapped to
  // the nearest boundary point within the snap distance; Cell InvalidIndex: none).
  struct Location
  {
    Index Cell = InvalidIndex;
    bool Inside = false;
    double UV[2] = { 0, 0 };
  };
  Location Locate(double x, double y, Index hint) const;
  bool LocateInCell(Index c, double x, double y, double uv[2]) const;

  std::vector<std::unique_ptr<ReconstructedTwoCell>> Cells;
  TwoCellReconstructionReport Summary;
  // Uniform grid over the domain; bucket b lists the valid cells whose box (grown by the snap
  // distance) overlaps it.
  double Origin[2] = { 0, 0 };
  double BucketSize[2] = { 1, 1 };
  int Buckets[2] = { 0, 0 };
  double Snap = 0;
  std::vector<Index> BucketStart, BucketCells;
};
} // namespace topospline
