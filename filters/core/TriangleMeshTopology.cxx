#include "TriangleMeshTopology.h"

#include "DisjointSets.h"

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

void TriangleMeshTopology::BuildGrid(int nx, int ny, const ParallelFor& parallelFor)
{
  // Vertex v = (i, j) = j * nx + i; quad q = (i, j) = j * (nx - 1) + i holds triangles 2q =
  // (p00, p10, p01) and 2q + 1 = (p10, p11, p01) (GridTriangles). The edges of v towards higher
  // vertices, in increasing order of the other end: right (v + 1), the diagonal of the quad on
  // its left (v + nx - 1), up (v + nx).
  const Index nV = static_cast<Index>(nx) * ny;
  const Index quadsX = nx - 1;
  const Index nT = 2 * quadsX * (ny - 1);
  this->NumVertices = nV;
  auto has = [&](Index i, Index j, int which) {
    switch (which)
    {
      case 0:
        return i + 1 < nx;
      case 1:
        return i >= 1 && j + 1 < ny;
      default:
        return j + 1 < ny;
    }
  };
  this->EdgeOffsets.assign(nV + 1, 0);
  for (Index v = 0; v < nV; ++v)
  {
    const Index i = v % nx, j = v / nx;
    this->EdgeOffsets[v + 1] = this->EdgeOffsets[v] + has(i, j, 0) + has(i, j, 1) + has(i, j, 2);
  }
  // Id of edge `which` (0 right, 1 diagonal, 2 up) of vertex (i, j).
  auto edge = [&](Index i, Index j, int which) {
    Index local = 0;
    for (int w = 0; w < which; ++w)
    {
      local += has(i, j, w);
    }
    return this->EdgeOffsets[j * nx + i] + local;
  };
  auto triangle = [&](Index qi, Index qj, int half) { return 2 * (qj * quadsX + qi) + half; };

  const Index nE = this->EdgeOffsets[nV];
  // Every entry of these arrays is written by the parallel pass below.
  this->EdgeVertices.resize(nE);
  this->EdgeTriangles.resize(nE);
  this->BoundaryVertex.resize(nV);
  this->VertexTriangleOffsets.resize(nV + 1);
  this->VertexTriangleOffsets[0] = 0;
  for (Index v = 0; v < nV; ++v)
  {
    const Index i = v % nx, j = v / nx;
    // Triangles around (i, j), in increasing id: quads (i-1,j-1).1, (i,j-1).0, (i,j-1).1,
    // (i-1,j).0, (i-1,j).1, (i,j).0 where they exist.
    const bool left = i >= 1, right = i + 1 < nx, down = j >= 1, up = j + 1 < ny;
    this->VertexTriangleOffsets[v + 1] = this->VertexTriangleOffsets[v] + (left && down) + 2 * (right && down) +
      2 * (left && up) + (right && up);
  }
  this->VertexTriangles.resize(this->VertexTriangleOffsets[nV]);
  this->TriangleVertices.resize(nT);
  this->TriangleEdges.resize(nT);
  parallelFor(0, nV, [&](Index begin, Index end) {
    for (Index v = begin; v < end; ++v)
    {
      const Index i = v % nx, j = v / nx;
      const bool left = i >= 1, right = i + 1 < nx, down = j >= 1, up = j + 1 < ny;
      this->BoundaryVertex[v] = !(left && right && down && up);
      Index* around = &this->VertexTriangles[this->VertexTriangleOffsets[v]];
      if (left && down)
      {
        *around++ = triangle(i - 1, j - 1, 1);
      }
      if (right && down)
      {
        *around++ = triangle(i, j - 1, 0);
        *around++ = triangle(i, j - 1, 1);
      }
      if (left && up)
      {
        *around++ = triangle(i - 1, j, 0);
        *around++ = triangle(i - 1, j, 1);
      }
      if (right && up)
      {
        *around++ = triangle(i, j, 0);
      }
      // The edges of v and their triangles, lower-id triangle first.
      if (right)
      {
        const Index e = edge(i, j, 0);
        this->EdgeVertices[e] = { v, v + 1 };
        this->EdgeTriangles[e] = { down ? triangle(i, j - 1, 1) : InvalidIndex, up ? triangle(i, j, 0) : InvalidIndex };
      }
      if (left && up)
      {
        const Index e = edge(i, j, 1);
        this->EdgeVertices[e] = { v, v + nx - 1 };
        this->EdgeTriangles[e] = { triangle(i - 1, j, 0), triangle(i - 1, j, 1) };
      }
      if (up)
      {
        const Index e = edge(i, j, 2);
        this->EdgeVertices[e] = { v, v + nx };
        this->EdgeTriangles[e] = { left ? triangle(i - 1, j, 1) : InvalidIndex, right ? triangle(i, j, 0) : InvalidIndex };
      }
      // Quad (i, j)'s two triangles.
      if (right && up)
      {
        const Index p00 = v, p10 = v + 1, p01 = v + nx, p11 = v + nx + 1;
        const Index t0 = triangle(i, j, 0);
        this->TriangleVertices[t0] = { p00, p10, p01 };
        this->TriangleEdges[t0] = { edge(i, j, 0), edge(i + 1, j, 1), edge(i, j, 2) };
        this->TriangleVertices[t0 + 1] = { p10, p11, p01 };
        this->TriangleEdges[t0 + 1] = { edge(i + 1, j, 2), edge(i, j + 1, 0), edge(i + 1, j, 1) };
      }
    }
  });
  // Boundary edges have a single triangle: keep it in the first slot, as Build does.
  parallelFor(0, nE, [&](Index begin, Index end) {
    for (Index e = begin; e < end; ++e)
    {
      auto& slots = this->EdgeTriangles[e];
      if (slots[0] == InvalidIndex)
      {
        slots = { slots[1], InvalidIndex };
      }
    }
  });
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

//------------------------------------------------------------------------------
bool TriangleMeshTopology::CheckPlanarDisk(const std::vector<double>& points, std::string& error) const
{
  const Index nV = this->NumVertices;
  if (points.size() != 2 * static_cast<std::size_t>(nV))
  {
    error = "expected two coordinates per point";
    return false;
  }
  // One fan per vertex: its link is one path (boundary) or one cycle, so a boundary vertex has
  // two boundary edges and one edge more than triangles, an interior one as many as triangles.
  std::vector<Index> edges(nV, 0), boundaryEdges(nV, 0);
  UnionFind pieces(nV);
  for (Index e = 0; e < this->NumberOfEdges(); ++e)
  {
    for (const Index v : this->EdgeVertices[e])
    {
      ++edges[v];
      boundaryEdges[v] += this->IsBoundaryEdge(e) ? 1 : 0;
    }
    pieces.Union(this->EdgeVertices[e][0], this->EdgeVertices[e][1]);
  }
  for (Index v = 0; v < nV; ++v)
  {
    const Index triangles = this->VertexTriangleEnd(v) - this->VertexTriangleBegin(v);
    const bool oneFan = this->IsBoundaryVertex(v) ? boundaryEdges[v] == 2 && edges[v] == triangles + 1
                                                  : edges[v] == triangles;
    if (!oneFan)
    {
      error = "point " + std::to_string(v) + " joins several fans of triangles (a bow-tie: parts of the mesh " +
        "meet only at this point); TopoSpline needs a mesh shaped like a disk";
      return false;
    }
  }
  Index components = 0;
  for (Index v = 0; v < nV; ++v)
  {
    components += pieces.Find(v) == v ? 1 : 0;
  }
  if (components != 1)
  {
    error = "the mesh has " + std::to_string(components) + " separate pieces; TopoSpline needs one piece shaped like a disk";
    return false;
  }
  if (this->EulerCharacteristic() != 1)
  {
    error = "the mesh has " + std::to_string(1 - this->EulerCharacteristic()) +
      " hole(s) (Euler characteristic " + std::to_string(this->EulerCharacteristic()) +
      "); TopoSpline needs a mesh shaped like a disk";
    return false;
  }
  // Signed doubled area of (a, b, c).
  auto orientation = [&points](Index a, Index b, Index c) {
    return (points[2 * b] - points[2 * a]) * (points[2 * c + 1] - points[2 * a + 1]) -
      (points[2 * b + 1] - points[2 * a + 1]) * (points[2 * c] - points[2 * a]);
  };
  auto squared = [&points](Index a, Index b) {
    const double dx = points[2 * b] - points[2 * a], dy = points[2 * b + 1] - points[2 * a + 1];
    return dx * dx + dy * dy;
  };
  for (Index t = 0; t < this->NumberOfTriangles(); ++t)
  {
    const auto& v = this->TriangleVertices[t];
    const double longest = std::max({ squared(v[0], v[1]), squared(v[1], v[2]), squared(v[2], v[0]) });
    // Relative to the longest edge: a sliver this thin has no direction left in double precision.
    if (!(std::abs(orientation(v[0], v[1], v[2])) > 1e-12 * longest))
    {
      error = "triangle " + std::to_string(t) + " has zero area (its points are collinear or coincide)";
      return false;
    }
  }
  for (Index e = 0; e < this->NumberOfEdges(); ++e)
  {
    if (this->IsBoundaryEdge(e))
    {
      continue;
    }
    const Index a = this->EdgeVertices[e][0], b = this->EdgeVertices[e][1];
    const auto third = [&](Index t) {
      const auto& v = this->TriangleVertices[t];
      return v[0] != a && v[0] != b ? v[0] : (v[1] != a && v[1] != b ? v[1] : v[2]);
    };
    const Index t0 = this->EdgeTriangles[e][0], t1 = this->EdgeTriangles[e][1];
    if (!(orientation(a, b, third(t0)) * orientation(a, b, third(t1)) < 0))
    {
      error = "triangles " + std::to_string(t0) + " and " + std::to_string(t1) + " overlap: the mesh folds over " +
        "the edge of points " + std::to_string(a) + " and " + std::to_string(b);
      return false;
    }
  }
  return true;
}
} // namespace topospline
