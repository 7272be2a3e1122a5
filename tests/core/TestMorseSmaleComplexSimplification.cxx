// Tests of stage 2 (MorseSmaleComplexSimplification) on the synthetic fields: identity at 0%,
// monotone counts over a 0..100% sweep, Euler characteristic, well-formed 1-cells and 2-cells,
// stable ids, junction points, bad input, and an independent persistence computation (join and
// split trees by union-find) for the extrema that survive each threshold.
//
// Usage: TestMorseSmaleComplexSimplification [--benchmark]
//   --benchmark also times ComputeHierarchy and Simplify on a 1000x1000 Shepard field.
// Prints "N passed, N failed" and returns nonzero on failure.
#include "MorseSmaleComplexExtraction.h"
#include "MorseSmaleComplexSimplification.h"
#include "SyntheticFields.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <vector>

using namespace topospline;

namespace
{
int Passed = 0;
int Failed = 0;

// Records one check; prints the first few failures of each label.
bool Check(bool condition, const std::string& label, const std::string& detail = std::string())
{
  static std::map<std::string, int> printed;
  if (condition)
  {
    ++Passed;
    return true;
  }
  ++Failed;
  if (printed[label]++ < 5)
  {
    std::printf("  FAILED: %s %s\n", label.c_str(), detail.c_str());
  }
  return false;
}

PlanarScalarField FieldFromGrid(const GridField& grid)
{
  PlanarScalarField field;
  const int nx = grid.Dimensions[0], ny = grid.Dimensions[1];
  field.Points.reserve(2 * static_cast<size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i)
    {
      field.Points.push_back(grid.Origin[0] + i * grid.Spacing[0]);
      field.Points.push_back(grid.Origin[1] + j * grid.Spacing[1]);
    }
  }
  field.Triangles = GridTriangles(nx, ny);
  field.Values = grid.Values;
  return field;
}

