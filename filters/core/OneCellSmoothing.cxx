#include "OneCellSmoothing.h"

#include "CompressedGraph.h"
#include "JunctionValueProgram.h"
#include "PlanarGeometry.h"
#include "TriangleMeshTopology.h"
#include "TwoCellReconstruction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <queue>
#include <set>
#include <unordered_map>

namespace topospline
{
namespace
{
// Nodes for every critical point, with the critical value as both field value and value.
void AddCriticalNodes(const std::vector<CriticalPoint>& cps, std::vector<SmoothingNode>& nodes)
{
  for (Index c = 0; c < static_cast<Index>(cps.size()); ++c)
  {
    SmoothingNode node;
    node.Type = SmoothingNode::Critical;
    node.Source = c;
    node.FieldValue = node.Value = cps[c].Value;
    nodes.push_back(node);
  }
}

// Ties between critical values (plateaus, broken by vertex id in stage 1) would make a
// strictly increasing height impossible: separate tied values by at most 1e-9 of the range,
// in the order of simulation of simplicity (value, then vertex, then index).
void SeparateTiedCriticalValues(const std::vector<CriticalPoint>& cps, std::vector<SmoothingNode>& nodes)
{
  double low = cps.empty() ? 0 : cps[0].Value, high = low;
  for (const auto& cp : cps)
  {
    low = std::min(low, cp.Value);
    high = std::max(high, cp.Value);
  }
  std::vector<Index> order(cps.size());
  for (Index i = 0; i < static_cast<Index>(order.size()); ++i)
  {
    order[i] = i;
  }
  // A vertex can hold several critical cells (a boundary corner: a saddle edge and a
  // maximum triangle); the higher-dimensional cell is the higher one.
  std::sort(order.begin(), order.end(), [&](Index x, Index y) {
    if (cps[x].Value != cps[y].Value)
    {
      return cps[x].Value < cps[y].Value;
    }
    return cps[x].Vertex != cps[y].Vertex ? cps[x].Vertex < cps[y].Vertex : cps[x].MorseIndex < cps[y].MorseIndex;
  });
  const double step = 1e-9 * std::max(high - low, 1e-300) / std::max<size_t>(cps.size(), 1);
  for (size_t i = 1; i < order.size(); ++i)
  {
    SmoothingNode& node = nodes[order[i]];
    node.Value = std::max(node.Value, nodes[order[i - 1]].Value + step);
  }
}

// Nodes for the junction points that are not on a critical point; returns the node of every
// junction point (a saddle on it: the critical node).
std::vector<Index> AddJunctionNodes(const std::vector<JunctionPoint>& junctions, std::vector<SmoothingNode>& nodes)
{
  std::vector<Index> junctionNode(junctions.size());
  for (size_t j = 0; j < junctions.size(); ++j)
  {
    if (junctions[j].CriticalPoint != InvalidIndex)
    {
      junctionNode[j] = junctions[j].CriticalPoint;
      continue;
    }
    SmoothingNode node;
    node.Type = SmoothingNode::Junction;
    node.Source = static_cast<Index>(j);
    node.Position[0] = junctions[j].Position[0];
    node.Position[1] = junctions[j].Position[1];
    node.FieldValue = node.Value = junctions[j].Value;
    junctionNode[j] = static_cast<Index>(nodes.size());
    nodes.push_back(node);
  }
  return junctionNode;
}

// Where along a 1-cell its mesh cell `cell` sits, as an index into its Points; -1 if absent.
long PointIndexOfCell(const OneCell& oneCell, Index cell)
{
  const auto it = std::find(oneCell.MeshCells.begin(), oneCell.MeshCells.end(), cell);
  if (it == oneCell.MeshCells.end())
  {
    return -1;
  }
  // Ascending 1-cells carry the saddle's vertex before their first triangle.
  return static_cast<long>(it - oneCell.MeshCells.begin()) + (oneCell.Type == OneCell::Ascending ? 1 : 0);
}

// Where a 1-cell is cut: (position in its Points, node there).
using Cut = std::pair<long, Index>;

// Keeps, of the cuts of one 1-cell (source first, destination last), the longest chain whose
// nodes rise strictly in `rank` from the source to the destination.
void KeepRisingCuts(std::vector<Cut>& at, const std::vector<Index>& rank)
{
  const size_t m = at.size();
  std::vector<int> length(m, 0);
  std::vector<size_t> previous(m, 0);
  length[0] = 1;
  for (size_t i = 1; i < m; ++i)
  {
    for (size_t j = 0; j < i; ++j)
    {
      if (length[j] > 0 && length[j] + 1 > length[i] && rank[at[j].second] < rank[at[i].second])
      {
        length[i] = length[j] + 1;
        previous[i] = j;
      }
    }
  }
  if (m < 2 || length[m - 1] == 0)
  {
    return; // the ends themselves are out of order: left to the program's error
  }
  std::vector<Cut> kept;
  for (size_t i = m - 1;; i = previous[i])
  {
    kept.push_back(at[i]);
    if (i == 0)
    {
      break;
    }
  }
  std::reverse(kept.begin(), kept.end());
  at = std::move(kept);
}

// The strongly connected components of a directed graph (Tarjan, without recursion: noise
// gives chains of hundreds of thousands of nodes); component ids per node.
std::vector<Index> StronglyConnectedComponents(const CompressedGraph& next)
{
  const Index count = next.Nodes();
  std::vector<Index> order(count, InvalidIndex), low(count, 0), component(count, InvalidIndex);
  std::vector<Index> stack;
  std::vector<std::pair<Index, size_t>> calls; // node, next edge to follow
  Index visited = 0, components = 0;
  for (Index root = 0; root < count; ++root)
  {
    if (order[root] != InvalidIndex)
    {
      continue;
    }
    calls.push_back({ root, 0 });
    order[root] = low[root] = visited++;
    stack.push_back(root);
    while (!calls.empty())
    {
      auto& [n, edge] = calls.back();
      if (edge < next.Degree(n))
      {
        const Index m = next.Successor(n, edge++);
        if (order[m] == InvalidIndex)
        {
          order[m] = low[m] = visited++;
          stack.push_back(m);
          calls.push_back({ m, 0 });
        }
        else if (component[m] == InvalidIndex)
        {
          low[n] = std::min(low[n], order[m]);
        }
        continue;
      }
      const Index done = n;
      calls.pop_back();
      if (!calls.empty())
      {
        low[calls.back().first] = std::min(low[calls.back().first], low[done]);
      }
      if (low[done] == order[done])
      {
        Index m;
        do
        {
          m = stack.back();
          stack.pop_back();
          component[m] = components;
        } while (m != done);
        ++components;
      }
    }
  }
  return component;
}

// One order of all nodes for the cuts to follow: a topological order of the relations that
// consecutive cuts of every 1-cell make (lower first) and of the critical values (fixed, so
// they keep their order), lowest (value, index) first among the nodes that are free to come.
// Where the relations hold a cycle (a 1-cell merged by cancellations runs up and down and
// passes another 1-cell's nodes on its way down), the lowest node of a cycle whose other
// predecessors have all come comes next regardless: only relations inside strongly connected
// components are broken, so only 1-cells on a cycle lose cuts (KeepRisingCuts). A fallback
// for the whole complex (cuts only where the field values rise) left many 1-cells uncut at
// junctions they share with others, and their pieces overlapped along the shared stretch
// (100^2 noise at 25 %: 910 pairs of pieces crossed to the end, now 1).
std::vector<Index> RankNodes(const std::vector<SmoothingNode>& nodes, const std::vector<std::vector<Cut>>& cuts)
{
  const Index count = static_cast<Index>(nodes.size());
  auto lower = [&nodes](Index x, Index y) {
    return nodes[x].Value != nodes[y].Value ? nodes[x].Value < nodes[y].Value : x < y;
  };
  std::vector<std::array<Index, 2>> edges;
  std::vector<Index> critical;
  for (Index n = 0; n < count; ++n)
  {
    if (nodes[n].Type == SmoothingNode::Critical)
    {
      critical.push_back(n);
    }
  }
  std::sort(critical.begin(), critical.end(), lower);
  for (size_t i = 1; i < critical.size(); ++i)
  {
    edges.push_back({ critical[i - 1], critical[i] });
  }
  for (const std::vector<Cut>& at : cuts)
  {
    for (size_t k = 1; k < at.size(); ++k)
    {
      edges.push_back({ at[k - 1].second, at[k].second });
    }
  }
  const CompressedGraph higher(count, edges);
  edges = std::vector<std::array<Index, 2>>();
  const std::vector<Index> component = StronglyConnectedComponents(higher);
  // Predecessors not yet ranked, from other components and from the node's own.
  std::vector<Index> outer(count, 0), inner(count, 0);
  for (Index n = 0; n < count; ++n)
  {
    for (std::size_t k = 0; k < higher.Degree(n); ++k)
    {
      const Index h = higher.Successor(n, k);
      ++(component[h] == component[n] ? inner[h] : outer[h]);
    }
  }
  // ready: all predecessors ranked; onCycle: only predecessors in its own component left. Both
  // are heaps, lowest node on top; a node that moves from onCycle to ready leaves a stale entry
  // behind, which `in` tells apart (a std::set with erase took 1.7 s on 1000^2 noise).
  enum : unsigned char { Waiting, Ready, OnCycle, Ranked };
  std::vector<unsigned char> in(count, Waiting);
  const auto higherFirst = [&lower](Index x, Index y) { return lower(y, x); };
  std::priority_queue<Index, std::vector<Index>, decltype(higherFirst)> ready(higherFirst), onCycle(higherFirst);
  const auto place = [&](Index n) {
    const unsigned char where = inner[n] == 0 ? Ready : OnCycle;
    if (in[n] != where)
    {
      in[n] = where;
      (where == Ready ? ready : onCycle).push(n);
    }
  };
  for (Index n = 0; n < count; ++n)
  {
    if (outer[n] == 0)
    {
      place(n);
    }
  }
  std::vector<Index> rank(count, InvalidIndex);
  for (Index next = 0; next < count; ++next)
  {
    while (!ready.empty() && in[ready.top()] != Ready)
    {
      ready.pop();
    }
    while (!onCycle.empty() && in[onCycle.top()] != OnCycle)
    {
      onCycle.pop();
    }
    auto& from = ready.empty() ? onCycle : ready;
    if (from.empty())
    {
      break; // every node is placed once its predecessors are ranked (cannot happen)
    }
    const Index n = from.top();
    from.pop();
    in[n] = Ranked;
    rank[n] = next;
    for (std::size_t k = 0; k < higher.Degree(n); ++k)
    {
      const Index h = higher.Successor(n, k);
      if (rank[h] != InvalidIndex)
      {
        continue;
      }
      --(component[h] == component[n] ? inner[h] : outer[h]);
      if (outer[h] == 0)
      {
        place(h);
      }
    }
  }
  return rank;
}

// Whether the 1-cell passes one point twice (most do not: found without the maps of
// EraseRetracedLoops).
bool RepeatsAPoint(const OneCell& oneCell)
{
  std::vector<std::pair<double, double>> sorted(oneCell.Values.size());
  for (std::size_t i = 0; i < sorted.size(); ++i)
  {
    sorted[i] = { oneCell.Points[2 * i], oneCell.Points[2 * i + 1] };
  }
  std::sort(sorted.begin(), sorted.end());
  return std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
}

// A 1-cell merged by cancellations runs out to a cancelled extremum and back along the path it
// came (V-paths into one extremum merge and never split again, so the way back retraces the
// way out), and it may pass its own end's vertex before it ends there. Such a retraced loop
// bounds nothing: it is erased (the path goes on from the loop's first visit of the repeated
// point), so that the piece does not carry a spike out and back, and stage 4 does not get a
// side that runs out and back along another 1-cell (a slit outside the cell, or a stretch of
// boundary walked three times). Only loops that retrace every edge as often one way as the
// other are erased, and never a 1-cell that is a loop as a whole (a saddle and a maximum on
// one boundary vertex). Returns the number of loops erased.
int EraseRetracedLoops(OneCell& oneCell)
{
  const std::size_t n = oneCell.Values.size();
  const std::vector<double>& p = oneCell.Points;
  std::vector<std::size_t> kept;
  std::map<std::pair<double, double>, std::size_t> keptAt; // point -> position in kept
  int erased = 0;
  auto retraced = [&p](const std::vector<std::size_t>& path, std::size_t from, std::size_t closing) {
    // Every undirected edge of the loop as often one way as the other.
    std::map<std::array<double, 4>, int> balance;
    for (std::size_t k = from; k < path.size(); ++k)
    {
      const std::size_t a = path[k], b = k + 1 < path.size() ? path[k + 1] : closing;
      std::array<double, 4> forward{ p[2 * a], p[2 * a + 1], p[2 * b], p[2 * b + 1] };
      std::array<double, 4> backward{ p[2 * b], p[2 * b + 1], p[2 * a], p[2 * a + 1] };
      if (forward < backward)
      {
        ++balance[forward];
      }
      else
      {
        --balance[backward];
      }
    }
    return std::all_of(balance.begin(), balance.end(), [](const auto& entry) { return entry.second == 0; });
  };
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::pair<double, double> point{ p[2 * i], p[2 * i + 1] };
    const auto seen = keptAt.find(point);
    if (seen != keptAt.end() && !(seen->second == 0 && i + 1 == n) && retraced(kept, seen->second, i))
    {
      for (std::size_t k = seen->second + 1; k < kept.size(); ++k)
      {
        keptAt.erase({ p[2 * kept[k]], p[2 * kept[k] + 1] });
      }
      kept.resize(seen->second + 1);
      ++erased;
      continue;
    }
    keptAt[point] = kept.size();
    kept.push_back(i);
  }
  if (erased == 0)
  {
    return 0;
  }
  // Ascending 1-cells carry the saddle's and the maximum's vertex around their triangles.
  const std::size_t offset = oneCell.Type == OneCell::Ascending ? 1 : 0;
  OneCell trimmed;
  trimmed.Type = oneCell.Type;
  trimmed.Source = oneCell.Source;
  trimmed.Destination = oneCell.Destination;
  for (std::size_t i : kept)
  {
    trimmed.Points.insert(trimmed.Points.end(), { p[2 * i], p[2 * i + 1] });
    trimmed.Values.push_back(oneCell.Values[i]);
    if (i >= offset && i - offset < oneCell.MeshCells.size())
    {
      trimmed.MeshCells.push_back(oneCell.MeshCells[i - offset]);
    }
  }
  oneCell = std::move(trimmed);
  return erased;
}

// The cuts of every 1-cell at the junction points it passes (not at its ends).
std::vector<std::vector<Cut>> CutsAtJunctions(const std::vector<const OneCell*>& oneCells,
  const std::vector<JunctionPoint>& junctions, const std::vector<Index>& junctionNode)
{
  std::vector<std::vector<Cut>> cuts(oneCells.size());
  for (size_t j = 0; j < junctions.size(); ++j)
  {
    for (Index a : junctions[j].OneCells)
    {
      const long at = PointIndexOfCell(*oneCells[a], junctions[j].Cell);
      if (at > 0 && at + 1 < static_cast<long>(oneCells[a]->Values.size()))
      {
        cuts[a].push_back({ at, junctionNode[j] });
      }
    }
  }
  return cuts;
}

// The corners of the domain as nodes, made when a 1-cell first passes one, so that the
// boundary keeps its corners: the corners of the bounds, or, given the boundary's points, the
// point nearest each of them (OneCellSmoothing::BoundaryPoints).
class DomainCornerNodes
{
public:
  DomainCornerNodes(const double domainBounds[4], const std::vector<double>& boundaryPoints)
    : Corners{ { domainBounds[0], domainBounds[2] }, { domainBounds[1], domainBounds[2] },
      { domainBounds[1], domainBounds[3] }, { domainBounds[0], domainBounds[3] } }
  {
    if (boundaryPoints.size() < 2)
    {
      return;
    }
    for (auto& corner : this->Corners)
    {
      std::size_t nearest = 0;
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i + 1 < boundaryPoints.size(); i += 2)
      {
        const double d = std::hypot(boundaryPoints[i] - corner[0], boundaryPoints[i + 1] - corner[1]);
        if (d < best)
        {
          best = d;
          nearest = i;
        }
      }
      corner[0] = boundaryPoints[nearest];
      corner[1] = boundaryPoints[nearest + 1];
    }
  }

