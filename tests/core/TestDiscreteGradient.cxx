// Unit tests of the discrete gradient (DiscreteGradient) on small grids and unstructured
// meshes with random seeded fields, against properties checked independently here: a
// matching of cells inside lower stars, the boundary rule, no closed V-path, and critical
// cells that are the PL critical points of the field, counted from the lower links.
#include "DeterministicRandom.h"
#include "DiscreteGradient.h"
#include "SyntheticFields.h"
#include "TestHarness.h"
#include "TriangleMeshTopology.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <vector>

using namespace topospline;

namespace
{
struct MeshField
{
  std::string Name;
  std::vector<double> Points; // x, y per vertex
  std::vector<Index> Triangles;
  std::vector<double> Values;
};

// An nx x ny grid whose vertices are jittered and whose quads are split along a random
// diagonal: a planar disk that is not the grid triangulation. jitter = 0 and
// randomDiagonals = false give the image-data triangulation (GridTriangles).
MeshField JitteredGrid(int nx, int ny, std::uint64_t seed, double jitter, bool randomDiagonals)
{
  DeterministicRandom random(seed);
  MeshField mesh;
  mesh.Name = "grid " + std::to_string(nx) + "x" + std::to_string(ny) + " seed " + std::to_string(seed);
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i)
    {
      mesh.Points.push_back(i + random.Uniform(-jitter, jitter));
      mesh.Points.push_back(j + random.Uniform(-jitter, jitter));
    }
  }
  if (!randomDiagonals)
  {
    mesh.Triangles = GridTriangles(nx, ny);
    return mesh;
  }
  for (int j = 0; j + 1 < ny; ++j)
  {
    for (int i = 0; i + 1 < nx; ++i)
    {
      const Index a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      if (random.Integer(2) == 0)
      {
        mesh.Triangles.insert(mesh.Triangles.end(), { a, b, c, b, d, c });
      }
      else
      {
        mesh.Triangles.insert(mesh.Triangles.end(), { a, b, d, a, d, c });
      }
    }
  }
  return mesh;
}

// Random values; with `levels` > 0 rounded to that many levels, so that ties are common.
void RandomValues(MeshField& mesh, std::uint64_t seed, int levels)
{
  DeterministicRandom random(seed);
  mesh.Values.resize(mesh.Points.size() / 2);
  for (double& v : mesh.Values)
  {
    v = random.Uniform();
    if (levels > 0)
    {
      v = std::floor(v * levels) / levels;
    }
  }
}

std::vector<MeshField> TestMeshes()
{
  std::vector<MeshField> meshes;
  for (std::uint64_t seed = 1; seed <= 6; ++seed)
  {
    const int n = 4 + static_cast<int>(seed) * 3;
    meshes.push_back(JitteredGrid(n, n + 2, seed, 0.0, false));
    meshes.push_back(JitteredGrid(n + 1, n, 100 + seed, 0.3, true));
  }
  meshes.push_back(JitteredGrid(2, 2, 7, 0.0, false));
  meshes.push_back(JitteredGrid(3, 2, 8, 0.2, true));
  meshes.push_back(JitteredGrid(30, 25, 9, 0.45, true));
  std::vector<MeshField> fields;
  for (const MeshField& mesh : meshes)
  {
    for (int levels : { 0, 3 })
    {
      for (std::uint64_t seed = 1; seed <= 3; ++seed)
      {
        MeshField field = mesh;
        RandomValues(field, 1000 * seed + levels + field.Points.size(), levels);
        field.Name += " values " + std::to_string(seed) + (levels ? " with ties" : "");
        fields.push_back(field);
      }
    }
  }
  return fields;
}

// The order of the gradient: by value, ties by vertex id.
bool Lower(const MeshField& field, Index a, Index b)
{
  return field.Values[a] < field.Values[b] || (field.Values[a] == field.Values[b] && a < b);
}

Index Highest(const MeshField& field, std::initializer_list<Index> vertices)
{
  Index best = *vertices.begin();
  for (Index v : vertices)
  {
    if (Lower(field, best, v))
    {
      best = v;
    }
  }
  return best;
}

// The mesh of a field, checked.
TriangleMeshTopology MeshOf(const MeshField& field)
{
  TriangleMeshTopology mesh;
  std::string error;
  const bool built = mesh.Build(static_cast<Index>(field.Values.size()), field.Triangles, SequentialFor, error);
  CHECK(built);
  return mesh;
}

