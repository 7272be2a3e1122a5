// Tests of stage 3 as a whole (OneCellSmoothing; paper, section 4) on the output of the real
// stages 1 and 2 for synthetic fields: the 1-cells cut into chains of pieces between nodes,
// junction values strictly increasing along every piece, critical values kept, every height
// strictly increasing on its cubic Bezier coefficients and interpolating its nodes' values
// exactly, every curve from node to node inside the domain, no crossings left, the same result
// with 1 and several threads, progress and abort, and bad input. The units of stage 3 have
// their own tests: TestJunctionValueProgram, TestMonotoneBSplineFit, TestBezierSpline.
//
// Usage: TestOneCellSmoothing
// Prints figures per field, then "N passed, N failed"; returns nonzero on failure.
#include "DeterministicRandom.h"
#include "MorseSmaleComplexExtraction.h"
#include "MorseSmaleComplexSimplification.h"
#include "OneCellSmoothing.h"
#include "PiecewiseLinearField.h"
#include "SyntheticFields.h"
#include "TestHarness.h"
#include "TestSupport.h"
#include "TwoCellReconstruction.h"

#include <array>
#include <set>
#include <map>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

using namespace topospline;

namespace
{
struct Stage3Input
{
  MorseSmaleComplex Input;
  SimplificationOutput Simplified;
  double Bounds[4] = { 0, 0, 0, 0 };
  double Range = 0;
};

bool RunStages1And2(const GridField& grid, double percent, Stage3Input& input, std::string& error)
{
  const PlanarScalarField field = FieldOnGrid(grid);
  const int nx = grid.Dimensions[0], ny = grid.Dimensions[1];
  MorseSmaleComplexExtraction extraction;
  MorseSmaleComplexSimplification simplification;
  if (!extraction.Extract(field, input.Input, error) || !simplification.ComputeHierarchy(input.Input, error) ||
    !simplification.Simplify(percent, input.Simplified, error))
  {
    return false;
  }
  const auto [lo, hi] = std::minmax_element(grid.Values.begin(), grid.Values.end());
  input.Range = *hi - *lo;
  input.Bounds[0] = grid.Origin[0];
  input.Bounds[1] = grid.Origin[0] + (nx - 1) * grid.Spacing[0];
  input.Bounds[2] = grid.Origin[1];
  input.Bounds[3] = grid.Origin[1] + (ny - 1) * grid.Spacing[1];
  return true;
}

// Stage 3 of `input` with k segments and `heightTolerance`, other options default.
bool SmoothWithSegments(const Stage3Input& input, int k, double heightTolerance, OneCellSmoothingResult& result,
  std::string& error)
{
  OneCellSmoothing smoothing;
  smoothing.Segments = k;
  smoothing.HeightTolerance = heightTolerance;
  return smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error);
}

// Stages 1 and 2 of `grid` at `percent`, then stage 3 with k segments (other options default).
bool SmoothWithSegments(
  const GridField& grid, double percent, int k, Stage3Input& input, OneCellSmoothingResult& result, std::string& error)
{
  return RunStages1And2(grid, percent, input, error) && SmoothWithSegments(input, k, 0.0, result, error);
}

// The properties the paper asks of the smoothed 1-cells (section 4, steps 1-3).
void CheckSmoothedOneCells(const Stage3Input& input, const OneCellSmoothingResult& result, int k)
{
  const MorseSmaleComplex& complex = input.Simplified.Complex;
  const std::vector<SmoothingNode>& nodes = result.Nodes;
  CHECK(!result.Pieces.empty());
  CHECK(result.PiecesOfOneCell.size() == complex.OneCells.size());
  // Critical values are kept (up to the separation of ties); junctions get new values.
  for (Index c = 0; c < static_cast<Index>(complex.CriticalPoints.size()); ++c)
  {
    CHECK(nodes[c].Type == SmoothingNode::Critical && nodes[c].Source == c);
    CHECK(std::abs(nodes[c].Value - complex.CriticalPoints[c].Value) <= 1e-9 * input.Range);
  }
  // Every 1-cell is a chain of pieces from its source to its destination.
  for (Index a = 0; a < static_cast<Index>(complex.OneCells.size()); ++a)
  {
    const std::vector<Index>& chain = result.PiecesOfOneCell[a];
    // A 1-cell of one point (a boundary saddle on its extremum's vertex) has no piece.
    CHECK(chain.empty() == (complex.OneCells[a].Values.size() < 2));
    if (chain.empty())
    {
      continue;
    }
    // ... or at a node on the same point: a double saddle is two nodes on one vertex, and a
    // piece ends at the first it reaches (uniform noise has them).
    auto sameNode = [&nodes](Index x, Index y) {
      return x == y || (nodes[x].Position[0] == nodes[y].Position[0] && nodes[x].Position[1] == nodes[y].Position[1]);
    };
    CHECK(sameNode(result.Pieces[chain.front()].StartNode, complex.OneCells[a].Source));
    CHECK(sameNode(result.Pieces[chain.back()].EndNode, complex.OneCells[a].Destination));
    for (std::size_t i = 0; i + 1 < chain.size(); ++i)
    {
      CHECK(result.Pieces[chain[i]].EndNode == result.Pieces[chain[i + 1]].StartNode);
    }
    for (Index p : chain)
    {
      const auto& cells = result.Pieces[p].OneCells;
      CHECK(std::find(cells.begin(), cells.end(), a) != cells.end());
    }
  }
  int badHeights = 0, badEnds = 0, outsideBox = 0;
  for (const SmoothedPiece& piece : result.Pieces)
  {
    const double a = nodes[piece.StartNode].Value, b = nodes[piece.EndNode].Value;
    CHECK(a < b);
    // k, or on shorter pieces at least a segment per jagged edge
    const int edges = static_cast<int>(piece.Points.size() / 2) - 1;
    CHECK(piece.Segments >= std::min(k, std::max(2, edges)) && piece.Height.Segments == piece.Segments &&
      piece.Curve.Segments == piece.Segments);
    CHECK(piece.Height.Dimension == 1 && piece.Curve.Dimension == 2);
    // Strictly increasing ordinates but for the zero slopes at both ends.
    const int segments = piece.Height.Segments;
    for (int j = 0; j < segments; ++j)
    {
      const double* c = piece.Height.Segment(j);
      for (int m = 0; m < 3; ++m)
      {
        const bool end = (j == 0 && m == 0) || (j == segments - 1 && m == 2);
        badHeights += end ? c[m + 1] != c[m] : !(c[m + 1] > c[m]);
      }
    }
    badEnds += piece.Height.Value(0.0) != a || piece.Height.Value(1.0) != b;
    double start[2], end[2];
    piece.Curve.Evaluate(0.0, start);
    piece.Curve.Evaluate(1.0, end);
    badEnds += start[0] != piece.Points[0] || start[1] != piece.Points[1];
    badEnds += end[0] != piece.Points[piece.Points.size() - 2] || end[1] != piece.Points.back();
    // Clamped control points keep the curve in the domain's box.
    for (std::size_t i = 0; i < piece.Curve.ControlPoints.size(); ++i)
    {
      const double value = piece.Curve.ControlPoints[i];
      const int axis = static_cast<int>(i % 2);
      outsideBox += value < input.Bounds[2 * axis] || value > input.Bounds[2 * axis + 1];
    }
    // (the LP's rounding: relative to the errors too, where spread ties make b - a ~1e-11)
    CHECK(piece.L1Error >= piece.UnconstrainedL1Error - 1e-6 * (b - a) * static_cast<double>(piece.Values.size()) -
        1e-12 * piece.UnconstrainedL1Error);
  }
  CHECK(badHeights == 0);
  CHECK(badEnds == 0);
  CHECK(outsideBox == 0);
  CHECK(result.RemainingCrossings == 0);
  CHECK(result.PiecesOutsideDomain == 0);
  CHECK(result.JunctionMargin > 0);
}

bool SameResult(const OneCellSmoothingResult& x, const OneCellSmoothingResult& y)
{
  if (x.Pieces.size() != y.Pieces.size() || x.Nodes.size() != y.Nodes.size() ||
    x.AdaptedPieces != y.AdaptedPieces || x.RemainingCrossings != y.RemainingCrossings)
  {
    return false;
  }
  for (std::size_t n = 0; n < x.Nodes.size(); ++n)
  {
    if (x.Nodes[n].Value != y.Nodes[n].Value)
    {
      return false;
    }
  }
  for (std::size_t p = 0; p < x.Pieces.size(); ++p)
  {
    if (x.Pieces[p].Height.ControlPoints != y.Pieces[p].Height.ControlPoints ||
      x.Pieces[p].Curve.ControlPoints != y.Pieces[p].Curve.ControlPoints)
    {
      return false;
    }
  }
  return true;
}

// Stages 1 to 3 (k = 4) on seeded n x n uniform noise at `percent`; false with the error printed.
bool SmoothNoise(int n, std::uint64_t seed, double percent, Stage3Input& input, OneCellSmoothing& smoothing,
  OneCellSmoothingResult& result)
{
  std::string error;
  smoothing.Segments = 4;
  const bool ok = RunStages1And2(UniformNoise(n, seed), percent, input, error) &&
    smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error);
  if (!ok)
  {
    std::printf(
      "  noise %d^2, seed %llu, %g %%: %s\n", n, static_cast<unsigned long long>(seed), percent, error.c_str());
  }
  return ok;
}
} // namespace

