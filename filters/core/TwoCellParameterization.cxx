#include "TwoCellParameterization.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_no_edge_refinement_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Sparse>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>

namespace topospline
{
namespace
{
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
// The vertex info is the output index; it is reset before every use because the mesher
// creates Steiner vertices with an uninitialized info.
using VertexBase = CGAL::Delaunay_mesh_vertex_base_2<Kernel, CGAL::Triangulation_vertex_base_with_info_2<Index, Kernel>>;
using FaceBase = CGAL::Delaunay_mesh_face_base_2<Kernel>;
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

// tan(a/2) for the angle a between vectors (ax, ay) and (bx, by), in the form that stays
// accurate for small angles: sin a / (1 + cos a).
double HalfAngleTangent(double ax, double ay, double bx, double by)
{
  const double cross = std::abs(ax * by - ay * bx);
  const double dot = ax * bx + ay * by;
  return cross / (std::hypot(ax, ay) * std::hypot(bx, by) + dot);
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

// Midpoints of the interior edges whose end points are boundary samples on a common side of
// the square. Mean value coordinates map such an edge onto that side, and the part of the
// cell it cuts off (only boundary vertices of that side, plus interior vertices that become
// convex combinations of them) collapses: Floater's one-to-one theorem excludes exactly them.
std::vector<Point> DividingEdgeMidpoints(const Triangulation& cdt, const std::vector<int>& sideMasks)
{
  std::vector<Point> midpoints;
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
      // Each interior edge is seen from both faces: keep one.
      if (&*neighbor < &*f)
      {
        continue;
      }
      const VertexHandle a = f->vertex(Triangulation::cw(i));
      const VertexHandle b = f->vertex(Triangulation::ccw(i));
      const Index ia = a->info();
      const Index ib = b->info();
      if (ia == InvalidIndex || ib == InvalidIndex)
      {
        continue;
      }
      if (sideMasks[ia] & sideMasks[ib])
      {
        midpoints.push_back(CGAL::midpoint(a->point(), b->point()));
      }
    }
  }
  return midpoints;
}
} // namespace

