// Stage 2 of the paper (section 3.2): persistence simplification of a discrete Morse-Smale
// complex, as a hierarchy computed once per input and replayed for any threshold.
//
// Cancellation rule (the paper's section 3.2; Shivashankar's mscomplex-tri `cancel_pair`):
// cancelling a saddle s with an extremum x removes both and connects every other neighbour of
// s (the other extremum x' of s, of x's kind) to every other neighbour of x (the other saddles
// of x). Every 1-cell keeps its saddle, so this amounts to "every 1-cell that ended at x now
// ends at x'": x' inherits x's region, 1-cells and 2-cells.
// A pair is cancellable (checked when it is popped, in order of increasing persistence) when
// neither point is cancelled yet, the 1-cell is at least as long in value as the extremum's
// ordinary persistence (the elder rule on the input complex: sublevel sets for minima,
// superlevel sets for maxima; so no extremum at or above a threshold is ever cancelled below
// it), exactly one 1-cell joins them, both or neither lie on the boundary curve (boundary
// minima and saddles of boundary edges; except a boundary junction, see the .cxx), a boundary
// minimum is not held by a living interior saddle on the boundary, no new 1-cell would be
// inverted, and no 2-cell would lose all its corners (only stage-1 inputs that are not
// planar-consistent trigger this last rule). docs/Simplification.md says it in words.
//
// Threshold semantics (saved states depend on them; never change them):
//  * persistence of a cancellation = |f(saddle) - f(extremum)| along its 1-cell (at least the
//    extremum's ordinary persistence);
//  * MaximumPersistence() = (largest critical value) - (smallest critical value) of the
//    complex given to ComputeHierarchy; for a complex extracted from a field this is the
//    field's range max f - min f, since the global extrema are always critical;
//  * Simplify(percent) performs, in hierarchy order, the cancellations whose Threshold (the
//    running maximum of the persistences of the hierarchy up to it) is strictly below
//    percent / 100 * MaximumPersistence(); percent = 0 performs none, percent = 100 performs
//    the whole hierarchy (every cancellation that the validity rules allow).
// The running maximum makes the replay of a threshold t exactly what a greedy simplification
// stopped at t would do (it stops at the first pair of persistence >= t), and makes the
// counts monotone in t even where a cancellation creates a pair of lower persistence.
#pragma once

#include "CoreTypes.h"
#include "MorseSmaleComplex.h"

#include <array>
#include <string>
#include <vector>

namespace topospline
{
// One step of the hierarchy, in the stable ids (CriticalPoint::Id) of the input complex.
struct Cancellation
{
  Index Lower = InvalidIndex;    // the minimum (min-saddle pair) or the saddle (saddle-max pair)
  Index Upper = InvalidIndex;    // the saddle or the maximum
  Index Survivor = InvalidIndex; // the extremum that inherits the cancelled extremum's region
  double Persistence = 0;        // |f(Upper) - f(Lower)|
  double Threshold = 0;          // performed for every absolute threshold strictly above this
};

// Why an extremum whose persistence is below the threshold survives it: the last rule that
// refused a cancellation through a 1-cell reaching its persistence.
enum class BlockReason : unsigned char
{
  NotAdjacent,          // no such 1-cell reached it (its saddle's 1-cell ends at a critical
                        // point kept in between, such as a boundary minimum)
  DoubleOneCell,        // two 1-cells join the pair: cancelling would pinch off a region
  BoundaryInterior,     // one of the two is a critical point of the boundary curve
  TwoCellPinched,       // a 2-cell would lose all its corners (not planar-consistent input)
  InvertedOneCell,      // a new 1-cell would join a saddle to a higher minimum (lower maximum)
  BoundaryMinimumPinned, // a boundary minimum held by a living interior saddle on the boundary
  CornerSaddle           // the triangle of a one-triangle boundary vertex holding a boundary saddle
                         // between two minima
};

// A short name for field data and messages ("boundary-interior", ...).
const char* BlockReasonName(BlockReason reason);

struct SimplificationOutput
{
  // The simplified complex, in the form stage 1 produces. Every reference to a critical
  // point in it (OneCell::Source/Destination, TwoCell::Minimum/Maximum/Saddles and the
  // per-vertex AscendingManifold/DescendingManifold) is a position in its CriticalPoints;
  // CriticalPoints[i].Id is the stable id of the input. OneCells and 2-cells keep the
  // relative order of the input ones they come from.
  MorseSmaleComplex Complex;
  std::vector<Cancellation> Cancellations; // performed, in hierarchy order
  // Extrema of persistence (Persistence: their elder-rule pair's) below the threshold that
  // the rules kept (Survivor unset), in elder-rule order.
  std::vector<Cancellation> Blocked;
  std::vector<BlockReason> BlockReasons; // one per Blocked
  std::vector<JunctionPoint> JunctionPoints;
  double AbsoluteThreshold = 0;            // percent / 100 * MaximumPersistence()
};

class MorseSmaleComplexSimplification
{
public:
  // Checks the input, copies it and computes the whole cancellation sequence. Returns false
  // with a message for inputs that are not a complex of the stage-1 form.
  bool ComputeHierarchy(const MorseSmaleComplex& input, std::string& error);

