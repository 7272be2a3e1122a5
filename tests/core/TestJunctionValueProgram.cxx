// Tests of the junction values (JunctionValueProgram; paper, section 4, step 1) on small
// hand-made graphs and random forests of 1-cells: every relation strict, one value per shared
// junction, the optimum of the program, split and single programs alike, equal critical
// values spread apart, real inversions and cycles rejected (the cycle named), bad input, and
// timings.
//
// Usage: TestJunctionValueProgram
// Prints the error messages and timings, then "N passed, N failed"; returns nonzero on failure.
#include "JunctionValueProgram.h"
#include "TestHarness.h"
#include "TestSupport.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace topospline;

namespace
{
bool SatisfiesRelations(const std::vector<double>& values, const std::vector<std::array<Index, 2>>& relations)
{
  for (const auto& r : relations)
  {
    if (!(values[r[1]] > values[r[0]]))
    {
      return false;
    }
  }
  return true;
}

double Change(const std::vector<JunctionValueNode>& nodes, const std::vector<double>& values)
{
  double total = 0;
  for (std::size_t n = 0; n < nodes.size(); ++n)
  {
    total += std::abs(values[n] - nodes[n].Value);
  }
  return total;
}

// Relations from 1-cells given as node paths, lowest first.
std::vector<std::array<Index, 2>> RelationsOf(const std::vector<std::vector<Index>>& cells)
{
  std::vector<std::array<Index, 2>> relations;
  for (const auto& cell : cells)
  {
    for (std::size_t i = 0; i + 1 < cell.size(); ++i)
    {
      relations.push_back({ cell[i], cell[i + 1] });
    }
  }
  return relations;
}
} // namespace

