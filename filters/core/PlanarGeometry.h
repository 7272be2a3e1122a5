// Small planar geometry shared by the core stages.
#pragma once

#include <algorithm>

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
} // namespace topospline