DiscreteGradient GradientOf(const TriangleMeshTopology& mesh, const MeshField& field)
{
  DiscreteGradient gradient;
  gradient.Compute(mesh, field.Values.data(), SequentialFor);
  return gradient;
}

// Per vertex, the link: its neighbours and the link edges (the edge opposite to it in each
// of its triangles), read from the triangle list.
struct Links
{
  std::vector<std::set<Index>> Neighbours;
  std::vector<std::vector<std::array<Index, 2>>> Edges;
  std::vector<int> Triangles;
  std::vector<std::set<std::array<Index, 2>>> BoundaryEdges; // edges in one triangle only

  explicit Links(const MeshField& field)
    : Neighbours(field.Values.size())
    , Edges(field.Values.size())
    , Triangles(field.Values.size(), 0)
    , BoundaryEdges(field.Values.size())
  {
    std::map<std::array<Index, 2>, int> uses;
    for (size_t t = 0; t < field.Triangles.size(); t += 3)
    {
      for (int k = 0; k < 3; ++k)
      {
        const Index v = field.Triangles[t + k], a = field.Triangles[t + (k + 1) % 3], b = field.Triangles[t + (k + 2) % 3];
        this->Neighbours[v].insert(a);
        this->Neighbours[v].insert(b);
        this->Edges[v].push_back({ a, b });
        ++this->Triangles[v];
        ++uses[{ std::min(v, a), std::max(v, a) }];
      }
    }
    for (const auto& entry : uses)
    {
      if (entry.second == 1)
      {
        this->BoundaryEdges[entry.first[0]].insert(entry.first);
        this->BoundaryEdges[entry.first[1]].insert(entry.first);
      }
    }
  }
  bool OnBoundary(Index v) const { return !this->BoundaryEdges[v].empty(); }
};

// The critical cells of the gradient in the lower star of each vertex (by dimension).
std::vector<std::array<int, 3>> CriticalCellsByOwner(
  const TriangleMeshTopology& mesh, const DiscreteGradient& gradient, const MeshField& field)
{
  std::vector<std::array<int, 3>> count(field.Values.size(), { 0, 0, 0 });
  for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
  {
    count[v][0] += gradient.IsCriticalVertex(v);
  }
  for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
  {
    const auto& ev = mesh.EdgeVertices[e];
    count[Highest(field, { ev[0], ev[1] })][1] += gradient.IsCriticalEdge(e);
  }
  for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    const auto& tv = mesh.TriangleVertices[t];
    count[Highest(field, { tv[0], tv[1], tv[2] })][2] += gradient.IsCriticalTriangle(t);
  }
  return count;
}

// Whether following `next` from any start ever comes back to a node already on the path
// (InvalidIndex ends a path).
bool HasCycle(Index n, const std::function<Index(Index)>& next)
{
  std::vector<int> state(n, 0); // 0 unseen, 1 on the current path, 2 done
  for (Index start = 0; start < n; ++start)
  {
    std::vector<Index> path;
    Index x = start;
    while (x != InvalidIndex && state[x] == 0)
    {
      state[x] = 1;
      path.push_back(x);
      x = next(x);
    }
    if (x != InvalidIndex && state[x] == 1)
    {
      return true;
    }
    for (Index p : path)
    {
      state[p] = 2;
    }
  }
  return false;
}
} // namespace

TEST_CASE(EveryCellIsPairedAtMostOnceWithAFaceOrCofaceOfIt)
{
  for (const MeshField& field : TestMeshes())
  {
    const TriangleMeshTopology mesh = MeshOf(field);
    const DiscreteGradient g = GradientOf(mesh, field);
    bool consistent = true;
    for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
    {
      const Index e = g.VertexEdge[v];
      consistent = consistent &&
        (e == InvalidIndex ||
          (g.EdgeVertex[e] == v && (mesh.EdgeVertices[e][0] == v || mesh.EdgeVertices[e][1] == v)));
    }
    for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
    {
      const Index v = g.EdgeVertex[e], t = g.EdgeTriangle[e];
      // An edge pairs with a vertex or a triangle, not both.
      consistent = consistent && (v == InvalidIndex || t == InvalidIndex);
      consistent = consistent && (v == InvalidIndex || g.VertexEdge[v] == e);
      consistent = consistent && (t == InvalidIndex || g.TriangleEdge[t] == e);
    }
    for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
    {
      const Index e = g.TriangleEdge[t];
      const auto& te = mesh.TriangleEdges[t];
      consistent = consistent &&
        (e == InvalidIndex || (g.EdgeTriangle[e] == t && std::find(te.begin(), te.end(), e) != te.end()));
    }
    CHECK(consistent);
    if (!consistent)
    {
      std::printf("  on %s\n", field.Name.c_str());
    }
  }
}

