#include "DiscreteGradient.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>

namespace topospline
{
namespace
{
// A cell of the lower star of vertex v, described by its other vertices sorted from high to
// low: the key ProcessLowerStars orders its queues by (lexicographic, shorter first).
struct StarCell
{
  Index Id;
  std::array<Index, 2> Key; // Key[1] == InvalidIndex for edges
  bool IsEdge;
  bool Boundary;          // edges only
  std::array<int, 2> Faces; // triangles only: local indices of its two lower-star edges
  bool Paired = false;
};

struct LowerStarProcessor
{
  const TriangleMeshTopology& Mesh;
  VertexOrder Order;
  DiscreteGradient& Gradient;
  std::vector<StarCell> Edges;
  std::vector<StarCell> Triangles;
  std::vector<int> QueueZero; // local ids: edges as i, triangles as ~i
  std::vector<int> QueueOne;  // triangles (local ids)

  bool KeyLess(const std::array<Index, 2>& a, const std::array<Index, 2>& b) const
  {
    if (a[0] != b[0])
    {
      return this->Order.Lower(a[0], b[0]);
    }
    if (a[1] == b[1])
    {
      return false;
    }
    if (a[1] == InvalidIndex)
    {
      return true;
    }
    if (b[1] == InvalidIndex)
    {
      return false;
    }
    return this->Order.Lower(a[1], b[1]);
  }
  const StarCell& Cell(int local) const { return local >= 0 ? this->Edges[local] : this->Triangles[~local]; }

  // Triangles pair only with interior edges: boundary faces are not candidates.
  int UnpairedInteriorFaces(const StarCell& tri, int* lastFace) const
  {
    int count = 0;
    for (int f : tri.Faces)
    {
      const StarCell& edge = this->Edges[f];
      if (!edge.Paired && !edge.Boundary)
      {
        ++count;
        *lastFace = f;
      }
    }
    return count;
  }

  int PopMin(std::vector<int>& queue) const
  {
    auto best = queue.begin();
    for (auto it = queue.begin() + 1; it < queue.end(); ++it)
    {
      if (this->KeyLess(this->Cell(*it).Key, this->Cell(*best).Key))
      {
        best = it;
      }
    }
    const int local = *best;
    queue.erase(best);
    return local;
  }

  void PushReadyCofaces(int edgeLocal)
  {
    for (int t = 0; t < static_cast<int>(this->Triangles.size()); ++t)
    {
      const StarCell& tri = this->Triangles[t];
      if (tri.Paired || (tri.Faces[0] != edgeLocal && tri.Faces[1] != edgeLocal))
      {
        continue;
      }
      int face;
      if (this->UnpairedInteriorFaces(tri, &face) == 1 &&
        std::find(this->QueueOne.begin(), this->QueueOne.end(), t) == this->QueueOne.end())
      {
        this->QueueOne.push_back(t);
      }
    }
  }

  // The common case, a regular interior vertex: its link is a cycle and its lower link one
  // path of k vertices (k lower edges, k - 1 lower triangles). ProcessLowerStars then pairs v
  // with the steepest edge and every triangle with its face farther from that edge along the
  // path, whatever the queue order: do exactly that, without the queues.
  void ProcessRegular(Index v)
  {
    int steepest = 0;
    for (int i = 1; i < static_cast<int>(this->Edges.size()); ++i)
    {
      if (this->KeyLess(this->Edges[i].Key, this->Edges[steepest].Key))
      {
        steepest = i;
      }
    }
    this->Edges[steepest].Paired = true;
    this->Gradient.VertexEdge[v] = this->Edges[steepest].Id;
    this->Gradient.EdgeVertex[this->Edges[steepest].Id] = v;
    for (int direction = 0; direction < 2; ++direction)
    {
      int current = steepest;
      for (bool advanced = true; advanced;)
      {
        advanced = false;
        for (StarCell& tri : this->Triangles)
        {
          if (!tri.Paired && (tri.Faces[0] == current || tri.Faces[1] == current))
          {
            const int other = tri.Faces[0] == current ? tri.Faces[1] : tri.Faces[0];
            tri.Paired = true;
            this->Edges[other].Paired = true;
            this->Gradient.EdgeTriangle[this->Edges[other].Id] = tri.Id;
            this->Gradient.TriangleEdge[tri.Id] = this->Edges[other].Id;
            current = other;
            advanced = true;
            break;
          }
        }
      }
    }
  }

  // ProcessLowerStars on the lower star of v.
  void Process(Index v)
  {
    const bool boundaryVertex = this->Mesh.IsBoundaryVertex(v);
    this->CollectLowerStar(v, boundaryVertex);
    this->ClearPairings(v);
    if (!boundaryVertex && !this->Edges.empty() && this->Triangles.size() + 1 == this->Edges.size() &&
      !DiscreteGradient::GeneralPathOnly)
    {
      this->ProcessRegular(v);
      return;
    }
    this->PairWithSteepestEdge(v, boundaryVertex);
    this->PairWithQueues();
  }