  // Cuts `oneCell` at the corners it passes (not at its ends).
  void AddCuts(const OneCell& oneCell, std::vector<SmoothingNode>& nodes, std::vector<Cut>& at)
  {
    const auto& corners = this->Corners;
    const long n = static_cast<long>(oneCell.Values.size());
    for (long p = 1; p + 1 < n; ++p)
    {
      for (int c = 0; c < 4; ++c)
      {
        if (oneCell.Points[2 * p] == corners[c][0] && oneCell.Points[2 * p + 1] == corners[c][1])
        {
          auto found = this->NodeOfCorner.find({ corners[c][0], corners[c][1] });
          if (found == this->NodeOfCorner.end())
          {
            SmoothingNode node;
            node.Type = SmoothingNode::DomainCorner;
            node.Position[0] = corners[c][0];
            node.Position[1] = corners[c][1];
            node.FieldValue = node.Value = oneCell.Values[p];
            found =
              this->NodeOfCorner.insert({ { corners[c][0], corners[c][1] }, static_cast<Index>(nodes.size()) }).first;
            nodes.push_back(node);
          }
          at.push_back({ p, found->second });
        }
      }
    }
  }

private:
  double Corners[4][2];
  std::map<std::pair<double, double>, Index> NodeOfCorner;
};