//------------------------------------------------------------------------------
TEST_CASE(JunctionValues)
{
  JunctionValueProgram program;
  std::vector<double> values;
  std::string error;

  // A chain min(0) - j1(0.5) - j2(0.3) - saddle(1): the optimum moves the pair by 0.2 + margin.
  {
    const std::vector<JunctionValueNode> nodes = { { 0.0, true }, { 0.5, false }, { 0.3, false }, { 1.0, true } };
    const auto relations = RelationsOf({ { 0, 1, 2, 3 } });
    CHECK(program.Solve(nodes, relations, values, error));
    CHECK(std::abs(program.Margin - 1e-3) <= 1e-15);
    CHECK(SatisfiesRelations(values, relations));
    CHECK(values[0] == 0.0 && values[3] == 1.0);
    CHECK(std::abs(program.TotalChange - (0.2 + program.Margin)) <= 1e-9);
  }

  // Three saddles descending to one minimum through two shared junctions (the paper's
  // figure 3): one value per junction, all 1-cells strictly increasing.
  {
    // 0 min, 1..3 saddles, 4 = j1 (next to the min), 5 = j2.
    const std::vector<JunctionValueNode> nodes = { { 0.0, true }, { 1.0, true }, { 0.8, true }, { 0.9, true },
      { 0.3, false }, { 0.1, false } };
    const std::vector<std::vector<Index>> cells = { { 0, 4, 5, 1 }, { 0, 4, 5, 2 }, { 0, 4, 3 } };
    const auto relations = RelationsOf(cells);
    CHECK(program.Solve(nodes, relations, values, error));
    CHECK(values.size() == nodes.size());
    CHECK(SatisfiesRelations(values, relations));
    for (Index n = 0; n < 4; ++n)
    {
      CHECK(values[n] == nodes[n].Value);
    }
    // Optimum: |x4 - 0.3| + |x5 - 0.1| with x4 + m <= x5: 0.2 + m.
    CHECK(std::abs(Change(nodes, values) - (0.2 + program.Margin)) <= 1e-9);
    for (const auto& cell : cells)
    {
      for (std::size_t i = 0; i + 1 < cell.size(); ++i)
      {
        CHECK(values[cell[i + 1]] - values[cell[i]] >= program.Margin * (1 - 1e-9));
      }
    }
  }

  // Random forests of 1-cells like the ones of real complexes: saddles above, extrema below,
  // merging into trees of junctions. Split and single programs reach the same optimum, which
  // is no worse than a simple feasible reference (the repaired original values).
  std::mt19937 random(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 30; ++trial)
  {
    std::vector<JunctionValueNode> nodes;
    std::vector<std::vector<Index>> cells;
    const int minima = 1 + trial % 4;
    for (int m = 0; m < minima; ++m)
    {
      const Index minimum = static_cast<Index>(nodes.size());
      nodes.push_back({ 100.0 * unit(random), true });
      // A tree of junctions above the minimum; every saddle reaches it through a path.
      std::vector<Index> tree = { minimum };
      std::vector<std::vector<Index>> pathTo = { { minimum } };
      const int junctions = 2 + static_cast<int>(unit(random) * 15);
      for (int j = 0; j < junctions; ++j)
      {
        const std::size_t parent = static_cast<std::size_t>(unit(random) * tree.size()) % tree.size();
        const Index id = static_cast<Index>(nodes.size());
        nodes.push_back({ nodes[minimum].Value + 40.0 * unit(random) - 5.0, false });
        tree.push_back(id);
        pathTo.push_back(pathTo[parent]);
        pathTo.back().push_back(id);
      }
      const int saddles = 2 + static_cast<int>(unit(random) * 6);
      for (int s = 0; s < saddles; ++s)
      {
        const std::size_t via = static_cast<std::size_t>(unit(random) * tree.size()) % tree.size();
        const Index id = static_cast<Index>(nodes.size());
        nodes.push_back({ nodes[minimum].Value + 30.0 + 30.0 * unit(random), true });
        cells.push_back(pathTo[via]);
        cells.back().push_back(id);
      }
    }
    const auto relations = RelationsOf(cells);
    std::vector<double> split, single;
    program.SplitIntoComponents = true;
    const bool okSplit = program.Solve(nodes, relations, split, error);
    const double splitChange = program.TotalChange;
    program.SplitIntoComponents = false;
    const bool okSingle = program.Solve(nodes, relations, single, error);
    program.SplitIntoComponents = true;
    CHECK(okSplit && okSingle);
    if (!okSplit || !okSingle)
    {
      std::printf("  junction trial %d: %s\n", trial, error.c_str());
      continue;
    }
    CHECK(SatisfiesRelations(split, relations) && SatisfiesRelations(single, relations));
    CHECK(std::abs(splitChange - program.TotalChange) <= 1e-6 * 100.0);
    // The components' programs solved on several threads: the same values, bit for bit.
    {
      JunctionValueProgram threaded;
      threaded.Parallel = ThreadedFor;
      std::vector<double> again;
      CHECK(threaded.Solve(nodes, relations, again, error) && again == split);
    }
    for (std::size_t n = 0; n < nodes.size(); ++n)
    {
      if (nodes[n].Fixed)
      {
        CHECK(split[n] == nodes[n].Value && single[n] == nodes[n].Value);
      }
    }
    // Units: the same problem at another offset and scale gives the same answer, scaled.
    std::vector<JunctionValueNode> scaled = nodes;
    for (auto& node : scaled)
    {
      node.Value = 1e9 + 1e3 * node.Value;
    }
    std::vector<double> scaledValues;
    CHECK(program.Solve(scaled, relations, scaledValues, error));
    CHECK(std::abs(program.TotalChange - 1e3 * splitChange) <= 1e-6 * 1e5);
  }

  // Two critical points closer than MarginFraction * range allows along a chain: the
  // margin shrinks instead of failing.
  {
    const std::vector<JunctionValueNode> nodes = { { 0.0, true }, { 0.5, false }, { 0.5, false }, { 0.5, false },
      { 1e-6, true }, { 1.0, true } };
    const auto relations = RelationsOf({ { 0, 1, 2, 3, 4 }, { 4, 5 } });
    CHECK(program.Solve(nodes, relations, values, error));
    CHECK(SatisfiesRelations(values, relations));
    CHECK(program.Margin <= 0.5 * 1e-6 / 4 * (1 + 1e-12));
  }
  // Junctions without relations keep their values; an empty problem is fine.
  {
    const std::vector<JunctionValueNode> nodes = { { 3.0, false }, { -2.0, false } };
    CHECK(program.Solve(nodes, {}, values, error));
    CHECK(values[0] == 3.0 && values[1] == -2.0);
    CHECK(program.Solve({}, {}, values, error) && values.empty());
  }
}

