#include "TwoCellParameterization.h"

#include "PiecewiseLinearField.h"
#include "PlanarGeometry.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_no_edge_refinement_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Sparse>
#include <Eigen/SparseLU>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <iterator>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <tuple>

namespace topospline
{
namespace
{
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
// The vertex info marks boundary vertices (InvalidIndex: Steiner point), then holds the output
// index of Steiner points; it is reset before every use because the mesher creates Steiner
// vertices with an uninitialized info.
using VertexBase = CGAL::Delaunay_mesh_vertex_base_2<Kernel, CGAL::Triangulation_vertex_base_with_info_2<Index, Kernel>>;
// The face info holds, per corner at a boundary vertex, the sample (the visit of that vertex
// by the boundary walk) whose side of the slits the face lies on: that is how the mesh is cut
// open along slits without touching the triangulation. InvalidIndex at Steiner points.
using FaceInfo = std::array<Index, 3>;
using FaceBase = CGAL::Delaunay_mesh_face_base_2<Kernel,
  CGAL::Constrained_triangulation_face_base_2<Kernel, CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel>>>;
using DataStructure = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Triangulation = CGAL::Constrained_Delaunay_triangulation_2<Kernel, DataStructure>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<Triangulation>;
using Mesher = CGAL::Delaunay_mesher_no_edge_refinement_2<Triangulation, Criteria>;
using VertexHandle = Triangulation::Vertex_handle;
using FaceHandle = Triangulation::Face_handle;
using Point = Kernel::Point_2;

// (u, v) values on the border are compared with this slack: the caller computes them from
// curve parameters, so a side's coordinate may be off by rounding.
constexpr double BorderTolerance = 1e-12;

// Bits of the sides of the unit square that (u, v) lies on; corners have two bits.
int SideMask(double u, double v)
{
  int mask = 0;
  if (std::abs(v) <= BorderTolerance)
  {
    mask |= 1; // bottom
  }
  if (std::abs(u - 1) <= BorderTolerance)
  {
    mask |= 2; // right
  }
  if (std::abs(v - 1) <= BorderTolerance)
  {
    mask |= 4; // top
  }
  if (std::abs(u) <= BorderTolerance)
  {
    mask |= 8; // left
  }
  return mask;
}

// Position along the border, counter-clockwise from (0,0), in [0, 4).
double PerimeterCoordinate(double u, double v, int mask)
{
  if (mask & 1)
  {
    return u;
  }
  if (mask & 2)
  {
    return 1 + v;
  }
  if (mask & 4)
  {
    return 2 + (1 - u);
  }
  return 3 + (1 - v);
}

// tan(a/2) for the angle a between vectors (ax, ay) and (bx, by): sin a / (1 + cos a) for acute
// angles, (1 - cos a) / sin a for obtuse ones, so that neither cancels (a point split onto an
// edge next to a thin channel sees that edge's neighbours at almost 180 degrees).
double HalfAngleTangent(double ax, double ay, double bx, double by)
{
  const double cross = std::abs(ax * by - ay * bx);
  const double dot = ax * bx + ay * by;
  const double lengths = std::hypot(ax, ay) * std::hypot(bx, by);
  return dot >= 0 ? cross / (lengths + dot) : (lengths - dot) / cross;
}

// What CGAL::refine_Delaunay_mesh_2_without_edge_refinement(cdt, criteria) does, except that
// clear_seeds() initializes the mesher's seeds_mark flag, which CGAL 5.5's constructor leaves
// uninitialized (harmless, but UBSan reports the load). The domain is (re-)marked from scratch:
// the faces enclosed by constraints.
void Refine(Triangulation& cdt, const Criteria& criteria)
{
  Mesher mesher(cdt, criteria);
  mesher.clear_seeds();
  mesher.refine_mesh();
}

void ResetVertexIndices(Triangulation& cdt, const std::vector<VertexHandle>& boundary)
{
  for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
  {
    v->info() = InvalidIndex;
  }
  for (std::size_t i = 0; i < boundary.size(); ++i)
  {
    boundary[i]->info() = static_cast<Index>(i);
  }
}

// The boundary walk with equal coordinates identified.
struct BoundaryGraph
{
  std::vector<Index> PointOf;      // sample -> distinct point
  std::size_t PointCount = 0;
  std::vector<Index> Loop;         // one sample per outer loop point, in walk order
  std::vector<Index> Pinched;      // loop samples on a point the loop visits twice (FindOuterLoop)
  // Distinct undirected edges as point pairs: the Loop.size() loop edges, then the slit edges.
  std::vector<std::pair<Index, Index>> Edges;
};

// Numbers the distinct points of the walk and refuses zero-length edges. Exact comparison: a
// slit retraces bit-identical samples.
bool IdentifyEqualPoints(const double* xy, std::size_t n, BoundaryGraph& graph, std::string& error)
{
  std::vector<Index> order(n);
  std::iota(order.begin(), order.end(), 0);
  auto less = [xy](Index a, Index b) {
    return std::make_tuple(xy[2 * a], xy[2 * a + 1], a) < std::make_tuple(xy[2 * b], xy[2 * b + 1], b);
  };
  std::sort(order.begin(), order.end(), less);
  graph.PointOf.assign(n, 0);
  graph.PointCount = 0;
  for (std::size_t k = 0; k < n; ++k)
  {
    const Index i = order[k];
    if (k == 0 || xy[2 * i] != xy[2 * order[k - 1]] || xy[2 * i + 1] != xy[2 * order[k - 1] + 1])
    {
      ++graph.PointCount;
    }
    graph.PointOf[i] = static_cast<Index>(graph.PointCount - 1);
  }
  const std::vector<Index>& point = graph.PointOf;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (point[i] == point[(i + 1) % n])
    {
      std::ostringstream message;
      message << "TwoCellParameterization: samples " << i << " and " << (i + 1) % n
              << " are the same point (zero-length boundary edge)";
      error = message.str();
      return false;
    }
  }
  return true;
}

// The outer loop: the walk with its back-and-forth steps x y x -> x cancelled along the
// sequence, then across its wrap-around, until none is left. It must visit distinct points.
bool FindOuterLoop(std::size_t n, BoundaryGraph& graph, std::string& error)
{
  const std::vector<Index>& point = graph.PointOf;
  std::vector<Index> stack;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (stack.size() >= 2 && point[stack[stack.size() - 2]] == point[i])
    {
      stack.pop_back();
    }
    else
    {
      stack.push_back(static_cast<Index>(i));
    }
  }
  std::size_t head = 0;
  while (stack.size() - head >= 3)
  {
    if (point[stack[stack.size() - 2]] == point[stack[head]])
    {
      stack.resize(stack.size() - 2); // ... x y | x ...
    }
    else if (point[stack.back()] == point[stack[head + 1]])
    {
      head += 2; // ... x | y x ...
    }
    else
    {
      break;
    }
  }
  graph.Loop.assign(stack.begin() + head, stack.end());
  if (graph.Loop.size() < 3)
  {
    error = "TwoCellParameterization: the boundary encloses no area (it only runs out and back along slits)";
    return false;
  }
  std::vector<int> visits(graph.PointCount, 0);
  for (const Index s : graph.Loop)
  {
    ++visits[point[s]];
  }
  graph.Pinched.clear();
  for (const Index s : graph.Loop)
  {
    if (visits[point[s]] > 1)
    {
      graph.Pinched.push_back(s);
    }
  }
  if (!graph.Pinched.empty())
  {
    std::ostringstream message;
    message << "TwoCellParameterization: the boundary touches itself at sample " << graph.Pinched.front()
            << " (a repeated point that is not on a slit retraced straight back)";
    error = message.str();
    return false;
  }
  return true;
}

