// A directed graph in compressed rows, built from its edges by one counting pass.
#pragma once

#include "CoreTypes.h"

#include <array>
#include <numeric>
#include <vector>

namespace topospline
{
// Node n's successors are Targets[Offsets[n] .. Offsets[n + 1]), in the order their edges were
// given (a vector per node cost a second of allocations on 1000^2 noise).
struct CompressedGraph
{
  std::vector<Index> Offsets, Targets;

  CompressedGraph() = default;
  // edges: (from, to) pairs, nodes 0 .. nodes - 1.
  CompressedGraph(Index nodes, const std::vector<std::array<Index, 2>>& edges)
    : Offsets(static_cast<std::size_t>(nodes) + 1, 0)
    , Targets(edges.size())
  {
    for (const auto& edge : edges)
    {
      ++this->Offsets[edge[0] + 1];
    }
    std::partial_sum(this->Offsets.begin(), this->Offsets.end(), this->Offsets.begin());
    std::vector<Index> fill(this->Offsets.begin(), this->Offsets.end() - 1);
    for (const auto& edge : edges)
    {
      this->Targets[fill[edge[0]]++] = edge[1];
    }
  }
  Index Nodes() const { return static_cast<Index>(this->Offsets.size()) - 1; }
  std::size_t Degree(Index n) const { return static_cast<std::size_t>(this->Offsets[n + 1] - this->Offsets[n]); }
  Index Successor(Index n, std::size_t k) const { return this->Targets[this->Offsets[n] + k]; }
};
} // namespace topospline