bool TwoCellParameterization::Parameterize(
  const std::vector<double>& boundaryPoints, const std::vector<double>& boundaryParameters, std::string& error)
{
  this->Mesh = TwoCellMesh();
  this->BucketStart.clear();
  this->BucketTriangles.clear();
  this->GridSize[0] = this->GridSize[1] = 0;

  // --- Validate the boundary ---------------------------------------------------------------
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

  const double* xy = boundaryPoints.data();
  const double* uv = boundaryParameters.data();
  std::vector<int> sideMasks(n);
  double winding = 0;
  int steps[2] = { 0, 0 }; // forward, backward
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
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t j = (i + 1) % n;
    double step = PerimeterCoordinate(uv[2 * j], uv[2 * j + 1], sideMasks[j]) -
      PerimeterCoordinate(uv[2 * i], uv[2 * i + 1], sideMasks[i]);
    if (step > 2)
    {
      step -= 4;
    }
    else if (step <= -2)
    {
      step += 4;
    }
    if (step == 0)
    {
      std::ostringstream message;
      message << "TwoCellParameterization: samples " << i << " and " << j << " have the same parameter";
      error = message.str();
      return false;
    }
    ++steps[step > 0 ? 0 : 1];
    winding += step;
  }
  if ((steps[0] != 0 && steps[1] != 0) || std::abs(std::abs(winding) - 4) > 1e-9)
  {
    error = "TwoCellParameterization: the parameters do not go monotonically once around the unit square";
    return false;
  }
  const int parameterOrientation = winding > 0 ? 1 : -1;

  std::vector<Point> polygon(n);
  double bounds[4] = { xy[0], xy[0], xy[1], xy[1] };
  double perimeter = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    polygon[i] = Point(xy[2 * i], xy[2 * i + 1]);
    bounds[0] = std::min(bounds[0], xy[2 * i]);
    bounds[1] = std::max(bounds[1], xy[2 * i]);
    bounds[2] = std::min(bounds[2], xy[2 * i + 1]);
    bounds[3] = std::max(bounds[3], xy[2 * i + 1]);
    const std::size_t j = (i + 1) % n;
    perimeter += std::hypot(xy[2 * j] - xy[2 * i], xy[2 * j + 1] - xy[2 * i + 1]);
  }
  // Exact predicates: repeated points, touching or crossing edges and collinear (zero-area)
  // polygons are all "not simple". A pouch cell whose boundary runs twice along the same
  // 1-cell (a slit) lands here too: its slit vertices would need two (u, v) each, which a
  // single triangulation vertex cannot carry; the caller has to open the slit first.
  if (!CGAL::is_simple_2(polygon.begin(), polygon.end(), Kernel()))
  {
    error = "TwoCellParameterization: the boundary polygon is not simple (repeated points, self-touching or "
            "self-crossing, e.g. a pouch cell's slit, or zero area)";
    return false;
  }
  double signedArea = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t j = (i + 1) % n;
    signedArea += xy[2 * i] * xy[2 * j + 1] - xy[2 * j] * xy[2 * i + 1];
  }
  signedArea /= 2;
  const int polygonOrientation = CGAL::orientation_2(polygon.begin(), polygon.end(), Kernel()) == CGAL::LEFT_TURN ? 1 : -1;
  const double area = std::abs(signedArea);

  double edgeLength = this->TargetEdgeLength > 0 ? this->TargetEdgeLength : perimeter / static_cast<double>(n);
  // An equilateral triangle of side s covers sqrt(3)/4 s^2, and there are about twice as many
  // triangles as vertices.
  const double maximumVertices = std::max<double>(static_cast<double>(this->MaximumVertices), 2.0 * n);
  const double expectedVertices = area / (0.5 * 0.4330127 * edgeLength * edgeLength);
  if (!(edgeLength > 0) || expectedVertices > maximumVertices)
  {
    edgeLength = std::sqrt(area / (0.5 * 0.4330127 * maximumVertices));
  }

  TwoCellMesh& mesh = this->Mesh;
  try
  {
    // --- Constrained Delaunay triangulation and refinement ---------------------------------
    Triangulation cdt;
    std::vector<VertexHandle> boundary(n);
    VertexHandle hint;
    for (std::size_t i = 0; i < n; ++i)
    {
      boundary[i] = cdt.insert(polygon[i], hint == VertexHandle() ? FaceHandle() : hint->face());
      hint = boundary[i];
    }
    for (std::size_t i = 0; i < n; ++i)
    {
      cdt.insert_constraint(boundary[i], boundary[(i + 1) % n]);
    }
    if (cdt.number_of_vertices() != n)
    {
      error = "TwoCellParameterization: boundary samples merged in the triangulation";
      this->Mesh = TwoCellMesh();
      return false;
    }
    // Delaunay refinement is only guaranteed to end for a smallest angle up to ~20.7 degrees
    // (b = 0.125); a larger bound could refine forever.
    const double shapeBound = this->ShapeBound > 0 ? std::min(this->ShapeBound, 0.125) : 0.0;
    const Criteria criteria(shapeBound, edgeLength);
    Refine(cdt, criteria);

    // --- Remove dividing edges ---------------------------------------------------------------
    // Inserting a point on an edge removes that edge, and every edge a Delaunay insertion
    // creates ends at the new point: neither the fix nor the re-refinement can create another
    // dividing edge, so the rounds end.
    int round = 0;
    for (;; ++round)
    {
      ResetVertexIndices(cdt, boundary);
      const std::vector<Point> midpoints = DividingEdgeMidpoints(cdt, sideMasks);
      if (midpoints.empty())
      {
        break;
      }
      if (round >= this->MaximumFixRounds)
      {
        std::ostringstream message;
        message << "TwoCellParameterization: " << midpoints.size() << " dividing edges remain after "
                << this->MaximumFixRounds << " rounds of fixes";
        error = message.str();
        this->Mesh = TwoCellMesh();
        return false;
      }
      for (const Point& p : midpoints)
      {
        cdt.insert(p);
      }
      mesh.DividingEdgeFixes += static_cast<int>(midpoints.size());
      // Re-marks the domain (new faces are not marked) and restores the size and shape.
      Refine(cdt, criteria);
    }

    // --- Output: boundary vertices first, in input order ---------------------------------------
    mesh.BoundaryCount = static_cast<Index>(n);
    mesh.Points.assign(xy, xy + 2 * n);
    mesh.Parameters.assign(uv, uv + 2 * n);
    std::vector<char> boundaryUsed(n, 0);
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
    {
      if (!f->is_in_domain())
      {
        continue;
      }
      for (int k = 0; k < 3; ++k)
      {
        const VertexHandle v = f->vertex(k);
        if (v->info() == InvalidIndex)
        {
          v->info() = mesh.NumberOfPoints();
          mesh.Points.push_back(v->point().x());
          mesh.Points.push_back(v->point().y());
        }
        else if (v->info() < static_cast<Index>(n))
        {
          boundaryUsed[v->info()] = 1;
        }
        mesh.Triangles.push_back(v->info());
      }
    }
    for (std::size_t i = 0; i < n; ++i)
    {
      if (!boundaryUsed[i] || !cdt.is_edge(boundary[i], boundary[(i + 1) % n]))
      {
        error = "TwoCellParameterization: the triangulation does not keep the boundary samples and edges";
        this->Mesh = TwoCellMesh();
        return false;
      }
    }
    mesh.Parameters.resize(mesh.Points.size(), 0);
  }
  catch (const std::exception& e)
  {
    error = std::string("TwoCellParameterization: triangulation failed: ") + e.what();
    this->Mesh = TwoCellMesh();
    return false;
  }
  mesh.Orientation = polygonOrientation * parameterOrientation;

  // --- Mean value coordinates -------------------------------------------------------------
  // Interior vertex i: sum_j w_ij (uv_i - uv_j) = 0 with Floater's weights
  // w_ij = (tan(a/2) + tan(b/2)) / |v_j - v_i|, a and b the angles at v_i beside edge ij.
  const Index boundaryCount = mesh.BoundaryCount;
  const Index interiorCount = mesh.NumberOfPoints() - boundaryCount;
  const std::vector<double>& p = mesh.Points;
  if (interiorCount > 0)
  {
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(static_cast<std::size_t>(mesh.NumberOfTriangles()) * 6 + interiorCount);
    std::vector<double> diagonal(interiorCount, 0);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(interiorCount, 2);
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
        const double weights[2] = { tangent / std::hypot(ax, ay), tangent / std::hypot(bx, by) };
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
    if (!finite)
    {
      error = "TwoCellParameterization: degenerate triangle (zero or non-finite mean value weight)";
      this->Mesh = TwoCellMesh();
      return false;
    }
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
      this->Mesh = TwoCellMesh();
      return false;
    }
    const Eigen::MatrixXd solution = solver.solve(rhs);
    if (solver.info() != Eigen::Success)
    {
      error = "TwoCellParameterization: the mean value system could not be solved";
      this->Mesh = TwoCellMesh();
      return false;
    }
    for (Index i = 0; i < interiorCount; ++i)
    {
      mesh.Parameters[2 * (boundaryCount + i)] = solution(i, 0);
      mesh.Parameters[2 * (boundaryCount + i) + 1] = solution(i, 1);
    }
  }

  // --- Check: one-to-one ----------------------------------------------------------------------
  mesh.MinimumInteriorMargin = interiorCount > 0 ? std::numeric_limits<double>::infinity() : 0.5;
  for (Index i = boundaryCount; i < mesh.NumberOfPoints(); ++i)
  {
    const double u = mesh.Parameters[2 * i], v = mesh.Parameters[2 * i + 1];
    const double margin = std::min(std::min(u, 1 - u), std::min(v, 1 - v));
    mesh.MinimumInteriorMargin = std::isfinite(margin) ? std::min(mesh.MinimumInteriorMargin, margin) : -1;
  }
  mesh.MinimumParameterArea = std::numeric_limits<double>::infinity();
  Index flipped = 0;
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    const Index* tri = &mesh.Triangles[3 * t];
    const double* a = &mesh.Parameters[2 * tri[0]];
    const double* b = &mesh.Parameters[2 * tri[1]];
    const double* c = &mesh.Parameters[2 * tri[2]];
    const double signedParameterArea =
      mesh.Orientation * 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    if (!(signedParameterArea > 0))
    {
      ++flipped;
    }
    mesh.MinimumParameterArea = std::min(mesh.MinimumParameterArea, signedParameterArea);
  }
  if (flipped > 0 || !(mesh.MinimumInteriorMargin > 0))
  {
    std::ostringstream message;
    message << "TwoCellParameterization: the parameterization is not one-to-one (" << flipped << " of "
            << mesh.NumberOfTriangles() << " triangles degenerate or flipped in (u, v), smallest interior margin "
            << mesh.MinimumInteriorMargin << ")";
    error = message.str();
    this->Mesh = TwoCellMesh();
    return false;
  }

  this->BuildLocator();
  return true;
}

