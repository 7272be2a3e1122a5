#include "TwoCellReconstruction.h"

#include "BezierSpline.h"
#include "CompressedGraph.h"

#include "PiecewiseLinearField.h"

#include "PlanarGeometry.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace topospline
{
namespace
{
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Samples one side, forward from its lower corner: c points per Bezier segment (the piece's
// own count, SideSegments::Samples, when given) plus the end point, with the side parameter
// tau of each: segment j of piece i covers m_i grid segments of the N along the side
// (ChooseGridLayout).
void SampleSide(const SideSegments& side, const std::vector<int>& multipliers, int n, int c, std::vector<double>& xy,
  std::vector<double>& tau)
{
  double point[2];
  int segment = 0, offset = 0;
  std::size_t count = 1;
  for (std::size_t i = 0; i < side.Pieces.size(); ++i)
  {
    count += static_cast<std::size_t>(side.Pieces[i]) * (side.Samples.empty() ? c : side.Samples[i]);
  }
  xy.reserve(xy.size() + 2 * count);
  tau.reserve(tau.size() + count);
  for (std::size_t i = 0; i < side.Pieces.size(); ++i)
  {
    const int samples = side.Samples.empty() ? c : side.Samples[i];
    for (int j = 0; j < side.Pieces[i]; ++j, ++segment)
    {
      const double* curve = side.Curve[segment].data();
      for (int k = 0; k < samples; ++k)
      {
        const double t = static_cast<double>(k) / samples;
        // t = 0 is the control point itself, bit for bit: neighbouring cells and the two
        // sides of a slit then share their samples exactly.
        if (k == 0)
        {
          point[0] = curve[0];
          point[1] = curve[1];
        }
        else
        {
          CubicBezierSpline::EvaluateSegment(curve, 2, t, point);
        }
        xy.insert(xy.end(), point, point + 2);
        tau.push_back((offset + (j + t) * multipliers[i]) / n);
      }
    }
    offset += side.Pieces[i] * multipliers[i];
  }
  const double* end = side.Curve.back().data() + 6;
  xy.insert(xy.end(), end, end + 2);
  tau.push_back(1.0);
}

// The closed walk around a cell: bottom and right forwards, top and left backwards (each
// side without its last point, the next side's first), with the (u, v) of every sample, and
// the height segments of the four sides subdivided to the grid layout. False when no grid
// size up to `maximum` fits the sides.
bool BuildBoundaryWalk(const std::array<SideSegments, 4>& segments, int c, int maximum, std::vector<double>& walk,
  std::vector<double>& parameters, MonotoneSurfaceBoundary& boundary)
{
  std::array<std::vector<int>, 4> multipliers;
  const int n = ChooseGridLayout(segments, maximum, multipliers);
  if (n == 0)
  {
    return false;
  }
  std::array<std::vector<double>, 4> xy, tau;
  std::array<BezierSide, 4> heights;
  for (int s = 0; s < 4; ++s)
  {
    SampleSide(segments[s], multipliers[s], n, c, xy[s], tau[s]);
    int first = 0;
    for (std::size_t i = 0; i < segments[s].Pieces.size(); ++i)
    {
      const int k = segments[s].Pieces[i];
      const BezierSide piece(segments[s].Height.begin() + first, segments[s].Height.begin() + first + k);
      BezierSide subdivided;
      SubdivideSide(piece, k * multipliers[s][i], subdivided);
      heights[s].insert(heights[s].end(), subdivided.begin(), subdivided.end());
      first += k;
    }
  }
  walk.clear();
  parameters.clear();
  std::size_t points = 0;
  for (const std::vector<double>& side : tau)
  {
    points += side.size() - 1;
  }
  walk.reserve(2 * points);
  parameters.reserve(2 * points);
  auto append = [&](int s, bool forward, double u0, double v0, double du, double dv) {
    const std::size_t count = tau[s].size();
    for (std::size_t k = 0; k + 1 < count; ++k)
    {
      const std::size_t i = forward ? k : count - 1 - k;
      walk.push_back(xy[s][2 * i]);
      walk.push_back(xy[s][2 * i + 1]);
      parameters.push_back(u0 + du * tau[s][i]);
      parameters.push_back(v0 + dv * tau[s][i]);
    }
  };
  append(TwoCellSides::Bottom, true, 0, 0, 1, 0); // (tau, 0)
  append(TwoCellSides::Right, true, 1, 0, 0, 1);  // (1, tau)
  append(TwoCellSides::Top, false, 0, 1, 1, 0);   // (tau, 1), from tau = 1 down
  append(TwoCellSides::Left, false, 0, 0, 0, 1);  // (0, tau), from tau = 1 down
  boundary.Bottom = std::move(heights[TwoCellSides::Bottom]);
  boundary.Right = std::move(heights[TwoCellSides::Right]);
  boundary.Top = std::move(heights[TwoCellSides::Top]);
  boundary.Left = std::move(heights[TwoCellSides::Left]);
  return true;
}

// Even-odd point-in-polygon test.
bool InsidePolygon(const std::vector<double>& polygon, const std::array<double, 2>& p)
{
  bool inside = false;
  const std::size_t n = polygon.size() / 2;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++)
  {
    const double xi = polygon[2 * i], yi = polygon[2 * i + 1], xj = polygon[2 * j], yj = polygon[2 * j + 1];
    if ((yi > p[1]) != (yj > p[1]) && p[0] < (xj - xi) * (p[1] - yi) / (yj - yi) + xi)
    {
      inside = !inside;
    }
  }
  return inside;
}

// First and last point of a 1-cell's smoothed curve.
std::array<double, 2> StartOf(const OneCellSmoothingResult& smoothed, Index oneCell)
{
  const SmoothedPiece& piece = smoothed.Pieces[smoothed.PiecesOfOneCell[oneCell].front()];
  return { { piece.Curve.ControlPoints[0], piece.Curve.ControlPoints[1] } };
}
std::array<double, 2> EndOf(const OneCellSmoothingResult& smoothed, Index oneCell)
{
  const SmoothedPiece& piece = smoothed.Pieces[smoothed.PiecesOfOneCell[oneCell].back()];
  const std::size_t n = piece.Curve.ControlPoints.size();
  return { { piece.Curve.ControlPoints[n - 2], piece.Curve.ControlPoints[n - 1] } };
}

// Bernstein matrix of the cubic triangle at its 10 lattice points, inverted: control points
// of the cubic interpolating given values at the lattice points.
const Eigen::Matrix<double, 10, 10>& LatticeToControl()
{
  static const Eigen::Matrix<double, 10, 10> inverse = []() {
    Eigen::Matrix<double, 10, 10> m;
    const double factorial[4] = { 1, 1, 2, 6 };
    for (int i = 0; i <= 3; ++i)
    {
      for (int j = 0; i + j <= 3; ++j)
      {
        const int row = BezierOrdinateIndex(i, j);
        const double a = i / 3.0, b = j / 3.0, c = (3 - i - j) / 3.0;
        for (int p = 0; p <= 3; ++p)
        {
          for (int q = 0; p + q <= 3; ++q)
          {
            const int r = 3 - p - q;
            m(row, BezierOrdinateIndex(p, q)) =
              6.0 / (factorial[p] * factorial[q] * factorial[r]) * std::pow(a, p) * std::pow(b, q) * std::pow(c, r);
          }
        }
      }
    }
    return Eigen::Matrix<double, 10, 10>(m.inverse());
  }();
  return inverse;
}

} // namespace

namespace
{
// Two different descending 1-cells that share their first pieces merge before the minimum: the
// cell's boundary leaves them where they split, and that junction takes the minimum's corner
// (mergeAtMinimum, the paper's rule), or the shared stem stays on the boundary as a slit.
void CutMergedStemAtMinimum(std::vector<Index>& bottom, std::vector<Index>& left, bool mergeAtMinimum,
  TwoCellSides& sides)
{
  std::size_t shared = 0;
  while (shared < bottom.size() && shared < left.size() && bottom[shared] == left[shared])
  {
    ++shared;
  }
  if (shared > 0 && !mergeAtMinimum)
  {
    sides.Slit = true;
  }
  else if (shared > 0)
  {
    bottom.erase(bottom.begin(), bottom.begin() + shared);
    left.erase(left.begin(), left.begin() + shared);
    sides.MinimumShifted = true;
  }
}

// The same at the maximum, where ascending 1-cells share their last pieces.
void CutMergedStemAtMaximum(std::vector<Index>& right, std::vector<Index>& top, bool mergeAtMaximum,
  TwoCellSides& sides)
{
  std::size_t shared = 0;
  while (shared < right.size() && shared < top.size() && right[right.size() - 1 - shared] == top[top.size() - 1 - shared])
  {
    ++shared;
  }
  if (shared > 0 && !mergeAtMaximum)
  {
    sides.Slit = true;
  }
  else if (shared > 0)
  {
    right.resize(right.size() - shared);
    top.resize(top.size() - shared);
    sides.MaximumShifted = true;
  }
}

// A side of zero length (a 1-cell of one point: a saddle on its extremum's vertex) is no side:
// the cell has 3 corners. Likewise a side that ends where it starts and encloses at most
// `loopArea`: on the domain boundary, a maximum can sit on its saddle's vertex, and the
// ascending 1-cell between them is a loop through a few triangles around that vertex (well
// below a grid cell). A larger loop is a side: a descending 1-cell merged by cancellations can
// run round the whole domain boundary and back through its own saddle (a boundary saddle left
// as the boundary curve's only critical point), and the cell it bounds is the whole domain.
bool IsPointLike(const std::vector<Index>& side, const OneCellSmoothingResult& smoothed, double loopArea)
{
  const Index pieces = static_cast<Index>(smoothed.Pieces.size());
  if (!side.empty() && side.front() >= 0 && side.back() >= 0 && side.front() < pieces && side.back() < pieces)
  {
    const auto& first = smoothed.Pieces[side.front()].Curve.ControlPoints;
    const auto& last = smoothed.Pieces[side.back()].Curve.ControlPoints;
    if (!first.empty() && !last.empty() && first[0] == last[last.size() - 2] && first[1] == last.back())
    {
      // The area of the loop's control polygon (the curve's, closely enough for this).
      std::vector<double> polygon;
      for (Index p : side)
      {
        if (p < 0 || p >= pieces)
        {
          return false;
        }
        const auto& points = smoothed.Pieces[p].Curve.ControlPoints;
        polygon.insert(polygon.end(), points.begin(), points.end());
      }
      if (std::abs(0.5 * DoubleSignedArea(polygon)) <= loopArea)
      {
        return true;
      }
    }
  }
  bool degenerate = !side.empty();
  for (Index p : side)
  {
    if (p < 0 || p >= pieces)
    {
      return false;
    }
    const auto& points = smoothed.Pieces[p].Curve.ControlPoints;
    for (std::size_t i = 2; i < points.size() && degenerate; ++i)
    {
      degenerate = points[i] == points[i % 2];
    }
  }
  return degenerate;
}

// An empty side takes half of its partner in the pair Bottom + Right or Left + Top.
bool PairEmptySides(TwoCellSides& sides, std::string& error)
{
  const int partner[4] = { TwoCellSides::Right, TwoCellSides::Bottom, TwoCellSides::Left, TwoCellSides::Top };
  for (int s = 0; s < 4; ++s)
  {
    if (sides.Pieces[s].empty())
    {
      if (sides.Pieces[partner[s]].empty())
      {
        error = "both sides of a pair are empty (the cell has fewer than 3 corners)";
        return false;
      }
      sides.SplitSides[s == TwoCellSides::Bottom || s == TwoCellSides::Right ? 0 : 1] = partner[s];
    }
  }
  return true;
}

bool PiecesHaveCurves(const TwoCellSides& sides, const OneCellSmoothingResult& smoothed, std::string& error)
{
  for (const auto& side : sides.Pieces)
  {
    for (Index p : side)
    {
      if (p < 0 || p >= static_cast<Index>(smoothed.Pieces.size()) || smoothed.Pieces[p].Curve.Segments < 1 ||
        smoothed.Pieces[p].Height.Segments != smoothed.Pieces[p].Curve.Segments)
      {
        error = "a boundary piece has no Bezier curve";
        return false;
      }
    }
  }
  return true;
}
} // namespace

bool AssembleTwoCellSides(const TwoCell& cell, const OneCellSmoothingResult& smoothed, TwoCellSides& sides,
  std::string& error, bool mergeAtMinimum, bool mergeAtMaximum, double pointLikeLoopArea)
{
  sides = TwoCellSides();
  const Index oneCells = static_cast<Index>(smoothed.PiecesOfOneCell.size());
  for (Index a : cell.BoundaryOneCells)
  {
    if (a < 0 || a >= oneCells)
    {
      error = "a boundary 1-cell is not in the smoothed complex";
      return false;
    }
  }
  const Index d0 = cell.BoundaryOneCells[0], a0 = cell.BoundaryOneCells[1];
  const Index d1 = cell.BoundaryOneCells[2], a1 = cell.BoundaryOneCells[3];
  auto& bottom = sides.Pieces[TwoCellSides::Bottom];
  auto& right = sides.Pieces[TwoCellSides::Right];
  auto& top = sides.Pieces[TwoCellSides::Top];
  auto& left = sides.Pieces[TwoCellSides::Left];
  bottom = smoothed.PiecesOfOneCell[d0];
  right = smoothed.PiecesOfOneCell[a0];
  left = smoothed.PiecesOfOneCell[d1];
  top = smoothed.PiecesOfOneCell[a1];
  // The same 1-cell on both sides of a pair (a pouch) is a slit and stays whole.
  if (d0 != d1)
  {
    CutMergedStemAtMinimum(bottom, left, mergeAtMinimum, sides);
  }
  else
  {
    sides.Slit = true;
  }
  if (a0 != a1)
  {
    CutMergedStemAtMaximum(right, top, mergeAtMaximum, sides);
  }
  else if (sides.Slit)
  {
    error = "both pairs of sides are the same 1-cell";
    return false;
  }
  else
  {
    sides.Slit = true;
  }
  for (auto& side : sides.Pieces)
  {
    if (IsPointLike(side, smoothed, pointLikeLoopArea))
    {
      side.clear();
    }
  }
  return PairEmptySides(sides, error) && PiecesHaveCurves(sides, smoothed, error);
}

std::vector<int> BoundarySamplesPerPiece(const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed,
  int c, double spacing, Index fewerVerticesThan)
{
  std::vector<int> samples(smoothed.Pieces.size(), c);
  if (!(spacing > 0))
  {
    return samples;
  }
  // The most vertices of a 2-cell beside each piece: of the cells its 1-cells bound.
  std::vector<Index> largestCell(smoothed.Pieces.size(), 0);
  for (const TwoCell& cell : complex.TwoCells)
  {
    for (const Index o : cell.BoundaryOneCells)
    {
      if (o >= 0 && o < static_cast<Index>(smoothed.PiecesOfOneCell.size()))
      {
        for (const Index p : smoothed.PiecesOfOneCell[o])
        {
          if (p >= 0 && p < static_cast<Index>(largestCell.size()))
          {
            largestCell[p] = std::max(largestCell[p], cell.NumberOfVertices);
          }
        }
      }
    }
  }
  for (std::size_t p = 0; p < samples.size(); ++p)
  {
    const SmoothedPiece& piece = smoothed.Pieces[p];
    if (largestCell[p] >= fewerVerticesThan || piece.Curve.Dimension != 2)
    {
      continue;
    }
    double longest = 0;
    for (int j = 0; j < piece.Curve.Segments; ++j)
    {
      const double* b = piece.Curve.Segment(j);
      double length = 0;
      for (int m = 0; m < 3; ++m)
      {
        length += std::hypot(b[2 * m + 2] - b[2 * m], b[2 * m + 3] - b[2 * m + 1]);
      }
      longest = std::max(longest, length);
    }
    // Compared as doubles: a curve too long for an int keeps c.
    const double wanted = std::ceil(longest / spacing);
    samples[p] = wanted < c ? std::max(1, static_cast<int>(wanted)) : c;
  }
  return samples;
}

int ChooseGridLayout(const std::array<SideSegments, 4>& sides, int maximum, std::array<std::vector<int>, 4>& multipliers)
{
  int lowest = 1;
  for (const auto& side : sides)
  {
    lowest = std::max(lowest, static_cast<int>(side.Curve.size()));
  }
  // reach[s][r]: the piece whose count ends a way of writing r as a sum of the side's piece
  // counts (-1: none; r = 0 needs none), an unbounded coin problem per side. Filled only as far
  // as the counts tried need (up to `maximum` it was a sixtieth of stage 4 on noise, where the
  // first count tried fits almost always).
  std::array<std::vector<int>, 4> reach;
  const auto reachable = [&](int s, int extra) {
    std::vector<int>& table = reach[s];
    if (table.capacity() == 0)
    {
      table.reserve(std::max<std::size_t>(64, static_cast<std::size_t>(extra) + 1));
    }
    while (static_cast<int>(table.size()) <= extra)
    {
      const int r = static_cast<int>(table.size());
      int piece = -1;
      for (std::size_t i = 0; r > 0 && i < sides[s].Pieces.size() && piece < 0; ++i)
      {
        const int k = sides[s].Pieces[i];
        if (k <= r && (r == k || table[r - k] >= 0))
        {
          piece = static_cast<int>(i);
        }
      }
      table.push_back(piece);
    }
    return extra == 0 || table[extra] >= 0;
  };
  for (int n = lowest; n <= maximum; ++n)
  {
    bool fits = true;
    for (int s = 0; s < 4 && fits; ++s)
    {
      const int extra = n - static_cast<int>(sides[s].Curve.size());
      fits = extra == 0 || (extra > 0 && reachable(s, extra));
    }
    if (!fits)
    {
      continue;
    }
    for (int s = 0; s < 4; ++s)
    {
      multipliers[s].assign(sides[s].Pieces.size(), 1);
      for (int r = n - static_cast<int>(sides[s].Curve.size()); r > 0;)
      {
        const int i = reach[s][r];
        ++multipliers[s][i];
        r -= sides[s].Pieces[i];
      }
    }
    return n;
  }
  return 0;
}

namespace
{
// The empty sides of `result` (TwoCellSides::SplitSides) made up from half of their partners
// (see TwoCellSideSegments).
void SplitEmptySides(const TwoCellSides& sides, std::array<SideSegments, 4>& result, bool exactHalves, int cutOffset)
{
  // The lower half of a Right or Top side goes to its empty partner (Bottom or Left); the
  // upper half of a Bottom or Left side goes to its empty partner (Right or Top).
  // Split at the segment boundary nearest the middle: the samples stay those of the
  // neighbouring cell that shares this 1-cell, so both cells keep one common boundary. Only a
  // side of one segment is cut inside it (at t = 1/2); there the two cells' boundaries differ
  // by a sliver between two samples.
  for (int split : sides.SplitSides)
  {
    if (split < 0)
    {
      continue;
    }
    SideSegments whole = std::move(result[split]);
    if (whole.Curve.size() == 1 || (exactHalves && whole.Curve.size() % 2 == 1))
    {
      // Every segment cut at its middle: the side's parameter speed stays uniform and the
      // halves have equal counts.
      SideSegments halved;
      for (std::size_t j = 0; j < whole.Curve.size(); ++j)
      {
        std::array<double, 8> left, right;
        CubicBezierSpline::Subdivide(whole.Curve[j].data(), 2, 0.5, left.data(), right.data());
        halved.Curve.insert(halved.Curve.end(), { left, right });
        CubicHeightSegment lower, upper;
        CubicBezierSpline::Subdivide(
          whole.Height[j].data(), 1, 0.5, lower.data(), upper.data(), DeCasteljauStep::Weighted);
        halved.Height.insert(halved.Height.end(), { lower, upper });
      }
      for (int k : whole.Pieces)
      {
        halved.Pieces.push_back(2 * k);
      }
      halved.Samples = whole.Samples;
      whole = std::move(halved);
    }
    const int count = static_cast<int>(whole.Curve.size());
    const std::size_t half =
      static_cast<std::size_t>(count < 2 ? count / 2 : std::clamp(count / 2 + cutOffset, 1, count - 1));
    SideSegments lower, upper;
    lower.Curve.assign(whole.Curve.begin(), whole.Curve.begin() + half);
    lower.Height.assign(whole.Height.begin(), whole.Height.begin() + half);
    upper.Curve.assign(whole.Curve.begin() + half, whole.Curve.end());
    upper.Height.assign(whole.Height.begin() + half, whole.Height.end());
    // The piece counts of both halves (the piece cut at `half` goes partly to each).
    int seen = 0;
    for (std::size_t i = 0; i < whole.Pieces.size(); ++i)
    {
      const int k = whole.Pieces[i];
      const int below = std::clamp(static_cast<int>(half) - seen, 0, k);
      if (below > 0)
      {
        lower.Pieces.push_back(below);
        if (!whole.Samples.empty())
        {
          lower.Samples.push_back(whole.Samples[i]);
        }
      }
      if (k - below > 0)
      {
        upper.Pieces.push_back(k - below);
        if (!whole.Samples.empty())
        {
          upper.Samples.push_back(whole.Samples[i]);
        }
      }
      seen += k;
    }
    const bool bottomPair = split == TwoCellSides::Bottom || split == TwoCellSides::Right;
    result[bottomPair ? TwoCellSides::Bottom : TwoCellSides::Left] = std::move(lower);
    result[bottomPair ? TwoCellSides::Right : TwoCellSides::Top] = std::move(upper);
  }
}
} // namespace

std::array<SideSegments, 4> TwoCellSideSegments(const TwoCellSides& sides, const OneCellSmoothingResult& smoothed,
  bool exactHalves, int cutOffset, const std::vector<int>* samplesPerPiece)
{
  std::array<SideSegments, 4> result;
  for (int s = 0; s < 4; ++s)
  {
    for (Index p : sides.Pieces[s])
    {
      const SmoothedPiece& piece = smoothed.Pieces[p];
      result[s].Pieces.push_back(piece.Curve.Segments);
      if (samplesPerPiece != nullptr)
      {
        result[s].Samples.push_back((*samplesPerPiece)[p]);
      }
      for (int j = 0; j < piece.Curve.Segments; ++j)
      {
        std::array<double, 8> curve;
        std::copy(piece.Curve.Segment(j), piece.Curve.Segment(j) + 8, curve.begin());
        result[s].Curve.push_back(curve);
        const double* h = piece.Height.Segment(j);
        result[s].Height.push_back({ { h[0], h[1], h[2], h[3] } });
      }
    }
  }
  SplitEmptySides(sides, result, exactHalves, cutOffset);
  return result;
}

std::array<SideSegments, 4> TwoCellSideCounts(const TwoCellSides& sides, const std::function<int(Index)>& countOf)
{
  std::array<SideSegments, 4> result;
  for (int s = 0; s < 4; ++s)
  {
    for (Index p : sides.Pieces[s])
    {
      result[s].Pieces.push_back(countOf(p));
      result[s].Curve.resize(result[s].Curve.size() + result[s].Pieces.back());
      result[s].Height.resize(result[s].Curve.size());
    }
  }
  SplitEmptySides(sides, result, false, 0);
  return result;
}

namespace
{
// The mean distance between consecutive points of a closed walk.
double MeanSampleSpacing(const std::vector<double>& walk)
{
  double perimeter = 0;
  const std::size_t samples = walk.size() / 2;
  for (std::size_t i = 0; i < samples; ++i)
  {
    const std::size_t j = (i + 1) % samples;
    perimeter += std::hypot(walk[2 * j] - walk[2 * i], walk[2 * j + 1] - walk[2 * i + 1]);
  }
  return perimeter / std::max<std::size_t>(samples, 1);
}

// Where merged 1-cells leave a stem at the minimum (maximum) inside the cell, the stem stays
// on the boundary as a slit (merge = false) rather than the junction taking the corner. The
// first choice follows a point-in-polygon test; as that test can be fooled by a walk that is
// not simple, the other choices follow.
std::vector<std::array<bool, 2>> StemChoices(const TwoCell& twoCell, const TwoCellSides& sides,
  const OneCellSmoothingResult& smoothed, const std::vector<double>& walk)
{
  const bool stemAtMinimum = sides.MinimumShifted, stemAtMaximum = sides.MaximumShifted;
  const std::array<bool, 2> merge = { { !(stemAtMinimum && InsidePolygon(walk, StartOf(smoothed, twoCell.BoundaryOneCells[0]))),
    !(stemAtMaximum && InsidePolygon(walk, EndOf(smoothed, twoCell.BoundaryOneCells[1]))) } };
  std::vector<std::array<bool, 2>> choices = { merge };
  if (stemAtMinimum)
  {
    choices.push_back({ { !merge[0], merge[1] } });
  }
  if (stemAtMaximum)
  {
    choices.push_back({ { merge[0], !merge[1] } });
  }
  if (stemAtMinimum && stemAtMaximum)
  {
    choices.push_back({ { !merge[0], !merge[1] } });
  }
  return choices;
}
} // namespace

namespace
{
// Counting sort of the items 0..ids.size()-1 by their id in [0, groups): the items of group g
// are items[first[g] .. first[g + 1]). Items with an id outside the range are left out.
void GroupByIndex(const std::vector<Index>& ids, Index groups, std::vector<Index>& first, std::vector<Index>& items)
{
  first.assign(static_cast<std::size_t>(groups) + 1, 0);
  for (Index id : ids)
  {
    if (id >= 0 && id < groups)
    {
      ++first[id + 1];
    }
  }
  std::partial_sum(first.begin(), first.end(), first.begin());
  items.assign(first.back(), 0);
  std::vector<Index> next(first.begin(), first.end() - 1);
  for (Index item = 0; item < static_cast<Index>(ids.size()); ++item)
  {
    if (ids[item] >= 0 && ids[item] < groups)
    {
      items[next[ids[item]]++] = item;
    }
  }
}

// Whether vertex v (inside the mesh) is critical for the values `value(w)` (ties broken by
// vertex id, stage 1's order): its link is a cycle, one edge per incident triangle, and a
// regular vertex's link changes between lower and upper exactly twice.
template <typename Values>
bool IsCriticalVertex(const TriangleMeshTopology& mesh, Index v, const Values& value)
{
  const double fv = value(v);
  const auto lower = [&](Index w) {
    const double fw = value(w);
    return fw < fv || (fw == fv && w < v);
  };
  int changes = 0;
  for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v); ++i)
  {
    const auto& t = mesh.TriangleVertices[mesh.VertexTriangle(i)];
    const int at = t[0] == v ? 0 : t[1] == v ? 1 : 2;
    changes += lower(t[(at + 1) % 3]) != lower(t[(at + 2) % 3]) ? 1 : 0;
  }
  return changes != 2;
}