TEST_CASE(PairsLieInsideOneLowerStar)
{
  // A pair's two cells have the same highest vertex: both lie in its lower star.
  for (const MeshField& field : TestMeshes())
  {
    const TriangleMeshTopology mesh = MeshOf(field);
    const DiscreteGradient g = GradientOf(mesh, field);
    bool inside = true;
    for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
    {
      const Index e = g.VertexEdge[v];
      inside = inside && (e == InvalidIndex || Highest(field, { mesh.EdgeVertices[e][0], mesh.EdgeVertices[e][1] }) == v);
    }
    for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
    {
      const Index e = g.TriangleEdge[t];
      if (e != InvalidIndex)
      {
        const auto& tv = mesh.TriangleVertices[t];
        inside = inside &&
          Highest(field, { mesh.EdgeVertices[e][0], mesh.EdgeVertices[e][1] }) == Highest(field, { tv[0], tv[1], tv[2] });
      }
    }
    CHECK(inside);
    if (!inside)
    {
      std::printf("  on %s\n", field.Name.c_str());
    }
  }
}

TEST_CASE(BoundaryCellsPairOnlyWithBoundaryCells)
{
  for (const MeshField& field : TestMeshes())
  {
    const TriangleMeshTopology mesh = MeshOf(field);
    const DiscreteGradient g = GradientOf(mesh, field);
    const Links links(field);
    bool rule = true;
    for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
    {
      const Index e = g.VertexEdge[v];
      if (links.OnBoundary(v) && e != InvalidIndex)
      {
        const auto& ev = mesh.EdgeVertices[e];
        rule = rule && links.BoundaryEdges[v].count({ ev[0], ev[1] }) == 1;
      }
    }
    for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
    {
      const Index e = g.TriangleEdge[t];
      if (e != InvalidIndex)
      {
        const auto& ev = mesh.EdgeVertices[e];
        rule = rule && links.BoundaryEdges[ev[0]].count({ ev[0], ev[1] }) == 0;
      }
    }
    CHECK(rule);
    if (!rule)
    {
      std::printf("  on %s\n", field.Name.c_str());
    }
  }
}

TEST_CASE(NoClosedVPaths)
{
  for (const MeshField& field : TestMeshes())
  {
    const TriangleMeshTopology mesh = MeshOf(field);
    const DiscreteGradient g = GradientOf(mesh, field);
    const bool vertexCycle = HasCycle(mesh.NumberOfVertices(), [&](Index v) {
      const Index e = g.VertexEdge[v];
      return e == InvalidIndex ? InvalidIndex : mesh.OtherEdgeVertex(e, v);
    });
    const bool triangleCycle = HasCycle(mesh.NumberOfTriangles(), [&](Index t) {
      const Index e = g.TriangleEdge[t];
      return e == InvalidIndex ? InvalidIndex : mesh.OtherEdgeTriangle(e, t);
    });
    CHECK(!vertexCycle);
    CHECK(!triangleCycle);
    if (vertexCycle || triangleCycle)
    {
      std::printf("  on %s\n", field.Name.c_str());
    }
  }
}