//------------------------------------------------------------------------------
TEST_CASE(SmoothedOneCellsOfSyntheticFields)
{
  struct Case
  {
    const char* Name;
    GridField Grid;
    double Percent;
    int Segments;
  };
  const Case cases[] = {
    { "trigonometric 100x100, 1%, k=4", TrigonometricField(10, 100, -49), 1.0, 4 },
    { "trigonometric 100x100, 1%, k=7", TrigonometricField(10, 100, -49), 1.0, 7 },
    { "Shepard 40 sites 120x120, 5%, k=4", ShepardField(40, 2.0, 120, 3), 5.0, 4 },
    { "Shepard 40 sites 120x120, 0%, k=2", ShepardField(40, 2.0, 120, 3), 0.0, 2 },
  };
  for (const Case& c : cases)
  {
    Stage3Input input;
    std::string error;
    CHECK(RunStages1And2(c.Grid, c.Percent, input, error));
    OneCellSmoothing smoothing;
    smoothing.Segments = c.Segments;
    OneCellSmoothingResult result;
    const bool ok =
      smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error);
    CHECK(ok);
    if (!ok)
    {
      std::printf("  %s: %s\n", c.Name, error.c_str());
      continue;
    }
    CheckSmoothedOneCells(input, result, c.Segments);
    std::printf("  %s: %zu 1-cells, %zu nodes, %zu pieces, %d adapted, %d clamped, margin %.2e\n", c.Name,
      input.Simplified.Complex.OneCells.size(), result.Nodes.size(), result.Pieces.size(), result.AdaptedPieces,
      result.ClampedPieces, result.JunctionMargin);

    // The pieces are fitted in parallel: the same result with several threads.
    OneCellSmoothing threaded = smoothing;
    threaded.Parallel = ThreadedFor;
    OneCellSmoothingResult again;
    CHECK(threaded.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, again, error));
    CHECK(SameResult(result, again));
  }
}

//------------------------------------------------------------------------------
// Uniform noise: thousands of junction programs and a crossing repair over thousands of pieces,
// both in parallel (the programs, the crossing grid's bands): the same result on several threads
// as on one.
TEST_CASE(NoiseSmoothsTheSameOnAnyNumberOfThreads)
{
  for (const double percent : { 2.0, 10.0 })
  {
    Stage3Input input;
    OneCellSmoothing smoothing;
    OneCellSmoothingResult result;
    CHECK(SmoothNoise(90, 1234, percent, input, smoothing, result));
    CheckSmoothedOneCells(input, result, 4);
    OneCellSmoothing threaded = smoothing;
    threaded.Parallel = ThreadedFor;
    OneCellSmoothingResult again;
    std::string error;
    CHECK(threaded.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, again, error));
    CHECK(SameResult(result, again));
    CHECK(result.PiecesOfOneCell == again.PiecesOfOneCell && result.DroppedCuts == again.DroppedCuts);
    std::printf("  noise 90^2 at %g %%: %zu pieces, %d adapted, %d crossings left\n", percent, result.Pieces.size(),
      result.AdaptedPieces, result.RemainingCrossings);
  }
}

//------------------------------------------------------------------------------
// Uniform noise at a low threshold leaves thousands of pieces of 2-3 samples. At a large k they
// get the smallest divisor of k with a segment per edge, not k: their k segments fitted
// nothing, and stage 4's grids, as fine as a cell's busiest side, took over 24 GB on 100^2
// noise at k 21.
TEST_CASE(ShortPiecesGetNoMoreSegmentsThanEdges)
{
  const GridField noise = UniformNoise(40, 62);
  Stage3Input input;
  std::string error;
  OneCellSmoothingResult result;
  CHECK(SmoothWithSegments(noise, 2.0, 21, input, result, error));
  CheckSmoothedOneCells(input, result, 21);
  int shorter = 0, beyond = 0;
  long segments = 0;
  for (const SmoothedPiece& piece : result.Pieces)
  {
    const int edges = static_cast<int>(piece.Points.size() / 2) - 1;
    shorter += edges <= 7 ? 1 : 0; // 7: the largest divisor of 21 below it
    // a divisor of k (stage 4's grids), the smallest with an edge per segment, unless
    // crossings raised it
    int least = 21;
    for (int d = std::max(2, edges); d < 21 && least == 21; ++d)
    {
      least = 21 % d == 0 ? d : least;
    }
    beyond += piece.Segments != least ? 1 : 0;
    segments += piece.Segments;
  }
  CHECK(shorter > 0 && result.ShortPieces == shorter);
  CHECK(beyond <= result.AdaptedPieces);
  CHECK(segments < 21L * static_cast<long>(result.Pieces.size()) / 3);
  std::printf("  40^2 noise, 2%%, k 21: %zu pieces, %d short, %ld segments (k each: %zu), %d adapted\n",
    result.Pieces.size(), result.ShortPieces, segments, 21 * result.Pieces.size(), result.AdaptedPieces);
}

//------------------------------------------------------------------------------
// A prime k has no divisor to give short pieces: on noise they keep k segments each, and stage
// 4's grids grow with the square of a side's segments. The result names the nearest k whose
// divisors serve nearly every piece, checked here with the test's own count of the segments a
// piece of e edges starts with.
TEST_CASE(APrimeKOnNoiseIsToldABetterOne)
{
  const GridField noise = UniformNoise(40, 62);
  Stage3Input input;
  std::string error;
  CHECK(RunStages1And2(noise, 2.0, input, error));
  const auto startCount = [](int edges, int k) {
    for (int d = std::max(2, edges); d < k; ++d)
    {
      if (k % d == 0)
      {
        return d;
      }
    }
    return k;
  };
  // Segments on pieces with more than twice their edges, and all segments, at k.
  const auto spend = [&](const std::vector<int>& edges, int k) {
    long wasted = 0, total = 0;
    for (const int e : edges)
    {
      const int n = startCount(e, k);
      total += n;
      wasted += n > 2 * std::max(2, e) ? n : 0;
    }
    return std::make_pair(wasted, total);
  };
  for (const int k : { 11, 12, 4 })
  {
    OneCellSmoothing smoothing;
    smoothing.Segments = k;
    OneCellSmoothingResult result;
    CHECK(smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error));
    std::vector<int> edges;
    int oversegmented = 0;
    for (const SmoothedPiece& piece : result.Pieces)
    {
      edges.push_back(static_cast<int>(piece.Points.size() / 2) - 1);
      oversegmented += startCount(edges.back(), k) > 2 * std::max(2, edges.back()) ? 1 : 0;
    }
    CHECK(result.OversegmentedPieces == oversegmented);
    const auto [wasted, total] = spend(edges, k);
    const int suggested = result.SuggestedSegments;
    std::printf("  40^2 noise, 2%%, k %d: %d of %zu pieces oversegmented (%ld of %ld segments), suggested %d\n", k,
      oversegmented, result.Pieces.size(), wasted, total, suggested);
    if (2 * wasted <= total)
    {
      CHECK(suggested == 0);
      continue;
    }
    // A prime k on noise: a suggestion, within the GUI's range, that serves nearly every piece,
    // and none nearer does.
    CHECK(k == 11 && suggested >= 2 && suggested <= OneCellSmoothing::MaximumCurveSegments && suggested != k);
    const auto [w, t] = spend(edges, suggested);
    CHECK(10 * w <= t);
    for (int other = 2; other <= OneCellSmoothing::MaximumCurveSegments; ++other)
    {
      if (std::abs(other - k) < std::abs(suggested - k))
      {
        const auto [ow, ot] = spend(edges, other);
        CHECK(10 * ow > ot);
      }
    }
  }
  // Nothing to suggest without pieces; pieces of 2 edges alone at a prime k: an even k beside it.
  CHECK(OneCellSmoothing::SuggestCurveSegments({}, 11) == 0);
  const int twoEdges = OneCellSmoothing::SuggestCurveSegments(std::vector<int>(50, 2), 23);
  CHECK(twoEdges == 22 || twoEdges == 24);
}