// The cells of `order` through `parallel` in successive slices, each cell taken by the next
// thread that is free (largest first, when `order` is sorted so: split into fixed shares, a few
// cells far larger than the others, a terrain's, could all fall in one thread's share, the
// other thread idle; each cell's work depends on that cell alone, so the result does not depend
// on the order). The fraction done is reported (as [from, to] of the caller's progress) on the
// calling thread after each slice: on 1000 x 1000 noise one pass over the half million cells
// takes a minute, which a single report at its end left without a moving progress bar, and
// reports from the worker threads would reach VTK's observers off the main thread. Slices of
// at least 256 cells keep both threads busy; the abort is polled before each cell, and no slice
// starts after one.
void ForEachCellLargestFirst(const std::vector<Index>& order, const ParallelFor& parallel, const ProgressHooks& hooks,
  double from, double to, const std::function<void(Index)>& body)
{
  const Index n = static_cast<Index>(order.size());
  const Index slice = std::max<Index>(256, (n + 49) / 50);
  for (Index begin = 0; begin < n && !hooks.Aborted(); begin += slice)
  {
    const Index end = std::min(n, begin + slice);
    std::atomic<Index> next(begin);
    parallel(begin, end, [&](Index, Index) {
      for (Index i = next++; i < end && !hooks.Aborted(); i = next++)
      {
        body(order[i]);
      }
    });
    hooks.Report(from + (to - from) * static_cast<double>(end) / static_cast<double>(n));
  }
}

