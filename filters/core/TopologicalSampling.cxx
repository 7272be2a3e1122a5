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

// One sweep from `seeds` over the graph given by `neighbours`, upwards (ascending) or
// downwards. A vertex popped out of order (it lies in a pit the sweep reached only through a
// higher pass) is moved just past the last popped one. Returns the number of changed vertices.
template <typename Neighbours>
Index Sweep(const std::vector<Index>& seeds, bool ascending, const Neighbours& neighbours, std::vector<double>& values,
  std::vector<unsigned char>& visited, std::vector<Index>& touched)
{
  auto before = [ascending](const Key& a, const Key& b) { return ascending ? a < b : b < a; };
  auto later = [&](const Key& a, const Key& b) { return before(b, a); }; // min-heap in sweep order
  std::priority_queue<Key, std::vector<Key>, decltype(later)> queue(later);
  for (Index s : seeds)
  {
    if (!visited[s])
    {
      visited[s] = 1;
      touched.push_back(s);
      queue.push({ values[s], s });
    }
  }
  Index changed = 0;
  bool hasLast = false;
  Key last{ 0, 0 };
  std::vector<Index> around;
  while (!queue.empty())
  {
    Key current = queue.top();
    queue.pop();
    if (hasLast && !before(last, current))
    {
      // Just past `last` in the sweep order: the same value if the id already orders it after,
      // else the next double.
      double v = last.Value;
      const bool idAfter = ascending ? current.Vertex > last.Vertex : current.Vertex < last.Vertex;
      if (!idAfter)
      {
        v = std::nextafter(v, ascending ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity());
      }
      values[current.Vertex] = v;
      current.Value = v;
      ++changed;
    }
    last = current;
    hasLast = true;
    around.clear();
    neighbours(current.Vertex, around);
    for (Index n : around)
    {
      if (!visited[n])
      {
        visited[n] = 1;
        touched.push_back(n);
        queue.push({ values[n], n });
      }
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
  std::vector<unsigned char> visited(n, 0);
  std::vector<Index> touched;
  auto all = [&mesh](Index v, std::vector<Index>& out) {
    for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v); ++i)
    {
      for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
      {
        if (w != v)
        {
          out.push_back(w);
        }
      }
    }
  };
  auto alongBoundary = [&mesh](Index v, std::vector<Index>& out) {
    for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v); ++i)
    {
      for (Index e : mesh.TriangleEdges[mesh.VertexTriangle(i)])
      {
        const auto& ends = mesh.EdgeVertices[e];
        if (mesh.IsBoundaryEdge(e) && (ends[0] == v || ends[1] == v))
        {
          out.push_back(mesh.OtherEdgeVertex(e, v));
        }
      }
    }
  };
  auto reset = [&]() {
    for (Index v : touched)
    {
      visited[v] = 0;
    }
    touched.clear();
  };
  // Whether any vertex other than a wanted one is an extremum (of the whole link, or along the
  // boundary curve): a cheap test that spares the sweeps when there is nothing to do.
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
  auto spuriousExtremum = [&]() {
    std::vector<Index> around;
    for (Index v = 0; v < n; ++v)
    {
      const Key key{ values[v], v };
      auto check = [&](const auto& neighbours, unsigned char minimumFlag, unsigned char maximumFlag) {
        around.clear();
        neighbours(v, around);
        bool lower = false, higher = false;
        for (Index w : around)
        {
          const Key other{ values[w], w };
          (other < key ? lower : higher) = true;
        }
        return (!lower && !(wanted[v] & minimumFlag)) || (!higher && !(wanted[v] & maximumFlag));
      };
      if (check(all, 1, 2) || (mesh.IsBoundaryVertex(v) && check(alongBoundary, 4, 8)))
      {
        return true;
      }
    }
    return false;
  };
  for (report.Rounds = 1; report.Rounds <= maximumRounds; ++report.Rounds)
  {
    if (!spuriousExtremum())
    {
      report.Converged = true;
      break;
    }
    Index changed = 0;
    if (!constraints.BoundaryMinima.empty())
    {
      changed += Sweep(constraints.BoundaryMinima, true, alongBoundary, values, visited, touched);
      reset();
    }
    if (!constraints.BoundaryMaxima.empty())
    {
      changed += Sweep(constraints.BoundaryMaxima, false, alongBoundary, values, visited, touched);
      reset();
    }
    if (!constraints.Minima.empty())
    {
      changed += Sweep(constraints.Minima, true, all, values, visited, touched);
      reset();
    }
    if (!constraints.Maxima.empty())
    {
      changed += Sweep(constraints.Maxima, false, all, values, visited, touched);
      reset();
    }
    if (changed == 0)
    {
      report.Converged = true;
      break;
    }
  }
  report.Rounds = std::min(report.Rounds, maximumRounds);
  for (Index v = 0; v < n; ++v)
  {
    if (values[v] != original[v])
    {
      ++report.ChangedVertices;
      report.MaximumChange = std::max(report.MaximumChange, std::abs(values[v] - original[v]));
    }
  }
  return report;
}
} // namespace topospline