// A pinched cell: its outer loop passes one point twice. Uniform noise makes two kinds: two
// lobes touching there (a cell in two opposite sectors of one saddle), and a lens of two
// 1-cells between the same nodes that the cell wraps around, touching it at one end (a hole
// reached along a stem of no length; a stem of some length is the same, pinched at both of its
// ends). Either way the cell is still a disk, but its boundary is no simple polygon. Each visit
// is moved off the point by 1e-3 of its shorter edge, along the bisector of one of its two
// corners: the inner one (on the cell's side of the walk) if the other visit's edges lie
// outside it (the lens: a slot of that width then joins it to the outside), else the outer one
// (touching lobes: a neck of that width then joins them). The loop becomes simple, each visit
// keeps its (u, v), and the geometry moves by a thousandth of a sample spacing at one point
// (vertices there are snapped onto the nearest cell, as along every smoothed boundary). Only
// points visited exactly twice, whose visits do not cross (one visit's edges on both sides of
// the other's corner: a bow tie): false otherwise, and nothing is moved. `orientation`: +1 for
// a counter-clockwise walk.
bool OpenPinches(const BoundaryGraph& graph, std::size_t n, int orientation, std::vector<double>& xy)
{
  const std::vector<double> original = xy;
  const double pi = std::acos(-1.0);
  auto direction = [&original](std::size_t from, std::size_t to) {
    return std::atan2(original[2 * to + 1] - original[2 * from + 1], original[2 * to] - original[2 * from]);
  };
  // The angle swept from direction `from` to direction `to` on the cell's side of the walk,
  // in (0, 2 pi]: counter-clockwise for a counter-clockwise walk.
  auto sweep = [orientation, pi](double from, double to) {
    double angle = std::remainder((to - from) * orientation, 2 * pi);
    return angle <= 0 ? angle + 2 * pi : angle;
  };
  // Per visit: the directions to its next and previous samples.
  auto rays = [&](std::size_t i) {
    return std::array<double, 2>{ { direction(i, (i + 1) % n), direction(i, (i + n - 1) % n) } };
  };
  std::vector<std::vector<std::size_t>> visits(graph.PointCount);
  for (const Index s : graph.Pinched)
  {
    visits[graph.PointOf[s]].push_back(static_cast<std::size_t>(s));
  }
  std::vector<std::pair<std::size_t, double>> moves; // (sample, direction it moves in)
  for (const auto& pair : visits)
  {
    if (pair.empty())
    {
      continue;
    }
    if (pair.size() != 2)
    {
      return false;
    }
    for (int k = 0; k < 2; ++k)
    {
      const auto own = rays(pair[k]), other = rays(pair[1 - k]);
      const double corner = sweep(own[0], own[1]);
      const int inside = (sweep(own[0], other[0]) < corner ? 1 : 0) + (sweep(own[0], other[1]) < corner ? 1 : 0);
      if (inside == 1)
      {
        return false; // the visits cross
      }
      // the bisector of the inner corner, or the opposite one
      moves.emplace_back(pair[k], own[0] + orientation * 0.5 * corner + (inside == 0 ? 0 : pi));
    }
  }
  for (const auto& [i, bisector] : moves)
  {
    const double* x = &original[2 * i];
    const double* p = &original[2 * ((i + n - 1) % n)];
    const double* q = &original[2 * ((i + 1) % n)];
    // edges have length (IdentifyEqualPoints)
    const double step = 1e-3 * std::min(std::hypot(q[0] - x[0], q[1] - x[1]), std::hypot(p[0] - x[0], p[1] - x[1]));
    xy[2 * i] = x[0] + step * std::cos(bisector);
    xy[2 * i + 1] = x[1] + step * std::sin(bisector);
  }
  return true;
}

// The loop edges, then the slit edges: the cancelled edges, which must be traversed exactly once
// each way and form trees hanging from the loop (as many edges as non-loop points: contracting
// the loop to one vertex leaves a connected graph, so it is a tree).
bool CollectBoundaryEdges(std::size_t n, BoundaryGraph& graph, std::string& error)
{
  const std::vector<Index>& point = graph.PointOf;
  const std::size_t loopSize = graph.Loop.size();
  // Every walk step, as (smaller point, larger point, forward): count the traversals per edge.
  std::vector<std::tuple<Index, Index, bool>> steps(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const Index a = point[i], b = point[(i + 1) % n];
    steps[i] = std::make_tuple(std::min(a, b), std::max(a, b), a < b);
  }
  std::sort(steps.begin(), steps.end());
  graph.Edges.clear();
  for (std::size_t k = 0; k < loopSize; ++k)
  {
    graph.Edges.emplace_back(point[graph.Loop[k]], point[graph.Loop[(k + 1) % loopSize]]);
  }
  std::size_t singles = 0;
  bool valid = true;
  for (std::size_t k = 0; k < n && valid;)
  {
    std::size_t end = k;
    int forward = 0;
    while (end < n && std::get<0>(steps[end]) == std::get<0>(steps[k]) && std::get<1>(steps[end]) == std::get<1>(steps[k]))
    {
      forward += std::get<2>(steps[end]) ? 1 : 0;
      ++end;
    }
    if (end - k == 1)
    {
      ++singles;
    }
    else if (end - k == 2 && forward == 1)
    {
      graph.Edges.emplace_back(std::get<0>(steps[k]), std::get<1>(steps[k]));
    }
    else
    {
      valid = false;
    }
    k = end;
  }
  const std::size_t slitEdges = graph.Edges.size() - loopSize;
  if (!valid || singles != loopSize || slitEdges != graph.PointCount - loopSize)
  {
    error = "TwoCellParameterization: the boundary repeats points but is not an outer loop with slits "
            "(trees retraced straight back, each touching the loop at one point)";
    return false;
  }
  return true;
}

// Splits the walk into the outer loop and slits. A slit is retraced: ..., x, y, x, ... steps
// out along edge xy and straight back. Geometry is checked later. `loopWithoutTrees`, if
// given, tells whether the walk failed only there: a simple outer loop (graph.Loop) whose
// retraced rest is no set of trees hanging from it at one point each.
bool AnalyzeBoundary(
  const double* xy, std::size_t n, BoundaryGraph& graph, std::string& error, bool* loopWithoutTrees = nullptr)
{
  if (loopWithoutTrees)
  {
    *loopWithoutTrees = false;
  }
  if (!IdentifyEqualPoints(xy, n, graph, error) || !FindOuterLoop(n, graph, error))
  {
    return false;
  }
  if (CollectBoundaryEdges(n, graph, error))
  {
    return true;
  }
  if (loopWithoutTrees)
  {
    *loopWithoutTrees = true;
  }
  return false;
}

// Cuts the mesh open along the slits: gives every corner of a domain face at a boundary vertex
// the sample (visit of that vertex) of the wedge it lies in. With the cell on the left of a
// counter-clockwise walk, visit i of vertex v owns the faces swept counter-clockwise around v
// from edge (v, next sample) to edge (v, previous sample) (for a clockwise walk from previous to
// next). Boundary and slit edges are exactly the constrained edges, so the sweep stops at the
// first constrained edge, which must be the expected one. At a slit tip next = previous and the
// sweep goes all around. False if the wedges do not match the walk (slits visited in an order
// that does not follow their geometry around a vertex).
bool AssignBoundaryCorners(Triangulation& cdt, const std::vector<VertexHandle>& boundary, int orientation)
{
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
  {
    f->info().fill(InvalidIndex);
  }
  const std::size_t n = boundary.size();
  std::vector<std::pair<FaceHandle, int>> firstCorner(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const VertexHandle v = boundary[i];
    const VertexHandle next = boundary[(i + 1) % n], previous = boundary[(i + n - 1) % n];
    const VertexHandle from = orientation > 0 ? next : previous, to = orientation > 0 ? previous : next;
    FaceHandle f;
    int k;
    if (!cdt.is_edge(v, from, f, k))
    {
      return false;
    }
    int j = f->index(v);
    if (f->vertex(Triangulation::ccw(j)) != from)
    {
      f = f->neighbor(k);
      j = f->index(v);
    }
    firstCorner[i] = { f, j };
    for (;;)
    {
      if (cdt.is_infinite(f) || !f->is_in_domain() || f->info()[j] != InvalidIndex)
      {
        return false;
      }
      f->info()[j] = static_cast<Index>(i);
      if (f->is_constrained(Triangulation::ccw(j)))
      {
        if (f->vertex(Triangulation::cw(j)) != to)
        {
          return false;
        }
        break;
      }
      f = f->neighbor(Triangulation::ccw(j));
      j = f->index(v);
    }
  }
  // The face starting visit i's wedge has the edge to the neighbouring visit: it must end that
  // visit's wedge, so that the border of the cut mesh is the walk itself...
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t neighbor = orientation > 0 ? (i + 1) % n : (i + n - 1) % n;
    if (firstCorner[i].first->info()[Triangulation::ccw(firstCorner[i].second)] != static_cast<Index>(neighbor))
    {
      return false;
    }
  }
  // ... and every boundary corner of the domain belongs to a visit.
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
  {
    for (int k = 0; k < 3; ++k)
    {
      if (f->is_in_domain() && f->vertex(k)->info() != InvalidIndex && f->info()[k] == InvalidIndex)
      {
        return false;
      }
    }
  }
  return true;
}

