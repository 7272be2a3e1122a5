// Tests of TriangleMeshTopology: Build on the grid triangulation numbers everything exactly as
// BuildGrid does, and CheckPlanarDisk accepts grids and seeded jittered meshes but refuses the
// meshes the complex cannot handle (bow-tie vertices, several pieces, holes, zero-area
// triangles, folds), each with its own message.
//
// Usage: TestTriangleMeshTopology
// Prints the refusal messages, then "N passed, N failed"; returns nonzero on failure.
#include "SyntheticFields.h"
#include "TestHarness.h"
#include "TriangleMeshTopology.h"

#include <array>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

using namespace topospline;

namespace
{
std::vector<double> GridPoints(int nx, int ny, double jitter, unsigned seed)
{
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> offset(-jitter, jitter);
  std::vector<double> points;
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i)
    {
      points.push_back(i + offset(random));
      points.push_back(j + offset(random));
    }
  }
  return points;
}

bool Check(Index vertices, const std::vector<Index>& triangles, const std::vector<double>& points, std::string& error)
{
  TriangleMeshTopology mesh;
  error.clear();
  return mesh.Build(vertices, triangles, SequentialFor, error) && mesh.CheckPlanarDisk(points, error);
}
} // namespace

//------------------------------------------------------------------------------
TEST_CASE(BuildMatchesBuildGrid)
{
  for (const auto& size : { std::array<int, 2>{ 2, 2 }, std::array<int, 2>{ 5, 3 }, std::array<int, 2>{ 17, 11 } })
  {
    TriangleMeshTopology general, grid;
    std::string error;
    CHECK(general.Build(size[0] * size[1], GridTriangles(size[0], size[1]), SequentialFor, error));
    grid.BuildGrid(size[0], size[1], SequentialFor);
    CHECK(general.NumberOfEdges() == grid.NumberOfEdges());
    CHECK(general.EulerCharacteristic() == 1 && grid.EulerCharacteristic() == 1);
    bool same = true;
    for (Index e = 0; e < general.NumberOfEdges(); ++e)
    {
      same = same && general.EdgeVertices[e] == grid.EdgeVertices[e] && general.EdgeTriangles[e] == grid.EdgeTriangles[e];
    }
    for (Index t = 0; t < general.NumberOfTriangles(); ++t)
    {
      same = same && general.TriangleEdges[t] == grid.TriangleEdges[t];
    }
    for (Index v = 0; v < general.NumberOfVertices(); ++v)
    {
      same = same && general.IsBoundaryVertex(v) == grid.IsBoundaryVertex(v);
    }
    CHECK(same);
  }
}

//------------------------------------------------------------------------------
TEST_CASE(PlanarDisksAccepted)
{
  std::string error;
  for (unsigned seed = 0; seed < 5; ++seed)
  {
    // jitter below half a spacing keeps every triangle of the split grid positively oriented
    CHECK(Check(12 * 9, GridTriangles(12, 9), GridPoints(12, 9, 0.3, seed), error));
    if (!error.empty())
    {
      std::printf("  unexpected: %s\n", error.c_str());
    }
  }
}

//------------------------------------------------------------------------------
TEST_CASE(NonDisksRefused)
{
  struct Case
  {
    const char* Name;
    Index Vertices;
    std::vector<Index> Triangles;
    std::vector<double> Points;
    const char* Expected;
  };
  std::vector<Case> cases;
  cases.push_back({ "bow-tie", 5, { 0, 1, 2, 0, 3, 4 }, { 0, 0, 1, 0, 0, 1, -1, 0, 0, -1 }, "bow-tie" });
  {
    // two 3 x 3 grids side by side, not touching
    std::vector<Index> t = GridTriangles(3, 3);
    const std::size_t n = t.size();
    for (std::size_t i = 0; i < n; ++i)
    {
      t.push_back(t[i] + 9);
    }
    std::vector<double> p = GridPoints(3, 3, 0, 0), q = GridPoints(3, 3, 0, 0);
    for (std::size_t i = 0; i < q.size(); i += 2)
    {
      q[i] += 10;
    }
    p.insert(p.end(), q.begin(), q.end());
    cases.push_back({ "two pieces", 18, t, p, "2 separate pieces" });
  }
  {
    // a 4 x 4 grid without its middle quad: an annulus
    const std::vector<Index> all = GridTriangles(4, 4);
    std::vector<Index> t;
    for (std::size_t i = 0; i < all.size(); i += 3)
    {
      const std::size_t triangle = i / 3, quad = triangle / 2;
      if (quad != 4)
      {
        t.insert(t.end(), all.begin() + i, all.begin() + i + 3);
      }
    }
    cases.push_back({ "hole", 16, t, GridPoints(4, 4, 0, 0), "hole" });
  }
  cases.push_back({ "zero area", 4, { 0, 1, 3, 1, 2, 3, 0, 2, 1 }, { 0, 0, 1, 0, 2, 0, 1, 1 }, "zero area" });
  cases.push_back({ "fold", 4, { 0, 1, 2, 0, 1, 3 }, { 0, 0, 2, 0, 1, 1, 1, 2 }, "folds over" });
  for (const Case& c : cases)
  {
    std::string error;
    CHECK(!Check(c.Vertices, c.Triangles, c.Points, error));
    CHECK(error.find(c.Expected) != std::string::npos);
    std::printf("  %s: \"%s\"\n", c.Name, error.c_str());
  }
}

int main()
{
  return testing_harness::RunAll();
}