double Milliseconds(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

bool SameSeparatrix(const Separatrix& a, const Separatrix& b)
{
  return a.Type == b.Type && a.Source == b.Source && a.Destination == b.Destination &&
    a.MeshCells == b.MeshCells && a.Points == b.Points && a.Values == b.Values;
}

bool SameTwoCell(const TwoCell& a, const TwoCell& b)
{
  return a.Minimum == b.Minimum && a.Maximum == b.Maximum && a.Saddles == b.Saddles && a.Arcs == b.Arcs &&
    a.Pouch == b.Pouch && a.NumberOfVertices == b.NumberOfVertices && a.Centroid[0] == b.Centroid[0] &&
    a.Centroid[1] == b.Centroid[1] && a.Sectors == b.Sectors;
}

bool SameComplex(const MorseSmaleComplex& a, const MorseSmaleComplex& b)
{
  if (a.CriticalPoints.size() != b.CriticalPoints.size() || a.Separatrices.size() != b.Separatrices.size() ||
    a.TwoCells.size() != b.TwoCells.size())
  {
    return false;
  }
  for (size_t i = 0; i < a.CriticalPoints.size(); ++i)
  {
    const CriticalPoint &p = a.CriticalPoints[i], &q = b.CriticalPoints[i];
    if (p.Id != q.Id || p.MorseIndex != q.MorseIndex || p.Vertex != q.Vertex || p.Cell != q.Cell ||
      p.Value != q.Value || p.OnBoundary != q.OnBoundary)
    {
      return false;
    }
  }
  for (size_t i = 0; i < a.Separatrices.size(); ++i)
  {
    if (!SameSeparatrix(a.Separatrices[i], b.Separatrices[i]))
    {
      return false;
    }
  }
  for (size_t i = 0; i < a.TwoCells.size(); ++i)
  {
    if (!SameTwoCell(a.TwoCells[i], b.TwoCells[i]))
    {
      return false;
    }
  }
  return a.AscendingManifold == b.AscendingManifold && a.DescendingManifold == b.DescendingManifold &&
    a.TwoCellId == b.TwoCellId;
}

//------------------------------------------------------------------------------
// Independent persistence of the extrema of the PL field: the join tree (minima, sweeping up)
// and the split tree (maxima, sweeping down) by union-find over the vertices, in stage 1's
// order (value, then vertex id). Knows nothing of gradients or of the complex.
struct ExtremumPersistence
{
  double Persistence = std::numeric_limits<double>::infinity(); // infinite for the global one
  // The extremum's sublevel (superlevel) component just before it dies, or ever, touches the
  // domain boundary, or it dies at a boundary vertex.
  bool SeesBoundary = false;
};

std::map<Index, ExtremumPersistence> MergeTreePersistence(
  const TriangleMeshTopology& mesh, const std::vector<double>& f, bool minima)
{
  const Index nV = mesh.NumberOfVertices();
  std::vector<std::vector<Index>> neighbours(nV);
  for (const auto& edge : mesh.EdgeVertices)
  {
    neighbours[edge[0]].push_back(edge[1]);
    neighbours[edge[1]].push_back(edge[0]);
  }
  auto below = [&](Index a, Index b) { // a comes first in the sweep
    const bool lower = f[a] < f[b] || (f[a] == f[b] && a < b);
    return minima ? lower : !lower;
  };
  std::vector<Index> order(nV);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), below);
  std::vector<Index> rank(nV);
  for (Index i = 0; i < nV; ++i)
  {
    rank[order[i]] = i;
  }
  std::vector<Index> parent(nV), oldest(nV);
  std::vector<unsigned char> boundary(nV);
  auto find = [&](Index x) {
    while (parent[x] != x)
    {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  };
  std::map<Index, ExtremumPersistence> result;
  for (Index v : order)
  {
    parent[v] = v;
    oldest[v] = v;
    boundary[v] = mesh.IsBoundaryVertex(v);
    std::vector<Index> roots;
    for (Index w : neighbours[v])
    {
      if (rank[w] < rank[v])
      {
        roots.push_back(find(w));
      }
    }
    std::sort(roots.begin(), roots.end());
    roots.erase(std::unique(roots.begin(), roots.end()), roots.end());
    if (roots.empty())
    {
      result[v] = ExtremumPersistence();
      continue;
    }
    // Elder rule: the component with the earliest extremum survives, the others die at v.
    Index elder = roots[0];
    for (Index r : roots)
    {
      if (rank[oldest[r]] < rank[oldest[elder]])
      {
        elder = r;
      }
    }
    for (Index r : roots)
    {
      if (r != elder)
      {
        ExtremumPersistence& p = result[oldest[r]];
        p.Persistence = std::abs(f[v] - f[oldest[r]]);
        p.SeesBoundary = boundary[r] || mesh.IsBoundaryVertex(v);
      }
    }
    for (Index r : roots)
    {
      boundary[elder] = boundary[elder] || boundary[r];
      parent[r] = elder;
    }
    boundary[elder] = boundary[elder] || boundary[v];
    parent[v] = elder;
  }
  for (auto& entry : result)
  {
    if (std::isinf(entry.second.Persistence))
    {
      entry.second.SeesBoundary = true; // its component ends up being the whole domain
    }
  }
  return result;
}

//------------------------------------------------------------------------------
// Structural checks of one simplified complex against the mesh and field it came from.
struct Shape
{
  int NonSimpleArcs = 0;
};

