#include "JunctionValueProgram.h"

#include "CompressedGraph.h"
#include "DisjointSets.h"
#include "GlpkLinearProgram.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace topospline
{
namespace
{
std::string DescribeNode(const std::vector<JunctionValueNode>& nodes, Index n)
{
  return std::string(nodes[n].Fixed ? "critical node " : "junction node ") + std::to_string(n) + " (value " +
    std::to_string(nodes[n].Value) + ")";
}

// The relations as a graph over the nodes: each relation once, the out-lists in compressed
// rows, and a topological order.
struct RelationGraph
{
  std::vector<std::array<Index, 2>> Relations; // sorted, unique
  std::vector<Index> Offsets;                  // successors of v: Successors[Offsets[v] .. Offsets[v + 1])
  std::vector<Index> Successors;
  std::vector<Index> Order;    // topological
  std::vector<Index> Position; // of every node in Order
};

// The value range of the nodes, which sets the scale of the margin and of the programs.
struct ValueRange
{
  double Minimum = 0;
  double Maximum = 0;
  double Range = 0; // max - min, or a fallback scale when all values are equal
};

bool CheckNodesAndRelations(const std::vector<JunctionValueNode>& nodes,
  const std::vector<std::array<Index, 2>>& lowerThan, std::string& error)
{
  for (const auto& node : nodes)
  {
    if (!std::isfinite(node.Value))
    {
      error = "the junction program got a non-finite node value";
      return false;
    }
  }
  const Index count = static_cast<Index>(nodes.size());
  for (const auto& r : lowerThan)
  {
    if (r[0] < 0 || r[0] >= count || r[1] < 0 || r[1] >= count)
    {
      error = "the junction program got a relation with a node index out of range";
      return false;
    }
    if (r[0] == r[1])
    {
      error = "the junction program got a relation of " + DescribeNode(nodes, r[0]) + " with itself";
      return false;
    }
  }
  return true;
}

// Several 1-cells sharing a stretch give the same relation several times: keeps one, and
// builds the out-lists.
void BuildRelationGraph(Index count, const std::vector<std::array<Index, 2>>& lowerThan, RelationGraph& graph)
{
  std::vector<std::array<Index, 2>>& relations = graph.Relations;
  relations = lowerThan;
  std::sort(relations.begin(), relations.end());
  relations.erase(std::unique(relations.begin(), relations.end()), relations.end());

  CompressedGraph compressed(count, relations);
  graph.Offsets = std::move(compressed.Offsets);
  graph.Successors = std::move(compressed.Targets);
}

// Every leftover node of Kahn's algorithm (inDegree > 0) has a leftover predecessor: walking
// backwards from one must repeat a node, and the walk from there is a cycle, named here.
std::string DescribeCycle(const std::vector<JunctionValueNode>& nodes, const RelationGraph& graph,
  const std::vector<Index>& inDegree)
{
  const Index count = static_cast<Index>(nodes.size());
  std::vector<Index> predecessor(count, InvalidIndex);
  for (const auto& r : graph.Relations)
  {
    if (inDegree[r[0]] > 0 && inDegree[r[1]] > 0)
    {
      predecessor[r[1]] = r[0];
    }
  }
  Index at = 0;
  while (inDegree[at] == 0)
  {
    ++at;
  }
  std::vector<char> seen(count, 0);
  while (!seen[at])
  {
    seen[at] = 1;
    at = predecessor[at];
  }
  std::string cycle = DescribeNode(nodes, at);
  for (Index n = predecessor[at]; n != at; n = predecessor[n])
  {
    cycle = DescribeNode(nodes, n) + " < " + cycle;
  }
  // The cycle closes where it starts: at < (its predecessors' chain) < at.
  return DescribeNode(nodes, at) + " < " + cycle;
}

// Topological order (Kahn); false with the cycle named in `error` when there is none.
bool SortTopologically(const std::vector<JunctionValueNode>& nodes, RelationGraph& graph, std::string& error)
{
  const Index count = static_cast<Index>(nodes.size());
  std::vector<Index>& order = graph.Order;
  std::vector<Index> inDegree(count, 0);
  for (const auto& r : graph.Relations)
  {
    ++inDegree[r[1]];
  }
  order.reserve(count);
  for (Index n = 0; n < count; ++n)
  {
    if (inDegree[n] == 0)
    {
      order.push_back(n);
    }
  }
  for (std::size_t head = 0; head < order.size(); ++head)
  {
    const Index v = order[head];
    for (Index e = graph.Offsets[v]; e < graph.Offsets[v + 1]; ++e)
    {
      if (--inDegree[graph.Successors[e]] == 0)
      {
        order.push_back(graph.Successors[e]);
      }
    }
  }
  if (static_cast<Index>(order.size()) != count)
  {
    error = "the 'lower than' relations of the 1-cells contain a cycle (" + DescribeCycle(nodes, graph, inDegree) +
      "): no strictly monotone values exist";
    return false;
  }
  graph.Position.assign(count, 0);
  for (Index i = 0; i < count; ++i)
  {
    graph.Position[order[i]] = i;
  }
  return true;
}

ValueRange RangeOfValues(const std::vector<JunctionValueNode>& nodes)
{
  const Index count = static_cast<Index>(nodes.size());
  ValueRange result;
  double minimumValue = std::numeric_limits<double>::infinity();
  double maximumValue = -minimumValue;
  for (const auto& node : nodes)
  {
    minimumValue = std::min(minimumValue, node.Value);
    maximumValue = std::max(maximumValue, node.Value);
  }
  double range = count > 0 ? maximumValue - minimumValue : 1.0;
  if (!(range > 0))
  {
    // All values equal: fall back to their magnitude (or 1) as the scale of the margin.
    range = std::max(std::abs(minimumValue), 1.0);
    minimumValue = count > 0 ? minimumValue : 0.0;
  }
  result.Minimum = minimumValue;
  result.Maximum = maximumValue;
  result.Range = range;
  return result;
}

// Value spreading. The complex orders equal values by vertex id (simulation of simplicity),
// but the smoothed 1-cells need numbers that strictly increase, with room for k strictly
// increasing Bezier ordinates in double precision. Where a chain of d relations from a fixed
// node to another rises by less than d * gap (equal critical values on a plateau or a
// constant field, values a few ulps apart in noise), the higher fixed values are raised to
// the smallest values that leave that room, in topological order; nothing moves elsewhere.
// Returns the gap; counts the raised values and the largest raise.
double SpreadTiedFixedValues(std::vector<JunctionValueNode>& nodes, const RelationGraph& graph, ValueRange& range,
  int& spreadCount, double& maximumSpread)
{
  const Index count = static_cast<Index>(nodes.size());
  double scale = 0;
  for (const auto& node : nodes)
  {
    scale = std::max(scale, std::abs(node.Value));
  }
  if (count > 0)
  {
    scale = std::max(scale, range.Maximum - range.Minimum);
  }
  const double gap = JunctionValueProgram::SpreadingGap * (scale > 0 ? scale : 1.0);
  // floor: the least value v can take with room below it; reached: the highest original
  // fixed value below v (ties are spread, an inversion is an error further down).
  std::vector<double> floor(count, -std::numeric_limits<double>::infinity());
  std::vector<double> reached(count, -std::numeric_limits<double>::infinity());
  spreadCount = 0;
  maximumSpread = 0;
  for (const Index v : graph.Order)
  {
    if (nodes[v].Fixed && reached[v] > nodes[v].Value)
    {
      break; // fixed values in the wrong order: reported by the chain check
    }
    const double below = nodes[v].Fixed ? nodes[v].Value : reached[v];
    for (Index e = graph.Offsets[v]; e < graph.Offsets[v + 1]; ++e)
    {
      reached[graph.Successors[e]] = std::max(reached[graph.Successors[e]], below);
    }
    if (nodes[v].Fixed && floor[v] > nodes[v].Value)
    {
      maximumSpread = std::max(maximumSpread, floor[v] - nodes[v].Value);
      ++spreadCount;
      nodes[v].Value = floor[v];
    }
    // a free node can take any value above its floor: its successors only need room above that
    const double level = nodes[v].Fixed ? nodes[v].Value : floor[v];
    for (Index e = graph.Offsets[v]; e < graph.Offsets[v + 1]; ++e)
    {
      floor[graph.Successors[e]] = std::max(floor[graph.Successors[e]], level + gap);
    }
  }
  if (spreadCount > 0)
  {
    range.Maximum = -std::numeric_limits<double>::infinity();
    for (const auto& node : nodes)
    {
      range.Maximum = std::max(range.Maximum, node.Value);
    }
    range.Range = std::max(range.Range, range.Maximum - range.Minimum);
  }
  return gap;
}

// Chains between fixed nodes through free ones: d relations from f_a to f_b need
// f_b - f_a >= d * margin. Longest paths from each fixed node over the free nodes it
// reaches (in topological order) give the tightest chain for every pair: sets `tightestRatio`
// to the least (f_b - f_a) / d. False when fixed nodes are in the wrong order along a chain.
bool FindTightestChain(const std::vector<JunctionValueNode>& nodes, const RelationGraph& graph, double& tightestRatio,
  std::string& error)
{
  const Index count = static_cast<Index>(nodes.size());
  const std::vector<Index>& offsets = graph.Offsets;
  const std::vector<Index>& successors = graph.Successors;
  const std::vector<Index>& position = graph.Position;
  tightestRatio = std::numeric_limits<double>::infinity();
  std::vector<Index> stamp(count, InvalidIndex);
  std::vector<Index> longest(count, 0);
  std::vector<Index> reached;
  for (Index a = 0; a < count; ++a)
  {
    if (!nodes[a].Fixed || offsets[a] == offsets[a + 1])
    {
      continue;
    }
    reached.assign(1, a);
    stamp[a] = a;
    longest[a] = 0;
    for (std::size_t head = 0; head < reached.size(); ++head)
    {
      const Index v = reached[head];
      for (Index e = offsets[v]; e < offsets[v + 1]; ++e)
      {
        const Index w = successors[e];
        if (!nodes[w].Fixed && stamp[w] != a)
        {
          stamp[w] = a;
          longest[w] = 0;
          reached.push_back(w);
        }
      }
    }
    std::sort(reached.begin() + 1, reached.end(), [&position](Index x, Index y) { return position[x] < position[y]; });
    for (const Index v : reached)
    {
      for (Index e = offsets[v]; e < offsets[v + 1]; ++e)
      {
        const Index w = successors[e];
        const Index chain = longest[v] + 1;
        if (!nodes[w].Fixed)
        {
          longest[w] = std::max(longest[w], chain);
          continue;
        }
        const double rise = nodes[w].Value - nodes[a].Value;
        if (!(rise > 0))
        {
          error = "the 1-cells require " + DescribeNode(nodes, a) + " to be strictly lower than " +
            DescribeNode(nodes, w) + " (through " + std::to_string(chain) + " relations): no monotone values exist";
          return false;
        }
        tightestRatio = std::min(tightestRatio, rise / chain);
      }
    }
  }
  return true;
}

// The free nodes' bounds from their fixed neighbours, and the components of the free nodes
// linked by relations (all free nodes in one when not split into components).
struct FreeNodeProblems
{
  std::vector<double> Lower;
  std::vector<double> Upper;
  std::vector<std::vector<Index>> Components;
};

FreeNodeProblems SplitFreeNodes(
  const std::vector<JunctionValueNode>& nodes, const RelationGraph& graph, double margin, bool splitIntoComponents)
{
  const Index count = static_cast<Index>(nodes.size());
  const double infinity = std::numeric_limits<double>::infinity();
  FreeNodeProblems problems;
  std::vector<double>& lower = problems.Lower;
  std::vector<double>& upper = problems.Upper;
  lower.assign(count, -infinity);
  upper.assign(count, infinity);
  std::vector<Index> parent(count);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& r : graph.Relations)
  {
    const bool lowFixed = nodes[r[0]].Fixed;
    const bool highFixed = nodes[r[1]].Fixed;
    if (lowFixed && !highFixed)
    {
      lower[r[1]] = std::max(lower[r[1]], nodes[r[0]].Value + margin);
    }
    else if (!lowFixed && highFixed)
    {
      upper[r[0]] = std::min(upper[r[0]], nodes[r[1]].Value - margin);
    }
    else if (!lowFixed && !highFixed)
    {
      parent[FindRepresentative(parent, r[0])] = FindRepresentative(parent, r[1]);
    }
  }
  std::vector<Index> componentOf(count, InvalidIndex);
  for (Index n = 0; n < count; ++n)
  {
    if (nodes[n].Fixed)
    {
      continue;
    }
    const Index root = splitIntoComponents ? FindRepresentative(parent, n) : 0;
    if (componentOf[root] == InvalidIndex)
    {
      componentOf[root] = static_cast<Index>(problems.Components.size());
      problems.Components.emplace_back();
    }
    problems.Components[componentOf[root]].push_back(n);
  }
  return problems;
}

// The paper's program (section 4, step 1) on one component of free nodes, in normalized
// values y = (x - min) / range so that it is well scaled whatever the units of the field.
bool SolveComponentProgram(const std::vector<Index>& component, const std::vector<JunctionValueNode>& nodes,
  const RelationGraph& graph, const FreeNodeProblems& problems, double margin, const ValueRange& range,
  std::vector<Index>& variableOf, std::vector<double>& values, std::string& error)
{
  const double minimumValue = range.Minimum;
  LinearProgram program;
  const double programInfinity = LinearVariable::infinity();
  auto* objective = program.create_objective(CGAL::Linear_objective<double>::MINIMIZE);
  std::vector<LinearVariable*> variables;
  variables.reserve(component.size());
  for (const Index n : component)
  {
    const double lo =
      std::isfinite(problems.Lower[n]) ? (problems.Lower[n] - minimumValue) / range.Range : -programInfinity;
    const double hi =
      std::isfinite(problems.Upper[n]) ? (problems.Upper[n] - minimumValue) / range.Range : programInfinity;
    variableOf[n] = static_cast<Index>(variables.size());
    variables.push_back(program.create_variable(LinearVariable::CONTINUOUS, lo, hi));
  }
  for (const Index n : component)
  {
    // |y_n - f_n| <= d_n as two rows.
    const double target = (nodes[n].Value - minimumValue) / range.Range;
    LinearVariable* deviation = program.create_variable(LinearVariable::CONTINUOUS, 0.0, programInfinity);
    objective->add_coefficient(deviation, 1.0);
    LinearConstraint* above = program.create_constraint(target, programInfinity);
    above->add_coefficient(deviation, 1.0);
    above->add_coefficient(variables[variableOf[n]], 1.0);
    LinearConstraint* below = program.create_constraint(-target, programInfinity);
    below->add_coefficient(deviation, 1.0);
    below->add_coefficient(variables[variableOf[n]], -1.0);
  }
  for (const Index n : component)
  {
    for (Index e = graph.Offsets[n]; e < graph.Offsets[n + 1]; ++e)
    {
      const Index w = graph.Successors[e];
      if (!nodes[w].Fixed)
      {
        LinearConstraint* rise = program.create_constraint(margin / range.Range, programInfinity);
        rise->add_coefficient(variables[variableOf[w]], 1.0);
        rise->add_coefficient(variables[variableOf[n]], -1.0);
      }
    }
  }
  std::string solverError;
  if (!SolveLinearProgram(program, solverError))
  {
    error = "the linear program of the junction values failed: " + solverError;
    return false;
  }
  const std::vector<double>& solution = program.solution();
  for (const Index n : component)
  {
    values[n] = minimumValue + range.Range * solution[variables[variableOf[n]]->index()];
  }
  return true;
}

// The values of the free nodes: a lone junction in closed form, every other component by its
// program, in parallel (each writes its own nodes' values only; the junction values of 1000^2
// noise took 3.1 s with the programs one after the other). Counts the programs solved and the
// free nodes in the largest.
bool SolveFreeNodes(const std::vector<JunctionValueNode>& nodes, const RelationGraph& graph,
  const FreeNodeProblems& problems, double margin, const ValueRange& range, const ParallelFor& parallel,
  std::vector<double>& values, int& numberOfPrograms, int& largestProgram, std::string& error)
{
  const Index count = static_cast<Index>(nodes.size());
  std::vector<Index> variableOf(count, InvalidIndex);
  const Index components = static_cast<Index>(problems.Components.size());
  std::vector<std::string> errors(problems.Components.size());
  parallel(0, components, [&](Index begin, Index end) {
    for (Index c = begin; c < end; ++c)
    {
      const std::vector<Index>& component = problems.Components[c];
      if (component.size() == 1)
      {
        // min |x - f| within [lower, upper]: the clamp (lower <= upper, see FindTightestChain).
        const Index n = component[0];
        values[n] = std::min(std::max(nodes[n].Value, problems.Lower[n]), problems.Upper[n]);
        continue;
      }
      SolveComponentProgram(component, nodes, graph, problems, margin, range, variableOf, values, errors[c]);
    }
  });
  for (Index c = 0; c < components; ++c)
  {
    if (!errors[c].empty())
    {
      error = errors[c];
      return false;
    }
    if (problems.Components[c].size() > 1)
    {
      ++numberOfPrograms;
      largestProgram = std::max(largestProgram, static_cast<int>(problems.Components[c].size()));
    }
  }
  return true;
}

// GLPK meets the constraints to its tolerance (1e-7 of the range), not exactly. Raise every
// free node to its predecessors + margin (topological order), then lower it to its successors
// - margin (reverse order): the second pass keeps the first one's lower bounds because the
// chains are feasible (checked by FindTightestChain), and nothing moves when the solution
// already satisfies the constraints. False when a relation is still violated.
bool EnforceMargins(const std::vector<JunctionValueNode>& nodes, const RelationGraph& graph, double margin,
  std::vector<double>& values, std::string& error)
{
  for (const Index v : graph.Order)
  {
    for (Index e = graph.Offsets[v]; e < graph.Offsets[v + 1]; ++e)
    {
      const Index w = graph.Successors[e];
      if (!nodes[w].Fixed)
      {
        values[w] = std::max(values[w], values[v] + margin);
      }
    }
  }
  for (auto it = graph.Order.rbegin(); it != graph.Order.rend(); ++it)
  {
    const Index v = *it;
    if (nodes[v].Fixed)
    {
      continue;
    }
    for (Index e = graph.Offsets[v]; e < graph.Offsets[v + 1]; ++e)
    {
      values[v] = std::min(values[v], values[graph.Successors[e]] - margin);
    }
  }
  for (const auto& r : graph.Relations)
  {
    if (!(values[r[1]] - values[r[0]] >= 0.5 * margin))
    {
      error = "the junction values violate the relation " + DescribeNode(nodes, r[0]) + " < " +
        DescribeNode(nodes, r[1]) + " after solving";
      return false;
    }
  }
  return true;
}
} // namespace

