// Unit tests of the junction points (DetectJunctionPoints): hand-made complexes, and the
// complexes of random seeded fields (unsimplified and simplified) against an independent
// computation written here from the definition: per extremum, the cells of its tree where
// its 1-cells, followed from it, do not all go on the same way.
#include "JunctionPointDetection.h"
#include "MorseSmaleComplexExtraction.h"
#include "MorseSmaleComplexSimplification.h"
#include "SyntheticFields.h"
#include "TestHarness.h"

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

using namespace topospline;

namespace
{
// A critical point of a hand-made complex (its position is its id).
CriticalPoint Point(int morseIndex, Index vertex, Index cell)
{
  CriticalPoint cp;
  cp.MorseIndex = morseIndex;
  cp.Vertex = vertex;
  cp.Cell = cell;
  return cp;
}

// A descending 1-cell along `vertices` (minimum first), vertex v at (v, 0) with value v.
OneCell Descending(Index minimum, Index saddle, const std::vector<Index>& vertices)
{
  OneCell oneCell;
  oneCell.Type = OneCell::Descending;
  oneCell.Source = minimum;
  oneCell.Destination = saddle;
  oneCell.MeshCells = vertices;
  for (Index v : vertices)
  {
    oneCell.Points.insert(oneCell.Points.end(), { static_cast<double>(v), 0.0 });
    oneCell.Values.push_back(v);
  }
  return oneCell;
}

// An ascending 1-cell along `triangles` (saddle side first), triangle t at (t, 1) with value
// t; the saddle's and the maximum's vertices at the ends.
OneCell Ascending(const MorseSmaleComplex& complex, Index saddle, Index maximum, const std::vector<Index>& triangles)
{
  OneCell oneCell;
  oneCell.Type = OneCell::Ascending;
  oneCell.Source = saddle;
  oneCell.Destination = maximum;
  oneCell.MeshCells = triangles;
  const Index first = complex.CriticalPoints[saddle].Vertex, last = complex.CriticalPoints[maximum].Vertex;
  oneCell.Points = { static_cast<double>(first), 0.0 };
  oneCell.Values = { static_cast<double>(first) };
  for (Index t : triangles)
  {
    oneCell.Points.insert(oneCell.Points.end(), { static_cast<double>(t), 1.0 });
    oneCell.Values.push_back(t);
  }
  oneCell.Points.insert(oneCell.Points.end(), { static_cast<double>(last), 0.0 });
  oneCell.Values.push_back(last);
  return oneCell;
}

// (type, extremum, cell, critical point, 1-cells) of each junction, in order.
using JunctionKey = std::tuple<int, Index, Index, Index, std::vector<Index>>;
std::vector<JunctionKey> Keys(const std::vector<JunctionPoint>& junctions)
{
  std::vector<JunctionKey> keys;
  for (const JunctionPoint& j : junctions)
  {
    keys.emplace_back(j.Type, j.Extremum, j.Cell, j.CriticalPoint, j.OneCells);
  }
  return keys;
}

// The junction points from the definition, with maps instead of per-cell arrays. The tree
// of an extremum holds the cells its 1-cells pass through, except where a descending 1-cell
// ends (its last step is the saddle edge, not a gradient step) without any 1-cell of the
// extremum going on from there. Ordered as DetectJunctionPoints documents: descending ones
// first, each kind by the first visit (1-cells in order, each from its extremum).
std::vector<JunctionKey> ExpectedJunctions(const MorseSmaleComplex& c)
{
  struct Visit
  {
    Index OneCell;
    Index Following;
    bool Ends;
  };
  std::vector<JunctionKey> expected;
  for (const int type : { 0, 1 })
  {
    // (extremum, cell) -> visits, in order of first visit.
    std::map<std::pair<Index, Index>, std::vector<Visit>> visits;
    std::vector<std::pair<Index, Index>> order;
    std::set<std::pair<Index, Index>> inTree;
    for (Index a = 0; a < static_cast<Index>(c.OneCells.size()); ++a)
    {
      const OneCell& oneCell = c.OneCells[a];
      if (oneCell.Type != type)
      {
        continue;
      }
      std::vector<Index> path = oneCell.MeshCells;
      const Index extremum = type == 0 ? oneCell.Source : oneCell.Destination;
      if (type == 1)
      {
        std::reverse(path.begin(), path.end());
      }
      for (size_t i = 0; i < path.size(); ++i)
      {
        const bool last = i + 1 == path.size();
        if (type == 1 || !last)
        {
          inTree.insert({ extremum, path[i] });
        }
        if (i == 0)
        {
          continue;
        }
        Index following = -1;
        if (!last)
        {
          following = path[i + 1];
        }
        else if (type == 1)
        {
          following = -2 - c.CriticalPoints[oneCell.Source].Vertex;
        }
        auto& list = visits[{ extremum, path[i] }];
        if (list.empty())
        {
          order.push_back({ extremum, path[i] });
        }
        list.push_back({ a, following, type == 0 && last });
      }
    }
    // `order` is the order of first visits.
    for (const auto& place : order)
    {
      if (!inTree.count(place))
      {
        continue;
      }
      const auto& list = visits[place];
      std::set<Index> ways;
      for (const Visit& visit : list)
      {
        ways.insert(visit.Following);
      }
      if (ways.size() < 2)
      {
        continue;
      }
      Index criticalPoint = InvalidIndex;
      std::vector<Index> oneCells;
      for (const Visit& visit : list)
      {
        oneCells.push_back(visit.OneCell);
        if (visit.Ends)
        {
          criticalPoint = c.OneCells[visit.OneCell].Destination;
        }
      }
      expected.emplace_back(type, place.first, place.second, criticalPoint, oneCells);
    }
  }
  return expected;
}

void CheckAgainstDefinition(const MorseSmaleComplex& complex, const std::string& name)
{
  const auto found = Keys(DetectJunctionPoints(complex));
  const auto expected = ExpectedJunctions(complex);
  CHECK(found == expected);
  if (found != expected)
  {
    std::printf("  %s: %zu junction points, expected %zu\n", name.c_str(), found.size(), expected.size());
  }
}
} // namespace

