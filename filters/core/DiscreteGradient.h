// Forman discrete gradient of a PL scalar field on a planar triangulation, by Robins, Wood and
// Sheppard's ProcessLowerStars (PAMI 2011), one independent lower star per vertex.
//
// Domain boundary rule (Shivashankar et al.): boundary cells pair only with boundary cells.
// A boundary vertex pairs only with a boundary edge, and a triangle never pairs with a
// boundary edge. Consequences, which the rest of the pipeline relies on:
//  * every V-path that starts on the boundary curve stays on it, so the domain boundary is a
//    union of descending 1-cells (boundary saddle -> boundary minimum);
//  * no ascending V-path (triangle -> edge -> triangle) can leave the domain, so every
//    triangle reaches a maximum inside and every 2-cell is closed by 1-cells.
// The price: every local extremum of the field restricted to the boundary curve is a
// critical point of the complex (see docs/ for the discussion of the paper's trig example).
#pragma once

#include "CoreTypes.h"
#include "TriangleMeshTopology.h"

#include <vector>

namespace topospline
{
// Strict total order on vertices: by value, ties broken by vertex id (simulation of
// simplicity), so plateaus are handled consistently.
struct VertexOrder
{
  const double* Values;
  bool Lower(Index a, Index b) const
  {
    return this->Values[a] < this->Values[b] || (this->Values[a] == this->Values[b] && a < b);
  }
};

// The critical cells ProcessLowerStars leaves in one vertex's lower star: where stage 1 puts a
// minimum (the vertex), saddles (edges, with multiplicity) and a maximum (a triangle).
struct LowerStarCriticalCells
{
  bool Minimum = false;
  int Saddles = 0;
  bool Maximum = false;
  bool operator==(const LowerStarCriticalCells& o) const
  {
    return this->Minimum == o.Minimum && this->Saddles == o.Saddles && this->Maximum == o.Maximum;
  }
};

class DiscreteGradient
{
public:
  void Compute(const TriangleMeshTopology& mesh, const double* values, const ParallelFor& parallelFor);

  // Pairings; InvalidIndex means "not paired by this relation".
  // Every cell lies in exactly one lower star, which initializes and fills its entries.
  FilledByPassVector<Index> VertexEdge;   // vertex -> paired edge
  FilledByPassVector<Index> EdgeVertex;   // edge -> paired vertex
  FilledByPassVector<Index> EdgeTriangle; // edge -> paired triangle
  FilledByPassVector<Index> TriangleEdge; // triangle -> paired edge

  bool IsCriticalVertex(Index v) const { return this->VertexEdge[v] == InvalidIndex; }
  bool IsCriticalEdge(Index e) const
  {
    return this->EdgeVertex[e] == InvalidIndex && this->EdgeTriangle[e] == InvalidIndex;
  }
  bool IsCriticalTriangle(Index t) const { return this->TriangleEdge[t] == InvalidIndex; }

  // Tests only: process every lower star with the general queues (no fast path for regular
  // interior vertices), to show both give the same gradient.
  static bool GeneralPathOnly;

  // The vertices of the critical edges (saddles) that Compute gives for `values`, with
  // multiplicity and in increasing order, without computing the gradient: counted from each
  // vertex's lower link. Per lower star, ProcessLowerStars leaves one critical edge for each run
  // of lower link vertices but the one it starts from; with the boundary rule a boundary
  // vertex starts from a lower boundary edge, runs that reach a boundary neighbour are paired
  // from its boundary edge, every other run leaves one, and with both boundary neighbours lower
  // the second boundary edge is one (TestDiscreteGradient compares both on random fields).
  // Topological sampling matches saddles after each of its trials: on 4 million vertices this
  // takes a tenth of the time of a gradient. False, as Compute's callers fail, on a non-finite
  // value or a vertex in no triangle.
  static bool SaddleVertices(const TriangleMeshTopology& mesh, const double* values, const ParallelFor& parallelFor,
    std::vector<Index>& saddles);
  // The critical cells of v's lower star as Compute leaves them, counted from its lower link
  // alone (the saddles as SaddleVertices counts them; a boundary vertex is a minimum when no
  // boundary neighbour is lower, a maximum with a saddle when its whole link is). Values must
  // be finite around v.
  static LowerStarCriticalCells CriticalCellsOfLowerStar(const TriangleMeshTopology& mesh, const double* values, Index v);

  // The vertex whose lower star holds the cell (its highest vertex): where a critical cell
  // is placed in the domain.
  static Index EdgeOwner(const TriangleMeshTopology& mesh, const VertexOrder& order, Index e);
  static Index TriangleOwner(const TriangleMeshTopology& mesh, const VertexOrder& order, Index t);
};

// DiscreteGradient::SaddleVertices for value arrays on one mesh that differ in a few vertices
// from one count to the next (topological sampling's relocation rounds change a few hundred
// vertices of a million): after a count that succeeded, only the lower stars a changed value
// can change are counted again, those of the vertices whose value differs bit for bit from that
// count's and of their neighbours. The same saddles as SaddleVertices, and false where it is.
class SaddleVertexCount
{
public:
  SaddleVertexCount(const TriangleMeshTopology& mesh, const ParallelFor& parallelFor);
  bool Count(const std::vector<double>& values, std::vector<Index>& saddles);

private:
  const TriangleMeshTopology& Mesh;
  const ParallelFor Parallel;
  std::vector<double> Counted;             // the values of the last count that succeeded
  std::vector<unsigned char> Multiplicity; // its saddles per vertex
  std::vector<char> Stale;                 // scratch: the lower stars to count again
};
} // namespace topospline