// Per vertex: whether it is inside the mesh and its whole ring of neighbours lies in its own
// cell (cellOf; InvalidIndex: in none).
std::vector<char> RingsInTheirCells(
  const TriangleMeshTopology& mesh, const std::vector<Index>& cellOf, const ParallelFor& parallel)
{
  std::vector<char> ringInCell(cellOf.size(), 0);
  parallel(0, static_cast<Index>(cellOf.size()), [&](Index begin, Index end) {
    for (Index v = begin; v < end; ++v)
    {
      bool inside = cellOf[v] != InvalidIndex && !mesh.IsBoundaryVertex(v);
      for (Index i = mesh.VertexTriangleBegin(v); inside && i < mesh.VertexTriangleEnd(v); ++i)
      {
        for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
        {
          inside = inside && cellOf[w] == cellOf[v];
        }
      }
      ringInCell[v] = inside ? 1 : 0;
    }
  });
  return ringInCell;
}

// Whether points lie within `distance` of a closed polyline (a cell's boundary samples, which
// follow its smoothed 1-cells): each segment is listed in the squares of side `distance` its
// box touches, and a point asks the 3 x 3 squares around its own (a segment within reach has
// its box in them).
class PolylineProximity
{
public:
  PolylineProximity(const std::vector<double>& points, Index count, double distance)
    : Points(points)
    , Count(count)
    , Distance(distance)
  {
    for (Index s = 0; s < count; ++s)
    {
      const double* a = &points[2 * static_cast<std::size_t>(s)];
      const double* b = &points[2 * static_cast<std::size_t>((s + 1) % count)];
      const auto [i0, j0] = SquareBucket(std::min(a[0], b[0]), std::min(a[1], b[1]), distance);
      const auto [i1, j1] = SquareBucket(std::max(a[0], b[0]), std::max(a[1], b[1]), distance);
      for (long long i = i0; i <= i1; ++i)
      {
        for (long long j = j0; j <= j1; ++j)
        {
          this->Segments[SquareBucketKey(i, j)].push_back(s);
        }
      }
    }
  }

  bool Within(const double* p) const
  {
    const auto [pi, pj] = SquareBucket(p[0], p[1], this->Distance);
    for (long long i = pi - 1; i <= pi + 1; ++i)
    {
      for (long long j = pj - 1; j <= pj + 1; ++j)
      {
        const auto found = this->Segments.find(SquareBucketKey(i, j));
        if (found == this->Segments.end())
        {
          continue;
        }
        for (Index s : found->second)
        {
          double fraction;
          const double* a = &this->Points[2 * static_cast<std::size_t>(s)];
          const double* b = &this->Points[2 * static_cast<std::size_t>((s + 1) % this->Count)];
          if (SegmentDistance2(a, b, p[0], p[1], fraction) <= this->Distance * this->Distance)
          {
            return true;
          }
        }
      }
    }
    return false;
  }

private:
  const std::vector<double>& Points;
  const Index Count;
  const double Distance;
  std::unordered_map<long long, std::vector<Index>> Segments;
};

// Of a cell's vertices, those two rings of vertices or more inside it (its ring and the rings
// of its neighbours in the cell, RingsInTheirCells): no smoothed 1-cell passes next to them.
// With `farFromBoundary` (may be empty), also those whose ring alone is in the cell and that it
// calls far from the cell's boundary; byRings[k] says which kind sample k is (1: two rings).
std::vector<Index> DeepVertices(const TriangleMeshTopology& mesh, const Index* vertices, Index count,
  const std::vector<char>& ringInCell, const std::function<bool(Index)>& farFromBoundary, std::vector<char>& byRings)
{
  std::vector<Index> deep;
  byRings.assign(count, 0);
  for (Index k = 0; k < count; ++k)
  {
    const Index v = vertices[k];
    bool all = ringInCell[v] != 0;
    for (Index i = mesh.VertexTriangleBegin(v); all && i < mesh.VertexTriangleEnd(v); ++i)
    {
      for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
      {
        all = all && ringInCell[w] != 0;
      }
    }
    if (all || (ringInCell[v] != 0 && farFromBoundary && farFromBoundary(v)))
    {
      deep.push_back(k);
      byRings[k] = all ? 1 : 0;
    }
  }
  return deep;
}
} // namespace