// Adds the 1-cell's ends to its cuts and orders them along it, one cut per position.
void AddEndsAndOrderCuts(const OneCell& oneCell, std::vector<Cut>& at)
{
  const long n = static_cast<long>(oneCell.Values.size());
  // A merged 1-cell may pass its own end's vertex before it ends there (the trivial
  // embedding): no cut at its own ends' nodes.
  at.erase(std::remove_if(at.begin(), at.end(),
             [&](const auto& cut) { return cut.second == oneCell.Source || cut.second == oneCell.Destination; }),
    at.end());
  at.push_back({ 0, oneCell.Source });
  at.push_back({ n - 1, oneCell.Destination });
  std::sort(at.begin(), at.end());
  at.erase(std::unique(at.begin(), at.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
    at.end());
  // A node passed twice, in a row (which would make a piece from a node to itself) or after
  // an excursion: a merged 1-cell can run out to a cancelled extremum and back along the
  // same path, passing its nodes a second time in the opposite order, and pieces cut at both
  // visits would order those nodes both ways (a cycle no values can satisfy). The excursion
  // stays inside one piece, from the first visit to the node after the last one.
  for (size_t k = 0; k < at.size(); ++k)
  {
    size_t last = k;
    for (size_t m = k + 1; m < at.size(); ++m)
    {
      last = at[m].second == at[k].second ? m : last;
    }
    at.erase(at.begin() + k + 1, at.begin() + last + 1);
  }
}

// The pieces of 1-cell `a` between consecutive cuts; a piece already made by another 1-cell
// on the same points (merged 1-cells) is shared.
// An ascending piece whose last segment was made straight from the point before the maximum's
// triangle to the maximum (AddPiecesOfOneCell): the centroid of that triangle it left out.
struct Shortcut
{
  Index Piece = InvalidIndex;
  double Centroid[2] = { 0, 0 };
  double Value = 0;
};

// The pieces made so far, found by the stretch of 1-cell they were cut from: the same points
// (compared exactly, -0 equal to 0) and type make the same piece. Hashed, with each piece's
// stretch kept as a view of its 1-cell: on 1000^2 noise an ordered map keyed by copies of the
// points took 4.3 s for 1.35 million pieces.
class PiecesByGeometry
{
public:
  // The piece cut from oneCell's points from .. to, or InvalidIndex.
  Index Find(const OneCell& oneCell, long from, long to, std::uint64_t& hash) const
  {
    hash = Hash(oneCell, from, to);
    const auto range = this->Pieces.equal_range(hash);
    for (auto it = range.first; it != range.second; ++it)
    {
      if (Same(*it->second.Cell, it->second.From, it->second.To, oneCell, from, to))
      {
        return it->second.Piece;
      }
    }
    return InvalidIndex;
  }
  void Add(std::uint64_t hash, const OneCell& oneCell, long from, long to, Index piece)
  {
    this->Pieces.insert({ hash, { &oneCell, from, to, piece } });
  }

private:
  struct Stretch
  {
    const OneCell* Cell;
    long From, To;
    Index Piece;
  };
  static std::uint64_t Mix(std::uint64_t h, std::uint64_t x)
  {
    h ^= x + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    h ^= h >> 31;
    return h * 0xbf58476d1ce4e5b9ULL;
  }
  static std::uint64_t Hash(const OneCell& oneCell, long from, long to)
  {
    std::uint64_t h = static_cast<std::uint64_t>(oneCell.Type) + 1;
    for (long i = 2 * from; i < 2 * (to + 1); ++i)
    {
      const double x = oneCell.Points[i] + 0.0; // -0 + 0 is +0: equal values, equal bits
      std::uint64_t bits;
      std::memcpy(&bits, &x, sizeof bits);
      h = Mix(h, bits);
    }
    return h;
  }
  static bool Same(const OneCell& a, long aFrom, long aTo, const OneCell& b, long bFrom, long bTo)
  {
    return a.Type == b.Type && aTo - aFrom == bTo - bFrom &&
      std::equal(a.Points.begin() + 2 * aFrom, a.Points.begin() + 2 * (aTo + 1), b.Points.begin() + 2 * bFrom);
  }
  std::unordered_multimap<std::uint64_t, Stretch> Pieces;
};

void AddPiecesOfOneCell(Index a, const OneCell& oneCell, const std::vector<Cut>& at,
  PiecesByGeometry& pieceOfGeometry, OneCellSmoothingResult& result, std::vector<Shortcut>& shortcuts)
{
  const long n = static_cast<long>(oneCell.Values.size());
  for (size_t k = 0; k + 1 < at.size(); ++k)
  {
    const long from = at[k].first, to = at[k + 1].first;
    std::uint64_t hash = 0;
    Index found = pieceOfGeometry.Find(oneCell, from, to, hash);
    if (found == InvalidIndex)
    {
      SmoothedPiece piece;
      piece.Type = oneCell.Type;
      piece.StartNode = at[k].second;
      piece.EndNode = at[k + 1].second;
      piece.Points.assign(oneCell.Points.begin() + 2 * from, oneCell.Points.begin() + 2 * (to + 1));
      piece.Values.assign(oneCell.Values.begin() + from, oneCell.Values.begin() + to + 1);
      // Every ascending 1-cell into a maximum ends "centroid of the maximum's triangle,
      // maximum's vertex": a segment they would all share. Go straight to the vertex, except
      // from the saddle's own vertex when it is another vertex of that triangle: that straight
      // line would run along an edge of the triangle, which another 1-cell may cross into it
      // (at its midpoint, on a triangle mesh). (A saddle on the maximum's own vertex makes a
      // piece of no length, which touches nothing.)
      const std::vector<double>& q = piece.Points;
      const bool fromSaddleVertex = from == 0 && piece.Values.size() == 3 &&
        !(q[0] == q[q.size() - 2] && q[1] == q[q.size() - 1]);
      if (oneCell.Type == OneCell::Ascending && to == n - 1 && piece.Values.size() > 2 && !fromSaddleVertex)
      {
        const std::size_t c = piece.Values.size() - 2;
        shortcuts.push_back({ static_cast<Index>(result.Pieces.size()), { q[2 * c], q[2 * c + 1] }, piece.Values[c] });
        piece.Points.erase(piece.Points.end() - 4, piece.Points.end() - 2);
        piece.Values.erase(piece.Values.end() - 2);
      }
      found = static_cast<Index>(result.Pieces.size());
      pieceOfGeometry.Add(hash, oneCell, from, to, found);
      result.Pieces.push_back(std::move(piece));
    }
    result.Pieces[found].OneCells.push_back(a);
    result.PiecesOfOneCell[a].push_back(found);
  }
}

// The straight last segment of a shortcut (AddPiecesOfOneCell) leaves the two triangles it
// joins where they form a non-convex quad, and can then cross another 1-cell: on a Delaunay
// mesh at 2 % (stress case #275) six pairs of pieces crossed so, and still crossed as the
// jagged polylines stage 3 falls back to. The segments before it (point P, centroid C) and
// from C to the maximum M stay in their triangles and cross nothing, so a 1-cell that crosses
// P-M has a point inside the triangle P C M (it cannot leave through P-C or C-M); so does one
// whose own shortcut crosses P-M, once the centroids left out count as points. Where some
// point lies there, the piece goes through Q = C + t (P - C) instead, for the largest t of
// 1/2, 1/4, ..., 1/16 whose triangle Q C M holds none (Q-M then crosses nothing, and the
// pieces into one maximum still share no segment), or through C itself. Checked on all
// pieces' points and the centroids at once, through a grid.
void KeepShortcutsClear(const std::vector<Shortcut>& shortcuts, OneCellSmoothingResult& result)
{
  if (shortcuts.empty())
  {
    return;
  }
  // Every piece's point and every centroid left out, in a grid of cells about as large as the
  // mean step between points.
  const auto forEachPoint = [&](const auto& visit) {
    for (const SmoothedPiece& piece : result.Pieces)
    {
      for (std::size_t i = 0; 2 * i + 1 < piece.Points.size(); ++i)
      {
        visit(piece.Points[2 * i], piece.Points[2 * i + 1]);
      }
    }
    for (const Shortcut& shortcut : shortcuts)
    {
      visit(shortcut.Centroid[0], shortcut.Centroid[1]);
    }
  };
  double steps = 0;
  std::size_t count = 0, total = 0;
  for (const SmoothedPiece& piece : result.Pieces)
  {
    const std::vector<double>& q = piece.Points;
    for (std::size_t i = 2; i + 1 < q.size(); i += 2, ++count)
    {
      steps += std::hypot(q[i] - q[i - 2], q[i + 1] - q[i - 1]);
    }
  }
  double low[2] = { std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity() };
  double high[2] = { -low[0], -low[1] };
  forEachPoint([&](double x, double y) {
    low[0] = std::min(low[0], x);
    high[0] = std::max(high[0], x);
    low[1] = std::min(low[1], y);
    high[1] = std::max(high[1], y);
    ++total;
  });
  double size = count > 0 && steps > 0 ? steps / static_cast<double>(count) : 1.0;
  const auto cellsAlong = [&](int d) {
    return static_cast<Index>(std::min(4096.0, std::floor((high[d] - low[d]) / size) + 1));
  };
  // No more cells than points (1-cells cover a fraction of the domain only).
  while (static_cast<double>(cellsAlong(0)) * static_cast<double>(cellsAlong(1)) > static_cast<double>(total + 1))
  {
    size *= 2;
  }
  const Index nx = cellsAlong(0), ny = cellsAlong(1);
  const auto column = [&](double x) { return std::clamp(static_cast<Index>((x - low[0]) / size), Index(0), nx - 1); };
  const auto row = [&](double y) { return std::clamp(static_cast<Index>((y - low[1]) / size), Index(0), ny - 1); };
  std::vector<Index> start(static_cast<std::size_t>(nx * ny) + 1, 0);
  forEachPoint([&](double x, double y) { ++start[row(y) * nx + column(x) + 1]; });
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::array<double, 2>> points(total);
  std::vector<Index> fill(start.begin(), start.end() - 1);
  forEachPoint([&](double x, double y) { points[fill[row(y) * nx + column(x)]++] = { x, y }; });
  // Whether a point other than the triangle's corners lies in the triangle (q, c, m) or on q-m.
  const auto holdsAPoint = [&](const double* q, const double* c, const double* m) {
    const double turn = Orientation2D(q, c, m);
    if (turn == 0)
    {
      return false;
    }
    const Index x0 = column(std::min({ q[0], c[0], m[0] })), x1 = column(std::max({ q[0], c[0], m[0] }));
    const Index y0 = row(std::min({ q[1], c[1], m[1] })), y1 = row(std::max({ q[1], c[1], m[1] }));
    for (Index j = y0; j <= y1; ++j)
    {
      for (Index i = x0; i <= x1; ++i)
      {
        for (Index k = start[j * nx + i]; k < start[j * nx + i + 1]; ++k)
        {
          const double* x = points[k].data();
          if ((x[0] == q[0] && x[1] == q[1]) || (x[0] == c[0] && x[1] == c[1]) || (x[0] == m[0] && x[1] == m[1]))
          {
            continue;
          }
          // Strictly inside, or on q-m (the side a crossing would pass).
          const double a = Orientation2D(q, c, x) * turn, b = Orientation2D(c, m, x) * turn,
                       e = Orientation2D(m, q, x) * turn;
          if (a > 0 && b > 0 && e >= 0)
          {
            return true;
          }
        }
      }
    }
    return false;
  };
  for (const Shortcut& shortcut : shortcuts)
  {
    SmoothedPiece& piece = result.Pieces[shortcut.Piece];
    const std::size_t n = piece.Values.size();
    const double* p = &piece.Points[2 * n - 4];
    const double* m = &piece.Points[2 * n - 2];
    const double* c = shortcut.Centroid;
    if (!holdsAPoint(p, c, m))
    {
      continue;
    }
    double t = 0.5;
    double q[2];
    for (; t >= 1.0 / 16; t /= 2)
    {
      q[0] = c[0] + t * (p[0] - c[0]);
      q[1] = c[1] + t * (p[1] - c[1]);
      if (!holdsAPoint(q, c, m))
      {
        break;
      }
    }
    if (t < 1.0 / 16)
    {
      t = 0;
      q[0] = c[0];
      q[1] = c[1];
    }
    const double value = shortcut.Value + t * (piece.Values[n - 2] - shortcut.Value);
    piece.Points.insert(piece.Points.end() - 2, { q[0], q[1] });
    piece.Values.insert(piece.Values.end() - 1, value);
  }
}

// Cuts every 1-cell at the nodes it passes (its junction points, and the domain corners it
// meets, which are added to `nodes`) into pieces; identical pieces (merged 1-cells) are kept
// once. A 1-cell keeps only the cuts that rise in one order of all nodes (RankNodes), which
// drops cuts on cycles only. Node positions become the ends of the pieces that meet there.
void CutIntoPieces(const std::vector<const OneCell*>& oneCells, const std::vector<JunctionPoint>& junctions,
  const std::vector<Index>& junctionNode, const double domainBounds[4], const std::vector<double>& boundaryPoints,
  std::vector<SmoothingNode>& nodes, OneCellSmoothingResult& result)
{
  std::vector<std::vector<Cut>> cuts = CutsAtJunctions(oneCells, junctions, junctionNode);
  DomainCornerNodes corners(domainBounds, boundaryPoints);
  for (Index a = 0; a < static_cast<Index>(oneCells.size()); ++a)
  {
    corners.AddCuts(*oneCells[a], nodes, cuts[a]);
    AddEndsAndOrderCuts(*oneCells[a], cuts[a]);
  }
  const std::vector<Index> rank = RankNodes(nodes, cuts);
  PiecesByGeometry pieceOfGeometry;
  std::vector<Shortcut> shortcuts;
  result.PiecesOfOneCell.resize(oneCells.size());
  // At most one piece per pair of consecutive cuts: reserved, since growing the pieces
  // (216 bytes each, 1.35 million on 1000^2 noise) moved them all at every doubling.
  std::size_t mostPieces = 0;
  for (Index a = 0; a < static_cast<Index>(oneCells.size()); ++a)
  {
    const size_t before = cuts[a].size();
    KeepRisingCuts(cuts[a], rank);
    result.DroppedCuts += static_cast<int>(before - cuts[a].size());
    mostPieces += cuts[a].empty() ? 0 : cuts[a].size() - 1;
    result.PiecesOfOneCell[a].reserve(cuts[a].empty() ? 0 : cuts[a].size() - 1);
  }
  result.Pieces.reserve(mostPieces);
  for (Index a = 0; a < static_cast<Index>(oneCells.size()); ++a)
  {
    AddPiecesOfOneCell(a, *oneCells[a], cuts[a], pieceOfGeometry, result, shortcuts);
  }
  KeepShortcutsClear(shortcuts, result);
  // Node positions: the ends of the pieces that meet there.
  for (const SmoothedPiece& piece : result.Pieces)
  {
    for (int end = 0; end < 2; ++end)
    {
      SmoothingNode& node = nodes[end == 0 ? piece.StartNode : piece.EndNode];
      const size_t p = end == 0 ? 0 : piece.Values.size() - 1;
      node.Position[0] = piece.Points[2 * p];
      node.Position[1] = piece.Points[2 * p + 1];
    }
  }
}

// Junction (and corner) values: one global program, strictly increasing along every piece.
// False with the program's error (program.FoundOrderConflict says whether the pieces order
// nodes against each other).
bool SolveJunctionValues(std::vector<SmoothingNode>& nodes, OneCellSmoothingResult& result,
  JunctionValueProgram& program, std::string& error)
{
  std::vector<JunctionValueNode> programNodes(nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i)
  {
    programNodes[i].Value = nodes[i].Type == SmoothingNode::Critical ? nodes[i].Value : nodes[i].FieldValue;
    programNodes[i].Fixed = nodes[i].Type == SmoothingNode::Critical;
  }
  std::vector<std::array<Index, 2>> lowerThan;
  for (const SmoothedPiece& piece : result.Pieces)
  {
    lowerThan.push_back({ piece.StartNode, piece.EndNode });
  }
  std::sort(lowerThan.begin(), lowerThan.end());
  lowerThan.erase(std::unique(lowerThan.begin(), lowerThan.end()), lowerThan.end());
  std::vector<double> values;
  if (!program.Solve(programNodes, lowerThan, values, error))
  {
    return false;
  }
  for (size_t i = 0; i < nodes.size(); ++i)
  {
    nodes[i].Value = values[i];
  }
  result.JunctionMargin = program.Margin;
  result.SpreadCriticalValues = program.SpreadCriticalValues;
  result.MaximumSpread = program.MaximumSpread;
  result.JunctionTotalChange = program.TotalChange;
  return true;
}

// A hundredth of a piece's mean sample spacing: how far inside the domain's box its curve is
// kept (ClampCurveIntoDomain).
double ClampingMargin(const std::vector<double>& points)
{
  const std::size_t samples = points.size() / 2;
  double length = 0;
  for (std::size_t i = 1; i < samples; ++i)
  {
    length += std::hypot(points[2 * i] - points[2 * i - 2], points[2 * i + 1] - points[2 * i - 1]);
  }
  return samples > 1 ? 0.01 * length / (samples - 1) : 0.0;
}

// A least-squares curve fitted to a 1-cell that runs along the boundary and then turns
// inwards can overshoot the boundary slightly. A Bezier curve lies in the convex hull of its
// control points: clamping them keeps it inside (the ends, data points, never move). Only a
// piece that lies entirely on one side of the domain's box may touch that side: a boundary
// stretch belongs to one piece at most (1-cells on the same vertices share their pieces),
// and any other curve touching it would make the 2-cells of stage 4 pinch. Other pieces are
// kept a hundredth of their sample spacing inside.
void ClampCurveIntoDomain(SmoothedPiece& piece, const double bounds[4])
{
  const std::size_t samples = piece.Points.size() / 2;
  const double margin = ClampingMargin(piece.Points);
  double box[4];
  for (int side = 0; side < 4; ++side)
  {
    const int axis = side / 2;
    bool alongSide = samples > 1;
    for (std::size_t i = 0; i < samples && alongSide; ++i)
    {
      alongSide = piece.Points[2 * i + axis] == bounds[side];
    }
    box[side] = bounds[side] + (alongSide ? 0.0 : (side % 2 == 0 ? margin : -margin));
  }
  piece.Clamped = false;
  const std::size_t count = piece.Curve.ControlPoints.size();
  for (std::size_t i = 2; i + 2 < count; ++i)
  {
    double& coordinate = piece.Curve.ControlPoints[i];
    const std::size_t axis = i % 2;
    const double lo = box[2 * axis], hi = box[2 * axis + 1];
    const double clamped = lo <= hi ? std::clamp(coordinate, lo, hi) : 0.5 * (lo + hi);
    piece.Clamped = piece.Clamped || clamped != coordinate;
    coordinate = clamped;
  }
}

// A uniform grid of square cells over a box, numbered row by row (consecutive pieces run
// along x, and their cells then lie close together in the grid's arrays).
struct UniformGrid
{
  double Low[2] = { 0, 0 };
  double CellSize = 1;
  long Nx = 1, Ny = 1;

  // About `cells` cells over the box (xmin, xmax, ymin, ymax).
  void LayOut(const double bounds[4], double cells)
  {
    const double width = std::max(bounds[1] - bounds[0], 1e-12);
    const double height = std::max(bounds[3] - bounds[2], 1e-12);
    this->Low[0] = bounds[0];
    this->Low[1] = bounds[2];
    this->CellSize = std::max(std::sqrt(width * height / std::max(cells, 1.0)), 1e-12);
    this->Nx = static_cast<long>(width / this->CellSize) + 1;
    this->Ny = static_cast<long>(height / this->CellSize) + 1;
  }
  std::size_t Cells() const { return static_cast<std::size_t>(this->Nx * this->Ny); }
  long Column(double x) const
  {
    return std::clamp(static_cast<long>((x - this->Low[0]) / this->CellSize), 0L, this->Nx - 1);
  }
  long Row(double y) const
  {
    return std::clamp(static_cast<long>((y - this->Low[1]) / this->CellSize), 0L, this->Ny - 1);
  }
  std::size_t CellOf(const double* xy) const
  {
    return static_cast<std::size_t>(this->Row(xy[1]) * this->Nx + this->Column(xy[0]));
  }
  // Calls visit(cell) for every cell that the box of segment ab, grown by `grow`, overlaps.
  template <typename Visit>
  void ForEachCellNear(const double* a, const double* b, double grow, const Visit& visit) const
  {
    this->ForEachCellNear(a, b, grow, 0, this->Ny, visit);
  }
  // The same, for the cells in rows first .. last - 1 only.
  template <typename Visit>
  void ForEachCellNear(const double* a, const double* b, double grow, long first, long last, const Visit& visit) const
  {
    const long i0 = this->Column(std::min(a[0], b[0]) - grow), i1 = this->Column(std::max(a[0], b[0]) + grow);
    const long j0 = std::max(first, this->Row(std::min(a[1], b[1]) - grow));
    const long j1 = std::min(last - 1, this->Row(std::max(a[1], b[1]) + grow));
    for (long j = j0; j <= j1; ++j)
    {
      for (long i = i0; i <= i1; ++i)
      {
        visit(static_cast<std::size_t>(j * this->Nx + i));
      }
    }
  }
};

// Finds the pairs of pieces whose smoothed curves cross: samples every curve as a polyline,
// buckets its segments in a uniform grid, and tests pairs of segments of different pieces (and
// non-adjacent segments of one piece). Pieces meeting at a node may touch there.
// Curves that end at one point (the same node, or two nodes on one vertex: a boundary
// saddle and a maximum share their vertex, and the 1-cell between them is a loop) meet
// there: within two samples of such a shared end, a contact through that point (to rounding)
// is their meeting. Any other contact is a crossing, however close to the node: two 1-cells
// that leave a saddle almost tangentially and cross there leave a 2-cell without a simple
// boundary.
// Incremental: the repair refits a few pieces per round, so after the first full pass only
// the refitted pieces are sampled, re-bucketed and tested again (against all pieces); a pair
// of pieces neither of which changed keeps its answer. On 300^2 noise the repair runs rounds
// with a few hundred of 120 000 pieces each.
class CrossingDetector
{
public:
  CrossingDetector(const OneCellSmoothingResult& result, const double domainBounds[4], int samplesPerSegment,
    const ParallelFor& parallel)
    : Result(result)
    , Bounds(domainBounds)
    , SamplesPerSegment(samplesPerSegment)
    , MeetingTolerance(1e-9 * std::max(domainBounds[1] - domainBounds[0], domainBounds[3] - domainBounds[2]))
    , Parallel(parallel)
  {
  }

  // Samples and tests every piece; returns the number of crossing pairs and puts the pieces
  // that cross another one into `crossing`.
  int FindCrossings(std::set<Index>& crossing)
  {
    // All samples in one array (a vector per piece cost a third of stage 3 on 1000^2 noise in
    // allocations): piece p's points are Offset[p] .. Offset[p + 1].
    const Index count = static_cast<Index>(this->Result.Pieces.size());
    this->Offset.assign(count + 1, 0);
    for (Index p = 0; p < count; ++p)
    {
      this->Offset[p + 1] = this->Offset[p] + this->SampleCount(p);
    }
    this->Flat.resize(2 * this->Offset[count]);
    this->Moved.assign(count, 0);
    this->Resampled.clear();
    this->Extra.clear();
    this->Parallel(0, count, [this](Index begin, Index end) {
      for (Index p = begin; p < end; ++p)
      {
        this->SampleCurve(p, &this->Flat[2 * this->Offset[p]]);
      }
    });
    std::size_t segments = 0;
    for (Index p = 0; p < count; ++p)
    {
      segments += this->SegmentCount(p);
    }
    // About one segment per cell.
    this->SegmentGrid.LayOut(this->Bounds, static_cast<double>(segments));
    // The grid as compressed rows: count, then fill.
    // In bands of grid rows, one per task: a band takes the pieces that reach its rows, in
    // their order, so every cell lists its segments in the order of a single pass (3.5 s of
    // one thread on 1000^2 noise).
    std::vector<std::size_t>& start = this->CellStart;
    start.assign(this->SegmentGrid.Cells() + 1, 0);
    std::vector<std::array<long, 2>> rowsOf(static_cast<std::size_t>(count));
    this->Parallel(0, count, [&](Index begin, Index end) {
      for (Index p = begin; p < end; ++p)
      {
        std::array<long, 2> rows{ this->SegmentGrid.Ny, -1 };
        this->ForEachRowsOf(p, [&rows](long j0, long j1) {
          rows[0] = std::min(rows[0], j0);
          rows[1] = std::max(rows[1], j1);
        });
        rowsOf[p] = rows;
      }
    });
    // A piece reaching several bands is walked by each of them (a terrain's long pieces): a few
    // bands are enough to share the work.
    const Index bands = static_cast<Index>(std::min<long>(8, this->SegmentGrid.Ny));
    const auto forEachInBand = [&](Index band, const auto& visit) {
      const long first = band * this->SegmentGrid.Ny / bands, last = (band + 1) * this->SegmentGrid.Ny / bands;
      for (Index p = 0; p < count; ++p)
      {
        if (rowsOf[p][1] >= first && rowsOf[p][0] < last)
        {
          this->ForEachCellOf(p, first, last, [&visit, p](int segment, std::size_t cell) { visit(p, segment, cell); });
        }
      }
    };
    this->Parallel(0, bands, [&](Index begin, Index end) {
      for (Index band = begin; band < end; ++band)
      {
        forEachInBand(band, [&start](Index, int, std::size_t cell) { ++start[cell + 1]; });
      }
    });
    for (std::size_t c = 0; c + 1 < start.size(); ++c)
    {
      start[c + 1] += start[c];
    }
    this->Entries.resize(start.back());
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    this->Parallel(0, bands, [&](Index begin, Index end) {
      for (Index band = begin; band < end; ++band)
      {
        forEachInBand(
          band, [&](Index p, int segment, std::size_t cell) { this->Entries[fill[cell]++] = { p, segment }; });
      }
    });
    // Each grid cell's pairs, cells split among threads.
    std::mutex mutex;
    this->Pairs.clear();
    this->Parallel(0, static_cast<Index>(start.size() - 1), [&](Index begin, Index end) {
      std::vector<std::pair<Index, Index>> found;
      for (Index c = begin; c < end; ++c)
      {
        for (std::size_t x = start[c]; x < start[c + 1]; ++x)
        {
          for (std::size_t y = x + 1; y < start[c + 1]; ++y)
          {
            this->TestPair(this->Entries[x], this->Entries[y], found);
          }
        }
      }
      const std::lock_guard<std::mutex> lock(mutex);
      this->Pairs.insert(found.begin(), found.end());
    });
    this->BucketNodes();
    this->TestNodeClearance(count, [](Index p) { return p; });
    return this->Report(crossing);
  }

  // After the pieces in `changed` got new curves: samples and tests those again. Their entries
  // in the compressed grid are skipped from now on (Moved); their new segments go to a small
  // grid of their own (Extra).
  int UpdateCrossings(const std::vector<Index>& changed, std::set<Index>& crossing)
  {
    const std::set<Index> changedSet(changed.begin(), changed.end());
    for (auto pair = this->Pairs.begin(); pair != this->Pairs.end();)
    {
      pair = changedSet.count(pair->first) || changedSet.count(pair->second) ? this->Pairs.erase(pair) : std::next(pair);
    }
    for (Index p : changed)
    {
      if (this->Moved[p])
      {
        this->ForEachCellOf(p, [this, p](int, std::size_t cell) {
          std::vector<SegmentRef>& list = this->Extra[cell];
          list.erase(std::remove_if(list.begin(), list.end(), [p](const SegmentRef& r) { return r.Piece == p; }),
            list.end());
        });
      }
      this->Moved[p] = 1;
      std::vector<double>& samples = this->Resampled[p];
      samples.resize(2 * this->SampleCount(p));
    }
    this->Parallel(0, static_cast<Index>(changed.size()), [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        this->SampleCurve(changed[i], this->Resampled.at(changed[i]).data());
      }
    });
    for (Index p : changed)
    {
      this->ForEachCellOf(p, [this, p](int segment, std::size_t cell) { this->Extra[cell].push_back({ p, segment }); });
    }
    std::mutex mutex;
    this->Parallel(0, static_cast<Index>(changed.size()), [&](Index begin, Index end) {
      std::vector<std::pair<Index, Index>> found;
      for (Index i = begin; i < end; ++i)
      {
        this->ForEachCellOf(changed[i], [&](int segment, std::size_t cell) {
          const SegmentRef s{ changed[i], segment };
          for (std::size_t e = this->CellStart[cell]; e < this->CellStart[cell + 1]; ++e)
          {
            if (!this->Moved[this->Entries[e].Piece])
            {
              this->TestPair(s, this->Entries[e], found);
            }
          }
          const auto extra = this->Extra.find(cell);
          for (const SegmentRef& t : extra->second)
          {
            if (t.Piece != s.Piece || t.Segment != s.Segment)
            {
              this->TestPair(s, t, found);
            }
          }
        });
      }
      const std::lock_guard<std::mutex> lock(mutex);
      this->Pairs.insert(found.begin(), found.end());
    });
    this->TestNodeClearance(static_cast<Index>(changed.size()), [&changed](Index i) { return changed[i]; });
    return this->Report(crossing);
  }

  // The pairs found (a piece paired with itself: it passes a node not its own too closely).
  const std::set<std::pair<Index, Index>>& CrossingPairs() const { return this->Pairs; }

  // The piece's current samples (x y pairs) and their number.
  const double* Samples(Index p, std::size_t& count) const
  {
    if (this->Moved[p])
    {
      const std::vector<double>& samples = this->Resampled.at(p);
      count = samples.size() / 2;
      return samples.data();
    }
    count = this->Offset[p + 1] - this->Offset[p];
    return this->Flat.data() + 2 * this->Offset[p];
  }

private:
  struct SegmentRef
  {
    Index Piece;
    int Segment; // position along the piece's sampled polyline
  };

  int Report(std::set<Index>& crossing) const
  {
    for (const auto& pair : this->Pairs)
    {
      crossing.insert(pair.first);
      crossing.insert(pair.second);
    }
    return static_cast<int>(this->Pairs.size());
  }

  // A piece of no length (a boundary saddle and a maximum on one vertex, joined by one
  // ascending 1-cell) is a point at its node (no samples): it crosses nothing, and the pieces
  // that end there only touch it.
  bool IsPoint(Index p) const
  {
    const std::vector<double>& control = this->Result.Pieces[p].Curve.ControlPoints;
    for (std::size_t i = 2; i + 1 < control.size(); i += 2)
    {
      if (control[i] != control[0] || control[i + 1] != control[1])
      {
        return false;
      }
    }
    return true;
  }

  // Points of the piece's polyline: SamplesPerSegment segments per Bezier segment.
  std::size_t SampleCount(Index p) const
  {
    return this->IsPoint(p) ? 0 : static_cast<std::size_t>(this->Result.Pieces[p].Segments * this->SamplesPerSegment + 1);
  }

  void SampleCurve(Index p, double* samples) const
  {
    const std::size_t count = this->SampleCount(p);
    for (std::size_t s = 0; s < count; ++s)
    {
      this->Result.Pieces[p].Curve.Evaluate(static_cast<double>(s) / (count - 1), samples + 2 * s);
    }
  }

  std::size_t SegmentCount(Index p) const
  {
    std::size_t count;
    this->Samples(p, count);
    return count > 0 ? count - 1 : 0;
  }

  // Calls visit(segment, grid cell) for every grid cell that a segment's box overlaps.
  template <typename Visit>
  void ForEachCellOf(Index p, const Visit& visit) const
  {
    this->ForEachCellOf(p, 0, this->SegmentGrid.Ny, visit);
  }
  // The same, for the cells in grid rows first .. last - 1 only.
  template <typename Visit>
  void ForEachCellOf(Index p, long first, long last, const Visit& visit) const
  {
    std::size_t count;
    const double* samples = this->Samples(p, count);
    for (std::size_t s = 0; s + 1 < count; ++s)
    {
      // Boxes grown by how far the curve may stray (ChordSagitta): chords closer than that
      // share a cell and are tested (TestPair).
      const double* a = samples + 2 * s;
      this->SegmentGrid.ForEachCellNear(a, a + 2, this->ChordSagitta(p, static_cast<int>(s)), first, last,
        [&visit, s](std::size_t cell) { visit(static_cast<int>(s), cell); });
    }
  }
  // Calls visit(j0, j1) with the grid rows of each segment's grown box.
  template <typename Visit>
  void ForEachRowsOf(Index p, const Visit& visit) const
  {
    std::size_t count;
    const double* samples = this->Samples(p, count);
    for (std::size_t s = 0; s + 1 < count; ++s)
    {
      const double* a = samples + 2 * s;
      const double grow = this->ChordSagitta(p, static_cast<int>(s));
      visit(this->SegmentGrid.Row(std::min(a[1], a[3]) - grow), this->SegmentGrid.Row(std::max(a[1], a[3]) + grow));
    }
  }

  // The nodes at which pieces end, in a grid of their own: about four cells per node (the
  // segments' grid, one segment per cell, had some thirty cells per node and its offsets were
  // 200 MB on 1000^2 noise).
  void BucketNodes()
  {
    const std::vector<SmoothingNode>& nodes = this->Result.Nodes;
    std::vector<unsigned char> isEnd(nodes.size(), 0);
    for (const SmoothedPiece& piece : this->Result.Pieces)
    {
      isEnd[piece.StartNode] = isEnd[piece.EndNode] = 1;
    }
    const double ends = static_cast<double>(std::count(isEnd.begin(), isEnd.end(), 1));
    this->NodeGrid.LayOut(this->Bounds, std::min(4 * ends, static_cast<double>(this->SegmentGrid.Cells())));
    this->NodeStart.assign(this->NodeGrid.Cells() + 1, 0);
    for (std::size_t n = 0; n < nodes.size(); ++n)
    {
      this->NodeStart[this->NodeGrid.CellOf(nodes[n].Position) + 1] += isEnd[n];
    }
    for (std::size_t c = 0; c + 1 < this->NodeStart.size(); ++c)
    {
      this->NodeStart[c + 1] += this->NodeStart[c];
    }
    this->NodeEntries.resize(this->NodeStart.back());
    std::vector<std::size_t> fill(this->NodeStart.begin(), this->NodeStart.end() - 1);
    for (std::size_t n = 0; n < nodes.size(); ++n)
    {
      if (isEnd[n])
      {
        this->NodeEntries[fill[this->NodeGrid.CellOf(nodes[n].Position)]++] = static_cast<Index>(n);
      }
    }
  }

  // A piece that passes a node it does not end at closer than the polylines can resolve
  // crosses that node's pieces or touches it, on one sampling and not on another: on 128^2
  // noise a smoothed curve cut the corner of its jagged 1-cell 0.005 spacings from a saddle
  // and crossed all four of its 1-cells there, which this detector's polylines (8 points per
  // Bezier segment) passed on the free side while stage 4's boundary polygon (5 points) did
  // not, and the 2-cell failed. A polyline of n points per cubic segment is within
  // 0.75 M / n^2 of its curve (M: the largest second difference of the control points), so a
  // node within the sum of that bound for these samples and for 4 per segment (coarser than
  // any later sampling) of one of the piece's chords counts as a crossing of the piece.
  template <typename PieceAt>
  void TestNodeClearance(Index count, const PieceAt& pieceAt)
  {
    std::mutex mutex;
    this->Parallel(0, count, [&](Index begin, Index end) {
      std::vector<std::pair<Index, Index>> found;
      for (Index i = begin; i < end; ++i)
      {
        const Index p = pieceAt(i);
        if (this->TooCloseToANode(p))
        {
          found.emplace_back(p, p);
        }
      }
      const std::lock_guard<std::mutex> lock(mutex);
      this->Pairs.insert(found.begin(), found.end());
    });
  }

  bool TooCloseToANode(Index p) const
  {
    const SmoothedPiece& piece = this->Result.Pieces[p];
    const double* ends[2] = { this->Result.Nodes[piece.StartNode].Position,
      this->Result.Nodes[piece.EndNode].Position };
    std::size_t count;
    const double* samples = this->Samples(p, count);
    const double polylineFactor = 1.0 / (this->SamplesPerSegment * this->SamplesPerSegment) + 1.0 / 16;
    for (std::size_t s = 0; s + 1 < count; ++s)
    {
      const double clearance =
        polylineFactor * this->SegmentSagitta(p, static_cast<int>(s) / this->SamplesPerSegment) + this->MeetingTolerance;
      const double* a = samples + 2 * s;
      const double* b = a + 2;
      bool tooClose = false;
      this->NodeGrid.ForEachCellNear(a, b, clearance, [&](std::size_t cell) {
        for (std::size_t e = this->NodeStart[cell]; e < this->NodeStart[cell + 1] && !tooClose; ++e)
        {
          const Index n = this->NodeEntries[e];
          const double* q = this->Result.Nodes[n].Position;
          if (n == piece.StartNode || n == piece.EndNode || (q[0] == ends[0][0] && q[1] == ends[0][1]) ||
            (q[0] == ends[1][0] && q[1] == ends[1][1]))
          {
            continue;
          }
          double fraction;
          tooClose = SegmentDistance2(a, b, q[0], q[1], fraction) <= clearance * clearance;
        }
      });
      if (tooClose)
      {
        return true;
      }
    }
    return false;
  }

  const double* SegmentStart(const SegmentRef& s) const
  {
    std::size_t count;
    return this->Samples(s.Piece, count) + 2 * s.Segment;
  }

  // Chords that cross, or that pass closer than their curves may stray from them, are decided
  // on the curves themselves (RefinedCrossing): two curves can cross between the samples (two
  // 1-cells leaving one saddle almost tangentially crossed 0.14 spacings from it, unseen at 8
  // points per segment) where a finer sampling, such as stage 4's subdivided boundaries, sees
  // it; so can two curves leaving one node, from their second chords on.
  void TestPair(const SegmentRef& s, const SegmentRef& t, std::vector<std::pair<Index, Index>>& found) const
  {
    if (s.Piece == t.Piece && std::abs(s.Segment - t.Segment) <= 1)
    {
      return;
    }
    const double* sa = this->SegmentStart(s);
    const double* ta = this->SegmentStart(t);
    const bool chordsCross = SegmentsCrossProperly(sa, sa + 2, ta, ta + 2);
    // Within two chords of an end both pieces share, a contact through that point (to
    // rounding) is their meeting.
    bool crossing = chordsCross && !this->NearASharedEnd(s, t, 2, true);
    // The two chords that start at one shared end are left to the chords alone. Two curves
    // leaving a node may cross a hair from it (Shepard seed 4 at 5 %: 0.045 spacings from the
    // node, a 250th of the segment): no 2-cell boundary of stage 4 sees that, since its polygons
    // start at the node too and sample the curves only from a fifth of a segment on, and giving
    // those pieces more segments only made their heights fit worse (the largest error 1.37 ->
    // 2.08 eps).
    if (!crossing && (chordsCross || this->CurvesMayMeet(s, sa, t, ta)) && !this->NearASharedEnd(s, t, 1, false))
    {
      crossing = this->RefinedCrossing(s, t);
    }
    if (crossing && !this->CloseALoop(s.Piece, t.Piece))
    {
      found.emplace_back(std::min(s.Piece, t.Piece), std::max(s.Piece, t.Piece));
    }
  }

  // Whether chords sa (of s) and ta (of t) pass closer than their curves may stray from them.
  bool CurvesMayMeet(const SegmentRef& s, const double* sa, const SegmentRef& t, const double* ta) const
  {
    const double reach =
      this->ChordSagitta(s.Piece, s.Segment) + this->ChordSagitta(t.Piece, t.Segment) + this->MeetingTolerance;
    return !BoxesApart(sa, ta, reach) && ChordDistance(sa, ta) <= reach;
  }

  // Whether the boxes of segments a and b (two points each) lie more than `reach` apart.
  static bool BoxesApart(const double* a, const double* b, double reach)
  {
    for (int d = 0; d < 2; ++d)
    {
      if (std::min(a[d], a[d + 2]) - reach > std::max(b[d], b[d + 2]) ||
        std::min(b[d], b[d + 2]) - reach > std::max(a[d], a[d + 2]))
      {
        return true;
      }
    }
    return false;
  }

  static double ChordDistance(const double* a, const double* b)
  {
    double fraction;
    return std::sqrt(std::min({ SegmentDistance2(a, a + 2, b[0], b[1], fraction),
      SegmentDistance2(a, a + 2, b[2], b[3], fraction), SegmentDistance2(b, b + 2, a[0], a[1], fraction),
      SegmentDistance2(b, b + 2, a[2], a[3], fraction) }));
  }

  // How far the curve may stray from chord `chord` of piece p: a polyline of n points per cubic
  // segment lies within 0.75 M / n^2 of its curve (M: the largest second difference of the
  // segment's control points, |B''| <= 6 M).
  double ChordSagitta(Index p, int chord) const
  {
    return this->SegmentSagitta(p, chord / this->SamplesPerSegment) /
      (this->SamplesPerSegment * this->SamplesPerSegment);
  }

  // 0.75 M of Bezier segment `segment` of piece p: a chord over a parameter step h of the
  // segment lies within 0.75 M h^2 of it.
  double SegmentSagitta(Index p, int segment) const
  {
    const CubicBezierSpline& curve = this->Result.Pieces[p].Curve;
    const double* control = curve.Segment(std::min(segment, curve.Segments - 1));
    double second = 0;
    for (int c = 0; c < 2; ++c)
    {
      const double dx = control[2 * c + 4] - 2 * control[2 * c + 2] + control[2 * c];
      const double dy = control[2 * c + 5] - 2 * control[2 * c + 3] + control[2 * c + 1];
      second = std::max(second, dx * dx + dy * dy);
    }
    return 0.75 * std::sqrt(second);
  }

  // A stretch of one Bezier segment of a piece, by the segment's own parameter.
  struct CurveSpan
  {
    Index Piece;
    int Segment;
    double From, To;
  };

  CurveSpan SpanOf(const SegmentRef& chord) const
  {
    const int segment = std::min(chord.Segment / this->SamplesPerSegment, this->Result.Pieces[chord.Piece].Curve.Segments - 1);
    const double from = static_cast<double>(chord.Segment - segment * this->SamplesPerSegment) / this->SamplesPerSegment;
    return { chord.Piece, segment, from, from + 1.0 / this->SamplesPerSegment };
  }

  // Whether the curves of the two chords cross properly away from the ends of their pieces (to
  // rounding): each chord's stretch of curve is sampled 8 times finer, and sub-chords that are
  // still closer than their curves may stray are refined once more (512 points per segment; a
  // budget bounds curves that run along each other). Finer than that no sampling of stage 4
  // looks (5 points per segment of the common subdivision of a cell's sides), and counting the
  // crossings only a finer one sees, a hair from a shared end, gave pieces more segments where
  // the 2-cells were fine (Shepard seed 4 at 5 %: the largest error 1.37 -> 2.08 eps).
  bool RefinedCrossing(const SegmentRef& s, const SegmentRef& t) const
  {
    int budget = 32;
    return this->SpansCross(this->SpanOf(s), this->SpanOf(t), 0, budget);
  }

  bool SpansCross(const CurveSpan& a, const CurveSpan& b, int depth, int& budget) const
  {
    constexpr int Steps = 8, MaximumDepth = 1;
    double fineA[2 * (Steps + 1)], fineB[2 * (Steps + 1)];
    this->SampleSpan(a, Steps, fineA);
    this->SampleSpan(b, Steps, fineB);
    const double stepA = (a.To - a.From) / Steps, stepB = (b.To - b.From) / Steps;
    const double reach = this->SegmentSagitta(a.Piece, a.Segment) * stepA * stepA +
      this->SegmentSagitta(b.Piece, b.Segment) * stepB * stepB + this->MeetingTolerance;
    for (int i = 0; i < Steps; ++i)
    {
      for (int j = 0; j < Steps; ++j)
      {
        const double* u = fineA + 2 * i;
        const double* w = fineB + 2 * j;
        if (BoxesApart(u, w, reach))
        {
          continue;
        }
        if (SegmentsCrossProperly(u, u + 2, w, w + 2))
        {
          if (!this->NearAnEnd(a.Piece, u) && !this->NearAnEnd(b.Piece, w))
          {
            return true;
          }
        }
        else if (depth < MaximumDepth && budget > 0 && ChordDistance(u, w) <= reach)
        {
          --budget;
          const CurveSpan subA{ a.Piece, a.Segment, a.From + i * stepA, a.From + (i + 1) * stepA };
          const CurveSpan subB{ b.Piece, b.Segment, b.From + j * stepB, b.From + (j + 1) * stepB };
          if (this->SpansCross(subA, subB, depth + 1, budget))
          {
            return true;
          }
        }
      }
    }
    return false;
  }

  void SampleSpan(const CurveSpan& span, int steps, double* samples) const
  {
    const double* control = this->Result.Pieces[span.Piece].Curve.Segment(span.Segment);
    for (int i = 0; i <= steps; ++i)
    {
      CubicBezierSpline::EvaluateSegment(control, 2, span.From + (span.To - span.From) * i / steps, samples + 2 * i);
    }
  }

  bool NearAnEnd(Index p, const double* q) const
  {
    for (const bool atEnd : { false, true })
    {
      const double* e = this->EndPosition(p, atEnd);
      if ((q[0] - e[0]) * (q[0] - e[0]) + (q[1] - e[1]) * (q[1] - e[1]) <= this->MeetingTolerance * this->MeetingTolerance)
      {
        return true;
      }
    }
    return false;
  }

  bool PassesThrough(const SegmentRef& s, const double* q) const
  {
    const double* a = this->SegmentStart(s);
    double fraction;
    return std::sqrt(SegmentDistance2(a, a + 2, q[0], q[1], fraction)) <= this->MeetingTolerance;
  }

  const double* EndPosition(Index p, bool atEnd) const
  {
    const SmoothedPiece& piece = this->Result.Pieces[p];
    return this->Result.Nodes[atEnd ? piece.EndNode : piece.StartNode].Position;
  }

  // Whether s and t lie within `chords` chords of ends of their pieces at one point; with
  // `throughIt`, both chords must also pass through that point (to rounding).
  bool NearASharedEnd(const SegmentRef& s, const SegmentRef& t, int chords, bool throughIt) const
  {
    const int sCount = static_cast<int>(this->SegmentCount(s.Piece));
    const int tCount = static_cast<int>(this->SegmentCount(t.Piece));
    for (int es = 0; es < 2; ++es)
    {
      const bool nearS = es == 0 ? s.Segment < chords : s.Segment >= sCount - chords;
      for (int et = 0; et < 2 && nearS; ++et)
      {
        const bool nearT = et == 0 ? t.Segment < chords : t.Segment >= tCount - chords;
        const double* a = this->EndPosition(s.Piece, es == 1);
        const double* b = this->EndPosition(t.Piece, et == 1);
        if (nearT && a[0] == b[0] && a[1] == b[1] &&
          (!throughIt || (this->PassesThrough(s, a) && this->PassesThrough(t, a))))
        {
          return true;
        }
      }
    }
    return false;
  }

  // Two pieces that close a loop (a boundary saddle and a maximum on one vertex, joined by
  // the saddle's only ascending 1-cell, cut at a junction) start where the other ends: often
  // the loop has no area and both are one segment, traversed both ways. They may touch.
  bool CloseALoop(Index p, Index q) const
  {
    const double* ps = this->EndPosition(p, false);
    const double* pe = this->EndPosition(p, true);
    const double* qs = this->EndPosition(q, false);
    const double* qe = this->EndPosition(q, true);
    return ps[0] == qe[0] && ps[1] == qe[1] && pe[0] == qs[0] && pe[1] == qs[1];
  }

  const OneCellSmoothingResult& Result;
  const double* Bounds;
  int SamplesPerSegment;
  double MeetingTolerance;
  const ParallelFor& Parallel;
  std::vector<double> Flat;                             // every piece's samples at the first pass
  std::vector<std::size_t> Offset;                      // per piece, its first point in Flat
  std::vector<unsigned char> Moved;                     // refitted since: samples in Resampled
  std::unordered_map<Index, std::vector<double>> Resampled;
  std::vector<std::size_t> CellStart;                   // compressed grid of the first pass
  std::vector<SegmentRef> Entries;
  std::unordered_map<std::size_t, std::vector<SegmentRef>> Extra; // segments of moved pieces
  UniformGrid SegmentGrid;
  UniformGrid NodeGrid;
  std::vector<std::size_t> NodeStart; // the pieces' end nodes in NodeGrid, compressed rows
  std::vector<Index> NodeEntries;
  std::set<std::pair<Index, Index>> Pairs; // (p, p): p runs too close to a node not its own
};

