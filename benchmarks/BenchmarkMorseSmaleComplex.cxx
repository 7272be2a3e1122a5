// Stage 1 core benchmark: extraction time of the pure C++ core on an N x N Shepard field with
// 1 and 2 threads (std::thread), median of repeated runs. Prints figures; asserts nothing.
// Usage: BenchmarkMorseSmaleComplex [resolution=1000] [repeats=5]
#include "MorseSmaleComplexExtraction.h"
#include "SyntheticFields.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

using namespace topospline;

namespace
{
ParallelFor ThreadPool(int threads)
{
  return [threads](Index begin, Index end, const RangeBody& body) {
    std::vector<std::thread> workers;
    const Index chunk = (end - begin + threads - 1) / threads;
    for (int k = 1; k < threads; ++k)
    {
      const Index b = begin + k * chunk, e = std::min(end, b + chunk);
      if (b < e)
      {
        workers.emplace_back([&body, b, e] { body(b, e); });
      }
    }
    body(begin, std::min(end, begin + chunk));
    for (auto& w : workers)
    {
      w.join();
    }
  };
}
}

int main(int argc, char** argv)
{
  const int resolution = argc > 1 ? std::atoi(argv[1]) : 1000;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 5;
  const GridField grid = ShepardField(50, 2, resolution, 1);
  PlanarScalarField field;
  for (int j = 0; j < resolution; ++j)
  {
    for (int i = 0; i < resolution; ++i)
    {
      field.Points.push_back(i);
      field.Points.push_back(j);
    }
  }
  field.Values = grid.Values;
  field.GridDimensions[0] = field.GridDimensions[1] = resolution; // as for image data
  std::printf("Morse-Smale complex extraction (core only), Shepard %d x %d, median of %d runs\n", resolution,
    resolution, repeats);
  for (int threads : { 1, 2 })
  {
    std::vector<double> times;
    MorseSmaleComplex complex;
    for (int r = 0; r < repeats; ++r)
    {
      MorseSmaleComplexExtraction extraction;
      extraction.Parallel = threads == 1 ? ParallelFor(SequentialFor) : ThreadPool(threads);
      std::string error;
      const auto start = std::chrono::steady_clock::now();
      extraction.Extract(field, complex, error);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::sort(times.begin(), times.end());
    const auto n = complex.CountByIndex();
    std::printf("  threads %d: %.3f s (min %.3f)  [%d minima, %d saddles, %d maxima, %zu 2-cells]\n", threads,
      times[times.size() / 2], times.front(), n[0], n[1], n[2], complex.TwoCells.size());
  }
  return 0;
}