// The interior edges of the cut mesh whose end points are boundary samples on a common side
// of the square. Mean value coordinates map such an edge onto that side, and the part of the
// cell it cuts off (only boundary vertices of that side, plus interior vertices that become
// convex combinations of them) collapses: Floater's one-to-one theorem excludes exactly them.
// The samples are the visits of the face corners (AssignBoundaryCorners), so on a slit the
// side of the square of the edge's own side of the slit counts.
std::vector<std::pair<VertexHandle, VertexHandle>> DividingEdges(const Triangulation& cdt, const std::vector<int>& sideMasks)
{
  std::vector<std::pair<VertexHandle, VertexHandle>> edges;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
  {
    if (!f->is_in_domain())
    {
      continue;
    }
    for (int i = 0; i < 3; ++i)
    {
      const FaceHandle neighbor = f->neighbor(i);
      if (f->is_constrained(i) || cdt.is_infinite(neighbor) || !neighbor->is_in_domain())
      {
        continue;
      }
      // Each interior edge is seen from both faces, with its end points swapped: keep one
      // (by sample index rather than face address, so that the fixes do not depend on the
      // allocator).
      const Index ia = f->info()[Triangulation::cw(i)];
      const Index ib = f->info()[Triangulation::ccw(i)];
      if (ia != InvalidIndex && ib != InvalidIndex && ia < ib && (sideMasks[ia] & sideMasks[ib]))
      {
        edges.emplace_back(f->vertex(Triangulation::cw(i)), f->vertex(Triangulation::ccw(i)));
      }
    }
  }
  return edges;
}

// Splits the edges at their midpoints; returns the number of points inserted. The point is
// inserted *on* the edge: the rounded midpoint may be an ulp off it, and on a tiny edge (a
// thin channel) a point merely near it need not conflict with both of its triangles, so the
// edge could survive. An edge already flipped away by an earlier insertion is skipped.
int SplitEdges(Triangulation& cdt, const std::vector<std::pair<VertexHandle, VertexHandle>>& edges)
{
  int inserted = 0;
  for (const auto& edge : edges)
  {
    FaceHandle f;
    int i;
    if (cdt.is_edge(edge.first, edge.second, f, i))
    {
      cdt.insert(CGAL::midpoint(edge.first->point(), edge.second->point()), Triangulation::EDGE, f, i);
      ++inserted;
    }
  }
  return inserted;
}
// The boundary walk of one cell as Parameterize checks and uses it.
struct CellBoundary
{
  const double* XY = nullptr; // (x, y) per sample
  const double* UV = nullptr; // (u, v) per sample, on the border of the unit square
  std::size_t Count = 0;      // samples, without a repeated first one at the end
  std::vector<int> SideMasks; // SideMask of each sample's (u, v)
  int ParameterOrientation = 1; // +1 if (u, v) go counter-clockwise around the square
  BoundaryGraph Graph;
  int PolygonOrientation = 1; // +1 if the outer loop is counter-clockwise in (x, y)
  double Area = 0;            // enclosed by the outer loop
};

// Two sides of a cell that run along one stretch of straight boundary, each sampled its own
// way: uniform noise makes them where two 1-cells share part of their V-path and both follow
// it as straight segments (OneCellSmoothing::FollowPolyline), and the cell between them has no
// width there. Their samples interleave on one line, so the walk is neither a slit nor a
// simple polygon. Every sample lying inside another walk edge (within 1e-9 of its length) is
// copied into that edge, bit for bit, with the (u, v) interpolated along it: both sides then
// carry the same samples and the stretch is an ordinary slit. Edges whose (u, v) do not lie on
// one side of the square are left alone. Returns false if nothing was changed.
bool SampleOverlapsAlike(const CellBoundary& cell, std::vector<double>& points, std::vector<double>& parameters)
{
  const std::size_t n = cell.Count;
  const double* uv = cell.UV;
  const std::vector<int>& sideMasks = cell.SideMasks; // CheckBorderParameters
  // The two samplings' common points agree up to rounding: first made equal (the earlier
  // sample's coordinates win), or each would land next to the other one.
  std::vector<double> welded(cell.XY, cell.XY + 2 * n);
  const double* xy = welded.data();
  bool weldedAny = false;
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t h = (i + n - 1) % n, j = (i + 1) % n;
    const double edge = std::min(std::hypot(xy[2 * j] - xy[2 * i], xy[2 * j + 1] - xy[2 * i + 1]),
      std::hypot(xy[2 * h] - xy[2 * i], xy[2 * h + 1] - xy[2 * i + 1]));
    for (std::size_t k = i + 1; k < n; ++k)
    {
      const double d = std::hypot(xy[2 * k] - xy[2 * i], xy[2 * k + 1] - xy[2 * i + 1]);
      if (d > 0 && d <= 1e-9 * edge)
      {
        welded[2 * k] = xy[2 * i];
        welded[2 * k + 1] = xy[2 * i + 1];
        weldedAny = true;
      }
    }
  }
  // (edge, fraction along it, sample copied)
  std::vector<std::tuple<std::size_t, double, std::size_t>> inserts;
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t j = (i + 1) % n;
    const bool onOneSide = (sideMasks[i] & sideMasks[j]) != 0;
    const double length2 = (xy[2 * j] - xy[2 * i]) * (xy[2 * j] - xy[2 * i]) +
      (xy[2 * j + 1] - xy[2 * i + 1]) * (xy[2 * j + 1] - xy[2 * i + 1]);
    if (!onOneSide || length2 == 0)
    {
      continue;
    }
    for (std::size_t k = 0; k < n; ++k)
    {
      const double* p = &xy[2 * k];
      if ((p[0] == xy[2 * i] && p[1] == xy[2 * i + 1]) || (p[0] == xy[2 * j] && p[1] == xy[2 * j + 1]))
      {
        continue;
      }
      double fraction;
      if (SegmentDistance2(&xy[2 * i], &xy[2 * j], p[0], p[1], fraction) <= 1e-18 * length2 && fraction > 0 &&
        fraction < 1)
      {
        inserts.emplace_back(i, fraction, k);
      }
    }
  }
  if (inserts.empty() && !weldedAny)
  {
    return false;
  }
  std::sort(inserts.begin(), inserts.end());
  points.clear();
  parameters.clear();
  std::size_t next = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t j = (i + 1) % n;
    points.insert(points.end(), { xy[2 * i], xy[2 * i + 1] });
    parameters.insert(parameters.end(), { uv[2 * i], uv[2 * i + 1] });
    for (; next < inserts.size() && std::get<0>(inserts[next]) == i; ++next)
    {
      const auto [edge, f, k] = inserts[next];
      const double x = xy[2 * k], y = xy[2 * k + 1];
      if (x == points[points.size() - 2] && y == points.back())
      {
        continue; // the same point from another sample (the visits of a slit)
      }
      points.insert(points.end(), { x, y });
      parameters.insert(parameters.end(), { (1 - f) * uv[2 * i] + f * uv[2 * j], (1 - f) * uv[2 * i + 1] + f * uv[2 * j + 1] });
    }
  }
  return true;
}