// Pieces whose curve leaves the domain's bounding box (to rounding) at one of its samples.
int CountPiecesOutsideDomain(
  const std::vector<SmoothedPiece>& pieces, const double domainBounds[4], int samplesPerSegment)
{
  int outsideCount = 0;
  for (const SmoothedPiece& piece : pieces)
  {
    bool outside = false;
    const int count = piece.Segments * samplesPerSegment;
    for (int s = 0; s <= count && !outside; ++s)
    {
      double xy[2];
      piece.Curve.Evaluate(static_cast<double>(s) / count, xy);
      const double tolerance = 1e-9 * std::max(domainBounds[1] - domainBounds[0], domainBounds[3] - domainBounds[2]);
      outside = xy[0] < domainBounds[0] - tolerance || xy[0] > domainBounds[1] + tolerance ||
        xy[1] < domainBounds[2] - tolerance || xy[1] > domainBounds[3] + tolerance;
    }
    outsideCount += outside;
  }
  return outsideCount;
}
} // namespace

//------------------------------------------------------------------------------
bool OneCellSmoothing::FollowPolyline(SmoothedPiece& piece, const std::vector<SmoothingNode>& nodes)
{
  std::vector<double> p = piece.Points;
  const int edges = static_cast<int>(p.size() / 2) - 1;
  const int segments = piece.Curve.Segments;
  if (edges < 1 || segments < edges || piece.Curve.Dimension != 2)
  {
    return false;
  }
  p[0] = nodes[piece.StartNode].Position[0];
  p[1] = nodes[piece.StartNode].Position[1];
  p[2 * edges] = nodes[piece.EndNode].Position[0];
  p[2 * edges + 1] = nodes[piece.EndNode].Position[1];
  // Each edge's share of the parameter: its length, or its parameter step where the knots
  // crowd near contacts (the height keeps those parameters).
  const bool contactKnots = piece.ContactKnots && piece.Parameters.size() == piece.Points.size() / 2;
  std::vector<double> length(edges);
  double total = 0;
  for (int e = 0; e < edges; ++e)
  {
    length[e] = contactKnots ? piece.Parameters[e + 1] - piece.Parameters[e]
                             : std::hypot(p[2 * e + 2] - p[2 * e], p[2 * e + 3] - p[2 * e + 1]);
    total += length[e];
  }
  // Largest remainders of the length shares of the segments beyond one per edge.
  std::vector<int> count(edges, 1);
  const int extra = segments - edges;
  std::vector<std::pair<double, int>> remainders;
  int given = 0;
  for (int e = 0; e < edges; ++e)
  {
    const double share = total > 0 ? extra * length[e] / total : static_cast<double>(extra) / edges;
    count[e] += static_cast<int>(share);
    given += static_cast<int>(share);
    remainders.emplace_back(-(share - static_cast<int>(share)), e);
  }
  std::sort(remainders.begin(), remainders.end());
  for (int r = 0; given < extra; ++r, ++given)
  {
    ++count[remainders[r % edges].second];
  }
  std::vector<double>& control = piece.Curve.ControlPoints;
  control.clear();
  for (int e = 0; e < edges; ++e)
  {
    const double* a = &p[2 * e];
    const double* b = &p[2 * e + 2];
    for (int i = 0; i < count[e]; ++i)
    {
      for (int m = 0; m < 4; ++m)
      {
        // i + m / 3 is exact at the segment's ends (m = 0, 3), which its neighbours share.
        const double t = (i + m / 3.0) / count[e];
        control.push_back(t == 1 ? b[0] : a[0] + t * (b[0] - a[0]));
        control.push_back(t == 1 ? b[1] : a[1] + t * (b[1] - a[1]));
      }
    }
  }
  return true;
}