//------------------------------------------------------------------------------
// Counts raised by crossings or height misses still give every 2-cell a common grid. Stage 4
// subdivides each piece of a cell's four sides by a whole factor to one count N per side (at
// most 512, TwoCellReconstruction::MaximumGridSize). Short pieces start at a divisor of k; when
// raising doubled them too, k = 22 gave pieces of 32 (2 doubled four times) beside 44 and 88
// on one cell, and the first N they all reach is 704: the stress test's failed 2-cells on noise
// at 50 % and Delaunay meshes with k 22, 26 and 30. Oracle in the test: per cell, the smallest N
// that every non-empty side reaches as a sum of its pieces' counts, each used at least once
// (a coin problem solved here by a table over N).
namespace
{
bool SidesReachOneGrid(const std::array<std::vector<int>, 4>& sides, int limit, int& reached)
{
  std::array<std::vector<char>, 4> sums;
  for (int s = 0; s < 4; ++s)
  {
    sums[s].assign(limit + 1, 0);
    int base = 0;
    for (int count : sides[s])
    {
      base += count;
    }
    if (sides[s].empty() || base > limit)
    {
      sums[s].assign(limit + 1, sides[s].empty() ? 1 : 0);
      continue;
    }
    sums[s][base] = 1;
    for (int n = base + 1; n <= limit; ++n)
    {
      for (int count : sides[s])
      {
        sums[s][n] = sums[s][n] || (n - count >= base && sums[s][n - count]);
      }
    }
  }
  for (int n = 1; n <= limit; ++n)
  {
    if (sums[0][n] && sums[1][n] && sums[2][n] && sums[3][n])
    {
      reached = n;
      return true;
    }
  }
  return false;
}

// For every 2-cell whose sides assemble (AssembleTwoCellSides): whether its pieces' counts
// reach a common grid within `limit` (SidesReachOneGrid) and the grid reached.
void ForEachCellGrid(const Stage3Input& input, const OneCellSmoothingResult& result, int limit,
  const std::function<void(bool, int)>& visit)
{
  std::string error;
  for (const TwoCell& cell : input.Simplified.Complex.TwoCells)
  {
    TwoCellSides sides;
    if (!AssembleTwoCellSides(cell, result, sides, error))
    {
      continue;
    }
    std::array<std::vector<int>, 4> counts;
    for (int s = 0; s < 4; ++s)
    {
      for (Index p : sides.Pieces[s])
      {
        counts[s].push_back(result.Pieces[p].Segments);
      }
    }
    int reached = 0;
    const bool within = SidesReachOneGrid(counts, limit, reached);
    visit(within, reached);
  }
}
} // namespace

TEST_CASE(RaisedCountsKeepACommonGridPerCell)
{
  const int limit = TwoCellReconstruction().MaximumGridSize;
  int runs = 0, cells = 0, beyond = 0, largest = 0;
  for (int k : { 22, 26, 30 })
  {
    for (double percent : { 25.0, 50.0 })
    {
      for (std::uint64_t seed = 1; seed <= 4; ++seed)
      {
        const GridField noise = UniformNoise(64, 1000 * seed + k);
        Stage3Input input;
        std::string error;
        CHECK(RunStages1And2(noise, percent, input, error));
        OneCellSmoothing smoothing;
        smoothing.Segments = k;
        smoothing.HeightTolerance = percent / 100 * input.Range; // as the filter
        OneCellSmoothingResult result;
        CHECK(smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error));
        ++runs;
        ForEachCellGrid(input, result, limit, [&](bool within, int reached) {
          ++cells;
          if (!within)
          {
            ++beyond;
            std::printf("  k %d, %.0f %%, seed %llu: a cell's sides reach no common grid up to %d\n", k, percent,
              static_cast<unsigned long long>(seed), limit);
          }
          largest = std::max(largest, reached);
        });
      }
    }
  }
  std::printf("  64^2 noise, k 22/26/30, 25/50 %%: %d runs, %d cells, %d beyond %d, largest grid %d\n", runs, cells,
    beyond, limit, largest);
  CHECK(beyond == 0);
}

namespace
{
// The largest |height - sample| over a piece's interior samples, from its Bezier height.
double LargestMissOfOwnSamples(const SmoothedPiece& piece)
{
  double miss = 0;
  for (std::size_t i = 1; i + 1 < piece.Values.size(); ++i)
  {
    double h = 0;
    piece.Height.Evaluate(piece.Parameters[i], &h);
    miss = std::max(miss, std::abs(h - piece.Values[i]));
  }
  return miss;
}
} // namespace

//------------------------------------------------------------------------------
// Merged 1-cells share their pieces: two 1-cells that run through the same mesh cells are cut
// at the junction where they meet, so no two pieces run along one stretch (such pieces cross
// wherever their curves differ, and the 2-cell between them has no area). Only a 1-cell whose
// cuts would order nodes in a cycle loses cuts (DroppedCuts), and only there may pieces
// overlap. Before, one cycle anywhere left every 1-cell that ran down through a junction
// uncut: 100^2 noise at 25 % had 910 pairs of pieces crossing to the end.
// With a height tolerance (the filter passes the simplification's threshold), every piece whose
// height misses a sample by more gets twice its segments where it has the samples for them (3
// per segment) and stays within MaximumHeightSegments; fewer pieces miss by more than the
// tolerance. The misses are measured here from the Bezier heights at the pieces' parameters.
TEST_CASE(PiecesThatMissTheDataGetMoreSegments)
{
  int before = 0, after = 0, unrefined = 0;
  for (std::uint64_t seed : { 0, 2, 3 })
  {
    Stage3Input input;
    std::string error;
    CHECK(RunStages1And2(ShepardField(50, 2.0, 250, seed), 5.0, input, error));
    const double tolerance = 0.05 * input.Range;
    const auto misses = [&](const OneCellSmoothingResult& result, bool refined) {
      int count = 0;
      for (const SmoothedPiece& piece : result.Pieces)
      {
        const double miss = LargestMissOfOwnSamples(piece);
        count += miss > tolerance ? 1 : 0;
        const bool room = static_cast<int>(piece.Values.size()) > 3 * 8;
        unrefined += refined && miss > tolerance && room && piece.Segments < 8 ? 1 : 0;
        CHECK(piece.Segments <= 24 || !refined); // 12, or 24 where it missed by more than 2 eps
      }
      return count;
    };
    OneCellSmoothing plain;
    OneCellSmoothingResult a, b;
    CHECK(plain.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, a, error));
    OneCellSmoothing refining;
    refining.HeightTolerance = tolerance;
    CHECK(refining.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, b, error));
    CheckSmoothedOneCells(input, b, 4);
    CHECK(a.RefinedPieces == 0 && b.RefinedPieces > 0);
    before += misses(a, false);
    after += misses(b, true);
  }
  std::printf("  Shepard 5 %%, k = 4, seeds 0, 2, 3: pieces missing by more than 5 %% of the range %d -> %d\n",
    before, after);
  CHECK(after < before);
  CHECK(unrefined == 0);
}

// The field between its vertices, against what linear interpolation must give: a linear field
// exactly, on a grid with an origin and uneven spacing and on a Delaunay mesh of random points
// (the bucket grid's path; also with half its triangles listed clockwise); a Shepard field the
// same through the grid's closed form and through its triangles spelled out; nothing outside
// the domain.
TEST_CASE(PiecewiseLinearFieldInterpolatesOnGridsAndMeshes)
{
  const auto linear = [](double x, double y) { return 1.5 - 2 * x + 3 * y; };
  DeterministicRandom random(7);
  GridField grid = ShepardField(20, 2.0, 40, 3);
  grid.Origin[0] = -3;
  grid.Origin[1] = 5;
  grid.Spacing[1] = 0.25 * grid.Spacing[0];
  const double width = 39 * grid.Spacing[0], height = 39 * grid.Spacing[1];
  const PlanarScalarField shepard = FieldOnGrid(grid), shepardMesh = MeshFieldOnGrid(grid);
  PlanarScalarField plane = shepard, mesh;
  for (std::size_t v = 0; v < plane.Values.size(); ++v)
  {
    plane.Values[v] = linear(plane.Points[2 * v], plane.Points[2 * v + 1]);
  }
  for (int i = 0; i < 300; ++i)
  {
    mesh.Points.push_back(random.Uniform());
    mesh.Points.push_back(random.Uniform());
  }
  for (const double corner : { 0.0, 1.0 })
  {
    mesh.Points.insert(mesh.Points.end(), { corner, 0.0, corner, 1.0 });
  }
  mesh.Triangles = DelaunayTriangles(mesh.Points);
  for (std::size_t v = 0; v < mesh.Points.size() / 2; ++v)
  {
    mesh.Values.push_back(linear(mesh.Points[2 * v], mesh.Points[2 * v + 1]));
  }
  // VTK cells may list a mesh's triangles either way round.
  PlanarScalarField mixed = mesh;
  for (std::size_t t = 0; t < mixed.Triangles.size(); t += 6)
  {
    std::swap(mixed.Triangles[t + 1], mixed.Triangles[t + 2]);
  }
  const PiecewiseLinearField onPlane(plane), onShepard(shepard), onShepardMesh(shepardMesh), onMesh(mesh),
    onMixed(mixed);
  double largest = 0;
  for (int i = 0; i < 2000; ++i)
  {
    const double x = grid.Origin[0] + random.Uniform() * width, y = grid.Origin[1] + random.Uniform() * height;
    double a = 0, b = 0, c = 0, d = 0;
    CHECK(onPlane.ValueAt(x, y, a) && onShepard.ValueAt(x, y, b) && onShepardMesh.ValueAt(x, y, c));
    const double u = random.Uniform(), w = random.Uniform();
    double e = 0;
    CHECK(onMesh.ValueAt(u, w, d) && onMixed.ValueAt(u, w, e));
    largest = std::max({ largest, std::abs(a - linear(x, y)), std::abs(b - c), std::abs(d - linear(u, w)),
      std::abs(e - linear(u, w)) });
  }
  CHECK(largest < 1e-12);
  double ignored;
  CHECK(!onPlane.ValueAt(grid.Origin[0] - 0.01 * width, grid.Origin[1], ignored));
  CHECK(!onShepardMesh.ValueAt(grid.Origin[0], grid.Origin[1] + 1.01 * height, ignored));
  CHECK(!onMesh.ValueAt(1.01, 0.5, ignored));
  CHECK(!onMesh.ValueAt(std::nan(""), 0.5, ignored));
}