TEST_CASE(InteriorCriticalCellsAreThePiecewiseLinearCriticalPoints)
{
  // Per interior vertex, from its lower link (the part of its link below it): empty - one
  // critical vertex (a minimum); the whole link - one critical triangle (a maximum); k arcs -
  // k - 1 critical edges (a saddle of multiplicity k - 1, none for a regular vertex).
  for (const MeshField& field : TestMeshes())
  {
    const TriangleMeshTopology mesh = MeshOf(field);
    const DiscreteGradient g = GradientOf(mesh, field);
    const Links links(field);
    const auto found = CriticalCellsByOwner(mesh, g, field);
    bool same = true;
    for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
    {
      if (links.OnBoundary(v))
      {
        continue;
      }
      std::vector<Index> lower;
      for (Index w : links.Neighbours[v])
      {
        if (Lower(field, w, v))
        {
          lower.push_back(w);
        }
      }
      std::array<int, 3> expected{ 0, 0, 0 };
      if (lower.empty())
      {
        expected[0] = 1;
      }
      else if (lower.size() == links.Neighbours[v].size())
      {
        expected[2] = 1;
      }
      else
      {
        // Arcs of the lower link: its vertices minus its edges (a forest of paths).
        int edges = 0;
        for (const auto& e : links.Edges[v])
        {
          edges += Lower(field, e[0], v) && Lower(field, e[1], v);
        }
        expected[1] = static_cast<int>(lower.size()) - edges - 1;
      }
      same = same && found[v] == expected;
    }
    CHECK(same);
    if (!same)
    {
      std::printf("  on %s\n", field.Name.c_str());
    }
  }
}

TEST_CASE(BoundaryCriticalCellsAreTheExtremaAlongTheBoundary)
{
  // The boundary rule makes the boundary curve a 1D complex of its own: a boundary vertex
  // is a critical vertex exactly where both its boundary neighbours are higher (a minimum
  // along the curve), and owns a critical boundary edge exactly where both are lower (a
  // maximum along it). Over the whole disk, #vertices - #edges + #triangles = 1.
  for (const MeshField& field : TestMeshes())
  {
    const TriangleMeshTopology mesh = MeshOf(field);
    const DiscreteGradient g = GradientOf(mesh, field);
    const Links links(field);
    bool same = true;
    std::vector<int> criticalBoundaryEdges(field.Values.size(), 0);
    std::array<int, 3> total{ 0, 0, 0 };
    for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
    {
      const auto& ev = mesh.EdgeVertices[e];
      if (g.IsCriticalEdge(e) && links.BoundaryEdges[ev[0]].count({ ev[0], ev[1] }))
      {
        ++criticalBoundaryEdges[Highest(field, { ev[0], ev[1] })];
      }
      total[1] += g.IsCriticalEdge(e);
    }
    for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
    {
      total[0] += g.IsCriticalVertex(v);
      if (!links.OnBoundary(v))
      {
        continue;
      }
      int lowerAlong = 0;
      for (const auto& e : links.BoundaryEdges[v])
      {
        lowerAlong += Lower(field, e[0] == v ? e[1] : e[0], v);
      }
      same = same && g.IsCriticalVertex(v) == (lowerAlong == 0) && criticalBoundaryEdges[v] == (lowerAlong == 2 ? 1 : 0);
    }
    for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
    {
      total[2] += g.IsCriticalTriangle(t);
    }
    CHECK(same);
    CHECK_EQ(total[0] - total[1] + total[2], 1);
    if (!same || total[0] - total[1] + total[2] != 1)
    {
      std::printf("  on %s\n", field.Name.c_str());
    }
  }
}

TEST_CASE(RegularVertexShortcutEqualsProcessLowerStars)
{
  // The gradient's shortcut for regular interior vertices must give exactly the pairing of the
  // general queue-based ProcessLowerStars, on smooth fields and on fields full of ties.
  GridField ties = ShepardField(30, 2, 90, 5);
  for (double& v : ties.Values)
  {
    v = std::round(v * 20) / 20;
  }
  std::vector<MeshField> fields = TestMeshes();
  for (const GridField& grid : { ShepardField(50, 2, 200, 4), TrigonometricField(7, 80, -30), ties })
  {
    MeshField field = JitteredGrid(grid.Dimensions[0], grid.Dimensions[1], 0, 0.0, false);
    field.Values = grid.Values;
    fields.push_back(field);
  }
  for (const MeshField& field : fields)
  {
    const TriangleMeshTopology mesh = MeshOf(field);
    const DiscreteGradient fast = GradientOf(mesh, field);
    DiscreteGradient::GeneralPathOnly = true;
    const DiscreteGradient general = GradientOf(mesh, field);
    DiscreteGradient::GeneralPathOnly = false;
    CHECK(fast.VertexEdge == general.VertexEdge);
    CHECK(fast.EdgeVertex == general.EdgeVertex);
    CHECK(fast.EdgeTriangle == general.EdgeTriangle);
    CHECK(fast.TriangleEdge == general.TriangleEdge);
  }
}

