// What several core tests share: grid fields as triangle meshes, a ParallelFor over real
// threads, and the real stages 1-3 run on a synthetic grid (what the stage-4 tests start from).
#pragma once

#include "CoreTypes.h"
#include "MorseSmaleComplex.h"
#include "MorseSmaleComplexExtraction.h"
#include "MorseSmaleComplexSimplification.h"
#include "OneCellSmoothing.h"
#include "SyntheticFields.h"

#include <algorithm>
#include <string>
#include <thread>
#include <vector>

namespace topospline
{
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

struct Pipeline
{
  PlanarScalarField Field;
  MorseSmaleComplex Input;
  SimplificationOutput Simplified;
  OneCellSmoothingResult Smoothed;
  double Bounds[4] = { 0, 0, 0, 0 };
  double Range = 0;
};

inline bool RunStages1To3(const GridField& grid, double percent, int k, Pipeline& p, std::string& error)
{
  p.Field = FieldOnGrid(grid);
  MorseSmaleComplexExtraction extraction;
  MorseSmaleComplexSimplification simplification;
  if (!extraction.Extract(p.Field, p.Input, error) || !simplification.ComputeHierarchy(p.Input, error) ||
    !simplification.Simplify(percent, p.Simplified, error))
  {
    return false;
  }
  const auto [lo, hi] = std::minmax_element(grid.Values.begin(), grid.Values.end());
  p.Range = *hi - *lo;
  p.Bounds[0] = grid.Origin[0];
  p.Bounds[1] = grid.Origin[0] + (grid.Dimensions[0] - 1) * grid.Spacing[0];
  p.Bounds[2] = grid.Origin[1];
  p.Bounds[3] = grid.Origin[1] + (grid.Dimensions[1] - 1) * grid.Spacing[1];
  OneCellSmoothing smoothing;
  smoothing.Segments = k;
  return smoothing.Smooth(p.Simplified.Complex, p.Simplified.JunctionPoints, p.Bounds, p.Smoothed, error);
}
} // namespace topospline