bool TwoCellReconstruction::Reconstruct(const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed,
  std::string& error, const PlanarScalarField* data)
{
  this->Cells.clear();
  this->Summary = TwoCellReconstructionReport();
  if (this->BoundarySamples < 1 || this->BoundarySamples > 1000)
  {
    error = "the number of boundary samples must be in [1, 1000], not " + std::to_string(this->BoundarySamples);
    return false;
  }
  if (smoothed.PiecesOfOneCell.size() != complex.OneCells.size())
  {
    error = "the smoothed 1-cells do not belong to this complex";
    return false;
  }
  const Index n = static_cast<Index>(complex.TwoCells.size());
  this->Cells.resize(n);
  for (auto& cell : this->Cells)
  {
    cell = std::make_unique<ReconstructedTwoCell>();
  }
  std::vector<MonotoneSurfaceBoundary> boundaries(n);

  // Pass 1 (the paper's "time II"): sides, boundary samples, triangulation, parameterization.
  auto start = Clock::now();
  const std::vector<int> samplesPerPiece =
    BoundarySamplesPerPiece(complex, smoothed, this->BoundarySamples, this->BoundarySampleSpacing, SparseSamplesBelowVertices);
  // The cells with the most vertices first, in every pass: their meshes, maps and fits take
  // the longest (ForEachCellLargestFirst).
  std::vector<Index> largestFirst(n);
  std::iota(largestFirst.begin(), largestFirst.end(), 0);
  std::stable_sort(largestFirst.begin(), largestFirst.end(),
    [&](Index a, Index b) { return complex.TwoCells[a].NumberOfVertices > complex.TwoCells[b].NumberOfVertices; });
  ForEachCellLargestFirst(largestFirst, this->Parallel, this->Hooks, 0.0, 0.65, [&](Index c) {
    this->ParameterizeCell(complex.TwoCells[c], smoothed, samplesPerPiece, *this->Cells[c], boundaries[c]);
  });
  this->DensifyFailedBoundaries(complex, smoothed, samplesPerPiece, boundaries);
  if (this->Hooks.Aborted())
  {
    error = "aborted";
    return false;
  }
  this->Summary.ParameterizationSeconds = Seconds(start);
  this->Hooks.Report(0.7);

  // Pass 2 (the paper's "time III"): subdivision to a common count and the Sibson surface,
  // fitted to the cell's input samples when asked.
  start = Clock::now();
  const bool fit = this->Interior == TwoCellInterior::Fitted && data != nullptr &&
    complex.TwoCellId.size() == data->Values.size() && data->Points.size() == 2 * data->Values.size();
  std::vector<Index> firstVertex, vertices; // vertices of cell c: [firstVertex[c], firstVertex[c + 1])
  std::vector<double> parameters;           // (u, v) per vertex in its cell
  std::vector<Index> cellOf;                // the cell of every vertex (InvalidIndex: none)
  if (fit)
  {
    // Every vertex is data for the smoothed cell that contains it (near the 1-cells that is
    // often not the region stage 1 put it in).
    this->BuildCellLocator();
    this->LocateSamples(*data, complex.TwoCellId, firstVertex, vertices, parameters, cellOf);
  }
  const bool stiffen = fit && this->Mesh != nullptr &&
    (this->StiffeningRounds > 0 || this->OrderingRounds > 0 || this->AxisAimTrigger > 0) &&
    this->Mesh->NumberOfVertices() == static_cast<Index>(data->Values.size());
  const std::vector<char> ringInCell = stiffen ? RingsInTheirCells(*this->Mesh, cellOf, this->Parallel) : std::vector<char>();
  if (!this->SurfacesFitInMemory(boundaries, firstVertex, error))
  {
    return false;
  }
  std::vector<char> refined(n, 0), stiffened(n, 0), ordered(n, 0), remapped(n, 0), axisFree(n, 0);
  auto samplesOf = [&](Index c) {
    std::vector<SurfaceSample> samples;
    samples.reserve(firstVertex[c + 1] - firstVertex[c]);
    for (Index k = firstVertex[c]; k < firstVertex[c + 1]; ++k)
    {
      samples.push_back({ parameters[2 * vertices[k]], parameters[2 * vertices[k] + 1], data->Values[vertices[k]] });
    }
    return samples;
  };
  // Small cells (FitSizeOf) are only measured here: the paper's largest miss of each, when
  // beyond SmallCellFitTrigger times the tolerance; they are fitted after the others.
  std::vector<double> smallMiss(n, 0.0);
  std::vector<char> smallFitted(n, 0);
  ForEachCellLargestFirst(largestFirst, this->Parallel, this->Hooks, 0.7, 0.85, [&](Index c) {
    ReconstructedTwoCell& cell = *this->Cells[c];
    BuildSurface(cell, boundaries[c]);
    if (fit && cell.Valid)
    {
      const std::vector<SurfaceSample> samples = samplesOf(c);
      const FitSize size = this->FitSizeOf(cell, samples.size());
      if (size == FitSize::Regular)
      {
        refined[c] = this->FitSurface(cell, boundaries[c], samples);
      }
      else if (size == FitSize::Small && this->SmallCellFitTrigger > 0)
      {
        double maximum = 0, rms = 0;
        cell.Surface.MeasureResiduals(samples, maximum, rms);
        smallMiss[c] = maximum > this->SmallCellFitTrigger * this->SurfaceTolerance ? maximum : 0.0;
      }
    }
    // Only fitted cells read their sides again (alternative maps, stiffening): on uniform
    // noise the others are nearly all, and their sides were a tenth of stage 4's peak.
    if (!(fit && cell.Valid && cell.Surface.FitReport().Fitted) && smallMiss[c] == 0)
    {
      boundaries[c] = MonotoneSurfaceBoundary();
    }
  });
  // The small cells the paper's interior misses most, fitted while their number stays within a
  // share of the regular fits' (SmallCellFitsPerRegularFit; at least MinimumSmallCellFits): a
  // narrow cell of a terrain between two ridges then follows its valley, and uniform noise,
  // whose cells are nearly all small, keeps most of stage 4's time.
  std::vector<Index> smallCells;
  for (Index c = 0; c < n; ++c)
  {
    if (smallMiss[c] > 0)
    {
      smallCells.push_back(c);
    }
  }
  std::stable_sort(
    smallCells.begin(), smallCells.end(), [&](Index a, Index b) { return smallMiss[a] > smallMiss[b]; });
  const std::size_t regularFits = static_cast<std::size_t>(std::count_if(this->Cells.begin(), this->Cells.end(),
    [](const std::unique_ptr<ReconstructedTwoCell>& cell) { return cell->Surface.FitReport().Fitted; }));
  const std::size_t smallFits = std::min(smallCells.size(),
    std::max<std::size_t>(MinimumSmallCellFits, static_cast<std::size_t>(SmallCellFitsPerRegularFit * regularFits)));
  for (std::size_t i = smallFits; i < smallCells.size(); ++i)
  {
    boundaries[smallCells[i]] = MonotoneSurfaceBoundary();
  }
  smallCells.resize(smallFits);
  ForEachCellLargestFirst(smallCells, this->Parallel, this->Hooks, 0.85, 0.9, [&](Index c) {
    ReconstructedTwoCell& cell = *this->Cells[c];
    refined[c] = this->FitSurface(cell, boundaries[c], samplesOf(c));
    smallFitted[c] = cell.Surface.FitReport().Fitted ? 1 : 0;
    if (!smallFitted[c])
    {
      boundaries[c] = MonotoneSurfaceBoundary();
    }
  });
  // The largest misses get their second chance on the alternative maps (AlternativeMapStrength):
  // the cells from the one that misses most down, while each is improved (a cell that is not
  // keeps the largest miss where it is) and misses by more than AlternativeMapTrigger times
  // the tolerance. Then the stiffening, on the maps kept. Small cells keep the mean value map:
  // on noise they miss most, and the first one a map does not improve would end the pass
  // before the regular cells it helps.
  std::vector<std::vector<SurfaceSample>> remappedSamples(n);
  if (fit && this->AlternativeMapStrength > 0)
  {
    std::vector<std::pair<double, Index>> misses;
    for (Index c = 0; c < n; ++c)
    {
      const ReconstructedTwoCell& cell = *this->Cells[c];
      if (cell.Valid && cell.Surface.FitReport().Fitted && !smallFitted[c] &&
        cell.Surface.FitReport().MaximumResidual > AlternativeMapTrigger * this->SurfaceTolerance)
      {
        misses.emplace_back(cell.Surface.FitReport().MaximumResidual, c);
      }
    }
    std::sort(misses.begin(), misses.end(), std::greater<>());
    // Built only when some cell qualifies (on a mesh it is a bucket grid over the triangles).
    std::unique_ptr<PiecewiseLinearField> field;
    if (!misses.empty())
    {
      field = std::make_unique<PiecewiseLinearField>(*data);
    }
    for (const auto& miss : misses)
    {
      const Index c = miss.second;
      std::vector<SurfaceSample> samples = samplesOf(c);
      if (this->Hooks.Aborted() ||
        !this->FitOnAlternativeMaps(*this->Cells[c], boundaries[c], *field, *data, vertices.data() + firstVertex[c], samples))
      {
        break;
      }
      remapped[c] = 1;
      remappedSamples[c] = std::move(samples);
    }
  }
  ForEachCellLargestFirst(largestFirst, this->Parallel, this->Hooks, 0.9, 0.99, [&](Index c) {
    ReconstructedTwoCell& cell = *this->Cells[c];
    if (stiffen && cell.Valid && cell.Surface.FitReport().Fitted)
    {
      const std::vector<SurfaceSample> samples = remapped[c] ? std::move(remappedSamples[c]) : samplesOf(c);
      const int outcome =
        this->StiffenWhereSamplingBreaks(cell, samples, vertices.data() + firstVertex[c], ringInCell, data->Points);
      stiffened[c] = (outcome & StiffenedFit) != 0 ? 1 : 0;
      ordered[c] = (outcome & OrderedFit) != 0 ? 1 : 0;
      axisFree[c] = (outcome & AxisFreeFit) != 0 ? 1 : 0;
    }
  });
  if (this->Hooks.Aborted())
  {
    error = "aborted";
    return false;
  }
  this->Summary.RefinedCells = std::count(refined.begin(), refined.end(), 1);
  this->Summary.StiffenedCells = std::count(stiffened.begin(), stiffened.end(), 1);
  this->Summary.OrderedCells = std::count(ordered.begin(), ordered.end(), 1);
  this->Summary.RemappedCells = std::count(remapped.begin(), remapped.end(), 1);
  this->Summary.AxisFreeCells = std::count(axisFree.begin(), axisFree.end(), 1);
  this->Summary.SmallFittedCells = std::count(smallFitted.begin(), smallFitted.end(), 1);
  this->Summary.SurfaceSeconds = Seconds(start);
  this->Summarize();
  this->BuildCellLocator();
  this->Hooks.Report(1.0);
  return true;
}

