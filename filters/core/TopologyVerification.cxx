#include "TopologyVerification.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
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
    location.Vertex = cp.Vertex;
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
      location.Vertex = v;
      location.Hops = BoundaryJunctionHops;
      result.push_back(location);
    }
  }
  return result;
}

namespace
{
constexpr std::size_t Unmatched = UnmatchedCriticalPoint;

// A maximum matching of the candidate pairs (distance, expected, found), sorted closest first:
// the closest pairs are taken first, then every expected point left over looks for an
// augmenting path (Kuhn's algorithm, iterative). Closest-first alone can leave a point
// unmatched where a one-to-one assignment within the tolerance exists: with A and X on one
// vertex and B and Y a spacing away on either side, A takes X, and B finds nothing, although
// A-Y and B-X would do. Returns the found point of each expected one (Unmatched: none).
std::vector<std::size_t> MatchAsManyAsPossible(
  const std::vector<std::tuple<double, std::size_t, std::size_t>>& pairs, std::size_t expected, std::size_t found)
{
  // Each expected point's candidates in the order of `pairs`, as compressed rows (a vector per
  // point made a third of the matching's time on 1000 x 1000 noise).
  std::vector<std::size_t> offsets(expected + 1, 0), candidateOf(pairs.size());
  for (const auto& pair : pairs)
  {
    ++offsets[std::get<1>(pair) + 1];
  }
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
  std::vector<std::size_t> partnerOfExpected(expected, Unmatched), partnerOfFound(found, Unmatched);
  for (const auto& [d, e, f] : pairs)
  {
    candidateOf[fill[e]++] = f;
    if (partnerOfExpected[e] == Unmatched && partnerOfFound[f] == Unmatched)
    {
      partnerOfExpected[e] = f;
      partnerOfFound[f] = e;
    }
  }
  std::vector<std::size_t> visitedIn(found, Unmatched);
  for (std::size_t start = 0; start < expected; ++start)
  {
    if (partnerOfExpected[start] != Unmatched || offsets[start] == offsets[start + 1])
    {
      continue;
    }
    // Depth-first over alternating paths: (expected point, next candidate to try) per level.
    std::vector<std::pair<std::size_t, std::size_t>> stack{ { start, offsets[start] } };
    std::vector<std::size_t> via; // the found point taken at each level
    bool augmented = false;
    while (!stack.empty() && !augmented)
    {
      auto& [e, next] = stack.back();
      if (next == offsets[e + 1])
      {
        stack.pop_back();
        if (!via.empty())
        {
          via.pop_back();
        }
        continue;
      }
      const std::size_t f = candidateOf[next++];
      if (visitedIn[f] == start)
      {
        continue;
      }
      visitedIn[f] = start;
      via.push_back(f);
      if (partnerOfFound[f] == Unmatched)
      {
        augmented = true;
        break;
      }
      stack.emplace_back(partnerOfFound[f], offsets[partnerOfFound[f]]);
    }
    if (augmented)
    {
      // stack[i].first takes via[i]
      for (std::size_t i = 0; i < via.size(); ++i)
      {
        partnerOfExpected[stack[i].first] = via[i];
        partnerOfFound[via[i]] = stack[i].first;
      }
    }
  }
  return partnerOfExpected;
}

// The distance between a pair's points if it is within `limit`: the squared distance first
// (with a margin for its rounding) tells most pairs apart before std::hypot, which gives the
// pairs' order.
bool WithinReach(const double* a, const double* b, double limit, double& distance)
{
  const double dx = a[0] - b[0];
  const double dy = a[1] - b[1];
  if (dx * dx + dy * dy > limit * limit * (1 + 1e-9))
  {
    return false;
  }
  distance = std::hypot(dx, dy);
  return distance <= limit;
}

// The vertices within `hops` edges of a (a first), each once: the vertices b for which
// WithinHops(mesh, a, b, hops) holds.
void VerticesWithinHops(const TriangleMeshTopology& mesh, Index a, int hops, std::vector<Index>& out)
{
  out.assign(1, a);
  for (std::size_t ringBegin = 0, ringEnd = 1; hops > 0 && ringBegin < ringEnd; --hops)
  {
    for (std::size_t k = ringBegin; k < ringEnd; ++k)
    {
      const Index u = out[k];
      for (Index i = mesh.VertexTriangleBegin(u); i < mesh.VertexTriangleEnd(u); ++i)
      {
        for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
        {
          if (std::find(out.begin(), out.end(), w) == out.end())
          {
            out.push_back(w);
          }
        }
      }
    }
    ringBegin = ringEnd;
    ringEnd = out.size();
  }
}

// Whether b is within `hops` edges of a: a walk over the triangles around each vertex, with
// nothing allocated. The topological sampling matches its saddles many times per run with the
// mesh: a sorted neighbourhood per expected point made stage 4 take 2 s of 16 more on 300 x 300
// noise.
bool WithinHops(const TriangleMeshTopology& mesh, Index a, Index b, int hops)
{
  if (a == b)
  {
    return true;
  }
  if (hops <= 0)
  {
    return false;
  }
  for (Index i = mesh.VertexTriangleBegin(a); i < mesh.VertexTriangleEnd(a); ++i)
  {
    for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
    {
      if (w != a && WithinHops(mesh, w, b, hops - 1))
      {
        return true;
      }
    }
  }
  return false;
}
} // namespace