void CheckComplex(const std::string& name, const PlanarScalarField& field, const TriangleMeshTopology& mesh,
  const MorseSmaleComplex& input, const SimplificationOutput& result, bool wholeHierarchy, Shape& shape)
{
  const MorseSmaleComplex& c = result.Complex;
  const auto& cps = c.CriticalPoints;
  const Index nCP = static_cast<Index>(cps.size());
  const auto counts = c.CountByIndex();
  Check(counts[0] - counts[1] + counts[2] == 1, name + " Euler characteristic",
    std::to_string(counts[0]) + " - " + std::to_string(counts[1]) + " + " + std::to_string(counts[2]));

  // Survivors: a sorted subset of the input, unchanged; the removed ones are listed.
  bool sorted = true, unchanged = true;
  std::set<Index> kept;
  for (Index i = 0; i < nCP; ++i)
  {
    const CriticalPoint& cp = cps[i];
    kept.insert(cp.Id);
    if (i > 0)
    {
      const CriticalPoint& p = cps[i - 1];
      sorted = sorted &&
        std::make_tuple(p.MorseIndex, p.Vertex, p.Cell) < std::make_tuple(cp.MorseIndex, cp.Vertex, cp.Cell);
    }
    const bool valid = cp.Id >= 0 && cp.Id < static_cast<Index>(input.CriticalPoints.size());
    const CriticalPoint& original = input.CriticalPoints[valid ? cp.Id : 0];
    unchanged = unchanged && valid && original.Vertex == cp.Vertex && original.Cell == cp.Cell &&
      original.Value == cp.Value && original.MorseIndex == cp.MorseIndex && original.OnBoundary == cp.OnBoundary;
  }
  Check(sorted, name + " critical points sorted");
  Check(unchanged, name + " surviving critical points keep id, vertex, value");
  std::set<Index> removed;
  bool cancellationsConsistent = true;
  for (const Cancellation& k : result.Cancellations)
  {
    removed.insert(k.Lower);
    removed.insert(k.Upper);
    const CriticalPoint& lower = input.CriticalPoints[k.Lower];
    const CriticalPoint& upper = input.CriticalPoints[k.Upper];
    cancellationsConsistent = cancellationsConsistent && upper.MorseIndex == lower.MorseIndex + 1 &&
      k.Persistence == std::abs(upper.Value - lower.Value) && k.Threshold >= k.Persistence &&
      (k.Threshold < result.AbsoluteThreshold || wholeHierarchy) &&
      input.CriticalPoints[k.Survivor].MorseIndex == (lower.MorseIndex == 0 ? 0 : 2);
  }
  Check(cancellationsConsistent, name + " cancellations consistent");
  Check(removed.size() == 2 * result.Cancellations.size() && kept.size() + removed.size() == input.CriticalPoints.size(),
    name + " every input critical point is kept or removed, once");
  bool disjoint = true;
  for (Index id : removed)
  {
    disjoint = disjoint && kept.count(id) == 0;
  }
  Check(disjoint, name + " removed and kept are disjoint");

  // 1-cells: paths in the mesh from the right critical cells, with the field's points.
  std::vector<int> descending(nCP, 0), ascending(nCP, 0);
  bool arcsValid = true, geometryValid = true;
  std::string detail;
  for (size_t a = 0; a < c.Separatrices.size(); ++a)
  {
    const Separatrix& arc = c.Separatrices[a];
    const bool d = arc.Type == Separatrix::Descending;
    const Index lowerIndex = d ? 0 : 1;
    if (arc.Source < 0 || arc.Source >= nCP || arc.Destination < 0 || arc.Destination >= nCP ||
      cps[arc.Source].MorseIndex != lowerIndex || cps[arc.Destination].MorseIndex != lowerIndex + 1 ||
      arc.MeshCells.empty())
    {
      arcsValid = false;
      detail = "arc " + std::to_string(a) + " endpoints";
      continue;
    }
    const size_t n = arc.MeshCells.size();
    std::set<Index> distinct(arc.MeshCells.begin(), arc.MeshCells.end());
    shape.NonSimpleArcs += distinct.size() != n;
    if (d)
    {
      ++descending[arc.Destination];
      bool ok = arc.MeshCells.front() == cps[arc.Source].Vertex && arc.MeshCells.back() == cps[arc.Destination].Vertex &&
        arc.Points.size() == 2 * n && arc.Values.size() == n;
      for (size_t i = 0; ok && i < n; ++i)
      {
        const Index v = arc.MeshCells[i];
        ok = arc.Points[2 * i] == field.Points[2 * v] && arc.Points[2 * i + 1] == field.Points[2 * v + 1] &&
          arc.Values[i] == field.Values[v] && (i == 0 || mesh.FindEdge(arc.MeshCells[i - 1], v) != InvalidIndex);
      }
      geometryValid = geometryValid && ok;
      if (!ok)
      {
        detail = "descending arc " + std::to_string(a);
      }
    }
    else
    {
      ++ascending[arc.Source];
      const auto& saddleTriangles = mesh.EdgeTriangles[cps[arc.Source].Cell];
      bool ok = arc.MeshCells.back() == cps[arc.Destination].Cell && arc.Points.size() == 2 * (n + 2) &&
        arc.Values.size() == n + 2 &&
        (saddleTriangles[0] == arc.MeshCells[0] || saddleTriangles[1] == arc.MeshCells[0]);
      const Index sv = cps[arc.Source].Vertex, mv = cps[arc.Destination].Vertex;
      ok = ok && arc.Points[0] == field.Points[2 * sv] && arc.Values[0] == field.Values[sv] &&
        arc.Points[2 * (n + 1)] == field.Points[2 * mv] && arc.Values[n + 1] == field.Values[mv];
      for (size_t i = 0; ok && i < n; ++i)
      {
        const Index t = arc.MeshCells[i];
        double cx = 0, value = 0;
        for (Index v : mesh.TriangleVertices[t])
        {
          cx += field.Points[2 * v] / 3;
          value += field.Values[v] / 3;
        }
        ok = arc.Points[2 * (i + 1)] == cx && arc.Values[i + 1] == value;
        if (ok && i > 0)
        {
          // Consecutive triangles share an edge.
          int shared = 0;
          for (Index e : mesh.TriangleEdges[t])
          {
            shared += mesh.OtherEdgeTriangle(e, t) == arc.MeshCells[i - 1];
          }
          ok = shared == 1;
        }
      }
      geometryValid = geometryValid && ok;
      if (!ok)
      {
        detail = "ascending arc " + std::to_string(a);
      }
    }
  }
  Check(arcsValid, name + " 1-cells join critical points of consecutive index", detail);
  Check(geometryValid, name + " 1-cells are mesh paths with the field's points and values", detail);
  bool saddleArcs = true;
  Index boundarySaddles = 0, interiorSaddles = 0;
  for (Index i = 0; i < nCP; ++i)
  {
    if (cps[i].MorseIndex == 1)
    {
      const int expectedUp = cps[i].OnBoundary ? 1 : 2;
      saddleArcs = saddleArcs && descending[i] == 2 && ascending[i] == expectedUp;
      (cps[i].OnBoundary ? boundarySaddles : interiorSaddles) += 1;
    }
  }
  Check(saddleArcs, name + " every saddle keeps 2 descending and 2 (interior) or 1 (boundary) ascending 1-cells");

  // 2-cells: closed cycles min -> saddle -> max -> saddle -> min; one per pair of corners.
  bool cellsValid = true;
  for (size_t k = 0; k < c.TwoCells.size(); ++k)
  {
    const TwoCell& cell = c.TwoCells[k];
    bool ok = cell.Sectors == 2 && cell.Pouch == (cell.Saddles[0] == cell.Saddles[1]);
    for (int s = 0; ok && s < 2; ++s)
    {
      const Index down = cell.Arcs[2 * s], up = cell.Arcs[2 * s + 1];
      ok = down >= 0 && up >= 0 && down < static_cast<Index>(c.Separatrices.size()) &&
        up < static_cast<Index>(c.Separatrices.size()) &&
        c.Separatrices[down].Type == Separatrix::Descending && c.Separatrices[up].Type == Separatrix::Ascending &&
        c.Separatrices[down].Source == cell.Minimum && c.Separatrices[down].Destination == cell.Saddles[s] &&
        c.Separatrices[up].Source == cell.Saddles[s] && c.Separatrices[up].Destination == cell.Maximum;
    }
    if (!ok && cellsValid)
    {
      detail = "2-cell " + std::to_string(k) + " sectors " + std::to_string(cell.Sectors);
    }
    cellsValid = cellsValid && ok;
  }
  Check(cellsValid, name + " every 2-cell is a closed min-saddle-max-saddle cycle (or pouch)", detail);
  Check(static_cast<Index>(c.TwoCells.size()) == 2 * interiorSaddles + boundarySaddles,
    name + " one 2-cell per two saddle corners");

  bool labels = c.TwoCellId.size() == field.Values.size() && c.AscendingManifold.size() == field.Values.size() &&
    c.DescendingManifold.size() == field.Values.size();
  std::vector<Index> vertices(c.TwoCells.size(), 0);
  for (size_t v = 0; labels && v < c.TwoCellId.size(); ++v)
  {
    const Index id = c.TwoCellId[v], a = c.AscendingManifold[v], d = c.DescendingManifold[v];
    labels = id >= 0 && id < static_cast<Index>(c.TwoCells.size()) && a >= 0 && a < nCP && d >= 0 && d < nCP &&
      cps[a].MorseIndex == 0 && cps[d].MorseIndex == 2;
    if (labels)
    {
      ++vertices[id];
    }
  }
  Check(labels, name + " every vertex has a 2-cell and surviving extrema");
  bool counted = labels;
  for (size_t k = 0; counted && k < c.TwoCells.size(); ++k)
  {
    counted = vertices[k] == c.TwoCells[k].NumberOfVertices;
  }
  Check(counted, name + " 2-cell vertex counts match the per-vertex ids");

  // Junction points: a mesh cell shared by 2+ of the listed 1-cells, all of its extremum.
  bool junctionsValid = true;
  for (const JunctionPoint& j : result.JunctionPoints)
  {
    bool ok = j.Separatrices.size() >= 2 && j.Extremum >= 0 && j.Extremum < nCP;
    for (Index a : j.Separatrices)
    {
      const Separatrix& arc = c.Separatrices[a];
      ok = ok && arc.Type == j.Type &&
        (j.Type == Separatrix::Descending ? arc.Source : arc.Destination) == j.Extremum &&
        std::find(arc.MeshCells.begin(), arc.MeshCells.end(), j.Cell) != arc.MeshCells.end();
    }
    junctionsValid = junctionsValid && ok;
  }
  Check(junctionsValid, name + " junction points lie on 2+ 1-cells of their extremum");
}