// k for a piece: the k asked for, or on a piece of fewer edges, the smallest divisor of k that
// gives each edge a segment (at least 2). Segments beyond the samples fit nothing, and stage 4
// pays for them: a 2-cell's Sibson grid is at least as fine as its busiest side, and its
// patches grow with the square of that. Noise at a low threshold leaves thousands of pieces of
// 2-3 edges: 100^2 noise at 2 %, k 21 took over 24 GB. Divisors of k, because stage 4 needs one
// grid count that every side's pieces reach by whole multiples (ChooseGridLayout): counts that
// divide k keep every grid at most as fine as with k everywhere, while counts such as 13 and 19
// on one cell need a grid of 247.
int OneCellSmoothing::SegmentsForEdges(int edges, int asked)
{
  for (int d = std::max(2, edges); d < asked; ++d)
  {
    if (asked % d == 0)
    {
      return d;
    }
  }
  return asked;
}

// A prime k has no divisor to give a short piece: on 200^2 uniform noise at 2 %, where 46 818 of
// 57 718 pieces have 2 edges, k = 11 gave every piece 11 segments and stage 4 was refused for
// 534 million Bezier triangles (12.8 GB), while k = 12 (2, 3, 4 or 6 on short pieces) took 4.3
// million and 0.6 GB, and k = 23 took 170 million, k = 24 4.2 million. Giving such pieces
// fewer segments than a divisor was tried three ways and dropped (docs/Reconstruction.md,
// "Fewer segments on short pieces"), so the filter names a better k instead.
int OneCellSmoothing::SuggestCurveSegments(const std::vector<int>& edges, int asked, int* oversegmented)
{
  // Segments on pieces given more than twice their edges, all segments, and their squares.
  struct Spend
  {
    long long Wasted = 0, Total = 0, Squares = 0;
    int Pieces = 0;
  };
  const auto spend = [&](int k) {
    Spend s;
    for (const int e : edges)
    {
      const long long n = SegmentsForEdges(e, k);
      s.Total += n;
      s.Squares += n * n;
      if (n > 2 * std::max(2, e))
      {
        s.Wasted += n;
        ++s.Pieces;
      }
    }
    return s;
  };
  const Spend now = spend(asked);
  if (oversegmented)
  {
    *oversegmented = now.Pieces;
  }
  if (2 * now.Wasted <= now.Total)
  {
    return 0;
  }
  for (int distance = 1; distance < MaximumCurveSegments; ++distance)
  {
    int best = 0;
    long long bestSquares = 0;
    for (const int k : { asked - distance, asked + distance })
    {
      if (k < 2 || k > MaximumCurveSegments)
      {
        continue;
      }
      const Spend s = spend(k);
      if (10 * s.Wasted <= s.Total && (best == 0 || s.Squares < bestSquares))
      {
        best = k;
        bestSquares = s.Squares;
      }
    }
    if (best != 0)
    {
      return best;
    }
  }
  return 0;
}

namespace
{
// The jagged edges of a piece's path (its samples less one).
int EdgesOf(const SmoothedPiece& piece)
{
  return static_cast<int>(piece.Points.size() / 2) - 1;
}

int SegmentsOfPiece(const SmoothedPiece& piece, int asked)
{
  return OneCellSmoothing::SegmentsForEdges(EdgesOf(piece), asked);
}

// The count a piece's k rises to where it crosses another piece or misses its heights: the
// next divisor of k at least twice the current count (k if none), beyond k twice the count.
// Every count then divides k 2^j, so the pieces of one 2-cell's sides reach a common grid
// count (ChooseGridLayout) within a few multiples of the largest. Doubling the divisors as
// well gave counts like 32 (2 doubled four times) beside 44 and 88 at k = 22, which need a
// grid of 704, beyond stage 4's limit: the stress test's failed 2-cells on noise at 50 %
// and on Delaunay meshes with k 22, 26 and 30.
int RaisedSegments(int current, int asked)
{
  if (current >= asked)
  {
    return 2 * current;
  }
  for (int d = 2 * current; d < asked; ++d)
  {
    if (asked % d == 0)
    {
      return d;
    }
  }
  return asked;
}

// Contact knots (RepairCrossings): a path sample of a crossing piece is in contact where it
// lies within ContactPathReach of the other piece's jagged path, or where the piece's curve at
// its parameter lies within ContactCurveReach of the other's curve (working-frame units, about
// grid spacings; paths never cross, so where curves do, each has strayed from its path).
constexpr double ContactPathReach = 2;
constexpr double ContactCurveReach = 1;
// Each raise multiplies the density of a crossing piece's knots on its contacts by this.
constexpr double ContactDensityGrowth = 4;
// Knots crowd at contacts only on pieces with at least this many edges per segment.
constexpr int ContactSamplesPerSegment = 4;

// Marks in `contact` (one flag per path sample) the samples of `piece` in contact with another
// piece or with nodes: `otherPath` and the `curveCount` points of `otherCurve` (x y pairs) are
// that piece's jagged path and its sampled curve, or the nodes' positions for both. Where the
// curves come near, the samples a segment of the piece's curve either side count too: the
// crossing lies between.
void MarkContacts(const SmoothedPiece& piece, const std::vector<double>& otherPath, const double* otherCurve,
  std::size_t curveCount, std::vector<char>& contact)
{
  const auto nearAny = [](const double* x, const double* points, std::size_t count, double reach) {
    for (std::size_t j = 0; j < count; ++j)
    {
      const double dx = points[2 * j] - x[0], dy = points[2 * j + 1] - x[1];
      if (dx * dx + dy * dy < reach * reach)
      {
        return true;
      }
    }
    return false;
  };
  std::vector<double> near;
  const std::size_t count = piece.Values.size();
  for (std::size_t i = 0; i < count; ++i)
  {
    contact[i] = contact[i] || nearAny(&piece.Points[2 * i], otherPath.data(), otherPath.size() / 2, ContactPathReach);
    double xy[2];
    piece.Curve.Evaluate(piece.Parameters[i], xy);
    if (nearAny(xy, otherCurve, curveCount, ContactCurveReach))
    {
      near.push_back(piece.Parameters[i]);
    }
  }
  const double reach = 1.0 / piece.Segments;
  for (std::size_t i = 0, h = 0; i < count && !near.empty(); ++i)
  {
    while (h + 1 < near.size() && near[h] < piece.Parameters[i] - reach)
    {
      ++h;
    }
    contact[i] = contact[i] || std::abs(near[h] - piece.Parameters[i]) <= reach;
  }
}

// The positions (x y pairs) of the nodes within `reach` of the bounding box of a piece's path
// and control points, but for its own ends.
std::vector<double> NodesNear(const SmoothedPiece& piece, const std::vector<SmoothingNode>& nodes, double reach)
{
  double box[4] = { 1e300, -1e300, 1e300, -1e300 };
  for (const std::vector<double>* points : { &piece.Points, &piece.Curve.ControlPoints })
  {
    for (std::size_t i = 0; i + 1 < points->size(); i += 2)
    {
      box[0] = std::min(box[0], (*points)[i]);
      box[1] = std::max(box[1], (*points)[i]);
      box[2] = std::min(box[2], (*points)[i + 1]);
      box[3] = std::max(box[3], (*points)[i + 1]);
    }
  }
  const double* ends[2] = { nodes[piece.StartNode].Position, nodes[piece.EndNode].Position };
  std::vector<double> near;
  for (const SmoothingNode& node : nodes)
  {
    const double* x = node.Position;
    if (x[0] >= box[0] - reach && x[0] <= box[1] + reach && x[1] >= box[2] - reach && x[1] <= box[3] + reach &&
      !(x[0] == ends[0][0] && x[1] == ends[0][1]) && !(x[0] == ends[1][0] && x[1] == ends[1][1]))
    {
      near.insert(near.end(), { x[0], x[1] });
    }
  }
  return near;
}

// A crossing piece during RepairCrossings: its segments before its first raise, the density
// of its knots on its contacts (segments per unit of its whole parameter range), its path
// samples near other pieces or nodes and the pieces it crossed (both accumulated over the
// repair's rounds), and whether it went back to even knots.
struct PieceContacts
{
  int BaseSegments = 0;
  double Density = 0;
  std::vector<char> Near;
  std::set<Index> Partners; // the pieces it crossed (InvalidIndex: a node)
  bool Even = false;        // back to even knots for good
};

// Parameters of a crossing piece about to get `segments` segments (see PieceContacts): arc
// length, but the edges with a sample in contact (see MarkContacts) weigh more, so that the
// contacts get ContactDensityGrowth times the density of knots they had (at most one segment
// per edge in contact) and the rest of the piece what is left, never less than the density it
// had before the repair. The curve then follows its path where another piece or a node comes
// near, and stays as smooth elsewhere: raising k evenly took a msh_crater piece of 300
// samples to 256 segments for two contacts, and the 2-cell beside it past the grids stage 4
// fits. (All of the new knots on the contacts at once made the curve follow a staircase
// there, which crossed the smooth pieces meeting it at its node: Shepard seed 5, 150^2.)
// Plain arc length where no edge, or every edge, is in contact, or where the contacts would
// get no more than an even share.
std::vector<double> ArcLengthWithContacts(const std::vector<double>& points, int segments, PieceContacts& contacts)
{
  std::vector<double> parameters = MonotoneBSplineFit::NormalizedArcLength(points);
  const std::size_t count = parameters.size();
  const std::vector<char>& near = contacts.Near;
  const auto inContact = [&near](std::size_t i) { return near[i - 1] || near[i]; };
  double length = 0;
  std::size_t edges = 0;
  for (std::size_t i = 1; i < count; ++i)
  {
    length += inContact(i) ? parameters[i] - parameters[i - 1] : 0;
    edges += inContact(i) ? 1 : 0;
  }
  if (!(length > 0) || !(length < 1))
  {
    return parameters;
  }
  // Knots on the contacts: segments per unit of the whole piece's parameter, times length.
  const double onContacts = std::min({ ContactDensityGrowth * contacts.Density * length, static_cast<double>(edges),
    segments - contacts.BaseSegments * (1.0 - length) });
  const double share = onContacts / segments;
  if (share <= length)
  {
    contacts.Density = segments;
    return parameters;
  }
  contacts.Density = onContacts / length;
  const double weight = share * (1.0 - length) / ((1.0 - share) * length);
  std::vector<double> warped(count, 0.0);
  for (std::size_t i = 1; i < count; ++i)
  {
    warped[i] = warped[i - 1] + (parameters[i] - parameters[i - 1]) * (inContact(i) ? weight : 1.0);
  }
  for (std::size_t i = 1; i + 1 < count; ++i)
  {
    warped[i] /= warped.back();
  }
  warped.back() = 1.0;
  return warped;
}
} // namespace

