// Stage 4 of the paper (section 5.1): the parameterization Phi of one 2-cell onto the unit
// square. The closed boundary of the cell, sampled from its smoothed 1-cells, is triangulated
// (constrained Delaunay + Delaunay refinement that never splits the boundary, so the boundary
// vertices are exactly the samples), and every interior vertex gets (u, v) from Floater's mean
// value coordinates with the boundary fixed on the border of the square. A point location
// grid then evaluates Phi(x, y) anywhere in the cell, which is what F o Phi needs.
//
// CGAL stays in the .cxx: its meshing headers cost ~20 s per translation unit.
#pragma once

#include "CoreTypes.h"

#include <string>
#include <vector>

namespace topospline
{
// The triangulated cell and its parameterization.
struct TwoCellMesh
{
  // Vertex positions (x, y), interleaved. The first BoundaryCount vertices are the input
  // samples, in input order; the rest are interior Steiner points.
  std::vector<double> Points;
  // (u, v) per vertex, interleaved: the given values on the boundary (bit for bit), mean value
  // coordinates inside.
  std::vector<double> Parameters;
  // Vertex index triples, counter-clockwise in (x, y).
  std::vector<Index> Triangles;
  Index BoundaryCount = 0;
  // +1 if Phi preserves orientation (triangles are also counter-clockwise in (u, v)), -1 if the
  // caller's (u, v) run around the square against the polygon's orientation, so that Phi is a
  // mirror map (all triangles clockwise in (u, v)). Either way Phi is one-to-one.
  int Orientation = 1;
  // Interior points inserted at the midpoints of "dividing edges" (interior edges joining two
  // boundary vertices on the same side of the square), which would give degenerate triangles.
  int DividingEdgeFixes = 0;
  // min over triangles of Orientation * (signed area in (u, v)): > 0 proves Phi one-to-one.
  double MinimumParameterArea = 0;
  // Smallest distance of an interior vertex's (u, v) to the border of the square.
  double MinimumInteriorMargin = 0;

  Index NumberOfPoints() const { return static_cast<Index>(this->Points.size() / 2); }
  Index NumberOfTriangles() const { return static_cast<Index>(this->Triangles.size() / 3); }
};

class TwoCellParameterization
{
public:
  // Target edge length of the interior triangles. <= 0: the mean boundary sample spacing, as
  // in the paper ("size of inner triangles similar to the average sample point distance").
  double TargetEdgeLength = 0;
  // CGAL's shape bound b = sin^2(smallest angle); 0.125 ~ 20.7 degrees (CGAL's default, and
  // the largest value used: beyond it refinement need not terminate). 0: size criterion only.
  double ShapeBound = 0.125;
  // The edge length is raised where the target would need more vertices than this (a guard
  // against a tiny target on a large cell, not a quality knob).
  Index MaximumVertices = 200000;
  // Rounds of dividing-edge fixes (one round fixes every dividing edge present; refinement
  // never creates new ones, so one round normally suffices).
  int MaximumFixRounds = 8;

  // boundaryPoints: (x, y) of the n samples of the closed boundary, in order (either
  // orientation; a repeated first sample at the end is dropped). boundaryParameters: their
  // (u, v), on the border of the unit square, going monotonically once around it in the same
  // order. Returns false with a message on invalid or degenerate input (n < 4, non-finite
  // values, repeated points, self-touching or zero-area polygons such as a pouch cell's slit,
  // (u, v) off the border or not monotone) or if the map could not be made one-to-one.
  bool Parameterize(const std::vector<double>& boundaryPoints, const std::vector<double>& boundaryParameters,
    std::string& error);

  // The result of the last successful Parameterize (empty otherwise).
  const TwoCellMesh& GetMesh() const { return this->Mesh; }

  // Finds the triangle containing (x, y) and its barycentric coordinates. Points on the
  // boundary, or outside by rounding only (relative 1e-9), are found; others return false.
  bool Locate(double x, double y, Index& triangle, double barycentric[3]) const;
  // Phi(x, y): the piecewise linear parameterization at (x, y). False outside the cell.
  bool Evaluate(double x, double y, double uv[2]) const;

private:
  void BuildLocator();

  TwoCellMesh Mesh;
  // Uniform grid over the bounding box; cell c holds triangles BucketTriangles[BucketStart[c]
  // .. BucketStart[c+1]) whose bounding boxes overlap it.
  double GridOrigin[2] = { 0, 0 };
  double GridCellSize[2] = { 1, 1 };
  int GridSize[2] = { 0, 0 };
  double LocateTolerance = 0;
  std::vector<Index> BucketStart;
  std::vector<Index> BucketTriangles;
};
} // namespace topospline
