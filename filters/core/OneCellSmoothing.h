// Stage 3 of the paper (section 4): smooth, strictly monotone 1-cells. Cuts the 1-cells of a
// (simplified) complex into pieces at their junction points, gives the junction points new
// values with one global linear program (JunctionValueProgram), fits on every piece a
// strictly increasing height and a planar curve (MonotoneBSplineFit), both k cubic Beziers,
// and checks that the smoothed curves do not cross (adapting k where they do).
#pragma once

#include "CoreTypes.h"
#include "MonotoneBSplineFit.h"
#include "MorseSmaleComplex.h"

#include <functional>
#include <string>
#include <vector>

namespace topospline
{
// A critical point, a junction point or a corner of the domain: where pieces start and end.
struct SmoothingNode
{
  enum Kind : int
  {
    Critical = 0,
    Junction = 1,
    DomainCorner = 2
  };
  Kind Type = Critical;
  Index Source = InvalidIndex; // critical point (position in the complex) or junction index
  double Position[2] = { 0, 0 };
  double FieldValue = 0; // f at the node (critical value, or the junction's sampled value)
  double Value = 0;      // the smoothed value: f for critical points, else the program's
};

// One piece of 1-cell between two consecutive nodes; merged 1-cells share their pieces.
struct SmoothedPiece
{
  OneCell::Kind Type = OneCell::Descending;
  Index StartNode = InvalidIndex; // the lower end
  Index EndNode = InvalidIndex;   // the higher end
  std::vector<Index> OneCells; // 1-cells that run through it
  std::vector<double> Points;      // the jagged samples (x, y), start to end
  std::vector<double> Values;      // the field along them
  std::vector<double> Parameters;  // arc length and rise (MonotoneBSplineFit::ArcLengthAndRise)
  int Segments = 0;                // k used (more than asked where crossings forced it)
  // The rise ratios whose knots bettered the height in turn, the one in use last (RepairCrossings
  // steps a crossing piece back through them before even knots); none: arc length only.
  std::vector<double> RiseRatios;
  bool RiseKnots() const { return !this->RiseRatios.empty(); } // Parameters follow the rise too
  bool ContactKnots = false;       // Parameters crowd the knots where other pieces came near (RepairCrossings)
  CubicBezierSpline Curve;         // Dimension 2
  CubicBezierSpline Height;        // Dimension 1, strictly increasing
  double L1Error = 0;              // monotone fit, over the interior samples
  double LargestMiss = 0;          // monotone fit, the largest |height - sample|
  double UnconstrainedL1Error = 0; // the same fit without monotonicity, for comparison
  bool Clamped = false;            // control points were clamped into the domain's box
  bool HeightAlongCurve = false;   // Height fits the field sampled along Curve, not Values (see FieldAt)
  bool HeightRefined = false;      // k was raised because the height missed (HeightTolerance)
};

struct OneCellSmoothingResult
{
  std::vector<SmoothingNode> Nodes;
  std::vector<SmoothedPiece> Pieces;
  std::vector<std::vector<Index>> PiecesOfOneCell; // per 1-cell, its pieces in order
  int ShortPieces = 0;         // pieces of fewer edges than k, fitted with fewer segments (a divisor of k)
  // Pieces first given more than twice as many segments as edges (k has no divisor between),
  // and, where those hold most of the segments, a k near the asked one whose divisors serve
  // nearly every piece (SuggestCurveSegments; 0: none needed or found).
  int OversegmentedPieces = 0;
  int SuggestedSegments = 0;
  int AdaptedPieces = 0;       // pieces whose k was raised to remove crossings
  int RiseKnotPieces = 0;      // pieces whose knots follow their rise (MonotoneBSplineFit::ArcLengthAndRise)
  int ContactKnotPieces = 0;   // pieces whose knots crowd where other pieces came near (RepairCrossings)
  int CurveHeightPieces = 0;   // pieces whose height fits the field along their curve (FieldAt)
  int RefinedPieces = 0;       // pieces whose k was doubled because the height missed (HeightTolerance)
  int PolylinePieces = 0;      // of them, pieces that still crossed at their largest k and follow
                               // their jagged 1-cell in straight segments instead
  int RemainingCrossings = 0;  // pairs of pieces that still cross (0 is the goal); a piece that
                               // passes a node not its own too closely counts as one
  int PiecesOutsideDomain = 0; // pieces whose curve leaves the domain's bounding box
  int ClampedPieces = 0;       // pieces kept inside it by clamping control points
  double JunctionMargin = 0;
  double JunctionTotalChange = 0;
  int ErasedLoops = 0;          // retraced loops of merged 1-cells erased before cutting (EraseRetracedLoops)
  int DroppedCuts = 0;          // cuts at junctions left out to break cycles of the relations (RankNodes)
  int SpreadCriticalValues = 0; // critical values raised to make room for strict monotonicity
  double MaximumSpread = 0;     // the largest raise (see JunctionValueProgram)
};

class OneCellSmoothing
{
public:
  // The range of k a user may ask for (the GUI's range): beyond 30 the pieces have more
  // segments than most 1-cells have samples, and the fits become long and fail.
  static constexpr int MaximumCurveSegments = 30;
  // The segments a piece of `edges` jagged edges starts with at k = `asked`: k, or on a piece of
  // fewer edges the smallest divisor of k that gives each edge a segment (at least 2).
  static int SegmentsForEdges(int edges, int asked);
  // Where the pieces first given more than twice as many segments as edges hold most of the
  // segments (a prime k on noise, whose pieces mostly have 2 edges: stage 4's grids grow with
  // the square of a side's segments), the k nearest `asked` in [2, MaximumCurveSegments] at
  // which such pieces hold at most a tenth of them (of two as near, the one with the smaller sum
  // of squared counts); 0 where nothing needs it or no k does. `edges`: each piece's edges.
  static int SuggestCurveSegments(const std::vector<int>& edges, int asked, int* oversegmented = nullptr);
  // k: cubic segments per piece (the paper's "Curve Segments": 4 or 7), in [2, MaximumCurveSegments].
  int Segments = 4;
  // Crossings are removed by raising k on the pieces involved, up to this many segments (or
  // up to the piece's number of samples, if larger).
  int MaximumSegments = 32;
  // Points per Bezier segment used to check crossings.
  int SamplesPerSegment = 8;
  // A piece whose height misses a sample by more than this (in the field's units; 0: never;
  // the filter passes the simplification's absolute persistence threshold) gets twice its
  // segments, twice at most, up to MaximumHeightSegments (twice that where it misses by more
  // than twice this); a piece with fewer than 3 samples per new segment keeps its curve and only
  // its height gets them (RefitHeightOnCurve), where it has a sample per segment and every
  // 2-cell beside it keeps its grid or gets a multiple that stage 4's refinement could choose.
  double HeightTolerance = 0;
  // A quarter of stage 4's fitted-grid limit (TwoCellReconstruction::MaximumFittedGridSize):
  // a cell's grid is a common count of its sides, each the sum of its pieces' counts, and
  // cells beyond that limit keep the paper's interior (on the Rainier crop at k = 7, pieces
  // doubled to 14 made grids of 84 and a cell 24 % of the range off; fitting those instead
  // took the crop from 0.87 to 1.44 s).
  int MaximumHeightSegments = 12;
  // A piece refined past MaximumHeightSegments keeps the sum of the segments of every 1-cell
  // through it (a side of the 2-cells that 1-cell bounds) within this: half of stage 4's
  // fitted-grid limit (TwoCellReconstruction::MaximumFittedGridSize), since a cell's grid is a
  // count all four sides reach by whole multiples of their pieces' counts and can lie well above
  // its longest side (sides within 48 made grids of 66 on a Rainier crop at 0.5 %, k = 6, and two
  // cells lost their fitted interiors).
  int MaximumSideSegments = 24;
  // A piece's knots follow its rise as well as its length (MonotoneBSplineFit::ArcLengthAndRise)
  // where its height then fits better and its planar curve stays this close to the path
  // (working-frame units, about grid spacings) or not much farther than with knots uniform in
  // arc length (see FitPiece).
  double RiseCurveTolerance = 0.25;
  // The crossing repair crowds a long piece's new knots where the other piece (or a node)
  // comes near, keeping the density of the rest (ContactKnots; false: k rises evenly).
  bool CrowdKnotsAtContacts = true;

