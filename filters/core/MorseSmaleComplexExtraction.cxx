#include "MorseSmaleComplexExtraction.h"

#include "DisjointSets.h"
#include "PlanarGeometry.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <numeric>

namespace topospline
{
namespace
{
// Follows a deterministic successor function until a fixed point, labelling every visited
// element with the label of the fixed point. Linear overall; `limit` guards against a cycle,
// which a valid gradient cannot have.
template <typename Next, typename Terminal>
bool LabelByFlow(Index n, std::vector<Index>& label, Next next, Terminal terminalLabel)
{
  label.assign(n, InvalidIndex);
  std::vector<Index> path;
  for (Index start = 0; start < n; ++start)
  {
    path.clear();
    Index x = start;
    while (label[x] == InvalidIndex)
    {
      const Index y = next(x);
      if (y == InvalidIndex)
      {
        label[x] = terminalLabel(x);
        break;
      }
      path.push_back(x);
      if (static_cast<Index>(path.size()) > n)
      {
        return false;
      }
      x = y;
    }
    for (Index p : path)
    {
      label[p] = label[x];
    }
  }
  return true;
}
Index ThirdVertex(const TriangleMeshTopology& mesh, Index t, Index a, Index b)
{
  for (Index v : mesh.TriangleVertices[t])
  {
    if (v != a && v != b)
    {
      return v;
    }
  }
  return InvalidIndex;
}

double Orientation(const std::vector<double>& p, Index a, Index b, Index c)
{
  return Orientation2D(&p[2 * a], &p[2 * b], &p[2 * c]);
}

// Counter-clockwise angle in [0, 2pi) from direction (rx, ry) to (dx, dy).
double TurningAngle(double rx, double ry, double dx, double dy)
{
  double angle = std::atan2(rx * dy - ry * dx, rx * dx + ry * dy);
  return angle < 0 ? angle + 2 * M_PI : angle;
}
} // namespace

void MorseSmaleComplexExtraction::SortAroundExtremum(const MorseSmaleComplex& complex,
  const std::vector<double>& saddleEnds, Index extremum, std::vector<Index>& oneCells)
{
  // The 1-cells of an extremum form a planar tree rooted at it (V-paths merge and never
  // split): descending ones as vertex paths, ascending ones as triangle paths (through the
  // centroids). Order its leaves counter-clockwise: compare two paths where they diverge by
  // the turning angle of their next step from the way back (from +x at the root).
  const bool minimum = complex.CriticalPoints[extremum].MorseIndex == 0;
  std::sort(oneCells.begin(), oneCells.end());
  std::vector<std::vector<std::array<double, 2>>> paths(oneCells.size());
  for (size_t k = 0; k < oneCells.size(); ++k)
  {
    const OneCell& oneCell = complex.OneCells[oneCells[k]];
    // From the extremum outwards; ascending 1-cells are stored from the saddle.
    for (size_t p = 0; p < oneCell.Values.size(); ++p)
    {
      const size_t i = minimum ? p : oneCell.Values.size() - 1 - p;
      paths[k].push_back({ oneCell.Points[2 * i], oneCell.Points[2 * i + 1] });
    }
    paths[k].push_back({ saddleEnds[2 * oneCells[k]], saddleEnds[2 * oneCells[k] + 1] });
  }
  auto pathOf = [&](Index a) -> const std::vector<std::array<double, 2>>& {
    return paths[std::lower_bound(oneCells.begin(), oneCells.end(), a) - oneCells.begin()];
  };
  auto less = [&](Index ia, Index ib) {
    const auto& pa = pathOf(ia);
    const auto& pb = pathOf(ib);
    size_t k = 1;
    while (k < pa.size() && k < pb.size() && pa[k] == pb[k])
    {
      ++k;
    }
    if (k >= pa.size() || k >= pb.size())
    {
      return pa.size() != pb.size() ? pa.size() < pb.size() : ia < ib; // one path contains the other
    }
    const auto& node = pa[k - 1];
    double rx = 1, ry = 0;
    if (k >= 2)
    {
      rx = pa[k - 2][0] - node[0];
      ry = pa[k - 2][1] - node[1];
    }
    const double aa = TurningAngle(rx, ry, pa[k][0] - node[0], pa[k][1] - node[1]);
    const double ab = TurningAngle(rx, ry, pb[k][0] - node[0], pb[k][1] - node[1]);
    return aa != ab ? aa < ab : ia < ib;
  };
  // Sort a copy: `less` finds paths in `oneCells`, which must stay sorted by id meanwhile.
  std::vector<Index> sorted = oneCells;
  std::sort(sorted.begin(), sorted.end(), less);
  oneCells = sorted;
}

namespace
{
// A saddle opens into 4 sectors (2 on the boundary), each between one descending and one
// ascending 1-cell of it: a corner of one 2-cell.
struct Sector
{
  Index Saddle, Descending, Ascending;
  Index Component; // the region it opens into, if any
  // Left of the descending 1-cell walked from the minimum to the saddle; then it is also
  // left of the ascending 1-cell walked from the saddle to the maximum.
  bool LeftOfDescending;
};

// What the steps of Extract after the discrete gradient share.
struct ExtractionState
{
  ExtractionState(const PlanarScalarField& field, const TriangleMeshTopology& mesh, const DiscreteGradient& gradient,
    const ParallelFor& parallel, MorseSmaleComplex& complex)
    : Field(field)
    , Mesh(mesh)
    , Gradient(gradient)
    , Values(field.Values.data())
    , Parallel(parallel)
    , Complex(complex)
    , NumberOfVertices(static_cast<Index>(field.Values.size()))
  {
  }

  const PlanarScalarField& Field;
  const TriangleMeshTopology& Mesh;
  const DiscreteGradient& Gradient;
  const double* Values;
  const ParallelFor& Parallel;
  MorseSmaleComplex& Complex;
  const Index NumberOfVertices;