// The meshes above, and four jittered grids of about nx x ny (plain and with random diagonals)
// with noise of few levels (monkey saddles, plateaus touching the boundary).
std::vector<MeshField> MeshesWithNoise(int nx, int ny, std::uint64_t gridSeed, std::uint64_t valueSeed)
{
  std::vector<MeshField> fields = TestMeshes();
  for (std::uint64_t seed = 1; seed <= 4; ++seed)
  {
    MeshField field =
      JitteredGrid(nx + static_cast<int>(seed), ny, gridSeed + seed, seed % 2 ? 0.0 : 0.4, seed % 2 == 0);
    RandomValues(field, valueSeed + seed, seed <= 2 ? 0 : static_cast<int>(seed));
    fields.push_back(field);
  }
  return fields;
}

TEST_CASE(SaddleVerticesCountedFromLowerLinksAreTheGradientsCriticalEdges)
{
  // DiscreteGradient::SaddleVertices (used by topological sampling) must list exactly the
  // owners of the gradient's critical edges, with multiplicity, in increasing order: on the
  // meshes above (ties, random diagonals, 2 x 2 and 3 x 2 grids), on larger noise with few
  // levels (monkey saddles, plateaus touching the boundary), with both lower-star paths, and
  // with threads.
  const std::vector<MeshField> fields = MeshesWithNoise(40, 37, 500, 700);
  // Three stretches, as threads would take them (the count must not depend on them).
  const ParallelFor inThreeStretches = [](Index begin, Index end, const RangeBody& body) {
    const Index third = (end - begin + 2) / 3;
    for (Index b = begin; b < end; b += std::max<Index>(third, 1))
    {
      body(b, std::min(end, b + std::max<Index>(third, 1)));
    }
  };
  Index compared = 0, multiple = 0;
  for (const bool generalPath : { false, true })
  {
    for (const MeshField& field : fields)
    {
      const TriangleMeshTopology mesh = MeshOf(field);
      DiscreteGradient::GeneralPathOnly = generalPath;
      const DiscreteGradient g = GradientOf(mesh, field);
      DiscreteGradient::GeneralPathOnly = false;
      std::vector<Index> expected;
      const VertexOrder order{ field.Values.data() };
      for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
      {
        if (g.IsCriticalEdge(e))
        {
          expected.push_back(DiscreteGradient::EdgeOwner(mesh, order, e));
        }
      }
      std::sort(expected.begin(), expected.end());
      std::vector<Index> counted;
      CHECK(DiscreteGradient::SaddleVertices(mesh, field.Values.data(), inThreeStretches, counted));
      if (counted != expected)
      {
        std::printf("  %s: %zu saddles counted, %zu critical edges\n", field.Name.c_str(), counted.size(),
          expected.size());
      }
      CHECK(counted == expected);
      compared += static_cast<Index>(expected.size());
      multiple += std::adjacent_find(expected.begin(), expected.end()) != expected.end() ? 1 : 0;
    }
  }
  CHECK(compared > 1000);
  CHECK(multiple > 0); // some fields have saddles of multiplicity 2 or more
  // Stage 1 refuses non-finite values: so does the count.
  MeshField broken = fields.front();
  broken.Values[broken.Values.size() / 2] = std::nan("");
  std::vector<Index> counted;
  CHECK(!DiscreteGradient::SaddleVertices(MeshOf(broken), broken.Values.data(), SequentialFor, counted));
}

