#include "TriangleMeshTopology.h"

#include "DisjointSets.h"
#include "PlanarGeometry.h"

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

// offsets[k + 1] holds the number of items of k on entry, the first item of k + 1 on exit.
void CountsToOffsets(std::vector<Index>& offsets)
{
  for (std::size_t k = 1; k < offsets.size(); ++k)
  {
    offsets[k] += offsets[k - 1];
  }
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

//------------------------------------------------------------------------------
// The grid triangulation GridTriangles(nx, ny): vertex v = (i, j) = j * nx + i; quad q = (i, j) =
// j * (nx - 1) + i holds triangles 2q = (p00, p10, p01) and 2q + 1 = (p10, p11, p01). The edges
// of v towards higher vertices, in increasing order of the other end: right (v + 1), the
// diagonal of the quad on its left (v + nx - 1), up (v + nx).
struct TriangleMeshTopology::GridVertex
{
  Index V, I, J;
  bool Left, Right, Down, Up; // whether the grid goes on in that direction
};

struct TriangleMeshTopology::GridLayout
{
  enum EdgeDirection
  {
    RightEdge = 0,
    DiagonalEdge = 1,
    UpEdge = 2
  };

  Index Nx, Ny, QuadsX;

  GridVertex At(Index v) const
  {
    const Index i = v % this->Nx, j = v / this->Nx;
    return { v, i, j, i >= 1, i + 1 < this->Nx, j >= 1, j + 1 < this->Ny };
  }
  bool HasEdge(Index i, Index j, int which) const
  {
    switch (which)
    {
      case RightEdge:
        return i + 1 < this->Nx;
      case DiagonalEdge:
        return i >= 1 && j + 1 < this->Ny;
      default:
        return j + 1 < this->Ny;
    }
  }
  Index Triangle(Index qi, Index qj, int half) const { return 2 * (qj * this->QuadsX + qi) + half; }
};

void TriangleMeshTopology::BuildGrid(int nx, int ny, const ParallelFor& parallelFor)
{
  const GridLayout grid{ nx, ny, nx - 1 };
  const Index nV = static_cast<Index>(nx) * ny;
  const Index nT = 2 * grid.QuadsX * (ny - 1);
  this->NumVertices = nV;
  this->CountGridEdges(grid);
  this->CountGridVertexTriangles(grid);
  // Every entry of these arrays is written by the parallel pass below.
  const Index nE = this->EdgeOffsets[nV];
  this->EdgeVertices.resize(nE);
  this->EdgeTriangles.resize(nE);
  this->BoundaryVertex.resize(nV);
  this->VertexTriangles.resize(this->VertexTriangleOffsets[nV]);
  this->TriangleVertices.resize(nT);
  this->TriangleEdges.resize(nT);
  parallelFor(0, nV, [&](Index begin, Index end) {
    for (Index v = begin; v < end; ++v)
    {
      const GridVertex at = grid.At(v);
      this->BoundaryVertex[v] = !(at.Left && at.Right && at.Down && at.Up);
      this->FillGridVertexTriangles(grid, at);
      this->FillGridEdges(grid, at);
      this->FillGridQuad(grid, at);
    }
  });
  this->MoveSingleTrianglesToFirstSlot(parallelFor);
}

void TriangleMeshTopology::CountGridEdges(const GridLayout& grid)
{
  this->EdgeOffsets.assign(this->NumVertices + 1, 0);
  for (Index v = 0; v < this->NumVertices; ++v)
  {
    const GridVertex at = grid.At(v);
    this->EdgeOffsets[v + 1] = grid.HasEdge(at.I, at.J, GridLayout::RightEdge) +
      grid.HasEdge(at.I, at.J, GridLayout::DiagonalEdge) + grid.HasEdge(at.I, at.J, GridLayout::UpEdge);
  }
  CountsToOffsets(this->EdgeOffsets);
}

void TriangleMeshTopology::CountGridVertexTriangles(const GridLayout& grid)
{
  this->VertexTriangleOffsets.assign(this->NumVertices + 1, 0);
  for (Index v = 0; v < this->NumVertices; ++v)
  {
    // The triangles FillGridVertexTriangles lists.
    const GridVertex at = grid.At(v);
    this->VertexTriangleOffsets[v + 1] = (at.Left && at.Down) + 2 * (at.Right && at.Down) + 2 * (at.Left && at.Up) +
      (at.Right && at.Up);
  }
  CountsToOffsets(this->VertexTriangleOffsets);
}

// Id of edge `which` (a GridLayout::EdgeDirection) of vertex (i, j).
Index TriangleMeshTopology::GridEdge(const GridLayout& grid, Index i, Index j, int which) const
{
  Index local = 0;
  for (int w = 0; w < which; ++w)
  {
    local += grid.HasEdge(i, j, w);
  }
  return this->EdgeOffsets[j * grid.Nx + i] + local;
}

void TriangleMeshTopology::FillGridVertexTriangles(const GridLayout& grid, const GridVertex& at)
{
  // Triangles around (i, j), in increasing id: quads (i-1,j-1).1, (i,j-1).0, (i,j-1).1,
  // (i-1,j).0, (i-1,j).1, (i,j).0 where they exist.
  const Index i = at.I, j = at.J;
  Index* around = &this->VertexTriangles[this->VertexTriangleOffsets[at.V]];
  if (at.Left && at.Down)
  {
    *around++ = grid.Triangle(i - 1, j - 1, 1);
  }
  if (at.Right && at.Down)
  {
    *around++ = grid.Triangle(i, j - 1, 0);
    *around++ = grid.Triangle(i, j - 1, 1);
  }
  if (at.Left && at.Up)
  {
    *around++ = grid.Triangle(i - 1, j, 0);
    *around++ = grid.Triangle(i - 1, j, 1);
  }
  if (at.Right && at.Up)
  {
    *around++ = grid.Triangle(i, j, 0);
  }
}

// The edges of v towards higher vertices and their triangles, lower-id triangle first.
void TriangleMeshTopology::FillGridEdges(const GridLayout& grid, const GridVertex& at)
{
  const Index v = at.V, i = at.I, j = at.J;
  if (at.Right)
  {
    const Index e = this->GridEdge(grid, i, j, GridLayout::RightEdge);
    this->EdgeVertices[e] = { v, v + 1 };
    this->EdgeTriangles[e] = { at.Down ? grid.Triangle(i, j - 1, 1) : InvalidIndex,
      at.Up ? grid.Triangle(i, j, 0) : InvalidIndex };
  }
  if (at.Left && at.Up)
  {
    const Index e = this->GridEdge(grid, i, j, GridLayout::DiagonalEdge);
    this->EdgeVertices[e] = { v, v + grid.Nx - 1 };
    this->EdgeTriangles[e] = { grid.Triangle(i - 1, j, 0), grid.Triangle(i - 1, j, 1) };
  }
  if (at.Up)
  {
    const Index e = this->GridEdge(grid, i, j, GridLayout::UpEdge);
    this->EdgeVertices[e] = { v, v + grid.Nx };
    this->EdgeTriangles[e] = { at.Left ? grid.Triangle(i - 1, j, 1) : InvalidIndex,
      at.Right ? grid.Triangle(i, j, 0) : InvalidIndex };
  }
}

// The two triangles of the quad whose lower-left corner is v.
void TriangleMeshTopology::FillGridQuad(const GridLayout& grid, const GridVertex& at)
{
  if (!(at.Right && at.Up))
  {
    return;
  }
  const Index i = at.I, j = at.J;
  const Index p00 = at.V, p10 = at.V + 1, p01 = at.V + grid.Nx, p11 = at.V + grid.Nx + 1;
  const Index t0 = grid.Triangle(i, j, 0);
  this->TriangleVertices[t0] = { p00, p10, p01 };
  this->TriangleEdges[t0] = { this->GridEdge(grid, i, j, GridLayout::RightEdge),
    this->GridEdge(grid, i + 1, j, GridLayout::DiagonalEdge), this->GridEdge(grid, i, j, GridLayout::UpEdge) };
  this->TriangleVertices[t0 + 1] = { p10, p11, p01 };
  this->TriangleEdges[t0 + 1] = { this->GridEdge(grid, i + 1, j, GridLayout::UpEdge),
    this->GridEdge(grid, i, j + 1, GridLayout::RightEdge), this->GridEdge(grid, i + 1, j, GridLayout::DiagonalEdge) };
}

// Boundary edges have a single triangle: keep it in the first slot, as Build does.
void TriangleMeshTopology::MoveSingleTrianglesToFirstSlot(const ParallelFor& parallelFor)
{
  parallelFor(0, this->NumberOfEdges(), [&](Index begin, Index end) {
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

//------------------------------------------------------------------------------
bool TriangleMeshTopology::Build(Index numberOfVertices, const std::vector<Index>& triangles,
  const ParallelFor& parallelFor, std::string& error)
{
  this->NumVertices = numberOfVertices;
  if (!this->ReadTriangles(triangles, error))
  {
    return false;
  }
  this->BuildVertexTriangles();
  this->CountEdges(parallelFor);
  if (!this->NumberEdgesAndConnectTriangles(parallelFor, error))
  {
    return false;
  }
  this->FlagBoundaryVertices();
  return true;
}

bool TriangleMeshTopology::ReadTriangles(const std::vector<Index>& triangles, std::string& error)
{
  const Index nV = this->NumVertices;
  const Index nT = static_cast<Index>(triangles.size() / 3);
  this->TriangleVertices.resize(nT);
  for (Index t = 0; t < nT; ++t)
  {
    const Index a = triangles[3 * t], b = triangles[3 * t + 1], c = triangles[3 * t + 2];
    if (a < 0 || b < 0 || c < 0 || a >= nV || b >= nV || c >= nV)
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
  return true;
}

// Vertex -> triangles (counting sort: linear and deterministic).
void TriangleMeshTopology::BuildVertexTriangles()
{
  this->VertexTriangleOffsets.assign(this->NumVertices + 1, 0);
  for (const auto& tri : this->TriangleVertices)
  {
    for (Index v : tri)
    {
      ++this->VertexTriangleOffsets[v + 1];
    }
  }
  CountsToOffsets(this->VertexTriangleOffsets);
  this->VertexTriangles.resize(this->VertexTriangleOffsets[this->NumVertices]);
  std::vector<Index> cursor(this->VertexTriangleOffsets.begin(), this->VertexTriangleOffsets.end() - 1);
  for (Index t = 0; t < this->NumberOfTriangles(); ++t)
  {
    for (Index v : this->TriangleVertices[t])
    {
      this->VertexTriangles[cursor[v]++] = t;
    }
  }
}

// Edges: count the higher neighbours of every vertex, prefix-sum; NumberEdgesAndConnectTriangles
// fills them. Both passes are per-vertex, so they run in parallel and number edges identically
// on any backend.
void TriangleMeshTopology::CountEdges(const ParallelFor& parallelFor)
{
  this->EdgeOffsets.assign(this->NumVertices + 1, 0);
  parallelFor(0, this->NumVertices, [&](Index begin, Index end) {
    std::vector<Index> scratch;
    for (Index v = begin; v < end; ++v)
    {
      HigherNeighbours(*this, v, scratch);
      this->EdgeOffsets[v + 1] = static_cast<Index>(scratch.size());
    }
  });
  CountsToOffsets(this->EdgeOffsets);
}

// One pass per vertex v numbers the edges (v, w > v), and records for each of them its
// triangles and its slot in those triangles: every slot written belongs to an edge whose
// lower endpoint is v, so the tasks never write the same memory.
bool TriangleMeshTopology::NumberEdgesAndConnectTriangles(const ParallelFor& parallelFor, std::string& error)
{
  const Index nV = this->NumVertices;
  const Index nE = this->EdgeOffsets[nV];
  this->EdgeVertices.resize(nE);
  this->EdgeTriangles.assign(nE, { InvalidIndex, InvalidIndex });
  this->TriangleEdges.resize(this->NumberOfTriangles());
  std::vector<unsigned char> manifold(nV, 1);
  parallelFor(0, nV, [&](Index begin, Index end) {
    std::vector<Index> scratch;
    for (Index v = begin; v < end; ++v)
    {
      manifold[v] = this->NumberEdgesOfVertex(v, scratch) ? 1 : 0;
    }
  });
  for (Index v = 0; v < nV; ++v)
  {
    if (!manifold[v])
    {
      error = "the mesh is not a 2-manifold: an edge at point " + std::to_string(v) +
        " is shared by more than two triangles";
      return false;
    }
  }
  return true;
}

// False when an edge of v has a third triangle.
bool TriangleMeshTopology::NumberEdgesOfVertex(Index v, std::vector<Index>& scratch)
{
  HigherNeighbours(*this, v, scratch);
  const Index first = this->EdgeOffsets[v];
  for (size_t k = 0; k < scratch.size(); ++k)
  {
    this->EdgeVertices[first + k] = { v, scratch[k] };
  }
  bool manifold = true;
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
        manifold = false;
      }
    }
  }
  return manifold;
}

void TriangleMeshTopology::FlagBoundaryVertices()
{
  this->BoundaryVertex.assign(this->NumVertices, 0);
  for (Index e = 0; e < this->NumberOfEdges(); ++e)
  {
    if (this->IsBoundaryEdge(e))
    {
      this->BoundaryVertex[this->EdgeVertices[e][0]] = 1;
      this->BoundaryVertex[this->EdgeVertices[e][1]] = 1;
    }
  }
}

//------------------------------------------------------------------------------
namespace
{
// One fan per vertex: its link is one path (boundary) or one cycle, so a boundary vertex has
// two boundary edges and one edge more than triangles, an interior one as many as triangles.
bool CheckOneFanPerVertex(const TriangleMeshTopology& mesh, std::string& error)
{
  const Index nV = mesh.NumberOfVertices();
  std::vector<Index> edges(nV, 0), boundaryEdges(nV, 0);
  for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
  {
    for (const Index v : mesh.EdgeVertices[e])
    {
      ++edges[v];
      boundaryEdges[v] += mesh.IsBoundaryEdge(e) ? 1 : 0;
    }
  }
  for (Index v = 0; v < nV; ++v)
  {
    const Index triangles = mesh.VertexTriangleEnd(v) - mesh.VertexTriangleBegin(v);
    const bool oneFan =
      mesh.IsBoundaryVertex(v) ? boundaryEdges[v] == 2 && edges[v] == triangles + 1 : edges[v] == triangles;
    if (!oneFan)
    {
      error = "point " + std::to_string(v) + " joins several fans of triangles (a bow-tie: parts of the mesh " +
        "meet only at this point); TopoSpline needs a mesh shaped like a disk";
      return false;
    }
  }
  return true;
}

bool CheckOnePiece(const TriangleMeshTopology& mesh, std::string& error)
{
  const Index nV = mesh.NumberOfVertices();
  UnionFind pieces(nV);
  for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
  {
    pieces.Union(mesh.EdgeVertices[e][0], mesh.EdgeVertices[e][1]);
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
  return true;
}

bool CheckNoHole(const TriangleMeshTopology& mesh, std::string& error)
{
  if (mesh.EulerCharacteristic() != 1)
  {
    error = "the mesh has " + std::to_string(1 - mesh.EulerCharacteristic()) + " hole(s) (Euler characteristic " +
      std::to_string(mesh.EulerCharacteristic()) + "); TopoSpline needs a mesh shaped like a disk";
    return false;
  }
  return true;
}

// Signed doubled area of (a, b, c); points: x, y per vertex.
double Orientation(const std::vector<double>& points, Index a, Index b, Index c)
{
  return Orientation2D(&points[2 * a], &points[2 * b], &points[2 * c]);
}

double SquaredDistance(const std::vector<double>& points, Index a, Index b)
{
  const double dx = points[2 * b] - points[2 * a], dy = points[2 * b + 1] - points[2 * a + 1];
  return dx * dx + dy * dy;
}

bool CheckNoZeroAreaTriangle(const TriangleMeshTopology& mesh, const std::vector<double>& points, std::string& error)
{
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    const auto& v = mesh.TriangleVertices[t];
    const double longest = std::max({ SquaredDistance(points, v[0], v[1]), SquaredDistance(points, v[1], v[2]),
      SquaredDistance(points, v[2], v[0]) });
    // Relative to the longest edge: a sliver this thin has no direction left in double precision.
    if (!(std::abs(Orientation(points, v[0], v[1], v[2])) > 1e-12 * longest))
    {
      error = "triangle " + std::to_string(t) + " has zero area (its points are collinear or coincide)";
      return false;
    }
  }
  return true;
}

// The two triangles of every interior edge lie on opposite sides of it.
bool CheckNoFold(const TriangleMeshTopology& mesh, const std::vector<double>& points, std::string& error)
{
  for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
  {
    if (mesh.IsBoundaryEdge(e))
    {
      continue;
    }
    const Index a = mesh.EdgeVertices[e][0], b = mesh.EdgeVertices[e][1];
    const auto third = [&](Index t) {
      const auto& v = mesh.TriangleVertices[t];
      return v[0] != a && v[0] != b ? v[0] : (v[1] != a && v[1] != b ? v[1] : v[2]);
    };
    const Index t0 = mesh.EdgeTriangles[e][0], t1 = mesh.EdgeTriangles[e][1];
    if (!(Orientation(points, a, b, third(t0)) * Orientation(points, a, b, third(t1)) < 0))
    {
      error = "triangles " + std::to_string(t0) + " and " + std::to_string(t1) + " overlap: the mesh folds over " +
        "the edge of points " + std::to_string(a) + " and " + std::to_string(b);
      return false;
    }
  }
  return true;
}
} // namespace

bool TriangleMeshTopology::CheckPlanarDisk(const std::vector<double>& points, std::string& error) const
{
  if (points.size() != 2 * static_cast<std::size_t>(this->NumVertices))
  {
    error = "expected two coordinates per point";
    return false;
  }
  return CheckOneFanPerVertex(*this, error) && CheckOnePiece(*this, error) && CheckNoHole(*this, error) &&
    CheckNoZeroAreaTriangle(*this, points, error) && CheckNoFold(*this, points, error);
}
} // namespace topospline