// Shepard fields (250 x 250, 50 sites) of seeds 20-59, which no table or test above used,
// through stages 1 and 2 at 5 %: body(grid, input, eps) for each, eps = 5 % of its range.
void ForFortyShepardFieldsAtFivePercent(
  const std::function<void(const GridField&, const Stage3Input&, double)>& body)
{
  for (std::uint64_t seed = 20; seed < 60; ++seed)
  {
    const GridField grid = ShepardField(50, 2.0, 250, seed);
    Stage3Input input;
    std::string error;
    CHECK(RunStages1And2(grid, 5.0, input, error));
    body(grid, input, 0.05 * input.Range);
  }
}

// Every piece whose height misses its own samples by more than the threshold has as many
// segments as the refinement allows, also after the crossings are repaired: a crossing piece
// whose knots followed its rise is fitted again with knots uniform in arc length, and that fit
// can miss where the rise knots did not (Shepard seed 20 at 5 %: a ridge that climbs slowly,
// then steeply, 2.3 eps above the data over 15 spacings with 4 segments). The misses and the
// next count are the test's own (k = 4: 1 -> 2 -> 4 -> 8 -> 16; at most 12, 3 samples each; at
// most 24 for a miss beyond 2 eps while every 1-cell through the piece keeps 24 segments).
// Pieces with fewer samples: ShortPiecesGetAFinerHeightOnTheSameCurve.
TEST_CASE(PiecesStillMissingAfterTheCrossingRepairGetMoreSegments)
{
  int missing = 0, unrefined = 0;
  for (const double percent : { 2.0, 5.0 })
  for (std::uint64_t seed = 20; seed < 60; ++seed)
  {
    Stage3Input input;
    std::string error;
    CHECK(RunStages1And2(ShepardField(50, 2.0, 250, seed), percent, input, error));
    const double eps = percent / 100 * input.Range;
    OneCellSmoothing smoothing;
    smoothing.HeightTolerance = eps;
    OneCellSmoothingResult result;
    CHECK(smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error));
    for (const SmoothedPiece& piece : result.Pieces)
    {
      const double miss = LargestMissOfOwnSamples(piece);
      if (miss <= eps || piece.HeightAlongCurve)
      {
        continue;
      }
      ++missing;
      const int next = piece.Segments == 1 ? 2 : (piece.Segments < 4 ? 4 : 2 * piece.Segments);
      // Past 12 only for misses beyond 2 eps, and only while every 1-cell through the piece
      // keeps at most 24 segments (half of stage 4's fitted-grid limit).
      bool sidesRoom = true;
      for (const Index o : piece.OneCells)
      {
        int sum = next - piece.Segments;
        for (const Index q : result.PiecesOfOneCell[o])
        {
          sum += result.Pieces[q].Segments;
        }
        sidesRoom = sidesRoom && sum <= 24;
      }
      const int cap = miss > 2 * eps && sidesRoom ? 24 : 12;
      if (next <= cap && static_cast<int>(piece.Values.size()) > 3 * next)
      {
        std::printf("  %d-segment piece of %zu samples misses them by %.2f eps\n", piece.Segments,
          piece.Values.size(), miss / eps);
        ++unrefined;
      }
    }
  }
  std::printf("  Shepard 250^2, 2 and 5 %%, seeds 20-59: pieces missing their samples by more than eps %d, of which "
              "could have more segments %d\n", missing, unrefined);
  CHECK(unrefined == 0);
}

// A piece with too few samples for a finer curve (3 per segment) that misses its samples gets
// the segments on its height alone: its curve is the one it had without refinement, point for
// point, and its height fits its samples no worse in the L1 sense the fit minimizes (the
// spline space with twice the segments holds the old one; up to the fit's tie-break), and
// better in total. On Shepard seed 13 at 5 % such a piece leaves a steep minimum (the height
// starts with zero slope; the reconstruction's largest error 2.0 eps at k = 4, 1.3 with it);
// seeds 34 and 20-59 have more. The curves are compared at 201 parameters.
TEST_CASE(ShortPiecesGetAFinerHeightOnTheSameCurve)
{
  int refined = 0, worseL1 = 0;
  double largestShift = 0, missesBefore = 0, missesAfter = 0;
  const auto l1 = [](const SmoothedPiece& piece) {
    double sum = 0;
    for (std::size_t i = 1; i + 1 < piece.Values.size(); ++i)
    {
      double h = 0;
      piece.Height.Evaluate(piece.Parameters[i], &h);
      sum += std::abs(h - piece.Values[i]);
    }
    return sum;
  };
  std::vector<std::uint64_t> seeds = { 13, 34 };
  for (std::uint64_t seed = 20; seed < 60; ++seed)
  {
    seeds.push_back(seed);
  }
  for (const std::uint64_t seed : seeds)
  {
    Stage3Input input;
    std::string error;
    CHECK(RunStages1And2(ShepardField(50, 2.0, 250, seed), 5.0, input, error));
    OneCellSmoothing plain, refining;
    refining.HeightTolerance = 0.05 * input.Range;
    OneCellSmoothingResult a, b;
    CHECK(plain.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, a, error));
    CHECK(refining.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, b, error));
    CHECK(a.Pieces.size() == b.Pieces.size());
    for (std::size_t p = 0; p < a.Pieces.size() && p < b.Pieces.size(); ++p)
    {
      const SmoothedPiece &before = a.Pieces[p], &after = b.Pieces[p];
      // Short pieces the refinement reached, fitted along their path both times, and that no
      // crossing refitted in either run (k = 4 is the most a piece starts with).
      if (!after.HeightRefined || static_cast<int>(after.Values.size()) > 3 * after.Segments || before.Segments > 4 ||
        after.Segments % before.Segments != 0 || after.RiseKnots() != before.RiseKnots() || before.HeightAlongCurve ||
        after.HeightAlongCurve)
      {
        continue;
      }
      ++refined;
      for (int i = 0; i <= 200; ++i)
      {
        double x[2], y[2];
        before.Curve.Evaluate(i / 200.0, x);
        after.Curve.Evaluate(i / 200.0, y);
        largestShift = std::max(largestShift, std::hypot(x[0] - y[0], x[1] - y[1]));
      }
      const double rise = input.Range;
      worseL1 += l1(after) > l1(before) + 1e-4 * rise ? 1 : 0;
      missesBefore += LargestMissOfOwnSamples(before) / refining.HeightTolerance;
      missesAfter += LargestMissOfOwnSamples(after) / refining.HeightTolerance;
    }
  }
  std::printf("  Shepard 250^2 at 5 %%, seeds 13, 34, 20-59: %d short pieces refined, their largest misses %.1f -> %.1f "
              "eps in all, %d fitting worse, curves moved by at most %.2e\n",
    refined, missesBefore, missesAfter, worseL1, largestShift);
  CHECK(refined > 0);
  CHECK(worseL1 == 0);
  CHECK(missesAfter < missesBefore);
  CHECK(largestShift < 1e-9);
}

// Heights fitted along the jagged paths miss the field along the smoothed curves where a curve
// cuts across a slope its path climbs (a staircase round a peak); with the field at hand
// (FieldAt), such pieces are fitted to the field along their curves, and refined where that
// still misses. Measured with the test's own interpolation at every sample of every curve, on
// 40 Shepard fields the tables never used: no field's largest miss grows, some shrink.
TEST_CASE(HeightsFollowTheFieldAlongTheirCurves)
{
  int improved = 0, worseBefore = 0, worseAfter = 0;
  double largestBefore = 0, largestAfter = 0;
  ForFortyShepardFieldsAtFivePercent([&](const GridField& grid, const Stage3Input& input, double eps) {
    std::string error;
    const int nx = grid.Dimensions[0], ny = grid.Dimensions[1];
    // The grid's triangles split each square along its (i+1, j)-(i, j+1) diagonal. (The
    // results are in the field's coordinates; FieldAt is called in the complex's frame.)
    const auto fieldAt = [&](const double xy[2]) {
      const double fx = (xy[0] - grid.Origin[0]) / grid.Spacing[0], fy = (xy[1] - grid.Origin[1]) / grid.Spacing[1];
      const int i = std::clamp(static_cast<int>(fx), 0, nx - 2), j = std::clamp(static_cast<int>(fy), 0, ny - 2);
      const double a = fx - i, b = fy - j;
      const auto f = [&](int di, int dj) { return grid.Values[(j + dj) * nx + i + di]; };
      return a + b <= 1 ? (1 - a - b) * f(0, 0) + a * f(1, 0) + b * f(0, 1)
                        : (a + b - 1) * f(1, 1) + (1 - a) * f(0, 1) + (1 - b) * f(1, 0);
    };
    const auto largestMiss = [&](const OneCellSmoothingResult& result, int& worse) {
      double largest = 0;
      for (const SmoothedPiece& piece : result.Pieces)
      {
        for (std::size_t i = 1; i + 1 < piece.Parameters.size(); ++i)
        {
          double xy[2], h;
          piece.Curve.Evaluate(piece.Parameters[i], xy);
          piece.Height.Evaluate(piece.Parameters[i], &h);
          const double miss = std::abs(h - fieldAt(xy)) / eps;
          largest = std::max(largest, miss);
          worse += miss > 2 ? 1 : 0;
        }
      }
      return largest;
    };
    const PlanarScalarField field = FieldOnGrid(grid);
    const PiecewiseLinearField between(field);
    const PlanarFrame frame = input.Simplified.Complex.Frame;
    OneCellSmoothing pathOnly, withField;
    pathOnly.HeightTolerance = withField.HeightTolerance = eps;
    withField.FieldAt = [&](double x, double y, double& value) {
      double xy[2] = { x, y };
      frame.ToWorld(xy);
      return between.ValueAt(xy[0], xy[1], value);
    };
    OneCellSmoothingResult a, b;
    CHECK(pathOnly.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, a, error));
    CHECK(withField.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, b, error));
    CheckSmoothedOneCells(input, b, 4);
    CHECK(a.CurveHeightPieces == 0);
    const double before = largestMiss(a, worseBefore), after = largestMiss(b, worseAfter);
    CHECK(after <= before + 1e-9);
    improved += after < before - 0.1 ? 1 : 0;
    largestBefore = std::max(largestBefore, before);
    largestAfter = std::max(largestAfter, after);
  });
  std::printf("  Shepard 250^2, 5 %%, seeds 20-59: fields whose heights miss the field along their curves by 0.1 eps "
              "less %d; samples missing by more than 2 eps %d -> %d; largest miss %.2f -> %.2f eps\n",
    improved, worseBefore, worseAfter, largestBefore, largestAfter);
  CHECK(improved > 0);
  CHECK(worseAfter <= worseBefore);
}