// SaddleVertexCount counts again only the lower stars around changed values: after every step
// of a sequence of changes (a few vertices to new values, to a neighbour's value, the sign of a
// zero flipped, a NaN that fails the count and is then taken back) its saddles must be
// SaddleVertices' of the same values, on the meshes above, in stretches as threads take them.
TEST_CASE(SaddleVertexCountFollowsChangedValues)
{
  const std::vector<MeshField> fields = MeshesWithNoise(30, 27, 300, 400);
  const ParallelFor inTwoStretches = [](Index begin, Index end, const RangeBody& body) {
    const Index half = std::max<Index>((end - begin + 1) / 2, 1);
    for (Index b = begin; b < end; b += half)
    {
      body(b, std::min(end, b + half));
    }
  };
  DeterministicRandom random(41);
  Index steps = 0, changedSaddles = 0;
  for (const MeshField& field : fields)
  {
    const TriangleMeshTopology mesh = MeshOf(field);
    std::vector<double> values = field.Values;
    const Index n = mesh.NumberOfVertices();
    SaddleVertexCount count(mesh, inTwoStretches);
    std::vector<Index> counted, expected, before;
    CHECK(count.Count(values, counted));
    for (int step = 0; step < 25; ++step)
    {
      const std::vector<double> last = values;
      const int changes = 1 + static_cast<int>(random.Uniform() * 6);
      for (int c = 0; c < changes; ++c)
      {
        const Index v = std::min<Index>(n - 1, static_cast<Index>(random.Uniform() * n));
        const double kind = random.Uniform();
        if (kind < 0.4)
        {
          values[v] = random.Uniform();
        }
        else if (kind < 0.8)
        {
          const Index t = mesh.VertexTriangle(mesh.VertexTriangleBegin(v));
          values[v] = values[mesh.TriangleVertices[t][0] == v ? mesh.TriangleVertices[t][1] : mesh.TriangleVertices[t][0]];
        }
        else
        {
          values[v] = values[v] == 0 ? -values[v] : 0.0;
        }
      }
      if (step == 10)
      {
        std::vector<double> broken = values;
        broken[n / 2] = std::nan("");
        CHECK(!count.Count(broken, counted));
      }
      before = expected;
      CHECK(DiscreteGradient::SaddleVertices(mesh, values.data(), SequentialFor, expected));
      CHECK(count.Count(values, counted));
      CHECK(counted == expected);
      changedSaddles += before != expected ? 1 : 0;
      ++steps;
    }
  }
  CHECK(steps > 100);
  CHECK(changedSaddles > steps / 4); // the changes do move saddles
}

TEST_CASE(CriticalCellsOfOneLowerStarAreTheGradients)
{
  // DiscreteGradient::CriticalCellsOfLowerStar (topological sampling's local moves judge a
  // changed value by it) must give, vertex by vertex, the gradient's critical vertex, the
  // number of its critical edges and its critical triangle, boundary vertices included.
  const std::vector<MeshField> fields = MeshesWithNoise(30, 27, 900, 1700);
  Index boundaryMinima = 0, boundaryMaxima = 0, vertices = 0;
  for (const MeshField& field : fields)
  {
    const TriangleMeshTopology mesh = MeshOf(field);
    const DiscreteGradient g = GradientOf(mesh, field);
    const VertexOrder order{ field.Values.data() };
    std::vector<LowerStarCriticalCells> expected(static_cast<std::size_t>(mesh.NumberOfVertices()));
    for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
    {
      expected[v].Minimum = g.IsCriticalVertex(v);
    }
    for (Index e = 0; e < mesh.NumberOfEdges(); ++e)
    {
      expected[DiscreteGradient::EdgeOwner(mesh, order, e)].Saddles += g.IsCriticalEdge(e) ? 1 : 0;
    }
    for (Index t = 0; t < mesh.NumberOfTriangles(); ++t)
    {
      if (g.IsCriticalTriangle(t))
      {
        CHECK(!expected[DiscreteGradient::TriangleOwner(mesh, order, t)].Maximum); // one per lower star
        expected[DiscreteGradient::TriangleOwner(mesh, order, t)].Maximum = true;
      }
    }
    for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
    {
      const LowerStarCriticalCells local = DiscreteGradient::CriticalCellsOfLowerStar(mesh, field.Values.data(), v);
      if (!(local == expected[v]))
      {
        std::printf("  %s vertex %lld: local %d/%d/%d, gradient %d/%d/%d\n", field.Name.c_str(),
          static_cast<long long>(v), local.Minimum, local.Saddles, local.Maximum, expected[v].Minimum,
          expected[v].Saddles, expected[v].Maximum);
      }
      CHECK(local == expected[v]);
      boundaryMinima += mesh.IsBoundaryVertex(v) && expected[v].Minimum ? 1 : 0;
      boundaryMaxima += mesh.IsBoundaryVertex(v) && expected[v].Maximum ? 1 : 0;
      ++vertices;
    }
  }
  CHECK(vertices > 3000);
  CHECK(boundaryMinima > 10);
  CHECK(boundaryMaxima > 10);
}

int main()
{
  return testing_harness::RunAll();
}
