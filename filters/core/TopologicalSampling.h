// Samplings of the reconstruction with exactly the simplified complex's critical points.
//
// F o Phi has no critical point inside a 2-cell, but a piecewise-linear sampling of it can
// have small spurious pairs where the field is nearly flat or where a 1-cell (a C0 crease)
// crosses the grid obliquely: along a ridge that rises slowly, a vertex beside the crease can
// have all its neighbours lower. This pass removes them from the sampled values with the
// flooding of Tierny and Pascucci ("Generalized topological simplification of scalar fields on
// surfaces", IEEE TVCG 2012): a sweep upwards from the wanted minima fills every other pit to
// the level at which the sweep reaches it, a sweep downwards from the wanted maxima cuts every
// other peak, alternately until nothing changes. Values move only inside spurious pits and
// peaks, by less than their depth. The stage-1 boundary rule (boundary cells pair only with
// boundary cells) makes the extrema of the field along the boundary curve critical too, so
// the same sweeps first run along the boundary curve, from the wanted boundary minima and
// boundary saddles. Ties are ordered as stage 1 orders them: by value, then vertex id.
// Before the floods, the complex's smoothed 1-cells are carved into the sampling
// (CarveOneCells), so that a ridge or valley running between two rows of vertices is not cut
// into islands; after them, saddles left off their nodes are moved back (RelocateSaddles: their
// 1-cells carved again, then the patterns of their links, PlaceMissingSaddlesByTheirLinks);
// a spare saddle still a few edges off is walked there one vertex value at a time
// (WalkSpareSaddlesOntoMissing). Last, every changed vertex moves back toward F o Phi as far as the critical points allow
// (RelaxTowardTargets). TopologicalSampling::Apply runs the whole sequence.
#pragma once

#include "CoreTypes.h"
#include "MorseSmaleComplex.h"
#include "OneCellSmoothing.h"
#include "TriangleMeshTopology.h"

#include <functional>
#include <memory>
#include <utility>
#include <vector>

