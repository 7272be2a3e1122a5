// What several core tests share: a grid field as the core's planar scalar field, and a
// ParallelFor over real threads.
#pragma once

#include "CoreTypes.h"
#include "MorseSmaleComplex.h"
#include "SyntheticFields.h"

#include <algorithm>
#include <thread>
#include <vector>

namespace topospline
{
// The grid's points with its origin and spacing, x fastest, as a structured grid (triangulated
// by the stages that need triangles).
inline PlanarScalarField StructuredFieldFromGrid(const GridField& grid)
{
  PlanarScalarField field;
  const int nx = grid.Dimensions[0], ny = grid.Dimensions[1];
  field.GridDimensions[0] = nx;
  field.GridDimensions[1] = ny;
  field.Points.resize(2 * static_cast<std::size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i)
    {
      field.Points[2 * (j * nx + i)] = grid.Origin[0] + i * grid.Spacing[0];
      field.Points[2 * (j * nx + i) + 1] = grid.Origin[1] + j * grid.Spacing[1];
    }
  }
  field.Values = grid.Values;
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
} // namespace topospline
