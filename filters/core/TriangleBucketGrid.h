// A uniform grid of buckets over a planar triangulation, to find the triangle containing a
// point: the 2-cells' meshes (Phi and Phi^-1) and the input field between its vertices use it.
#pragma once

#include "CoreTypes.h"

#include <vector>

namespace topospline
{
// Uniform grid over the bounding box of some vertex coordinates; cell c holds the triangles
// Triangles[Start[c] .. Start[c+1]) that come within Tolerance of it.
struct TriangleBucketGrid
{
  double Origin[2] = { 0, 0 };
  double CellSize[2] = { 1, 1 };
  int Size[2] = { 0, 0 };
  double Tolerance = 0;
  std::vector<Index> Start;
  std::vector<Index> Triangles;

  // coordinates: x, y per vertex; triangles: 3 vertex ids each.
  void Build(const std::vector<double>& coordinates, const std::vector<Index>& triangles);
  // The triangle in which (x, y) lies deepest, and its barycentric coordinates; orientation is
  // the sign of the triangles' areas in `coordinates` (others are skipped). False outside.
  bool Locate(const std::vector<double>& coordinates, const std::vector<Index>& triangles, int orientation, double x,
    double y, Index& triangle, double barycentric[3]) const;
};
} // namespace topospline