  // x, y (the complex's coordinates) of the domain's boundary vertices, for a mesh whose
  // corners need not be the corners of domainBounds (a jittered grid: a 1-cell's curve along
  // the boundary cut its corner vertex off, and that vertex was in no 2-cell): the boundary
  // vertex nearest each corner of the bounds (in the complex's frame) is then the domain's
  // corner. Empty (an image; the filter leaves it so): the corners of domainBounds.
  std::vector<double> BoundaryPoints;
  // The points of a triangle mesh's boundary vertices, for BoundaryPoints (empty if the mesh is
  // not one the complex can be built on).
  static std::vector<double> BoundaryPointsOf(const PlanarScalarField& mesh);

  // domainBounds: xmin, xmax, ymin, ymax of the domain (its corners become nodes when 1-cells
  // run through them, so that the boundary keeps its corners; see BoundaryPoints). Works in
  // complex.Frame; the result is in the complex's coordinates. Returns false with a message.
  bool Smooth(const MorseSmaleComplex& complex, const std::vector<JunctionPoint>& junctions,
    const double domainBounds[4], OneCellSmoothingResult& result, std::string& error) const;

  // The piece's curve made its own jagged polyline (piece.Points, its ends moved onto its
  // nodes), in the same number of cubic segments, so that stage 4's grid layouts still fit:
  // each polyline edge gets at least one straight segment, the rest go by length, so that the
  // curve's parameter still follows arc length, as the height's does. False (nothing changed)
  // if the piece has more edges than segments. The fallback for pieces that still cross.
  static bool FollowPolyline(SmoothedPiece& piece, const std::vector<SmoothingNode>& nodes);

