#include "TopologyVerification.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace topospline
{
std::vector<CriticalPointLocation> CriticalPointLocations(
  const MorseSmaleComplex& complex, const std::vector<double>& points)
{
  std::vector<CriticalPointLocation> result;
  result.reserve(complex.CriticalPoints.size());
  for (const CriticalPoint& cp : complex.CriticalPoints)
  {
    CriticalPointLocation location;
    location.MorseIndex = cp.MorseIndex;
    location.Position[0] = points[2 * static_cast<std::size_t>(cp.Vertex)];
    location.Position[1] = points[2 * static_cast<std::size_t>(cp.Vertex) + 1];
    location.Value = cp.Value;
    result.push_back(location);
  }
  // A boundary junction: the boundary 1-cells fall into it and on into the domain, so it is a
  // minimum of the field along the boundary curve with a lower interior neighbour, which
  // stage 1's boundary rule extracts as a minimum and a saddle on that vertex.
  for (Index v : complex.BoundaryJunctions)
  {
    for (int morseIndex : { 0, 1 })
    {
      CriticalPointLocation location;
      location.MorseIndex = morseIndex;
      location.Position[0] = points[2 * static_cast<std::size_t>(v)];
      location.Position[1] = points[2 * static_cast<std::size_t>(v) + 1];
      location.Value = std::nan("");
      location.Reach = BoundaryJunctionReach;
      result.push_back(location);
    }
  }
  return result;
}

TopologyComparison CompareCriticalPoints(const std::vector<CriticalPointLocation>& expected,
  const std::vector<CriticalPointLocation>& found, double tolerance)
{
  TopologyComparison comparison;
  for (const auto& cp : expected)
  {
    ++comparison.Expected[std::clamp(cp.MorseIndex, 0, 2)];
  }
  for (const auto& cp : found)
  {
    ++comparison.Found[std::clamp(cp.MorseIndex, 0, 2)];
  }
  // Candidate pairs within the tolerance, closest first. The found points are bucketed in
  // squares of the largest reach, so each expected point looks at its 3 x 3 neighbourhood
  // only (comparing all pairs took 5.6 s for the 20 000 critical points of 200 x 200 noise).
  double reach = 1;
  for (const auto& cp : expected)
  {
    reach = std::max(reach, cp.Reach);
  }
  const double side = tolerance * reach > 0 ? tolerance * reach : 1.0;
  auto bucketOf = [side](double x, double y) {
    return std::make_pair(static_cast<long long>(std::floor(x / side)), static_cast<long long>(std::floor(y / side)));
  };
  std::map<std::pair<long long, long long>, std::vector<std::size_t>> buckets;
  for (std::size_t f = 0; f < found.size(); ++f)
  {
    buckets[bucketOf(found[f].Position[0], found[f].Position[1])].push_back(f);
  }
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  for (std::size_t e = 0; e < expected.size(); ++e)
  {
    const auto home = bucketOf(expected[e].Position[0], expected[e].Position[1]);
    for (long long i = home.first - 1; i <= home.first + 1; ++i)
    {
      for (long long j = home.second - 1; j <= home.second + 1; ++j)
      {
        const auto bucket = buckets.find({ i, j });
        if (bucket == buckets.end())
        {
          continue;
        }
        for (const std::size_t f : bucket->second)
        {
          if (expected[e].MorseIndex != found[f].MorseIndex)
          {
            continue;
          }
          const double d = std::hypot(expected[e].Position[0] - found[f].Position[0],
            expected[e].Position[1] - found[f].Position[1]);
          if (d <= tolerance * expected[e].Reach)
          {
            pairs.emplace_back(d, e, f);
          }
        }
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<char> usedExpected(expected.size(), 0), usedFound(found.size(), 0);
  for (const auto& [d, e, f] : pairs)
  {
    if (!usedExpected[e] && !usedFound[f])
    {
      usedExpected[e] = usedFound[f] = 1;
      comparison.MaximumDistance = std::max(comparison.MaximumDistance, d);
    }
  }
  for (std::size_t e = 0; e < expected.size(); ++e)
  {
    if (!usedExpected[e])
    {
      comparison.Missing.push_back(expected[e]);
    }
  }
  for (std::size_t f = 0; f < found.size(); ++f)
  {
    if (!usedFound[f])
    {
      comparison.Spurious.push_back(found[f]);
    }
  }
  return comparison;
}
} // namespace topospline