  // The edges and triangles of the lower star of v, keyed by their other vertices.
  void CollectLowerStar(Index v, bool boundaryVertex)
  {
    const TriangleMeshTopology& mesh = this->Mesh;
    this->Edges.clear();
    this->Triangles.clear();
    auto localEdge = [&](Index e, Index other) {
      for (int i = 0; i < static_cast<int>(this->Edges.size()); ++i)
      {
        if (this->Edges[i].Id == e)
        {
          return i;
        }
      }
      StarCell c;
      c.Id = e;
      c.Key = { other, InvalidIndex };
      c.IsEdge = true;
      // Only a boundary vertex has boundary edges (saves a random read per edge).
      c.Boundary = boundaryVertex && mesh.IsBoundaryEdge(e);
      this->Edges.push_back(c);
      return static_cast<int>(this->Edges.size()) - 1;
    };
    for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v); ++i)
    {
      const Index t = mesh.VertexTriangle(i);
      const auto& tv = mesh.TriangleVertices[t];
      const auto& te = mesh.TriangleEdges[t];
      std::array<int, 2> faces{ -1, -1 };
      std::array<Index, 2> others{};
      int n = 0;
      for (int k = 0; k < 3; ++k)
      {
        const Index a = tv[k], b = tv[(k + 1) % 3];
        if (a != v && b != v)
        {
          continue;
        }
        const Index other = a == v ? b : a;
        if (this->Order.Lower(other, v))
        {
          faces[n] = localEdge(te[k], other);
        }
        others[n++] = other;
      }
      if (faces[0] >= 0 && faces[1] >= 0)
      {
        StarCell c;
        c.Id = t;
        c.Key = this->Order.Lower(others[0], others[1]) ? std::array<Index, 2>{ others[1], others[0] } : others;
        c.IsEdge = false;
        c.Boundary = false;
        c.Faces = faces;
        this->Triangles.push_back(c);
      }
    }
  }

  // Every cell of the lower star is initialized here (FilledByPassVector): unpaired.
  void ClearPairings(Index v)
  {
    this->Gradient.VertexEdge[v] = InvalidIndex;
    for (const StarCell& edge : this->Edges)
    {
      this->Gradient.EdgeVertex[edge.Id] = InvalidIndex;
      this->Gradient.EdgeTriangle[edge.Id] = InvalidIndex;
    }
    for (const StarCell& tri : this->Triangles)
    {
      this->Gradient.TriangleEdge[tri.Id] = InvalidIndex;
    }
  }

  // The vertex pairs with its steepest admissible lower edge (same boundary flag).
  void PairWithSteepestEdge(Index v, bool boundaryVertex)
  {
    int steepest = -1;
    for (int i = 0; i < static_cast<int>(this->Edges.size()); ++i)
    {
      if (this->Edges[i].Boundary == boundaryVertex &&
        (steepest < 0 || this->KeyLess(this->Edges[i].Key, this->Edges[steepest].Key)))
      {
        steepest = i;
      }
    }
    if (steepest >= 0)
    {
      this->Edges[steepest].Paired = true;
      this->Gradient.VertexEdge[v] = this->Edges[steepest].Id;
      this->Gradient.EdgeVertex[this->Edges[steepest].Id] = v;
    }
  }

  void PairWithQueues()
  {
    // Boundary edges cannot pair with triangles: the ones left are boundary saddles.
    // Interior edges and triangles go through the two queues of ProcessLowerStars.
    this->QueueZero.clear();
    this->QueueOne.clear();
    for (int i = 0; i < static_cast<int>(this->Edges.size()); ++i)
    {
      if (!this->Edges[i].Paired && !this->Edges[i].Boundary)
      {
        this->QueueZero.push_back(i);
      }
    }
    for (int t = 0; t < static_cast<int>(this->Triangles.size()); ++t)
    {
      int face;
      const int unpaired = this->UnpairedInteriorFaces(this->Triangles[t], &face);
      if (unpaired == 1)
      {
        this->QueueOne.push_back(t);
      }
      else if (unpaired == 0)
      {
        this->QueueZero.push_back(~t);
      }
    }
    while (!this->QueueOne.empty() || !this->QueueZero.empty())
    {
      while (!this->QueueOne.empty())
      {
        const int t = this->PopMin(this->QueueOne);
        StarCell& tri = this->Triangles[t];
        int face;
        if (this->UnpairedInteriorFaces(tri, &face) == 0)
        {
          this->QueueZero.push_back(~t);
          continue;
        }
        StarCell& edge = this->Edges[face];
        edge.Paired = true;
        tri.Paired = true;
        this->Gradient.EdgeTriangle[edge.Id] = tri.Id;
        this->Gradient.TriangleEdge[tri.Id] = edge.Id;
        this->QueueZero.erase(std::remove(this->QueueZero.begin(), this->QueueZero.end(), face), this->QueueZero.end());
        this->PushReadyCofaces(face);
      }
      if (!this->QueueZero.empty())
      {
        const int critical = this->PopMin(this->QueueZero);
        if (critical >= 0)
        {
          // A critical (saddle) edge: stays unpaired; its cofaces may now be ready.
          this->Edges[critical].Paired = true;
          this->PushReadyCofaces(critical);
        }
        else
        {
          this->Triangles[~critical].Paired = true; // a maximum
        }
      }
    }
  }
};
} // namespace