namespace
{
// How much farther from its path a curve with knots that follow the rise may run than with
// knots uniform in arc length (crossings it causes are repaired: RepairCrossings first gives
// the pieces involved uniform knots again).
constexpr double RiseCurveSlack = 2.5;

// Knots follow the rise with RiseRatios only on pieces with this many samples per segment:
// with fewer the least-squares curve nearly interpolates the samples, and uneven parameters
// make it hook (straight pieces excepted; the others try SparseRiseRatios: see FitPiece).
constexpr int RiseSamplesPerSegment = 3;

// Whether `samples` samples give `segments` segments fewer than `perSegment` each.
bool FewSamplesPerSegment(std::size_t samples, int segments, int perSegment = RiseSamplesPerSegment)
{
  return samples < static_cast<std::size_t>(perSegment * segments + 1);
}

// A piece whose height misses by more than this times HeightTolerance may be refined up to
// twice MaximumHeightSegments (RefineMissedHeights).
constexpr double SevereMissFactor = 2;

// The grids stage 4 will give the 2-cells beside a piece (AssembleTwoCellSides, then
// ChooseGridLayout: the smallest count all four sides reach by whole multiples of their pieces'
// counts), asked before a piece is refined on its height alone. A cell's grid may change only to
// a multiple of itself that its own refinement could choose (TwoCellReconstruction::
// GridHasSamplesFor: 4 samples per grid cell). A grid that grows past what a cell's samples
// carry costs the cell its fit: short pieces doubled on a ttk_happi crop at 2 % took its
// largest grid from 30 to 56 and a cell from 12 to 19 % of the range off. A grid that is not a
// multiple does not hold the coarser fit: from 16 to 20 a Maunga Whau crop's largest cell at 2 %
// went from 1.0 to 1.6 % RMS. A count can also shrink a grid where a cell with three corners has
// a side cut in its middle (9 -> 6 on stress seed 97 #299, a cell's RMS 3.1 -> 7.4 %), and stage
// 4 may fall back on another cut of such sides: on #182 (a msh_crater crop at 1 %) a cell with
// two of them got a grid of 40 where the first cut gives 8, lost its fit and went from 0.7 to
// 2.2 % of the range RMS. Such cells are left as they are.
class CellGrids
{
public:
  CellGrids(const MorseSmaleComplex& complex, const OneCellSmoothingResult& result)
    : Complex(complex)
    , Result(result)
    , CellsOfOneCell(result.PiecesOfOneCell.size())
  {
    for (std::size_t c = 0; c < complex.TwoCells.size(); ++c)
    {
      for (const Index o : complex.TwoCells[c].BoundaryOneCells)
      {
        if (o >= 0 && o < static_cast<Index>(this->CellsOfOneCell.size()))
        {
          this->CellsOfOneCell[o].push_back(static_cast<Index>(c));
        }
      }
    }
  }

  // Whether `piece` may have `segments` segments, every other piece q count(q).
  bool KeepGrids(Index piece, int segments, const std::function<int(Index)>& count) const
  {
    for (const Index o : this->Result.Pieces[piece].OneCells)
    {
      for (const Index c : this->CellsOfOneCell[o])
      {
        const TwoCellSides* assembled = this->SidesOf(c);
        if (!assembled)
        {
          return false;
        }
        const TwoCellSides& sides = *assembled;
        std::array<std::vector<int>, 4> multipliers;
        const int before = ChooseGridLayout(TwoCellSideCounts(sides, count), this->Stage4.MaximumGridSize, multipliers);
        const int after = ChooseGridLayout(
          TwoCellSideCounts(sides, [&](Index q) { return q == piece ? segments : count(q); }),
          this->Stage4.MaximumGridSize, multipliers);
        const auto samples = static_cast<std::size_t>(this->Complex.TwoCells[c].NumberOfVertices);
        if (after == 0 || before == 0 ||
          (after != before && (after % before != 0 || !this->Stage4.GridHasSamplesFor(after, samples))))
        {
          return false;
        }
      }
    }
    return true;
  }

  // Whether a 2-cell beside `piece` has, with every piece q at count(q) segments, a grid that
  // stage 4 fits (TwoCellReconstruction::MaximumFittedGridSize). A cell left alone by SidesOf
  // counts as one.
  bool BesideAFittedCell(Index piece, const std::function<int(Index)>& count) const
  {
    for (const Index o : this->Result.Pieces[piece].OneCells)
    {
      for (const Index c : this->CellsOfOneCell[o])
      {
        const TwoCellSides* sides = this->SidesOf(c);
        std::array<std::vector<int>, 4> multipliers;
        const int grid =
          sides ? ChooseGridLayout(TwoCellSideCounts(*sides, count), this->Stage4.MaximumGridSize, multipliers) : 0;
        if (!sides || (grid > 0 && grid <= this->Stage4.MaximumFittedGridSize))
        {
          return true;
        }
      }
    }
    return false;
  }

private:
  // The cell's sides, assembled once per cell (the refinement changes counts and curves, not
  // which pieces bound a cell); null where the guard leaves the cell alone: sides that do not
  // assemble, or a cell with three corners, where stage 4 cuts a side in two and may fall back
  // on other cuts, whose grids differ (a msh_crater crop's cell with two such sides got 40 where
  // the first cut gives 8).
  const TwoCellSides* SidesOf(Index c) const
  {
    auto [entry, added] = this->Sides.try_emplace(c);
    if (added)
    {
      TwoCellSides sides;
      std::string ignored;
      if (AssembleTwoCellSides(this->Complex.TwoCells[c], this->Result, sides, ignored) && sides.SplitSides[0] < 0 &&
        sides.SplitSides[1] < 0)
      {
        entry->second = std::make_unique<TwoCellSides>(std::move(sides));
      }
    }
    return entry->second.get();
  }

  const MorseSmaleComplex& Complex;
  const OneCellSmoothingResult& Result;
  std::vector<std::vector<Index>> CellsOfOneCell;
  mutable std::unordered_map<Index, std::unique_ptr<TwoCellSides>> Sides; // SidesOf; one thread asks
  const TwoCellReconstruction Stage4; // its grid limits (the filter keeps the defaults)
};

// How much the rise may count per unit of length, tried in turn (see ArcLengthAndRise): the
// fit with the best height (BetterHeight) is kept.
const std::vector<double> RiseRatios = { 3, 10 };
// On a straight path with fewer than RiseSamplesPerSegment samples per segment also gentler
// ones: there the curve must advance along the line (FitStraightCurve), and with few samples
// the least-squares curve for a steep rise does not (a boundary piece of six samples that rises
// by 64 % of its rise in its first edge: ratio 3 makes its curve turn back, and the parameters
// FitStraightCurve then reads off the pooled curve miss by 0.56 of the rise where ratio 2 keeps
// the curve advancing and misses by 0.07).
const std::vector<double> StraightRiseRatios = { 1, 2, 3, 10 };
// On a path that is not straight, with fewer than RiseSamplesPerSegment samples per segment
// but at least SparseRiseSamplesPerSegment, only the gentle ones: steeper ratios make the
// least-squares curve hook between the samples (a ten-sample valley piece of Shepard seed 14
// at 5 % that climbs 64 % of its rise in its first edge: ratio 3 runs 1.2 spacings off the path
// and backs up 2, ratio 1 stays within 0.40 like even knots and misses the data by 0.071
// instead of 0.127), and the path check in FitPiece decides. With fewer samples still (three
// on two segments) even gentle ratios bent curves on 40² noise into contacts that the crossing
// check's 8 samples per segment missed and 32 found.
const std::vector<double> SparseRiseRatios = { 1, 2 };
constexpr int SparseRiseSamplesPerSegment = 2;
// And only where knots uniform in arc length miss the samples by more than this times
// HeightTolerance: a gentler miss gained little, and the curve the gentle knots move changed the
// surface beside it (Shepard seeds 20, 27, 36 at 5 % rose by 0.12-0.25 eps with every sparse
// piece tried; seed 16 at 25 % by 0.19 points of RMS).
constexpr double SparseRiseTrigger = 0.5;

// Whether a planar curve stays inside the domain by ClampCurveIntoDomain's margin: its
// coefficients do (the Bezier control points are convex combinations of them). A curve that
// had to be clamped runs along the boundary a hair's breadth from it and touches the
// boundary 1-cells: the 2-cells between them are not simple.
bool InsideDomain(const UniformQuadraticBSpline& curve, const std::vector<double>& points, const double bounds[4])
{
  const double margin = ClampingMargin(points);
  const auto& c = curve.Coefficients;
  for (std::size_t j = 2; j + 2 < c.size(); j += 2)
  {
    if (!(c[j] >= bounds[0] + margin && c[j] <= bounds[1] - margin && c[j + 1] >= bounds[2] + margin &&
          c[j + 1] <= bounds[3] - margin))
    {
      return false;
    }
  }
  return true;
}

// The largest miss decides: it is what the carving copies onto the vertices (the L1 error
// chose about the same).
bool BetterHeight(const HeightFit& candidate, const HeightFit& best)
{
  return candidate.MaximumError < best.MaximumError;
}

// All points on the line through the first and the last (to rounding).
bool IsStraight(const std::vector<double>& points)
{
  const std::size_t count = points.size() / 2;
  if (count < 3)
  {
    return true;
  }
  const double* a = &points[0];
  const double* b = &points[2 * (count - 1)];
  const double length = std::hypot(b[0] - a[0], b[1] - a[1]);
  for (std::size_t i = 1; i + 1 < count; ++i)
  {
    if (std::abs(Orientation2D(a, b, &points[2 * i])) > 1e-12 * length * (length + 1))
    {
      return false;
    }
  }
  return length > 0;
}

// The planar curve along a straight path (along the domain's boundary) for parameters that are
// not its arc length: the least-squares curve, put exactly on the line, with coefficients that
// advance strictly along the chord, which makes the curve advance strictly too (its derivative
// is a positive combination of their differences). A curve that overshoots along the line and
// comes back touches itself, and one that stops closes a 2-cell with a spike. Where the
// least-squares coefficients do not advance (parameters that follow a steep rise crowd a few
// path steps into a whole segment, and a quadratic cannot turn that sharply), their positions
// along the chord are made to advance (the closest non-decreasing sequence, then a small strict
// gap). There, and on pieces with fewer than RiseSamplesPerSegment samples per segment, each
// sample gets the parameter at which the curve passes through it (the curve advances, so there
// is one), so the height fitted at those parameters stays where its samples are: with few
// samples per segment the least-squares curve passes far from them (a boundary piece of six
// samples on four segments). With more it passes near them, and the parameters asked for are
// kept: moving them there too (a terrace's piece of 13 samples missed a cliff by 3 eps where
// its curve passed, 1.75 eps with them moved) changes which pieces the height refinement
// raises, and with them stage 4's grids: a Saint Helens crop at 5 % went from 1.03 to 2.03
// eps, its largest cell's grid 16 -> 12 (docs/Reconstruction.md, "Short boundary pieces that
// follow a cliff"). The parameters still crowd where the path rises, as the least-squares curve
// does.
bool FitStraightCurve(const MonotoneBSplineFit& fitter, std::vector<double>& parameters,
  const std::vector<double>& points, PlanarCurveFit& curve)
{
  std::string ignored;
  if (!fitter.FitPlanarCurve(parameters, points, curve, ignored))
  {
    return false;
  }
  const double* a = &points[0];
  const double* b = &points[points.size() - 2];
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double length2 = dx * dx + dy * dy;
  std::vector<double>& c = curve.Spline.Coefficients;
  const std::size_t count = c.size() / 2;
  if (count < 2 || !(length2 > 0))
  {
    return false;
  }
  // Positions along the chord, 0 and 1 at the ends.
  std::vector<double> along(count, 0.0);
  bool advancing = true;
  for (std::size_t j = 1; j + 1 < count; ++j)
  {
    along[j] = ((c[2 * j] - a[0]) * dx + (c[2 * j + 1] - a[1]) * dy) / length2;
    advancing = advancing && along[j] > along[j - 1] && along[j] < 1;
  }
  along[count - 1] = 1;
  if (!advancing)
  {
    // Pool adjacent violators over the inner positions, then a strict gap inside (0, 1).
    std::vector<std::pair<double, int>> blocks; // mean, size
    for (std::size_t j = 1; j + 1 < count; ++j)
    {
      blocks.push_back({ along[j], 1 });
      while (blocks.size() > 1 && blocks[blocks.size() - 2].first >= blocks.back().first)
      {
        const auto last = blocks.back();
        blocks.pop_back();
        auto& merged = blocks.back();
        merged.first = (merged.first * merged.second + last.first * last.second) / (merged.second + last.second);
        merged.second += last.second;
      }
    }
    std::size_t j = 1;
    for (const auto& block : blocks)
    {
      for (int k = 0; k < block.second; ++k)
      {
        along[j++] = block.first;
      }
    }
    const double gap = 1e-3 / static_cast<double>(count);
    for (std::size_t k = 1; k + 1 < count; ++k)
    {
      along[k] = std::clamp(along[k], along[k - 1] + gap, 1 - static_cast<double>(count - 1 - k) * gap);
    }
  }
  for (std::size_t j = 1; j + 1 < count; ++j)
  {
    c[2 * j] = a[0] + along[j] * dx;
    c[2 * j + 1] = a[1] + along[j] * dy;
  }
  if (advancing && !FewSamplesPerSegment(parameters.size(), fitter.Segments))
  {
    return true;
  }
  // Bisection on the curve's position along the chord.
  const auto positionAt = [&](double t) {
    double xy[2];
    curve.Spline.Evaluate(t, xy);
    return ((xy[0] - a[0]) * dx + (xy[1] - a[1]) * dy) / length2;
  };
  double previous = 0;
  for (std::size_t i = 1; i + 1 < parameters.size(); ++i)
  {
    const double target = ((points[2 * i] - a[0]) * dx + (points[2 * i + 1] - a[1]) * dy) / length2;
    double lo = previous, hi = 1;
    for (int step = 0; step < 60 && hi - lo > 1e-15; ++step)
    {
      const double mid = 0.5 * (lo + hi);
      (positionAt(mid) < target ? lo : hi) = mid;
    }
    parameters[i] = previous = std::max(previous, 0.5 * (lo + hi));
  }
  return true;
}

// How far a planar curve strays from the path it was fitted to, at `perSegment` parameters
// per segment: the largest distance to the path (to its edges whose parameters lie within a
// segment's span), and the largest backtrack, how far the nearest path position falls behind
// the farthest one reached before (a curve that overshoots along a straight path and comes
// back touches itself, and its 2-cells are not simple).
struct PathDeviation
{
  double Distance = 0;
  double Backtrack = 0;
};

PathDeviation DeviationFromPath(const UniformQuadraticBSpline& curve, const std::vector<double>& parameters,
  const std::vector<double>& points, int perSegment)
{
  PathDeviation deviation;
  const std::size_t count = parameters.size();
  std::vector<double> along(count, 0.0);
  for (std::size_t i = 1; i < count; ++i)
  {
    along[i] = along[i - 1] + std::hypot(points[2 * i] - points[2 * i - 2], points[2 * i + 1] - points[2 * i - 1]);
  }
  const int samples = std::max(1, curve.Segments * perSegment);
  const double window = 1.0 / std::max(1, curve.Segments);
  double reached = 0;
  std::size_t first = 0;
  for (int q = 0; q <= samples; ++q)
  {
    const double t = static_cast<double>(q) / samples;
    double xy[2];
    curve.Evaluate(t, xy);
    while (first + 1 < count && parameters[first + 1] < t - window)
    {
      ++first;
    }
    double nearest = std::numeric_limits<double>::infinity(), position = reached;
    for (std::size_t i = first; i + 1 < count && parameters[i] <= t + window; ++i)
    {
      double fraction;
      const double d2 = SegmentDistance2(&points[2 * i], &points[2 * i + 2], xy[0], xy[1], fraction);
      if (d2 < nearest)
      {
        nearest = d2;
        position = along[i] + fraction * (along[i + 1] - along[i]);
      }
    }
    if (std::isfinite(nearest))
    {
      deviation.Distance = std::max(deviation.Distance, std::sqrt(nearest));
      deviation.Backtrack = std::max(deviation.Backtrack, reached - position);
      reached = std::max(reached, position);
    }
  }
  return deviation;
}
// A piece's height and its fits' errors, with `segments` segments (its curve is set apart).
void KeepHeight(SmoothedPiece& piece, int segments, const HeightFit& height, const HeightFit& free)
{
  piece.Segments = segments;
  piece.Height = height.Spline.ToCubicBezier();
  piece.L1Error = height.L1Error;
  piece.LargestMiss = height.MaximumError;
  piece.UnconstrainedL1Error = free.L1Error;
}
} // namespace