// Slits that lie outside the outer loop. A merged 1-cell that runs out to a cancelled
// extremum and back along its own path (an excursion stage 3 keeps inside one piece, or a
// 1-cell left uncut where its cuts would order nodes in a cycle) is retraced in the walk like a
// slit, but its geometry can lie in the neighbouring 2-cell: the cell's other sides pass it on
// the wrong side. It bounds no area of this cell, so the walk goes on without it: the slit's
// samples and the return visit of its base are left out (the base keeps its first visit and
// its (u, v)). Phi then maps the loop edge after the base onto a chord of the square that skips
// the slit's stretch of the border; the square's image is still convex, so Phi stays one to
// one (Floater), and F o Phi departs from the 1-cell's heights only along that one edge.
// Writes the walk without such slits; returns how many were left out.
int DropSlitsOutsideTheLoop(const CellBoundary& cell, std::vector<double>& points, std::vector<double>& parameters)
{
  const BoundaryGraph& graph = cell.Graph;
  const std::size_t n = cell.Count;
  const double* xy = cell.XY;
  if (graph.Loop.size() >= n || graph.Loop.empty())
  {
    return 0;
  }
  std::vector<Point> loop;
  std::vector<unsigned char> onLoop(n, 0), loopPoint(graph.PointCount, 0);
  for (Index i : graph.Loop)
  {
    loop.emplace_back(xy[2 * i], xy[2 * i + 1]);
    onLoop[i] = 1;
    loopPoint[graph.PointOf[i]] = 1;
  }
  // Walking once around from a loop sample, a tree is the stretch between two visits of one
  // loop point (the most recent one before) that holds no loop sample; it lies on one side of
  // the loop (slits cross nothing), which the midpoint of its first edge tells.
  std::vector<unsigned char> keep(n, 1);
  int dropped = 0;
  std::map<Index, std::size_t> lastVisit; // point -> walk position (unrolled)
  const std::size_t start = graph.Loop.front();
  // (p = start + n visits the first sample again: a tree across the walk's first sample closes.)
  for (std::size_t p = start; p <= start + n; ++p)
  {
    const std::size_t i = p % n;
    const auto seen = lastVisit.find(graph.PointOf[i]);
    bool tree = loopPoint[graph.PointOf[i]] && seen != lastVisit.end() && seen->second + 1 < p;
    for (std::size_t q = tree ? seen->second + 1 : p; q < p && tree; ++q)
    {
      tree = !onLoop[q % n]; // a stretch of the loop itself (a pinch) is no slit
    }
    if (tree)
    {
      const std::size_t u = seen->second % n, first = (seen->second + 1) % n;
      const Point middle(0.5 * (xy[2 * u] + xy[2 * first]), 0.5 * (xy[2 * u + 1] + xy[2 * first + 1]));
      if (CGAL::bounded_side_2(loop.begin(), loop.end(), middle, Kernel()) == CGAL::ON_UNBOUNDED_SIDE)
      {
        for (std::size_t q = seen->second + 1; q < p; ++q)
        {
          keep[q % n] = 0;
        }
        // One visit of the base stays: the loop's own one.
        keep[onLoop[i] ? u : i] = 0;
        ++dropped;
      }
    }
    lastVisit[graph.PointOf[i]] = p;
  }
  if (dropped == 0)
  {
    return 0;
  }
  points.clear();
  parameters.clear();
  for (std::size_t i = 0; i < n; ++i)
  {
    if (keep[i])
    {
      points.insert(points.end(), { xy[2 * i], xy[2 * i + 1] });
      parameters.insert(parameters.end(), { cell.UV[2 * i], cell.UV[2 * i + 1] });
    }
  }
  return dropped;
}

// The walk with every run of consecutive samples that lie on (next to) one point made one
// sample. A 1-cell piece that stage 3 left of no length is sampled k times at one point, and
// its samples differ by rounding only: a few ulps apart, in no order, they make zero-length
// edges and pinches that no triangulation takes. A run is a chain of consecutive samples each
// within the tolerance below of the one before (in x and in y); it becomes one sample at the
// least of its points (by x, then y), so that a slit, which retraces a run backwards, gets the
// same point on both of its sides. Its parameter is its first sample's, or that of the corner
// of the square it holds (u and v each 0 or 1), which must stay; a run holding two corners (a
// side of no length) keeps both, on one point, and is refused later. Returns the number of
// samples dropped; when it is 0 the caller reads the walk as given.
std::size_t MergeCoincidentRuns(const std::vector<double>& boundaryPoints,
  const std::vector<double>& boundaryParameters, std::vector<double>& points, std::vector<double>& parameters)
{
  points.clear();
  parameters.clear();
  const std::size_t n = std::min(boundaryPoints.size(), boundaryParameters.size()) / 2;
  if (n < 2)
  {
    return 0;
  }
  // Within 1e-12 of the walk's extent, or a few ulps of its coordinates where they lie far
  // from 0 (an image's origin may be up to 1e12 spacings away): a tolerance relative to the
  // coordinates alone would merge samples a spacing apart there.
  double low[2] = { boundaryPoints[0], boundaryPoints[1] }, high[2] = { low[0], low[1] };
  double largest = 0;
  for (std::size_t i = 0; i < 2 * n; ++i)
  {
    low[i % 2] = std::min(low[i % 2], boundaryPoints[i]);
    high[i % 2] = std::max(high[i % 2], boundaryPoints[i]);
    largest = std::max(largest, std::abs(boundaryPoints[i]));
  }
  const double tolerance = std::max(
    1e-12 * std::max(high[0] - low[0], high[1] - low[1]), 16 * std::numeric_limits<double>::epsilon() * largest);
  const auto near = [&](std::size_t a, std::size_t b) {
    return std::abs(boundaryPoints[2 * a] - boundaryPoints[2 * b]) <= tolerance &&
      std::abs(boundaryPoints[2 * a + 1] - boundaryPoints[2 * b + 1]) <= tolerance;
  };
  // A run starts where a sample is not near the one before it (cyclically).
  std::size_t start = n;
  bool anyNear = false;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (near((i + n - 1) % n, i))
    {
      anyNear = true;
    }
    else if (start == n)
    {
      start = i;
    }
  }
  if (!anyNear || start == n)
  {
    return 0; // nothing to merge, or the whole walk on one point (refused later)
  }
  const auto corner = [&](std::size_t a) {
    const double u = boundaryParameters[2 * a], v = boundaryParameters[2 * a + 1];
    return (u == 0 || u == 1) && (v == 0 || v == 1);
  };
  std::vector<std::size_t> run;
  for (std::size_t k = 0; k < n;)
  {
    run.clear();
    run.push_back((start + k) % n);
    for (++k; k < n && near(run.back(), (start + k) % n); ++k)
    {
      run.push_back((start + k) % n);
    }
    double x = boundaryPoints[2 * run[0]], y = boundaryPoints[2 * run[0] + 1];
    for (const std::size_t i : run)
    {
      if (std::make_pair(boundaryPoints[2 * i], boundaryPoints[2 * i + 1]) < std::make_pair(x, y))
      {
        x = boundaryPoints[2 * i];
        y = boundaryPoints[2 * i + 1];
      }
    }
    std::vector<std::size_t> kept;
    std::copy_if(run.begin(), run.end(), std::back_inserter(kept), corner);
    if (kept.empty())
    {
      kept.push_back(run.front());
    }
    for (const std::size_t i : kept)
    {
      points.insert(points.end(), { x, y }); // a run of one sample: its own point
      parameters.insert(parameters.end(), { boundaryParameters[2 * i], boundaryParameters[2 * i + 1] });
    }
  }
  return n - points.size() / 2;
}

// Pairs of equal count, finite, at least one sample per corner of the square.
bool ReadBoundarySamples(const std::vector<double>& boundaryPoints, const std::vector<double>& boundaryParameters,
  CellBoundary& cell, std::string& error)
{
  if (boundaryPoints.size() % 2 != 0 || boundaryPoints.size() != boundaryParameters.size())
  {
    error = "TwoCellParameterization: boundary points and parameters must be (x, y) and (u, v) pairs of equal count";
    return false;
  }
  std::size_t n = boundaryPoints.size() / 2;
  for (std::size_t i = 0; i < 2 * n; ++i)
  {
    if (!std::isfinite(boundaryPoints[i]) || !std::isfinite(boundaryParameters[i]))
    {
      error = "TwoCellParameterization: non-finite boundary coordinate or parameter";
      return false;
    }
  }
  // A closed polyline often repeats its first sample at the end.
  if (n >= 2 && boundaryPoints[0] == boundaryPoints[2 * n - 2] && boundaryPoints[1] == boundaryPoints[2 * n - 1] &&
    boundaryParameters[0] == boundaryParameters[2 * n - 2] && boundaryParameters[1] == boundaryParameters[2 * n - 1])
  {
    --n;
  }
  if (n < 4)
  {
    std::ostringstream message;
    message << "TwoCellParameterization: the boundary has " << n
            << " samples; at least 4 are needed (one per corner of the square)";
    error = message.str();
    return false;
  }
  cell.XY = boundaryPoints.data();
  cell.UV = boundaryParameters.data();
  cell.Count = n;
  return true;
}