std::vector<std::size_t> MatchCriticalPoints(const std::vector<CriticalPointLocation>& expected,
  const std::vector<CriticalPointLocation>& found, double tolerance, const TriangleMeshTopology* mesh,
  const ParallelFor& parallel)
{
  // Candidate pairs within the tolerance, closest first. The found points are bucketed in
  // squares of the largest reach, so each expected point looks at its 3 x 3 neighbourhood
  // only (comparing all pairs took 5.6 s for the 20 000 critical points of 200 x 200 noise).
  // The buckets are one sorted array, not a tree of vectors: the topological sampling matches
  // its saddles several times per run, and on 500 x 500 noise (60 000 saddles) the tree's
  // lookups and allocations took 5 s of it.
  double reach = 1;
  for (const auto& cp : expected)
  {
    reach = std::max(reach, cp.Reach);
  }
  const double side = tolerance * reach > 0 ? tolerance * reach : 1.0;
  auto bucketOf = [side](double x, double y) {
    return std::make_pair(static_cast<long long>(std::floor(x / side)), static_cast<long long>(std::floor(y / side)));
  };
  using Bucket = std::pair<long long, long long>;
  std::vector<std::pair<Bucket, std::size_t>> buckets(found.size());
  for (std::size_t f = 0; f < found.size(); ++f)
  {
    buckets[f] = { bucketOf(found[f].Position[0], found[f].Position[1]), f };
  }
  std::sort(buckets.begin(), buckets.end());
  const auto byBucket = [](const std::pair<Bucket, std::size_t>& a, const std::pair<Bucket, std::size_t>& b) {
    return a.first < b.first;
  };
  using Pair = std::tuple<double, std::size_t, std::size_t>;
  const auto onMesh = [mesh](const CriticalPointLocation& cp) {
    return mesh != nullptr && cp.Vertex != InvalidIndex && cp.Vertex < mesh->NumberOfVertices();
  };
  // Each stretch of expected points gathers its own pairs: the sampling matches 60 000 saddles
  // about 60 times on 500 x 500 noise, a third of its time. The pairs are sorted whole after,
  // so the stretches' order does not matter.
  const Index count = static_cast<Index>(expected.size());
  const auto candidatesOf = [&](Index item, std::vector<Pair>& candidates) {
    const std::size_t e = static_cast<std::size_t>(item);
    const auto home = bucketOf(expected[e].Position[0], expected[e].Position[1]);
    // The three buckets of a row follow each other in the sorted array: one search per row.
    for (long long i = home.first - 1; i <= home.first + 1; ++i)
    {
      const Bucket last{ i, home.second + 1 };
      for (auto entry = std::lower_bound(buckets.begin(), buckets.end(),
             std::make_pair(Bucket{ i, home.second - 1 }, std::size_t{ 0 }), byBucket);
           entry != buckets.end() && entry->first <= last; ++entry)
      {
        const std::size_t f = entry->second;
        if (expected[e].MorseIndex != found[f].MorseIndex)
        {
          continue;
        }
        // Most points of the nine buckets are beyond the reach.
        double d = 0;
        if (WithinReach(expected[e].Position, found[f].Position, tolerance * expected[e].Reach, d) &&
          (!onMesh(expected[e]) || !onMesh(found[f]) ||
            WithinHops(*mesh, expected[e].Vertex, found[f].Vertex, expected[e].Hops)))
        {
          candidates.emplace_back(d, e, f);
        }
      }
    }
  };
  std::vector<Pair> pairs = CollectInStretches<Pair>(count, 4096, parallel, candidatesOf);
  std::sort(pairs.begin(), pairs.end());
  return MatchAsManyAsPossible(pairs, expected.size(), found.size());
}