template <class Spline>
bool OneCellSmoothing::SampledAlongCurve(const SmoothedPiece& piece, const Spline& curve, std::vector<double>& values) const
{
  values = piece.Values;
  for (std::size_t i = 1; i + 1 < values.size(); ++i)
  {
    double xy[2];
    curve.Evaluate(piece.Parameters[i], xy);
    if (!this->FieldAt(xy[0], xy[1], values[i]))
    {
      return false;
    }
  }
  return true;
}

// Paper, section 4, steps 2 and 3 for one piece: a strictly increasing height (and the
// unconstrained one, for comparison) and a planar curve, both as k cubic Beziers.
bool OneCellSmoothing::FitPiece(SmoothedPiece& piece, const std::vector<SmoothingNode>& nodes, int segments,
  const double bounds[4], std::string& error) const
{
  const double a = nodes[piece.StartNode].Value, b = nodes[piece.EndNode].Value;
  MonotoneBSplineFit fitter;
  fitter.Segments = segments;
  PlanarCurveFit curve;
  HeightFit height, free;
  const bool firstFit = piece.Parameters.size() != piece.Values.size();
  piece.HeightAlongCurve = false;
  if (firstFit)
  {
    piece.Parameters = MonotoneBSplineFit::NormalizedArcLength(piece.Points);
    piece.RiseRatios.clear();
  }
  // A refit (more segments) of a straight piece with rise knots keeps its curve on the line,
  // or goes back to arc length (see FitStraightCurve).
  bool curveFitted = false;
  if (!firstFit && piece.RiseKnots() && IsStraight(piece.Points))
  {
    curveFitted = FitStraightCurve(fitter, piece.Parameters, piece.Points, curve);
    if (!curveFitted)
    {
      piece.Parameters = MonotoneBSplineFit::NormalizedArcLength(piece.Points);
      piece.RiseRatios.clear();
    }
  }
  if ((!curveFitted && !fitter.FitPlanarCurve(piece.Parameters, piece.Points, curve, error)) ||
    !fitter.FitHeight(piece.Parameters, piece.Values, a, b, true, height, error))
  {
    return false;
  }
  // Any piece with an interior sample may follow its rise. With fewer than
  // RiseSamplesPerSegment samples per segment the least-squares curve could hook between them:
  // a straight path (a side of the domain) has no such curve (FitStraightCurve; a short
  // boundary piece that falls by nearly its whole rise in its first edge, next to a node where
  // its height starts flat: 8 eps on a ttk_happi crop at 2 %, four segments on six edges), and
  // other paths try the gentle SparseRiseRatios only.
  const bool straight = IsStraight(piece.Points);
  const bool sparse = FewSamplesPerSegment(piece.Values.size(), segments);
  if (firstFit && piece.Values.size() >= 3)
  {
    // Knots that follow the rise as well as the length (for each of RiseRatios), kept where
    // the height then misses the samples by less (a valley that falls steeply and flattens:
    // uniform knots put one of k = 4 segments on the fall) and the planar curve still follows
    // the path: within RiseCurveTolerance or RiseCurveSlack times as far as with arc length,
    // backtracking no more, and inside the domain by the clamping margin where the arc-length
    // curve is (a curve whose speed follows the heights bulges on long flat stretches, and
    // bulges cross: see RepairCrossings). On a straight path the curve runs along the line
    // (FitStraightCurve).
    const int perSegment = this->SamplesPerSegment;
    const PathDeviation even =
      straight ? PathDeviation() : DeviationFromPath(curve.Spline, piece.Parameters, piece.Points, perSegment);
    const bool evenInside = straight || InsideDomain(curve.Spline, piece.Points, bounds);
    const std::vector<double> none;
    const bool gentle = !FewSamplesPerSegment(piece.Values.size(), segments, SparseRiseSamplesPerSegment) &&
      (this->HeightTolerance <= 0 || height.MaximumError > SparseRiseTrigger * this->HeightTolerance);
    for (const double ratio : !sparse ? RiseRatios
           : straight                 ? StraightRiseRatios
           : gentle                   ? SparseRiseRatios
                                      : none)
    {
      std::vector<double> rise = MonotoneBSplineFit::ArcLengthAndRise(piece.Points, piece.Values, a, b, ratio);
      PlanarCurveFit riseCurve;
      HeightFit riseHeight;
      std::string ignored;
      const auto followsPath = [&]() {
        const PathDeviation risen = DeviationFromPath(riseCurve.Spline, rise, piece.Points, perSegment);
        return risen.Distance <= std::max(RiseCurveSlack * even.Distance, this->RiseCurveTolerance) &&
          risen.Backtrack <= std::max(even.Backtrack, this->RiseCurveTolerance) &&
          (InsideDomain(riseCurve.Spline, piece.Points, bounds) || !evenInside);
      };
      if (rise != piece.Parameters &&
        (straight ? FitStraightCurve(fitter, rise, piece.Points, riseCurve)
                  : fitter.FitPlanarCurve(rise, piece.Points, riseCurve, ignored) && followsPath()) &&
        fitter.FitHeight(rise, piece.Values, a, b, true, riseHeight, ignored) &&
        BetterHeight(riseHeight, height))
      {
        piece.Parameters = std::move(rise);
        piece.RiseRatios.push_back(ratio);
        curve = std::move(riseCurve);
        height = std::move(riseHeight);
      }
    }
  }
  // The surface passes through the curve, not through the jagged path; where the curve cuts
  // across a slope the path climbs (a staircase round a peak), the field along the curve
  // differs from the path's at the same parameter, and a height fitted to the path misses it
  // by several times the threshold (Shepard field, seed 12, 5 %: 2.85 eps next to a maximum).
  // There the height is fitted to the field sampled along the curve instead. Elsewhere the
  // path's fit stays: the field along a curve that follows its path tells nothing new, and
  // a different miss would change which pieces get refined or refitted.
  std::vector<double> alongCurve;
  const std::vector<double>* fitted = &piece.Values;
  if (this->FieldAt && this->SampledAlongCurve(piece, curve.Spline, alongCurve))
  {
    const double margin = this->HeightTolerance > 0 ? 0.5 * this->HeightTolerance : 0.05 * (b - a);
    HeightFit pathHeight = height;
    MonotoneBSplineFit::MeasureHeightErrors(piece.Parameters, alongCurve, pathHeight);
    const double pathMiss = pathHeight.MaximumError;
    HeightFit curveHeight;
    std::string ignored;
    if (pathMiss > height.MaximumError + margin &&
      fitter.FitHeight(piece.Parameters, alongCurve, a, b, true, curveHeight, ignored) &&
      curveHeight.MaximumError < pathMiss)
    {
      height = std::move(curveHeight);
      fitted = &alongCurve;
      piece.HeightAlongCurve = true;
    }
  }
  if (!fitter.FitHeight(piece.Parameters, *fitted, a, b, false, free, error))
  {
    return false;
  }
  piece.Curve = curve.Spline.ToCubicBezier();
  ClampCurveIntoDomain(piece, bounds);
  KeepHeight(piece, segments, height, free);
  return true;
}

bool OneCellSmoothing::RefitHeightOnCurve(
  SmoothedPiece& piece, const std::vector<SmoothingNode>& nodes, int segments, std::string& error) const
{
  // The height is fitted to what it was fitted to before: the field along the curve where
  // FitPiece chose it (the curve is the same), else the path's samples.
  std::vector<double> alongCurve;
  piece.HeightAlongCurve = piece.HeightAlongCurve && this->FieldAt && this->SampledAlongCurve(piece, piece.Curve, alongCurve);
  const std::vector<double>& fitted = piece.HeightAlongCurve ? alongCurve : piece.Values;
  const double a = nodes[piece.StartNode].Value, b = nodes[piece.EndNode].Value;
  if (piece.Segments <= 0 || segments % piece.Segments != 0)
  {
    error = "a height refitted on its curve needs a multiple of the curve's segments";
    return false;
  }
  MonotoneBSplineFit fitter;
  fitter.Segments = segments;
  HeightFit height, free;
  if (!fitter.FitHeight(piece.Parameters, fitted, a, b, true, height, error) ||
    !fitter.FitHeight(piece.Parameters, fitted, a, b, false, free, error))
  {
    return false;
  }
  piece.Curve = piece.Curve.SplitEvenly(segments / piece.Segments);
  KeepHeight(piece, segments, height, free);
  return true;
}