void TwoCellParameterization::BuildLocator()
{
  const TwoCellMesh& mesh = this->Mesh;
  const Index triangles = mesh.NumberOfTriangles();
  double bounds[4] = { mesh.Points[0], mesh.Points[0], mesh.Points[1], mesh.Points[1] };
  for (Index i = 0; i < mesh.NumberOfPoints(); ++i)
  {
    bounds[0] = std::min(bounds[0], mesh.Points[2 * i]);
    bounds[1] = std::max(bounds[1], mesh.Points[2 * i]);
    bounds[2] = std::min(bounds[2], mesh.Points[2 * i + 1]);
    bounds[3] = std::max(bounds[3], mesh.Points[2 * i + 1]);
  }
  const double width = std::max(bounds[1] - bounds[0], 1e-300);
  const double height = std::max(bounds[3] - bounds[2], 1e-300);
  this->LocateTolerance = 1e-9 * std::max(width, height);
  // About one triangle per grid cell, cells roughly square, at most 1024 a side (thin cells
  // get a thin grid).
  const double cellSize = std::sqrt(width * height / std::max<Index>(triangles, 1));
  for (int d = 0; d < 2; ++d)
  {
    const double extent = d == 0 ? width : height;
    this->GridSize[d] = static_cast<int>(std::min(1024.0, std::max(1.0, std::ceil(extent / cellSize))));
    this->GridOrigin[d] = bounds[2 * d] - this->LocateTolerance;
    this->GridCellSize[d] = (extent + 2 * this->LocateTolerance) / this->GridSize[d];
  }
  auto cellOf = [this](double value, int d) {
    const double c = std::floor((value - this->GridOrigin[d]) / this->GridCellSize[d]);
    return static_cast<int>(std::min<double>(std::max(c, 0.0), this->GridSize[d] - 1));
  };
  const std::size_t cells = static_cast<std::size_t>(this->GridSize[0]) * this->GridSize[1];
  std::vector<int> ranges(4 * static_cast<std::size_t>(triangles));
  this->BucketStart.assign(cells + 1, 0);
  for (int pass = 0; pass < 2; ++pass)
  {
    std::vector<Index> fill;
    if (pass == 1)
    {
      for (std::size_t c = 0; c < cells; ++c)
      {
        this->BucketStart[c + 1] += this->BucketStart[c];
      }
      this->BucketTriangles.resize(this->BucketStart[cells]);
      fill.assign(this->BucketStart.begin(), this->BucketStart.end() - 1);
    }
    for (Index t = 0; t < triangles; ++t)
    {
      int* range = &ranges[4 * t];
      if (pass == 0)
      {
        const Index* tri = &mesh.Triangles[3 * t];
        for (int d = 0; d < 2; ++d)
        {
          double lo = mesh.Points[2 * tri[0] + d], hi = lo;
          for (int k = 1; k < 3; ++k)
          {
            lo = std::min(lo, mesh.Points[2 * tri[k] + d]);
            hi = std::max(hi, mesh.Points[2 * tri[k] + d]);
          }
          range[2 * d] = cellOf(lo - this->LocateTolerance, d);
          range[2 * d + 1] = cellOf(hi + this->LocateTolerance, d);
        }
      }
      for (int cy = range[2]; cy <= range[3]; ++cy)
      {
        for (int cx = range[0]; cx <= range[1]; ++cx)
        {
          const std::size_t c = static_cast<std::size_t>(cy) * this->GridSize[0] + cx;
          if (pass == 0)
          {
            ++this->BucketStart[c + 1];
          }
          else
          {
            this->BucketTriangles[fill[c]++] = t;
          }
        }
      }
    }
  }
}

