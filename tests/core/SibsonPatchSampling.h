// Sampling of Sibson patches and their triangles, shared by the patch and surface tests.
#pragma once

#include "MonotoneSibsonPatch.h"

#include <algorithm>
#include <limits>

namespace topospline_test
{
// D_(1,1)F sampled densely over the open cell: a regular grid, both diagonals, the lines
// through the centre, and points close to the corners and edges (down to `closest`). Returns
// the minimum. Where a cell only just satisfies the conditions, D_(1,1)F near a corner can be
// of the order of the squared distance times a tiny coefficient, below double rounding; the
// positivity tests therefore stop at 1e-6 from the boundary, the violation search goes closer.
inline double MinimumDiagonalDerivative(const topospline::MonotoneSibsonPatch& patch, double closest = 1e-6)
{
  double minimum = std::numeric_limits<double>::infinity();
  auto sample = [&](double X, double Y) {
    double value, gradient[2];
    patch.EvaluateWithGradient(X, Y, value, gradient);
    minimum = std::min(minimum, gradient[0] + gradient[1]);
  };
  const int n = 40;
  for (int a = 1; a < n; ++a)
  {
    const double t = static_cast<double>(a) / n;
    for (int b = 1; b < n; ++b)
    {
      sample(t, static_cast<double>(b) / n);
    }
    sample(t, t);
    sample(t, 1 - t);
  }
  for (double e : { closest, 1e-3, 1e-2, 3e-2 })
  {
    for (int a = 1; a < n; ++a)
    {
      const double t = static_cast<double>(a) / n;
      sample(t, e);
      sample(t, 1 - e);
      sample(e, t);
      sample(1 - e, t);
    }
    sample(e, e);
    sample(1 - e, e);
    sample(e, 1 - e);
    sample(1 - e, 1 - e);
    sample(e, 2 * e);
    sample(1 - e, 2 * e);
    sample(2 * e, 1 - e);
    sample(1 - 2 * e, 1 - e);
  }
  return minimum;
}

// Uniformly distributed barycentric coordinates of a point of a triangle.
template <typename Random>
void RandomBarycentric(Random& random, double& l0, double& l1, double& l2)
{
  l1 = random.Uniform();
  l2 = random.Uniform();
  if (l1 + l2 > 1)
  {
    l1 = 1 - l1;
    l2 = 1 - l2;
  }
  l0 = 1 - l1 - l2;
}
} // namespace topospline_test
