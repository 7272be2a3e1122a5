// Edge and incidence structure of a planar triangulation, built once per input and shared by
// the discrete gradient, the 1-cell tracing and the segmentation.
#pragma once

#include "CoreTypes.h"

#include <array>
#include <string>
#include <vector>

namespace topospline
{
class TriangleMeshTopology
{
public:
  // triangles: 3 vertex ids per triangle. Returns false and fills `error` for meshes the
  // Morse-Smale machinery cannot handle (degenerate triangles, edges with 3+ triangles).
  bool Build(Index numberOfVertices, const std::vector<Index>& triangles, const ParallelFor& parallelFor,
    std::string& error);

  // After Build, on a mesh whose every point is in a triangle (MorseSmaleComplexExtraction
  // checks that first): false with `error` unless the mesh is a planar disk as the complex needs it:
  // one fan of triangles around every vertex (no bow-tie), one piece without holes (Euler
  // characteristic 1), no zero-area triangle, and no fold (the two triangles of every
  // interior edge on opposite sides of it). points: x, y per vertex.
  bool CheckPlanarDisk(const std::vector<double>& points, std::string& error) const;

  // The same structure, numbered exactly as Build(nx * ny, GridTriangles(nx, ny)) numbers it,
  // written in closed form: no searching or sorting. For image data.
  void BuildGrid(int nx, int ny, const ParallelFor& parallelFor);

  Index NumberOfVertices() const { return this->NumVertices; }
  Index NumberOfEdges() const { return static_cast<Index>(this->EdgeVertices.size()); }
  Index NumberOfTriangles() const { return static_cast<Index>(this->TriangleVertices.size()); }

  bool IsBoundaryEdge(Index e) const { return this->EdgeTriangles[e][1] == InvalidIndex; }
  bool IsBoundaryVertex(Index v) const { return this->BoundaryVertex[v] != 0; }
  Index OtherEdgeVertex(Index e, Index v) const
  {
    return this->EdgeVertices[e][0] == v ? this->EdgeVertices[e][1] : this->EdgeVertices[e][0];
  }
  Index OtherEdgeTriangle(Index e, Index t) const
  {
    return this->EdgeTriangles[e][0] == t ? this->EdgeTriangles[e][1] : this->EdgeTriangles[e][0];
  }
  // Triangles incident to vertex v: [VertexTriangles + begin, + end).
  Index VertexTriangleBegin(Index v) const { return this->VertexTriangleOffsets[v]; }
  Index VertexTriangleEnd(Index v) const { return this->VertexTriangleOffsets[v + 1]; }
  Index VertexTriangle(Index i) const { return this->VertexTriangles[i]; }
  // Edge joining a and b, or InvalidIndex.
  Index FindEdge(Index a, Index b) const;
  // The Euler characteristic V - E + T: 1 for a disk.
  long long EulerCharacteristic() const
  {
    return static_cast<long long>(this->NumVertices) - this->NumberOfEdges() + this->NumberOfTriangles();
  }

  FilledByPassVector<std::array<Index, 3>> TriangleVertices;
  FilledByPassVector<std::array<Index, 3>> TriangleEdges; // edges (v0v1, v1v2, v2v0)
  FilledByPassVector<std::array<Index, 2>> EdgeVertices;  // sorted: [0] < [1]
  FilledByPassVector<std::array<Index, 2>> EdgeTriangles; // [1] == InvalidIndex on the domain boundary
  FilledByPassVector<unsigned char> BoundaryVertex;

private:
  // Build's steps, in order.
  bool ReadTriangles(const std::vector<Index>& triangles, std::string& error);
  void BuildVertexTriangles();
  void CountEdges(const ParallelFor& parallelFor);
  bool NumberEdgesAndConnectTriangles(const ParallelFor& parallelFor, std::string& error);
  bool NumberEdgesOfVertex(Index v, std::vector<Index>& scratch);
  void FlagBoundaryVertices();

  // BuildGrid's steps (GridLayout and GridVertex are defined in the .cxx).
  struct GridLayout;
  struct GridVertex;
  void CountGridEdges(const GridLayout& grid);
  void CountGridVertexTriangles(const GridLayout& grid);
  Index GridEdge(const GridLayout& grid, Index i, Index j, int which) const;
  void FillGridVertexTriangles(const GridLayout& grid, const GridVertex& at);
  void FillGridEdges(const GridLayout& grid, const GridVertex& at);
  void FillGridQuad(const GridLayout& grid, const GridVertex& at);
  void MoveSingleTrianglesToFirstSlot(const ParallelFor& parallelFor);

  Index NumVertices = 0;
  std::vector<Index> VertexTriangleOffsets;
  FilledByPassVector<Index> VertexTriangles;
  // Edges (v, w) with w > v are numbered consecutively per v: [EdgeOffsets[v], EdgeOffsets[v+1]).
  std::vector<Index> EdgeOffsets;
};
} // namespace topospline