TEST_CASE(HandMadeDescendingTree)
{
  // Minimum 0 at vertex 0; saddles at vertices 3, 4, 5 and 6. From the minimum, 1-cells
  // 0 and 1 run together over vertices 1 and 2 and part at 2; 1-cell 2 leaves them at 1;
  // 1-cell 3 ends at vertex 2 (its saddle's) where 1-cells 0 and 1 go on: a junction that
  // is also a critical point.
  MorseSmaleComplex c;
  c.CriticalPoints = { Point(0, 0, 0), Point(1, 3, 30), Point(1, 4, 40), Point(1, 5, 50), Point(1, 2, 20) };
  c.OneCells = { Descending(0, 1, { 0, 1, 2, 3 }), Descending(0, 2, { 0, 1, 2, 4 }), Descending(0, 3, { 0, 1, 5 }),
    Descending(0, 4, { 0, 7, 2 }) };
  const auto junctions = DetectJunctionPoints(c);
  CHECK_EQ(junctions.size(), 2u);
  if (junctions.size() == 2)
  {
    CHECK_EQ(junctions[0].Cell, 1);
    CHECK(junctions[0].OneCells == std::vector<Index>({ 0, 1, 2 }));
    CHECK_EQ(junctions[0].CriticalPoint, InvalidIndex);
    CHECK_EQ(junctions[1].Cell, 2);
    CHECK(junctions[1].OneCells == std::vector<Index>({ 0, 1, 3 }));
    CHECK_EQ(junctions[1].CriticalPoint, 4);
    CHECK_EQ(junctions[1].Position[0], 2.0);
    CHECK_EQ(junctions[1].Value, 2.0);
    CHECK(junctions[1].Type == OneCell::Descending);
    CHECK_EQ(junctions[1].Extremum, 0);
  }
  CheckAgainstDefinition(c, "hand-made descending");
}

TEST_CASE(DescendingOneCellEndingInAnotherTree)
{
  // 1-cell 2 of minimum 1 ends at vertex 2, which lies on the tree of minimum 0: no junction
  // of either minimum there. 1-cells 0 and 1 of minimum 0 run together to the end (the same
  // saddle vertex 3): no junction either.
  MorseSmaleComplex c;
  c.CriticalPoints = { Point(0, 0, 0), Point(0, 9, 9), Point(1, 3, 30), Point(1, 3, 31), Point(1, 2, 20) };
  c.OneCells = { Descending(0, 2, { 0, 1, 2, 3 }), Descending(0, 3, { 0, 1, 2, 3 }), Descending(1, 4, { 9, 8, 2 }) };
  CHECK(DetectJunctionPoints(c).empty());
  CheckAgainstDefinition(c, "other tree");
}

