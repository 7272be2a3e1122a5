#include "TopologicalSampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

namespace topospline
{
namespace
{
// Stage 1's order: by value, then by vertex id.
struct Key
{
  double Value;
  Index Vertex;
  bool operator<(const Key& o) const { return this->Value < o.Value || (this->Value == o.Value && this->Vertex < o.Vertex); }
};

// A graph in compressed rows: the neighbours of v are Adjacent[Start[v] .. Start[v + 1]).
struct Graph
{
  std::vector<Index> Start;
  std::vector<Index> Adjacent;
};

// Whether v has no neighbour before it in the sweep order (a minimum when ascending).
bool IsExtremum(const Graph& g, const std::vector<double>& values, Index v, bool ascending)
{
  if (g.Start[v] == g.Start[v + 1])
  {
    return false;
  }
  const Key key{ values[v], v };
  for (Index i = g.Start[v]; i < g.Start[v + 1]; ++i)
  {
    const Index w = g.Adjacent[i];
    const Key other{ values[w], w };
    if (ascending ? other < key : key < other)
    {
      return false;
    }
  }
  return true;
}

// Removes the unwanted extremum v by a local flood (priority-flood depression filling, the
// local form of Tierny and Pascucci's sweep): the region grown from v in sweep order up to the
// first vertex that drains outside it (a neighbour before it, not in the region) or that is a
// wanted extremum of the same kind, is then re-valued from that outlet inwards, every vertex
// just past the neighbour it was reached from, so that each has a neighbour before it. Values
// only move in the sweep direction. Returns the number of changed vertices.
Index Fill(const Graph& g, std::vector<double>& values, Index v, bool ascending,
  const std::vector<unsigned char>& wanted, unsigned char flag, std::vector<unsigned>& mark, unsigned& stamp)
{
  auto before = [ascending](const Key& a, const Key& b) { return ascending ? a < b : b < a; };
  auto later = [&](const Key& a, const Key& b) { return before(b, a); };
  std::priority_queue<Key, std::vector<Key>, decltype(later)> queue(later);
  const unsigned seen = ++stamp;
  mark[v] = seen;
  queue.push({ values[v], v });
  std::vector<Index> region;
  Index outlet = InvalidIndex;
  while (!queue.empty() && outlet == InvalidIndex)
  {
    const Index u = queue.top().Vertex;
    queue.pop();
    const Key key{ values[u], u };
    if (u != v && (wanted[u] & flag))
    {
      outlet = u;
      break;
    }
    for (Index i = g.Start[u]; i < g.Start[u + 1]; ++i)
    {
      const Index w = g.Adjacent[i];
      if (mark[w] != seen && before({ values[w], w }, key))
      {
        outlet = u;
        break;
      }
    }
    if (outlet != InvalidIndex)
    {
      break;
    }
    region.push_back(u);
    for (Index i = g.Start[u]; i < g.Start[u + 1]; ++i)
    {
      const Index w = g.Adjacent[i];
      if (mark[w] != seen)
      {
        mark[w] = seen;
        queue.push({ values[w], w });
      }
    }
  }
  if (outlet == InvalidIndex)
  {
    return 0; // the whole component: nothing to drain into
  }
  // From the outlet inwards (breadth first over the region).
  const unsigned inRegion = ++stamp;
  for (Index r : region)
  {
    mark[r] = inRegion;
  }
  const double direction = ascending ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
  std::vector<Index> front = { outlet };
  Index changed = 0;
  for (std::size_t k = 0; k < front.size(); ++k)
  {
    const Index p = front[k];
    for (Index i = g.Start[p]; i < g.Start[p + 1]; ++i)
    {
      const Index r = g.Adjacent[i];
      if (mark[r] != inRegion)
      {
        continue;
      }
      mark[r] = 0;
      const double past = std::nextafter(values[p], direction);
      if (ascending ? values[r] < past : values[r] > past)
      {
        values[r] = past;
        ++changed;
      }
      front.push_back(r);
    }
  }
  return changed;
}
} // namespace

TopologicalSamplingReport EnforceCriticalVertices(const TriangleMeshTopology& mesh,
  const SamplingConstraints& constraints, std::vector<double>& values, int maximumRounds)
{
  TopologicalSamplingReport report;
  const Index n = mesh.NumberOfVertices();
  const std::vector<double> original = values;
  // Vertex adjacency (all edges, and boundary edges only), built once.
  Graph all, boundary;
  all.Start.assign(n + 1, 0);
  boundary.Start.assign(n + 1, 0);
  for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
  {
    for (Index v : mesh.EdgeVertices[e])
    {
      ++all.Start[v + 1];
      boundary.Start[v + 1] += mesh.IsBoundaryEdge(e) ? 1 : 0;
    }
  }
  for (Index v = 0; v < n; ++v)
  {
    all.Start[v + 1] += all.Start[v];
    boundary.Start[v + 1] += boundary.Start[v];
  }
  all.Adjacent.resize(all.Start[n]);
  boundary.Adjacent.resize(boundary.Start[n]);
  {
    std::vector<Index> fill(all.Start.begin(), all.Start.end() - 1);
    std::vector<Index> boundaryFill(boundary.Start.begin(), boundary.Start.end() - 1);
    for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
    {
      const Index a = mesh.EdgeVertices[e][0], b = mesh.EdgeVertices[e][1];
      all.Adjacent[fill[a]++] = b;
      all.Adjacent[fill[b]++] = a;
      if (mesh.IsBoundaryEdge(e))
      {
        boundary.Adjacent[boundaryFill[a]++] = b;
        boundary.Adjacent[boundaryFill[b]++] = a;
      }
    }
  }
  std::vector<unsigned char> wanted(n, 0);
  for (Index v : constraints.Minima)
  {
    wanted[v] |= 1;
  }
  for (Index v : constraints.Maxima)
  {
    wanted[v] |= 2;
  }
  for (Index v : constraints.BoundaryMinima)
  {
    wanted[v] |= 4;
  }
  for (Index v : constraints.BoundaryMaxima)
  {
    wanted[v] |= 8;
  }
  // Passes: along the boundary curve first (stage 1's boundary rule), then whole links.
  struct Pass
  {
    const Graph* G;
    bool Ascending;
    unsigned char Flag;
  };
  const Pass passes[4] = { { &boundary, true, 4 }, { &boundary, false, 8 }, { &all, true, 1 }, { &all, false, 2 } };
  std::vector<unsigned> mark(n, 0);
  unsigned stamp = 0;
  Index previousChanged = -1;
  for (report.Rounds = 1; report.Rounds <= maximumRounds; ++report.Rounds)
  {
    Index changed = 0;
    for (const Pass& pass : passes)
    {
      std::vector<Index> candidates;
      for (Index v = 0; v < n; ++v)
      {
        if (!(wanted[v] & pass.Flag) && IsExtremum(*pass.G, values, v, pass.Ascending))
        {
          candidates.push_back(v);
        }
      }
      for (Index v : candidates)
      {
        if (IsExtremum(*pass.G, values, v, pass.Ascending))
        {
          changed += Fill(*pass.G, values, v, pass.Ascending, wanted, pass.Flag, mark, stamp);
        }
      }
      if (stamp > std::numeric_limits<unsigned>::max() / 2)
      {
        std::fill(mark.begin(), mark.end(), 0u);
        stamp = 0;
      }
    }
    if (changed == 0)
    {
      report.Converged = true;
      break;
    }
    // The same handful of changes again: a boundary and a whole-link constraint keep undoing
    // each other by a few ulps; more rounds would only repeat it.
    if (changed == previousChanged)
    {
      break;
    }
    previousChanged = changed;
  }
  report.Rounds = std::min(report.Rounds, maximumRounds);
  CountChanges(original, values, report);
  return report;
}

SamplingConstraints ComplexConstraints(const MorseSmaleComplex& complex, const TriangleMeshTopology& complexMesh,
  const TriangleMeshTopology& mesh, const std::function<Index(Index)>& vertexAt)
{
  SamplingConstraints constraints;
  for (const CriticalPoint& cp : complex.CriticalPoints)
  {
    const Index v = vertexAt(cp.Vertex);
    if (v < 0 || v >= mesh.NumberOfVertices())
    {
      continue;
    }
    if (cp.MorseIndex == 0)
    {
      constraints.Minima.push_back(v);
      if (mesh.IsBoundaryVertex(v))
      {
        constraints.BoundaryMinima.push_back(v);
      }
    }
    else if (cp.MorseIndex == 2)
    {
      constraints.Maxima.push_back(v);
    }
    else
    {
      constraints.Saddles.push_back(v);
      if (cp.Cell >= 0 && cp.Cell < complexMesh.NumberOfEdges() && complexMesh.IsBoundaryEdge(cp.Cell) &&
        mesh.IsBoundaryVertex(v))
      {
        constraints.BoundaryMaxima.push_back(v);
      }
    }
  }
  return constraints;
}

void CountChanges(const std::vector<double>& before, const std::vector<double>& after,
  TopologicalSamplingReport& report)
{
  for (std::size_t v = 0; v < before.size() && v < after.size(); ++v)
  {
    if (after[v] != before[v])
    {
      ++report.ChangedVertices;
      report.MaximumChange = std::max(report.MaximumChange, std::abs(after[v] - before[v]));
    }
  }
}

int RelocateSaddles(const PlanarScalarField& field, const TriangleMeshTopology& mesh,
  const SamplingConstraints& constraints, double tolerance, double reach, std::vector<double>& values,
  int maximumRounds, int maximumMissing)
{
  const std::vector<Index>& wantedSaddles = constraints.Saddles;
  PlanarScalarField sampled = field;
  const auto& p = field.Points;
  auto distance = [&p](Index a, Index b) { return std::hypot(p[2 * a] - p[2 * b], p[2 * a + 1] - p[2 * b + 1]); };
  // Unmatched wanted saddles and the found saddles no wanted one claims, for `current`.
  auto unmatched = [&](const std::vector<double>& current, std::vector<Index>& missing, std::vector<Index>& spare) {
    sampled.Values = current;
    MorseSmaleComplexExtraction extraction;
    MorseSmaleComplex found;
    std::string error;
    missing.clear();
    spare.clear();
    if (!extraction.Extract(sampled, found, error))
    {
      missing = wantedSaddles;
      return;
    }
    std::vector<Index> saddles;
    for (const CriticalPoint& cp : found.CriticalPoints)
    {
      if (cp.MorseIndex == 1)
      {
        saddles.push_back(cp.Vertex);
      }
    }
    std::vector<char> used(saddles.size(), 0);
    for (Index w : wantedSaddles)
    {
      std::size_t best = saddles.size();
      for (std::size_t i = 0; i < saddles.size(); ++i)
      {
        if (!used[i] && distance(w, saddles[i]) <= tolerance &&
          (best == saddles.size() || distance(w, saddles[i]) < distance(w, saddles[best])))
        {
          best = i;
        }
      }
      if (best < saddles.size())
      {
        used[best] = 1;
      }
      else
      {
        missing.push_back(w);
      }
    }
    for (std::size_t i = 0; i < saddles.size(); ++i)
    {
      if (!used[i])
      {
        spare.push_back(saddles[i]);
      }
    }
  };
  std::vector<Index> missing, spare;
  unmatched(values, missing, spare);
  // Each round costs an extraction of the whole sampling: worth it for the few saddles of a
  // flat pass, not when many are missing (a failed 2-cell keeps the input's own saddles).
  if (static_cast<int>(missing.size()) > maximumMissing)
  {
    return static_cast<int>(missing.size());
  }
  for (int round = 0; round < maximumRounds && !missing.empty(); ++round)
  {
    std::vector<double> trial = values;
    bool moved = false;
    for (Index w : missing)
    {
      Index nearest = InvalidIndex;
      for (Index f : spare)
      {
        if (distance(w, f) <= reach && (nearest == InvalidIndex || distance(w, f) < distance(w, nearest)))
        {
          nearest = f;
        }
      }
      if (nearest == InvalidIndex)
      {
        continue;
      }
      const bool raise = trial[nearest] <= trial[w];
      trial[nearest] = std::nextafter(trial[w], raise ? std::numeric_limits<double>::infinity()
                                                      : -std::numeric_limits<double>::infinity());
      moved = true;
    }
    if (!moved)
    {
      break;
    }
    EnforceCriticalVertices(mesh, constraints, trial);
    std::vector<Index> trialMissing, trialSpare;
    unmatched(trial, trialMissing, trialSpare);
    if (trialMissing.size() >= missing.size())
    {
      break;
    }
    values = std::move(trial);
    missing = std::move(trialMissing);
    spare = std::move(trialSpare);
  }
  return static_cast<int>(missing.size());
}
} // namespace topospline