namespace
{
// The side of the domain a piece runs along: 0 when every sample has the first one's x on a
// bound of x, 1 the same for y, -1 for a piece inside the domain.
int SideOfDomain(const SmoothedPiece& piece, const double* bounds)
{
  const std::size_t n = piece.Values.size();
  const double* p = piece.Points.data();
  int axis = -1;
  for (int d = 0; d < 2 && n > 2; ++d)
  {
    bool same = p[d] == bounds[2 * d] || p[d] == bounds[2 * d + 1];
    for (std::size_t i = 1; i < n && same; ++i)
    {
      same = p[2 * i + d] == p[d];
    }
    axis = same ? d : axis;
  }
  return axis;
}

// Along a piece on side `axis` of the domain: checks that its curve stays on that side and
// advances strictly, and returns the largest |height - sample| over its interior samples, the
// height taken where the curve passes through the sample (bisection on the position along the
// side), not at the piece's own parameters.
double LargestMissAlongTheSide(const SmoothedPiece& piece, int axis)
{
  const std::size_t n = piece.Values.size();
  const double* p = piece.Points.data();
  const int along = 1 - axis;
  const double direction = p[2 * (n - 1) + along] > p[along] ? 1 : -1;
  const auto position = [&](double t) {
    double xy[2];
    piece.Curve.Evaluate(t, xy);
    CHECK(std::abs(xy[axis] - p[axis]) < 1e-9);
    return direction * xy[along];
  };
  double previous = -std::numeric_limits<double>::infinity();
  for (int q = 0; q <= 64 * piece.Segments; ++q)
  {
    const double x = position(q / (64.0 * piece.Segments));
    CHECK(x > previous || q == 0);
    previous = x;
  }
  double miss = 0;
  for (std::size_t i = 1; i + 1 < n; ++i)
  {
    double lo = 0, hi = 1;
    for (int step = 0; step < 60; ++step)
    {
      const double mid = 0.5 * (lo + hi);
      (position(mid) < direction * p[2 * i + along] ? lo : hi) = mid;
    }
    double h;
    piece.Height.Evaluate(0.5 * (lo + hi), &h);
    miss = std::max(miss, std::abs(h - piece.Values[i]));
  }
  return miss;
}

// The pieces along the domain's sides with fewer than `samplesBelow` samples, smoothed with
// the height tolerance eps: how many, how many with knots that follow their rise, and their
// largest miss in eps (LargestMissAlongTheSide).
struct SidePieces
{
  int Pieces = 0;
  int RiseKnots = 0;
  double LargestMiss = 0;
  void Measure(const Stage3Input& input, double eps, std::size_t samplesBelow)
  {
    std::string error;
    OneCellSmoothing smoothing;
    smoothing.HeightTolerance = eps;
    OneCellSmoothingResult result;
    CHECK(smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error));
    for (const SmoothedPiece& piece : result.Pieces)
    {
      const int axis = SideOfDomain(piece, input.Bounds);
      if (axis >= 0 && piece.Values.size() < samplesBelow)
      {
        ++this->Pieces;
        this->RiseKnots += piece.RiseKnots() ? 1 : 0;
        this->LargestMiss = std::max(this->LargestMiss, LargestMissAlongTheSide(piece, axis) / eps);
      }
    }
  }
};
} // namespace

// A 1-cell along the domain's boundary that rises steeply from a minimum and then runs nearly
// flat for a hundred spacings: knots uniform in arc length put one of k segments on the rise,
// and a height with zero slope at its ends cannot climb that fast (Shepard field, seed 54, 5 %:
// 3.7 eps below the data next to the minimum). Knots that follow the rise are what the
// smoothing tries for such pieces; on a straight piece the least-squares curve for them did not
// advance along the line and was refused. Checked here on 40 Shepard fields, for every piece
// that runs straight along the boundary: its curve stays on the line and advances, and its
// height misses its samples by less than 2 eps (the test's own evaluation).
TEST_CASE(StraightPiecesFollowSteepRises)
{
  SidePieces side;
  ForFortyShepardFieldsAtFivePercent([&](const GridField&, const Stage3Input& input, double eps) {
    side.Measure(input, eps, std::numeric_limits<std::size_t>::max());
  });
  std::printf("  Shepard 250^2, 5 %%, seeds 20-59: %d pieces along the boundary, %d with knots that follow "
              "their rise; heights miss their samples by up to %.2f eps\n",
    side.Pieces, side.RiseKnots, side.LargestMiss);
  CHECK(side.Pieces > 0 && side.RiseKnots > 0);
  CHECK(side.LargestMiss < 2);
}

// A Shepard field (120^2, 50 sites) raised by half its range past a random column, or row,
// of the seed's: a cliff its 1-cells climb.
GridField TerracedShepardField(std::uint64_t seed, bool pastARow)
{
  GridField grid = ShepardField(50, 2.0, 120, seed);
  DeterministicRandom random(seed);
  const int line = 10 + random.Integer(100);
  const auto [low, high] = std::minmax_element(grid.Values.begin(), grid.Values.end());
  const double step = 0.5 * (*high - *low);
  for (std::size_t v = 0; v < grid.Values.size(); ++v)
  {
    grid.Values[v] += static_cast<int>(pastARow ? v / 120 : v % 120) >= line ? step : 0.0;
  }
  return grid;
}

// Short pieces along the domain's sides follow a cliff next to their node too. The height of a
// piece starts flat at its nodes, so with evenly spaced knots a piece of a few samples whose
// data jump in the first edge missed the jump by most of its size (a ttk_happi crop at 2 %:
// 8 eps, six edges, four segments); its knots may now follow the rise on any straight piece,
// not only where the curve has three samples per segment. Terraces: Shepard fields (120^2,
// seeds 60-79) raised by half their range past a random column, so that the sides at y = 0
// and y = 119 climb a cliff; 5 %, k = 4; the pieces along the sides with fewer than 13 samples
// (three per segment at k = 4, where no piece got such knots before: 6.2 eps then).
TEST_CASE(ShortPiecesAlongTheSidesFollowCliffs)
{
  SidePieces side;
  for (std::uint64_t seed = 60; seed < 80; ++seed)
  {
    const GridField grid = TerracedShepardField(seed, false);
    Stage3Input input;
    std::string error;
    CHECK(RunStages1And2(grid, 5.0, input, error));
    side.Measure(input, 0.05 * input.Range, 3 * 4 + 1);
  }
  std::printf("  terraced Shepard 120^2, 5 %%, seeds 60-79: %d short pieces along the boundary, %d with knots "
              "that follow their rise; heights miss their samples by up to %.2f eps\n",
    side.Pieces, side.RiseKnots, side.LargestMiss);
  CHECK(side.Pieces > 0 && side.RiseKnots > 0);
  CHECK(side.LargestMiss < 2);
}

