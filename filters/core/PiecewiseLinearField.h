// The input field between its vertices: linear on every triangle of the input's triangulation
// (a grid's triangles as GridTriangles splits its squares). Stage 3 samples it along the
// smoothed 1-cells, through which the reconstruction passes.
#pragma once

#include "MorseSmaleComplex.h"
#include "TriangleBucketGrid.h"

#include <vector>

namespace topospline
{
class PiecewiseLinearField
{
public:
  // Keeps a reference to `field`, which must outlive this object. A mesh gets a bucket grid
  // over its triangles (a grid needs none).
  explicit PiecewiseLinearField(const PlanarScalarField& field);

  // The field at (x, y) (the field's coordinates); false outside the domain.
  bool ValueAt(double x, double y, double& value) const;

private:
  const PlanarScalarField& Field;
  // Meshes only: the triangles, each turned counter-clockwise (VTK cells may list a mesh's
  // triangles either way round), and the bucket grid over them.
  std::vector<Index> CounterClockwise;
  TriangleBucketGrid Buckets;
};
} // namespace topospline
