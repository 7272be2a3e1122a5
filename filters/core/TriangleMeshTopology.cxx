#include "TriangleMeshTopology.h"

#include <algorithm>

namespace topospline
{
namespace
{
// Higher-numbered neighbours of v (from its incident triangles), sorted and unique.
template <typename Container>
void HigherNeighbours(const TriangleMeshTopology& mesh, Index v, Container& out)
{
  out.clear();
  for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v); ++i)
  {
    for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
    {
      if (w > v)
      {
        out.push_back(w);
      }
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}
} // namespace

Index TriangleMeshTopology::FindEdge(Index a, Index b) const
{
  if (a > b)
  {
    std::swap(a, b);
  }
  for (Index e = this->EdgeOffsets[a]; e < this->EdgeOffsets[a + 1]; ++e)
  {
    if (this->EdgeVertices[e][1] == b)
    {
      return e;
    }
  }
  return InvalidIndex;
}

bool TriangleMeshTopology::Build(Index numberOfVertices, const std::vector<Index>& triangles,
  const ParallelFor& parallelFor, std::string& error)
{
  const Index nT = static_cast<Index>(triangles.size() / 3);
  this->NumVertices = numberOfVertices;
  this->TriangleVertices.resize(nT);
  for (Index t = 0; t < nT; ++t)
  {
    const Index a = triangles[3 * t], b = triangles[3 * t + 1], c = triangles[3 * t + 2];
    if (a < 0 || b < 0 || c < 0 || a >= numberOfVertices || b >= numberOfVertices || c >= numberOfVertices)
    {
      error = "triangle " + std::to_string(t) + " references a vertex that does not exist";
      return false;
    }
    if (a == b || b == c || a == c)
    {
      error = "triangle " + std::to_string(t) + " is degenerate (repeated vertex " + std::to_string(a == b ? a : c) + ")";
      return false;
    }
    this->TriangleVertices[t] = { a, b, c };
  }

  // Vertex -> triangles (counting sort: linear and deterministic).
  this->VertexTriangleOffsets.assign(numberOfVertices + 1, 0);
  for (const auto& tri : this->TriangleVertices)
  {
    for (Index v : tri)
    {
      ++this->VertexTriangleOffsets[v + 1];
    }
  }
  for (Index v = 0; v < numberOfVertices; ++v)
  {
    this->VertexTriangleOffsets[v + 1] += this->VertexTriangleOffsets[v];
  }
  this->VertexTriangles.resize(this->VertexTriangleOffsets[numberOfVertices]);
  {
    std::vector<Index> cursor(this->VertexTriangleOffsets.begin(), this->VertexTriangleOffsets.end() - 1);
    for (Index t = 0; t < nT; ++t)
    {
      for (Index v : this->TriangleVertices[t])
      {
        this->VertexTriangles[cursor[v]++] = t;
      }
    }
  }

  // Edges: count the higher neighbours of every vertex, prefix-sum, then fill. Both passes
  // are per-vertex, so they run in parallel and number edges identically on any backend.
  this->EdgeOffsets.assign(numberOfVertices + 1, 0);
  parallelFor(0, numberOfVertices, [&](Index begin, Index end) {
    std::vector<Index> scratch;
    for (Index v = begin; v < end; ++v)
    {
      HigherNeighbours(*this, v, scratch);
      this->EdgeOffsets[v + 1] = static_cast<Index>(scratch.size());
    }
  });
  for (Index v = 0; v < numberOfVertices; ++v)
  {
    this->EdgeOffsets[v + 1] += this->EdgeOffsets[v];
  }
  const Index nE = this->EdgeOffsets[numberOfVertices];
  this->EdgeVertices.resize(nE);
  this->EdgeTriangles.assign(nE, { InvalidIndex, InvalidIndex });
  this->TriangleEdges.resize(nT);
  // One pass per vertex v numbers the edges (v, w > v), and records for each of them its
  // triangles and its slot in those triangles: every slot written belongs to an edge whose
  // lower endpoint is v, so the tasks never write the same memory.
  std::vector<unsigned char> manifold(numberOfVertices, 1);
  parallelFor(0, numberOfVertices, [&](Index begin, Index end) {
    std::vector<Index> scratch;
    for (Index v = begin; v < end; ++v)
    {
      HigherNeighbours(*this, v, scratch);
      const Index first = this->EdgeOffsets[v];
      for (size_t k = 0; k < scratch.size(); ++k)
      {
        this->EdgeVertices[first + k] = { v, scratch[k] };
      }
      for (Index i = this->VertexTriangleOffsets[v]; i < this->VertexTriangleOffsets[v + 1]; ++i)
      {
        const Index t = this->VertexTriangles[i];
        const auto& tv = this->TriangleVertices[t];
        for (int k = 0; k < 3; ++k)
        {
          const Index a = tv[k], b = tv[(k + 1) % 3];
          if (std::min(a, b) != v)
          {
            continue;
          }
          const Index w = std::max(a, b);
          const Index e = first + static_cast<Index>(std::lower_bound(scratch.begin(), scratch.end(), w) - scratch.begin());
          this->TriangleEdges[t][k] = e;
          auto& slots = this->EdgeTriangles[e];
          if (slots[0] == InvalidIndex)
          {
            slots[0] = t;
          }
          else if (slots[1] == InvalidIndex)
          {
            slots[1] = t;
          }
          else
          {
            manifold[v] = 0;
          }
        }
      }
    }
  });
  for (Index v = 0; v < numberOfVertices; ++v)
  {
    if (!manifold[v])
    {
      error = "the mesh is not a 2-manifold: an edge at point " + std::to_string(v) +
        " is shared by more than two triangles";
      return false;
    }
  }

  this->BoundaryVertex.assign(numberOfVertices, 0);
  for (Index e = 0; e < nE; ++e)
  {
    if (this->IsBoundaryEdge(e))
    {
      this->BoundaryVertex[this->EdgeVertices[e][0]] = 1;
      this->BoundaryVertex[this->EdgeVertices[e][1]] = 1;
    }
  }
  return true;
}
} // namespace topospline