// Every (u, v) on the border of the square, going monotonically once around it.
bool CheckBorderParameters(CellBoundary& cell, std::string& error)
{
  const std::size_t n = cell.Count;
  const double* uv = cell.UV;
  cell.SideMasks.resize(n);
  std::vector<int>& sideMasks = cell.SideMasks;
  for (std::size_t i = 0; i < n; ++i)
  {
    const double u = uv[2 * i], v = uv[2 * i + 1];
    sideMasks[i] = SideMask(u, v);
    if (sideMasks[i] == 0 || u < -BorderTolerance || u > 1 + BorderTolerance || v < -BorderTolerance ||
      v > 1 + BorderTolerance)
    {
      std::ostringstream message;
      message << "TwoCellParameterization: parameter " << i << " (" << u << ", " << v
              << ") is not on the border of the unit square";
      error = message.str();
      return false;
    }
  }
  // Once around, monotonically: the steps taken forward (each in [0, 4)) add up to one turn, or
  // those taken backward do. A walk without a slit outside its loop (DropSlitsOutsideTheLoop)
  // may jump over more than half of the border in one step, so a step's direction cannot be
  // told from its length alone.
  double forward = 0, backward = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t j = (i + 1) % n;
    double step = PerimeterCoordinate(uv[2 * j], uv[2 * j + 1], sideMasks[j]) -
      PerimeterCoordinate(uv[2 * i], uv[2 * i + 1], sideMasks[i]);
    if (step == 0)
    {
      std::ostringstream message;
      message << "TwoCellParameterization: samples " << i << " and " << j << " have the same parameter";
      error = message.str();
      return false;
    }
    step = step < 0 ? step + 4 : step;
    forward += step;
    backward += 4 - step;
  }
  const bool once = std::abs(forward - 4) <= 1e-9;
  if (!once && std::abs(backward - 4) > 1e-9)
  {
    error = "TwoCellParameterization: the parameters do not go monotonically once around the unit square";
    return false;
  }
  cell.ParameterOrientation = once ? 1 : -1;
  return true;
}

// A walk of boundary samples, read (ReadBoundarySamples) and its (u, v) checked
// (CheckBorderParameters): the given one, and each walk rebuilt from it.
bool ReadBoundaryWalk(const std::vector<double>& boundaryPoints, const std::vector<double>& boundaryParameters,
  CellBoundary& cell, std::string& error)
{
  return ReadBoundarySamples(boundaryPoints, boundaryParameters, cell, error) && CheckBorderParameters(cell, error);
}

// The outer loop must be a simple polygon (exact predicates: touching or crossing edges and
// collinear, zero-area loops are all "not simple"; repeated points were refused already unless
// they are on slits). Sets its orientation and area.
bool CheckOuterLoop(CellBoundary& cell, std::string& error)
{
  const BoundaryGraph& graph = cell.Graph;
  const std::size_t loopSize = graph.Loop.size();
  const bool hasSlits = loopSize < cell.Count;
  std::vector<Point> loop(loopSize);
  for (std::size_t k = 0; k < loopSize; ++k)
  {
    loop[k] = Point(cell.XY[2 * graph.Loop[k]], cell.XY[2 * graph.Loop[k] + 1]);
  }
  if (!CGAL::is_simple_2(loop.begin(), loop.end(), Kernel()))
  {
    std::ostringstream message;
    message << (hasSlits ? "TwoCellParameterization: the outer loop of the boundary (without its slits) is not "
                           "simple (self-touching, self-crossing or zero area)"
                         : "TwoCellParameterization: the boundary polygon is not simple (self-touching, "
                           "self-crossing or zero area)");
    // Where: the first two non-adjacent loop edges that meet (quadratic, on failure only).
    const std::size_t m = loop.size();
    bool located = false;
    for (std::size_t a = 0; a < m && !located; ++a)
    {
      const Kernel::Segment_2 first(loop[a], loop[(a + 1) % m]);
      for (std::size_t b = a + 2; b < m && !located; ++b)
      {
        if ((b + 1) % m == a)
        {
          continue;
        }
        if (CGAL::do_intersect(first, Kernel::Segment_2(loop[b], loop[(b + 1) % m])))
        {
          message << " at boundary samples " << graph.Loop[a] << " and " << graph.Loop[b] << " near ("
                  << loop[a].x() << ", " << loop[a].y() << ")";
          located = true;
        }
      }
    }
    error = message.str();
    return false;
  }
  cell.PolygonOrientation = CGAL::orientation_2(loop.begin(), loop.end(), Kernel()) == CGAL::LEFT_TURN ? 1 : -1;
  double signedArea = 0;
  for (std::size_t k = 0; k < loopSize; ++k)
  {
    const Point& p = loop[k];
    const Point& q = loop[(k + 1) % loopSize];
    signedArea += p.x() * q.y() - q.x() * p.y();
  }
  cell.Area = std::abs(signedArea) / 2;
  return true;
}

// The target edge length of the interior triangles: `target`, or (<= 0) the mean sample
// spacing of the whole walk (slit edges count twice, as they have two sides), raised where the
// cell would need more than `maximumVertexCount` vertices.
double InteriorEdgeLength(const CellBoundary& cell, double target, Index maximumVertexCount)
{
  const std::size_t n = cell.Count;
  const double* xy = cell.XY;
  double perimeter = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t j = (i + 1) % n;
    perimeter += std::hypot(xy[2 * j] - xy[2 * i], xy[2 * j + 1] - xy[2 * i + 1]);
  }
  double edgeLength = target > 0 ? target : perimeter / static_cast<double>(n);
  // An equilateral triangle of side s covers sqrt(3)/4 s^2, and there are about twice as many
  // triangles as vertices.
  const double maximumVertices = std::max<double>(static_cast<double>(maximumVertexCount), 2.0 * n);
  const double expectedVertices = cell.Area / (0.5 * 0.4330127 * edgeLength * edgeLength);
  if (!(edgeLength > 0) || expectedVertices > maximumVertices)
  {
    edgeLength = std::sqrt(cell.Area / (0.5 * 0.4330127 * maximumVertices));
  }
  return edgeLength;
}

// One vertex per distinct point; the loop and slit edges are the constraints (slit edges are
// interior constraints, with the domain on both sides). `boundary` gets the vertex of every
// sample (the visits of a slit point share one).
bool InsertBoundary(const CellBoundary& cell, Triangulation& cdt, std::vector<VertexHandle>& boundary, std::string& error)
{
  const BoundaryGraph& graph = cell.Graph;
  const std::size_t n = cell.Count;
  const double* xy = cell.XY;
  std::vector<VertexHandle> pointVertex(graph.PointCount);
  boundary.assign(n, VertexHandle());
  VertexHandle hint;
  for (std::size_t i = 0; i < n; ++i)
  {
    VertexHandle& v = pointVertex[graph.PointOf[i]];
    if (v == VertexHandle())
    {
      v = cdt.insert(Point(xy[2 * i], xy[2 * i + 1]), hint == VertexHandle() ? FaceHandle() : hint->face());
      hint = v;
    }
    boundary[i] = v;
  }
  for (const auto& edge : graph.Edges)
  {
    cdt.insert_constraint(pointVertex[edge.first], pointVertex[edge.second]);
  }
  if (cdt.number_of_vertices() != graph.PointCount)
  {
    error = "TwoCellParameterization: boundary samples merged in the triangulation";
    return false;
  }
  // A constraint through another sample is split there: a slit touching the loop or another
  // slit, or (without slits) a sample on an edge, which is_simple_2 already refused.
  for (const auto& edge : graph.Edges)
  {
    if (!cdt.is_edge(pointVertex[edge.first], pointVertex[edge.second]))
    {
      error = "TwoCellParameterization: a slit touches the outer loop or another slit";
      return false;
    }
  }
  const std::size_t loopSize = graph.Loop.size();
  if (loopSize < n)
  {
    // The domain is what the loop encloses (faces not reachable from the infinite face
    // without crossing a constraint): a slit edge must have it on both sides.
    Mesher::mark_convex_hull(cdt);
    for (std::size_t e = loopSize; e < graph.Edges.size(); ++e)
    {
      FaceHandle f;
      int k;
      cdt.is_edge(pointVertex[graph.Edges[e].first], pointVertex[graph.Edges[e].second], f, k);
      if (!f->is_in_domain() || !f->neighbor(k)->is_in_domain())
      {
        error = "TwoCellParameterization: a slit lies outside the outer loop of the boundary";
        return false;
      }
    }
  }
  return true;
}