  // The input field at a point (working-frame coordinates), false outside the domain. When
  // set, a piece whose height, fitted to its jagged path, misses the field sampled along its
  // smoothed curve by clearly more than it misses the path (by half HeightTolerance, or 5 % of
  // the piece's rise without one) gets its height fitted to the field along the curve, if that
  // misses it by less: the surface passes through the curve, not through the path.
  std::function<bool(double x, double y, double& value)> FieldAt;

  ProgressHooks Hooks;
  // The per-piece fits are independent (GLPK keeps its state per thread): they run on this.
  ParallelFor Parallel = SequentialFor;

private:
  // Smooth in the coordinates given (Smooth maps the complex into its frame and back).
  // (boundaryPoints: BoundaryPoints in those coordinates.)
  bool SmoothInFrame(const MorseSmaleComplex& complex, const std::vector<JunctionPoint>& junctions,
    const double domainBounds[4], const std::vector<double>& boundaryPoints, OneCellSmoothingResult& result,
    std::string& error) const;
  // Paper, section 4, step 1: cuts the 1-cells into pieces at their nodes and solves the
  // junction values; a 1-cell on a cycle of the relations is not cut where it runs down.
  bool CutAndSolveJunctionValues(const MorseSmaleComplex& complex, const std::vector<JunctionPoint>& junctions,
    const std::vector<Index>& junctionNode, const double domainBounds[4], const std::vector<double>& boundaryPoints,
    OneCellSmoothingResult& result, std::string& error) const;
  // Steps 2 and 3 on every piece with k = Segments (fewer on pieces of fewer edges).
  bool FitAllPieces(const MorseSmaleComplex& complex, OneCellSmoothingResult& result, const double domainBounds[4],
    std::string& error) const;
  // Raises k (twice at most) on the listed pieces whose height misses by more than
  // HeightTolerance, and fits them again.
  bool RefineMissedHeights(const MorseSmaleComplex& complex, OneCellSmoothingResult& result, std::vector<Index> pieces,
    const double domainBounds[4], std::string& error) const;
  // Raises k on crossing pieces and fits them again (sets AdaptedPieces, RefinedPieces,
  // RiseKnotPieces, RemainingCrossings).
  bool RepairCrossings(const MorseSmaleComplex& complex, OneCellSmoothingResult& result, const double domainBounds[4],
    std::string& error) const;
  // Fits the listed pieces in parallel, each with segmentsOf(piece) segments (only the height,
  // on the curve as it is, where keepCurve(piece) says so: RefitHeightOnCurve); false with the
  // first failing piece in list order named in `error`.
  bool FitInParallel(OneCellSmoothingResult& result, const std::vector<Index>& pieces,
    const std::function<int(const SmoothedPiece&)>& segmentsOf, const double domainBounds[4],
    std::string& error, const std::function<bool(const SmoothedPiece&)>& keepCurve = {}) const;
  // One piece (its arc-length parameters are derived from its samples on the first fit).
  bool FitPiece(SmoothedPiece& piece, const std::vector<SmoothingNode>& nodes, int segments, const double bounds[4],
    std::string& error) const;
  // The height of a fitted piece again with `segments` (a multiple of its count) on the same
  // parameters; its curve stays the same curve, each segment cut evenly.
  bool RefitHeightOnCurve(
    SmoothedPiece& piece, const std::vector<SmoothingNode>& nodes, int segments, std::string& error) const;
  // FieldAt at curve(t_i) for the piece's interior samples (its ends keep their values);
  // false if a point lies outside the domain. Spline: a UniformQuadraticBSpline or a
  // CubicBezierSpline of dimension 2.
  template <class Spline>
  bool SampledAlongCurve(const SmoothedPiece& piece, const Spline& curve, std::vector<double>& values) const;
};
// Applies `map` (an (x, y) in place: a PlanarFrame's ToFrame or ToWorld) to every position of
// a smoothing: its nodes, the pieces' samples and curves. Heights stay as they are.
template <typename Map>
void MapSmoothedGeometry(OneCellSmoothingResult& result, Map&& map)
{
  for (SmoothingNode& node : result.Nodes)
  {
    map(node.Position);
  }
  for (SmoothedPiece& piece : result.Pieces)
  {
    for (std::vector<double>* points : { &piece.Points, &piece.Curve.ControlPoints })
    {
      for (std::size_t i = 0; i + 1 < points->size(); i += 2)
      {
        map(&(*points)[i]);
      }
    }
  }
}
} // namespace topospline