//------------------------------------------------------------------------------
struct SweepSummary
{
  std::array<Index, 3> Input{};
  std::array<Index, 3> At25{};
  Index Junctions25 = 0;
  int NonSimpleArcs = 0;
  Index Compared = 0;
  Index Mismatches = 0;
  Index Inversions = 0;
  Index ElderViolations = 0;
};

SweepSummary RunField(const std::string& name, const GridField& grid, bool fullSweep)
{
  SweepSummary summary;
  const PlanarScalarField field = FieldFromGrid(grid);
  MorseSmaleComplexExtraction extraction;
  MorseSmaleComplex input;
  std::string error;
  if (!Check(extraction.Extract(field, input, error), name + " extraction", error))
  {
    return summary;
  }
  summary.Input = input.CountByIndex();
  MorseSmaleComplexSimplification simplification;
  if (!Check(simplification.ComputeHierarchy(input, error), name + " hierarchy", error))
  {
    return summary;
  }
  const auto& hierarchy = simplification.Hierarchy();
  bool monotone = true;
  for (size_t k = 0; k < hierarchy.size(); ++k)
  {
    monotone = monotone && (k == 0 || hierarchy[k].Threshold >= hierarchy[k - 1].Threshold);
    summary.Inversions += k > 0 && hierarchy[k].Persistence < hierarchy[k - 1].Threshold;
    const CriticalPoint& removed = input.CriticalPoints[hierarchy[k].Lower].MorseIndex == 0
      ? input.CriticalPoints[hierarchy[k].Lower]
      : input.CriticalPoints[hierarchy[k].Upper];
    const CriticalPoint& survivor = input.CriticalPoints[hierarchy[k].Survivor];
    // The elder rule would keep the deeper minimum (higher maximum).
    summary.ElderViolations += removed.MorseIndex == 0 ? survivor.Value > removed.Value : survivor.Value < removed.Value;
  }
  Check(monotone, name + " hierarchy thresholds are non-decreasing");
  double range[2] = { input.CriticalPoints[0].Value, input.CriticalPoints[0].Value };
  for (const CriticalPoint& cp : input.CriticalPoints)
  {
    range[0] = std::min(range[0], cp.Value);
    range[1] = std::max(range[1], cp.Value);
  }
  Check(simplification.MaximumPersistence() == range[1] - range[0], name + " maximum persistence is the critical value range");

  // 0%: the input itself.
  SimplificationOutput zero;
  Check(simplification.Simplify(0, zero, error), name + " simplify 0%", error);
  Check(SameComplex(zero.Complex, input), name + " 0% returns the input unchanged");
  Check(zero.Cancellations.empty(), name + " 0% cancels nothing");

  // Independent persistence of the PL extrema, compared where it is comparable (see below).
  const auto joinTree = MergeTreePersistence(extraction.Mesh, field.Values, true);
  const auto splitTree = MergeTreePersistence(extraction.Mesh, field.Values, false);

  // Sweep: counts never increase, survivors only shrink, every output is a valid complex.
  std::set<Index> previous;
  for (const CriticalPoint& cp : input.CriticalPoints)
  {
    previous.insert(cp.Id);
  }
  std::array<Index, 3> last = summary.Input;
  std::map<Index, std::string> mismatchOf;
  const int step = fullSweep ? 1 : 5;
  for (int percent = 0; percent <= 100; percent += step)
  {
    const std::string label = name + " " + std::to_string(percent) + "%";
    SimplificationOutput result;
    if (!Check(simplification.Simplify(percent, result, error), label + " simplify", error))
    {
      continue;
    }
    const auto counts = result.Complex.CountByIndex();
    Check(counts[0] <= last[0] && counts[1] <= last[1] && counts[2] <= last[2], name + " counts never increase");
    last = counts;
    std::set<Index> kept;
    for (const CriticalPoint& cp : result.Complex.CriticalPoints)
    {
      kept.insert(cp.Id);
    }
    Check(std::includes(previous.begin(), previous.end(), kept.begin(), kept.end()),
      name + " survivors of a higher threshold survive every lower one");
    previous = kept;
    Shape shape;
    CheckComplex(label, field, extraction.Mesh, input, result, percent == 100, shape);
    summary.NonSimpleArcs = std::max(summary.NonSimpleArcs, shape.NonSimpleArcs);
    if (percent == 25)
    {
      summary.At25 = counts;
      summary.Junctions25 = static_cast<Index>(result.JunctionPoints.size());
    }

    // Extrema kept at threshold t vs. persistence pairs >= t. Comparable only away from the
    // domain boundary: stage 1's boundary rule makes every local minimum of f along the
    // boundary curve a critical point (the PL field has no such extremum), paired on its own
    // vertex with an interior saddle that it may never cancel against (boundary-interior).
    // So an interior basin that drains to the boundary is absorbed by a boundary minimum at
    // the depth of the boundary exit, not at its join-tree persistence; boundary PL maxima
    // sit on a boundary saddle with one ascending 1-cell and are never cancelled. The join
    // (split) tree pairs are therefore compared for the interior extrema whose sublevel
    // (superlevel) component never touched the boundary before the extremum died, and that
    // died at an interior vertex; the global extrema and the others are not compared.
    const double t = result.AbsoluteThreshold;
    for (const CriticalPoint& cp : input.CriticalPoints)
    {
      if (cp.MorseIndex == 1 || cp.OnBoundary)
      {
        continue;
      }
      const auto& trees = cp.MorseIndex == 0 ? joinTree : splitTree;
      const auto found = trees.find(cp.Vertex);
      if (!Check(found != trees.end(), name + " interior extremum of the complex is a PL extremum"))
      {
        continue;
      }
      if (found->second.SeesBoundary)
      {
        continue;
      }
      const bool expected = percent < 100 ? found->second.Persistence >= t : false;
      const bool survives = kept.count(cp.Id) > 0;
      ++summary.Compared;
      if (expected != survives)
      {
        ++summary.Mismatches;
        char text[160];
        std::snprintf(text, sizeof(text), "extremum id %d (index %d) at %d%%: persistence %.6g, threshold %.6g, %s",
          cp.Id, cp.MorseIndex, percent, found->second.Persistence, t, survives ? "kept" : "removed");
        mismatchOf.emplace(cp.Id, text);
      }
    }
  }
  for (const auto& entry : mismatchOf)
  {
    Check(false, name + " survivors match the merge-tree persistence", entry.second);
  }
  if (mismatchOf.empty())
  {
    Check(true, name + " survivors match the merge-tree persistence");
  }

  // 100%: the whole hierarchy; what is left cannot be cancelled any more.
  SimplificationOutput all;
  Check(simplification.Simplify(100, all, error), name + " simplify 100%", error);
  Check(all.Cancellations.size() == hierarchy.size(), name + " 100% performs the whole hierarchy");

  // Replaying is deterministic.
  SimplificationOutput again;
  simplification.Simplify(25, again, error);
  SimplificationOutput once;
  simplification.Simplify(25, once, error);
  Check(SameComplex(again.Complex, once.Complex), name + " replay is deterministic");
  return summary;
}

