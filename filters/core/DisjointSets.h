// Forest of representatives with path halving: union-find for the 2-cell regions and the
// junction program's components, forwarding pointers (cancelled -> surviving extremum) for
// the simplification.
#pragma once

#include "CoreTypes.h"

#include <algorithm>
#include <numeric>
#include <vector>

namespace topospline
{
// The root of x in the forest `parent` (parent[root] == root), halving the path on the way.
inline Index FindRepresentative(std::vector<Index>& parent, Index x)
{
  while (parent[x] != x)
  {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

struct UnionFind
{
  std::vector<Index> Parent;
  explicit UnionFind(Index n)
    : Parent(n)
  {
    std::iota(this->Parent.begin(), this->Parent.end(), 0);
  }
  // Without path compression: safe to call from several threads at once.
  Index Root(Index x) const
  {
    while (this->Parent[x] != x)
    {
      x = this->Parent[x];
    }
    return x;
  }
  Index Find(Index x) { return FindRepresentative(this->Parent, x); }
  void Union(Index a, Index b)
  {
    a = this->Find(a);
    b = this->Find(b);
    if (a != b)
    {
      // The smaller root wins: the result does not depend on the order of the unions.
      this->Parent[std::max(a, b)] = std::min(a, b);
    }
  }
};
} // namespace topospline