namespace topospline
{
struct TopologicalSamplingReport
{
  int Rounds = 0;
  bool Converged = false;
  Index ChangedVertices = 0;
  double MaximumChange = 0;
  int DisplacedSaddles = 0; // wanted saddles with no sampled saddle within the spacing and two
                            // mesh edges (the verdict's pairing, MatchCriticalPoints)
  // x, y of each wanted boundary saddle that stood above its whole link and whose only way into
  // the domain ran through a wanted minimum or saddle: its way up raised one (the sampling's
  // vertices are too few there for the complex).
  std::vector<double> BlockedWaysUp;
  std::vector<Index> BlockedWaysUpVertices; // the same saddles' vertices in the sampling
  // Wanted boundary saddles with no way up that the sampling wants one step along the boundary
  // instead, where there is one.
  int MovedBoundarySaddles = 0;
  // Interior saddles left off their nodes that the sampling wants one edge away instead
  // (TopologicalSampling::MoveDisplacedSaddles).
  int MovedInteriorSaddles = 0;
  // Spare saddles walked onto wanted ones still off their nodes (WalkSpareSaddlesOntoMissing).
  int WalkedSaddles = 0;
  // The sampling matched the complex worse than F o Phi at the same vertices, which was kept
  // unchanged (TopologicalSampling::Apply, last step).
  bool KeptExact = false;
  // The sampling stopped between two of its passes because an abort was requested (Hooks):
  // the values are those of the last pass done, not a finished sampling.
  bool Aborted = false;
};

// One smoothed 1-cell of a wanted saddle, sampled from the saddle outwards: x, y and height per
// point (heights rise along an ascending 1-cell, fall along a descending one).
struct SaddleOneCell
{
  Index Saddle = InvalidIndex; // the saddle's vertex in the sampling
  bool Ascending = false;
  std::vector<double> Points;
  // Or, with Points empty, the same points as runs [first, last) of a store that 1-cells
  // sharing smoothed pieces share (SamplingConstraints::SharedOneCellSamples, offsets in
  // doubles), in order: merged 1-cells share their first pieces, and on uniform noise their
  // own copies of those samples were a third of stage 4's peak.
  std::vector<std::pair<std::size_t, std::size_t>> Runs;
};

struct SamplingConstraints
{
  std::vector<Index> Minima;         // vertices of the wanted minima
  std::vector<Index> Maxima;         // vertices of the wanted maxima
  std::vector<Index> BoundaryMinima; // wanted minima along the boundary curve (boundary vertices)
  std::vector<Index> BoundaryMaxima; // wanted maxima along the boundary curve (higher vertex of a
                                     // critical boundary edge: a boundary saddle)
  std::vector<Index> Saddles;        // vertices of the wanted saddles (RelocateSaddles)
  // Optional, for RelocateSaddles: the smoothed 1-cells of the wanted saddles
  // (AddSaddleOneCells).
  std::vector<SaddleOneCell> SaddleOneCells;
  // Optional, for CarveOneCells: every smoothed 1-cell of the complex, whole (AddOneCells).
  std::vector<SaddleOneCell> OneCells;
  // The store of the OneCells given as Runs (each smoothed piece sampled once per direction).
  std::shared_ptr<const std::vector<double>> SharedOneCellSamples;
};


// The critical points of `complex`, extracted on `complexMesh`, as constraints on a sampling
// with mesh `mesh`: `vertexAt` gives the sampling's vertex for a vertex of `complexMesh`
// (InvalidIndex: none). A saddle of a boundary edge is a wanted maximum along the boundary.
SamplingConstraints ComplexConstraints(const MorseSmaleComplex& complex, const TriangleMeshTopology& complexMesh,
  const TriangleMeshTopology& mesh, const std::function<Index(Index)>& vertexAt);



// How CarveOneCells changes the vertices it walks along a 1-cell. The gentler, the fewer
// vertices change and the less, but on noise a saddle ends off its node more often:
// TopologicalSampling::Apply tries them in this order.
enum class OneCellCarving : int
{
  // Only where the walk would turn back (a vertex it reaches already past the value before it
  // keeps its value), and then just past that value; a ridge is not carved beside a boundary
  // row that stands as high.
  JustPastTheWalk = 0,
  // As JustPastTheWalk, but raised (lowered) to the 1-cell's height.
  WhereNeeded = 1,
  // Every vertex walked onto, to the 1-cell's height.
  Everywhere = 2
};

// Embeds the complex's 1-cells (constraints.OneCells) in the sampling before the floods. A
// 1-cell is a crease of F o Phi (a ridge for an ascending one, a valley for a descending one)
// that can run between two rows of vertices, where no vertex sees it: along a narrow ridge
// every vertex lies on its flanks, the sampled ridge breaks into islands, and the floods
// then cut them and route the 1-cell through the nearest pass, which may be another saddle.
// Each 1-cell gets a chain of vertices walking along it (each the vertex nearest to the
// curve), raised to the 1-cell's height for an ascending one (lowered for a descending one)
// and strictly monotone from the saddle on. Vertices within `spacing` of the 1-cell's saddle
// or extremum are left to the floods and to CarveSaddleOneCells; so are vertices that a
// ridge and a valley both claim, unless one kind's 1-cells pass at less than half the other's
// distance (the vertex is then that kind's), and boundary vertices the 1-cell does not run
// through. A 1-cell whose walk met a vertex claimed by both (a ridge and a valley less than a
// spacing apart) is walked again round the vertices the other kind claimed (but those that are
// its kind's), so that its chain does not break there; the other 1-cells are walked once.
// Critical vertices keep their values (the nodes' critical values, as Apply sets them), no
// vertex next to a wanted maximum (minimum) is raised (lowered) past it, and the link of a
// wanted interior monkey saddle keeps its values where the claims would leave the saddle fewer
// pieces of lower link than it needs.
// `carving` says how far (OneCellCarving). The walks run with `parallel` (they only read the
// values; the result does not depend on it). Returns the number of changed vertices.
Index CarveOneCells(const PlanarScalarField& field, const TriangleMeshTopology& mesh,
  const SamplingConstraints& constraints, double spacing, std::vector<double>& values,
  OneCellCarving carving = OneCellCarving::Everywhere, const ParallelFor& parallel = SequentialFor);

// The whole topological sampling of a reconstruction: the complex's critical points as
// constraints, its smoothed 1-cells carved in (CarveOneCells), the floods
// (EnforceCriticalVertices) and the saddles moved back onto their nodes (within Spacing and
// two mesh edges, as the verdict pairs them; looked for within 8 spacings), and the changed
// vertices relaxed back toward F o Phi (RelaxTowardTargets). The 1-cells are carved gently
// first (OneCellCarving); while saddles are left off their nodes, the whole sequence runs
// again with the next carving (on samplings of at most MaximumVerticesForMorePasses
// vertices), and the sampling with the fewest displaced saddles is kept, the gentler one of
// equals. Boundary saddles whose way up the floods forced through a wanted point are then
// wanted one step along the boundary where that has a way (MoveBlockedBoundarySaddles), and the
// kept carving runs once more (kept if it leaves fewer saddles off, or as many and fewer
// blocked). Interior saddles still off their nodes are then wanted one edge away in turn
// (MoveDisplacedSaddles; kept if fewer wanted points are missing), and spare saddles a few edges
// from wanted ones still unmatched are walked onto them (WalkSpareSaddlesOntoMissing), before the
// changed vertices are relaxed toward F o Phi (F o Phi itself is kept where the verdict's
// matching pairs more of its critical points: KeepExactWhenBetter). The complex side is fixed at
// construction; Apply samples one sampling of the reconstruction (the input vertices, a finer
// grid).
// `complexPoints` (x, y per vertex of `complexMesh`) tells where the nodes are: on a sampling
// whose vertices do not include them (an image resampled over a triangle mesh), the vertex
// nearest each node first takes the node's critical value, so that the wanted extremum is
// where the floods expect it (F o Phi peaks at the node, not at the vertex). At each of the
// complex's boundary junctions the wanted boundary pit is where the junction drains along the
// boundary (within 3 spacings), with the field falling into the domain there; a wanted
// boundary saddle at a domain corner is wanted on the higher corner neighbour (a corner above
// both its neighbours is also a maximum of stage 1).
struct CriticalPointLocation; // TopologyVerification.h
struct VertexGraphs; // the adjacency the floods walk (TopologicalSampling.cxx)

class TopologicalSampling
{
public:
  TopologicalSampling(const MorseSmaleComplex& complex, const TriangleMeshTopology& complexMesh,
    const std::vector<double>& complexPoints, const OneCellSmoothingResult& smoothed)
    : Complex(complex)
    , ComplexMesh(complexMesh)
    , ComplexPoints(complexPoints)
    , Smoothed(smoothed)
  {
  }