void TwoCellReconstruction::DensifyFailedBoundaries(const MorseSmaleComplex& complex,
  const OneCellSmoothingResult& smoothed, std::vector<int> samplesPerPiece,
  std::vector<MonotoneSurfaceBoundary>& boundaries)
{
  const Index n = static_cast<Index>(this->Cells.size());
  // Up to 2^BoundaryDensifications times the samples, but no denser than 64 per segment (a
  // failing cell with hundreds of segments would otherwise get millions of samples when c is
  // already large).
  const int mostSamples = std::max(this->BoundarySamples,
    std::min(this->BoundarySamples << std::clamp(this->BoundaryDensifications, 0, 8), MostDensifiedSamples));
  // The smoothed pieces on the sides of cell c (known ones only).
  auto forEachPiece = [&](Index c, auto&& visit) {
    for (const auto& side : this->Cells[c]->Sides.Pieces)
    {
      for (Index p : side)
      {
        if (p >= 0 && p < static_cast<Index>(smoothed.Pieces.size()))
        {
          visit(p);
        }
      }
    }
  };
  for (int round = 0; round < this->BoundaryDensifications && !this->Hooks.Aborted(); ++round)
  {
    // The pieces of the failed cells, each sampled twice as densely as before.
    std::vector<char> densified(smoothed.Pieces.size(), 0);
    bool any = false;
    for (Index c = 0; c < n; ++c)
    {
      if (this->Cells[c]->MapFailed)
      {
        forEachPiece(c, [&](Index p) {
          if (!densified[p] && samplesPerPiece[p] < mostSamples)
          {
            densified[p] = 1;
            samplesPerPiece[p] *= 2;
            any = true;
          }
        });
      }
    }
    if (!any)
    {
      break;
    }
    // Every cell on those pieces, parameterized again; one that was valid and now fails keeps
    // its earlier map and boundary.
    std::vector<Index> again;
    for (Index c = 0; c < n; ++c)
    {
      bool touched = false;
      forEachPiece(c, [&](Index p) { touched = touched || densified[p]; });
      if (touched)
      {
        again.push_back(c);
      }
    }
    this->Parallel(0, static_cast<Index>(again.size()), [&](Index begin, Index end) {
      for (Index k = begin; k < end && !this->Hooks.Aborted(); ++k)
      {
        const Index c = again[k];
        auto cell = std::make_unique<ReconstructedTwoCell>();
        MonotoneSurfaceBoundary boundary;
        this->ParameterizeCell(complex.TwoCells[c], smoothed, samplesPerPiece, *cell, boundary);
        if (cell->Valid || !this->Cells[c]->Valid)
        {
          cell->Resampled = true;
          this->Cells[c] = std::move(cell);
          boundaries[c] = std::move(boundary);
        }
      }
    });
  }
}

// The cell's sides assembled, sampled into a closed walk, triangulated and mapped onto the
// unit square; `boundary` receives its sides' Bezier segments at the grid layout.
void TwoCellReconstruction::ParameterizeCell(const TwoCell& twoCell, const OneCellSmoothingResult& smoothed,
  const std::vector<int>& samplesPerPiece, ReconstructedTwoCell& cell, MonotoneSurfaceBoundary& boundary) const
{
  std::string message;
  std::vector<double> walk, parameters;
  const double pointLikeLoopArea =
    this->NegligibleArea > 0 ? this->NegligibleArea : std::numeric_limits<double>::infinity();
  auto assemble = [&](bool mergeAtMinimum, bool mergeAtMaximum) {
    if (!AssembleTwoCellSides(
          twoCell, smoothed, cell.Sides, message, mergeAtMinimum, mergeAtMaximum, pointLikeLoopArea))
    {
      return false;
    }
    // Halves cut at a segment boundary keep the samples of the neighbouring cell that shares
    // the split 1-cell; when their counts (k and k + 1) make the grid too fine, they are cut at
    // the exact middle instead, and the two cells' boundaries differ by slivers between samples.
    const std::array<SideSegments, 4> atSegmentBoundaries =
      TwoCellSideSegments(cell.Sides, smoothed, false, 0, &samplesPerPiece);
    if (!BuildBoundaryWalk(atSegmentBoundaries, this->BoundarySamples, this->MaximumGridSize, walk, parameters,
          boundary) &&
      !BuildBoundaryWalk(TwoCellSideSegments(cell.Sides, smoothed, true, 0, &samplesPerPiece),
        this->BoundarySamples, this->MaximumGridSize, walk, parameters, boundary) &&
      !this->BuildBoundaryWalkCutOffMiddle(cell.Sides, smoothed, samplesPerPiece, walk, parameters, boundary) &&
      !(this->LargestGridSize > this->MaximumGridSize &&
        BuildBoundaryWalk(
          atSegmentBoundaries, this->BoundarySamples, this->LargestGridSize, walk, parameters, boundary)))
    {
      message = "its sides need more than " +
        std::to_string(std::max(this->MaximumGridSize, this->LargestGridSize)) + " segments each (pieces";
      for (const SideSegments& side : TwoCellSideSegments(cell.Sides, smoothed))
      {
        std::string counts;
        for (int k : side.Pieces)
        {
          counts += (counts.empty() ? " " : "+") + std::to_string(k);
        }
        message += (counts.empty() ? " none" : counts) + ",";
      }
      message += ")";
      return false;
    }
    return true;
  };
  // The paper's rule first (merged 1-cells: the junction takes the corner); a stem that ends
  // inside the resulting walk is the cell's own, and stays on its boundary as a slit.
  if (!assemble(true, true))
  {
    cell.Error = message;
    return;
  }
  std::string firstError;
  bool firstErrorIsMap = false; // the error reported comes from Parameterize (not the grid)
  for (const auto& choice : StemChoices(twoCell, cell.Sides, smoothed, walk))
  {
    if (!assemble(choice[0], choice[1]))
    {
      firstError = firstError.empty() ? message : firstError;
      continue;
    }
    // Cells of (almost) no area, e.g. a zero-persistence pair on the domain boundary whose
    // 1-cells run on top of each other, hold no vertex: they are skipped, and counted.
    if (std::abs(0.5 * DoubleSignedArea(walk)) <= this->NegligibleArea)
    {
      cell.Negligible = true;
      break;
    }
    cell.Bounds[0] = cell.Bounds[2] = std::numeric_limits<double>::infinity();
    cell.Bounds[1] = cell.Bounds[3] = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < walk.size(); i += 2)
    {
      cell.Bounds[0] = std::min(cell.Bounds[0], walk[i]);
      cell.Bounds[1] = std::max(cell.Bounds[1], walk[i]);
      cell.Bounds[2] = std::min(cell.Bounds[2], walk[i + 1]);
      cell.Bounds[3] = std::max(cell.Bounds[3], walk[i + 1]);
    }
    // The paper's interior triangle size is the mean boundary sample spacing; dense samples on
    // short 1-cells (large k) would make it far finer than the input grid, which only costs
    // time: it is kept at least MinimumMeshEdgeLength.
    cell.Parameterization.TargetEdgeLength = std::max(MeanSampleSpacing(walk), this->MinimumMeshEdgeLength);
    if (cell.Parameterization.Parameterize(walk, parameters, message))
    {
      cell.Valid = true;
      break;
    }
    if (firstError.empty())
    {
      firstError = "parameterization: " + message;
      firstErrorIsMap = true;
    }
  }
  if (cell.Negligible)
  {
    cell.Error = "it has no area";
  }
  else if (!cell.Valid)
  {
    cell.Error = firstError;
    cell.MapFailed = firstErrorIsMap;
  }
}

void TwoCellReconstruction::LocateSamples(const PlanarScalarField& data, const std::vector<Index>& hints,
  std::vector<Index>& firstVertex, std::vector<Index>& vertices, std::vector<double>& parameters,
  std::vector<Index>& cellOf) const
{
  const Index count = static_cast<Index>(data.Values.size());
  cellOf.assign(count, InvalidIndex);
  parameters.assign(2 * static_cast<std::size_t>(count), 0.0);
  this->Parallel(0, count, [&](Index begin, Index end) {
    for (Index v = begin; v < end; ++v)
    {
      const Location location = this->Locate(data.Points[2 * v], data.Points[2 * v + 1], hints[v]);
      // Snapped vertices (outside every cell) would only repeat the fixed boundary curve.
      if (location.Inside)
      {
        cellOf[v] = location.Cell;
        parameters[2 * v] = location.UV[0];
        parameters[2 * v + 1] = location.UV[1];
      }
    }
  });
  GroupByIndex(cellOf, this->NumberOfCells(), firstVertex, vertices);
}

// A side split at the segment boundary nearest its middle can leave counts whose grid layout
// exceeds MaximumGridSize: a side of pieces 128 + 2 splits into 65 and 63 + 2, which with sides
// of 4 and 32 need a grid of 2080, where a cut at 64 needs 128. The corner made up there can be
// anywhere along the split side, so cuts ever farther from the middle (up to a quarter of the
// side's segments either way) are tried, the nearest one whose layout fits is taken.
bool TwoCellReconstruction::BuildBoundaryWalkCutOffMiddle(const TwoCellSides& sides,
  const OneCellSmoothingResult& smoothed, const std::vector<int>& samplesPerPiece, std::vector<double>& walk,
  std::vector<double>& parameters, MonotoneSurfaceBoundary& boundary) const
{
  int longest = 0;
  for (int split : sides.SplitSides)
  {
    if (split >= 0)
    {
      int count = 0;
      for (Index p : sides.Pieces[split])
      {
        count += smoothed.Pieces[p].Curve.Segments;
      }
      longest = std::max(longest, count);
    }
  }
  for (int distance = 1; distance <= longest / 4; ++distance)
  {
    for (int offset : { -distance, distance })
    {
      if (BuildBoundaryWalk(TwoCellSideSegments(sides, smoothed, false, offset, &samplesPerPiece),
            this->BoundarySamples, this->MaximumGridSize, walk, parameters, boundary))
      {
        return true;
      }
    }
  }
  return false;
}

// A handful of samples (tiny cells of noisy data), or far fewer samples than grid cells (a long
// boundary around a small region), pins down little the boundary does not, at the cost of
// thousands of unknowns: such cells keep the paper's interior, or are fitted only where it
// misses (Small).
TwoCellReconstruction::FitSize TwoCellReconstruction::FitSizeOf(
  const ReconstructedTwoCell& cell, std::size_t samples) const
{
  const std::size_t gridCells = static_cast<std::size_t>(cell.GridSize) * static_cast<std::size_t>(cell.GridSize);
  if (cell.GridSize > this->MaximumFittedGridSize || samples < std::max<std::size_t>(3, gridCells / 64))
  {
    return FitSize::None;
  }
  return samples < std::max<std::size_t>(8, gridCells / 16) ? FitSize::Small : FitSize::Regular;
}

bool TwoCellReconstruction::FitSurface(ReconstructedTwoCell& cell, const MonotoneSurfaceBoundary& subdivided,
  const std::vector<SurfaceSample>& samples) const
{
  std::string message;
  if (!cell.Surface.FitToSamples(samples, message, this->Fit))
  {
    return false;
  }
  // Refinement: double the grid while the fit misses the tolerance, every grid cell keeps a
  // few samples (FinestRefinedGridSize), and each doubling gains (the spaces are not nested:
  // keep the best).
  bool refined = false;
  MonotoneSurfaceBoundary boundary = subdivided;
  const int finest = this->FinestRefinedGridSize(cell.GridSize, samples.size());
  for (int n = cell.GridSize * 2; n <= finest && cell.Surface.FitReport().MaximumResidual > this->SurfaceTolerance;
       n *= 2)
  {
    MonotoneSurfaceBoundary finer;
    if (!SubdivideBoundary(boundary, n, finer))
    {
      break;
    }
    boundary = finer;
    ReconstructedTwoCell trial;
    trial.Valid = true;
    BuildSurface(trial, boundary);
    const MonotoneSurfaceFitReport& coarse = cell.Surface.FitReport();
    if (!trial.Valid || !trial.Surface.FitToSamples(samples, message, this->Fit) ||
      (trial.Surface.FitReport().MaximumResidual > 0.9 * coarse.MaximumResidual &&
        trial.Surface.FitReport().RMSResidual > 0.9 * coarse.RMSResidual))
    {
      break;
    }
    cell.Surface = std::move(trial.Surface);
    cell.GridSize = trial.GridSize;
    refined = true;
  }
  return refined;
}