  // Critical points by their cell; the saddles in id order.
  std::vector<Index> MinimumOfVertex, MaximumOfTriangle, Saddles;
  // Per saddle k: the 1-cells traced from it, two descending (slots 4k, 4k+1) and up to two
  // ascending ones (4k+2, 4k+3), InvalidIndex for none.
  std::vector<Index> OneCellOfSlot;
  // The mesh cut along the 1-cells: vertices on them, edges crossed, and the regions left.
  std::vector<unsigned char> OnOneCell;
  UnionFind Regions{ 0 };
  std::vector<Sector> Sectors;
  // Per extremum, its 1-cells counter-clockwise around it; per 1-cell, its place there.
  std::vector<std::vector<Index>> OneCellsAround;
  std::vector<Index> PlaceAround;
  // 2-cells as pairs of sectors, and the sectors left without a partner.
  std::vector<std::array<Index, 2>> CellSectors;
  std::vector<Index> UnpairedSectors;

  // The V-path steps of the gradient (InvalidIndex at a critical cell).
  Index NextVertex(Index v) const
  {
    const Index e = this->Gradient.VertexEdge[v];
    return e == InvalidIndex ? InvalidIndex : this->Mesh.OtherEdgeVertex(e, v);
  }
  Index NextTriangle(Index t) const
  {
    const Index e = this->Gradient.TriangleEdge[t];
    return e == InvalidIndex ? InvalidIndex : this->Mesh.OtherEdgeTriangle(e, t);
  }
  bool SameLabels(Index a, Index b) const
  {
    return this->Complex.AscendingManifold[a] == this->Complex.AscendingManifold[b];
  }
  // The 1-cell next to `oneCell` around its extremum: counter-clockwise (+1) or clockwise (-1).
  Index NeighbourAround(Index oneCell, int direction) const
  {
    const OneCell& sep = this->Complex.OneCells[oneCell];
    const auto& around = this->OneCellsAround[sep.Type == OneCell::Descending ? sep.Source : sep.Destination];
    const Index n = static_cast<Index>(around.size());
    return around[(this->PlaceAround[oneCell] + n + direction) % n];
  }
  // The minimum and maximum of the 2-cell a sector is a corner of.
  std::pair<Index, Index> GroupKey(Index i) const
  {
    return std::make_pair(this->Complex.OneCells[this->Sectors[i].Descending].Source,
      this->Complex.OneCells[this->Sectors[i].Ascending].Destination);
  }
};

// Critical cells, placed at their highest vertex, in an order that depends only on the data
// (stable ids).
void CollectCriticalPoints(ExtractionState& state)
{
  const TriangleMeshTopology& mesh = state.Mesh;
  const DiscreteGradient& grad = state.Gradient;
  const double* f = state.Values;
  const VertexOrder order{ f };
  auto& cps = state.Complex.CriticalPoints;
  for (Index v = 0; v < state.NumberOfVertices; ++v)
  {
    if (grad.IsCriticalVertex(v))
    {
      cps.push_back({ InvalidIndex, 0, v, v, f[v], mesh.IsBoundaryVertex(v) });
    }
  }
  for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
  {
    if (grad.IsCriticalEdge(e))
    {
      const Index o = DiscreteGradient::EdgeOwner(mesh, order, e);
      const Index other = mesh.EdgeVertices[e][0] == o ? mesh.EdgeVertices[e][1] : mesh.EdgeVertices[e][0];
      cps.push_back({ InvalidIndex, 1, o, e, f[o], mesh.IsBoundaryVertex(o), other });
    }
  }
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    if (grad.IsCriticalTriangle(t))
    {
      const Index o = DiscreteGradient::TriangleOwner(mesh, order, t);
      cps.push_back({ InvalidIndex, 2, o, t, f[o], mesh.IsBoundaryVertex(o), InvalidIndex,
        mesh.VertexTriangleEnd(o) - mesh.VertexTriangleBegin(o) == 1 });
    }
  }
  std::sort(cps.begin(), cps.end(), [](const CriticalPoint& a, const CriticalPoint& b) {
    if (a.MorseIndex != b.MorseIndex)
    {
      return a.MorseIndex < b.MorseIndex;
    }
    return a.Vertex != b.Vertex ? a.Vertex < b.Vertex : a.Cell < b.Cell;
  });
  for (Index id = 0; id < static_cast<Index>(cps.size()); ++id)
  {
    cps[id].Id = id;
  }
}

void IndexCriticalPoints(ExtractionState& state)
{
  const auto& cps = state.Complex.CriticalPoints;
  state.MinimumOfVertex.assign(state.NumberOfVertices, InvalidIndex);
  state.MaximumOfTriangle.assign(state.Mesh.NumberOfTriangles(), InvalidIndex);
  for (Index id = 0; id < static_cast<Index>(cps.size()); ++id)
  {
    if (cps[id].MorseIndex == 0)
    {
      state.MinimumOfVertex[cps[id].Cell] = id;
    }
    else if (cps[id].MorseIndex == 1)
    {
      state.Saddles.push_back(id);
    }
    else
    {
      state.MaximumOfTriangle[cps[id].Cell] = id;
    }
  }
}

// Ascending manifolds: per vertex, the minimum its V-path reaches. (Descending manifolds are
// read from the 2-cells, DescendingManifoldsAndCentroids.) False if the gradient has a cycle.
bool LabelAscendingManifolds(ExtractionState& state)
{
  return LabelByFlow(
    state.NumberOfVertices, state.Complex.AscendingManifold, [&state](Index v) { return state.NextVertex(v); },
    [&state](Index v) { return state.MinimumOfVertex[v]; });
}

void AppendPoint(const PlanarScalarField& field, Index v, std::vector<double>& points)
{
  points.push_back(field.Points[2 * v]);
  points.push_back(field.Points[2 * v + 1]);
}

// The descending 1-cell of saddle `saddle` through the endpoint `side` of its edge: the
// vertex V-path from there down to a minimum, stored from the minimum. Returns false if the
// path does not end (a cycle of the gradient).
bool TraceDescendingOneCell(const ExtractionState& state, Index saddle, int side, OneCell& oneCell)
{
  const PlanarScalarField& field = state.Field;
  const Index nV = state.NumberOfVertices;
  const CriticalPoint& cp = state.Complex.CriticalPoints[saddle];
  const Index owner = cp.Vertex;
  oneCell.Type = OneCell::Descending;
  oneCell.Destination = saddle;
  std::vector<Index> cells{ owner };
  Index u = state.Mesh.EdgeVertices[cp.Cell][side];
  if (u != owner)
  {
    cells.push_back(u);
  }
  while (state.NextVertex(u) != InvalidIndex && static_cast<Index>(cells.size()) <= nV)
  {
    u = state.NextVertex(u);
    cells.push_back(u);
  }
  const bool ends = state.NextVertex(u) == InvalidIndex;
  oneCell.Source = state.MinimumOfVertex[u];
  oneCell.MeshCells.assign(cells.rbegin(), cells.rend());
  for (Index v : oneCell.MeshCells)
  {
    AppendPoint(field, v, oneCell.Points);
    oneCell.Values.push_back(state.Values[v]);
  }
  return ends;
}

// The ascending 1-cell of `saddle` that starts at triangle t of its edge: the triangle
// V-path up to a maximum, from the saddle's vertex to the maximum's, one point per triangle:
// its centroid, unless the segment to the next triangle's point does not cross the edge
// between them (the two form a non-convex quad, on a triangle mesh), then the midpoint of that
// edge. Such a segment leaves the two triangles and can cross a descending 1-cell; a polyline
// whose every segment stays in its two triangles meets none (descending 1-cells run along edges
// no triangle of the gradient is paired with), and stage 3 falls back to these polylines where
// smoothed curves cross. The points are decided from the maximum back, each against the next
// one as finally chosen: deciding each against the next centroid let a centroid's segment run
// to the next triangle's midpoint outside the quad (stress case #275, a Delaunay mesh: an
// ascending polyline crossed both descending 1-cells of a saddle). A grid's quads are convex:
// all centroids. Returns false if the path does not end (a cycle of the gradient).
bool TraceAscendingOneCell(const ExtractionState& state, Index saddle, Index t, OneCell& oneCell)
{
  const PlanarScalarField& field = state.Field;
  const TriangleMeshTopology& mesh = state.Mesh;
  const double* f = state.Values;
  const auto& cps = state.Complex.CriticalPoints;
  const Index owner = cps[saddle].Vertex;
  oneCell.Type = OneCell::Ascending;
  oneCell.Source = saddle;
  AppendPoint(field, owner, oneCell.Points);
  oneCell.Values.push_back(f[owner]);
  oneCell.MeshCells.push_back(t);
  while (state.NextTriangle(t) != InvalidIndex && static_cast<Index>(oneCell.MeshCells.size()) <= mesh.NumberOfTriangles())
  {
    t = state.NextTriangle(t);
    oneCell.MeshCells.push_back(t);
  }
  const bool ends = state.NextTriangle(t) == InvalidIndex;
  const std::size_t n = oneCell.MeshCells.size();
  const auto centroid = [&](Index triangle, double c[2]) {
    c[0] = c[1] = 0;
    for (Index v : mesh.TriangleVertices[triangle])
    {
      c[0] += field.Points[2 * v] / 3;
      c[1] += field.Points[2 * v + 1] / 3;
    }
  };
  // Centroids first; then, from the maximum back, a centroid whose segment to the next point
  // (final by then) does not cross the edge between the two triangles gives way to that edge's
  // midpoint, from which both neighbouring segments stay in their triangles.
  const std::size_t first = oneCell.Points.size() / 2;
  for (std::size_t i = 0; i < n; ++i)
  {
    const auto& tv = mesh.TriangleVertices[oneCell.MeshCells[i]];
    double c[2];
    centroid(oneCell.MeshCells[i], c);
    oneCell.Points.push_back(c[0]);
    oneCell.Points.push_back(c[1]);
    oneCell.Values.push_back((f[tv[0]] / 3 + f[tv[1]] / 3) + f[tv[2]] / 3);
  }
  for (std::size_t i = n - 1; i-- > 0 && !field.IsGrid();)
  {
    const auto& tv = mesh.TriangleVertices[oneCell.MeshCells[i]];
    const auto& next = mesh.TriangleVertices[oneCell.MeshCells[i + 1]];
    Index shared[2] = { InvalidIndex, InvalidIndex };
    int count = 0;
    for (Index v : tv)
    {
      if (std::find(next.begin(), next.end(), v) != next.end() && count < 2)
      {
        shared[count++] = v;
      }
    }
    if (count < 2)
    {
      continue;
    }
    double* c = &oneCell.Points[2 * (first + i)];
    const double* d = &oneCell.Points[2 * (first + i + 1)];
    const double* a = &field.Points[2 * shared[0]];
    const double* b = &field.Points[2 * shared[1]];
    if (!SegmentsCrossProperly(c, d, a, b))
    {
      c[0] = a[0] / 2 + b[0] / 2;
      c[1] = a[1] / 2 + b[1] / 2;
      oneCell.Values[first + i] = f[shared[0]] / 2 + f[shared[1]] / 2;
    }
  }
  oneCell.Destination = state.MaximumOfTriangle[t];
  const Index top = cps[oneCell.Destination].Vertex;
  AppendPoint(field, top, oneCell.Points);
  oneCell.Values.push_back(f[top]);
  return ends;
}

// 1-cells as V-paths: two descending and up to two ascending per saddle (one per triangle of
// its edge). Slots are fixed per saddle so the parallel tracing writes disjoint entries.
// False if the gradient has a cycle.
bool TraceOneCells(ExtractionState& state)
{
  const auto& saddles = state.Saddles;
  const Index nS = static_cast<Index>(saddles.size());
  std::vector<OneCell> slots(4 * static_cast<size_t>(nS));
  std::vector<unsigned char> traced(4 * static_cast<size_t>(nS), 0);
  std::atomic<bool> cycle(false); // written by every thread that meets one
  state.Parallel(0, nS, [&](Index begin, Index end) {
    for (Index k = begin; k < end; ++k)
    {
      const Index e = state.Complex.CriticalPoints[saddles[k]].Cell;
      for (int side = 0; side < 2; ++side)
      {
        if (!TraceDescendingOneCell(state, saddles[k], side, slots[4 * k + side]))
        {
          cycle = true;
        }
        traced[4 * k + side] = 1;
      }
      for (int side = 0; side < 2; ++side)
      {
        const Index t = state.Mesh.EdgeTriangles[e][side];
        if (t == InvalidIndex)
        {
          continue;
        }
        if (!TraceAscendingOneCell(state, saddles[k], t, slots[4 * k + 2 + side]))
        {
          cycle = true;
        }
        traced[4 * k + 2 + side] = 1;
      }
    }
  });
  if (cycle)
  {
    return false;
  }
  auto& oneCells = state.Complex.OneCells;
  state.OneCellOfSlot.assign(slots.size(), InvalidIndex);
  for (size_t s = 0; s < slots.size(); ++s)
  {
    if (traced[s])
    {
      state.OneCellOfSlot[s] = static_cast<Index>(oneCells.size());
      oneCells.push_back(std::move(slots[s]));
    }
  }
  return true;
}

// A 2-cell is a region of vertices that no 1-cell crosses. Cut the mesh along the 1-cells:
// vertices of descending 1-cells and of maximum triangles join no region directly, and edges
// that an ascending 1-cell crosses join nothing. Descending 1-cells bound the descending
// manifolds, so each region lies in one of them; its maximum is read from the sectors.
// (Per-vertex labels alone are not enough: both sides of a 1-cell can flow to the same
// extrema, e.g. next to a saddle whose descending 1-cells share a minimum.)
void CutMeshAlongOneCells(ExtractionState& state)
{
  const TriangleMeshTopology& mesh = state.Mesh;
  const MorseSmaleComplex& complex = state.Complex;
  const auto& cps = complex.CriticalPoints;
  const Index nV = state.NumberOfVertices;
  std::vector<unsigned char>& onOneCell = state.OnOneCell;
  onOneCell.assign(nV, 0);
  std::vector<unsigned char> crossed(mesh.NumberOfEdges(), 0);
  for (const OneCell& oneCell : complex.OneCells)
  {
    if (oneCell.Type == OneCell::Descending)
    {
      for (Index v : oneCell.MeshCells)
      {
        onOneCell[v] = 1;
      }
    }
    else
    {
      crossed[cps[oneCell.Source].Cell] = 1;
      for (size_t i = 0; i + 1 < oneCell.MeshCells.size(); ++i)
      {
        crossed[state.Gradient.TriangleEdge[oneCell.MeshCells[i]]] = 1;
      }
    }
  }
  for (const CriticalPoint& cp : cps)
  {
    if (cp.MorseIndex == 2)
    {
      for (Index v : mesh.TriangleVertices[cp.Cell])
      {
        onOneCell[v] = 1;
      }
    }
  }
  state.Regions = UnionFind(nV);
  for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
  {
    const Index a = mesh.EdgeVertices[e][0], b = mesh.EdgeVertices[e][1];
    if (!crossed[e] && !onOneCell[a] && !onOneCell[b] && state.SameLabels(a, b))
    {
      state.Regions.Union(a, b);
    }
  }
}

// The sectors of every saddle and the region each opens into. The 2-cell of a sector runs
// along the whole ascending 1-cell on the side of the descending one, so walk the ascending
// path, tracking which endpoint of each crossed edge is on that side, and take the region of
// the first such vertex that is off the 1-cells and carries the sector's labels.
void FindSectors(ExtractionState& state)
{
  const TriangleMeshTopology& mesh = state.Mesh;
  const MorseSmaleComplex& complex = state.Complex;
  const auto& cps = complex.CriticalPoints;
  const auto& saddles = state.Saddles;
  const Index nS = static_cast<Index>(saddles.size());
  for (Index k = 0; k < nS; ++k)
  {
    const CriticalPoint& saddle = cps[saddles[k]];
    const Index e = saddle.Cell;
    for (int tside = 0; tside < 2; ++tside)
    {
      const Index ascending = state.OneCellOfSlot[4 * k + 2 + tside];
      if (ascending == InvalidIndex)
      {
        continue;
      }
      const OneCell& up = complex.OneCells[ascending];
      for (int dside = 0; dside < 2; ++dside)
      {
        // The sector lies left of the curve (minimum -> x -> y -> other minimum) through the
        // saddle edge when its triangle does.
        const Index x = mesh.EdgeVertices[e][dside], y = mesh.EdgeVertices[e][1 - dside];
        const Index c = ThirdVertex(mesh, up.MeshCells.front(), x, y);
        Sector sector{ saddles[k], state.OneCellOfSlot[4 * k + dside], ascending, InvalidIndex,
          Orientation(state.Field.Points, x, y, c) > 0 };
        const Index m = complex.OneCells[sector.Descending].Source;
        auto accept = [&](Index w) {
          if (!state.OnOneCell[w] && complex.AscendingManifold[w] == m)
          {
            sector.Component = state.Regions.Find(w);
            return true;
          }
          return false;
        };
        Index near = mesh.EdgeVertices[e][dside], far = mesh.EdgeVertices[e][1 - dside];
        bool found = accept(near);
        for (size_t i = 0; !found && i + 1 < up.MeshCells.size(); ++i)
        {
          const Index crossing = state.Gradient.TriangleEdge[up.MeshCells[i]];
          const Index p = mesh.EdgeVertices[crossing][0], q = mesh.EdgeVertices[crossing][1];
          if (p == near || q == near)
          {
            far = p == near ? q : p;
          }
          else
          {
            near = p == far ? q : p;
            found = accept(near);
          }
        }
        state.Sectors.push_back(sector);
      }
    }
  }
}

// The 1-cells of each extremum (descending ones for minima, ascending ones for maxima),
// counter-clockwise around it, and each 1-cell's place in its extremum's order. Each 1-cell
// ends at the midpoint of its saddle edge: two saddles that share their highest vertex
// share a 1-cell path up to it, and only their edges tell the two apart.
void SortOneCellsAroundExtrema(ExtractionState& state)
{
  const PlanarScalarField& field = state.Field;
  const TriangleMeshTopology& mesh = state.Mesh;
  const MorseSmaleComplex& complex = state.Complex;
  const auto& cps = complex.CriticalPoints;
  std::vector<double> saddleEdgeMidpoints(2 * complex.OneCells.size());
  auto& arcsOfExtremum = state.OneCellsAround;
  arcsOfExtremum.assign(cps.size(), {});
  for (Index a = 0; a < static_cast<Index>(complex.OneCells.size()); ++a)
  {
    const OneCell& oneCell = complex.OneCells[a];
    const bool descending = oneCell.Type == OneCell::Descending;
    arcsOfExtremum[descending ? oneCell.Source : oneCell.Destination].push_back(a);
    const Index edge = cps[descending ? oneCell.Destination : oneCell.Source].Cell;
    for (int c = 0; c < 2; ++c)
    {
      saddleEdgeMidpoints[2 * a + c] = 0.5 *
        (field.Points[2 * mesh.EdgeVertices[edge][0] + c] + field.Points[2 * mesh.EdgeVertices[edge][1] + c]);
    }
  }
  auto& placeAroundExtremum = state.PlaceAround;
  placeAroundExtremum.assign(complex.OneCells.size(), InvalidIndex);
  state.Parallel(0, static_cast<Index>(cps.size()), [&](Index begin, Index end) {
    for (Index x = begin; x < end; ++x)
    {
      MorseSmaleComplexExtraction::SortAroundExtremum(complex, saddleEdgeMidpoints, x, arcsOfExtremum[x]);
      for (size_t k = 0; k < arcsOfExtremum[x].size(); ++k)
      {
        placeAroundExtremum[arcsOfExtremum[x][k]] = static_cast<Index>(k);
      }
    }
  });
}

// Pair sectors into 2-cells by tracing the faces of the planar graph of 1-cells. A cell lies
// left of its first descending 1-cell (walked from the minimum), so counter-clockwise of it
// around the minimum up to the next descending 1-cell; and left of its first ascending
// 1-cell (walked to the maximum), so clockwise of it around the maximum up to the previous
// ascending 1-cell. Those two 1-cells must belong to one saddle, whose sector between them
// (right of both) closes the cell. The order is what makes this exact: a sliver between
// two 1-cells that run side by side has no region to identify it, and one region can touch
// the sectors of two cells on both sides of a thin loop (a saddle whose two ascending
// 1-cells reach the same maximum), which paired them into a pouch outside its own loop.
// Returns which sectors it paired.
std::vector<unsigned char> PairSectorsByPlanarOrder(ExtractionState& state)
{
  const auto& sectors = state.Sectors;
  std::map<std::pair<Index, Index>, Index> sectorOfArcs;
  for (Index i = 0; i < static_cast<Index>(sectors.size()); ++i)
  {
    sectorOfArcs[{ sectors[i].Descending, sectors[i].Ascending }] = i;
  }
  std::vector<unsigned char> sectorPaired(sectors.size(), 0);
  for (Index i = 0; i < static_cast<Index>(sectors.size()); ++i)
  {
    const Sector& left = sectors[i];
    if (!left.LeftOfDescending || sectorPaired[i])
    {
      continue;
    }
    const auto right =
      sectorOfArcs.find({ state.NeighbourAround(left.Descending, +1), state.NeighbourAround(left.Ascending, -1) });
    if (right == sectorOfArcs.end() || sectors[right->second].LeftOfDescending || sectorPaired[right->second])
    {
      continue;
    }
    state.CellSectors.push_back({ i, right->second });
    sectorPaired[i] = sectorPaired[right->second] = 1;
  }
  return sectorPaired;
}

// Thin cells (e.g. ascending 1-cells that run side by side and merge) have no region to tell
// them apart: pair a whole (minimum, maximum) group by the planar order of the descending
// 1-cells at the minimum. A cell lies between two descending 1-cells that are consecutive
// around its minimum: the sector left of one pairs with the sector right of its
// counter-clockwise successor. At the maximum the same holds with the ascending 1-cells;
// there the sector left of one (walking towards the maximum) pairs with the one right of
// its clockwise predecessor. Try the minimum first; fall back to the maximum when some stay
// unpaired (e.g. saddles sharing a vertex have identical descending paths).
void PairGroupByPlanarOrder(ExtractionState& state, const std::vector<Index>& group)
{
  const auto& sectors = state.Sectors;
  std::vector<std::array<Index, 2>> pairs;
  std::vector<Index> rest;
  for (int end = 0; end < 2; ++end)
  {
    std::vector<std::array<Index, 2>> tryPairs;
    std::vector<Index> tryRest;
    auto arcOf = [&](const Sector& sector) { return end == 0 ? sector.Descending : sector.Ascending; };
    std::vector<unsigned char> used(group.size(), 0);
    for (size_t a = 0; a < group.size(); ++a)
    {
      const Sector& left = sectors[group[a]];
      if (used[a] || !left.LeftOfDescending)
      {
        continue;
      }
      const Index neighbour = state.NeighbourAround(arcOf(left), end == 0 ? +1 : -1);
      for (size_t b = 0; b < group.size(); ++b)
      {
        const Sector& right = sectors[group[b]];
        if (!used[b] && b != a && !right.LeftOfDescending && arcOf(right) == neighbour)
        {
          tryPairs.push_back({ group[a], group[b] });
          used[a] = used[b] = 1;
          break;
        }
      }
    }
    for (size_t a = 0; a < group.size(); ++a)
    {
      if (!used[a])
      {
        tryRest.push_back(group[a]);
      }
    }
    if (end == 0 || tryRest.size() < rest.size())
    {
      pairs = tryPairs;
      rest = tryRest;
    }
    if (rest.size() <= 2)
    {
      break;
    }
  }
  state.CellSectors.insert(state.CellSectors.end(), pairs.begin(), pairs.end());
  if (rest.size() == 2)
  {
    state.CellSectors.push_back({ rest[0], rest[1] });
  }
  else
  {
    state.UnpairedSectors.insert(state.UnpairedSectors.end(), rest.begin(), rest.end());
  }
}

// What the planar order leaves (it fails only where it ties): two sectors form a 2-cell when
// they share (minimum, maximum) and open into the same region. A cell thinner than the mesh
// may have no region (no vertex off its 1-cells) or fall apart into two: within a
// (minimum, maximum) group, the sectors left over after pairing by region pair up when
// exactly two are left; with more, the group is paired by planar order alone.
void PairLeftoverSectors(ExtractionState& state, const std::vector<unsigned char>& sectorPaired)
{
  const auto& sectors = state.Sectors;
  std::vector<Index> bySector;
  for (Index i = 0; i < static_cast<Index>(sectors.size()); ++i)
  {
    if (!sectorPaired[i])
    {
      bySector.push_back(i);
    }
  }
  std::stable_sort(bySector.begin(), bySector.end(), [&](Index a, Index b) {
    const auto ka = state.GroupKey(a), kb = state.GroupKey(b);
    if (ka != kb)
    {
      return ka < kb;
    }
    return sectors[a].Component < sectors[b].Component;
  });
  for (size_t i = 0; i < bySector.size();)
  {
    size_t j = i;
    while (j < bySector.size() && state.GroupKey(bySector[j]) == state.GroupKey(bySector[i]))
    {
      ++j;
    }
    // First by region: two sectors opening into the same region are one cell.
    std::vector<std::array<Index, 2>> byRegion;
    std::vector<Index> leftover;
    for (size_t k = i; k < j;)
    {
      size_t l = k;
      while (l < j && sectors[bySector[l]].Component == sectors[bySector[k]].Component)
      {
        ++l;
      }
      if (l - k == 2 && sectors[bySector[k]].Component != InvalidIndex)
      {
        byRegion.push_back({ bySector[k], bySector[k + 1] });
      }
      else
      {
        leftover.insert(leftover.end(), bySector.begin() + k, bySector.begin() + l);
      }
      k = l;
    }
    if (leftover.size() <= 2)
    {
      state.CellSectors.insert(state.CellSectors.end(), byRegion.begin(), byRegion.end());
      if (leftover.size() == 2)
      {
        state.CellSectors.push_back({ leftover[0], leftover[1] });
      }
    }
    else
    {
      PairGroupByPlanarOrder(state, std::vector<Index>(bySector.begin() + i, bySector.begin() + j));
    }
    i = j;
  }
}

// The 2-cells, from the pairs of sectors, in the order of their first sector: an order fixed
// by the saddles' ids; then a cell per sector left without a partner. Returns the 2-cell of
// each region's root vertex.
std::vector<Index> BuildTwoCells(ExtractionState& state)
{
  MorseSmaleComplex& complex = state.Complex;
  auto& cellSectors = state.CellSectors;
  const auto& sectors = state.Sectors;
  for (auto& pair : cellSectors)
  {
    if (pair[1] < pair[0])
    {
      std::swap(pair[0], pair[1]);
    }
  }
  std::sort(cellSectors.begin(), cellSectors.end());
  std::vector<Index> cellOfRoot(state.NumberOfVertices, InvalidIndex);
  for (const auto& pair : cellSectors)
  {
    TwoCell cell;
    for (int k = 0; k < 2; ++k)
    {
      const Sector& sector = sectors[pair[k]];
      cell.Saddles[k] = sector.Saddle;
      cell.BoundaryOneCells[2 * k] = sector.Descending;
      cell.BoundaryOneCells[2 * k + 1] = sector.Ascending;
      if (sector.Component != InvalidIndex)
      {
        cellOfRoot[sector.Component] = static_cast<Index>(complex.TwoCells.size());
      }
    }
    cell.Sectors = 2;
    cell.Minimum = complex.OneCells[cell.BoundaryOneCells[0]].Source;
    cell.Maximum = complex.OneCells[cell.BoundaryOneCells[1]].Destination;
    cell.Pouch = cell.Saddles[0] == cell.Saddles[1];
    complex.TwoCells.push_back(cell);
  }
  // A sector that found no partner still bounds a region of the domain: keep it as a cell
  // with one sector, so that nothing is silently dropped (tests flag such cells).
  for (Index i : state.UnpairedSectors)
  {
    const Sector& sector = sectors[i];
    TwoCell cell;
    cell.Saddles[0] = sector.Saddle;
    cell.BoundaryOneCells[0] = sector.Descending;
    cell.BoundaryOneCells[1] = sector.Ascending;
    cell.Sectors = 1;
    cell.Minimum = complex.OneCells[sector.Descending].Source;
    cell.Maximum = complex.OneCells[sector.Ascending].Destination;
    if (sector.Component != InvalidIndex && cellOfRoot[sector.Component] == InvalidIndex)
    {
      cellOfRoot[sector.Component] = static_cast<Index>(complex.TwoCells.size());
    }
    complex.TwoCells.push_back(cell);
  }
  return cellOfRoot;
}

// Vertices of regions get their region's 2-cell, and a 2-cell without a region its saddle's
// vertex. Returns the vertices that had no region.
std::vector<Index> AssignRegionsToTwoCells(ExtractionState& state, const std::vector<Index>& cellOfRoot)
{
  MorseSmaleComplex& complex = state.Complex;
  const auto& cps = complex.CriticalPoints;
  const Index nV = state.NumberOfVertices;
  complex.TwoCellId.assign(nV, InvalidIndex);
  std::vector<unsigned char> hasRegion(complex.TwoCells.size(), 0);
  state.Parallel(0, nV, [&](Index begin, Index end) {
    for (Index v = begin; v < end; ++v)
    {
      complex.TwoCellId[v] = cellOfRoot[state.Regions.Root(v)];
    }
  });
  std::vector<Index> unassigned;
  for (Index v = 0; v < nV; ++v)
  {
    if (complex.TwoCellId[v] != InvalidIndex)
    {
      hasRegion[complex.TwoCellId[v]] = 1;
    }
    else
    {
      unassigned.push_back(v);
    }
  }
  // A cell without a region of its own (a thin cell, or a whole domain that is one pouch)
  // grows from its saddle's vertex.
  for (Index c = 0; c < static_cast<Index>(complex.TwoCells.size()); ++c)
  {
    const Index v = cps[complex.TwoCells[c].Saddles[0]].Vertex;
    if (!hasRegion[c] && complex.TwoCellId[v] == InvalidIndex)
    {
      complex.TwoCellId[v] = c;
    }
  }
  return unassigned;
}

// The vertices without a 2-cell (1-cell vertices, slivers) join a neighbouring cell, first
// through neighbours flowing to the same minimum, then through any neighbour.
void GrowTwoCellsOverUnassigned(ExtractionState& state, std::vector<Index>& unassigned)
{
  const TriangleMeshTopology& mesh = state.Mesh;
  MorseSmaleComplex& complex = state.Complex;
  const Index nV = state.NumberOfVertices;
  auto forNeighbours = [&](Index u, auto&& visit) {
    for (Index i = mesh.VertexTriangleBegin(u); i < mesh.VertexTriangleEnd(u); ++i)
    {
      for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
      {
        visit(w);
      }
    }
  };
  // Breadth-first from the assigned vertices that touch unassigned ones (the only ones that
  // can spread), in vertex order: linear in the unassigned part, deterministic.
  std::vector<unsigned char> queued(nV, 0);
  for (int pass = 0; pass < 2; ++pass)
  {
    unassigned.erase(std::remove_if(unassigned.begin(), unassigned.end(),
                       [&](Index u) { return complex.TwoCellId[u] != InvalidIndex; }),
      unassigned.end());
    if (unassigned.empty())
    {
      break;
    }
    std::vector<Index> queue;
    std::fill(queued.begin(), queued.end(), 0);
    auto enqueue = [&](Index w) {
      if (complex.TwoCellId[w] != InvalidIndex && !queued[w])
      {
        queued[w] = 1;
        queue.push_back(w);
      }
    };
    for (Index u : unassigned)
    {
      enqueue(u);
      forNeighbours(u, enqueue);
    }
    for (size_t head = 0; head < queue.size(); ++head)
    {
      const Index u = queue[head];
      forNeighbours(u, [&](Index w) {
        if (complex.TwoCellId[w] == InvalidIndex && (pass == 1 || state.SameLabels(u, w)))
        {
          complex.TwoCellId[w] = complex.TwoCellId[u];
          queue.push_back(w);
        }
      });
    }
  }
}

// Per 2-cell its vertex count and centroid; per vertex the maximum it flows up to, the
// maximum of its 2-cell.
void DescendingManifoldsAndCentroids(ExtractionState& state)
{
  const PlanarScalarField& field = state.Field;
  MorseSmaleComplex& complex = state.Complex;
  const auto& cps = complex.CriticalPoints;
  const Index nV = state.NumberOfVertices;
  for (Index v = 0; v < nV; ++v)
  {
    TwoCell& cell = complex.TwoCells[complex.TwoCellId[v]];
    ++cell.NumberOfVertices;
    cell.Centroid[0] += field.Points[2 * v];
    cell.Centroid[1] += field.Points[2 * v + 1];
  }
  complex.DescendingManifold.resize(nV);
  for (Index v = 0; v < nV; ++v)
  {
    complex.DescendingManifold[v] = complex.TwoCells[complex.TwoCellId[v]].Maximum;
  }
  for (TwoCell& cell : complex.TwoCells)
  {
    if (cell.NumberOfVertices > 0)
    {
      cell.Centroid[0] /= cell.NumberOfVertices;
      cell.Centroid[1] /= cell.NumberOfVertices;
    }
    else
    {
      // A cell with no vertex of its own: place it at its first saddle.
      const Index v = cps[cell.Saddles[0]].Vertex;
      cell.Centroid[0] = field.Points[2 * v];
      cell.Centroid[1] = field.Points[2 * v + 1];
    }
  }
}
} // namespace

