// Tests of the topology comparison behind the verdict: points are matched one to one within
// the tolerance, as many as any assignment can (closest-first alone can miss one), and the
// bucketed search matches as many as a maximum matching over all pairs (written here).
//
// Usage: TestTopologyVerification
// Prints "N passed, N failed"; returns nonzero on failure.
#include "TestHarness.h"
#include "TestSupport.h"
#include "TopologyVerification.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

using namespace topospline;

TEST_CASE(TopologyComparisonMatchesClosestFirst)
{
  std::vector<CriticalPointLocation> expected(3), found(3);
  expected[0].MorseIndex = 0;
  expected[1].MorseIndex = 0;
  expected[1].Position[0] = 1;
  expected[2].MorseIndex = 2;
  found[0].MorseIndex = 0;
  found[0].Position[0] = 0.9;
  found[1].MorseIndex = 0;
  found[1].Position[0] = 0.2;
  found[2].MorseIndex = 1; // wrong index: spurious, and the maximum is missing
  const auto c = CompareCriticalPoints(expected, found, 0.5);
  CHECK_EQ(c.Spurious.size(), std::size_t(1));
  CHECK_EQ(c.Missing.size(), std::size_t(1));
  CHECK_EQ(c.Missing[0].MorseIndex, 2);
  CHECK(std::abs(c.MaximumDistance - 0.2) < 1e-12);
  CHECK(!c.Identical());
  CHECK(CompareCriticalPoints(expected, expected, 0).Identical());
}

// "Next to its node" is counted in edges when the comparison has the mesh: the Euclidean
// tolerance alone (the longest edge, on an irregular mesh) can reach 3 or more edges.
TEST_CASE(TopologyComparisonOnAMeshCountsEdges)
{
  TriangleMeshTopology mesh;
  mesh.BuildGrid(5, 5, SequentialFor); // triangles cut by the (i + 1, j)-(i, j + 1) diagonals
  auto at = [](int i, int j) {
    CriticalPointLocation cp;
    cp.MorseIndex = 1;
    cp.Position[0] = i;
    cp.Position[1] = j;
    cp.Vertex = i + 5 * j;
    return cp;
  };
  const std::vector<CriticalPointLocation> node{ at(0, 0) };
  // (1, 1) is 2 edges from (0, 0); (2, 1) is 3 (no vertex neighbours both), 2.24 away.
  CHECK(CompareCriticalPoints(node, { at(1, 1) }, 3.0, &mesh).Identical());
  CHECK(CompareCriticalPoints(node, { at(2, 1) }, 3.0).Identical());
  const auto far = CompareCriticalPoints(node, { at(2, 1) }, 3.0, &mesh);
  CHECK(far.Missing.size() == 1 && far.Spurious.size() == 1);
  // A boundary junction's pair may be 3 edges away, as far as its reach allows.
  std::vector<CriticalPointLocation> junction{ at(0, 0) };
  junction[0].Hops = BoundaryJunctionHops;
  CHECK(CompareCriticalPoints(junction, { at(2, 1) }, 3.0, &mesh).Identical());
  CHECK(!CompareCriticalPoints(junction, { at(2, 2) }, 3.0, &mesh).Identical()); // 4 edges, 2.83 away
}

// Closest pairs first would take A-X here and leave B alone, although A-Y and B-X are both
// within the tolerance: the comparison must find the one-to-one assignment.
TEST_CASE(TopologyComparisonFindsAOneToOneAssignment)
{
  std::vector<CriticalPointLocation> expected(2), found(2);
  expected[0].Position[0] = 0;   // A
  expected[1].Position[0] = 1;   // B
  found[0].Position[0] = 0.1;    // X, closest to A
  found[1].Position[0] = -0.9;   // Y, near A only
  for (auto* points : { &expected, &found })
  {
    for (auto& cp : *points)
    {
      cp.MorseIndex = 1;
    }
  }
  const auto c = CompareCriticalPoints(expected, found, 1.0);
  CHECK(c.Identical());
  CHECK(std::abs(c.MaximumDistance - 0.9) < 1e-12);
}

