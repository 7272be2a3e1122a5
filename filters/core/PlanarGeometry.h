// Small planar geometry shared by the core stages.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace topospline
{
// Closest point of segment ab to (x, y): returns the squared distance and sets `fraction`, the
// closest point's position along ab (0 at a, 1 at b; 0 for a segment of zero length).
inline double SegmentDistance2(const double* a, const double* b, double x, double y, double& fraction)
{
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double length2 = dx * dx + dy * dy;
  fraction = length2 > 0 ? std::clamp(((x - a[0]) * dx + (y - a[1]) * dy) / length2, 0.0, 1.0) : 0.0;
  const double ex = a[0] + fraction * dx - x, ey = a[1] + fraction * dy - y;
  return ex * ex + ey * ey;
}

// The square bucket of side `side` that holds (x, y), and one key for a bucket (i, j): the rule
// by which the bucketed searches of stage 4 register points and look them up (a point and
// the buckets around it must be found by the same rounding).
inline std::pair<long long, long long> SquareBucket(double x, double y, double side)
{
  return { static_cast<long long>(std::floor(x / side)), static_cast<long long>(std::floor(y / side)) };
}

inline long long SquareBucketKey(long long i, long long j)
{
  return (i << 32) ^ (j & 0xffffffffLL);
}

// Twice the signed area of the triangle (o, a, b): positive when it turns counter-clockwise.
inline double Orientation2D(const double* o, const double* a, const double* b)
{
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// Twice the signed area of a closed walk (x, y per point): positive when counter-clockwise.
inline double DoubleSignedArea(const std::vector<double>& walk)
{
  double area = 0;
  for (std::size_t i = 0, count = walk.size() / 2; i < count; ++i)
  {
    const std::size_t j = (i + 1) % count;
    area += walk[2 * i] * walk[2 * j + 1] - walk[2 * j] * walk[2 * i + 1];
  }
  return area;
}

// Whether segments ab and cd cross at a point inside both: each separates the other's ends
// strictly (touching ends and collinear overlaps are not crossings).
inline bool SegmentsCrossProperly(const double* a, const double* b, const double* c, const double* d)
{
  const double d1 = Orientation2D(a, b, c), d2 = Orientation2D(a, b, d);
  const double d3 = Orientation2D(c, d, a), d4 = Orientation2D(c, d, b);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

// The coordinates stages 3 and 4 work in: the domain's own, divided per axis by a power of two
// close to its typical edge extent along that axis. Why: curve fits, crossings, triangulations
// and mean value maps judge shapes by Euclidean lengths, so on an image of spacing 0.01 x 3 every
// 2-cell is a sliver and its parameterization folds, while the same field on a square grid is
// reconstructed; dividing by the spacing gives the square grid back. Powers of two make the map
// exact both ways, so node positions, curve ends and vertices still coincide after the round
// trip; a reconstruction of polynomials in the plane stays one under a per-axis scaling, so
// its critical points, monotonicity and values are unchanged.
struct PlanarFrame
{
  double Scale[2] = { 1, 1 }; // world = frame * Scale, per axis

  bool IsIdentity() const { return this->Scale[0] == 1 && this->Scale[1] == 1; }
  void ToFrame(double* xy) const
  {
    xy[0] /= this->Scale[0];
    xy[1] /= this->Scale[1];
  }
  void ToWorld(double* xy) const
  {
    xy[0] *= this->Scale[0];
    xy[1] *= this->Scale[1];
  }
  // x, y pairs.
  void ToFrame(std::vector<double>& points) const
  {
    for (std::size_t i = 0; i + 1 < points.size(); i += 2)
    {
      this->ToFrame(&points[i]);
    }
  }
  void ToWorld(std::vector<double>& points) const
  {
    for (std::size_t i = 0; i + 1 < points.size(); i += 2)
    {
      this->ToWorld(&points[i]);
    }
  }
  // xmin, xmax, ymin, ymax.
  void BoundsToFrame(double bounds[4]) const
  {
    bounds[0] /= this->Scale[0];
    bounds[1] /= this->Scale[0];
    bounds[2] /= this->Scale[1];
    bounds[3] /= this->Scale[1];
  }

  // The power of two nearest to `extent` (1 for an extent that is not positive and finite).
  static double PowerOfTwoNear(double extent)
  {
    if (!(extent > 0) || !std::isfinite(extent))
    {
      return 1;
    }
    return std::ldexp(1.0, static_cast<int>(std::lround(std::log2(extent))));
  }
  // From typical extents along x and y: a grid's spacings, or the root mean squares of a mesh's
  // edges' dx and dy (a grid's triangles give 0.82 times its spacings: the same frame).
  static PlanarFrame FromExtents(double x, double y)
  {
    PlanarFrame frame;
    frame.Scale[0] = PowerOfTwoNear(x);
    frame.Scale[1] = PowerOfTwoNear(y);
    return frame;
  }
};
} // namespace topospline