  // Replays the hierarchy up to `percent` of MaximumPersistence() (see the top of this file)
  // and builds the simplified complex; never recomputes the hierarchy. Fails for a percent
  // outside [0, 100] or when no hierarchy was computed.
  bool Simplify(double percent, SimplificationOutput& output, std::string& error) const;
  bool Simplify(double percent, MorseSmaleComplex& output, std::string& error) const;

  bool HasHierarchy() const { return this->Computed; }
  Index NumberOfInputCriticalPoints() const { return static_cast<Index>(this->Input.CriticalPoints.size()); }
  double MaximumPersistence() const { return this->MaxPersistence; }
  // Every cancellation, in order; Threshold is non-decreasing along it.
  const std::vector<Cancellation>& Hierarchy() const { return this->Sequence; }
  // How many cancellations of Hierarchy() Simplify(percent) performs (percent in [0, 100]).
  Index NumberOfCancellations(double percent) const;

  // Whether the critical values vary, but by less than NearConstantRange of their magnitude
  // (VariesByLessThanPrecision). Stage 1's filter reads such fields as constant, so this holds
  // only for complexes extracted without it (MorseSmaleComplexExtraction::
  // NearConstantAsConstant); the filter then simplifies completely, with a warning.
  static constexpr double NearConstantRange = topospline::NearConstantRange;
  bool NearConstant() const;

  ProgressHooks Hooks;

private:
  // An elder-rule pair: the saddle where the extremum's component dies (positions).
  struct PersistencePair
  {
    double Persistence;
    Index Saddle;
    Index Extremum;
  };
  // Where, in the input, each cancellation happens (positions, not stable ids).
  struct Step
  {
    Index Saddle;
    Index Extremum;
    Index Survivor;
    int Side; // which of the saddle's 1-cells of the extremum's kind reached the extremum
  };
  // Mesh cells of the 1-cells, numbered compactly, with their point and value: the nodes of
  // the gradient forests in which merged 1-cells are traced.
  struct NodeSet
  {
    std::vector<Index> Cell;
    std::vector<double> Point; // x, y per node
    std::vector<double> Value;
    std::vector<std::array<Index, 2>> Edges; // gradient steps, each once

    // The node of mesh cell `cell`, added with its point and value at its first visit.
    Index Node(std::vector<Index>& nodeOf, Index cell, const double* point, double value);
    void AddEdge(Index a, Index b);
  };

  // Defined in the .cxx: the greedy cancellation's queue entries, running state and plan of
  // one cancellation; a replay of the hierarchy's first cancellations and its merged forests.
  struct Candidate;
  struct GreedyState;
  struct CancellationPlan;
  struct Replay;
  struct MergedForests;