//------------------------------------------------------------------------------
// The steps of the paper's section 3.1: the mesh, the discrete gradient, its critical cells,
// the 1-cells as V-paths, the 2-cells and the per-vertex manifolds.
bool MorseSmaleComplexExtraction::Extract(
  const PlanarScalarField& field, MorseSmaleComplex& complex, std::string& error)
{
  complex = MorseSmaleComplex();
  this->ReadAsConstant = false;
  if (!this->CheckField(field, error))
  {
    return false;
  }
  if (this->NearConstantAsConstant && !field.Values.empty())
  {
    const auto [lowest, highest] = std::minmax_element(field.Values.begin(), field.Values.end());
    if (VariesByLessThanPrecision(*lowest, *highest, std::max(std::abs(*lowest), std::abs(*highest))))
    {
      PlanarScalarField constant = field;
      std::fill(constant.Values.begin(), constant.Values.end(), *lowest + 0.5 * (*highest - *lowest));
      this->ReadAsConstant = this->ExtractChecked(constant, complex, error);
      return this->ReadAsConstant;
    }
  }
  return this->ExtractChecked(field, complex, error);
}

bool MorseSmaleComplexExtraction::ExtractChecked(
  const PlanarScalarField& field, MorseSmaleComplex& complex, std::string& error)
{
  const TriangleMeshTopology* mesh = this->PrepareMesh(field, error);
  if (!mesh)
  {
    return false;
  }
  complex.Frame = DomainFrame(field);
  this->Hooks.Report(0.2);
  if (this->Hooks.Aborted())
  {
    error = "aborted";
    return false;
  }

  this->Gradient.Compute(*mesh, field.Values.data(), this->Parallel);
  this->Hooks.Report(0.5);
  if (this->Hooks.Aborted())
  {
    error = "aborted";
    return false;
  }

  ExtractionState state(field, *mesh, this->Gradient, this->Parallel, complex);
  CollectCriticalPoints(state);
  if (this->CriticalPointsOnly)
  {
    this->Hooks.Report(1.0);
    return true;
  }
  IndexCriticalPoints(state);
  if (!LabelAscendingManifolds(state))
  {
    error = "internal error: the discrete gradient has a cycle";
    return false;
  }
  this->Hooks.Report(0.65);
  if (!TraceOneCells(state))
  {
    error = "internal error: the discrete gradient has a cycle";
    return false;
  }
  this->Hooks.Report(0.8);

  // 2-cells: the regions the 1-cells cut out, identified by the saddle sectors that open into
  // them; sectors pair up by the planar order of the 1-cells around the extrema.
  CutMeshAlongOneCells(state);
  FindSectors(state);
  SortOneCellsAroundExtrema(state);
  PairLeftoverSectors(state, PairSectorsByPlanarOrder(state));
  std::vector<Index> unassigned = AssignRegionsToTwoCells(state, BuildTwoCells(state));
  GrowTwoCellsOverUnassigned(state, unassigned);
  DescendingManifoldsAndCentroids(state);
  this->Hooks.Report(1.0);
  return true;
}