bool DiscreteGradient::GeneralPathOnly = false;

Index DiscreteGradient::EdgeOwner(const TriangleMeshTopology& mesh, const VertexOrder& order, Index e)
{
  const auto& ev = mesh.EdgeVertices[e];
  return order.Lower(ev[0], ev[1]) ? ev[1] : ev[0];
}

Index DiscreteGradient::TriangleOwner(const TriangleMeshTopology& mesh, const VertexOrder& order, Index t)
{
  const auto& tv = mesh.TriangleVertices[t];
  Index best = tv[0];
  for (int k = 1; k < 3; ++k)
  {
    if (order.Lower(best, tv[k]))
    {
      best = tv[k];
    }
  }
  return best;
}

void DiscreteGradient::Compute(const TriangleMeshTopology& mesh, const double* values, const ParallelFor& parallelFor)
{
  // No fill here: each lower star sets its own cells (every cell is in exactly one).
  this->VertexEdge.resize(mesh.NumberOfVertices());
  this->EdgeVertex.resize(mesh.NumberOfEdges());
  this->EdgeTriangle.resize(mesh.NumberOfEdges());
  this->TriangleEdge.resize(mesh.NumberOfTriangles());
  // Each lower star owns its cells, so the per-vertex tasks write disjoint slots.
  parallelFor(0, mesh.NumberOfVertices(), [&](Index begin, Index end) {
    LowerStarProcessor processor{ mesh, VertexOrder{ values }, *this, {}, {}, {}, {} };
    for (Index v = begin; v < end; ++v)
    {
      processor.Process(v);
    }
  });
}

LowerStarCriticalCells DiscreteGradient::CriticalCellsOfLowerStar(
  const TriangleMeshTopology& mesh, const double* values, Index v)
{
  const VertexOrder order{ values };
  LowerStarCriticalCells cells;
  const Index triangles = mesh.VertexTriangleEnd(v) - mesh.VertexTriangleBegin(v);
  // Per triangle (v, a, b): its lower link vertices a, b (an interior edge of v is in two
  // triangles, a boundary edge in one), whether both are lower (a lower link edge), and the
  // lower ends of v's boundary edges.
  Index lowerEnds = 0, lowerLinkEdges = 0, boundaryEnds = 0;
  for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v); ++i)
  {
    const Index t = mesh.VertexTriangle(i);
    const auto& tv = mesh.TriangleVertices[t];
    const auto& te = mesh.TriangleEdges[t];
    int lower = 0;
    for (int k = 0; k < 3; ++k)
    {
      const Index a = tv[k], b = tv[(k + 1) % 3];
      if (a != v && b != v)
      {
        continue;
      }
      const bool below = order.Lower(a == v ? b : a, v);
      lower += below ? 1 : 0;
      if (mesh.IsBoundaryEdge(te[k]))
      {
        boundaryEnds += below ? 1 : 0;
      }
    }
    lowerEnds += lower;
    lowerLinkEdges += lower == 2 ? 1 : 0;
  }
  const Index lowerLinkVertices = (lowerEnds + boundaryEnds) / 2;
  const Index runs = lowerLinkVertices - lowerLinkEdges; // the lower link is a forest of paths
  const bool boundary = mesh.IsBoundaryVertex(v);
  // The vertex pairs with a lower edge of its own kind (a boundary vertex with a boundary edge).
  cells.Minimum = boundary ? boundaryEnds == 0 : lowerLinkVertices == 0;
  // Triangles pair with interior edges only: one is left when the whole star is lower.
  cells.Maximum = triangles > 0 && lowerLinkEdges == triangles;
  if (!boundary)
  {
    // A minimum (no run), a maximum (the whole cycle) or runs - 1 saddles.
    cells.Saddles = lowerLinkVertices > 0 && lowerLinkEdges < triangles ? static_cast<int>(runs - 1) : 0;
  }
  else if (lowerLinkEdges == triangles)
  {
    cells.Saddles = 1; // the whole link: a maximum inside and a saddle along the boundary curve
  }
  else
  {
    // Runs that reach a boundary neighbour pair from its boundary edge; with both
    // boundary neighbours lower, v pairs with one boundary edge and the other is a saddle.
    cells.Saddles = static_cast<int>(runs - boundaryEnds + (boundaryEnds == 2 ? 1 : 0));
  }
  return cells;
}

