// Stage 4 of the paper (section 5.1): the parameterization Phi of one 2-cell onto the unit
// square. The closed boundary of the cell, sampled from its smoothed 1-cells, is triangulated
// (constrained Delaunay + Delaunay refinement that never splits the boundary, so the boundary
// vertices are exactly the samples), and every interior vertex gets (u, v) from Floater's mean
// value coordinates with the boundary fixed on the border of the square. A point location
// grid then evaluates Phi(x, y) anywhere in the cell, which is what F o Phi needs; Phi^-1(u, v)
// is made on request (TwoCellParameterization::Inverse), with a second grid over the square.
// Other maps on the same mesh, their weights reweighted by the input's gradient, are made on
// request too (WeightByFieldGradient): stage 4 tries them where a fit misses the data most.
//
// Pouch cells: the boundary walk may run out along a slit (a tree of boundary edges hanging
// from the outer loop into the cell) and straight back. The mesh is then cut open along the
// slits, so each visit of a slit sample is its own mesh vertex with its own (u, v), and the
// cut mesh is a disk whose border is exactly the walk.
//
// CGAL stays in the .cxx: its meshing headers cost ~20 s per translation unit.
#pragma once

#include "CoreTypes.h"
#include "TriangleBucketGrid.h"

#include <string>
#include <vector>

namespace topospline
{
class PiecewiseLinearField;

// Which edges TwoCellParameterization::WeightByFieldGradient strengthens.
enum class GradientWeighting
{
  AlongLevelSets,
  AlongGradient
};

// The triangulated cell and its parameterization.
struct TwoCellMesh
{
  // Vertex positions (x, y), interleaved. The first BoundaryCount vertices are the input
  // samples (as repaired, see Parameterize), in input order; the rest are interior Steiner
  // points. A slit sample visited k times is k vertices with equal (x, y) (the mesh is cut open
  // along the slit); the triangles on each side of the slit use the copy of that side.
  std::vector<double> Points;
  // (u, v) per vertex, interleaved: the given values on the boundary (bit for bit), mean value
  // coordinates inside.
  std::vector<double> Parameters;
  // Vertex index triples, counter-clockwise in (x, y).
  std::vector<Index> Triangles;
  Index BoundaryCount = 0;
  // +1 if Phi preserves orientation (triangles are also counter-clockwise in (u, v)), -1 if the
  // caller's (u, v) run around the square against the polygon's orientation, so that Phi is a
  // mirror map (all triangles clockwise in (u, v)). Either way Phi is one-to-one.
  int Orientation = 1;
  // Interior points inserted at the midpoints of "dividing edges" (interior edges joining two
  // boundary vertices on the same side of the square), which would give degenerate triangles.
  int DividingEdgeFixes = 0;
  // min over triangles of Orientation * (signed area in (u, v)): > 0 proves Phi one-to-one.
  double MinimumParameterArea = 0;
  // Smallest distance of an interior vertex's (u, v) to the border of the square.
  double MinimumInteriorMargin = 0;
  // Triangles flattened to zero area in (u, v) by rounding: a narrow arm of the cell crowds
  // towards the border of the square, and its interior vertices land within 1e-12 of it (see
  // CheckOneToOne). Phi is evaluated from (x, y), so they cost nothing there; the inverse map
  // skips them.
  Index CrowdedTriangles = 0;
  // Visits of pinch points moved apart (0: none), and whether samples were copied between
  // overlapping straight sides (a slit sampled two ways): TwoCellParameterization::Parameterize.
  int OpenedPinches = 0;
  bool ResampledOverlaps = false;
  // Slits outside the outer loop left out of the walk (DropSlitsOutsideTheLoop in the .cxx).
  int OutsideSlits = 0;

  Index NumberOfPoints() const { return static_cast<Index>(this->Points.size() / 2); }
  Index NumberOfTriangles() const { return static_cast<Index>(this->Triangles.size() / 3); }
};

class TwoCellParameterization
{
public:
  // Target edge length of the interior triangles. <= 0: the mean boundary sample spacing, as
  // in the paper ("size of inner triangles similar to the average sample point distance").
  double TargetEdgeLength = 0;
  // CGAL's shape bound b = sin^2(smallest angle); 0.125 ~ 20.7 degrees (CGAL's default, and
  // the largest value used: beyond it refinement need not terminate). 0: size criterion only.
  double ShapeBound = 0.125;
  // The edge length is raised where the target would need more vertices than this (a guard
  // against a tiny target on a large cell, not a quality knob).
  Index MaximumVertices = 200000;
  // Rounds of dividing-edge fixes (one round fixes every dividing edge present; refinement
  // never creates new ones, so one round normally suffices).
  int MaximumFixRounds = 8;

