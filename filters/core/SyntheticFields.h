// The paper's two synthetic inputs (section 6), as plain grids of values.
#pragma once

#include "CoreTypes.h"
#include "MorseSmaleComplex.h"

#include <cstdint>
#include <vector>

namespace topospline
{
struct GridField
{
  int Dimensions[2] = { 0, 0 };
  double Origin[2] = { 0, 0 };
  double Spacing[2] = { 1, 1 };
  std::vector<double> Values; // x fastest
};

// Shepard's inverse-distance interpolant F_mu(x) = sum f_k |x-x_k|^-mu / sum |x-x_j|^-mu of
// `sites` random sites (uniform in the grid's extent) with random values in [0, 1], sampled on
// a resolution x resolution grid of spacing 1 starting at the origin. Same seed, same field,
// on every platform (the generator is written out, not taken from <random>'s distributions).
GridField ShepardField(int sites, double power, int resolution, std::uint64_t seed,
  const ParallelFor& parallelFor = SequentialFor);

// a * sin(x/a) * sin(y/a) on a resolution x resolution grid of spacing 1 from (origin, origin).
// The paper's example: a = 10, 100 samples from -49.
GridField TrigonometricField(double amplitude, int resolution, double origin);

// The grid as the field the stages take (vertex (i, j) at Origin + (i, j) * Spacing).
PlanarScalarField FieldOnGrid(const GridField& grid);

// Splits every grid quad along its (i+1,j)-(i,j+1) diagonal, the triangulation used for
// image data throughout (and by the data catalog's critical-point counts).
std::vector<Index> GridTriangles(int nx, int ny);
} // namespace topospline