// Pieces away from the sides with 2 to 3 samples per segment try the gentle rise ratios (the
// steeper ones hook their curves between such samples): a ten-sample valley piece of Shepard
// seed 14 at 5 % climbs 64 % of its rise in the edge off its minimum, where its height starts
// flat, and with even knots missed by 2.4 eps. Measured against the even-knot fit the test makes
// itself (same segments and ends) on terraced Shepard fields nothing was tuned on (seeds 80-99,
// raised past a random row so that 1-cells climb a cliff), over the pieces with 2 to 3 samples
// per segment that were not refined or fitted to the field along their curve: most take rise
// knots, none misses its samples by more, and the largest miss falls (before: 11 of 361 had
// such knots, straight ones). With the threshold as the height tolerance (as the filter runs),
// only pieces whose even knots miss by more than half of it take them (SparseRiseTrigger).
TEST_CASE(SparsePiecesFollowSteepRisesWithGentleKnots)
{
  int sparse = 0, risen = 0, risenWithTolerance = 0, risenWithinHalf = 0;
  double evenMiss = 0, keptMiss = 0;
  bool noWorse = true;
  for (std::uint64_t seed = 80; seed < 100; ++seed)
  {
    Stage3Input input;
    std::string error;
    CHECK(RunStages1And2(TerracedShepardField(seed, true), 5.0, input, error));
    const double eps = 0.05 * input.Range;
    for (const bool withTolerance : { false, true })
    {
      OneCellSmoothingResult result;
      CHECK(SmoothWithSegments(input, 4, withTolerance ? eps : 0.0, result, error));
      for (const SmoothedPiece& piece : result.Pieces)
      {
        const std::size_t n = piece.Values.size();
        if (piece.Segments != 4 || n < 2 * 4 + 1 || n >= 3 * 4 + 1 || piece.HeightAlongCurve ||
          piece.Points[0] == piece.Points[2 * n - 2] || piece.Points[1] == piece.Points[2 * n - 1])
        {
          continue; // not sparse, refined, or possibly straight
        }
        const double a = result.Nodes[piece.StartNode].Value, b = result.Nodes[piece.EndNode].Value;
        MonotoneBSplineFit fitter;
        fitter.Segments = 4;
        HeightFit even;
        const std::vector<double> arcLength = MonotoneBSplineFit::NormalizedArcLength(piece.Points);
        CHECK(fitter.FitHeight(arcLength, piece.Values, a, b, true, even, error));
        if (withTolerance)
        {
          // Straight paths (a side, a diagonal) try every ratio whatever the miss.
          const double dx = piece.Points[2 * n - 2] - piece.Points[0], dy = piece.Points[2 * n - 1] - piece.Points[1];
          bool straight = true;
          for (std::size_t i = 1; i + 1 < n && straight; ++i)
          {
            const double cross = dx * (piece.Points[2 * i + 1] - piece.Points[1]) - dy * (piece.Points[2 * i] - piece.Points[0]);
            straight = std::abs(cross) <= 1e-9 * (dx * dx + dy * dy);
          }
          if (straight)
          {
            continue;
          }
          risenWithTolerance += piece.RiseKnots() ? 1 : 0;
          risenWithinHalf += piece.RiseKnots() && even.MaximumError <= 0.5 * eps ? 1 : 0;
          continue;
        }
        double kept = 0;
        for (std::size_t i = 1; i + 1 < n; ++i)
        {
          double h;
          piece.Height.Evaluate(piece.Parameters[i], &h);
          kept = std::max(kept, std::abs(h - piece.Values[i]));
        }
        ++sparse;
        risen += piece.RiseKnots() ? 1 : 0;
        noWorse = noWorse && kept <= even.MaximumError + 1e-9 * input.Range;
        evenMiss = std::max(evenMiss, even.MaximumError / eps);
        keptMiss = std::max(keptMiss, kept / eps);
      }
    }
  }
  std::printf("  terraced Shepard 120^2, 5 %%, seeds 80-99: %d sparse pieces, %d with rise knots; largest "
              "miss %.2f eps, %.2f with even knots; with the height tolerance %d with rise knots, %d of "
              "them within half of it with even knots\n",
    sparse, risen, keptMiss, evenMiss, risenWithTolerance, risenWithinHalf);
  CHECK(2 * risen > sparse);
  CHECK(noWorse);
  CHECK(keptMiss < evenMiss);
  CHECK(risenWithTolerance > 0 && risenWithinHalf == 0);
}

TEST_CASE(MergedOneCellsShareTheirPiecesOnNoise)
{
  for (const double percent : { 10.0, 25.0, 50.0 })
  {
    for (std::uint64_t seed = 1; seed <= 3; ++seed)
    {
      Stage3Input input;
      OneCellSmoothing smoothing;
      OneCellSmoothingResult result;
      CHECK(SmoothNoise(48, seed, percent, input, smoothing, result));
      // The pieces on every edge of the jagged 1-cells (either direction).
      std::map<std::array<double, 4>, std::set<Index>> piecesOfEdge;
      for (Index p = 0; p < static_cast<Index>(result.Pieces.size()); ++p)
      {
        const std::vector<double>& q = result.Pieces[p].Points;
        for (std::size_t i = 0; i + 3 < q.size(); i += 2)
        {
          std::array<double, 4> edge{ q[i], q[i + 1], q[i + 2], q[i + 3] };
          if (std::make_pair(edge[2], edge[3]) < std::make_pair(edge[0], edge[1]))
          {
            edge = { edge[2], edge[3], edge[0], edge[1] };
          }
          if (edge[0] != edge[2] || edge[1] != edge[3])
          {
            piecesOfEdge[edge].insert(p);
          }
        }
      }
      // A boundary saddle and a maximum on one vertex, joined by an ascending 1-cell that
      // goes out to a triangle and back, with a junction out there: two pieces, one the other
      // reversed, which close a loop (stage 3 lets them touch, stage 4 knows them).
      auto closeALoop = [&result](Index p, Index q) {
        const std::vector<double>& a = result.Pieces[p].Points;
        const std::vector<double>& b = result.Pieces[q].Points;
        return a.size() == 4 && b.size() == 4 && a[0] == b[2] && a[1] == b[3] && a[2] == b[0] && a[3] == b[1];
      };
      std::set<Index> overlapping;
      for (const auto& entry : piecesOfEdge)
      {
        const std::vector<Index> on(entry.second.begin(), entry.second.end());
        for (std::size_t x = 0; x < on.size(); ++x)
        {
          for (std::size_t y = x + 1; y < on.size(); ++y)
          {
            if (!closeALoop(on[x], on[y]))
            {
              overlapping.insert(on[x]);
              overlapping.insert(on[y]);
            }
          }
        }
      }
      // No 1-cell, followed along its pieces, walks an edge it already walked (merged 1-cells
      // that ran out and back along their path had those loops erased). Loops around an area
      // stay (a descending 1-cell can pass its own saddle and circle back to it).
      int retracedEdges = 0;
      for (const std::vector<Index>& pieces : result.PiecesOfOneCell)
      {
        std::vector<std::pair<double, double>> path;
        for (Index p : pieces)
        {
          const std::vector<double>& q = result.Pieces[p].Points;
          for (std::size_t i = path.empty() ? 0 : 2; i + 1 < q.size(); i += 2)
          {
            path.emplace_back(q[i], q[i + 1]);
          }
        }
        std::set<std::pair<std::pair<double, double>, std::pair<double, double>>> walked;
        for (std::size_t i = 0; i + 1 < path.size() && path.front() != path.back(); ++i)
        {
          retracedEdges += walked.insert(std::minmax(path[i], path[i + 1])).second ? 0 : 1;
        }
      }
      std::printf("  48^2 noise seed %d at %g %%: %zu pieces, %d retraced loops erased, %d cuts dropped, "
                  "%zu pieces overlap another, %d crossings left\n",
        static_cast<int>(seed), percent, result.Pieces.size(), result.ErasedLoops, result.DroppedCuts,
        overlapping.size(), result.RemainingCrossings);
      CHECK_EQ(retracedEdges, 0);
      CHECK(static_cast<int>(overlapping.size()) <= 3 * result.DroppedCuts);
    }
  }
}