  // ComputeHierarchy, in order: index the input, then the elder rule and the greedy sequence.
  void IndexOneCellsBySaddle();
  void FindBoundaryCurve();
  void IndexBoundaryCurveEdges();
  bool FindSaddleCorners(std::string& error);
  void BuildForests();
  void AddDescendingPath(Index oneCell, std::vector<Index>& nodeOfVertex);
  void AddAscendingPath(Index oneCell, std::vector<Index>& nodeOfTriangle);
  void SetCriticalPointPosition(Index criticalPoint, const double* point);
  void ComputeSequence();
  std::vector<PersistencePair> ElderRulePairs(bool minima) const;
  void ComputeOrdinaryPersistence(GreedyState& state);
  void FindBoundaryPins(GreedyState& state) const;
  void OfferAllPairs(GreedyState& state) const;
  bool PlanCancellation(GreedyState& state, const Candidate& candidate, CancellationPlan& plan);
  bool WouldPinchTwoCell(GreedyState& state, Index saddle, CancellationPlan& plan) const;
  bool KeepsCornerMaximum(GreedyState& state, Index maximum) const;
  bool IsBoundaryCurveEdge(Index a, Index b) const;
  void Cancel(GreedyState& state, const Candidate& candidate, const CancellationPlan& plan);
  int CellMerges(Index saddle, bool minimum, int side, std::array<std::array<Index, 2>, 2>& pairs) const;

  // Simplify, in order.
  void ReportBlockedExtrema(double percent, SimplificationOutput& output) const;
  Replay ReplayCancellations(Index performed, MorseSmaleComplex& out) const;
  MergedForests GrowMergedForests(const Replay& replay) const;
  bool BuildMergedOneCells(Replay& replay, const MergedForests& forests, MorseSmaleComplex& out, std::string& error) const;
  void MergeTwoCells(Replay& replay) const;
  void BuildMergedTwoCells(Replay& replay, MorseSmaleComplex& out) const;
  void RelabelVertices(Replay& replay, MorseSmaleComplex& out) const;
  std::vector<Index> FindBoundaryJunctions(const MorseSmaleComplex& out) const;

  bool Computed = false;
  MorseSmaleComplex Input;
  double MaxPersistence = 0;
  std::vector<Cancellation> Sequence;
  std::vector<Step> Steps;
  // Elder-rule pairs of the input (both kinds), each extremum's ordinary persistence, the
  // threshold its cancellation needs (infinite if never) and why it was last refused.
  std::vector<PersistencePair> ElderPairs;
  std::vector<double> OrdinaryPersistence;
  std::vector<double> CancelledAt;
  std::vector<BlockReason> RefusalOf;

  // Per critical point (position): for a saddle its descending 1-cells [0..1] and ascending
  // ones [2..3] (InvalidIndex when it has a single ascending one, on the boundary).
  std::vector<std::array<Index, 4>> SaddleOneCells;
  std::vector<Index> ArcExtremum; // per input 1-cell: its minimum or maximum (position)
  std::vector<unsigned char> OnBoundaryCurve; // per critical point: a cell of the boundary curve
  // The edges of the boundary curve (vertex pairs, lower id first, sorted): the steps of the
  // input's boundary 1-cells, which make up the whole curve.
  std::vector<std::array<Index, 2>> BoundaryCurveEdges;
  std::vector<unsigned char> OnBoundaryCurveVertex; // per vertex id up to the largest on the curve
  // Per saddle, the input 2-cell at each corner: [2 d + a] for its descending 1-cell d and
  // ascending 1-cell a (0 or 1, in SaddleOneCells order); InvalidIndex if the input has none.
  std::vector<std::array<Index, 4>> SaddleCorners;

  NodeSet DescendingNodes; // vertices
  NodeSet AscendingNodes;  // triangles
  std::vector<Index> ArcFirstNode; // per 1-cell: the saddle-side node of the forest path
  std::vector<Index> ArcLastNode;  // per descending 1-cell: the saddle's vertex (none if 1 vertex)
  std::vector<Index> RootNode;     // per extremum: its vertex / triangle node
  std::vector<double> CriticalPointPosition; // x, y per critical point (its vertex)
  // Per critical point: x, y, value of a saddle's other edge vertex (CriticalPoint::EdgeVertex),
  // NaN where unknown (extrema; a complex read without it). See BuildMergedOneCells.
  std::vector<double> SaddleEdgeEnd;
};
} // namespace topospline