//------------------------------------------------------------------------------
bool OneCellSmoothing::CutAndSolveJunctionValues(const MorseSmaleComplex& complex,
  const std::vector<JunctionPoint>& junctions, const std::vector<Index>& junctionNode, const double domainBounds[4],
  const std::vector<double>& boundaryPoints, OneCellSmoothingResult& result, std::string& error) const
{
  // Every 1-cell is cut at every node it passes, except where the cuts would order nodes in a
  // cycle (see RankNodes).
  result.Pieces.clear();
  result.PiecesOfOneCell.clear();
  // The 1-cells as cut: the complex's own, or a copy with its retraced loops erased.
  std::vector<const OneCell*> oneCells(complex.OneCells.size());
  std::vector<std::unique_ptr<OneCell>> trimmed(complex.OneCells.size());
  result.ErasedLoops = 0;
  for (std::size_t a = 0; a < oneCells.size(); ++a)
  {
    oneCells[a] = &complex.OneCells[a];
    if (!RepeatsAPoint(complex.OneCells[a]))
    {
      continue;
    }
    auto copy = std::make_unique<OneCell>(complex.OneCells[a]);
    const int erased = EraseRetracedLoops(*copy);
    if (erased > 0)
    {
      result.ErasedLoops += erased;
      trimmed[a] = std::move(copy);
      oneCells[a] = trimmed[a].get();
    }
  }
  CutIntoPieces(oneCells, junctions, junctionNode, domainBounds, boundaryPoints, result.Nodes, result);
  this->Hooks.Report(0.1);
  JunctionValueProgram program;
  program.Parallel = this->Parallel;
  if (!SolveJunctionValues(result.Nodes, result, program, error))
  {
    error = "junction values: " + error;
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool OneCellSmoothing::FitAllPieces(const MorseSmaleComplex& complex,
  OneCellSmoothingResult& result, const double domainBounds[4], std::string& error) const
{
  // In chunks between which progress is reported and an abort is seen (from this thread only).
  const Index count = static_cast<Index>(result.Pieces.size());
  const Index chunk = std::max<Index>(256, count / 16);
  for (Index first = 0; first < count; first += chunk)
  {
    const Index last = std::min(count, first + chunk);
    std::vector<Index> pieces(static_cast<std::size_t>(last - first));
    std::iota(pieces.begin(), pieces.end(), first);
    if (!this->FitInParallel(result, pieces,
          [this](const SmoothedPiece& piece) { return SegmentsOfPiece(piece, this->Segments); }, domainBounds,
          error))
    {
      return false;
    }
    for (Index p = first; p < last; ++p)
    {
      result.ShortPieces += result.Pieces[p].Segments < this->Segments ? 1 : 0;
    }
    this->Hooks.Report(0.2 + 0.5 * static_cast<double>(last) / count);
    if (this->Hooks.Aborted())
    {
      error = "aborted";
      return false;
    }
  }
  std::vector<int> edges(result.Pieces.size());
  std::transform(result.Pieces.begin(), result.Pieces.end(), edges.begin(), EdgesOf);
  result.SuggestedSegments = SuggestCurveSegments(edges, this->Segments, &result.OversegmentedPieces);
  std::vector<Index> all(static_cast<std::size_t>(count));
  std::iota(all.begin(), all.end(), 0);
  return this->RefineMissedHeights(complex, result, std::move(all), domainBounds, error);
}

bool OneCellSmoothing::RefineMissedHeights(const MorseSmaleComplex& complex, OneCellSmoothingResult& result,
  std::vector<Index> pieces, const double domainBounds[4], std::string& error) const
{
  // Pieces whose height misses a sample by more than the simplification's threshold get twice
  // their segments (twice at most): the user simplifies to remove features smaller than that,
  // not to move the 1-cells off the data by more (a long valley of the Shepard field that falls
  // steeply then flattens still missed its samples by 10 % of the range with knots that follow
  // the rise). Pieces that miss by more than twice the threshold may go to twice the cap (a
  // valley that climbs 430 m into its saddle in its last 13 of 321 samples, Saint Helens crop at
  // 5 %: 4.3 eps at 8 segments) where every 1-cell through them keeps at most
  // MaximumSideSegments: each 1-cell is a side of the 2-cells it bounds, and stage 4 fits a
  // cell's interior only on grids up to its limit, which the sides' segments push up (without
  // this, on a Rainier crop at 0.5 %, k = 10, a cell kept the paper's interior and missed by
  // 12.7 % of the range instead of 1.6 %).
  std::unordered_map<Index, int> planned; // this round's raised counts
  const auto count = [&](Index q) {
    const auto raise = planned.find(q);
    return raise != planned.end() ? raise->second : result.Pieces[q].Segments;
  };
  const auto sidesAllow = [&](const SmoothedPiece& piece, Index p, int raised) {
    for (const Index o : piece.OneCells)
    {
      int sum = 0;
      for (const Index q : result.PiecesOfOneCell[o])
      {
        sum += q == p ? raised : count(q);
      }
      if (sum > this->MaximumSideSegments)
      {
        return false;
      }
    }
    return true;
  };
  // A curve of more segments needs about 3 samples per segment (with fewer the least-squares
  // curve hooks between them); a piece with fewer keeps its curve, cut evenly, where the new
  // count is a multiple of the old, and at least one sample per segment, and only its height gets
  // the segments (where no cell's grid changes but as CellGrids allows). A valley of 21 samples
  // leaves a minimum at 0.069 with 0.108 and 0.202 beside it (Shepard seed 13 at 5 %): a height
  // starts with zero slope, and at k = 4 it missed by 1.8 eps, at 8 by 0.5 (the
  // reconstruction's largest error 2.0 -> 1.3 eps).
  std::unique_ptr<CellGrids> cellGrids; // made for the first piece refined on its curve
  const auto grids = [&]() -> const CellGrids& {
    if (!cellGrids)
    {
      cellGrids = std::make_unique<CellGrids>(complex, result);
    }
    return *cellGrids;
  };
  const auto keepCurve = [this](const SmoothedPiece& piece) {
    return static_cast<int>(piece.Values.size()) <= 3 * RaisedSegments(piece.Segments, this->Segments);
  };
  for (int round = 0; round < 2 && this->HeightTolerance > 0; ++round)
  {
    std::vector<Index> missing;
    planned.clear();
    for (const Index p : pieces)
    {
      const SmoothedPiece& piece = result.Pieces[p];
      const int raised = RaisedSegments(piece.Segments, this->Segments);
      if (piece.LargestMiss <= this->HeightTolerance ||
        (keepCurve(piece) && (raised % piece.Segments != 0 || static_cast<int>(piece.Values.size()) <= raised ||
                               !grids().KeepGrids(p, raised, count))))
      {
        continue;
      }
      if (raised <= this->MaximumHeightSegments ||
        (piece.LargestMiss > SevereMissFactor * this->HeightTolerance && raised <= 2 * this->MaximumHeightSegments &&
          sidesAllow(piece, p, raised)))
      {
        missing.push_back(p);
        planned[p] = raised;
      }
    }
    if (missing.empty())
    {
      break;
    }
    if (!this->FitInParallel(
          result, missing, [this](const SmoothedPiece& piece) { return RaisedSegments(piece.Segments, this->Segments); },
          domainBounds, error, keepCurve))
    {
      return false;
    }
    for (const Index p : missing)
    {
      result.Pieces[p].HeightRefined = true;
    }
    pieces = std::move(missing);
  }
  return true;
}

bool OneCellSmoothing::FitInParallel(OneCellSmoothingResult& result, const std::vector<Index>& pieces,
  const std::function<int(const SmoothedPiece&)>& segmentsOf, const double domainBounds[4], std::string& error,
  const std::function<bool(const SmoothedPiece&)>& keepCurve) const
{
  std::vector<std::string> pieceErrors(pieces.size());
  std::vector<unsigned char> failed(pieces.size(), 0);
  this->Parallel(0, static_cast<Index>(pieces.size()), [&](Index begin, Index end) {
    for (Index i = begin; i < end; ++i)
    {
      SmoothedPiece& piece = result.Pieces[pieces[i]];
      const int segments = segmentsOf(piece);
      failed[i] = keepCurve && keepCurve(piece)
        ? !this->RefitHeightOnCurve(piece, result.Nodes, segments, pieceErrors[i])
        : !this->FitPiece(piece, result.Nodes, segments, domainBounds, pieceErrors[i]);
    }
  });
  for (std::size_t i = 0; i < pieces.size(); ++i)
  {
    if (failed[i])
    {
      error = "1-cell piece " + std::to_string(pieces[i]) + ": " + pieceErrors[i];
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
namespace
{
// Before the pieces in `raise` get more segments (RaisedSegments of their count and `asked`):
// on those with ContactSamplesPerSegment edges per new segment and beside a 2-cell that stage
// 4 fits with the raised counts (besideAFittedCell), the knots crowd where their crossing
// partners in the detector's pairs (a piece with itself: a node) come near, instead of
// spreading evenly (sets ContactKnots; see ArcLengthWithContacts). The partners' curves are
// the detector's samples of them.
void PlaceContactKnots(OneCellSmoothingResult& result, const CrossingDetector& detector, const std::vector<Index>& raise,
  int asked, const std::function<bool(Index)>& besideAFittedCell, std::map<Index, PieceContacts>& contacts)
{
  std::map<Index, std::vector<Index>> partners; // InvalidIndex: a node not its own
  for (const auto& pair : detector.CrossingPairs())
  {
    partners[pair.first].push_back(pair.second == pair.first ? InvalidIndex : pair.second);
    if (pair.second != pair.first)
    {
      partners[pair.second].push_back(pair.first);
    }
  }
  for (Index p : raise)
  {
    SmoothedPiece& piece = result.Pieces[p];
    const int raised = RaisedSegments(piece.Segments, asked);
    // Only on pieces with ContactSamplesPerSegment samples per segment and more: on shorter
    // ones the knots between the contacts are too few to follow the path, and even knots
    // soon reach a segment per edge anyway. And only beside a 2-cell whose grid stage 4 still
    // fits with the round's raised counts: what the crowded knots save is a fitted interior; a
    // cell that keeps the paper's interior follows its boundary, which even knots fit more
    // closely (a Saint Helens crop at 25 %, k = 17, whose three cells got grids of 68 from the
    // raise: 1.31 -> 1.67 eps with crowded knots).
    const bool longPiece = static_cast<int>(piece.Values.size()) - 1 >= ContactSamplesPerSegment * raised;
    const auto found = partners.find(p);
    PieceContacts* contactsOfPiece = nullptr;
    if (longPiece && found != partners.end())
    {
      contactsOfPiece =
        &contacts.emplace(p, PieceContacts{ piece.Segments, static_cast<double>(piece.Segments), {}, {}, false })
           .first->second;
      contactsOfPiece->Even = contactsOfPiece->Even || !besideAFittedCell(p);
    }
    if (contactsOfPiece && !contactsOfPiece->Even)
    {
      contactsOfPiece->Near.resize(piece.Values.size(), 0);
      for (Index q : found->second)
      {
        std::vector<char> near(piece.Values.size(), 0);
        if (q != InvalidIndex)
        {
          std::size_t count;
          const double* curve = detector.Samples(q, count);
          MarkContacts(piece, result.Pieces[q].Points, curve, count, near);
        }
        else
        {
          const std::vector<double> nodes = NodesNear(piece, result.Nodes, ContactPathReach);
          MarkContacts(piece, nodes, nodes.data(), nodes.size() / 2, near);
        }
        // A piece whose crowded knots made it cross a piece or node it did not cross before,
        // away from its contacts, goes back to even knots for good: the sparser knots between
        // its contacts, or the switch between dense and sparse, made it hook there.
        bool touches = false;
        for (std::size_t i = 0; i < near.size(); ++i)
        {
          touches = touches || (near[i] && contactsOfPiece->Near[i]);
          contactsOfPiece->Near[i] = contactsOfPiece->Near[i] || near[i];
        }
        contactsOfPiece->Even = contactsOfPiece->Even ||
          (piece.ContactKnots && !touches && contactsOfPiece->Partners.count(q) == 0);
        contactsOfPiece->Partners.insert(q);
      }
    }
    if (!contactsOfPiece || contactsOfPiece->Even)
    {
      if (piece.ContactKnots)
      {
        piece.Parameters = MonotoneBSplineFit::NormalizedArcLength(piece.Points);
        piece.ContactKnots = false;
      }
      continue;
    }
    std::vector<double> parameters = ArcLengthWithContacts(piece.Points, raised, *contactsOfPiece);
    piece.ContactKnots = piece.ContactKnots || parameters != piece.Parameters;
    piece.Parameters = std::move(parameters);
  }
}
} // namespace

bool OneCellSmoothing::RepairCrossings(const MorseSmaleComplex& complex,
  OneCellSmoothingResult& result, const double domainBounds[4], std::string& error) const
{
  // Where pieces cross, raise their k and fit again, until none cross or no k can rise.
  CrossingDetector detector(result, domainBounds, this->SamplesPerSegment, this->Parallel);
  std::set<Index> crossing;
  int pairs = detector.FindCrossings(crossing);
  std::set<Index> adapted, followsPolyline;
  std::map<Index, PieceContacts> contacts;
  std::unique_ptr<CellGrids> cellGrids; // made for the first raise with crowded knots
  while (pairs > 0)
  {
    // Up to MaximumSegments, or to the piece's number of samples for long pieces: with about
    // one segment per sample the least-squares curve follows the jagged 1-cell, which does
    // not cross the others.
    // A crossing piece whose knots follow its rise first gets gentler ones at the same k: the
    // ratio that bettered its height before the one in use, and then knots uniform in arc
    // length, whose curve runs as evenly as the path. Straight to even knots, a valley piece of
    // ttk_happi at 2 % that climbs 43 % of its rise in the edge off a junction (where a second
    // piece with rise knots starts, and their curves crossed) missed the data there by 0.4 of
    // its rise (the field's largest error, 5.7 eps); stepped down, that error is 3.3 eps.
    std::vector<Index> even;
    for (Index p : crossing)
    {
      SmoothedPiece& piece = result.Pieces[p];
      if (piece.RiseKnots())
      {
        piece.RiseRatios.pop_back();
        piece.Parameters = piece.RiseKnots()
          ? MonotoneBSplineFit::ArcLengthAndRise(piece.Points, piece.Values, result.Nodes[piece.StartNode].Value,
              result.Nodes[piece.EndNode].Value, piece.RiseRatios.back())
          : MonotoneBSplineFit::NormalizedArcLength(piece.Points);
        even.push_back(p);
      }
    }
    if (!even.empty())
    {
      // Uniform knots can miss the heights that the rise knots followed (a ridge that climbs
      // slowly, then steeply: Shepard seed 20 at 5 %, 2.3 times the threshold along 15
      // spacings), so those pieces are refined again as in FitAllPieces.
      if (!this->FitInParallel(
            result, even, [](const SmoothedPiece& piece) { return piece.Segments; }, domainBounds, error) ||
        !this->RefineMissedHeights(complex, result, even, domainBounds, error))
      {
        return false;
      }
      crossing.clear();
      pairs = detector.UpdateCrossings(even, crossing);
      continue;
    }
    // k rises to the next divisor of k or doubles beyond it (RaisedSegments; a cap between
    // would leave counts like 25 and 37, whose common multiples exceed stage 4's grid limit):
    // stage 4 subdivides each piece of the four sides of a cell by a whole factor to one
    // common count.
    std::vector<Index> raise;
    for (Index p : crossing)
    {
      const SmoothedPiece& piece = result.Pieces[p];
      const int cap = std::max(this->MaximumSegments, static_cast<int>(piece.Values.size()) - 1);
      if (piece.Segments < cap && RaisedSegments(piece.Segments, this->Segments) <= MonotoneBSplineFit::MaximumSegments)
      {
        raise.push_back(p);
      }
    }
    if (this->CrowdKnotsAtContacts)
    {
      if (!cellGrids)
      {
        cellGrids = std::make_unique<CellGrids>(complex, result);
      }
      // With every piece of this round at its raised count.
      const std::set<Index> raised(raise.begin(), raise.end());
      const auto besideAFittedCell = [&](Index p) {
        return cellGrids->BesideAFittedCell(p, [&](Index q) {
          const int segments = result.Pieces[q].Segments;
          return raised.count(q) ? RaisedSegments(segments, this->Segments) : segments;
        });
      };
      PlaceContactKnots(result, detector, raise, this->Segments, besideAFittedCell, contacts);
    }
    if (!this->FitInParallel(
          result, raise, [this](const SmoothedPiece& piece) { return RaisedSegments(piece.Segments, this->Segments); },
          domainBounds, error))
    {
      return false;
    }
    adapted.insert(raise.begin(), raise.end());
    std::vector<Index> changed = raise;
    if (changed.empty())
    {
      // No k can rise: the pieces still crossing follow their jagged 1-cells, which never
      // cross (they are V-paths of one discrete gradient), in as many straight segments.
      for (Index p : crossing)
      {
        if (followsPolyline.insert(p).second && FollowPolyline(result.Pieces[p], result.Nodes))
        {
          ++result.PolylinePieces;
          changed.push_back(p);
        }
      }
    }
    if (changed.empty())
    {
      break;
    }
    crossing.clear();
    pairs = detector.UpdateCrossings(changed, crossing);
  }
  result.AdaptedPieces = static_cast<int>(adapted.size());
  result.RefinedPieces = static_cast<int>(std::count_if(result.Pieces.begin(), result.Pieces.end(),
    [](const SmoothedPiece& piece) { return piece.HeightRefined; }));
  result.RiseKnotPieces = static_cast<int>(std::count_if(result.Pieces.begin(), result.Pieces.end(),
    [](const SmoothedPiece& piece) { return piece.RiseKnots(); }));
  result.CurveHeightPieces = static_cast<int>(std::count_if(result.Pieces.begin(), result.Pieces.end(),
    [](const SmoothedPiece& piece) { return piece.HeightAlongCurve; }));
  result.ContactKnotPieces = static_cast<int>(std::count_if(result.Pieces.begin(), result.Pieces.end(),
    [](const SmoothedPiece& piece) { return piece.ContactKnots; }));
  result.RemainingCrossings = pairs;
  return true;
}

//------------------------------------------------------------------------------
std::vector<double> OneCellSmoothing::BoundaryPointsOf(const PlanarScalarField& mesh)
{
  TriangleMeshTopology topology;
  std::string error;
  std::vector<double> points;
  const Index n = static_cast<Index>(mesh.Points.size() / 2);
  if (!topology.Build(n, mesh.Triangles, SequentialFor, error))
  {
    return points;
  }
  for (Index v = 0; v < n; ++v)
  {
    if (topology.IsBoundaryVertex(v))
    {
      points.insert(points.end(), { mesh.Points[2 * v], mesh.Points[2 * v + 1] });
    }
  }
  return points;
}

//------------------------------------------------------------------------------
bool OneCellSmoothing::Smooth(const MorseSmaleComplex& complex, const std::vector<JunctionPoint>& junctions,
  const double domainBounds[4], OneCellSmoothingResult& result, std::string& error) const
{
  const PlanarFrame& frame = complex.Frame;
  if (frame.IsIdentity())
  {
    return this->SmoothInFrame(complex, junctions, domainBounds, this->BoundaryPoints, result, error);
  }
  // The fits, crossings and clamping in the complex's frame (see PlanarFrame); the per-vertex
  // arrays are not needed here.
  MorseSmaleComplex framed;
  framed.CriticalPoints = complex.CriticalPoints;
  framed.OneCells = complex.OneCells;
  framed.TwoCells = complex.TwoCells;
  framed.BoundaryJunctions = complex.BoundaryJunctions;
  GeometryToFrame(frame, framed);
  std::vector<JunctionPoint> framedJunctions = junctions;
  for (JunctionPoint& junction : framedJunctions)
  {
    frame.ToFrame(junction.Position);
  }
  double bounds[4] = { domainBounds[0], domainBounds[1], domainBounds[2], domainBounds[3] };
  frame.BoundsToFrame(bounds);
  std::vector<double> boundaryPoints = this->BoundaryPoints;
  frame.ToFrame(boundaryPoints);
  if (!this->SmoothInFrame(framed, framedJunctions, bounds, boundaryPoints, result, error))
  {
    return false;
  }
  MapSmoothedGeometry(result, [&frame](double* xy) { frame.ToWorld(xy); });
  return true;
}

bool OneCellSmoothing::SmoothInFrame(const MorseSmaleComplex& complex, const std::vector<JunctionPoint>& junctions,
  const double domainBounds[4], const std::vector<double>& boundaryPoints, OneCellSmoothingResult& result,
  std::string& error) const
{
  result = OneCellSmoothingResult();
  if (this->Segments < 2 || this->Segments > MaximumCurveSegments)
  {
    error = "the number of curve segments must be in [2, " + std::to_string(MaximumCurveSegments) +
      "], not " + std::to_string(this->Segments);
    return false;
  }
  if (complex.OneCells.empty())
  {
    error = "the complex has no 1-cells";
    return false;
  }

  // Nodes: every critical point, every junction point, and the domain corners met (added
  // while cutting).
  AddCriticalNodes(complex.CriticalPoints, result.Nodes);
  SeparateTiedCriticalValues(complex.CriticalPoints, result.Nodes);
  const std::vector<Index> junctionNode = AddJunctionNodes(junctions, result.Nodes);

  // Paper, section 4, step 1: the pieces between nodes and the junction values.
  if (!this->CutAndSolveJunctionValues(complex, junctions, junctionNode, domainBounds, boundaryPoints, result, error))
  {
    return false;
  }
  this->Hooks.Report(0.2);
  // Steps 2 and 3: a monotone height and a planar curve on every piece.
  if (!this->FitAllPieces(complex, result, domainBounds, error))
  {
    return false;
  }

  // The smoothed curves must not cross, or the 2-cells of stage 4 would not be simple.
  if (!this->RepairCrossings(complex, result, domainBounds, error))
  {
    return false;
  }
  for (const SmoothedPiece& piece : result.Pieces)
  {
    result.ClampedPieces += piece.Clamped;
  }
  result.PiecesOutsideDomain = CountPiecesOutsideDomain(result.Pieces, domainBounds, this->SamplesPerSegment);
  this->Hooks.Report(1.0);
  return true;
}
} // namespace topospline
