#include "JunctionPointDetection.h"

#include <algorithm>
#include <limits>

namespace topospline
{
namespace
{
// A 1-cell read from its extremum outwards: descending 1-cells are stored that way, ascending
// ones from the saddle, with the saddle's vertex as an extra first point and the maximum's
// vertex as an extra last point (around the triangle centroids).
struct PathFromExtremum
{
  const OneCell& Cell;

  bool Descending() const { return this->Cell.Type == OneCell::Descending; }
  size_t Size() const { return this->Cell.MeshCells.size(); }
  Index Extremum() const { return this->Descending() ? this->Cell.Source : this->Cell.Destination; }
  Index MeshCell(size_t i) const
  {
    return this->Cell.MeshCells[this->Descending() ? i : this->Size() - 1 - i];
  }
  // Index of the step's point and value in the 1-cell's Points and Values.
  size_t PointIndex(size_t i) const { return this->Descending() ? i : this->Size() - i; }
};

// Where a 1-cell goes after step i: its next mesh cell; beyond the last one, nowhere for a
// descending 1-cell (it ends at its saddle's vertex) and, for an ascending one, on to its
// saddle's vertex (encoded below zero, apart from the triangle ids).
constexpr Index Unseen = std::numeric_limits<Index>::min();
constexpr Index EndsHere = -1;
Index Following(const MorseSmaleComplex& complex, const PathFromExtremum& path, size_t i)
{
  if (i + 1 < path.Size())
  {
    return path.MeshCell(i + 1);
  }
  return path.Descending() ? EndsHere : -2 - complex.CriticalPoints[path.Cell.Source].Vertex;
}

// The 1-cells of one extremum form a tree rooted at it (V-paths are deterministic, so they
// merge and never split when followed towards the extremum). Per mesh cell: the extremum
// whose tree holds it. A descending 1-cell's last step is the saddle edge, not a gradient
// step, so its last vertex (its saddle's) is in a tree only when some other 1-cell passes
// through it: then it may lie in the tree of another extremum, whose 1-cells it does not
// concern.
std::vector<Index> TreeOfCell(const MorseSmaleComplex& complex, OneCell::Kind kind)
{
  Index bound = 0;
  for (const OneCell& oneCell : complex.OneCells)
  {
    if (oneCell.Type == kind)
    {
      for (Index c : oneCell.MeshCells)
      {
        bound = std::max(bound, c + 1);
      }
    }
  }
  std::vector<Index> tree(bound, InvalidIndex);
  for (const OneCell& oneCell : complex.OneCells)
  {
    const PathFromExtremum path{ oneCell };
    if (oneCell.Type != kind)
    {
      continue;
    }
    const size_t inTree = path.Descending() ? path.Size() - 1 : path.Size();
    for (size_t i = 0; i < inTree; ++i)
    {
      Index& owner = tree[path.MeshCell(i)];
      if (owner == InvalidIndex)
      {
        owner = path.Extremum();
      }
    }
  }
  return tree;
}

// Calls visit(a, path, i) for every step i >= 1 of every 1-cell a of `kind`, followed from
// its extremum, that lies in the extremum's tree (TreeOfCell). A triangle entered twice in a
// row is one step: a merged ascending 1-cell passes a cancelled saddle's edge midpoint as a
// second entry of the triangle (MorseSmaleComplexSimplification::BuildMergedOneCells), met
// first from the extremum; the triangle's own point is the second.
template <typename Visit>
void ForEachStepInTree(
  const MorseSmaleComplex& complex, OneCell::Kind kind, const std::vector<Index>& tree, Visit&& visit)
{
  for (Index a = 0; a < static_cast<Index>(complex.OneCells.size()); ++a)
  {
    const PathFromExtremum path{ complex.OneCells[a] };
    if (path.Cell.Type != kind)
    {
      continue;
    }
    for (size_t i = 1; i < path.Size(); ++i)
    {
      const bool repeated = i + 1 < path.Size() && path.MeshCell(i + 1) == path.MeshCell(i);
      if (!repeated && tree[path.MeshCell(i)] == path.Extremum())
      {
        visit(a, path, i);
      }
    }
  }
}

// Junction points of the 1-cells of one kind. A cell is a junction when the 1-cells of its
// tree through it do not all continue the same way (to the same next cell, or all ending
// there). A descending 1-cell that ends in its own tree, where others go on, makes the
// junction also the place of its saddle.
void DetectJunctionPointsOfKind(
  const MorseSmaleComplex& complex, OneCell::Kind kind, std::vector<JunctionPoint>& junctions)
{
  const std::vector<Index> tree = TreeOfCell(complex, kind);
  std::vector<Index> next(tree.size(), Unseen);
  std::vector<unsigned char> split(tree.size(), 0);
  ForEachStepInTree(complex, kind, tree, [&](Index, const PathFromExtremum& path, size_t i) {
    const Index u = path.MeshCell(i);
    const Index following = Following(complex, path, i);
    if (next[u] == Unseen)
    {
      next[u] = following;
    }
    else if (next[u] != following)
    {
      split[u] = 1;
    }
  });

  std::vector<Index> junctionOfCell(tree.size(), InvalidIndex);
  ForEachStepInTree(complex, kind, tree, [&](Index a, const PathFromExtremum& path, size_t i) {
    const Index u = path.MeshCell(i);
    if (!split[u])
    {
      return;
    }
    if (junctionOfCell[u] == InvalidIndex)
    {
      junctionOfCell[u] = static_cast<Index>(junctions.size());
      JunctionPoint junction;
      junction.Type = kind;
      junction.Extremum = path.Extremum();
      junction.Cell = u;
      const size_t p = path.PointIndex(i);
      junction.Position[0] = path.Cell.Points[2 * p];
      junction.Position[1] = path.Cell.Points[2 * p + 1];
      junction.Value = path.Cell.Values[p];
      junctions.push_back(junction);
    }
    JunctionPoint& junction = junctions[junctionOfCell[u]];
    junction.OneCells.push_back(a);
    if (path.Descending() && i + 1 == path.Size())
    {
      junction.CriticalPoint = path.Cell.Destination;
    }
  });
}
} // namespace

//------------------------------------------------------------------------------
std::vector<JunctionPoint> DetectJunctionPoints(const MorseSmaleComplex& complex)
{
  std::vector<JunctionPoint> junctions;
  DetectJunctionPointsOfKind(complex, OneCell::Descending, junctions);
  DetectJunctionPointsOfKind(complex, OneCell::Ascending, junctions);
  return junctions;
}
} // namespace topospline