CriticalPointMatcher::CriticalPointMatcher(const std::vector<CriticalPointLocation>& expected,
  const std::vector<double>& points, double tolerance, const TriangleMeshTopology& mesh, const ParallelFor& parallel)
  : Expected(expected)
  , Points(points)
  , Tolerance(tolerance)
  , Mesh(mesh)
  , Parallel(parallel)
{
  for (const CriticalPointLocation& cp : expected)
  {
    this->OnVertices = this->OnVertices && this->IsVertex(cp.Vertex);
  }
  if (!this->OnVertices)
  {
    return;
  }
  this->Candidates = CollectInStretches<Candidate>(
    static_cast<Index>(expected.size()), 4096, parallel, [&](Index e, std::vector<Candidate>& candidates) {
      const CriticalPointLocation& cp = expected[e];
      thread_local std::vector<Index> within;
      VerticesWithinHops(mesh, cp.Vertex, cp.Hops, within);
      for (Index v : within)
      {
        double d = 0;
        if (WithinReach(cp.Position, &points[2 * static_cast<std::size_t>(v)], tolerance * cp.Reach, d))
        {
          candidates.push_back({ d, e, v });
        }
      }
    });
  std::sort(this->Candidates.begin(), this->Candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.Distance, a.Expected, a.Vertex) < std::tie(b.Distance, b.Expected, b.Vertex);
  });
}

bool CriticalPointMatcher::IsVertex(Index v) const
{
  return v >= 0 && v < this->Mesh.NumberOfVertices() && 2 * static_cast<std::size_t>(v) + 1 < this->Points.size();
}

std::vector<std::size_t> CriticalPointMatcher::Match(const std::vector<CriticalPointLocation>& found)
{
  bool atVertices = this->OnVertices;
  for (std::size_t f = 0; f < found.size() && atVertices; ++f)
  {
    const Index v = found[f].Vertex;
    atVertices = this->IsVertex(v) && found[f].Position[0] == this->Points[2 * v] &&
      found[f].Position[1] == this->Points[2 * v + 1];
  }
  if (!atVertices)
  {
    return MatchCriticalPoints(this->Expected, found, this->Tolerance, &this->Mesh, this->Parallel);
  }
  // The found points on each vertex, in increasing order: a list through `next` from `first`.
  constexpr std::size_t none = Unmatched;
  std::vector<std::size_t>& first = this->FirstFoundAt;
  first.resize(static_cast<std::size_t>(this->Mesh.NumberOfVertices()), none);
  std::vector<std::size_t> next(found.size());
  for (std::size_t f = found.size(); f-- > 0;)
  {
    next[f] = first[found[f].Vertex];
    first[found[f].Vertex] = f;
  }
  // MatchCriticalPoints' pairs sort by (distance, expected, found); the candidates are in that
  // order but for the found points of one run of equal distance and expected point, which may
  // lie on several vertices in another order than their numbers.
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < this->Candidates.size();)
  {
    const Candidate& head = this->Candidates[i];
    const std::size_t runStart = pairs.size();
    for (; i < this->Candidates.size() && this->Candidates[i].Distance == head.Distance &&
         this->Candidates[i].Expected == head.Expected;
         ++i)
    {
      const std::size_t e = static_cast<std::size_t>(head.Expected);
      for (std::size_t f = first[this->Candidates[i].Vertex]; f != none; f = next[f])
      {
        if (found[f].MorseIndex == this->Expected[e].MorseIndex)
        {
          pairs.emplace_back(head.Distance, e, f);
        }
      }
    }
    std::sort(pairs.begin() + static_cast<std::ptrdiff_t>(runStart), pairs.end());
  }
  for (const CriticalPointLocation& cp : found)
  {
    first[cp.Vertex] = none;
  }
  return MatchAsManyAsPossible(pairs, this->Expected.size(), found.size());
}

TopologyComparison CompareCriticalPoints(const std::vector<CriticalPointLocation>& expected,
  const std::vector<CriticalPointLocation>& found, double tolerance, const TriangleMeshTopology* mesh,
  const ParallelFor& parallel)
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
  const std::vector<std::size_t> partner = MatchCriticalPoints(expected, found, tolerance, mesh, parallel);
  std::vector<char> usedFound(found.size(), 0);
  for (std::size_t e = 0; e < expected.size(); ++e)
  {
    if (partner[e] == UnmatchedCriticalPoint)
    {
      comparison.Missing.push_back(expected[e]);
      continue;
    }
    usedFound[partner[e]] = 1;
    comparison.MaximumDistance = std::max(comparison.MaximumDistance,
      std::hypot(expected[e].Position[0] - found[partner[e]].Position[0],
        expected[e].Position[1] - found[partner[e]].Position[1]));
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