//------------------------------------------------------------------------------
bool JunctionValueProgram::Solve(const std::vector<JunctionValueNode>& originalNodes,
  const std::vector<std::array<Index, 2>>& lowerThan, std::vector<double>& values, std::string& error)
{
  std::vector<JunctionValueNode> nodes = originalNodes; // fixed values may be spread below
  this->FoundOrderConflict = false;
  if (!(this->MarginFraction > 0) || !(this->MarginSafety > 0 && this->MarginSafety < 1))
  {
    error = "the junction program needs MarginFraction > 0 and MarginSafety in (0, 1)";
    return false;
  }
  if (!CheckNodesAndRelations(nodes, lowerThan, error))
  {
    return false;
  }
  const Index count = static_cast<Index>(nodes.size());
  RelationGraph graph;
  BuildRelationGraph(count, lowerThan, graph);
  if (!SortTopologically(nodes, graph, error))
  {
    this->FoundOrderConflict = true;
    return false;
  }

  ValueRange range = RangeOfValues(nodes);
  const double gap = SpreadTiedFixedValues(nodes, graph, range, this->SpreadCriticalValues, this->MaximumSpread);
  double tightestRatio = 0;
  if (!FindTightestChain(nodes, graph, tightestRatio, error))
  {
    this->FoundOrderConflict = true;
    return false;
  }
  // At least half the spreading gap: a field whose whole range is a few ulps of its values
  // (near-constant) still needs steps the fits can resolve; the chains allow it (>= gap).
  const double margin =
    std::min(std::max(this->MarginFraction * range.Range, 0.5 * gap), this->MarginSafety * tightestRatio);
  if (!(margin > 0) || !std::isfinite(margin))
  {
    error = "the junction program found no positive margin for the value range " + std::to_string(range.Range);
    return false;
  }

  // The paper's program, split into independent components of free nodes.
  const FreeNodeProblems problems = SplitFreeNodes(nodes, graph, margin, this->SplitIntoComponents);
  values.resize(count);
  for (Index n = 0; n < count; ++n)
  {
    values[n] = nodes[n].Value;
  }
  this->NumberOfPrograms = 0;
  this->LargestProgram = 0;
  if (!SolveFreeNodes(nodes, graph, problems, margin, range, this->Parallel, values, this->NumberOfPrograms,
        this->LargestProgram, error))
  {
    return false;
  }
  if (!EnforceMargins(nodes, graph, margin, values, error))
  {
    return false;
  }

  this->Margin = margin;
  this->TotalChange = 0;
  this->MaximumChange = 0;
  for (Index n = 0; n < count; ++n)
  {
    if (!nodes[n].Fixed)
    {
      const double change = std::abs(values[n] - nodes[n].Value);
      this->TotalChange += change;
      this->MaximumChange = std::max(this->MaximumChange, change);
    }
  }
  return true;
}
} // namespace topospline