//------------------------------------------------------------------------------
// Equal or nearly equal critical values (plateaus, constant fields, noise a few ulps apart),
// which the complex orders by vertex id, are spread just enough to rise strictly; values
// that are far enough apart are never touched.
TEST_CASE(ValueSpreading)
{
  JunctionValueProgram program;
  std::vector<double> values;
  std::string error;
  const double gap = JunctionValueProgram::SpreadingGap;
  // A constant field: min = saddle = max = 1 through a junction.
  {
    const std::vector<JunctionValueNode> nodes = { { 1.0, true }, { 1.0, false }, { 1.0, true } };
    CHECK(program.Solve(nodes, { { 0, 1 }, { 1, 2 } }, values, error));
    CHECK(values[0] == 1.0);
    CHECK(values[0] < values[1] && values[1] < values[2]);
    CHECK(program.SpreadCriticalValues == 1);
    // two relations of room above the scale 1
    CHECK(std::abs(program.MaximumSpread - 2 * gap) < 1e-3 * gap);
  }
  // A constant field at 0 (no scale from the values: 1 is used).
  {
    const std::vector<JunctionValueNode> nodes = { { 0.0, true }, { 0.0, true }, { 0.0, true } };
    CHECK(program.Solve(nodes, { { 0, 1 }, { 1, 2 }, { 0, 2 } }, values, error));
    CHECK(values[0] == 0.0 && values[0] < values[1] && values[1] < values[2]);
    CHECK(program.SpreadCriticalValues == 2);
  }
  // Values 1 ulp apart in a chain of 3 relations: spread; the lowest one stays.
  {
    const double a = 0.4, b = std::nextafter(a, 1.0);
    const std::vector<JunctionValueNode> nodes = { { a, true }, { 0.3, false }, { 0.5, false }, { b, true } };
    CHECK(program.Solve(nodes, { { 0, 1 }, { 1, 2 }, { 2, 3 } }, values, error));
    CHECK(values[0] == a && values[0] < values[1] && values[1] < values[2] && values[2] < values[3]);
    CHECK(program.SpreadCriticalValues == 1 && program.MaximumSpread < 4 * gap);
  }
  // Well separated values: nothing spread, fixed values exact.
  {
    const std::vector<JunctionValueNode> nodes = { { 0.0, true }, { 0.5, false }, { 1.0, true } };
    CHECK(program.Solve(nodes, { { 0, 1 }, { 1, 2 } }, values, error));
    CHECK(values[0] == 0.0 && values[2] == 1.0 && program.SpreadCriticalValues == 0 && program.MaximumSpread == 0);
  }
  // An inversion is not a tie: still an error.
  {
    const std::vector<JunctionValueNode> nodes = { { 1.0, true }, { 1.0, false }, { 1.0 - 1e-6, true } };
    CHECK(!program.Solve(nodes, { { 0, 1 }, { 1, 2 } }, values, error) && !error.empty());
    CHECK(program.FoundOrderConflict);
  }
}

//------------------------------------------------------------------------------
TEST_CASE(InfeasibleJunctionPrograms)
{
  JunctionValueProgram program;
  std::vector<double> values;
  struct Case
  {
    const char* Name;
    std::vector<JunctionValueNode> Nodes;
    std::vector<std::array<Index, 2>> Relations;
  };
  const std::vector<Case> cases = {
    { "fixed nodes in the wrong order", { { 1.0, true }, { 0.0, true } }, { { 0, 1 } } },
    { "fixed nodes in the wrong order through junctions",
      { { 1.0, true }, { 0.5, false }, { 0.7, false }, { 0.0, true } }, { { 0, 1 }, { 1, 2 }, { 2, 3 } } },
    { "a cycle of junctions", { { 0.0, true }, { 0.5, false }, { 0.6, false }, { 1.0, true } },
      { { 0, 1 }, { 1, 2 }, { 2, 1 }, { 2, 3 } } },
    { "a self relation", { { 0.0, false } }, { { 0, 0 } } },
    { "an index out of range", { { 0.0, false } }, { { 0, 1 } } },
    { "a non-finite value", { { std::nan(""), false }, { 1.0, true } }, { { 0, 1 } } },
  };
  for (const Case& c : cases)
  {
    std::string error;
    const bool ok = program.Solve(c.Nodes, c.Relations, values, error);
    CHECK(!ok && !error.empty());
    std::printf("  %s: \"%s\"\n", c.Name, error.c_str());
  }
}

