// What several core tests share: grid fields as triangle meshes, Delaunay meshes of random
// points, a segment-crossing predicate and the crossing segment pairs of polylines, a
// ParallelFor over real threads, and the real stages 1-3 run on a synthetic grid or mesh (what
// the stage-4 tests start from).
#pragma once

#include "CoreTypes.h"
#include "DeterministicRandom.h"
#include "MorseSmaleComplex.h"
#include "MorseSmaleComplexExtraction.h"
#include "MorseSmaleComplexSimplification.h"
#include "OneCellSmoothing.h"
#include "SyntheticFields.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace topospline
{
// Whether segments a-b and c-d cross at one point inside both (the tests' own predicate, by the
// signs of exact-enough orientations; touching, collinear or shared ends do not count).
inline bool SegmentsCrossProperlyInTest(const double* a, const double* b, const double* c, const double* d)
{
  const auto orient = [](const double* o, const double* p, const double* q) {
    const double s = (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0]);
    return (s > 0) - (s < 0);
  };
  return orient(a, b, c) * orient(a, b, d) < 0 && orient(c, d, a) * orient(c, d, b) < 0;
}

// The pairs of segments of polylines (x, y per point) that cross properly, each segment as its
// end coordinates in a fixed order, so a segment shared by two polylines is one (pairs of one
// polyline count, but not two segments that follow each other). Found pair by pair within
// overlapping boxes.
using TestSegment = std::array<double, 4>;
inline std::set<std::pair<TestSegment, TestSegment>> CrossingSegmentPairs(
  const std::vector<const std::vector<double>*>& lines)
{
  const auto undirected = [](const double* a, const double* b) {
    const TestSegment s{ a[0], a[1], b[0], b[1] }, t{ b[0], b[1], a[0], a[1] };
    return std::min(s, t);
  };
  std::set<std::pair<TestSegment, TestSegment>> pairs;
  std::vector<std::array<double, 4>> boxes(lines.size(), { 1e300, -1e300, 1e300, -1e300 });
  for (std::size_t p = 0; p < lines.size(); ++p)
  {
    const std::vector<double>& q = *lines[p];
    for (std::size_t i = 0; i + 1 < q.size(); i += 2)
    {
      boxes[p] = { std::min(boxes[p][0], q[i]), std::max(boxes[p][1], q[i]), std::min(boxes[p][2], q[i + 1]),
        std::max(boxes[p][3], q[i + 1]) };
    }
  }
  for (std::size_t p = 0; p < lines.size(); ++p)
  {
    const std::vector<double>& a = *lines[p];
    for (std::size_t q = p; q < lines.size(); ++q)
    {
      if (boxes[p][0] > boxes[q][1] || boxes[q][0] > boxes[p][1] || boxes[p][2] > boxes[q][3] ||
        boxes[q][2] > boxes[p][3])
      {
        continue;
      }
      const std::vector<double>& b = *lines[q];
      for (std::size_t i = 0; i + 3 < a.size(); i += 2)
      {
        for (std::size_t j = p == q ? i + 4 : 0; j + 3 < b.size(); j += 2)
        {
          if (SegmentsCrossProperlyInTest(&a[i], &a[i + 2], &b[j], &b[j + 2]))
          {
            const TestSegment s = undirected(&a[i], &a[i + 2]), t = undirected(&b[j], &b[j + 2]);
            pairs.insert({ std::min(s, t), std::max(s, t) });
          }
        }
      }
    }
  }
  return pairs;
}

// The grid with its triangles spelled out (GridTriangles), so that the stages take the general
// triangle-mesh path instead of the grid's closed forms.
inline PlanarScalarField MeshFieldOnGrid(const GridField& grid)
{
  PlanarScalarField field = FieldOnGrid(grid);
  field.Triangles = GridTriangles(grid.Dimensions[0], grid.Dimensions[1]);
  field.GridDimensions[0] = field.GridDimensions[1] = 0;
  return field;
}

// Runs body on `threads` contiguous chunks of [begin, end), each on its own thread.
inline void ThreadedFor(Index begin, Index end, const RangeBody& body)
{
  const Index threads = 4;
  std::vector<std::thread> pool;
  const Index chunk = std::max<Index>(1, (end - begin + threads - 1) / threads);
  for (Index b = begin; b < end; b += chunk)
  {
    pool.emplace_back([&body, b, end, chunk]() { body(b, std::min(end, b + chunk)); });
  }
  for (auto& thread : pool)
  {
    thread.join();
  }
}

// Uniform noise in [0, 1) on an n x n grid (DeterministicRandom: the same on every platform).
inline GridField UniformNoise(int n, std::uint64_t seed)
{
  GridField grid;
  grid.Dimensions[0] = grid.Dimensions[1] = n;
  DeterministicRandom random(seed);
  for (int v = 0; v < n * n; ++v)
  {
    grid.Values.push_back(random.Uniform());
  }
  return grid;
}

struct Pipeline
{
  PlanarScalarField Field;
  MorseSmaleComplex Input;
  SimplificationOutput Simplified;
  OneCellSmoothingResult Smoothed;
  double Bounds[4] = { 0, 0, 0, 0 };
  double Range = 0;
  bool ReadAsConstant = false; // stage 1 read a near-constant field as constant
};

