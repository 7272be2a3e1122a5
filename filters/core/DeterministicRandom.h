// SplitMix64: a tiny, well-distributed generator that gives the same numbers on every platform
// (unlike <random>'s distributions). Synthetic fields and tests use it so that a seed always
// means the same field or the same test cases.
#pragma once

#include <cstdint>

namespace topospline
{
struct DeterministicRandom
{
  std::uint64_t State;
  explicit DeterministicRandom(std::uint64_t seed)
    : State(seed)
  {
  }
  std::uint64_t Next()
  {
    std::uint64_t z = (this->State += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [a, b).
  double Uniform(double a = 0, double b = 1) { return a + (b - a) * ((this->Next() >> 11) * 0x1.0p-53); }
  int Integer(int n) { return static_cast<int>(this->Next() % static_cast<std::uint64_t>(n)); }
};
} // namespace topospline