void CheckBadInput()
{
  std::string error;
  MorseSmaleComplexSimplification simplification;
  MorseSmaleComplex output;
  Check(!simplification.Simplify(10, output, error) && !error.empty(), "simplify before ComputeHierarchy fails");
  error.clear();
  Check(!simplification.ComputeHierarchy(MorseSmaleComplex(), error) && !error.empty(), "empty complex is refused");

  const PlanarScalarField field = FieldFromGrid(ShepardField(10, 2, 30, 7));
  MorseSmaleComplexExtraction extraction;
  MorseSmaleComplex input;
  extraction.Extract(field, input, error);
  MorseSmaleComplex broken = input;
  broken.Separatrices[0].Source = static_cast<Index>(broken.CriticalPoints.size());
  error.clear();
  Check(!simplification.ComputeHierarchy(broken, error) && !error.empty(), "1-cell with a bad endpoint is refused", error);
  broken = input;
  broken.Separatrices.pop_back();
  error.clear();
  Check(!simplification.ComputeHierarchy(broken, error) && !error.empty(), "saddle missing a 1-cell is refused", error);
  broken = input;
  broken.TwoCellId.pop_back();
  error.clear();
  Check(!simplification.ComputeHierarchy(broken, error) && !error.empty(), "short per-vertex arrays are refused", error);

  Check(simplification.ComputeHierarchy(input, error), "valid complex accepted", error);
  for (double percent : { -1.0, 100.5, std::numeric_limits<double>::quiet_NaN() })
  {
    error.clear();
    Check(!simplification.Simplify(percent, output, error) && !error.empty(),
      "threshold out of range is refused", std::to_string(percent));
  }
  Check(simplification.Simplify(100, output, error), "100% accepted", error);

  // Simplifying an already simplified complex (chained filters) works too.
  MorseSmaleComplex half;
  simplification.Simplify(30, half, error);
  MorseSmaleComplexSimplification chained;
  Check(chained.ComputeHierarchy(half, error), "a simplified complex is a valid input", error);
  MorseSmaleComplex same;
  Check(chained.Simplify(0, same, error) && SameComplex(same, half), "chained 0% returns its input");
}