  // One grid spacing of the samplings: how near its node a critical point must be.
  double Spacing = 1;
  // Runs the saddle counts and matchings of the samplings and the floods' scans for candidates
  // (the floods themselves are sequential).
  ParallelFor Parallel = SequentialFor;
  // Samplings with more vertices keep the first pass (the gentlest carving) even with saddles
  // off their nodes (see Apply).
  Index MaximumVerticesForMorePasses = Index(1) << 20;
  // MoveDisplacedSaddles runs on samplings of at most this many vertices, while at most
  // MaximumSaddlesToMove saddles are off, and tries at most MaximumSaddleMoveTries neighbours
  // (each try is a whole pass).
  Index MaximumVerticesForSaddleMoves = Index(1) << 16;
  int MaximumSaddlesToMove = 4;
  int MaximumSaddleMoveTries = 24;
  // Spare saddles walked onto wanted ones still off their nodes, last (WalkSpareSaddlesOntoMissing);
  // off only to see the other steps alone.
  bool WalkSpareSaddles = true;
  // F o Phi kept unchanged where its critical points match the complex better than the
  // sampling's (by the verdict's matching); off only to see the sampling itself.
  bool KeepExactWhenBetter = true;
  // A boundary junction's pit is the boundary pit its vertex falls into along the curve; where
  // that descent stops beside a node it may not take (a wanted boundary minimum lower than the
  // vertex it reached, which is then no pit), the junction's own vertex is made the pit.
  bool PitsOnJunctionVertices = true;
  // Progress over the passes, and an abort polled between them (a pass takes seconds on a
  // million vertices of noise).
  ProgressHooks Hooks;