bool TwoCellReconstruction::FitOnAlternativeMaps(ReconstructedTwoCell& cell, const MonotoneSurfaceBoundary& subdivided,
  const PiecewiseLinearField& field, const PlanarScalarField& data, const Index* vertices,
  std::vector<SurfaceSample>& samples) const
{
  // Every alternative starts from the mean value map's mesh, and is fitted once at the grid
  // the mean value map's fit ended with (its refinement already chose it: refining again for
  // each map would cost more than the rest of the fit).
  const TwoCellParameterization meanValue = cell.Parameterization;
  MonotoneSurfaceBoundary atGrid;
  if (!SubdivideBoundary(subdivided, cell.GridSize, atGrid))
  {
    return false;
  }
  // Both maps and fits at once (the cells come here one at a time), then kept in this order.
  const GradientWeighting weightings[2] = { GradientWeighting::AlongGradient, GradientWeighting::AlongLevelSets };
  ReconstructedTwoCell trials[2];
  std::vector<SurfaceSample> moved[2] = { samples, samples };
  bool fitted[2] = { false, false };
  this->Parallel(0, 2, [&](Index begin, Index end) {
    for (Index t = begin; t < end; ++t)
    {
      ReconstructedTwoCell& trial = trials[t];
      trial.Parameterization = meanValue;
      std::string message;
      if (!trial.Parameterization.WeightByFieldGradient(field, this->AlternativeMapStrength, weightings[t], message))
      {
        continue;
      }
      bool located = true;
      for (std::size_t k = 0; k < moved[t].size() && located; ++k)
      {
        double uv[2];
        located = trial.Parameterization.Evaluate(data.Points[2 * vertices[k]], data.Points[2 * vertices[k] + 1], uv);
        moved[t][k].U = uv[0];
        moved[t][k].V = uv[1];
      }
      trial.Valid = located;
      BuildSurface(trial, atGrid);
      fitted[t] = trial.Valid && trial.Surface.FitToSamples(moved[t], message, this->Fit) &&
        trial.Surface.FitReport().Fitted;
    }
  });
  bool kept = false;
  for (int t = 0; t < 2; ++t)
  {
    const MonotoneSurfaceFitReport& best = cell.Surface.FitReport();
    const MonotoneSurfaceFitReport& after = trials[t].Surface.FitReport();
    if (!fitted[t] || !(after.MaximumResidual < AlternativeMapGain * best.MaximumResidual) ||
      after.RMSResidual > AlternativeMapRMSGrowth * best.RMSResidual)
    {
      continue;
    }
    cell.Parameterization = std::move(trials[t].Parameterization);
    cell.Surface = std::move(trials[t].Surface);
    samples = std::move(moved[t]);
    kept = true;
  }
  return kept;
}

// The vertices of one cell two rings or more inside it, or one ring and farther than
// FarFromOneCells from its boundary (DeepVertices: no smoothed 1-cell passes next to them, so no
// node of the complex can explain a critical point there) and, for a surface, those of them
// critical for F sampled at the cell's vertices.
class TwoCellReconstruction::DeepCriticalVertices
{
public:
  DeepCriticalVertices(const TriangleMeshTopology& mesh, const std::vector<SurfaceSample>& samples,
    const Index* vertices, const std::vector<char>& ringInCell, const std::function<bool(Index)>& farFromBoundary)
    : Mesh(mesh)
    , Samples(samples)
    , Vertices(vertices)
  {
    this->Deep =
      DeepVertices(mesh, vertices, static_cast<Index>(samples.size()), ringInCell, farFromBoundary, this->ByRings);
    // Each vertex's slot among the samples, found once for every round.
    this->SlotOf.reserve(2 * samples.size());
    for (Index k = 0; k < static_cast<Index>(samples.size()); ++k)
    {
      this->SlotOf[vertices[k]] = k;
    }
  }

  bool Empty() const { return this->Deep.empty(); }

  // How good a fit with these critical samples (Find) is, compared lexicographically: those two
  // rings inside first, then those only far from the boundary (the band of 2-3 spacings along
  // the 1-cells comes second: counted together, a fit that cleared the band could win with a
  // new crest deep inside).
  using Score = std::pair<std::size_t, std::size_t>;
  Score ScoreOf(const std::vector<Index>& critical) const
  {
    Score score(0, 0);
    for (Index k : critical)
    {
      ++(this->ByRings[k] ? score.first : score.second);
    }
    return score;
  }

  // Whether a fit with `score` and largest residual `residual` is better than the best so far
  // (`fewest`): a lower score, but one lower in the band alone only within BandResidualGrowth
  // of the first fit's largest residual (`firstResidual`): stiffened there without that bound,
  // a Rainier crop's cell missed the data by 29 % more.
  static bool Better(const Score& score, const Score& fewest, double residual, double firstResidual)
  {
    return score < fewest && (score.first < fewest.first || residual <= BandResidualGrowth * firstResidual);
  }

  // Of `critical`, those the rounds treat now: the ones two rings inside while there are any
  // (spots and orders in the band too made the rounds' fits miss the data by more than they
  // allow, and left crests deep inside), then the others.
  std::vector<Index> FirstConcern(const std::vector<Index>& critical) const
  {
    std::vector<Index> first;
    std::copy_if(critical.begin(), critical.end(), std::back_inserter(first), [this](Index k) { return this->ByRings[k] != 0; });
    return first.empty() ? critical : first;
  }

  // The samples (slots) of the deep vertices critical for `surface`; its values at every sample
  // are kept (Values) for RiseDirection.
  std::vector<Index> Find(const MonotoneSibsonSurface& surface)
  {
    surface.EvaluateSamples(this->Samples, this->Values);
    const auto value = [&](Index w) { return this->Values[this->SlotOf.at(w)]; };
    std::vector<Index> critical;
    for (Index k : this->Deep)
    {
      if (IsCriticalVertex(this->Mesh, this->Vertices[k], value))
      {
        critical.push_back(k);
      }
    }
    return critical;
  }

  // The samples of the vertices within `rings` rings of deep sample k's vertex that lie in the
  // cell (the first ring always does; the second of a vertex deep by its distance to the
  // boundary need not), k excepted.
  std::vector<Index> Around(Index k, int rings) const
  {
    std::vector<Index> around = { this->Vertices[k] };
    for (int ring = 0, from = 0; ring < rings; ++ring)
    {
      const int to = static_cast<int>(around.size());
      for (int a = from; a < to; ++a)
      {
        const Index v = around[a];
        for (Index i = this->Mesh.VertexTriangleBegin(v); i < this->Mesh.VertexTriangleEnd(v); ++i)
        {
          for (Index w : this->Mesh.TriangleVertices[this->Mesh.VertexTriangle(i)])
          {
            if (std::find(around.begin(), around.end(), w) == around.end())
            {
              around.push_back(w);
            }
          }
        }
      }
      from = to;
    }
    std::vector<Index> slots;
    for (std::size_t a = 1; a < around.size(); ++a)
    {
      const auto slot = this->SlotOf.find(around[a]);
      if (slot != this->SlotOf.end())
      {
        slots.push_back(slot->second);
      }
    }
    return slots;
  }

  // Whether the images in the square of sample k's neighbours wind around its own (each
  // incident triangle turns by the signed angle its far edge subtends; a fold of the sampled
  // map turns by 0): only then can an order of its neighbours make it regular.
  bool Surrounded(Index k) const
  {
    const Index v = this->Vertices[k];
    double turn = 0;
    for (Index i = this->Mesh.VertexTriangleBegin(v); i < this->Mesh.VertexTriangleEnd(v); ++i)
    {
      const auto& t = this->Mesh.TriangleVertices[this->Mesh.VertexTriangle(i)];
      const int at = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      const SurfaceSample& a = this->Samples[this->SlotOf.at(t[(at + 1) % 3])];
      const SurfaceSample& b = this->Samples[this->SlotOf.at(t[(at + 2) % 3])];
      const double au = a.U - this->Samples[k].U, av = a.V - this->Samples[k].V;
      const double bu = b.U - this->Samples[k].U, bv = b.V - this->Samples[k].V;
      turn += std::atan2(au * bv - av * bu, au * bu + av * bv);
    }
    return std::abs(turn) > M_PI;
  }

  // The unit gradient in the square of the plane fitted by least squares to the last surface's
  // values (Find) at sample k and the two rings around it; (1, 1) / sqrt 2, F's rise across
  // the square, where the plane is level.
  void RiseDirection(Index k, double direction[2]) const
  {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    std::vector<Index> slots = this->Around(k, 2);
    slots.push_back(k);
    for (Index w : slots)
    {
      const Eigen::Vector3d row(1, this->Samples[w].U - this->Samples[k].U, this->Samples[w].V - this->Samples[k].V);
      normal += row * row.transpose();
      moment += this->Values[w] * row;
    }
    const Eigen::Vector3d plane = normal.ldlt().solve(moment);
    const double length = std::hypot(plane[1], plane[2]);
    direction[0] = direction[1] = std::sqrt(0.5);
    if (std::isfinite(length) && length > 0)
    {
      direction[0] = plane[1] / length;
      direction[1] = plane[2] / length;
    }
  }

private:
  const TriangleMeshTopology& Mesh;
  const std::vector<SurfaceSample>& Samples;
  const Index* Vertices;
  std::vector<Index> Deep;
  std::vector<char> ByRings; // per sample: 1 if deep by its two rings, 0 by its distance alone
  std::unordered_map<Index, Index> SlotOf;
  std::vector<double> Values;
};

// The aim at p >= 0 and q >= 0 is the fit's own choice, not the guarantee's: where the data falls
// across the square from one side to the opposite one, it holds the whole cell off the data (a
// Maunga Whau crop at 2 %: a cell 10-18 m above it, RMS 3.7 % of the range). Released only
// where the fit misses most and the release takes no vertex of the cell to a critical point
// the stiffening would have to take out again.
bool TwoCellReconstruction::ReleaseAxisAim(ReconstructedTwoCell& cell, const std::vector<SurfaceSample>& samples,
  DeepCriticalVertices& deep, MonotoneSurfaceFitOptions& options) const
{
  const MonotoneSurfaceFitReport& fitted = cell.Surface.FitReport();
  if (!options.IncreasingAlongAxes || this->AxisAimTrigger <= 0 || this->SurfaceTolerance <= 0 ||
    fitted.MaximumResidual <= this->AxisAimTrigger * this->SurfaceTolerance)
  {
    return false;
  }
  MonotoneSurfaceFitOptions free = options;
  free.IncreasingAlongAxes = false;
  MonotoneSibsonSurface trial = cell.Surface; // the fit it has: feasible for every row
  std::string message;
  if (!trial.FitToSamples(samples, message, free) || !trial.FitReport().Fitted ||
    trial.FitReport().MaximumResidual >= AlternativeMapGain * fitted.MaximumResidual ||
    trial.FitReport().RMSResidual > fitted.RMSResidual ||
    (trial.FitReport().RMSResidual >= AxisAimRMSGain * fitted.RMSResidual &&
      deep.ScoreOf(deep.Find(cell.Surface)) < deep.ScoreOf(deep.Find(trial))))
  {
    return false;
  }
  cell.Surface = std::move(trial);
  options = free;
  return true;
}

