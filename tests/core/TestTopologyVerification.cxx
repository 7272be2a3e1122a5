// Tests of the topology comparison behind the verdict: closest pairs are matched first, each
// point once, and the bucketed search matches exactly what a brute force over all pairs
// (written here) matches.
//
// Usage: TestTopologyVerification
// Prints "N passed, N failed"; returns nonzero on failure.
#include "TestHarness.h"
#include "TopologyVerification.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
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

// The comparison looks only at nearby candidates (a bucket grid): on seeded random points,
// with reaches of 1 and 3 and negative coordinates, it must match exactly what every pair,
// sorted closest first, matches (a brute force written here).
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
    std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
    for (std::size_t e = 0; e < expected.size(); ++e)
    {
      for (std::size_t f = 0; f < found.size(); ++f)
      {
        const double d = std::hypot(expected[e].Position[0] - found[f].Position[0],
          expected[e].Position[1] - found[f].Position[1]);
        if (expected[e].MorseIndex == found[f].MorseIndex && d <= tolerance * expected[e].Reach)
        {
          pairs.emplace_back(d, e, f);
        }
      }
    }
    std::sort(pairs.begin(), pairs.end());
    std::vector<char> usedExpected(expected.size(), 0), usedFound(found.size(), 0);
    std::size_t matched = 0;
    double farthest = 0;
    for (const auto& [d, e, f] : pairs)
    {
      if (!usedExpected[e] && !usedFound[f])
      {
        usedExpected[e] = usedFound[f] = 1;
        ++matched;
        farthest = std::max(farthest, d);
      }
    }
    const auto c = CompareCriticalPoints(expected, found, tolerance);
    CHECK_EQ(c.Missing.size(), expected.size() - matched);
    CHECK_EQ(c.Spurious.size(), found.size() - matched);
    CHECK(c.MaximumDistance == farthest);
  }
}

int main()
{
  return testing_harness::RunAll();
}
