#include "TriangleBucketGrid.h"

#include "PlanarGeometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace topospline
{
void TriangleBucketGrid::Build(
  const std::vector<double>& coordinates, const std::vector<Index>& triangleList, Index scanBelow)
{
  TriangleBucketGrid& grid = *this;
  grid.ScanAll = false;
  grid.Start.clear();
  grid.Triangles.clear();
  const Index points = static_cast<Index>(coordinates.size() / 2);
  const Index triangles = static_cast<Index>(triangleList.size() / 3);
  double bounds[4] = { coordinates[0], coordinates[0], coordinates[1], coordinates[1] };
  for (Index i = 0; i < points; ++i)
  {
    bounds[0] = std::min(bounds[0], coordinates[2 * i]);
    bounds[1] = std::max(bounds[1], coordinates[2 * i]);
    bounds[2] = std::min(bounds[2], coordinates[2 * i + 1]);
    bounds[3] = std::max(bounds[3], coordinates[2 * i + 1]);
  }
  const double width = std::max(bounds[1] - bounds[0], 1e-300);
  const double height = std::max(bounds[3] - bounds[2], 1e-300);
  grid.Tolerance = 1e-9 * std::max(width, height);
  // About one triangle per grid cell, cells roughly square, at most 1024 a side (thin cells
  // get a thin grid).
  const double cellSize = std::sqrt(width * height / std::max<Index>(triangles, 1));
  grid.ScanAll = triangles <= scanBelow;
  for (int d = 0; d < 2; ++d)
  {
    const double extent = d == 0 ? width : height;
    grid.Size[d] = grid.ScanAll ? 1 : static_cast<int>(std::min(1024.0, std::max(1.0, std::ceil(extent / cellSize))));
    grid.Origin[d] = bounds[2 * d] - grid.Tolerance;
    grid.CellSize[d] = (extent + 2 * grid.Tolerance) / grid.Size[d];
  }
  if (grid.ScanAll)
  {
    return;
  }
  auto cellOf = [&grid](double value, int d) {
    const double c = std::floor((value - grid.Origin[d]) / grid.CellSize[d]);
    return static_cast<int>(std::min<double>(std::max(c, 0.0), grid.Size[d] - 1));
  };
  // Whether a triangle comes within the grid's tolerance of a grid cell (separating axes: the
  // cell's own axes are the caller's bounding-box range, the triangle's edge normals are tested
  // here). A long sliver across the parameter square has a bounding box of hundreds of cells
  // but meets a few dozen: bucketing by the box alone put 200 triangles in a typical cell of a
  // Delaunay-mesh 2-cell, and locating points took 65 % of stage 4 there.
  auto triangleMeetsCell = [&grid, &coordinates](const Index* tri, int cx, int cy) {
    const double x0 = grid.Origin[0] + cx * grid.CellSize[0] - grid.Tolerance;
    const double x1 = grid.Origin[0] + (cx + 1) * grid.CellSize[0] + grid.Tolerance;
    const double y0 = grid.Origin[1] + cy * grid.CellSize[1] - grid.Tolerance;
    const double y1 = grid.Origin[1] + (cy + 1) * grid.CellSize[1] + grid.Tolerance;
    for (int e = 0; e < 3; ++e)
    {
      const double* a = &coordinates[2 * tri[e]];
      const double* b = &coordinates[2 * tri[(e + 1) % 3]];
      const double* c = &coordinates[2 * tri[(e + 2) % 3]];
      const double nx = a[1] - b[1], ny = b[0] - a[0];
      const double edge = nx * a[0] + ny * a[1];
      const double opposite = nx * c[0] + ny * c[1];
      const double lo = std::min(edge, opposite), hi = std::max(edge, opposite);
      const double corners[4] = { nx * x0 + ny * y0, nx * x1 + ny * y0, nx * x0 + ny * y1, nx * x1 + ny * y1 };
      const double boxLo = *std::min_element(corners, corners + 4), boxHi = *std::max_element(corners, corners + 4);
      // Rounding of the projections, relative to their size: never separate by less.
      const double slack = 1e-12 * (std::abs(lo) + std::abs(hi) + std::abs(boxLo) + std::abs(boxHi));
      if (boxHi < lo - slack || boxLo > hi + slack)
      {
        return false;
      }
    }
    return true;
  };
  const std::size_t cells = static_cast<std::size_t>(grid.Size[0]) * grid.Size[1];
  std::vector<int> ranges(4 * static_cast<std::size_t>(triangles));
  grid.Start.assign(cells + 1, 0);
  for (int pass = 0; pass < 2; ++pass)
  {
    std::vector<Index> fill;
    if (pass == 1)
    {
      for (std::size_t c = 0; c < cells; ++c)
      {
        grid.Start[c + 1] += grid.Start[c];
      }
      grid.Triangles.resize(grid.Start[cells]);
      fill.assign(grid.Start.begin(), grid.Start.end() - 1);
    }
    for (Index t = 0; t < triangles; ++t)
    {
      int* range = &ranges[4 * t];
      if (pass == 0)
      {
        const Index* tri = &triangleList[3 * t];
        for (int d = 0; d < 2; ++d)
        {
          double lo = coordinates[2 * tri[0] + d], hi = lo;
          for (int k = 1; k < 3; ++k)
          {
            lo = std::min(lo, coordinates[2 * tri[k] + d]);
            hi = std::max(hi, coordinates[2 * tri[k] + d]);
          }
          range[2 * d] = cellOf(lo - grid.Tolerance, d);
          range[2 * d + 1] = cellOf(hi + grid.Tolerance, d);
        }
      }
      const bool boxOnly = range[1] - range[0] < 2 || range[3] - range[2] < 2;
      for (int cy = range[2]; cy <= range[3]; ++cy)
      {
        for (int cx = range[0]; cx <= range[1]; ++cx)
        {
          if (!boxOnly && !triangleMeetsCell(&triangleList[3 * t], cx, cy))
          {
            continue;
          }
          const std::size_t c = static_cast<std::size_t>(cy) * grid.Size[0] + cx;
          if (pass == 0)
          {
            ++grid.Start[c + 1];
          }
          else
          {
            grid.Triangles[fill[c]++] = t;
          }
        }
      }
    }
  }
}

namespace
{
double DistanceToSegment(double x, double y, const double* a, const double* b)
{
  double fraction;
  return std::sqrt(SegmentDistance2(a, b, x, y, fraction));
}

// For a point outside the triangle.
double DistanceToTriangle(double x, double y, const double* a, const double* b, const double* c)
{
  return std::min(DistanceToSegment(x, y, a, b), std::min(DistanceToSegment(x, y, b, c), DistanceToSegment(x, y, c, a)));
}
} // namespace

bool TriangleBucketGrid::Locate(const std::vector<double>& coordinates, const std::vector<Index>& triangleList,
  int orientation, double x, double y, Index& triangle, double barycentric[3]) const
{
  const TriangleBucketGrid& grid = *this;
  triangle = InvalidIndex;
  if (grid.Size[0] == 0 || !std::isfinite(x) || !std::isfinite(y))
  {
    return false;
  }
  const double position[2] = { x, y };
  int cell[2];
  for (int d = 0; d < 2; ++d)
  {
    const double c = std::floor((position[d] - grid.Origin[d]) / grid.CellSize[d]);
    if (c < 0 || c >= grid.Size[d])
    {
      return false;
    }
    cell[d] = static_cast<int>(c);
  }
  const std::size_t c = static_cast<std::size_t>(cell[1]) * grid.Size[0] + cell[0];
  const Index first = grid.ScanAll ? 0 : grid.Start[c];
  const Index last = grid.ScanAll ? static_cast<Index>(triangleList.size() / 3) : grid.Start[c + 1];
  // The triangle in which (x, y) is deepest (largest smallest barycentric coordinate, scaled
  // to a distance) wins, so that points on shared edges get a definite answer.
  double best = -std::numeric_limits<double>::infinity();
  for (Index k = first; k < last; ++k)
  {
    const Index t = grid.ScanAll ? k : grid.Triangles[k];
    const Index* tri = &triangleList[3 * t];
    const double* a = &coordinates[2 * tri[0]];
    const double* b = &coordinates[2 * tri[1]];
    const double* q = &coordinates[2 * tri[2]];
    const double twiceArea = (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0]);
    if (!(orientation * twiceArea > 0))
    {
      continue;
    }
    // Twice the signed areas of the sub-triangles (x, y) + edge, each from its own cross
    // product: at a vertex two are exactly 0, which 1 - l0 - l1 would not give on a sliver.
    double lambda[3];
    lambda[0] = (b[0] - x) * (q[1] - y) - (b[1] - y) * (q[0] - x);
    lambda[1] = (q[0] - x) * (a[1] - y) - (q[1] - y) * (a[0] - x);
    lambda[2] = (a[0] - x) * (b[1] - y) - (a[1] - y) * (b[0] - x);
    const double sum = lambda[0] + lambda[1] + lambda[2];
    if (!(orientation * sum > 0))
    {
      continue;
    }
    if (orientation * lambda[0] > 0 && orientation * lambda[1] > 0 && orientation * lambda[2] > 0)
    {
      // Strictly inside: no other triangle of a valid mesh contains the point, no need to
      // compare depths (this is the common case, so it comes first).
      for (int k2 = 0; k2 < 3; ++k2)
      {
        barycentric[k2] = lambda[k2] / sum;
      }
      triangle = t;
      return true;
    }
    // Sub-area over the opposite edge length = signed distance to that edge's line.
    auto length = [](const double* u, const double* w) {
      return std::sqrt((u[0] - w[0]) * (u[0] - w[0]) + (u[1] - w[1]) * (u[1] - w[1]));
    };
    const double edges[3] = { length(q, b), length(a, q), length(b, a) };
    double depth = std::numeric_limits<double>::infinity();
    for (int k2 = 0; k2 < 3; ++k2)
    {
      depth = std::min(depth, orientation * lambda[k2] / edges[k2]);
      lambda[k2] /= sum;
    }
    if (depth < 0)
    {
      // Outside. The distances to the edge *lines* only bound the distance to the triangle
      // from below: a point far beyond the sharp tip of a sliver is nearly on both long edge
      // lines. Candidates that can still win are scored by the true distance.
      if (depth < -grid.Tolerance || depth <= best)
      {
        continue;
      }
      depth = -DistanceToTriangle(x, y, a, b, q);
    }
    if (depth > best)
    {
      best = depth;
      triangle = t;
      std::copy(lambda, lambda + 3, barycentric);
    }
  }
  if (triangle == InvalidIndex || best < -grid.Tolerance)
  {
    triangle = InvalidIndex;
    return false;
  }
  // Rounding may leave a coordinate slightly negative: clamp so the result stays in the
  // triangle's image.
  double sum = 0;
  for (int k = 0; k < 3; ++k)
  {
    barycentric[k] = std::max(barycentric[k], 0.0);
    sum += barycentric[k];
  }
  for (int k = 0; k < 3; ++k)
  {
    barycentric[k] /= sum;
  }
  return true;
}
} // namespace topospline