// A monotone F has no critical point, but sampled at the vertices, a ridge or a trough that
// rises slowly along its crest compared with its flanks breaks into pairs of critical points:
// the fit makes such crests where the monotonicity rows bind against data that falls (a
// cancelled pit filled, its rim kept). Stiffening the thin plate there widens them until the
// vertices see the rise; where that is not enough, the samples around the points left are
// ordered (OrderWhereSamplingBreaks).
int TwoCellReconstruction::StiffenWhereSamplingBreaks(ReconstructedTwoCell& cell,
  const std::vector<SurfaceSample>& samples, const Index* vertices, const std::vector<char>& ringInCell,
  const std::vector<double>& points) const
{
  // Made only if some vertex of the cell asks (its ring in the cell, its second ring not).
  std::unique_ptr<PolylineProximity> boundary;
  std::function<bool(Index)> farFromBoundary;
  const TwoCellMesh& mesh = cell.Parameterization.GetMesh();
  if (this->FarFromOneCells > 0 && mesh.BoundaryCount > 1)
  {
    farFromBoundary = [&](Index v) {
      if (!boundary)
      {
        boundary = std::make_unique<PolylineProximity>(mesh.Points, mesh.BoundaryCount, this->FarFromOneCells);
      }
      return !boundary->Within(&points[2 * static_cast<std::size_t>(v)]);
    };
  }
  DeepCriticalVertices deep(*this->Mesh, samples, vertices, ringInCell, farFromBoundary);
  MonotoneSurfaceFitOptions options = this->Fit;
  int outcome = this->ReleaseAxisAim(cell, samples, deep, options) ? AxisFreeFit : 0;
  if (deep.Empty() || this->StiffeningRounds + this->OrderingRounds <= 0)
  {
    return outcome;
  }
  std::vector<Index> critical = deep.Find(cell.Surface);
  DeepCriticalVertices::Score fewest = deep.ScoreOf(critical);
  options.AcceptedResidualGrowth = this->StiffeningResidualGrowth;
  MonotoneSurfaceFitOptions kept = options;
  const MonotoneSibsonSurface first = cell.Surface;
  double step = this->StiffeningFactor;
  for (int round = 0, stale = 0; round < this->StiffeningRounds && !critical.empty(); ++round)
  {
    // Stiffer where it was stiffened before, and around the points the last fit left (a crest
    // can move aside instead of widening).
    const MonotoneSurfaceFitOptions before = options;
    for (MonotoneSurfaceFitOptions::StiffSpot& spot : options.StiffSpots)
    {
      spot.Factor *= step;
    }
    for (Index k : deep.FirstConcern(critical))
    {
      options.StiffSpots.push_back({ samples[k].U, samples[k].V, step });
    }
    // From the first fit (it meets every row), kept within the allowed growth of its residual.
    // A refused round is tried again with the square root of its step (10, 3.2, 1.8), and the
    // later rounds keep the smaller step; below 1.5 the rounds end.
    MonotoneSibsonSurface trial = first;
    std::string message;
    if (!trial.FitToSamples(samples, message, options) || !trial.FitReport().Fitted)
    {
      options = before;
      step = std::sqrt(step);
      if (step < 1.5)
      {
        break;
      }
      continue;
    }
    critical = deep.Find(trial);
    const DeepCriticalVertices::Score score = deep.ScoreOf(critical);
    if (DeepCriticalVertices::Better(score, fewest, trial.FitReport().MaximumResidual, first.FitReport().MaximumResidual))
    {
      fewest = score;
      cell.Surface = std::move(trial);
      kept = options;
      outcome |= StiffenedFit;
      stale = 0;
    }
    else if (++stale == 2)
    {
      break; // points that stiffening does not move (a kink of Phi, a crest the rows force)
    }
  }
  if (fewest != DeepCriticalVertices::Score(0, 0) && this->OrderingRounds > 0 &&
    this->OrderWhereSamplingBreaks(cell, first, kept, deep, samples))
  {
    outcome |= OrderedFit;
  }
  return outcome;
}

// The points stiffening leaves are mostly crests too narrow or too level for the thin plate to
// widen at an acceptable cost. Their values are ordered instead: around each, every neighbour
// ahead along the local rise (the gradient of the plane fitted to the last fit's values over
// two rings, which on a crest is the rise along its top: the flanks cancel) is asked to be
// higher than the vertex, every one behind it lower, each by OrderingSlope x the cell's sample
// range x its distance along that direction in the square. A linear order of a star-shaped
// link has one arc above and one below: a regular vertex. Neighbouring points' directions are
// close, so their orders agree; the rows are only aimed at (ConstrainedLeastSquares), and a fit
// is kept only with fewer such points.
bool TwoCellReconstruction::OrderWhereSamplingBreaks(ReconstructedTwoCell& cell, const MonotoneSibsonSurface& first,
  MonotoneSurfaceFitOptions options, DeepCriticalVertices& deep, const std::vector<SurfaceSample>& samples) const
{
  double lowest = std::numeric_limits<double>::max(), highest = -lowest;
  for (const SurfaceSample& sample : samples)
  {
    lowest = std::min(lowest, sample.Value);
    highest = std::max(highest, sample.Value);
  }
  const double slope = this->OrderingSlope * (highest - lowest);
  // The rows need not hold at the start, so the fit may end above the first fit's objective.
  options.Solver.KeepStartIfLower = false;
  std::vector<Index> critical = deep.Find(cell.Surface);
  DeepCriticalVertices::Score fewest = deep.ScoreOf(critical);
  std::unordered_map<Index, std::vector<MonotoneSurfaceFitOptions::SampleOrder>> ordersAt;
  bool ordered = false;
  for (int round = 0, stale = 0; round < this->OrderingRounds && stale < 2; ++round)
  {
    // The values of the fit that left these points (deep.Values) set each point's direction;
    // a point met again gets its orders anew. Points where the sampled map folds are left.
    critical.erase(std::remove_if(critical.begin(), critical.end(), [&](Index k) { return !deep.Surrounded(k); }),
      critical.end());
    if (critical.empty())
    {
      break;
    }
    for (Index k : deep.FirstConcern(critical))
    {
      double direction[2];
      deep.RiseDirection(k, direction);
      std::vector<MonotoneSurfaceFitOptions::SampleOrder>& orders = ordersAt[k];
      orders.clear();
      for (Index w : deep.Around(k, 1))
      {
        const double along =
          direction[0] * (samples[w].U - samples[k].U) + direction[1] * (samples[w].V - samples[k].V);
        const int vertex = static_cast<int>(k), neighbour = static_cast<int>(w);
        orders.push_back(along > 0 ? MonotoneSurfaceFitOptions::SampleOrder{ vertex, neighbour, slope * along }
                                   : MonotoneSurfaceFitOptions::SampleOrder{ neighbour, vertex, -slope * along });
      }
    }
    options.SampleOrders.clear();
    for (const auto& entry : ordersAt)
    {
      options.SampleOrders.insert(options.SampleOrders.end(), entry.second.begin(), entry.second.end());
    }
    MonotoneSibsonSurface trial = first;
    std::string message;
    if (!trial.FitToSamples(samples, message, options) || !trial.FitReport().Fitted)
    {
      break;
    }
    critical = deep.Find(trial);
    const DeepCriticalVertices::Score score = deep.ScoreOf(critical);
    if (DeepCriticalVertices::Better(score, fewest, trial.FitReport().MaximumResidual, first.FitReport().MaximumResidual))
    {
      fewest = score;
      cell.Surface = std::move(trial);
      ordered = true;
      stale = 0;
    }
    else
    {
      ++stale;
    }
  }
  return ordered;
}

int TwoCellReconstruction::FinestRefinedGridSize(int gridSize, std::size_t samples) const
{
  int n = gridSize;
  while (this->SurfaceTolerance > 0 && n > 0 && this->GridHasSamplesFor(2 * n, samples))
  {
    n *= 2;
  }
  return n;
}

bool TwoCellReconstruction::SurfacesFitInMemory(
  const std::vector<MonotoneSurfaceBoundary>& boundaries, const std::vector<Index>& firstVertex, std::string& error) const
{
  if (this->MemoryBudget <= 0)
  {
    return true;
  }
  double triangles = 0;
  std::size_t finest = 0;
  for (std::size_t c = 0; c < boundaries.size(); ++c)
  {
    const double n = static_cast<double>(boundaries[c].Bottom.size());
    finest = std::max(finest, boundaries[c].Bottom.size());
    // Fitted cells may be refined up to FinestRefinedGridSize.
    const double refined = !firstVertex.empty() && n <= this->MaximumFittedGridSize
      ? this->FinestRefinedGridSize(static_cast<int>(n), static_cast<std::size_t>(firstVertex[c + 1] - firstVertex[c]))
      : n;
    triangles += 4 * refined * refined;
  }
  const double needed = triangles * BytesPerBezierTriangle;
  if (needed <= this->MemoryBudget)
  {
    return true;
  }
  std::ostringstream message;
  message.precision(3);
  message << "the 2-cells' surfaces need about " << needed / 1e9 << " GB (" << triangles / 1e6
          << " million Bezier triangles, grids up to " << finest << " x " << finest << "), more than the "
          << this->MemoryBudget / 1e9 << " GB available to them; choose fewer Curve Segments or a "
          << "higher Persistence Threshold";
  error = message.str();
  return false;
}

// The monotone Sibson surface on the square from the cell's subdivided sides.
void TwoCellReconstruction::BuildSurface(ReconstructedTwoCell& cell, const MonotoneSurfaceBoundary& subdivided)
{
  if (!cell.Valid)
  {
    return;
  }
  const int count = static_cast<int>(subdivided.Bottom.size());
  std::string message;
  MonotoneSurfaceOptions options;
  // Subdivision and the B-spline conversion round the segment joins by ~1e-12 relative to the
  // values, which can exceed 1e-9 of a small cell's own range; at piece joins the heights'
  // zero end slopes hold to the linear program's rounding, ~1e-11 of the values: a cell of a
  // Delaunay mesh at 0.5 % whose values all lie within 2.3e-11 (of magnitude 0.12) failed on a
  // mismatch of 1.2e-12.
  options.ConsistencyTolerance = 1e-7;
  options.RoundingTolerance = 1e-10;
  // A cell whose whole range is at that rounding level (a Delaunay mesh at 2 %: values 0.211
  // within 2.6e-11) has sides that differ by a fifth of it (4.8e-12, from a junction's zero
  // end slope); still 1e-10 of the values at most, so rounding: half of the range is allowed.
  options.RoundingShareOfRange = 0.5;
  // A flat valley floor or ridge top along the 1-cells (see MonotoneSurfaceOptions).
  options.FlatAcrossBoundary = true;
  // False also when the conditions are infeasible somewhere: the surface is then built anyway
  // and its violating cells are counted (Surface.Report()).
  cell.Surface.Build(subdivided, message, options);
  if (cell.Surface.GetGridSize() != count)
  {
    // Malformed boundary data (not merely infeasible conditions): no surface at all.
    cell.Valid = false;
    cell.Error = "surface: " + message;
    return;
  }
  cell.GridSize = count;
}