//------------------------------------------------------------------------------
// Stage 4 cuts each 2-cell's boundary out of these curves at its own sampling (5 points per
// Bezier segment, finer after subdivision). Where stage 3 reports no crossing, no sampling may
// find one: two pieces' polylines at 5, 8 and 32 points per segment neither cross nor touch
// away from a shared end, and no piece's polyline passes through a node it does not end at.
// The oracle is written here (orientation tests on the samples). On noise a smoothed curve
// that cut the corner of its jagged 1-cell 0.005 spacings from a saddle crossed its four
// 1-cells there, on one sampling and not on another.
namespace
{
double Orientation(const double* a, const double* b, const double* c)
{
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

bool ClosedSegmentsMeet(const double* a, const double* b, const double* c, const double* d)
{
  const double o1 = Orientation(a, b, c), o2 = Orientation(a, b, d);
  const double o3 = Orientation(c, d, a), o4 = Orientation(c, d, b);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
  {
    return true;
  }
  auto onSegment = [](const double* p, const double* q, const double* r, double o) {
    return o == 0 && std::min(p[0], q[0]) <= r[0] && r[0] <= std::max(p[0], q[0]) && std::min(p[1], q[1]) <= r[1] &&
      r[1] <= std::max(p[1], q[1]);
  };
  return onSegment(a, b, c, o1) || onSegment(a, b, d, o2) || onSegment(c, d, a, o3) || onSegment(c, d, b, o4);
}

std::vector<double> SampledCurve(const CubicBezierSpline& curve, int perSegment)
{
  std::vector<double> samples;
  for (int j = 0; j < curve.Segments; ++j)
  {
    for (int s = j == 0 ? 0 : 1; s <= perSegment; ++s)
    {
      double xy[2];
      CubicBezierSpline::EvaluateSegment(curve.Segment(j), 2, static_cast<double>(s) / perSegment, xy);
      samples.insert(samples.end(), { xy[0], xy[1] });
    }
  }
  return samples;
}

// Contacts between the polylines of two pieces (or of one piece with itself), away from the
// ends they share: points within `shared` of a common end node are their meeting.
int ContactsAwayFromSharedEnds(const std::vector<double>& a, const std::vector<double>& b, bool same,
  const std::vector<const double*>& sharedEnds, double shared)
{
  auto nearShared = [&](const double* p) {
    for (const double* e : sharedEnds)
    {
      if (std::hypot(p[0] - e[0], p[1] - e[1]) <= shared)
      {
        return true;
      }
    }
    return false;
  };
  int contacts = 0;
  for (std::size_t i = 0; i + 3 < a.size(); i += 2)
  {
    for (std::size_t j = same ? i + 4 : 0; j + 3 < b.size(); j += 2)
    {
      if (ClosedSegmentsMeet(&a[i], &a[i + 2], &b[j], &b[j + 2]) &&
        !(nearShared(&a[i]) || nearShared(&a[i + 2])) && !(nearShared(&b[j]) || nearShared(&b[j + 2])))
      {
        ++contacts;
      }
    }
  }
  return contacts;
}
// The oracle's contacts between the pieces' polylines at 5, 8 and 32 points per segment, away
// from shared ends, and in `throughNodes` the pieces whose polylines pass through a node they
// do not end at.
int IndependentContacts(const OneCellSmoothingResult& result, const double bounds[4], int& throughNodes)
{
  const Index count = static_cast<Index>(result.Pieces.size());
  int contacts = 0;
  throughNodes = 0;
  for (const int perSegment : { 5, 8, 32 })
  {
    std::vector<std::vector<double>> polylines(count);
    std::vector<std::array<double, 4>> boxes(count);
    for (Index p = 0; p < count; ++p)
    {
      polylines[p] = SampledCurve(result.Pieces[p].Curve, perSegment);
      boxes[p] = { 1e300, -1e300, 1e300, -1e300 };
      for (std::size_t i = 0; i + 1 < polylines[p].size(); i += 2)
      {
        boxes[p] = { std::min(boxes[p][0], polylines[p][i]), std::max(boxes[p][1], polylines[p][i]),
          std::min(boxes[p][2], polylines[p][i + 1]), std::max(boxes[p][3], polylines[p][i + 1]) };
      }
    }
    const double shared = 1e-9 * (bounds[1] - bounds[0]);
    for (Index p = 0; p < count; ++p)
    {
      const SmoothedPiece& a = result.Pieces[p];
      const double* aEnds[2] = { result.Nodes[a.StartNode].Position, result.Nodes[a.EndNode].Position };
      for (Index q = p; q < count; ++q)
      {
        if (boxes[p][0] > boxes[q][1] || boxes[q][0] > boxes[p][1] || boxes[p][2] > boxes[q][3] ||
          boxes[q][2] > boxes[p][3])
        {
          continue;
        }
        const SmoothedPiece& b = result.Pieces[q];
        std::vector<const double*> sharedEnds;
        for (const double* e : aEnds)
        {
          for (const Index n : { b.StartNode, b.EndNode })
          {
            if (e[0] == result.Nodes[n].Position[0] && e[1] == result.Nodes[n].Position[1])
            {
              sharedEnds.push_back(e);
            }
          }
        }
        // Two pieces that close a loop (start where the other ends, both ways) may
        // retrace each other.
        // A piece that starts where it ends (a boundary saddle and a maximum on one
        // vertex) may retrace itself.
        const bool loop = sharedEnds.size() >= 2 &&
          result.Nodes[a.StartNode].Position[0] == result.Nodes[b.EndNode].Position[0] &&
          result.Nodes[a.StartNode].Position[1] == result.Nodes[b.EndNode].Position[1];
        if (!loop)
        {
          contacts += ContactsAwayFromSharedEnds(polylines[p], polylines[q], p == q, sharedEnds, shared);
        }
      }
      for (std::size_t n = 0; n < result.Nodes.size(); ++n)
      {
        const double* x = result.Nodes[n].Position;
        if ((x[0] == aEnds[0][0] && x[1] == aEnds[0][1]) || (x[0] == aEnds[1][0] && x[1] == aEnds[1][1]) ||
          x[0] < boxes[p][0] || x[0] > boxes[p][1] || x[1] < boxes[p][2] || x[1] > boxes[p][3])
        {
          continue;
        }
        for (std::size_t i = 0; i + 3 < polylines[p].size(); i += 2)
        {
          const double* u = &polylines[p][i];
          if (ClosedSegmentsMeet(u, u + 2, x, x))
          {
            ++throughNodes;
            break;
          }
        }
      }
    }
  }
  return contacts;
}
} // namespace

TEST_CASE(NoSamplingFindsCrossingsWhereNoneAreReported)
{
  int checkedResults = 0;
  for (const double percent : { 5.0 })
  {
    for (std::uint64_t seed = 1; seed <= 4; ++seed)
    {
      const GridField noise = UniformNoise(40, 100 + seed);
      Stage3Input input;
      std::string error;
      CHECK(RunStages1And2(noise, percent, input, error));
      for (const int k : { 4, 15 })
      {
        if (k == 15 && seed > 1)
        {
          continue;
        }
        OneCellSmoothing smoothing;
        smoothing.Segments = k;
        OneCellSmoothingResult result;
        CHECK(smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error));
        if (result.RemainingCrossings != 0)
        {
          continue;
        }
        ++checkedResults;
        int throughNodes = 0;
        const int contacts = IndependentContacts(result, input.Bounds, throughNodes);
        std::printf("  40^2 noise seed %d at %g %%, k = %d: %zu pieces, %d adapted, contacts at 5/8/32 "
                    "points per segment %d, through foreign nodes %d\n",
          static_cast<int>(100 + seed), percent, k, result.Pieces.size(), result.AdaptedPieces, contacts,
          throughNodes);
        CHECK_EQ(contacts, 0);
        CHECK_EQ(throughNodes, 0);
      }
    }
  }
  CHECK(checkedResults >= 4);
}

//------------------------------------------------------------------------------
// Where long pieces cross, the repair crowds their new knots where they meet
// (CrowdKnotsAtContacts) instead of spreading them over the whole piece: on a msh_crater crop
// at 2 % a piece of 300 samples went to 256 segments for two contacts, and the 2-cell beside
// it past the grids stage 4 fits (test_reconstruction.py checks that crop). Against the even
// repair, on Shepard fields nothing was tuned on: no crossing or node contact the even repair
// does not leave (the oracle above), no more segments in all, no more cells whose sides reach
// no common grid within stage 4's fitted limit (the test's own count, SidesReachOneGrid), and
// some pieces crowded.
TEST_CASE(CrossingRepairsCrowdKnotsWhereThePiecesMeet)
{
  const int limit = TwoCellReconstruction().MaximumFittedGridSize;
  int runs = 0, crowded = 0, newContacts = 0;
  long segments[2] = { 0, 0 };
  int beyond[2] = { 0, 0 }, largest[2] = { 0, 0 };
  for (std::uint64_t seed = 12; seed < 24; ++seed)
  {
    const GridField field = ShepardField(40, 2.0, 250, seed);
    for (const double percent : { 2.0, 5.0 })
    {
      Stage3Input input;
      std::string error;
      CHECK(RunStages1And2(field, percent, input, error));
      for (const int k : { 4, 7 })
      {
        int contacts[2] = { 0, 0 }, throughNodes[2] = { 0, 0 }, pieceSegments[2] = { 0, 0 };
        for (const bool crowd : { false, true })
        {
          OneCellSmoothing smoothing;
          smoothing.Segments = k;
          smoothing.HeightTolerance = percent / 100 * input.Range; // as the filter
          smoothing.CrowdKnotsAtContacts = crowd;
          OneCellSmoothingResult result;
          CHECK(smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error));
          contacts[crowd] = IndependentContacts(result, input.Bounds, throughNodes[crowd]);
          crowded += crowd ? result.ContactKnotPieces : 0;
          for (const SmoothedPiece& piece : result.Pieces)
          {
            segments[crowd] += piece.Segments;
            pieceSegments[crowd] = std::max(pieceSegments[crowd], piece.Segments);
          }
          ForEachCellGrid(input, result, limit, [&](bool within, int reached) {
            beyond[crowd] += within ? 0 : 1;
            largest[crowd] = std::max(largest[crowd], reached);
          });
        }
        ++runs;
        newContacts += std::max(0, contacts[1] + throughNodes[1] - contacts[0] - throughNodes[0]);
        if (pieceSegments[0] != pieceSegments[1] || contacts[0] + throughNodes[0] + contacts[1] + throughNodes[1] > 0)
        {
          std::printf("  seed %d at %g %%, k = %d: most segments on a piece %d -> %d, contacts %d -> %d, "
                      "through nodes %d -> %d\n",
            static_cast<int>(seed), percent, k, pieceSegments[0], pieceSegments[1], contacts[0], contacts[1],
            throughNodes[0], throughNodes[1]);
        }
      }
    }
  }
  std::printf("  Shepard 250^2 seeds 12-23, 2 and 5 %%, k 4 and 7: %d runs, %d pieces crowded; segments %ld -> %ld, "
              "cells beyond a grid of %d %d -> %d, largest grid %d -> %d, new contacts %d\n",
    runs, crowded, segments[0], segments[1], limit, beyond[0], beyond[1], largest[0], largest[1], newContacts);
  CHECK(crowded > 0);
  CHECK_EQ(newContacts, 0);
  CHECK(segments[1] <= segments[0]);
  CHECK(beyond[1] <= beyond[0]);
}