// Cuts the mesh open along the slits and removes dividing edges. Inserting a point on an edge
// removes that edge, and every edge a Delaunay insertion creates ends at the new point: neither
// the fix nor the re-refinement can create another dividing edge, so one round suffices (the
// others are a guard).
bool CutOpenAndFixDividingEdges(const CellBoundary& cell, const Criteria& criteria, int maximumFixRounds,
  Triangulation& cdt, const std::vector<VertexHandle>& boundary, int& dividingEdgeFixes, std::string& error)
{
  for (int round = 0;; ++round)
  {
    ResetVertexIndices(cdt, boundary);
    if (!AssignBoundaryCorners(cdt, boundary, cell.PolygonOrientation))
    {
      error = "TwoCellParameterization: the mesh cannot be cut open along the slits so that its border is the "
              "boundary walk (slits visited in an order that does not match their geometry)";
      return false;
    }
    const std::vector<std::pair<VertexHandle, VertexHandle>> dividing = DividingEdges(cdt, cell.SideMasks);
    if (dividing.empty())
    {
      return true;
    }
    if (round >= maximumFixRounds)
    {
      std::ostringstream message;
      message << "TwoCellParameterization: " << dividing.size() << " dividing edges remain after "
              << maximumFixRounds << " rounds of fixes";
      error = message.str();
      return false;
    }
    dividingEdgeFixes += SplitEdges(cdt, dividing);
    // Re-marks the domain (new faces are not marked) and restores the size and shape.
    Refine(cdt, criteria);
  }
}

// The output mesh: boundary vertices first, in input order, with their given (u, v). Boundary
// corners take the sample of their wedge (so each visit of a slit point is its own vertex),
// Steiner points are numbered as they are met.
void ExtractMesh(const CellBoundary& cell, Triangulation& cdt, TwoCellMesh& mesh)
{
  const std::size_t n = cell.Count;
  mesh.BoundaryCount = static_cast<Index>(n);
  mesh.Points.assign(cell.XY, cell.XY + 2 * n);
  mesh.Parameters.assign(cell.UV, cell.UV + 2 * n);
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
  {
    if (!f->is_in_domain())
    {
      continue;
    }
    for (int k = 0; k < 3; ++k)
    {
      Index corner = f->info()[k];
      if (corner == InvalidIndex)
      {
        const VertexHandle v = f->vertex(k);
        if (v->info() == InvalidIndex)
        {
          v->info() = mesh.NumberOfPoints();
          mesh.Points.push_back(v->point().x());
          mesh.Points.push_back(v->point().y());
        }
        corner = v->info();
      }
      mesh.Triangles.push_back(corner);
    }
  }
  mesh.Parameters.resize(mesh.Points.size(), 0);
}

// Constrained Delaunay triangulation of the cell, refined without splitting the boundary,
// cut open along the slits, without dividing edges, written to `mesh` (parameters of the
// interior vertices still 0).
bool TriangulateCell(const CellBoundary& cell, double edgeLength, double shapeBound, int maximumFixRounds,
  TwoCellMesh& mesh, std::string& error)
{
  try
  {
    Triangulation cdt;
    std::vector<VertexHandle> boundary;
    if (!InsertBoundary(cell, cdt, boundary, error))
    {
      return false;
    }
    // Delaunay refinement is only guaranteed to end for a smallest angle up to ~20.7 degrees
    // (b = 0.125); a larger bound could refine forever. Points that would encroach upon a
    // constraint (boundary or slit) are not inserted, so constraints are never split.
    const Criteria criteria(shapeBound > 0 ? std::min(shapeBound, 0.125) : 0.0, edgeLength);
    Refine(cdt, criteria);
    if (!CutOpenAndFixDividingEdges(cell, criteria, maximumFixRounds, cdt, boundary, mesh.DividingEdgeFixes, error))
    {
      return false;
    }
    ExtractMesh(cell, cdt, mesh);
  }
  catch (const Triangulation::Intersection_of_constraints_exception&)
  {
    error = "TwoCellParameterization: the boundary crosses itself (a slit crosses the outer loop or another slit)";
    return false;
  }
  catch (const std::exception& e)
  {
    error = std::string("TwoCellParameterization: triangulation failed: ") + e.what();
    return false;
  }
  return true;
}

// The linear system of Floater's mean value coordinates (paper, section 5.1): interior vertex i
// satisfies sum_j w_ij (uv_i - uv_j) = 0 with w_ij = (tan(a/2) + tan(b/2)) / |v_j - v_i|, a and
// b the angles at v_i beside edge ij; the boundary (u, v) are fixed and go to the right side.
struct MeanValueSystem
{
  std::vector<Eigen::Triplet<double>> OffDiagonal; // -w_ij between interior vertices
  std::vector<double> Diagonal;                    // sum_j w_ij
  Eigen::MatrixXd RightSide;                       // sum over boundary j of w_ij uv_j
};

// The field's gradient at each interior vertex of the mesh: the area-weighted mean of the
// gradients of the triangles around it (the field linear on each triangle through its values at
// the mesh vertices; triangles with a NaN value are left out). (0, 0) where none is known.
std::vector<double> InteriorGradients(const TwoCellMesh& mesh, const std::vector<double>& values)
{
  const Index boundaryCount = mesh.BoundaryCount;
  const Index interiorCount = mesh.NumberOfPoints() - boundaryCount;
  const std::vector<double>& p = mesh.Points;
  std::vector<double> gradients(2 * static_cast<std::size_t>(interiorCount), 0.0), areas(interiorCount, 0.0);
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    const Index* tri = &mesh.Triangles[3 * t];
    const double f0 = values[tri[0]], f1 = values[tri[1]], f2 = values[tri[2]];
    if (!std::isfinite(f0) || !std::isfinite(f1) || !std::isfinite(f2))
    {
      continue;
    }
    const double ax = p[2 * tri[1]] - p[2 * tri[0]], ay = p[2 * tri[1] + 1] - p[2 * tri[0] + 1];
    const double bx = p[2 * tri[2]] - p[2 * tri[0]], by = p[2 * tri[2] + 1] - p[2 * tri[0] + 1];
    const double cross = ax * by - ay * bx; // twice the signed area
    if (cross == 0)
    {
      continue;
    }
    // Area times gradient: (df1 (by, -bx) + df2 (-ay, ax)) / 2, signed by the orientation (the
    // gradient's 1 / cross cancels the area's cross).
    const double sign = cross > 0 ? 1 : -1;
    const double gx = 0.5 * sign * ((f1 - f0) * by - (f2 - f0) * ay);
    const double gy = 0.5 * sign * ((f2 - f0) * ax - (f1 - f0) * bx);
    for (int k = 0; k < 3; ++k)
    {
      if (tri[k] >= boundaryCount)
      {
        gradients[2 * (tri[k] - boundaryCount)] += gx;
        gradients[2 * (tri[k] - boundaryCount) + 1] += gy;
        areas[tri[k] - boundaryCount] += 0.5 * std::abs(cross);
      }
    }
  }
  for (Index i = 0; i < interiorCount; ++i)
  {
    if (areas[i] > 0)
    {
      gradients[2 * i] /= areas[i];
      gradients[2 * i + 1] /= areas[i];
    }
  }
  return gradients;
}

// The reweighting of TwoCellParameterization::WeightByFieldGradient: the field at every mesh
// vertex (NaN: unknown), the strength (> 0) and which edges it strengthens.
struct FieldGradientWeights
{
  const std::vector<double>* Values = nullptr;
  double Strength = 0;
  GradientWeighting Weighting = GradientWeighting::AlongLevelSets;
};