void Benchmark()
{
  const auto start = std::chrono::steady_clock::now();
  const PlanarScalarField field = FieldFromGrid(ShepardField(50, 2, 1000, 1));
  const double generate = Milliseconds(start);
  MorseSmaleComplexExtraction extraction;
  MorseSmaleComplex input;
  std::string error;
  auto t0 = std::chrono::steady_clock::now();
  extraction.Extract(field, input, error);
  const double extract = Milliseconds(t0);
  MorseSmaleComplexSimplification simplification;
  t0 = std::chrono::steady_clock::now();
  Check(simplification.ComputeHierarchy(input, error), "benchmark hierarchy", error);
  const double hierarchy = Milliseconds(t0);
  double simplify[3];
  const double percents[3] = { 2, 25, 100 };
  SimplificationOutput result;
  for (int k = 0; k < 3; ++k)
  {
    t0 = std::chrono::steady_clock::now();
    Check(simplification.Simplify(percents[k], result, error), "benchmark simplify", error);
    simplify[k] = Milliseconds(t0);
  }
  const auto counts = input.CountByIndex();
  std::printf("benchmark Shepard 50 sites 1000x1000 seed 1: field %.0f ms, extraction %.0f ms, %d critical points;\n"
              "  ComputeHierarchy %.2f ms (%zu cancellations); Simplify 2%% %.2f ms, 25%% %.2f ms, 100%% %.2f ms\n",
    generate, extract, counts[0] + counts[1] + counts[2], hierarchy, simplification.Hierarchy().size(), simplify[0],
    simplify[1], simplify[2]);
}
} // namespace

