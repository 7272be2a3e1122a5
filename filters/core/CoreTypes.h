// Shared vocabulary of the pure C++ core: index type and the parallel-loop hook through
// which the VTK layer injects vtkSMPTools (the core itself never includes VTK).
#pragma once

#include <cstdint>
#include <functional>
#include <iterator>
#include <memory>
#include <vector>

namespace topospline
{
// 32-bit ids: a 2D triangulation with 2^31 edges (~700M vertices) is far beyond what fits
// in memory anyway, and halving the id size halves the memory traffic of every pass.
using Index = std::int32_t;
constexpr Index InvalidIndex = -1;

// ParallelFor(begin, end, body) must call body(b, e) on disjoint sub-ranges covering
// [begin, end). Every core loop that uses it writes only to slots owned by its index, so
// the result does not depend on how the range is split (Sequential == STDThread).
using RangeBody = std::function<void(Index, Index)>;
using ParallelFor = std::function<void(Index, Index, const RangeBody&)>;

inline void SequentialFor(Index begin, Index end, const RangeBody& body)
{
  if (begin < end)
  {
    body(begin, end);
  }
}

// For loops whose items append what they find to a list: the items [0, count) in stretches of
// `size` (StretchesOf), the stretches in parallel, body(item, stretch) for each item in order
// within its stretch. Each stretch appends to its own list; joined in stretch order afterwards,
// the lists are what one thread would have made, whatever the split.
inline Index StretchesOf(Index count, Index size)
{
  return count > 0 ? (count + size - 1) / size : 0;
}

template <typename Body>
void ForEachInStretches(Index count, Index size, const ParallelFor& parallel, const Body& body)
{
  parallel(0, StretchesOf(count, size), [&](Index begin, Index end) {
    for (Index s = begin; s < end; ++s)
    {
      for (Index i = s * size; i < count && i < (s + 1) * size; ++i)
      {
        body(i, s);
      }
    }
  });
}

// ForEachInStretches where each item appends to a list: body(item, list) with its stretch's own
// list, the lists joined in stretch order (what one thread would have made).
template <typename T, typename Body>
std::vector<T> CollectInStretches(Index count, Index size, const ParallelFor& parallel, const Body& body)
{
  std::vector<std::vector<T>> stretches(static_cast<std::size_t>(StretchesOf(count, size)));
  ForEachInStretches(count, size, parallel, [&](Index item, Index stretch) { body(item, stretches[stretch]); });
  std::size_t total = 0;
  for (const std::vector<T>& part : stretches)
  {
    total += part.size();
  }
  std::vector<T> joined;
  joined.reserve(total);
  for (std::vector<T>& part : stretches)
  {
    std::move(part.begin(), part.end(), std::back_inserter(joined));
    std::vector<T>().swap(part);
  }
  return joined;
}

// An allocator whose resize() leaves new elements uninitialized (default- rather than value-
// initialized). For the large per-cell arrays that a parallel pass fills completely anyway:
// it saves a sequential zero-fill and lets each thread touch its own pages first.
template <typename T>
struct DefaultInitAllocator : std::allocator<T>
{
  template <typename U>
  struct rebind
  {
    using other = DefaultInitAllocator<U>;
  };
  using std::allocator<T>::allocator;
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args)
  {
    if constexpr (sizeof...(Args) == 0)
    {
      ::new (static_cast<void*>(p)) U;
    }
    else
    {
      ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
  }
};
template <typename T>
using FilledByPassVector = std::vector<T, DefaultInitAllocator<T>>;

// Cooperative cancellation and progress, also injected by the VTK layer.
struct ProgressHooks
{
  std::function<void(double)> Progress;   // fraction in [0,1] of the current algorithm
  std::function<bool()> AbortRequested;   // polled between passes

  void Report(double fraction) const
  {
    if (this->Progress)
    {
      this->Progress(fraction);
    }
  }
  bool Aborted() const { return this->AbortRequested && this->AbortRequested(); }
};
} // namespace topospline
