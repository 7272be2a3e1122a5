// The data every stage shares: the scalar field on its planar triangulation, the Morse-Smale
// complex stage 1 extracts and stage 2 simplifies (critical points, 1-cells, 2-cells and the
// per-vertex segmentation), and the junction points where 1-cells sharing an extremum merge,
// which stage 3 cuts them at. The algorithms live in the headers named after the stages.
#pragma once

#include "CoreTypes.h"
#include "PlanarGeometry.h"

#include <array>
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
  // For a grid: the distance between neighbouring vertices along each axis.
  double GridSpacing[2] = { 0, 0 };
  bool IsGrid() const { return this->GridDimensions[0] > 1 && this->GridDimensions[1] > 1; }
};

// Values that vary, but by less than this fraction of their magnitude (a field of 1 + 1e-13
// noise), are too close for what stages 3 and 4 need: values that rise strictly along every
// 1-cell with room between them in double precision (JunctionValueProgram's spreading, 1e-11
// of the magnitude, would dwarf such a field's own variation and leave 2-cells whose sides do
// not join). Stage 1 reads such a field as the constant it is within that precision.
constexpr double NearConstantRange = 1e-9;
// Whether values from `lowest` to `highest`, of largest magnitude `magnitude`, vary by less
// than NearConstantRange of it (and vary at all).
inline bool VariesByLessThanPrecision(double lowest, double highest, double magnitude)
{
  return highest > lowest && highest - lowest < NearConstantRange * magnitude;
}

struct CriticalPoint
{
  Index Id = InvalidIndex;      // stable id, kept through simplification
  int MorseIndex = 0;           // 0 minimum, 1 saddle, 2 maximum
  Index Vertex = InvalidIndex;  // where it sits: the highest vertex of its critical cell
  Index Cell = InvalidIndex;    // the critical vertex, edge or triangle
  double Value = 0;
  bool OnBoundary = false;     // its vertex lies on the domain boundary
  // A saddle's: the other (lower) vertex of its critical edge. Stage 2 draws a merged ascending
  // 1-cell across the edge of a cancelled saddle through the edge's midpoint (triangle meshes).
  Index EdgeVertex = InvalidIndex;
  // A maximum's: its triangle is the only one at its vertex (two corners of a grid, an ear of a
  // mesh's hull). Such a vertex above both of its neighbours is a boundary saddle and this
  // maximum at once in any sampling, so stage 2 keeps the maximum while that saddle lies
  // between two minima (MorseSmaleComplexSimplification::KeepsCornerMaximum).
  bool CornerTriangle = false;
};

// A 1-cell between a lower-index source and a higher-index destination critical point.
// Geometry and values run from source to destination.
struct OneCell
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
  // Per saddle k: BoundaryOneCells[2k] descends to the minimum, BoundaryOneCells[2k+1] ascends to the maximum.
  std::array<Index, 4> BoundaryOneCells{ InvalidIndex, InvalidIndex, InvalidIndex, InvalidIndex };
  bool Pouch = false;
  Index NumberOfVertices = 0;
  double Centroid[2] = { 0, 0 };
  int Sectors = 0; // saddle sectors that open into it: 2 for a well-formed cell
};

struct MorseSmaleComplex
{
  std::vector<CriticalPoint> CriticalPoints; // sorted by (index, vertex, cell): stable ids
  std::vector<OneCell> OneCells;
  std::vector<TwoCell> TwoCells;
  // Per input vertex.
  std::vector<Index> AscendingManifold;  // id of the minimum it flows down to
  std::vector<Index> DescendingManifold; // id of the maximum it flows up to
  std::vector<Index> TwoCellId;
  // Vertices of the boundary curve, on no critical point, where descending 1-cells come down
  // the curve from both sides and turn inwards (set by simplification from the 1-cells'
  // routes; boundary minima cancelled with the interior saddle on their own vertex start out
  // as such). Every monotone reconstruction falls into the domain there, and stage 1 extracts a
  // minimum and a saddle on such a vertex, so a topology check expects them
  // (TopologyVerification).
  std::vector<Index> BoundaryJunctions;
  // The coordinates stages 3 and 4 work in (PlanarFrame): set by stage 1 from the domain's
  // edges, kept by simplification.
  PlanarFrame Frame;

  std::array<Index, 3> CountByIndex() const
  {
    std::array<Index, 3> counts{ 0, 0, 0 };
    for (const auto& cp : this->CriticalPoints)
    {
      ++counts[cp.MorseIndex];
    }
    return counts;
  }
};

// A vertex (descending 1-cells) or triangle (ascending 1-cells) where 1-cells that share an
// extremum split apart when followed from the extremum towards their saddles (equivalently:
// merge when followed from the saddles). Stage 3 cuts 1-cells into pieces at these points.
struct JunctionPoint
{
  OneCell::Kind Type = OneCell::Descending; // Cell is a vertex (Descending) or a triangle
  Index Extremum = InvalidIndex;      // position in the output CriticalPoints
  Index Cell = InvalidIndex;
  double Position[2] = { 0, 0 };      // the vertex, or the triangle's centroid
  double Value = 0;                   // f at the vertex, or the mean of the triangle's values
  // Position of a saddle sitting on this vertex whose descending 1-cell ends here while
  // others go on (the junction is then also that critical point), else InvalidIndex.
  Index CriticalPoint = InvalidIndex;
  std::vector<Index> OneCells;    // output 1-cells through it, ascending order
};

// Maps the complex's geometry (1-cell points, 2-cell centroids) from the domain's coordinates
// into `frame`.
inline void GeometryToFrame(const PlanarFrame& frame, MorseSmaleComplex& complex)
{
  for (OneCell& oneCell : complex.OneCells)
  {
    frame.ToFrame(oneCell.Points);
  }
  for (TwoCell& twoCell : complex.TwoCells)
  {
    frame.ToFrame(twoCell.Centroid);
  }
}

} // namespace topospline