bool TwoCellParameterization::Locate(double x, double y, Index& triangle, double barycentric[3]) const
{
  triangle = InvalidIndex;
  if (this->GridSize[0] == 0 || !std::isfinite(x) || !std::isfinite(y))
  {
    return false;
  }
  const double position[2] = { x, y };
  int cell[2];
  for (int d = 0; d < 2; ++d)
  {
    const double c = std::floor((position[d] - this->GridOrigin[d]) / this->GridCellSize[d]);
    if (c < 0 || c >= this->GridSize[d])
    {
      return false;
    }
    cell[d] = static_cast<int>(c);
  }
  const std::size_t c = static_cast<std::size_t>(cell[1]) * this->GridSize[0] + cell[0];
  const TwoCellMesh& mesh = this->Mesh;
  // The triangle in which (x, y) is deepest (largest smallest barycentric coordinate, scaled
  // to a distance) wins, so that points on shared edges get a definite answer.
  double best = -std::numeric_limits<double>::infinity();
  for (Index k = this->BucketStart[c]; k < this->BucketStart[c + 1]; ++k)
  {
    const Index t = this->BucketTriangles[k];
    const Index* tri = &mesh.Triangles[3 * t];
    const double* a = &mesh.Points[2 * tri[0]];
    const double* b = &mesh.Points[2 * tri[1]];
    const double* q = &mesh.Points[2 * tri[2]];
    const double twiceArea = (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0]);
    if (!(twiceArea > 0))
    {
      continue;
    }
    double lambda[3];
    lambda[0] = ((b[0] - x) * (q[1] - y) - (b[1] - y) * (q[0] - x)) / twiceArea;
    lambda[1] = ((q[0] - x) * (a[1] - y) - (q[1] - y) * (a[0] - x)) / twiceArea;
    lambda[2] = 1 - lambda[0] - lambda[1];
    // Barycentric coordinate times the opposite edge length = distance to that edge.
    const double edges[3] = { std::hypot(q[0] - b[0], q[1] - b[1]), std::hypot(a[0] - q[0], a[1] - q[1]),
      std::hypot(b[0] - a[0], b[1] - a[1]) };
    double depth = std::numeric_limits<double>::infinity();
    for (int k2 = 0; k2 < 3; ++k2)
    {
      depth = std::min(depth, lambda[k2] * twiceArea / edges[k2]);
    }
    if (depth > best)
    {
      best = depth;
      triangle = t;
      std::copy(lambda, lambda + 3, barycentric);
    }
  }
  if (triangle == InvalidIndex || best < -this->LocateTolerance)
  {
    triangle = InvalidIndex;
    return false;
  }
  // Rounding may leave a coordinate slightly negative: clamp so the result stays in the
  // triangle's image.
  double sum = 0;
  for (int k = 0; k < 3; ++k)
  {
    barycentric[k] = std::max(barycentric[k], 0.0);
    sum += barycentric[k];
  }
  for (int k = 0; k < 3; ++k)
  {
    barycentric[k] /= sum;
  }
  return true;
}

bool TwoCellParameterization::Evaluate(double x, double y, double uv[2]) const
{
  Index triangle;
  double barycentric[3];
  if (!this->Locate(x, y, triangle, barycentric))
  {
    return false;
  }
  const Index* tri = &this->Mesh.Triangles[3 * triangle];
  for (int d = 0; d < 2; ++d)
  {
    uv[d] = barycentric[0] * this->Mesh.Parameters[2 * tri[0] + d] +
      barycentric[1] * this->Mesh.Parameters[2 * tri[1] + d] + barycentric[2] * this->Mesh.Parameters[2 * tri[2] + d];
  }
  return true;
}
} // namespace topospline
