#include "SyntheticFields.h"

#include "DeterministicRandom.h"

#include <cmath>

namespace topospline
{
GridField ShepardField(int sites, double power, int resolution, std::uint64_t seed, const ParallelFor& parallelFor)
{
  GridField grid;
  grid.Dimensions[0] = grid.Dimensions[1] = resolution;
  grid.Values.assign(static_cast<size_t>(resolution) * resolution, 0.0);
  DeterministicRandom random(seed);
  const double extent = resolution - 1;
  std::vector<double> sx(sites), sy(sites), sv(sites);
  for (int k = 0; k < sites; ++k)
  {
    sx[k] = random.Uniform() * extent;
    sy[k] = random.Uniform() * extent;
    sv[k] = random.Uniform();
  }
  const double halfPower = 0.5 * power;
  parallelFor(0, resolution, [&](Index begin, Index end) {
    for (Index j = begin; j < end; ++j)
    {
      for (int i = 0; i < resolution; ++i)
      {
        double numerator = 0, denominator = 0, exact = -1;
        for (int k = 0; k < sites && exact < 0; ++k)
        {
          const double d2 = (i - sx[k]) * (i - sx[k]) + (j - sy[k]) * (j - sy[k]);
          if (d2 == 0)
          {
            exact = sv[k];
            break;
          }
          const double w = power == 2 ? 1.0 / d2 : std::pow(d2, -halfPower);
          numerator += w * sv[k];
          denominator += w;
        }
        grid.Values[static_cast<size_t>(j) * resolution + i] = exact >= 0 ? exact : numerator / denominator;
      }
    }
  });
  return grid;
}

GridField TrigonometricField(double amplitude, int resolution, double origin)
{
  GridField grid;
  grid.Dimensions[0] = grid.Dimensions[1] = resolution;
  grid.Origin[0] = grid.Origin[1] = origin;
  grid.Values.resize(static_cast<size_t>(resolution) * resolution);
  for (int j = 0; j < resolution; ++j)
  {
    for (int i = 0; i < resolution; ++i)
    {
      const double x = origin + i, y = origin + j;
      grid.Values[static_cast<size_t>(j) * resolution + i] =
        amplitude * std::sin(x / amplitude) * std::sin(y / amplitude);
    }
  }
  return grid;
}

std::vector<Index> GridTriangles(int nx, int ny)
{
  std::vector<Index> triangles;
  if (nx < 2 || ny < 2)
  {
    return triangles;
  }
  triangles.reserve(6 * static_cast<size_t>(nx - 1) * (ny - 1));
  for (int j = 0; j + 1 < ny; ++j)
  {
    for (int i = 0; i + 1 < nx; ++i)
    {
      const Index p00 = j * nx + i, p10 = p00 + 1, p01 = p00 + nx, p11 = p01 + 1;
      triangles.insert(triangles.end(), { p00, p10, p01, p10, p11, p01 });
    }
  }
  return triangles;
}
PlanarScalarField FieldOnGrid(const GridField& grid)
{
  PlanarScalarField field;
  const int nx = grid.Dimensions[0], ny = grid.Dimensions[1];
  field.GridDimensions[0] = nx;
  field.GridDimensions[1] = ny;
  field.GridSpacing[0] = grid.Spacing[0];
  field.GridSpacing[1] = grid.Spacing[1];
  field.Points.resize(2 * static_cast<std::size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i)
    {
      field.Points[2 * (static_cast<std::size_t>(j) * nx + i)] = grid.Origin[0] + i * grid.Spacing[0];
      field.Points[2 * (static_cast<std::size_t>(j) * nx + i) + 1] = grid.Origin[1] + j * grid.Spacing[1];
    }
  }
  field.Values = grid.Values;
  return field;
}
} // namespace topospline