  // `values` (one per vertex of `mesh`, at sampling.Points) is modified in place; `vertexAt`
  // gives the sampling's vertex for a vertex of the complex's mesh (InvalidIndex: none). The
  // report counts every changed vertex and the saddles left off their nodes.
  TopologicalSamplingReport Apply(const PlanarScalarField& sampling, const TriangleMeshTopology& mesh,
    const std::function<Index(Index)>& vertexAt, std::vector<double>& values) const;

private:
  int MoveDisplacedSaddles(const VertexGraphs& graphs, const PlanarScalarField& sampling,
    const TriangleMeshTopology& mesh,
    const std::function<Index(Index)>& vertexAt, OneCellCarving carving, SamplingConstraints& constraints,
    std::vector<double>& prepared, std::vector<double>& values, TopologicalSamplingReport& report) const;
  // How far from its node a saddle is looked for and carved back.
  double SaddleReach() const { return 8 * this->Spacing; }
  // One pass: carves the 1-cells, places the boundary junctions (added to `constraints` for the
  // pass only), floods and relocates saddles.
  TopologicalSamplingReport Settle(const VertexGraphs& graphs, const PlanarScalarField& sampling,
    const TriangleMeshTopology& mesh,
    const std::function<Index(Index)>& vertexAt, SamplingConstraints& constraints, OneCellCarving carving,
    std::vector<double>& values) const;

