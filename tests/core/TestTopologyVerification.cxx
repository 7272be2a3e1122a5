// Tests of the topology comparison behind the verdict: points are matched one to one within
// the tolerance, as many as any assignment can (closest-first alone can miss one), and the
// bucketed search matches as many as a maximum matching over all pairs (written here).
//
// Usage: TestTopologyVerification
// Prints "N passed, N failed"; returns nonzero on failure.
#include "TestHarness.h"
#include "TopologyVerification.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <tuple>
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

int main()
{
  return testing_harness::RunAll();
}