// False if a weight is zero or not finite (a degenerate triangle). With `reweighting`, each
// weight w_ij of an interior vertex i is multiplied by 1 / (1 / strength + c^2), c the cosine
// (or the sine) of the angle between edge ij and the field's gradient at i, damped where the
// field is nearly flat (TwoCellParameterization::WeightByFieldGradient).
bool AssembleMeanValueSystem(
  const TwoCellMesh& mesh, MeanValueSystem& system, const FieldGradientWeights* reweighting = nullptr)
{
  const Index boundaryCount = mesh.BoundaryCount;
  const Index interiorCount = mesh.NumberOfPoints() - boundaryCount;
  const std::vector<double>& p = mesh.Points;
  std::vector<Eigen::Triplet<double>>& entries = system.OffDiagonal;
  entries.reserve(static_cast<std::size_t>(mesh.NumberOfTriangles()) * 6 + interiorCount);
  std::vector<double>& diagonal = system.Diagonal;
  diagonal.assign(interiorCount, 0);
  Eigen::MatrixXd& rhs = system.RightSide;
  rhs = Eigen::MatrixXd::Zero(interiorCount, 2);
  const bool reweighted = reweighting != nullptr;
  std::vector<double> gradients;
  // The slope below which a vertex counts as flat: a tenth of the cell's mean one (its range
  // over its size), so that the noise of a nearly flat stretch does not orient its weights.
  double flatSlope = 0;
  if (reweighted)
  {
    const std::vector<double>& values = *reweighting->Values;
    gradients = InteriorGradients(mesh, values);
    double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
    double xmin = lowest, xmax = highest, ymin = lowest, ymax = highest;
    for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
    {
      if (std::isfinite(values[v]))
      {
        lowest = std::min(lowest, values[v]);
        highest = std::max(highest, values[v]);
      }
      xmin = std::min(xmin, p[2 * v]);
      xmax = std::max(xmax, p[2 * v]);
      ymin = std::min(ymin, p[2 * v + 1]);
      ymax = std::max(ymax, p[2 * v + 1]);
    }
    const double size = std::hypot(xmax - xmin, ymax - ymin);
    flatSlope = highest > lowest && size > 0 ? 0.1 * (highest - lowest) / size : 0.0;
  }
  // The factor of edge (ex, ey) leaving interior vertex i.
  auto factor = [&](Index i, double ex, double ey) {
    const double gx = gradients[2 * (i - boundaryCount)], gy = gradients[2 * (i - boundaryCount) + 1];
    const double length = std::hypot(ex, ey), slope = std::hypot(gx, gy);
    if (!(length > 0) || !(slope + flatSlope > 0))
    {
      return 1.0;
    }
    const double cosine = std::abs(gx * ex + gy * ey) / (length * (slope + flatSlope));
    const double c = reweighting->Weighting == GradientWeighting::AlongLevelSets
      ? cosine
      : std::sqrt(std::max(0.0, 1 - cosine * cosine));
    return 1 / (1 / reweighting->Strength + c * c);
  };
  bool finite = true;
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    const Index* tri = &mesh.Triangles[3 * t];
    for (int k = 0; k < 3; ++k)
    {
      const Index i = tri[k];
      if (i < boundaryCount)
      {
        continue;
      }
      const Index j = tri[(k + 1) % 3], l = tri[(k + 2) % 3];
      const double ax = p[2 * j] - p[2 * i], ay = p[2 * j + 1] - p[2 * i + 1];
      const double bx = p[2 * l] - p[2 * i], by = p[2 * l + 1] - p[2 * i + 1];
      const double tangent = HalfAngleTangent(ax, ay, bx, by);
      double weights[2] = { tangent / std::hypot(ax, ay), tangent / std::hypot(bx, by) };
      if (reweighted)
      {
        weights[0] *= factor(i, ax, ay);
        weights[1] *= factor(i, bx, by);
      }
      const Index neighbors[2] = { j, l };
      for (int s = 0; s < 2; ++s)
      {
        if (!std::isfinite(weights[s]) || !(weights[s] > 0))
        {
          finite = false;
        }
        diagonal[i - boundaryCount] += weights[s];
        if (neighbors[s] < boundaryCount)
        {
          rhs(i - boundaryCount, 0) += weights[s] * mesh.Parameters[2 * neighbors[s]];
          rhs(i - boundaryCount, 1) += weights[s] * mesh.Parameters[2 * neighbors[s] + 1];
        }
        else
        {
          entries.emplace_back(i - boundaryCount, neighbors[s] - boundaryCount, -weights[s]);
        }
      }
    }
  }
  return finite;
}

// (u, v) of the interior vertices from the mean value system.
bool SolveMeanValueCoordinates(
  TwoCellMesh& mesh, std::string& error, const FieldGradientWeights* reweighting = nullptr)
{
  const Index boundaryCount = mesh.BoundaryCount;
  const Index interiorCount = mesh.NumberOfPoints() - boundaryCount;
  if (interiorCount <= 0)
  {
    return true;
  }
  MeanValueSystem system;
  if (!AssembleMeanValueSystem(mesh, system, reweighting))
  {
    error = "TwoCellParameterization: degenerate triangle (zero or non-finite mean value weight)";
    return false;
  }
  std::vector<Eigen::Triplet<double>>& entries = system.OffDiagonal;
  const std::vector<double>& diagonal = system.Diagonal;
  Eigen::MatrixXd& rhs = system.RightSide;
  for (Index i = 0; i < interiorCount; ++i)
  {
    entries.emplace_back(i, i, diagonal[i]);
  }
  Eigen::SparseMatrix<double> matrix(interiorCount, interiorCount);
  matrix.setFromTriplets(entries.begin(), entries.end());
  // Rows scaled to unit diagonal: the weights scale like 1/length.
  for (Index i = 0; i < interiorCount; ++i)
  {
    rhs.row(i) /= diagonal[i];
  }
  matrix = Eigen::SparseMatrix<double>(Eigen::VectorXd::Map(diagonal.data(), interiorCount).cwiseInverse().asDiagonal() * matrix);
  matrix.makeCompressed();
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> solver;
  solver.compute(matrix);
  if (solver.info() != Eigen::Success)
  {
    error = "TwoCellParameterization: the mean value system could not be factored";
    return false;
  }
  const Eigen::MatrixXd solution = solver.solve(rhs);
  if (solver.info() != Eigen::Success)
  {
    error = "TwoCellParameterization: the mean value system could not be solved";
    return false;
  }
  for (Index i = 0; i < interiorCount; ++i)
  {
    mesh.Parameters[2 * (boundaryCount + i)] = solution(i, 0);
    mesh.Parameters[2 * (boundaryCount + i) + 1] = solution(i, 1);
  }
  return true;
}

// Phi is one-to-one if no triangle is degenerate or flipped in (u, v) and every interior vertex
// lies strictly inside the square; records the smallest area and margin.
//
// In exact arithmetic it always is: the mean value weights are positive, the square is convex
// and no edge joins two vertices of one side (Floater 2003). What fails is rounding: where the
// cell has a long narrow arm, the map crowds the arm's interior vertices exponentially close to
// the border of the square, and they land on it or 1e-16 beyond. Those are clamped onto the
// square and their flattened triangles counted (CrowdedTriangles); anything beyond the
// tolerances below is a real failure.
bool CheckOneToOne(TwoCellMesh& mesh, std::string& error)
{
  // (u, v) lie in [0, 1]: solved coordinates are good to a few ulps times the system's
  // condition; triangle areas are products of two such differences.
  constexpr double marginTolerance = 1e-12;
  constexpr double areaTolerance = 1e-14;
  const Index boundaryCount = mesh.BoundaryCount;
  const Index interiorCount = mesh.NumberOfPoints() - boundaryCount;
  mesh.MinimumInteriorMargin = interiorCount > 0 ? std::numeric_limits<double>::infinity() : 0.5;
  for (Index i = boundaryCount; i < mesh.NumberOfPoints(); ++i)
  {
    double* uv = &mesh.Parameters[2 * i];
    const double margin = std::min(std::min(uv[0], 1 - uv[0]), std::min(uv[1], 1 - uv[1]));
    mesh.MinimumInteriorMargin = std::isfinite(margin) ? std::min(mesh.MinimumInteriorMargin, margin) : -1;
    if (margin > -marginTolerance)
    {
      uv[0] = std::clamp(uv[0], 0.0, 1.0);
      uv[1] = std::clamp(uv[1], 0.0, 1.0);
    }
  }
  mesh.MinimumParameterArea = std::numeric_limits<double>::infinity();
  mesh.CrowdedTriangles = 0;
  Index flipped = 0;
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    const Index* tri = &mesh.Triangles[3 * t];
    const double* a = &mesh.Parameters[2 * tri[0]];
    const double* b = &mesh.Parameters[2 * tri[1]];
    const double* c = &mesh.Parameters[2 * tri[2]];
    const double signedParameterArea =
      mesh.Orientation * 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    if (!(signedParameterArea > -areaTolerance))
    {
      ++flipped;
    }
    else if (!(signedParameterArea > 0))
    {
      ++mesh.CrowdedTriangles;
    }
    mesh.MinimumParameterArea = std::min(mesh.MinimumParameterArea, signedParameterArea);
  }
  if (flipped > 0 || !(mesh.MinimumInteriorMargin > -marginTolerance))
  {
    std::ostringstream message;
    message << "TwoCellParameterization: the parameterization is not one-to-one (" << flipped << " of "
            << mesh.NumberOfTriangles() << " triangles flipped in (u, v) beyond rounding, smallest area "
            << mesh.MinimumParameterArea << ", smallest interior margin " << mesh.MinimumInteriorMargin << ")";
    error = message.str();
    return false;
  }
  return true;
}
} // namespace