//------------------------------------------------------------------------------
// The optimum of the program against brute force on tiny graphs: with relations
// x_high - x_low >= margin only, some optimum has every junction value at a node's value
// plus a whole multiple of the margin (at most the longest chain), so trying all of those
// finds the least total change.
TEST_CASE(OptimalAgainstBruteForce)
{
  std::mt19937 random(23);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  JunctionValueProgram program;
  program.MarginFraction = 0.05; // large enough for the margin to matter
  int checked = 0;
  for (int trial = 0; trial < 40; ++trial)
  {
    // Fixed 0 and 1, three junctions in a random order between them, each relation of that
    // order present with probability 1/2 (fixed ends always linked to some junction).
    std::vector<JunctionValueNode> nodes = { { 0.0, true }, { 1.0, true } };
    for (int j = 0; j < 3; ++j)
    {
      nodes.push_back({ 1.4 * unit(random) - 0.2, false });
    }
    std::vector<Index> order = { 2, 3, 4 };
    std::shuffle(order.begin(), order.end(), random);
    std::vector<std::array<Index, 2>> relations = { { 0, order[0] }, { order[2], 1 } };
    for (int x = 0; x < 3; ++x)
    {
      for (int y = x + 1; y < 3; ++y)
      {
        if (unit(random) < 0.5)
        {
          relations.push_back({ order[x], order[y] });
        }
      }
      if (x > 0 && unit(random) < 0.5)
      {
        relations.push_back({ 0, order[x] });
      }
      if (x < 2 && unit(random) < 0.5)
      {
        relations.push_back({ order[x], 1 });
      }
    }
    std::vector<double> values;
    std::string error;
    CHECK(program.Solve(nodes, relations, values, error));
    if (values.size() != nodes.size())
    {
      continue;
    }
    CHECK(SatisfiesRelations(values, relations));
    const double margin = program.Margin;
    std::vector<double> candidates;
    for (const auto& node : nodes)
    {
      for (int d = -4; d <= 4; ++d)
      {
        candidates.push_back(node.Value + d * margin);
      }
    }
    double best = std::numeric_limits<double>::infinity();
    std::vector<double> x = { 0.0, 1.0, 0.0, 0.0, 0.0 };
    for (double a : candidates)
    {
      for (double b : candidates)
      {
        for (double c : candidates)
        {
          x[2] = a;
          x[3] = b;
          x[4] = c;
          bool feasible = true;
          for (const auto& r : relations)
          {
            feasible = feasible && x[r[1]] - x[r[0]] >= margin * (1 - 1e-12);
          }
          if (feasible)
          {
            best = std::min(best, Change(nodes, x));
          }
        }
      }
    }
    CHECK(std::abs(program.TotalChange - best) <= 1e-9);
    CHECK(std::abs(Change(nodes, values) - best) <= 1e-9);
    ++checked;
  }
  CHECK(checked == 40);
}

//------------------------------------------------------------------------------
// A cycle of relations is an order conflict, and the message names the nodes on it in order;
// a real inversion of fixed values is one too; other bad input is not.
TEST_CASE(OrderConflicts)
{
  JunctionValueProgram program;
  std::vector<double> values;
  std::string error;
  // 0 < 1 < 2 < 3 < 1 (a cycle through junctions 1, 2, 3), 3 < 4.
  const std::vector<JunctionValueNode> nodes = { { 0.0, true }, { 0.2, false }, { 0.4, false }, { 0.6, false },
    { 1.0, true } };
  CHECK(!program.Solve(nodes, { { 0, 1 }, { 1, 2 }, { 2, 3 }, { 3, 1 }, { 3, 4 } }, values, error));
  CHECK(program.FoundOrderConflict);
  std::printf("  cycle: \"%s\"\n", error.c_str());
  CHECK(error.find("cycle") != std::string::npos);
  CHECK(error.find("junction node 1 (value 0.2") != std::string::npos);
  CHECK(error.find("junction node 2 (value 0.4") != std::string::npos);
  CHECK(error.find("junction node 3 (value 0.6") != std::string::npos);
  CHECK(error.find("node 0 ") == std::string::npos && error.find("node 4 ") == std::string::npos);
  // The cycle is named in its order: each node is lower than the next.
  const std::size_t one = error.find("junction node 1 "), two = error.find("junction node 2 "),
                    three = error.find("junction node 3 ");
  CHECK((one < two && two < three) || (two < three && three < one) || (three < one && one < two));
  // ... and closes where it starts: "a < b < c < a".
  const std::size_t open = error.find("cycle (") + 7, close = error.find("): ");
  std::vector<std::string> chain;
  for (std::size_t at = open; at < close;)
  {
    const std::size_t next = std::min(error.find(" < ", at), close);
    chain.push_back(error.substr(at, next - at));
    at = next + 3;
  }
  CHECK_EQ(chain.size(), std::size_t(4));
  CHECK(chain.size() == 4 && chain.front() == chain.back() && chain[0] != chain[1] && chain[1] != chain[2]);

  // A critical value below a lower one along a chain of junctions.
  error.clear();
  CHECK(!program.Solve({ { 1.0, true }, { 0.5, false }, { 0.0, true } }, { { 0, 1 }, { 1, 2 } }, values, error));
  CHECK(program.FoundOrderConflict);
  CHECK(error.find("critical node 0") != std::string::npos && error.find("critical node 2") != std::string::npos);

  // Bad input is no order conflict, and a success clears the flag.
  CHECK(!program.Solve({ { 0.0, false } }, { { 0, 1 } }, values, error));
  CHECK(!program.FoundOrderConflict);
  CHECK(!program.Solve(nodes, { { 0, 1 }, { 1, 2 }, { 2, 3 }, { 3, 1 } }, values, error));
  CHECK(program.Solve(nodes, { { 0, 1 }, { 1, 2 }, { 2, 3 }, { 3, 4 } }, values, error));
  CHECK(!program.FoundOrderConflict);
}