int main(int argc, char** argv)
{
  const bool benchmark = argc > 1 && std::strcmp(argv[1], "--benchmark") == 0;
  struct Case
  {
    std::string Name;
    GridField Grid;
    bool FullSweep;
  };
  std::vector<Case> cases;
  cases.push_back({ "trig a=10 100x100", TrigonometricField(10, 100, -49), true });
  for (int seed = 1; seed <= 5; ++seed)
  {
    cases.push_back({ "shepard seed " + std::to_string(seed) + " 250x250", ShepardField(50, 2, 250, seed), true });
  }
  cases.push_back({ "shepard seed 1 60x60", ShepardField(50, 2, 60, 1), true });
  cases.push_back({ "shepard seed 3 120x120", ShepardField(50, 2, 120, 3), true });
  cases.push_back({ "shepard 200 sites power 3 seed 9 150x150", ShepardField(200, 3, 150, 9), true });
  for (const Case& c : cases)
  {
    const SweepSummary s = RunField(c.Name, c.Grid, c.FullSweep);
    std::printf("%s: input %d/%d/%d (min/saddle/max), at 25%%: %d/%d/%d, %d junction points; "
                "merge-tree comparisons %d, mismatches %d; persistence inversions %d, elder-rule violations %d, "
                "non-simple 1-cells %d\n",
      c.Name.c_str(), s.Input[0], s.Input[1], s.Input[2], s.At25[0], s.At25[1], s.At25[2], s.Junctions25, s.Compared,
      s.Mismatches, s.Inversions, s.ElderViolations, s.NonSimpleArcs);
  }
  CheckBadInput();
  if (benchmark)
  {
    Benchmark();
  }
  std::printf("%d passed, %d failed\n", Passed, Failed);
  return Failed == 0 ? 0 : 1;
}