// Stages 1-3 on any planar field (a grid's or a triangle mesh's): the domain's bounds are
// the points' bounding box. `nearConstantAsConstant`: stage 1 as the filter runs it
// (MorseSmaleComplexExtraction::NearConstantAsConstant).
// `meshCorners`: on a triangle mesh, the boundary vertices nearest the bounds' corners are the
// domain's corners, as the filter takes them (OneCellSmoothing::BoundaryPoints).
inline bool RunStages1To3(const PlanarScalarField& field, double percent, int k, Pipeline& p, std::string& error,
  bool nearConstantAsConstant = false, bool meshCorners = false)
{
  p.Field = field;
  MorseSmaleComplexExtraction extraction;
  extraction.NearConstantAsConstant = nearConstantAsConstant;
  MorseSmaleComplexSimplification simplification;
  const bool extracted = extraction.Extract(p.Field, p.Input, error);
  p.ReadAsConstant = extraction.ReadAsConstant;
  if (!extracted || !simplification.ComputeHierarchy(p.Input, error) ||
    !simplification.Simplify(percent, p.Simplified, error))
  {
    return false;
  }
  const auto [lo, hi] = std::minmax_element(field.Values.begin(), field.Values.end());
  p.Range = *hi - *lo;
  p.Bounds[0] = p.Bounds[2] = std::numeric_limits<double>::infinity();
  p.Bounds[1] = p.Bounds[3] = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < field.Points.size(); i += 2)
  {
    for (int axis = 0; axis < 2; ++axis)
    {
      p.Bounds[2 * axis] = std::min(p.Bounds[2 * axis], field.Points[i + axis]);
      p.Bounds[2 * axis + 1] = std::max(p.Bounds[2 * axis + 1], field.Points[i + axis]);
    }
  }
  OneCellSmoothing smoothing;
  smoothing.Segments = k;
  if (meshCorners && !field.IsGrid())
  {
    smoothing.BoundaryPoints = OneCellSmoothing::BoundaryPointsOf(field);
  }
  return smoothing.Smooth(p.Simplified.Complex, p.Simplified.JunctionPoints, p.Bounds, p.Smoothed, error);
}

inline bool RunStages1To3(const GridField& grid, double percent, int k, Pipeline& p, std::string& error,
  bool nearConstantAsConstant = false)
{
  return RunStages1To3(FieldOnGrid(grid), percent, k, p, error, nearConstantAsConstant);
}

// The Delaunay triangulation of `points` (x, y pairs, in general position), counter-clockwise
// (Bowyer-Watson, quadratic: for test meshes of a few hundred points).
inline std::vector<Index> DelaunayTriangles(const std::vector<double>& points)
{
  const Index n = static_cast<Index>(points.size() / 2);
  std::vector<double> p = points;
  // A super-triangle far around the points.
  p.insert(p.end(), { -1e3, -1e3, 1e3, -1e3, 0, 1e3 });
  std::vector<std::array<Index, 3>> triangles = { { n, n + 1, n + 2 } };
  const auto inCircumcircle = [&p](const std::array<Index, 3>& t, Index q) {
    const double* a = &p[2 * t[0]];
    const double* b = &p[2 * t[1]];
    const double* c = &p[2 * t[2]];
    const double ax = a[0] - p[2 * q], ay = a[1] - p[2 * q + 1];
    const double bx = b[0] - p[2 * q], by = b[1] - p[2 * q + 1];
    const double cx = c[0] - p[2 * q], cy = c[1] - p[2 * q + 1];
    return (ax * ax + ay * ay) * (bx * cy - cx * by) - (bx * bx + by * by) * (ax * cy - cx * ay) +
        (cx * cx + cy * cy) * (ax * by - bx * ay) > 0;
  };
  for (Index q = 0; q < n; ++q)
  {
    std::vector<std::array<Index, 3>> kept;
    std::map<std::pair<Index, Index>, int> edges; // directed edges of the removed triangles
    for (const auto& t : triangles)
    {
      if (inCircumcircle(t, q))
      {
        for (int k = 0; k < 3; ++k)
        {
          ++edges[{ t[k], t[(k + 1) % 3] }];
        }
      }
      else
      {
        kept.push_back(t);
      }
    }
    // The cavity's border: edges whose reverse was not removed too.
    for (const auto& e : edges)
    {
      if (edges.count({ e.first.second, e.first.first }) == 0)
      {
        kept.push_back({ e.first.first, e.first.second, q });
      }
    }
    triangles.swap(kept);
  }
  std::vector<Index> result;
  for (const auto& t : triangles)
  {
    if (t[0] < n && t[1] < n && t[2] < n)
    {
      result.insert(result.end(), t.begin(), t.end());
    }
  }
  return result;
}

// The stress test's "delaunay" kind in small: `points` uniform random points in the unit
// square, triangulated by DelaunayTriangles, with a wavy field plus 20 % noise.
inline PlanarScalarField RandomDelaunayField(std::uint64_t seed, int points)
{
  DeterministicRandom random(seed);
  PlanarScalarField field;
  for (int k = 0; k < points; ++k)
  {
    const double x = random.Uniform(), y = random.Uniform();
    field.Points.insert(field.Points.end(), { x, y });
    field.Values.push_back(std::sin(6 * x) * std::cos(5 * y) + 0.2 * random.Uniform());
  }
  field.Triangles = DelaunayTriangles(field.Points);
  return field;
}

} // namespace topospline
