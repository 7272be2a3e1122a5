// Stage 1 of the paper (section 3.1): the discrete Morse-Smale complex of a PL scalar field on
// a planar triangulation: critical points, separatrices (1-cells), 2-cells, and the per-vertex
// ascending/descending manifolds that embed them.
#pragma once

#include "CoreTypes.h"
#include "DiscreteGradient.h"
#include "TriangleMeshTopology.h"

#include <array>
#include <string>
#include <vector>

namespace topospline
{
struct PlanarScalarField
{
  std::vector<double> Points;   // x, y per vertex
  std::vector<Index> Triangles; // 3 vertex ids per triangle (unused for a grid)
  std::vector<double> Values;   // one scalar per vertex
  // For a grid (image data): nx, ny with vertex (i, j) = j * nx + i, triangulated as
  // GridTriangles(nx, ny) without spelling the triangles out. {0, 0} for a general mesh.
  int GridDimensions[2] = { 0, 0 };
  bool IsGrid() const { return this->GridDimensions[0] > 1 && this->GridDimensions[1] > 1; }
};

struct CriticalPoint
{
  Index Id = InvalidIndex;      // stable id, kept through simplification
  int MorseIndex = 0;           // 0 minimum, 1 saddle, 2 maximum
  Index Vertex = InvalidIndex;  // where it sits: the highest vertex of its critical cell
  Index Cell = InvalidIndex;    // the critical vertex, edge or triangle
  double Value = 0;
  bool OnBoundary = false;     // its vertex lies on the domain boundary
};

// A separatrix between a lower-index source and a higher-index destination critical point.
// Geometry and values run from source to destination.
struct Separatrix
{
  enum Kind : int
  {
    Descending = 0, // minimum - saddle: a V-path of vertices and edges
    Ascending = 1   // saddle - maximum: a V-path of triangles and edges (through centroids)
  };
  Kind Type = Descending;
  Index Source = InvalidIndex;      // critical point id
  Index Destination = InvalidIndex; // critical point id
  std::vector<Index> MeshCells;     // vertex ids (descending) or triangle ids (ascending)
  std::vector<double> Points;       // x, y per point
  std::vector<double> Values;       // scalar per point
};

// A quad min - saddle - max - saddle; a pouch has the same saddle twice.
struct TwoCell
{
  Index Minimum = InvalidIndex;
  Index Maximum = InvalidIndex;
  std::array<Index, 2> Saddles{ InvalidIndex, InvalidIndex };
  // Per saddle k: Arcs[2k] descends to the minimum, Arcs[2k+1] ascends to the maximum.
  std::array<Index, 4> Arcs{ InvalidIndex, InvalidIndex, InvalidIndex, InvalidIndex };
  bool Pouch = false;
  Index NumberOfVertices = 0;
  double Centroid[2] = { 0, 0 };
  int Sectors = 0; // saddle sectors that open into it: 2 for a well-formed cell
};

struct MorseSmaleComplex
{
  std::vector<CriticalPoint> CriticalPoints; // sorted by (index, vertex, cell): stable ids
  std::vector<Separatrix> Separatrices;
  std::vector<TwoCell> TwoCells;
  // Per input vertex.
  std::vector<Index> AscendingManifold;  // id of the minimum it flows down to
  std::vector<Index> DescendingManifold; // id of the maximum it flows up to
  std::vector<Index> TwoCellId;
  // Vertices of boundary-curve minima that simplification cancelled with the interior saddle
  // on their own vertex (a zero-persistence pair of stage 1's boundary rule): the boundary
  // 1-cells turn inwards there. Stage 1 extracts that pair again from any field that falls
  // into the domain at such a vertex, so a topology check expects it (TopologyVerification).
  std::vector<Index> BoundaryJunctions;

  std::array<Index, 3> CountByIndex() const;
};

class MorseSmaleComplexExtraction
{
public:
  // Returns false with a message for inputs it refuses (the caller reports it).
  bool Extract(const PlanarScalarField& field, MorseSmaleComplex& complex, std::string& error);

  ParallelFor Parallel = SequentialFor;
  ProgressHooks Hooks;
  // Only the critical points (no 1-cells, 2-cells or manifolds): what a topology check needs,
  // in a fraction of the memory (samplings of tens of millions of vertices). field.Points may
  // then be empty.
  bool CriticalPointsOnly = false;
  // The field's mesh, if the caller has it already (it must be the mesh of field.Triangles or
  // of the grid, which may then be left empty); otherwise Mesh is built. Saves a second copy
  // of the largest structure.
  const TriangleMeshTopology* GivenMesh = nullptr;

  // Sorts `arcs`, 1-cells of `extremum` (descending ones for a minimum, ascending ones for a
  // maximum), counter-clockwise around it. `saddleEnds` holds, per 1-cell, the point (x, y)
  // where it ends at its saddle beyond its stored path (the saddle edge's midpoint).
  static void SortAroundExtremum(const MorseSmaleComplex& complex, const std::vector<double>& saddleEnds,
    Index extremum, std::vector<Index>& arcs);

  // Intermediate structures, kept for tests and later stages.
  TriangleMeshTopology Mesh;
  DiscreteGradient Gradient;
};
} // namespace topospline