//------------------------------------------------------------------------------
PlanarFrame MorseSmaleComplexExtraction::DomainFrame(const PlanarScalarField& field)
{
  if (field.IsGrid())
  {
    return PlanarFrame::FromExtents(field.GridSpacing[0], field.GridSpacing[1]);
  }
  const auto& p = field.Points;
  double sumX = 0, sumY = 0;
  std::size_t count = 0;
  for (std::size_t t = 0; t + 2 < field.Triangles.size(); t += 3)
  {
    for (int e = 0; e < 3; ++e)
    {
      const std::size_t a = field.Triangles[t + e], b = field.Triangles[t + (e + 1) % 3];
      if (2 * std::max(a, b) + 1 < p.size())
      {
        const double dx = p[2 * a] - p[2 * b], dy = p[2 * a + 1] - p[2 * b + 1];
        sumX += dx * dx;
        sumY += dy * dy;
        ++count;
      }
    }
  }
  return count ? PlanarFrame::FromExtents(std::sqrt(sumX / count), std::sqrt(sumY / count)) : PlanarFrame();
}

//------------------------------------------------------------------------------
bool MorseSmaleComplexExtraction::CheckField(const PlanarScalarField& field, std::string& error) const
{
  const Index nV = static_cast<Index>(field.Values.size());
  if (nV == 0 || (field.Triangles.empty() && !field.IsGrid() && !this->GivenMesh))
  {
    error = "the input has no triangles";
    return false;
  }
  if (field.IsGrid() && static_cast<long long>(field.GridDimensions[0]) * field.GridDimensions[1] != nV)
  {
    error = "the grid dimensions do not match the number of values";
    return false;
  }
  if (field.Points.size() != 2 * field.Values.size() && !(this->CriticalPointsOnly && field.Points.empty()))
  {
    error = "expected one scalar value per point";
    return false;
  }
  for (Index v = 0; v < nV; ++v)
  {
    if (!std::isfinite(field.Values[v]))
    {
      error = "the scalar field has a non-finite value (NaN or Inf) at point " + std::to_string(v);
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
// The given mesh or Mesh, built from the grid or the triangles; null (with `error`) for a
// mesh the complex cannot live on.
const TriangleMeshTopology* MorseSmaleComplexExtraction::PrepareMesh(const PlanarScalarField& field, std::string& error)
{
  const Index nV = static_cast<Index>(field.Values.size());
  if (this->GivenMesh)
  {
    if (this->GivenMesh->NumberOfVertices() != nV)
    {
      error = "the given mesh does not match the field";
      return nullptr;
    }
  }
  else if (field.IsGrid())
  {
    this->Mesh.BuildGrid(field.GridDimensions[0], field.GridDimensions[1], this->Parallel);
  }
  else if (!this->Mesh.Build(nV, field.Triangles, this->Parallel, error))
  {
    return nullptr;
  }
  const TriangleMeshTopology& mesh = this->GivenMesh ? *this->GivenMesh : this->Mesh;
  for (Index v = 0; v < nV; ++v)
  {
    if (mesh.VertexTriangleBegin(v) == mesh.VertexTriangleEnd(v))
    {
      error = "point " + std::to_string(v) + " is not used by any triangle";
      return nullptr;
    }
  }
  // A mesh given as triangles (not a grid, not the caller's): must be a planar disk.
  if (!this->GivenMesh && !field.IsGrid() && !field.Points.empty() && !this->Mesh.CheckPlanarDisk(field.Points, error))
  {
    return nullptr;
  }
  return &mesh;
}
} // namespace topospline