//------------------------------------------------------------------------------
TEST_CASE(Timings)
{
  std::mt19937 random(1);
  std::string error;
  int failures = 0;
  auto time = [](auto&& body) {
    const auto start = std::chrono::steady_clock::now();
    body();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  // The junction program on many trees of junctions (like the 1-cells of real complexes),
  // as split components and as one program, and on a long chain (one big component).
  {
    std::vector<JunctionValueNode> nodes;
    std::vector<std::vector<Index>> cells;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int m = 0; m < 100; ++m)
    {
      const Index minimum = static_cast<Index>(nodes.size());
      nodes.push_back({ unit(random), true });
      std::vector<std::vector<Index>> pathTo = { { minimum } };
      for (int j = 0; j < 20; ++j)
      {
        const std::size_t parent = static_cast<std::size_t>(unit(random) * pathTo.size()) % pathTo.size();
        pathTo.push_back(pathTo[parent]);
        pathTo.back().push_back(static_cast<Index>(nodes.size()));
        nodes.push_back({ nodes[minimum].Value + 0.5 * unit(random) - 0.1, false });
      }
      for (int s = 0; s < 8; ++s)
      {
        cells.push_back(pathTo[1 + static_cast<std::size_t>(unit(random) * 20) % 20]);
        cells.back().push_back(static_cast<Index>(nodes.size()));
        nodes.push_back({ nodes[minimum].Value + 0.5 + unit(random), true });
      }
    }
    const auto relations = RelationsOf(cells);
    JunctionValueProgram program;
    std::vector<double> values;
    const double split = time([&]() { failures += !program.Solve(nodes, relations, values, error); });
    CHECK(SatisfiesRelations(values, relations));
    const int programs = program.NumberOfPrograms;
    const int largest = program.LargestProgram;
    program.SplitIntoComponents = false;
    const double single = time([&]() { failures += !program.Solve(nodes, relations, values, error); });
    CHECK(SatisfiesRelations(values, relations));
    std::printf("  junction program, 100 trees of 20 junctions (%zu relations): split %.3f s (%d programs, largest %d "
                "junctions), single program %.3f s\n",
      relations.size(), split, programs, largest, single);
  }
  for (int size : { 200, 2000 })
  {
    std::vector<JunctionValueNode> nodes = { { 0.0, true } };
    std::vector<std::array<Index, 2>> relations;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int j = 1; j <= size; ++j)
    {
      nodes.push_back({ unit(random), false });
      relations.push_back({ j - 1, j });
    }
    nodes.push_back({ 1.0, true });
    relations.push_back({ size, size + 1 });
    JunctionValueProgram program;
    std::vector<double> values;
    const double chain = time([&]() { failures += !program.Solve(nodes, relations, values, error); });
    CHECK(SatisfiesRelations(values, relations));
    std::printf("  junction program, one chain of %d junctions: %.3f s (margin %.2e)\n", size, chain, program.Margin);
  }
  CHECK(failures == 0);
}

int main()
{
  return testing_harness::RunAll();
}