namespace
{
// Every vertex's saddle multiplicity (its lower star's critical edges); false on a non-finite
// value or a vertex in no triangle, as Compute's callers fail.
bool SaddleMultiplicities(const TriangleMeshTopology& mesh, const double* values, const ParallelFor& parallelFor,
  std::vector<unsigned char>& multiplicity)
{
  const Index n = mesh.NumberOfVertices();
  multiplicity.assign(static_cast<std::size_t>(n), 0);
  std::atomic<bool> valid(true);
  parallelFor(0, n, [&](Index begin, Index end) {
    for (Index v = begin; v < end; ++v)
    {
      if (!std::isfinite(values[v]) || mesh.VertexTriangleEnd(v) == mesh.VertexTriangleBegin(v))
      {
        valid = false;
        return;
      }
      multiplicity[v] =
        static_cast<unsigned char>(DiscreteGradient::CriticalCellsOfLowerStar(mesh, values, v).Saddles);
    }
  });
  return valid;
}

// The saddle vertices in increasing order, each as often as its multiplicity.
void ListSaddles(const std::vector<unsigned char>& multiplicity, std::vector<Index>& saddles)
{
  saddles.clear();
  for (std::size_t v = 0; v < multiplicity.size(); ++v)
  {
    saddles.insert(saddles.end(), multiplicity[v], static_cast<Index>(v));
  }
}
} // namespace

bool DiscreteGradient::SaddleVertices(const TriangleMeshTopology& mesh, const double* values,
  const ParallelFor& parallelFor, std::vector<Index>& saddles)
{
  std::vector<unsigned char> multiplicity;
  if (!SaddleMultiplicities(mesh, values, parallelFor, multiplicity))
  {
    saddles.clear();
    return false;
  }
  ListSaddles(multiplicity, saddles);
  return true;
}

SaddleVertexCount::SaddleVertexCount(const TriangleMeshTopology& mesh, const ParallelFor& parallelFor)
  : Mesh(mesh)
  , Parallel(parallelFor)
{
}

bool SaddleVertexCount::Count(const std::vector<double>& values, std::vector<Index>& saddles)
{
  const Index n = this->Mesh.NumberOfVertices();
  if (this->Counted.size() != values.size())
  {
    if (!SaddleMultiplicities(this->Mesh, values.data(), this->Parallel, this->Multiplicity))
    {
      this->Multiplicity.clear();
      saddles.clear();
      return false;
    }
    this->Counted = values;
    ListSaddles(this->Multiplicity, saddles);
    return true;
  }
  const auto differs = [](double a, double b) { return std::memcmp(&a, &b, sizeof(double)) != 0; };
  const std::vector<Index> changed =
    CollectInStretches<Index>(n, Index(1) << 16, this->Parallel, [&](Index v, std::vector<Index>& list) {
      if (differs(values[v], this->Counted[v]))
      {
        list.push_back(v);
      }
    });
  for (Index c : changed)
  {
    if (!std::isfinite(values[c]))
    {
      return false; // as SaddleVertices; the last count stays the reference
    }
  }
  // The changed vertices and their links: the lower stars whose lower links can differ.
  std::vector<Index> stars;
  this->Stale.resize(static_cast<std::size_t>(n), 0);
  for (Index c : changed)
  {
    for (Index i = this->Mesh.VertexTriangleBegin(c); i < this->Mesh.VertexTriangleEnd(c); ++i)
    {
      for (Index w : this->Mesh.TriangleVertices[this->Mesh.VertexTriangle(i)])
      {
        if (!this->Stale[w])
        {
          this->Stale[w] = 1;
          stars.push_back(w);
        }
      }
    }
  }
  this->Parallel(0, static_cast<Index>(stars.size()), [&](Index begin, Index end) {
    for (Index k = begin; k < end; ++k)
    {
      const Index v = stars[k];
      this->Multiplicity[v] =
        static_cast<unsigned char>(DiscreteGradient::CriticalCellsOfLowerStar(this->Mesh, values.data(), v).Saddles);
    }
  });
  for (Index v : stars)
  {
    this->Stale[v] = 0;
  }
  for (Index c : changed)
  {
    this->Counted[c] = values[c];
  }
  ListSaddles(this->Multiplicity, saddles);
  return true;
}
} // namespace topospline