  // boundaryPoints: (x, y) of the n samples of the closed boundary, in order (either
  // orientation; a repeated first sample at the end is dropped). boundaryParameters: their
  // (u, v), on the border of the unit square, going monotonically once around it in the same
  // order. The walk may contain slits: it goes out along a path into the cell and comes back
  // along the same samples reversed (bit-identical coordinates), e.g. ..., s, p1, p2, M, p2, p1,
  // s, ... (s on the outer loop, M the tip; trees of such paths and wrapping around the start of
  // the sequence are allowed; each visit has its own (u, v)). After identifying equal
  // coordinates the boundary must be a simple closed outer loop plus trees inside it that touch
  // the loop at one vertex each and nothing else. Returns false with a message on invalid or
  // degenerate input (n < 4, non-finite values, a zero-length edge, a self-crossing or
  // self-touching boundary that is not of this form, zero area, (u, v) off the border or not
  // monotone) or if the map could not be made one-to-one.
  // A walk of another form is repaired where it can be: consecutive samples within 1e-12 of the
  // walk's extent (or 16 ulps of its coordinates) of one another (a 1-cell piece of no length,
  // sampled k times at one point, its samples apart by rounding) are made one sample; sides
  // that overlap along a straight stretch, each sampled its own way, get each other's samples
  // (a slit then); a loop that touches itself at a point (a pinched cell) is opened there by
  // 1e-3 of an edge.
  bool Parameterize(const std::vector<double>& boundaryPoints, const std::vector<double>& boundaryParameters,
    std::string& error);

  // Another map on the mesh of the last successful Parameterize (same triangles, same boundary
  // (u, v)): each mean value weight w_ij of an interior vertex i is multiplied by
  // 1 / (1 / strength + c^2), c the cosine (AlongGradient: the sine) of the angle between edge
  // ij and the gradient of `field` at i (damped where the field is nearly flat). AlongLevelSets:
  // edges along the field's level sets pull up to strength + 1 times harder than edges across
  // them; AlongGradient the other way round. The weights stay positive, so Phi stays one-to-one
  // (Floater). Along the gradient, the flow lines from a cell's minimum pull hardest: around a
  // minimum the cell wraps 360 degrees (the tip of a slit), the round level sets then rise
  // along (1, 1) of the square, with a sixth of the mean value map's falling pairs
  // (TestTwoCellParameterization). Along the level sets does not straighten the level curves
  // as one might hope (the weights' ratio is bounded by the mesh's angles, and a level curve
  // dozens of edges long stays bent); it spreads the cell differently, which some fits follow
  // better (TwoCellReconstruction::AlternativeMapStrength tries both). False, with the mesh's
  // (u, v) unusable, if the map could not be made one-to-one (work on a copy).
  bool WeightByFieldGradient(const PiecewiseLinearField& field, double strength, GradientWeighting weighting,
    std::string& error);

  // The result of the last successful Parameterize (empty otherwise).
  const TwoCellMesh& GetMesh() const { return this->Mesh; }

  // Finds the triangle containing (x, y) and its barycentric coordinates. Points on the
  // boundary, or outside by rounding only (relative 1e-9), are found; others return false.
  // A point on a slit lies in triangles of both sides: either is reported.
  bool Locate(double x, double y, Index& triangle, double barycentric[3]) const;
  // Phi(x, y): the piecewise linear parameterization at (x, y). False outside the cell.
  bool Evaluate(double x, double y, double uv[2]) const;

public:
  // Phi^-1, for as long as the parameterization it was made from lives unchanged. Only the
  // planar Bezier patches need it, and its grid over the square is as large as the one Phi
  // uses (about 2 kB of a typical cell's 9), so cells do not keep one: half a million cells of
  // 1000 x 1000 noise would hold a gigabyte for an output that is left empty there.
  class Inverse
  {
  public:
    // Phi^-1(u, v): the triangle containing (u, v) in parameter space, its corners' (x, y)
    // interpolated. (u, v) on the border of the square or outside by rounding only (1e-9) are
    // found; false outside the square (or when made before a successful Parameterize).
    bool Evaluate(double u, double v, double xy[2]) const;

  private:
    friend class TwoCellParameterization;
    explicit Inverse(const TwoCellMesh& mesh);
    const TwoCellMesh* Mesh;
    TriangleBucketGrid Grid;
  };
  Inverse MakeInverse() const { return Inverse(this->Mesh); }

  // Meshes of at most this many triangles get no buckets for Locate: every triangle is tried.
  static constexpr Index ScannedMeshTriangles = 64;

private:
  TwoCellMesh Mesh;
  TriangleBucketGrid PointGrid; // over (x, y): Locate, Evaluate
};
} // namespace topospline