bool TwoCellParameterization::Parameterize(
  const std::vector<double>& boundaryPoints, const std::vector<double>& boundaryParameters, std::string& error)
{
  this->Mesh = TwoCellMesh();
  this->PointGrid = TriangleBucketGrid();

  // The boundary: (u, v) once around the square, an outer loop with slits, a simple polygon;
  // then the mesh of the cell (paper, section 5.1).
  CellBoundary cell;
  TwoCellMesh& mesh = this->Mesh;
  // Walks that are not an outer loop with slits as given: the sides resampled alike where they
  // overlap (SampleOverlapsAlike), then pinch points opened (OpenPinches). The first error
  // stands if neither helps.
  std::vector<double> alikePoints, alikeParameters, opened;
  bool resampled = false;
  int pinched = 0;
  // Set where the walk has a simple outer loop but what it retraces besides is no set of trees
  // hanging from it (a retraced stretch that passes another loop point: a merged 1-cell that
  // runs round a loop of its own through its saddle, outside this cell). Such a walk can still
  // be parameterized if all of that lies outside the loop and is left out (dropOutsideSlits).
  bool loopWithoutTrees = false;
  auto analyzeWalk = [&](std::string& message) {
    return AnalyzeBoundary(cell.XY, cell.Count, cell.Graph, message, &loopWithoutTrees);
  };
  auto analyze = [&]() {
    if (analyzeWalk(error))
    {
      return true;
    }
    std::string ignored;
    if (SampleOverlapsAlike(cell, alikePoints, alikeParameters))
    {
      CellBoundary alike;
      if (!ReadBoundaryWalk(alikePoints, alikeParameters, alike, ignored))
      {
        return false;
      }
      cell = alike;
      resampled = true;
      if (analyzeWalk(ignored))
      {
        error.clear();
        return true;
      }
    }
    if (cell.Graph.Pinched.empty())
    {
      return loopWithoutTrees;
    }
    opened.assign(cell.XY, cell.XY + 2 * cell.Count);
    if (!OpenPinches(cell.Graph, cell.Count, DoubleSignedArea(opened) >= 0 ? 1 : -1, opened))
    {
      return false;
    }
    cell.XY = opened.data();
    pinched = static_cast<int>(cell.Graph.Pinched.size());
    if (!AnalyzeBoundary(cell.XY, cell.Count, cell.Graph, ignored))
    {
      return false;
    }
    error.clear();
    return true;
  };
  // Slits outside the outer loop are left out (DropSlitsOutsideTheLoop).
  std::vector<double> withoutPoints, withoutParameters;
  int outsideSlits = 0;
  auto dropOutsideSlits = [&]() {
    outsideSlits = DropSlitsOutsideTheLoop(cell, withoutPoints, withoutParameters);
    if (outsideSlits == 0)
    {
      return !loopWithoutTrees; // the error of the first analysis stands
    }
    CellBoundary without;
    if (!ReadBoundaryWalk(withoutPoints, withoutParameters, without, error) ||
      !AnalyzeBoundary(without.XY, without.Count, without.Graph, error) || !CheckOuterLoop(without, error))
    {
      return false;
    }
    cell = without;
    error.clear();
    return true;
  };
  std::vector<double> mergedPoints, mergedParameters;
  const bool merged = MergeCoincidentRuns(boundaryPoints, boundaryParameters, mergedPoints, mergedParameters) > 0;
  if (!ReadBoundaryWalk(merged ? mergedPoints : boundaryPoints, merged ? mergedParameters : boundaryParameters, cell,
        error) ||
    !analyze() ||
    !CheckOuterLoop(cell, error) || !dropOutsideSlits() ||
    !TriangulateCell(cell, InteriorEdgeLength(cell, this->TargetEdgeLength, this->MaximumVertices), this->ShapeBound,
      this->MaximumFixRounds, mesh, error))
  {
    this->Mesh = TwoCellMesh();
    return false;
  }
  mesh.OpenedPinches = pinched;
  mesh.ResampledOverlaps = resampled;
  mesh.OutsideSlits = outsideSlits;
  // Phi on the mesh.
  mesh.Orientation = cell.PolygonOrientation * cell.ParameterOrientation;
  if (!SolveMeanValueCoordinates(mesh, error) || !CheckOneToOne(mesh, error))
  {
    this->Mesh = TwoCellMesh();
    return false;
  }
  // The mesh is kept as long as the reconstruction, for every cell at once (half a million on
  // 1000 x 1000 noise), and its arrays grew by doubling: about a third of what they held was
  // spare capacity.
  mesh.Points.shrink_to_fit();
  mesh.Parameters.shrink_to_fit();
  mesh.Triangles.shrink_to_fit();
  // Small meshes are scanned whole (TriangleBucketGrid::ScanAll): a cell of uniform noise has a
  // few dozen triangles and is located a few times, at its own vertices.
  this->PointGrid.Build(mesh.Points, mesh.Triangles, ScannedMeshTriangles);
  return true;
}

bool TwoCellParameterization::WeightByFieldGradient(
  const PiecewiseLinearField& field, double strength, GradientWeighting weighting, std::string& error)
{
  TwoCellMesh& mesh = this->Mesh;
  if (mesh.NumberOfTriangles() == 0 || !(strength > 0))
  {
    error = "TwoCellParameterization: no mesh to map again, or a strength that is not positive";
    return false;
  }
  std::vector<double> values(mesh.NumberOfPoints());
  for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
  {
    double value;
    values[v] = field.ValueAt(mesh.Points[2 * v], mesh.Points[2 * v + 1], value)
      ? value
      : std::numeric_limits<double>::quiet_NaN();
  }
  FieldGradientWeights reweighting;
  reweighting.Values = &values;
  reweighting.Strength = strength;
  reweighting.Weighting = weighting;
  return SolveMeanValueCoordinates(mesh, error, &reweighting) && CheckOneToOne(mesh, error);
}

bool TwoCellParameterization::Locate(double x, double y, Index& triangle, double barycentric[3]) const
{
  return this->PointGrid.Locate(this->Mesh.Points, this->Mesh.Triangles, 1, x, y, triangle, barycentric);
}

namespace
{
// Barycentric interpolation of per-vertex pairs over one triangle.
void Interpolate(const std::vector<double>& values, const Index* tri, const double barycentric[3], double out[2])
{
  for (int d = 0; d < 2; ++d)
  {
    out[d] = barycentric[0] * values[2 * tri[0] + d] + barycentric[1] * values[2 * tri[1] + d] +
      barycentric[2] * values[2 * tri[2] + d];
  }
}
} // namespace

bool TwoCellParameterization::Evaluate(double x, double y, double uv[2]) const
{
  Index triangle;
  double barycentric[3];
  if (!this->Locate(x, y, triangle, barycentric))
  {
    return false;
  }
  Interpolate(this->Mesh.Parameters, &this->Mesh.Triangles[3 * triangle], barycentric, uv);
  return true;
}

TwoCellParameterization::Inverse::Inverse(const TwoCellMesh& mesh)
  : Mesh(&mesh)
{
  if (mesh.NumberOfTriangles() > 0)
  {
    this->Grid.Build(mesh.Parameters, mesh.Triangles);
  }
}

bool TwoCellParameterization::Inverse::Evaluate(double u, double v, double xy[2]) const
{
  Index triangle;
  double barycentric[3];
  // Triangles are clockwise in (u, v) when Phi is a mirror map. Without a mesh the grid is
  // empty, and nothing is found.
  if (!this->Grid.Locate(this->Mesh->Parameters, this->Mesh->Triangles, this->Mesh->Orientation, u, v, triangle,
        barycentric))
  {
    return false;
  }
  Interpolate(this->Mesh->Points, &this->Mesh->Triangles[3 * triangle], barycentric, xy);
  return true;
}
} // namespace topospline