//------------------------------------------------------------------------------
TEST_CASE(JaggedPiecesAddNoCrossingOnTriangleMeshes)
{
  // Stage 3 falls back to the jagged pieces where smoothed curves cross, so those must not
  // cross where the complex's 1-cells do not. On Delaunay meshes of random points (the stress
  // test's "delaunay" cases) two triangles can form a non-convex quad, and a straight segment
  // joining points of two triangles leaves them: the last segment of an ascending piece, made
  // straight from the point before the maximum's triangle to the maximum, crossed other pieces
  // on stress case #275 (a Delaunay mesh at 2 %), and the fallback polylines still crossed
  // there. Oracle: of every pair of segments of the pieces' jagged polylines that cross
  // properly (of one piece, two that do not follow each other), one is a segment that crosses
  // another in the simplified complex's own 1-cells already (checked pair by pair here). (Those
  // crossed on 11 of these meshes until stage 2 passed a cancelled saddle's edge midpoint:
  // MergedOneCellsNeverCrossOnTriangleMeshes.)
  int runs = 0, pieces = 0, added = 0, inherited = 0;
  for (std::uint64_t seed = 1; seed <= 24; ++seed)
  {
    const PlanarScalarField field = RandomDelaunayField(500 + seed, 3000);
    Stage3Input input;
    std::string error;
    MorseSmaleComplexExtraction extraction;
    MorseSmaleComplexSimplification simplification;
    CHECK(extraction.Extract(field, input.Input, error) && simplification.ComputeHierarchy(input.Input, error));
    input.Bounds[0] = input.Bounds[2] = 1e300;
    input.Bounds[1] = input.Bounds[3] = -1e300;
    for (std::size_t i = 0; i < field.Points.size(); i += 2)
    {
      input.Bounds[0] = std::min(input.Bounds[0], field.Points[i]);
      input.Bounds[1] = std::max(input.Bounds[1], field.Points[i]);
      input.Bounds[2] = std::min(input.Bounds[2], field.Points[i + 1]);
      input.Bounds[3] = std::max(input.Bounds[3], field.Points[i + 1]);
    }
    for (const double percent : { 2.0 })
    {
      CHECK(simplification.Simplify(percent, input.Simplified, error));
      OneCellSmoothing smoothing;
      smoothing.Segments = 7;
      OneCellSmoothingResult result;
      CHECK(smoothing.Smooth(input.Simplified.Complex, input.Simplified.JunctionPoints, input.Bounds, result, error));
      std::vector<const std::vector<double>*> complexLines, pieceLines;
      for (const OneCell& oneCell : input.Simplified.Complex.OneCells)
      {
        complexLines.push_back(&oneCell.Points);
      }
      for (const SmoothedPiece& piece : result.Pieces)
      {
        pieceLines.push_back(&piece.Points);
      }
      const auto inComplex = CrossingSegmentPairs(complexLines);
      std::set<TestSegment> crossingInComplex;
      for (const auto& pair : inComplex)
      {
        crossingInComplex.insert(pair.first);
        crossingInComplex.insert(pair.second);
      }
      int newOnes = 0;
      for (const auto& pair : CrossingSegmentPairs(pieceLines))
      {
        newOnes += crossingInComplex.count(pair.first) || crossingInComplex.count(pair.second) ? 0 : 1;
      }
      std::printf("  seed %d at %g %%: %zu pieces; crossing segment pairs: %zu in the complex's 1-cells, %d more "
                  "of segments that cross nothing there (stage 3 reports %d crossing pairs, %d polyline pieces)\n",
        static_cast<int>(500 + seed), percent, result.Pieces.size(), inComplex.size(), newOnes,
        result.RemainingCrossings, result.PolylinePieces);
      ++runs;
      pieces += static_cast<int>(result.Pieces.size());
      added += newOnes;
      inherited += static_cast<int>(inComplex.size());
    }
  }
  std::printf("  %d runs, %d pieces: %d crossing segment pairs added by the pieces (%d in the complexes)\n", runs,
    pieces, added, inherited);
  CHECK_EQ(added, 0);
}

//------------------------------------------------------------------------------
TEST_CASE(ProgressAbortAndBadInput)
{
  Stage3Input input;
  std::string error;
  CHECK(RunStages1And2(TrigonometricField(10, 60, -29), 1.0, input, error));
  const MorseSmaleComplex& complex = input.Simplified.Complex;
  const auto& junctions = input.Simplified.JunctionPoints;
  OneCellSmoothingResult result;

  OneCellSmoothing smoothing;
  std::vector<double> reported;
  smoothing.Hooks.Progress = [&reported](double fraction) { reported.push_back(fraction); };
  CHECK(smoothing.Smooth(complex, junctions, input.Bounds, result, error));
  CHECK(!reported.empty() && reported.back() == 1.0);
  CHECK(std::is_sorted(reported.begin(), reported.end()));

  smoothing.Hooks.AbortRequested = []() { return true; };
  error.clear();
  CHECK(!smoothing.Smooth(complex, junctions, input.Bounds, result, error) && error == "aborted");
  smoothing.Hooks = ProgressHooks();

  for (int k : { 1, OneCellSmoothing::MaximumCurveSegments + 1 })
  {
    smoothing.Segments = k;
    error.clear();
    CHECK(!smoothing.Smooth(complex, junctions, input.Bounds, result, error) && !error.empty());
  }
  smoothing.Segments = 4;
  error.clear();
  CHECK(!smoothing.Smooth(MorseSmaleComplex(), {}, input.Bounds, result, error));
  CHECK(error == "the complex has no 1-cells");
}

//------------------------------------------------------------------------------
TEST_CASE(PolylineFallbackFollowsTheJaggedOneCell)
{
  // A zigzag of 4 edges (lengths 1, 3, 1, 3) between two nodes, drawn as 8 cubic segments.
  std::vector<SmoothingNode> nodes(2);
  nodes[0].Position[0] = 0;
  nodes[0].Position[1] = 0;
  nodes[1].Position[0] = 4;
  nodes[1].Position[1] = 6;
  SmoothedPiece piece;
  piece.StartNode = 0;
  piece.EndNode = 1;
  // The jagged ends lie off the nodes by 1e-3: they must be moved onto them.
  piece.Points = { 1e-3, 0, 1, 0, 1, 3, 2, 3, 4, 6 };
  piece.Curve.Segments = 8;
  piece.Curve.Dimension = 2;
  piece.Curve.ControlPoints.assign(8 * 4 * 2, 0.5);
  CHECK(OneCellSmoothing::FollowPolyline(piece, nodes));
  const CubicBezierSpline& curve = piece.Curve;
  CHECK_EQ(curve.Segments, 8);
  CHECK_EQ(curve.ControlPoints.size(), static_cast<std::size_t>(8 * 4 * 2));
  // Ends on the nodes.
  CHECK(curve.ControlPoints[0] == 0 && curve.ControlPoints[1] == 0);
  CHECK(curve.ControlPoints[62] == 4 && curve.ControlPoints[63] == 6);
  // Every segment is straight, joins the next exactly, and lies on one polyline edge; every
  // polyline corner is a segment joint, and the segments of one edge share its length.
  const double corners[5][2] = { { 0, 0 }, { 1, 0 }, { 1, 3 }, { 2, 3 }, { 4, 6 } };
  std::vector<int> perEdge(4, 0);
  bool straight = true, joined = true, onEdges = true;
  for (int j = 0; j < 8; ++j)
  {
    const double* c = curve.Segment(j);
    for (int m = 1; m < 3; ++m)
    {
      const double cross = (c[6] - c[0]) * (c[2 * m + 1] - c[1]) - (c[7] - c[1]) * (c[2 * m] - c[0]);
      straight = straight && std::abs(cross) <= 1e-12;
    }
    if (j + 1 < 8)
    {
      joined = joined && c[6] == c[8] && c[7] == c[9];
    }
    int edge = -1;
    for (int e = 0; e < 4; ++e)
    {
      const double* a = corners[e];
      const double* b = corners[e + 1];
      const auto onSegment = [&](double x, double y) {
        const double cross = (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
        const double dot = (x - a[0]) * (b[0] - a[0]) + (y - a[1]) * (b[1] - a[1]);
        const double length2 = (b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]);
        return std::abs(cross) <= 1e-12 && dot >= -1e-12 && dot <= length2 + 1e-12;
      };
      if (edge < 0 && onSegment(c[0], c[1]) && onSegment(c[6], c[7]) && !(c[0] == b[0] && c[1] == b[1]))
      {
        edge = e;
      }
    }
    onEdges = onEdges && edge >= 0;
    if (edge >= 0)
    {
      ++perEdge[edge];
    }
  }
  CHECK(straight);
  CHECK(joined);
  CHECK(onEdges);
  // Lengths 1, 3, 1, sqrt(13) = 3.6: one segment each, the 4 others to the long edges.
  CHECK(perEdge[0] >= 1 && perEdge[2] >= 1);
  CHECK(perEdge[1] >= 2 && perEdge[3] >= 2);
  CHECK_EQ(perEdge[0] + perEdge[1] + perEdge[2] + perEdge[3], 8);

  // Fewer segments than edges: refused, nothing changed.
  SmoothedPiece short3 = piece;
  short3.Curve.Segments = 3;
  short3.Curve.ControlPoints.assign(3 * 4 * 2, 0.5);
  const std::vector<double> before = short3.Curve.ControlPoints;
  CHECK(!OneCellSmoothing::FollowPolyline(short3, nodes));
  CHECK(short3.Curve.ControlPoints == before);
}

int main()
{
  return testing_harness::RunAll();
}