// The comparison looks only at nearby candidates (a bucket grid) and must match as many
// points as any one-to-one assignment within the tolerance can: on seeded random points, with
// reaches of 1 and 3 and negative coordinates, its count is checked against a maximum matching
// over every pair (augmenting paths, written here), and every pair it reports is checked.
TEST_CASE(TopologyComparisonEqualsAllPairs)
{
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> coordinate(-20, 20);
  for (int trial = 0; trial < 20; ++trial)
  {
    std::vector<CriticalPointLocation> expected(200), found(220);
    for (auto* points : { &expected, &found })
    {
      for (auto& cp : *points)
      {
        cp.MorseIndex = static_cast<int>(random() % 3);
        cp.Position[0] = coordinate(random);
        cp.Position[1] = coordinate(random);
        cp.Reach = points == &expected && random() % 5 == 0 ? 3 : 1;
      }
    }
    const double tolerance = 0.5 + 0.1 * trial;
    std::vector<std::vector<std::size_t>> near(expected.size());
    for (std::size_t e = 0; e < expected.size(); ++e)
    {
      for (std::size_t f = 0; f < found.size(); ++f)
      {
        const double d = std::hypot(expected[e].Position[0] - found[f].Position[0],
          expected[e].Position[1] - found[f].Position[1]);
        if (expected[e].MorseIndex == found[f].MorseIndex && d <= tolerance * expected[e].Reach)
        {
          near[e].push_back(f);
        }
      }
    }
    std::vector<int> owner(found.size(), -1);
    std::vector<char> seen;
    std::function<bool(std::size_t)> augment = [&](std::size_t e) {
      for (std::size_t f : near[e])
      {
        if (seen[f])
        {
          continue;
        }
        seen[f] = 1;
        if (owner[f] < 0 || augment(static_cast<std::size_t>(owner[f])))
        {
          owner[f] = static_cast<int>(e);
          return true;
        }
      }
      return false;
    };
    std::size_t matched = 0;
    for (std::size_t e = 0; e < expected.size(); ++e)
    {
      seen.assign(found.size(), 0);
      matched += augment(e) ? 1 : 0;
    }
    const auto c = CompareCriticalPoints(expected, found, tolerance);
    CHECK_EQ(c.Missing.size(), expected.size() - matched);
    CHECK_EQ(c.Spurious.size(), found.size() - matched);
    CHECK(c.MaximumDistance <= 3 * tolerance);
  }
}

// Topological sampling matches many found sets against one wanted set with a
// CriticalPointMatcher, whose pairs are found once: its partners must be MatchCriticalPoints'
// own, on a grid (integer coordinates: many pairs at equal distances, whose order decides the
// closest-first matching) and on a Delaunay mesh, with reaches of 1 and 3, hops of 2 and 3, two
// points on one vertex, found sets listed out of vertex order, on one thread and on four, and
// with a found point off its vertex (which Match hands to MatchCriticalPoints).
TEST_CASE(MatcherOfManyFoundSetsEqualsMatchCriticalPoints)
{
  std::mt19937_64 random(23);
  const int nx = 30, ny = 24;
  TriangleMeshTopology grid;
  grid.BuildGrid(nx, ny, SequentialFor);
  std::vector<double> gridPoints;
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i)
    {
      gridPoints.insert(gridPoints.end(), { double(i), double(j) });
    }
  }
  const PlanarScalarField scattered = RandomDelaunayField(5, 400);
  TriangleMeshTopology delaunay;
  std::string error;
  CHECK(delaunay.Build(static_cast<Index>(scattered.Points.size() / 2), scattered.Triangles, SequentialFor, error));
  const auto at = [](const std::vector<double>& points, Index v, int morseIndex) {
    CriticalPointLocation cp;
    cp.MorseIndex = morseIndex;
    cp.Position[0] = points[2 * v];
    cp.Position[1] = points[2 * v + 1];
    cp.Vertex = v;
    return cp;
  };
  int compared = 0, matched = 0;
  for (const auto& [mesh, points, tolerance] :
    { std::make_tuple(&grid, &std::as_const(gridPoints), 1.0 + 1e-9),
      std::make_tuple(&grid, &std::as_const(gridPoints), 1.5), std::make_tuple(&delaunay, &scattered.Points, 0.06) })
  {
    const Index vertices = mesh->NumberOfVertices();
    std::vector<CriticalPointLocation> expected;
    for (int k = 0; k < vertices / 5; ++k)
    {
      const Index v = static_cast<Index>(random() % vertices);
      expected.push_back(at(*points, v, static_cast<int>(random() % 3)));
      if (random() % 6 == 0)
      {
        expected.back().Reach = BoundaryJunctionReach;
        expected.back().Hops = BoundaryJunctionHops;
        expected.push_back(at(*points, v, 1)); // a second point on the vertex
      }
    }
    CriticalPointMatcher sequential(expected, *points, tolerance, *mesh);
    CriticalPointMatcher threaded(expected, *points, tolerance, *mesh, ThreadedFor);
    for (int set = 0; set < 8; ++set)
    {
      std::vector<CriticalPointLocation> found;
      for (int k = 0; k < vertices / 4; ++k)
      {
        const Index v = static_cast<Index>(random() % vertices);
        found.push_back(at(*points, v, static_cast<int>(random() % 3)));
        if (random() % 8 == 0)
        {
          found.push_back(found.back()); // a saddle of multiplicity 2
        }
      }
      if (set % 2 == 1)
      {
        std::sort(found.begin(), found.end(),
          [](const CriticalPointLocation& a, const CriticalPointLocation& b) { return a.Vertex < b.Vertex; });
      }
      if (set == 7)
      {
        found[0].Position[0] += 0.25 * tolerance; // off its vertex
      }
      const std::vector<std::size_t> reference = MatchCriticalPoints(expected, found, tolerance, mesh);
      CHECK(sequential.Match(found) == reference);
      CHECK(threaded.Match(found) == reference);
      ++compared;
      matched += static_cast<int>(
        std::count_if(reference.begin(), reference.end(), [](std::size_t f) { return f != UnmatchedCriticalPoint; }));
    }
  }
  CHECK_EQ(compared, 24);
  CHECK(matched > 500); // the sets do overlap
}

int main()
{
  return testing_harness::RunAll();
}
