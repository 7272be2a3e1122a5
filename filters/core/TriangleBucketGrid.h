// A uniform grid of buckets over a planar triangulation, to find the triangle containing a
// point: the 2-cells' meshes (Phi and Phi^-1) and the input field between its vertices use it.
#pragma once

#include "CoreTypes.h"

#include <vector>

namespace topospline
{
// Uniform grid over the bounding box of some vertex coordinates; cell c holds the triangles
// Triangles[Start[c] .. Start[c+1]) that come within Tolerance of it. A grid of a mesh with at
// most the `scanBelow` triangles given to Build is one cell over the box that lists nothing:
// Locate then tries every triangle, in order, and finds what the buckets would find (a
// triangle within Tolerance of a point is in the point's bucket; the others lose to it).
struct TriangleBucketGrid
{
  double Origin[2] = { 0, 0 };
  double CellSize[2] = { 1, 1 };
  int Size[2] = { 0, 0 };
  double Tolerance = 0;
  bool ScanAll = false; // one cell, every triangle a candidate (Start and Triangles empty)
  std::vector<Index> Start;
  std::vector<Index> Triangles;

  // coordinates: x, y per vertex; triangles: 3 vertex ids each. With `scanBelow` > 0, a mesh of
  // at most that many triangles gets no buckets (ScanAll): the 2-cells of uniform noise have a
  // few dozen triangles each and are located a few times, and half a million of them held
  // their buckets for the whole reconstruction.
  void Build(const std::vector<double>& coordinates, const std::vector<Index>& triangles, Index scanBelow = 0);
  // The triangle in which (x, y) lies deepest, and its barycentric coordinates; orientation is
  // the sign of the triangles' areas in `coordinates` (others are skipped). False outside.
  bool Locate(const std::vector<double>& coordinates, const std::vector<Index>& triangles, int orientation, double x,
    double y, Index& triangle, double barycentric[3]) const;
};
} // namespace topospline
