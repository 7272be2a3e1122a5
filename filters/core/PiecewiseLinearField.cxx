#include "PiecewiseLinearField.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace topospline
{
PiecewiseLinearField::PiecewiseLinearField(const PlanarScalarField& field)
  : Field(field)
{
  if (field.IsGrid() || field.Triangles.size() < 3)
  {
    return;
  }
  this->CounterClockwise = field.Triangles;
  for (std::size_t t = 0; t + 2 < this->CounterClockwise.size(); t += 3)
  {
    Index* corners = &this->CounterClockwise[t];
    const double* a = &field.Points[2 * corners[0]];
    const double* b = &field.Points[2 * corners[1]];
    const double* c = &field.Points[2 * corners[2]];
    if ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0)
    {
      std::swap(corners[1], corners[2]);
    }
  }
  this->Buckets.Build(field.Points, this->CounterClockwise);
}

bool PiecewiseLinearField::ValueAt(double x, double y, double& value) const
{
  const PlanarScalarField& f = this->Field;
  if (!std::isfinite(x) || !std::isfinite(y))
  {
    return false;
  }
  if (!f.IsGrid())
  {
    Index triangle;
    double barycentric[3];
    if (this->CounterClockwise.empty() ||
      !this->Buckets.Locate(f.Points, this->CounterClockwise, 1, x, y, triangle, barycentric))
    {
      return false;
    }
    const Index* corners = &this->CounterClockwise[3 * triangle];
    value = barycentric[0] * f.Values[corners[0]] + barycentric[1] * f.Values[corners[1]] +
      barycentric[2] * f.Values[corners[2]];
    return true;
  }
  const int nx = f.GridDimensions[0], ny = f.GridDimensions[1];
  const double fx = (x - f.Points[0]) / f.GridSpacing[0];
  const double fy = (y - f.Points[1]) / f.GridSpacing[1];
  const double slack = 1e-9;
  if (!(fx >= -slack && fy >= -slack && fx <= nx - 1 + slack && fy <= ny - 1 + slack))
  {
    return false;
  }
  const int i = std::min(std::max(static_cast<int>(std::floor(fx)), 0), nx - 2);
  const int j = std::min(std::max(static_cast<int>(std::floor(fy)), 0), ny - 2);
  const double a = fx - i, b = fy - j;
  const double* v = f.Values.data();
  const std::size_t corner = static_cast<std::size_t>(j) * nx + i;
  const double v00 = v[corner], v10 = v[corner + 1], v01 = v[corner + nx], v11 = v[corner + nx + 1];
  // GridTriangles splits each square along its (i+1, j)-(i, j+1) diagonal.
  value = a + b <= 1 ? v00 + a * (v10 - v00) + b * (v01 - v00) : v11 + (1 - a) * (v01 - v11) + (1 - b) * (v10 - v11);
  return true;
}
} // namespace topospline