void TwoCellReconstruction::Summarize()
{
  auto& s = this->Summary;
  s.Cells = static_cast<Index>(this->Cells.size());
  for (const auto& cell : this->Cells)
  {
    if (!cell->Valid)
    {
      ++(cell->Negligible ? s.NegligibleCells : s.FailedCells);
      continue;
    }
    s.SlitCells += cell->Sides.Slit ? 1 : 0;
    s.PinchedCells += cell->Parameterization.GetMesh().OpenedPinches > 0 ? 1 : 0;
    s.ResampledCells += cell->Resampled ? 1 : 0;
    s.OutsideSlitCells += cell->Parameterization.GetMesh().OutsideSlits > 0 ? 1 : 0;
    s.ShiftedCorners += (cell->Sides.MinimumShifted ? 1 : 0) + (cell->Sides.MaximumShifted ? 1 : 0);
    const MonotoneSurfaceReport& r = cell->Surface.Report();
    s.ViolatingPatches += r.ViolatingCells;
    s.LinearizedDiagonals += r.LinearizedDiagonals;
    s.FittedCells += cell->Surface.FitReport().Fitted ? 1 : 0;
    s.AdjustedDiagonals += r.AdjustedDiagonals;
    s.MeshTriangles += cell->Parameterization.GetMesh().NumberOfTriangles();
    s.CrowdedTriangles += cell->Parameterization.GetMesh().CrowdedTriangles;
    s.BezierTriangles += 4 * cell->GridSize * cell->GridSize;
    s.MaximumGridSize = std::max(s.MaximumGridSize, cell->GridSize);
  }
}

void TwoCellReconstruction::BuildCellLocator()
{
  double box[4] = { std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
    std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity() };
  Index valid = 0;
  for (const auto& cell : this->Cells)
  {
    if (cell->Valid)
    {
      ++valid;
      box[0] = std::min(box[0], cell->Bounds[0]);
      box[1] = std::max(box[1], cell->Bounds[1]);
      box[2] = std::min(box[2], cell->Bounds[2]);
      box[3] = std::max(box[3], cell->Bounds[3]);
    }
  }
  this->BucketStart.assign(1, 0);
  this->BucketCells.clear();
  this->Buckets[0] = this->Buckets[1] = 0;
  if (valid == 0)
  {
    return;
  }
  const double diagonal = std::hypot(box[1] - box[0], box[3] - box[2]);
  this->Snap = this->SnapDistance > 0 ? this->SnapDistance : 1e-3 * diagonal;
  box[0] -= this->Snap;
  box[1] += this->Snap;
  box[2] -= this->Snap;
  box[3] += this->Snap;
  const int side = std::max(1, static_cast<int>(std::ceil(2 * std::sqrt(static_cast<double>(valid)))));
  this->Buckets[0] = this->Buckets[1] = side;
  this->Origin[0] = box[0];
  this->Origin[1] = box[2];
  this->BucketSize[0] = std::max((box[1] - box[0]) / side, 1e-300);
  this->BucketSize[1] = std::max((box[3] - box[2]) / side, 1e-300);
  // The (bucket, cell) pairs in the order of the cells, as compressed rows (a vector per bucket,
  // four per cell, was most of this on noise).
  const auto bucketAlong = [&](double coordinate, int axis) {
    return std::clamp(static_cast<int>((coordinate - box[2 * axis]) / this->BucketSize[axis]), 0, side - 1);
  };
  std::vector<std::array<Index, 2>> cellInBucket;
  for (Index c = 0; c < this->NumberOfCells(); ++c)
  {
    const auto& cell = *this->Cells[c];
    if (!cell.Valid)
    {
      continue;
    }
    const int i0 = bucketAlong(cell.Bounds[0] - this->Snap, 0), i1 = bucketAlong(cell.Bounds[1] + this->Snap, 0);
    const int j0 = bucketAlong(cell.Bounds[2] - this->Snap, 1), j1 = bucketAlong(cell.Bounds[3] + this->Snap, 1);
    for (int j = j0; j <= j1; ++j)
    {
      for (int i = i0; i <= i1; ++i)
      {
        cellInBucket.push_back({ j * side + i, c });
      }
    }
  }
  CompressedGraph buckets(side * side, cellInBucket);
  this->BucketStart = std::move(buckets.Offsets);
  this->BucketCells = std::move(buckets.Targets);
}

bool TwoCellReconstruction::LocateInCell(Index c, double x, double y, double uv[2]) const
{
  const ReconstructedTwoCell& cell = *this->Cells[c];
  const double tolerance = 1e-9 * std::max(cell.Bounds[1] - cell.Bounds[0], cell.Bounds[3] - cell.Bounds[2]);
  if (!cell.Valid || x < cell.Bounds[0] - tolerance || x > cell.Bounds[1] + tolerance ||
    y < cell.Bounds[2] - tolerance || y > cell.Bounds[3] + tolerance)
  {
    return false;
  }
  return cell.Parameterization.Evaluate(x, y, uv);
}

TwoCellReconstruction::Location TwoCellReconstruction::Locate(double x, double y, Index hint) const
{
  Location result;
  if (hint >= 0 && hint < this->NumberOfCells() && this->LocateInCell(hint, x, y, result.UV))
  {
    result.Cell = hint;
    result.Inside = true;
    return result;
  }
  if (this->Buckets[0] == 0)
  {
    return result;
  }
  const int i = static_cast<int>(std::floor((x - this->Origin[0]) / this->BucketSize[0]));
  const int j = static_cast<int>(std::floor((y - this->Origin[1]) / this->BucketSize[1]));
  if (i < 0 || j < 0 || i >= this->Buckets[0] || j >= this->Buckets[1])
  {
    return result;
  }
  const std::size_t bucket = static_cast<std::size_t>(j) * this->Buckets[0] + i;
  const Index* begin = this->BucketCells.data() + this->BucketStart[bucket];
  const Index* end = this->BucketCells.data() + this->BucketStart[bucket + 1];
  for (const Index* c = begin; c != end; ++c)
  {
    if (*c != hint && this->LocateInCell(*c, x, y, result.UV))
    {
      result.Cell = *c;
      result.Inside = true;
      return result;
    }
  }
  // Outside every cell: the smoothed boundary of the domain or a rounding gap. The nearest
  // boundary point within the snap distance stands in.
  double best = this->Snap * this->Snap;
  for (const Index* c = begin; c != end; ++c)
  {
    const ReconstructedTwoCell& cell = *this->Cells[*c];
    const TwoCellMesh& mesh = cell.Parameterization.GetMesh();
    const Index count = mesh.BoundaryCount;
    for (Index k = 0; k < count; ++k)
    {
      const Index l = (k + 1) % count;
      double fraction;
      const double d2 = SegmentDistance2(&mesh.Points[2 * k], &mesh.Points[2 * l], x, y, fraction);
      if (d2 <= best)
      {
        best = d2;
        result.UV[0] = (1 - fraction) * mesh.Parameters[2 * k] + fraction * mesh.Parameters[2 * l];
        result.UV[1] = (1 - fraction) * mesh.Parameters[2 * k + 1] + fraction * mesh.Parameters[2 * l + 1];
        result.Cell = *c;
        result.Inside = false;
      }
    }
  }
  return result;
}

TwoCellReconstruction::Evaluation TwoCellReconstruction::Evaluate(double x, double y, Index hint) const
{
  const Location location = this->Locate(x, y, hint);
  Evaluation result;
  result.Cell = location.Cell;
  result.Inside = location.Inside;
  if (location.Cell != InvalidIndex)
  {
    result.Value = this->Cells[location.Cell]->Surface.Evaluate(location.UV[0], location.UV[1]);
  }
  return result;
}

std::vector<PlanarBezierTriangle> TwoCellReconstruction::PlanarBezierTriangles(Index c) const
{
  std::vector<PlanarBezierTriangle> result;
  const ReconstructedTwoCell& cell = *this->Cells[c];
  if (!cell.Valid)
  {
    return result;
  }
  const auto& toControl = LatticeToControl();
  const std::vector<SurfaceBezierTriangle> patches = cell.Surface.GetBezierTriangles();
  result.resize(patches.size());
  // The (u, v) of a polynomial triangle's control points are its lattice points: for the Sibson
  // split of an N x N grid, points of the (6N + 1)^2 lattice, most of them shared by two to
  // eight triangles. Each is mapped back to (x, y) once, into a dense table of the lattice (a
  // hash map of them was a third of this function on the Rainier crop; the table holds 36 N^2
  // points where about 25 N^2 are used, fewer bytes than the map's nodes).
  const int steps = 6 * cell.Surface.GetGridSize();
  const std::size_t side = static_cast<std::size_t>(steps) + 1;
  const TwoCellParameterization::Inverse phiInverse = cell.Parameterization.MakeInverse();
  std::vector<std::array<double, 2>> mapped(side * side);
  std::vector<char> done(side * side, 0);
  const auto inverse = [&](double u, double v) {
    const std::size_t key = static_cast<std::size_t>(std::llround(std::clamp(u, 0.0, 1.0) * steps)) * side +
      static_cast<std::size_t>(std::llround(std::clamp(v, 0.0, 1.0) * steps));
    if (!done[key])
    {
      done[key] = 1;
      if (!phiInverse.Evaluate(u, v, mapped[key].data()))
      {
        // Only rounding can put a lattice point outside the square's mesh; clamp it in.
        phiInverse.Evaluate(std::clamp(u, 0.0, 1.0), std::clamp(v, 0.0, 1.0), mapped[key].data());
      }
    }
    return mapped[key];
  };
  Eigen::Matrix<double, 10, 2> lattice;
  for (std::size_t t = 0; t < patches.size(); ++t)
  {
    for (int m = 0; m < 10; ++m)
    {
      const std::array<double, 2> xy = inverse(patches[t].Points[m][0], patches[t].Points[m][1]);
      lattice(m, 0) = xy[0];
      lattice(m, 1) = xy[1];
    }
    const Eigen::Matrix<double, 10, 2> control = toControl * lattice;
    for (int m = 0; m < 10; ++m)
    {
      result[t].Points[m] = { { control(m, 0), control(m, 1), patches[t].Points[m][2] } };
    }
  }
  return result;
}
} // namespace topospline