  const MorseSmaleComplex& Complex;
  const TriangleMeshTopology& ComplexMesh;
  const std::vector<double>& ComplexPoints;
  const OneCellSmoothingResult& Smoothed;
};




// Modifies `values` (one per mesh vertex) in place. The alternation settles in a few rounds;
// as a safeguard it stops after `maximumRounds` or when a round
// changes as many vertices as the one before (Converged is then false, and a few spurious
// pairs may remain).
// `blockedWaysUp`, if given, collects the wanted boundary saddles whose way up could not keep off
// the wanted points (see TopologicalSamplingReport::BlockedWaysUp). `idsAlongRows`: the mesh's
// vertex ids run along the rows of an image grid (PlanarScalarField::IsGrid), so that a region
// re-valued on one level with ties ordered by id lies on a tilted plane; otherwise regions are
// spread between their bounds first (a harmonic order), ties only where that fails.
TopologicalSamplingReport EnforceCriticalVertices(const TriangleMeshTopology& mesh,
  const SamplingConstraints& constraints, std::vector<double>& values, int maximumRounds = 6,
  std::vector<Index>* blockedWaysUp = nullptr, bool idsAlongRows = false);

// A wanted boundary saddle whose way up the floods had to force through a wanted minimum or
// saddle (SamplingBlockedWaysUp; on noise its only interior neighbour can be a wanted minimum)
// cannot be sampled on its vertex as the complex wants it: above both boundary neighbours with
// no higher vertex it can reach, it is a maximum as well, and the forced way up takes the wanted
// point away. A boundary neighbour, one step along the curve (within the verdict's spacing),
// can have a way: the peak of the boundary curve is then wanted there, at the saddle's value
// (in `start`), and the floods lower the saddle's own vertex below it. The neighbour must be
// wanted as nothing else, must not be a domain corner, and must have a way up that keeps off
// the wanted minima and saddles in `settled` (the values of the pass that was blocked); of two,
// the one whose value changes less. `blocked`: the saddles' vertices, as EnforceCriticalVertices
// lists them. `constraints` (BoundaryMaxima, Saddles) and `start` are changed; returns the number
// of saddles moved. TopologicalSampling::Apply then settles the sampling again from `start` and
// keeps the result if it leaves fewer saddles off their nodes (or as many, fewer blocked).
int MoveBlockedBoundarySaddles(const TriangleMeshTopology& mesh, const std::vector<Index>& blocked,
  const std::vector<double>& settled, SamplingConstraints& constraints, std::vector<double>& start);

// A wanted saddle inside the domain that the carving of its 1-cells did not put on its vertex
// (its smoothed 1-cells leave it where a carved link vertex is a dead end: raised past the
// saddle with no higher vertex beyond it, a peak that the floods cut back again; or sampling
// left a link vertex exactly at the saddle's value): its link vertices are put on the sides a
// saddle of its multiplicity needs (just past the saddle's value), one pattern of sides at a
// time in the order of the change it costs, and the floods run again; a pattern is kept if more
// wanted saddles are then matched within `tolerance` without more found ones. Only if at most
// `maximumMissing` wanted saddles are off (each pattern floods the whole sampling and counts its
// saddles), and the cheapest `maximumPatterns` patterns of each. Boundary saddles are left alone (the
// boundary rule has its own passes). Returns the number of wanted saddles still off.
// RelocateSaddles (TopologicalSampling::Apply) runs this after the carving.
int PlaceMissingSaddlesByTheirLinks(const PlanarScalarField& field, const TriangleMeshTopology& mesh,
  const SamplingConstraints& constraints, double tolerance, std::vector<double>& values, int maximumMissing,
  int maximumPatterns);

// The last step of a sampling: saddles still off their nodes, walked there one vertex value at
// a time. Where the complex is denser than the vertices (uniform noise, a boundary saddle beside
// a corner minimum), the passes can leave a wanted saddle unmatched and a spare saddle two or
// three edges away, with every extremum in place; no 1-cell carving or flood moves it the last
// step, but one vertex set past a neighbour's value often does. Each step changes one vertex
// that holds no wanted point, to the value nearest its own within another gap between its
// neighbours' values, and is taken only if, judged by stage 1's own lower-star rule
// (DiscreteGradient::CriticalCellsOfLowerStar) on that vertex and its link, no minimum or
// maximum appears or goes and the spare saddle alone moves, to a vertex no more edges from the
// missing one. The walk searches depth first (nearest steps first, then the smallest change; at
// most `maximumSteps` deep and `maximumTries` steps in all) until the saddle is within the
// missing one's reach as the verdict pairs them (`tolerance` times its Reach, within its Hops);
// a walk that does not get there is undone. Spare saddles farther than `reachHops` edges are
// not walked. `expected` is the verdict's list (CriticalPointLocations, with vertices of
// `mesh`); `points`: x, y per vertex. Every other critical cell stays where it is, so the
// verdict's matching gains one pair per walk kept (the lower stars and the matching run with
// `parallel`; the walks themselves are sequential). Returns the number of walks kept.
int WalkSpareSaddlesOntoMissing(const TriangleMeshTopology& mesh, const std::vector<double>& points,
  const std::vector<CriticalPointLocation>& expected, double tolerance, std::vector<double>& values,
  const ParallelFor& parallel = SequentialFor, int reachHops = 6, int maximumSteps = 12, int maximumTries = 200);

// The critical points of `values` that the verdict's matching leaves unpaired: wanted points of
// `expected` (CriticalPointLocations, with vertices of `mesh`) without a critical cell of
// stage 1's lower-star rule within `tolerance` and their Hops, and critical cells without a
// wanted point. 0: the verdict's comparison is identical.
Index MismatchedCriticalPoints(const TriangleMeshTopology& mesh, const std::vector<double>& points,
  const std::vector<CriticalPointLocation>& expected, double tolerance, const std::vector<double>& values,
  const ParallelFor& parallel = SequentialFor);

// Makes every wanted extremum an extremum again where a step before (a flood of the other
// kind, a carved 1-cell, a saddle moved back) took that away: the vertex is moved just past its
// extreme neighbour (the whole link for minima and maxima, the boundary curve for boundary
// minima and maxima). The floods then remove what this creates around it. Returns the number of
// changed vertices.
Index RestoreWantedExtrema(const TriangleMeshTopology& mesh, const SamplingConstraints& constraints,
  std::vector<double>& values);

// Moves every vertex whose value differs from its target back toward it without changing any
// critical point: as far as its order against each neighbour allows (strictly above every
// neighbour below it, strictly below every neighbour above it; ties by value, then vertex id),
// and, for a vertex off the boundary, past interior neighbours where neither it nor any of them
// changes kind (minimum, maximum, regular, saddle of its multiplicity: only their links change).
// The sampling keeps exactly its critical points (kinds, multiplicities, vertices), and every
// vertex ends at least as close to its target, while what the steps before changed beyond what
// the critical points need shrinks: a wanted minimum lifted with its pit sinks back to its
// critical value, a vertex raised past a carved chain comes back down. Sweeps go in order of
// value (those moving down from the lowest, those moving up from the highest), so that a run of
// vertices follows the one before it; at most `maximumSweeps`. Returns the number of moves.
Index RelaxTowardTargets(const TriangleMeshTopology& mesh, const std::vector<double>& targets,
  std::vector<double>& values, int maximumSweeps = 8);

} // namespace topospline