TEST_CASE(HandMadeAscendingTree)
{
  // Maximum 0 on triangle 10 (vertex 20). Saddles 1 and 2 share vertex 5, saddle 3 sits on
  // vertex 6. From the maximum: 10, 11, then 12 (saddle 1), 12 (saddle 2), 13 (saddle 3).
  // Triangle 11 is a junction (12 or 13 next); triangle 12 is one too, although saddles 1
  // and 2 go on to the same vertex, since saddle 4 on vertex 7 also ends at triangle 12.
  MorseSmaleComplex c;
  c.CriticalPoints = { Point(2, 20, 10), Point(1, 5, 50), Point(1, 5, 51), Point(1, 6, 60), Point(1, 7, 70) };
  c.OneCells = { Ascending(c, 1, 0, { 12, 11, 10 }), Ascending(c, 2, 0, { 12, 11, 10 }),
    Ascending(c, 3, 0, { 13, 11, 10 }) };
  auto junctions = DetectJunctionPoints(c);
  CHECK_EQ(junctions.size(), 1u);
  if (junctions.size() == 1)
  {
    CHECK(junctions[0].Type == OneCell::Ascending);
    CHECK_EQ(junctions[0].Extremum, 0);
    CHECK_EQ(junctions[0].Cell, 11);
    CHECK(junctions[0].OneCells == std::vector<Index>({ 0, 1, 2 }));
    CHECK_EQ(junctions[0].Position[0], 11.0);
    CHECK_EQ(junctions[0].Position[1], 1.0);
    CHECK_EQ(junctions[0].CriticalPoint, InvalidIndex);
  }
  CheckAgainstDefinition(c, "hand-made ascending");

  c.OneCells.push_back(Ascending(c, 4, 0, { 12, 11, 10 }));
  junctions = DetectJunctionPoints(c);
  CHECK_EQ(junctions.size(), 2u);
  if (junctions.size() == 2)
  {
    CHECK_EQ(junctions[1].Cell, 12);
    CHECK(junctions[1].OneCells == std::vector<Index>({ 0, 1, 3 }));
  }
  CheckAgainstDefinition(c, "hand-made ascending, saddle 4");
}

TEST_CASE(ComplexesOfRandomFields)
{
  // Stage-1 complexes, and their simplifications, of random seeded Shepard fields. The
  // simplifier reports the junction points of its output, which must be the definition's,
  // and at 0 % it returns its input unchanged: on a stage-1 complex the junction points
  // alone are what Simplify(0) gives.
  int compared = 0, nonEmpty = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed)
  {
    const PlanarScalarField field = FieldOnGrid(ShepardField(8 + 4 * static_cast<int>(seed), 2, 40 + 10 * static_cast<int>(seed), seed));
    MorseSmaleComplexExtraction extraction;
    MorseSmaleComplex input;
    std::string error;
    if (!extraction.Extract(field, input, error))
    {
      CHECK(false);
      continue;
    }
    const std::string name = "seed " + std::to_string(seed);
    CheckAgainstDefinition(input, name);
    MorseSmaleComplexSimplification simplification;
    CHECK(simplification.ComputeHierarchy(input, error));
    for (double percent : { 0.0, 2.0, 10.0, 30.0, 100.0 })
    {
      SimplificationOutput output;
      CHECK(simplification.Simplify(percent, output, error));
      CheckAgainstDefinition(output.Complex, name + " at " + std::to_string(percent) + "%");
      CHECK(Keys(output.JunctionPoints) == Keys(DetectJunctionPoints(output.Complex)));
      if (percent == 0)
      {
        CHECK(Keys(output.JunctionPoints) == Keys(DetectJunctionPoints(input)));
        CHECK_EQ(output.Complex.OneCells.size(), input.OneCells.size());
        bool sameOneCells = output.Complex.OneCells.size() == input.OneCells.size();
        for (size_t a = 0; sameOneCells && a < input.OneCells.size(); ++a)
        {
          sameOneCells = output.Complex.OneCells[a].MeshCells == input.OneCells[a].MeshCells &&
            output.Complex.OneCells[a].Points == input.OneCells[a].Points;
        }
        CHECK(sameOneCells);
      }
      ++compared;
      nonEmpty += !output.JunctionPoints.empty();
    }
  }
  CHECK_EQ(compared, 30);
  CHECK(nonEmpty > 20);
}

int main()
{
  return testing_harness::RunAll();
}
