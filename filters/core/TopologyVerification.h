// The reconstruction's promise, checked: the Morse-Smale complex of the reconstructed field
// (extracted again with stage 1 on a sampling of it) must have exactly the critical points of
// the simplified complex, each near its node, and no others.
#pragma once

#include "CoreTypes.h"
#include "MorseSmaleComplexExtraction.h"
#include "TriangleMeshTopology.h"

#include <array>
#include <vector>

namespace topospline
{
struct CriticalPointLocation
{
  int MorseIndex = 0;
  double Position[2] = { 0, 0 };
  double Value = 0;
  // How far from Position it may be found, in units of the comparison's tolerance: 1 for the
  // complex's nodes; more for the pair stage 1 puts where the boundary 1-cells of a boundary
  // junction turn into the domain (no critical point of the field itself: its place along
  // the boundary is wherever the sampled valley meets it).
  double Reach = 1;
  // The vertex it is on (InvalidIndex: none), and how many mesh edges away from it it may be
  // found when the comparison is given the mesh (below).
  Index Vertex = InvalidIndex;
  int Hops = 2;
};

// How far (in tolerances) from a boundary junction its stage-1 pair may lie along the boundary.
constexpr double BoundaryJunctionReach = 3;
// "On or next to its node", in edges: 2 takes in the 8 vertices around a grid vertex (the one
// in the diagonal the triangles do not cut is 2 edges away), as one grid diagonal of tolerance
// does; the pair of a boundary junction, 3. On an irregular mesh the longest edge (the
// tolerance) can span 3 or more typical edges: with the mesh, both limits hold.
constexpr int BoundaryJunctionHops = 3;

// The critical points of `complex`, placed at their vertices of `points` (x, y per vertex),
// and a minimum and a saddle at each of its boundary junctions (MorseSmaleComplex).
std::vector<CriticalPointLocation> CriticalPointLocations(
  const MorseSmaleComplex& complex, const std::vector<double>& points);

struct TopologyComparison
{
  std::array<Index, 3> Expected{ { 0, 0, 0 } }; // minima, saddles, maxima
  std::array<Index, 3> Found{ { 0, 0, 0 } };
  std::vector<CriticalPointLocation> Spurious; // found, not matched to an expected one
  std::vector<CriticalPointLocation> Missing;  // expected, not matched
  double MaximumDistance = 0;                  // over matched pairs
  bool Identical() const { return this->Spurious.empty() && this->Missing.empty(); }
};

// Matches found to expected critical points of the same index within `tolerance` (times the
// expected point's Reach), one to one, as many as any such assignment can (closest pairs
// first, then augmenting paths: a row of saddles found each one vertex along from its node is
// matched whole). Returns the found point of each expected one (UnmatchedCriticalPoint: none).
constexpr std::size_t UnmatchedCriticalPoint = static_cast<std::size_t>(-1);
// With `mesh` (whose vertices both sets' Vertex name), a pair also needs the found vertex
// within the expected point's Hops edges. The candidate pairs are looked for with `parallel`
// (the result does not depend on it).
std::vector<std::size_t> MatchCriticalPoints(const std::vector<CriticalPointLocation>& expected,
  const std::vector<CriticalPointLocation>& found, double tolerance, const TriangleMeshTopology* mesh = nullptr,
  const ParallelFor& parallel = SequentialFor);

// MatchCriticalPoints of many found sets against one expected set, on `mesh` (x, y per vertex in
// `points`): topological sampling matches its saddles a few dozen times per pass against the
// same wanted ones, and finding the candidate pairs again each time (a bucket search and a walk
// over the mesh per pair) and sorting them was a sixth of stage 4's time on 500 x 500 noise.
// Here every pair an expected point can make is found once, sorted as MatchCriticalPoints sorts
// its pairs: each vertex within the point's Hops edges and its reach (tolerance times Reach).
// Match keeps those whose vertex holds a found point of the point's index, in that order, and
// matches them as MatchCriticalPoints does: the same partners. When an expected point is on no
// vertex, or a found point not at its vertex, Match is MatchCriticalPoints itself.
class CriticalPointMatcher
{
public:
  CriticalPointMatcher(const std::vector<CriticalPointLocation>& expected, const std::vector<double>& points,
    double tolerance, const TriangleMeshTopology& mesh, const ParallelFor& parallel = SequentialFor);

  // The found point of each expected one (UnmatchedCriticalPoint: none), as MatchCriticalPoints.
  // Not for two threads at once: the found points are listed per vertex in this object.
  std::vector<std::size_t> Match(const std::vector<CriticalPointLocation>& found);

private:
  // Whether v is a vertex of the mesh with a position in Points.
  bool IsVertex(Index v) const;

  struct Candidate
  {
    double Distance;
    Index Expected;
    Index Vertex;
  };
  const std::vector<CriticalPointLocation> Expected;
  const std::vector<double>& Points;
  const double Tolerance;
  const TriangleMeshTopology& Mesh;
  const ParallelFor Parallel; // a copy: the default argument is a temporary
  bool OnVertices = true; // every expected point on a vertex of the mesh
  std::vector<Candidate> Candidates; // by distance, then expected point, then vertex
  // Per vertex, the first found point on it in a Match (cleared again after it): a list the
  // size of the mesh made each match cost a pass over every vertex, 4 million on a terrain
  // with a few hundred saddles.
  std::vector<std::size_t> FirstFoundAt;
};

// The comparison of MatchCriticalPoints: counts, the points left over on either side.
TopologyComparison CompareCriticalPoints(const std::vector<CriticalPointLocation>& expected,
  const std::vector<CriticalPointLocation>& found, double tolerance, const TriangleMeshTopology* mesh = nullptr,
  const ParallelFor& parallel = SequentialFor);
} // namespace topospline
