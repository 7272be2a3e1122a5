// Tests of stage 4 from end to end (FieldReconstruction, as "Reconstruct 2-Cells" runs it) on
// the output of the real stages 1-3, against oracles written here:
// - the error figures equal those recomputed from the values and the input;
// - the finer grid spans the input grid exactly, and without topological sampling its values
//   are F o Phi itself (evaluated here through the same cells at the same points);
// - topological sampling only changes values, never F o Phi (Exact equals the values of a run
//   without it), and the counts it reports are the differences counted here;
// - the verdict: when it is 1, an independent count of the sampled field's interior PL minima
//   and maxima (lower/upper links, written here) equals the complex's interior extrema;
// - the same report with one thread and several (also on noise, where the sampling's walks,
//   1-cell samples and saddle matching run in stretches);
// - an abort asked during the sampling ends the run between two of its passes, and the passes
//   over the cells report their progress slice by slice;
// - saddles on their nodes: on weak noise (monkey saddles, saddles a vertex apart), every
//   interior saddle of the complex has one of the sampling's within one edge and the other way
//   round (PL multiplicities and one-to-one pairings written here);
// - the stiffening rounds: F o Phi has fewer PL critical points deep inside the cells (counted
//   here) at a small cost in RMS;
// - an image of spacing 0.01 x 3 is reconstructed and verified (in the complex's frame), its
//   outputs in the image's coordinates.
//
// Usage: TestFieldReconstruction
// Prints figures per case, then "N passed, N failed"; returns nonzero on failure.
#include "FieldReconstruction.h"
#include "MorseSmaleComplexExtraction.h"
#include "TopologicalSampling.h"
#include "TestSupport.h"
#include "TestHarness.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <numeric>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <random>
#include <string>
#include <vector>

using namespace topospline;

namespace
{
// Which of the six neighbours of interior vertex (i, j), in turning order (E, N, NW, W, S, SE),
// lie below it, for a grid field triangulated along the (i+1,j)-(i,j+1) diagonals, ties broken
// by vertex id (as the simulation of simplicity of stage 1).
std::array<bool, 6> LowerLink(const std::vector<double>& f, int nx, int i, int j)
{
  const int di[6] = { 1, 0, -1, -1, 0, 1 }, dj[6] = { 0, 1, 1, 0, -1, -1 };
  const int v = j * nx + i;
  std::array<bool, 6> below;
  for (int k = 0; k < 6; ++k)
  {
    const int w = (j + dj[k]) * nx + i + di[k];
    below[k] = f[w] < f[v] || (f[w] == f[v] && w < v);
  }
  return below;
}

// How often interior vertex (i, j)'s link changes between lower and upper neighbours (LowerLink):
// 2 at a regular vertex, 0 at an extremum, 2 + 2m at a saddle of multiplicity m.
int LinkChanges(const std::vector<double>& f, int nx, int i, int j)
{
  const std::array<bool, 6> below = LowerLink(f, nx, i, j);
  int changes = 0;
  for (int k = 0; k < 6; ++k)
  {
    changes += below[k] != below[(k + 1) % 6] ? 1 : 0;
  }
  return changes;
}

// Interior PL minima and maxima of a grid field (LowerLink).
std::array<int, 2> InteriorExtrema(const PlanarScalarField& field)
{
  const int nx = field.GridDimensions[0], ny = field.GridDimensions[1];
  std::array<int, 2> counts{ 0, 0 };
  for (int j = 1; j + 1 < ny; ++j)
  {
    for (int i = 1; i + 1 < nx; ++i)
    {
      const std::array<bool, 6> below = LowerLink(field.Values, nx, i, j);
      const auto lower = std::count(below.begin(), below.end(), true);
      counts[0] += lower == 0 ? 1 : 0;
      counts[1] += lower == 6 ? 1 : 0;
    }
  }
  return counts;
}

std::array<int, 2> InteriorExtrema(const MorseSmaleComplex& complex)
{
  std::array<int, 2> counts{ 0, 0 };
  for (const auto& cp : complex.CriticalPoints)
  {
    if (!cp.OnBoundary && cp.MorseIndex != 1)
    {
      ++counts[cp.MorseIndex / 2];
    }
  }
  return counts;
}

void CheckCase(const char* name, const GridField& grid, double percent, int k, int resolution)
{
  Pipeline p;
  std::string error;
  CHECK(RunStages1To3(grid, percent, k, p, error));
  if (!error.empty())
  {
    std::printf("  %s: %s\n", name, error.c_str());
    return;
  }
  FieldReconstruction reconstruction;
  reconstruction.OutputResolution = resolution;
  FieldReconstructionReport report;
  CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
  const std::size_t n = p.Field.Values.size();
  CHECK_EQ(report.Values.size(), n);
  CHECK_EQ(report.Exact.size(), n);
  CHECK_EQ(report.CellOfVertex.size(), n);

  // Errors, recomputed.
  double largest = 0, squares = 0;
  bool differences = true;
  for (std::size_t v = 0; v < n; ++v)
  {
    const double d = report.Values[v] - p.Field.Values[v];
    differences = differences && report.Difference[v] == d;
    largest = std::max(largest, std::abs(d));
    squares += d * d;
  }
  CHECK(differences);
  CHECK(report.MaximumError == largest);
  CHECK(std::abs(report.RMSError - std::sqrt(squares / n)) <= 1e-12 * (1 + report.RMSError));
  CHECK(report.ValueRange[1] - report.ValueRange[0] == p.Range);

  // Topological sampling: the changes it reports are the ones made.
  std::size_t changed = 0;
  double largestChange = 0;
  for (std::size_t v = 0; v < n; ++v)
  {
    if (report.Values[v] != report.Exact[v])
    {
      ++changed;
      largestChange = std::max(largestChange, std::abs(report.Values[v] - report.Exact[v]));
    }
  }
  if (resolution == 1)
  {
    CHECK_EQ(static_cast<std::size_t>(report.Sampling.ChangedVertices), changed);
    CHECK(report.Sampling.MaximumChange == largestChange);
  }
  else
  {
    CHECK(static_cast<std::size_t>(report.Sampling.ChangedVertices) >= changed);
    CHECK(report.Sampling.MaximumChange >= largestChange);
  }

  // The finer grid spans the input grid.
  const int nx = p.Field.GridDimensions[0], ny = p.Field.GridDimensions[1];
  if (resolution > 1)
  {
    CHECK_EQ(report.Finer.Dimensions[0], (nx - 1) * resolution + 1);
    CHECK_EQ(report.Finer.Dimensions[1], (ny - 1) * resolution + 1);
    CHECK_EQ(report.Finer.Values.size(),
      static_cast<std::size_t>(report.Finer.Dimensions[0]) * static_cast<std::size_t>(report.Finer.Dimensions[1]));
    const double* last = &p.Field.Points[2 * (n - 1)];
    for (int axis = 0; axis < 2; ++axis)
    {
      CHECK(report.Finer.Origin[axis] == p.Field.Points[axis]);
      const double end = report.Finer.Origin[axis] + (report.Finer.Dimensions[axis] - 1) * report.Finer.Spacing[axis];
      CHECK(std::abs(end - last[axis]) <= 1e-9 * (1 + std::abs(last[axis])));
    }
  }

  // Without topological sampling the values are F o Phi itself: the Exact of the run above.
  FieldReconstruction raw;
  raw.OutputResolution = resolution;
  raw.TopologicalSampling = false;
  raw.VerifyTopology = false;
  FieldReconstructionReport rawReport;
  CHECK(raw.Run(p.Field, p.Simplified.Complex, p.Smoothed, rawReport, error));
  CHECK(rawReport.Values == report.Exact);
  CHECK(rawReport.Exact.empty() && !rawReport.Sampled && !rawReport.VerificationRan);

  // One thread or several: the same report.
  FieldReconstruction threaded;
  threaded.OutputResolution = resolution;
  threaded.Parallel = ThreadedFor;
  FieldReconstructionReport threadedReport;
  CHECK(threaded.Run(p.Field, p.Simplified.Complex, p.Smoothed, threadedReport, error));
  CHECK(threadedReport.Values == report.Values);
  CHECK(threadedReport.Finer.Values == report.Finer.Values);
  CHECK(threadedReport.Verified == report.Verified);

  // The verdict, against an independent count.
  PlanarScalarField sampled = p.Field;
  sampled.Values = report.Values;
  const auto found = InteriorExtrema(sampled);
  const auto wanted = InteriorExtrema(p.Simplified.Complex);
  std::printf("  %s %g%% k=%d x%d: %d cells (%d failed), verdict %d, interior minima %d/%d maxima %d/%d, "
              "max error %.3g, RMS %.3g, %d vertices changed by sampling\n",
    name, percent, k, resolution, report.Cells.Cells, report.Cells.FailedCells, report.Verified ? 1 : 0, found[0],
    wanted[0], found[1], wanted[1], report.MaximumError, report.RMSError, report.Sampling.ChangedVertices);
  CHECK(report.Verified);
  if (report.Verified)
  {
    CHECK(found == wanted);
  }
}
} // namespace

TEST_CASE(ThreadsGiveTheSameSamplingOnNoise)
{
  // Topological sampling walks the 1-cells, samples them and matches the saddles in parallel,
  // over stretches of a few hundred 1-cells and a few thousand saddles, and merges what each
  // stretch found: the merge must not depend on the threads. Noise large enough for several
  // stretches, with saddles left off their nodes after the first pass (the other carvings, the
  // relocations and the moves of displaced saddles run), one thread against four: the same
  // values bit for bit and the same report.
  Pipeline p;
  std::string error;
  CHECK(RunStages1To3(UniformNoise(130, 2), 2.0, 4, p, error));
  int saddles = 0;
  for (const CriticalPoint& cp : p.Simplified.Complex.CriticalPoints)
  {
    saddles += cp.MorseIndex == 1 ? 1 : 0;
  }
  FieldReconstruction sequential, threaded;
  threaded.Parallel = ThreadedFor;
  FieldReconstructionReport one, four;
  CHECK(sequential.Run(p.Field, p.Simplified.Complex, p.Smoothed, one, error));
  CHECK(threaded.Run(p.Field, p.Simplified.Complex, p.Smoothed, four, error));
  std::printf("  130^2 noise at 2 %%: %d saddles, %d 1-cells, %d vertices changed by sampling, %d boundary and %d "
              "interior saddles moved\n",
    saddles, static_cast<int>(p.Simplified.Complex.OneCells.size()), static_cast<int>(one.Sampling.ChangedVertices),
    one.Sampling.MovedBoundarySaddles, one.Sampling.MovedInteriorSaddles);
  CHECK(saddles > 4096);                                       // the saddles are matched in two stretches
  CHECK(p.Simplified.Complex.OneCells.size() > 16 * 256);     // the 1-cells walked in many
  CHECK(one.Sampling.MovedInteriorSaddles > 0);               // saddles were off after the first pass
  CHECK(four.Sampling.MovedInteriorSaddles == one.Sampling.MovedInteriorSaddles);
  CHECK(four.Sampling.MovedBoundarySaddles == one.Sampling.MovedBoundarySaddles);
  CHECK(four.Values == one.Values);
  CHECK(four.Exact == one.Exact);
  CHECK(four.Sampling.ChangedVertices == one.Sampling.ChangedVertices);
  CHECK(four.Sampling.MaximumChange == one.Sampling.MaximumChange);
  CHECK(four.Sampling.DisplacedSaddles == one.Sampling.DisplacedSaddles);
  CHECK(four.Verified == one.Verified);
}

TEST_CASE(AnAbortStopsTheSamplingBetweenItsPasses)
{
  // Topological sampling and the checks after it take seconds on large noise with no other
  // stage to poll an abort: an abort asked once the 2-cells are done, or once the sampling's
  // first pass is, must end the run with "aborted" before the sampling ends (the progress
  // reported stays below the sampling's end, 0.7). Without an abort the progress rises to 1.
  Pipeline p;
  std::string error;
  CHECK(RunStages1To3(UniformNoise(48, 3), 2.0, 4, p, error));
  for (const double abortAt : { 0.6, 0.64 })
  {
    FieldReconstruction reconstruction;
    double last = 0;
    bool rising = true;
    int polledInSampling = 0;
    reconstruction.Hooks.Progress = [&](double f) {
      rising = rising && f >= last;
      last = f;
    };
    reconstruction.Hooks.AbortRequested = [&]() {
      polledInSampling += last >= 0.6 ? 1 : 0;
      return last >= abortAt;
    };
    FieldReconstructionReport report;
    error.clear();
    const bool ran = reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error);
    std::printf("  abort from progress %.2f: run %s (%s), last progress %.3f, polled %d times from 0.6 on\n", abortAt,
      ran ? "finished" : "stopped", error.c_str(), last, polledInSampling);
    CHECK(!ran && error == "aborted");
    // Asked at 0.6 the sampling does not start a pass; asked after its first pass (0.64), it
    // does not start a second.
    CHECK(last >= abortAt && last < (abortAt < 0.64 ? 0.64 : 0.7));
    CHECK(rising);
  }
  FieldReconstruction whole;
  double last = 0;
  whole.Hooks.Progress = [&](double f) { last = f; };
  whole.Hooks.AbortRequested = []() { return false; };
  FieldReconstructionReport report;
  CHECK(whole.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
  CHECK(last == 1.0 && !report.Sampling.Aborted);
}

TEST_CASE(TheCellPassesReportProgressAsTheyGo)
{
  // The passes over the 2-cells (meshes and maps, surfaces, stiffening) report their progress
  // slice by slice on the calling thread (a pass over half a million cells takes a minute): on
  // 100² noise, a report per slice of 256 cells in each pass, rising, within the cells' share of
  // the reconstruction (0-0.6), and the same values as a run that reports nothing.
  Pipeline p;
  std::string error;
  CHECK(RunStages1To3(UniformNoise(100, 5), 2.0, 4, p, error));
  FieldReconstruction reconstruction;
  std::vector<double> reports;
  reconstruction.Hooks.Progress = [&](double f) { reports.push_back(f); };
  FieldReconstructionReport report;
  CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
  const int cells = static_cast<int>(p.Simplified.Complex.TwoCells.size());
  const long inCells = std::count_if(reports.begin(), reports.end(), [](double f) { return f < 0.6; });
  std::printf("  %d cells: %d progress reports, %ld of them during the cell passes\n", cells,
    static_cast<int>(reports.size()), inCells);
  CHECK(cells > 4 * 256);
  CHECK(inCells >= 2 * ((cells + 255) / 256)); // every slice of the first two passes at least
  CHECK(std::is_sorted(reports.begin(), reports.end()));
  CHECK(!reports.empty() && reports.front() >= 0 && reports.back() == 1.0);
  FieldReconstruction silent;
  FieldReconstructionReport quiet;
  CHECK(silent.Run(p.Field, p.Simplified.Complex, p.Smoothed, quiet, error));
  CHECK(quiet.Values == report.Values);
}

// Constant fields and fields varying by 1e-13 of their magnitude (read as constant by stage 1,
// as the filter asks) at every k: the reconstruction is flat at the complex's value, within the
// input's range, every vertex covered, no cell failed, verified. (At k = 30 a constant field's
// one 2-cell needed a Sibson grid of over 500 steps for a rise of 1e-11: it failed.) The
// oracle: the flat output has, ties broken by vertex id as here, the interior extrema of the
// complex (none), and its values are checked one by one.
TEST_CASE(ConstantFieldsAreReconstructedFlat)
{
  DeterministicRandom random(3);
  for (const double scale : { 0.0, 1e-13 })
  {
    for (const int k : { 2, 4, 30 })
    {
      GridField grid;
      grid.Dimensions[0] = 20;
      grid.Dimensions[1] = 15;
      for (int v = 0; v < 20 * 15; ++v)
      {
        grid.Values.push_back(1.0 + scale * random.Uniform());
      }
      Pipeline p;
      std::string error;
      CHECK(RunStages1To3(grid, 10, k, p, error, true));
      CHECK(p.ReadAsConstant == (scale > 0));
      FieldReconstruction reconstruction;
      FieldReconstructionReport report;
      CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
      const auto [lowest, highest] = std::minmax_element(grid.Values.begin(), grid.Values.end());
      const double value = report.Values.empty() ? -1 : report.Values.front();
      CHECK(value >= *lowest && value <= *highest);
      CHECK(std::all_of(report.Values.begin(), report.Values.end(), [&](double v) { return v == value; }));
      CHECK(report.MaximumError <= *highest - *lowest);
      CHECK(report.FailedCells.empty() && report.UnreconstructedPoints == 0);
      CHECK(report.Verified);
      PlanarScalarField sampled = p.Field;
      sampled.Values = report.Values;
      CHECK(InteriorExtrema(sampled) == InteriorExtrema(p.Simplified.Complex));
      std::printf("  constant + %g x noise, k = %d: flat at %.17g, verdict %d\n", scale, k, value,
        report.Verified ? 1 : 0);
    }
  }
}

TEST_CASE(ShepardAtTwoThresholds)
{
  CheckCase("shepard", ShepardField(50, 2.0, 120, 3), 5, 4, 1);
  CheckCase("shepard", ShepardField(50, 2.0, 120, 3), 25, 7, 2);
}

TEST_CASE(TrigonometricAtTwoThresholds)
{
  CheckCase("trigonometric", TrigonometricField(10, 100, -49), 0, 4, 2);
  CheckCase("trigonometric", TrigonometricField(10, 100, -49), 25, 4, 1);
}

namespace
{
struct Fidelity
{
  double Maximum = 0; // of Reconstructed, fraction of the range
  double RMS = 0;
  double ExactMaximum = 0; // of F o Phi
  Index FarSpurious = 0;
};

// Errors against the input, recomputed here from the values the report gives.
Fidelity Measure(const GridField& grid, double percent, int k, TwoCellInterior interior)
{
  Pipeline p;
  std::string error;
  Fidelity result;
  CHECK(RunStages1To3(grid, percent, k, p, error));
  FieldReconstruction reconstruction;
  reconstruction.Interior = interior;
  reconstruction.Parallel = ThreadedFor;
  FieldReconstructionReport report;
  CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
  CHECK(report.Verified);
  double squares = 0;
  for (std::size_t v = 0; v < p.Field.Values.size(); ++v)
  {
    const double d = std::abs(report.Values[v] - p.Field.Values[v]);
    result.Maximum = std::max(result.Maximum, d / p.Range);
    result.ExactMaximum = std::max(result.ExactMaximum, std::abs(report.Exact[v] - p.Field.Values[v]) / p.Range);
    squares += d * d;
  }
  result.RMS = std::sqrt(squares / p.Field.Values.size()) / p.Range;
  result.FarSpurious = report.RawSpuriousFarFromOneCells;
  return result;
}
} // namespace

TEST_CASE(FittedInteriorsFollowTheData)
{
  // The Trigonometric Field with nothing removed: the fitted surface itself (F o Phi) within 2 %
  // of the range everywhere, where the paper's boundary-only interior is off by a third.
  const GridField trig = TrigonometricField(10, 100, -49);
  const Fidelity fitted = Measure(trig, 0, 4, TwoCellInterior::Fitted);
  const Fidelity paper = Measure(trig, 0, 4, TwoCellInterior::Paper);
  std::printf("  trigonometric 0%%: F o Phi max error %.2f %% (paper %.2f %%), RMS %.2f %% (paper %.2f %%), "
              "%d spurious critical points far from the 1-cells\n",
    100 * fitted.ExactMaximum, 100 * paper.ExactMaximum, 100 * fitted.RMS, 100 * paper.RMS, fitted.FarSpurious);
  CHECK(fitted.ExactMaximum <= 0.02);
  CHECK(fitted.RMS <= 0.005);
  CHECK(paper.ExactMaximum > 0.1);
  CHECK(fitted.FarSpurious == 0);
  // Shepard fields at 5 %: RMS within 2 % of the range, at most half the paper's.
  for (std::uint64_t seed : { 0, 1, 2, 3 })
  {
    const GridField shepard = ShepardField(40, 2.0, 250, seed);
    const Fidelity f = Measure(shepard, 5, 4, TwoCellInterior::Fitted);
    const Fidelity q = Measure(shepard, 5, 4, TwoCellInterior::Paper);
    std::printf("  shepard seed %d 5%%: RMS %.2f %% (paper %.2f %%), max %.2f %% (paper %.2f %%)\n",
      static_cast<int>(seed), 100 * f.RMS, 100 * q.RMS, 100 * f.Maximum, 100 * q.Maximum);
    CHECK(f.RMS <= 0.02);
    CHECK(f.RMS <= 0.5 * q.RMS);
  }
}

namespace
{
// PL critical vertices of `f` (LowerLink: a regular vertex's link changes between lower and
// upper exactly twice) whose 5 x 5 box of vertices lies in one reconstructed cell: no smoothed
// 1-cell passes within two spacings, so no node of the complex can explain them.
int CriticalDeepInsideCells(const std::vector<double>& f, const std::vector<Index>& cellOf, int nx, int ny)
{
  int count = 0;
  for (int j = 2; j + 2 < ny; ++j)
  {
    for (int i = 2; i + 2 < nx; ++i)
    {
      bool deep = cellOf[j * nx + i] != InvalidIndex;
      for (int dj = -2; deep && dj <= 2; ++dj)
      {
        for (int di = -2; deep && di <= 2; ++di)
        {
          deep = cellOf[(j + dj) * nx + i + di] == cellOf[j * nx + i];
        }
      }
      if (!deep)
      {
        continue;
      }
      count += LinkChanges(f, nx, i, j) != 2 ? 1 : 0;
    }
  }
  return count;
}

// Reconstructs p's complex with the given stiffening and ordering rounds (verdict 1 checked):
// the critical points of F o Phi deep inside the cells (CriticalDeepInsideCells), the RMS of
// Reconstructed against the input in units of the range, and the cells the rounds changed.
struct DeepCriticalPoints
{
  int Deep = 0;
  double RMS = 0;
  Index StiffenedCells = 0;
  Index OrderedCells = 0;
};

DeepCriticalPoints CountDeepCriticalPoints(const GridField& field, const Pipeline& p, int stiffening, int ordering)
{
  FieldReconstruction reconstruction;
  reconstruction.Parallel = ThreadedFor;
  reconstruction.StiffeningRounds = stiffening;
  reconstruction.OrderingRounds = ordering;
  FieldReconstructionReport report;
  std::string error;
  CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
  CHECK(report.Verified);
  DeepCriticalPoints count;
  count.Deep = CriticalDeepInsideCells(report.Exact, report.CellOfVertex, field.Dimensions[0], field.Dimensions[1]);
  double squares = 0;
  for (std::size_t v = 0; v < p.Field.Values.size(); ++v)
  {
    squares += (report.Values[v] - p.Field.Values[v]) * (report.Values[v] - p.Field.Values[v]);
  }
  count.RMS = std::sqrt(squares / p.Field.Values.size()) / p.Range;
  count.StiffenedCells = report.Cells.StiffenedCells;
  count.OrderedCells = report.Cells.OrderedCells;
  return count;
}

// Shepard 150^2 fields (40 sites, mu = 2) of seeds [first, last) through stages 1-3 (k = 4), each
// at percentOf(seed): body(seed, percent, field, pipeline).
void ForShepardFields150(std::uint64_t first, std::uint64_t last, const std::function<int(std::uint64_t)>& percentOf,
  const std::function<void(std::uint64_t, int, const GridField&, Pipeline&)>& body)
{
  for (std::uint64_t seed = first; seed < last; ++seed)
  {
    const GridField shepard = ShepardField(40, 2.0, 150, seed);
    const int percent = percentOf(seed);
    Pipeline p;
    std::string error;
    CHECK(RunStages1To3(shepard, percent, 4, p, error));
    body(seed, percent, shepard, p);
  }
}

// Odd seeds at 5 %, even ones at 25 %.
int FiveOrTwentyFive(std::uint64_t seed)
{
  return seed % 2 ? 5 : 25;
}
} // namespace

TEST_CASE(StiffeningTakesCrestsOutOfTheCells)
{
  // Where the monotonicity rows bind against falling data (a cancelled pit), the fit makes a
  // crest that rises slowly along its top; sampled at the vertices it breaks into pairs of
  // critical points deep inside the cell. The stiffening rounds widen such crests: F o Phi at
  // the vertices has far fewer critical points deep inside the cells, at a small cost in RMS.
  int before = 0, after = 0;
  ForShepardFields150(0, 4, [](std::uint64_t) { return 25; }, [&](std::uint64_t seed, int, const GridField& shepard, Pipeline& p) {
    const DeepCriticalPoints plain = CountDeepCriticalPoints(shepard, p, 0, 0);
    const DeepCriticalPoints stiffened = CountDeepCriticalPoints(shepard, p, 5, 0);
    CHECK(plain.StiffenedCells == 0);
    CHECK(stiffened.StiffenedCells > 0 || plain.Deep == 0);
    std::printf("  shepard 150^2 seed %d at 25 %%: %d -> %d critical points of F o Phi deep inside the cells, "
                "RMS %.2f -> %.2f %% of the range\n",
      static_cast<int>(seed), plain.Deep, stiffened.Deep, 100 * plain.RMS, 100 * stiffened.RMS);
    CHECK(stiffened.Deep <= plain.Deep);
    CHECK(stiffened.RMS <= 1.15 * plain.RMS);
    before += plain.Deep;
    after += stiffened.Deep;
  });
  CHECK(before > 0);
  CHECK(2 * after <= before);
}

TEST_CASE(OrderingTakesOutWhatStiffeningLeaves)
{
  // After the stiffening rounds, the ordering rounds ask the neighbours of each critical point
  // left to lie above or below it along the local rise: F o Phi at the vertices has fewer
  // critical points deep inside the cells, none more on any field, for about the same RMS.
  // Shepard fields nothing was tuned on (seeds 40-43), at 25 % and 5 %.
  int before = 0, after = 0;
  ForShepardFields150(40, 44, FiveOrTwentyFive, [&](std::uint64_t seed, int percent, const GridField& shepard, Pipeline& p) {
    const DeepCriticalPoints stiffened = CountDeepCriticalPoints(shepard, p, 5, 0);
    const DeepCriticalPoints ordered = CountDeepCriticalPoints(shepard, p, 5, FieldReconstruction().OrderingRounds);
    CHECK(stiffened.OrderedCells == 0);
    CHECK(ordered.Deep == stiffened.Deep || ordered.OrderedCells > 0);
    std::printf("  shepard 150^2 seed %d at %d %%: %d -> %d critical points of F o Phi deep inside the cells, "
                "RMS %.3f -> %.3f %% of the range\n",
      static_cast<int>(seed), percent, stiffened.Deep, ordered.Deep, 100 * stiffened.RMS, 100 * ordered.RMS);
    CHECK(ordered.Deep <= stiffened.Deep);
    CHECK(ordered.RMS <= 1.05 * stiffened.RMS);
    before += stiffened.Deep;
    after += ordered.Deep;
  });
  CHECK(before > 0);
  CHECK(after < before);
}

namespace
{
// Interior PL critical vertices of `f` (LowerLink) farther than two spacings of grid `p.Field`
// from every smoothed 1-cell, each curve sampled 32 times per Bezier segment (the distance by
// brute force: the test's own, not the reconstruction's count).
int CriticalFarFromOneCells(const std::vector<double>& f, const Pipeline& p, int nx, int ny)
{
  std::vector<double> curve;
  for (const SmoothedPiece& piece : p.Smoothed.Pieces)
  {
    for (int s = 0; s <= 32 * piece.Curve.Segments; ++s)
    {
      double xy[2];
      piece.Curve.Evaluate(static_cast<double>(s) / (32 * piece.Curve.Segments), xy);
      curve.insert(curve.end(), xy, xy + 2);
    }
  }
  const double reach = 2 * std::max(p.Field.GridSpacing[0], p.Field.GridSpacing[1]);
  int count = 0;
  for (int j = 1; j + 1 < ny; ++j)
  {
    for (int i = 1; i + 1 < nx; ++i)
    {
      if (LinkChanges(f, nx, i, j) == 2)
      {
        continue;
      }
      const double* at = &p.Field.Points[2 * static_cast<std::size_t>(j * nx + i)];
      bool far = true;
      for (std::size_t c = 0; far && c < curve.size(); c += 2)
      {
        far = std::hypot(curve[c] - at[0], curve[c + 1] - at[1]) > reach;
      }
      count += far ? 1 : 0;
    }
  }
  return count;
}
} // namespace

TEST_CASE(CriticalPointsTwoSpacingsFromTheOneCellsAreTreatedToo)
{
  // Two rings of grid neighbours reach only two spacings along the axes: a critical point of
  // F o Phi 2-3 spacings from a 1-cell, which no node explains either, was left to topological
  // sampling. With FarFromOneCellsSpacings the stiffening and ordering rounds treat it too,
  // after the points two rings inside and only within 10 % of the largest residual of the
  // cell's first fit.
  // Shepard fields nothing was tuned on (seeds 52-59), odd at 5 %, even at 25 %.
  int before = 0, after = 0;
  ForShepardFields150(52, 60, FiveOrTwentyFive, [&](std::uint64_t seed, int percent, const GridField& shepard, Pipeline& p) {
    FieldReconstructionReport reports[2];
    for (int run = 0; run < 2; ++run)
    {
      FieldReconstruction reconstruction;
      reconstruction.Parallel = ThreadedFor;
      reconstruction.FarFromOneCellsSpacings = run == 0 ? 0 : 2;
      std::string error;
      CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, reports[run], error));
      CHECK(reports[run].Verified);
    }
    const int nx = shepard.Dimensions[0], ny = shepard.Dimensions[1];
    const int far[2] = { CriticalFarFromOneCells(reports[0].Exact, p, nx, ny),
      CriticalFarFromOneCells(reports[1].Exact, p, nx, ny) };
    double rms[2] = { 0, 0 }, largest[2] = { 0, 0 };
    for (int run = 0; run < 2; ++run)
    {
      for (std::size_t v = 0; v < p.Field.Values.size(); ++v)
      {
        const double d = std::abs(reports[run].Values[v] - p.Field.Values[v]);
        rms[run] += d * d;
        largest[run] = std::max(largest[run], d);
      }
      rms[run] = std::sqrt(rms[run] / p.Field.Values.size()) / p.Range;
      largest[run] /= p.Range;
    }
    std::printf("  shepard 150^2 seed %d at %d %%: %d -> %d critical points of F o Phi over two spacings from the "
                "1-cells, RMS %.3f -> %.3f %%, largest error %.2f -> %.2f %% of the range\n",
      static_cast<int>(seed), percent, far[0], far[1], 100 * rms[0], 100 * rms[1], 100 * largest[0], 100 * largest[1]);
    // Each cell's rounds may cost up to StiffeningResidualGrowth (1.25) of its fit's RMS; over a
    // field the cost is a few percent (seed 54 at 25 %: 2.63 -> 2.71 %).
    CHECK(rms[1] <= 1.05 * rms[0]);
    CHECK(largest[1] <= 1.05 * largest[0]);
    before += far[0];
    after += far[1];
  });
  CHECK(before > 0);
  CHECK(after < before);
}

namespace
{
// Two reconstructions of one complex, compared cell by cell from F o Phi at the vertices and the
// cell that gave each value: per cell the largest miss and the sum of squared misses in each run,
// and whether any value changed; per run the largest miss of F o Phi and of Reconstructed.
struct CellByCell
{
  std::vector<double> Miss[2], Squares[2];
  std::vector<char> Changed;
  double Largest[2] = { 0, 0 }, Reconstructed[2] = { 0, 0 };

  // The number of cells whose values changed between the runs; `allBetter`: whether
  // better(c) holds for each of them.
  int CountChanged(const std::function<bool(std::size_t)>& better, bool& allBetter) const
  {
    int changed = 0;
    allBetter = true;
    for (std::size_t c = 0; c < this->Changed.size(); ++c)
    {
      if (this->Changed[c])
      {
        ++changed;
        allBetter = allBetter && better(c);
      }
    }
    return changed;
  }
};

// p's complex reconstructed twice, without the stiffening and ordering rounds (which would move
// both runs' fits apart), `set` setting each run apart; each verified, and each vertex given by
// the same cell in both.
void ReconstructTwice(
  const Pipeline& p, const std::function<void(FieldReconstruction&, int run)>& set, FieldReconstructionReport reports[2])
{
  for (int run = 0; run < 2; ++run)
  {
    FieldReconstruction reconstruction;
    reconstruction.Parallel = ThreadedFor;
    reconstruction.StiffeningRounds = 0;
    reconstruction.OrderingRounds = 0;
    set(reconstruction, run);
    std::string error;
    CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, reports[run], error));
    CHECK(reports[run].Verified);
  }
  CHECK(reports[0].CellOfVertex == reports[1].CellOfVertex);
}

CellByCell CompareCellByCell(const Pipeline& p, const FieldReconstructionReport reports[2])
{
  const std::size_t cells = p.Simplified.Complex.TwoCells.size();
  CellByCell result;
  for (int run = 0; run < 2; ++run)
  {
    result.Miss[run].assign(cells, 0.0);
    result.Squares[run].assign(cells, 0.0);
  }
  result.Changed.assign(cells, 0);
  for (std::size_t v = 0; v < p.Field.Values.size(); ++v)
  {
    const Index c = reports[0].CellOfVertex[v];
    for (int run = 0; run < 2; ++run)
    {
      const double d = std::abs(reports[run].Exact[v] - p.Field.Values[v]);
      result.Largest[run] = std::max(result.Largest[run], d);
      result.Reconstructed[run] = std::max(result.Reconstructed[run], std::abs(reports[run].Values[v] - p.Field.Values[v]));
      if (c != InvalidIndex)
      {
        result.Miss[run][c] = std::max(result.Miss[run][c], d);
        result.Squares[run][c] += d * d;
      }
    }
    if (c != InvalidIndex && reports[1].Exact[v] != reports[0].Exact[v])
    {
      result.Changed[c] = 1;
    }
  }
  return result;
}
} // namespace

TEST_CASE(AlternativeMapsLowerOnlyTheLargestMisses)
{
  // The cells that miss the data most get a second chance on maps reweighted by the input's
  // gradient (FieldReconstruction::AlternativeMapStrength). Measured here from F o Phi at the
  // vertices and the cell that gave each value (no stiffening, which would move both runs'
  // fits apart): a cell either keeps its values bit for bit or misses less than before, the
  // cells that changed are the ones reported, and no field's largest miss grows. On Shepard
  // fields nothing was tuned on (seeds 60-71), at 5 %.
  int remapped = 0, lowered = 0;
  for (std::uint64_t seed = 60; seed < 72; ++seed)
  {
    const GridField shepard = ShepardField(40, 2.0, 200, seed);
    Pipeline p;
    std::string error;
    CHECK(RunStages1To3(shepard, 5, 4, p, error));
    FieldReconstructionReport reports[2];
    ReconstructTwice(p, [](FieldReconstruction& reconstruction, int run) {
      reconstruction.AlternativeMapStrength = run ? 30 : 0;
      reconstruction.AxisAimTrigger = 0; // its own test below
    }, reports);
    CHECK(reports[0].Cells.RemappedCells == 0);
    const CellByCell compared = CompareCellByCell(p, reports);
    bool onlyLower;
    const int changedCells =
      compared.CountChanged([&](std::size_t c) { return compared.Miss[1][c] < compared.Miss[0][c]; }, onlyLower);
    std::printf("  shepard 200^2 seed %d at 5 %%: %d cells remapped, largest miss of F o Phi %.2f -> %.2f %%, of "
                "Reconstructed %.2f -> %.2f %% of the range\n",
      static_cast<int>(seed), static_cast<int>(reports[1].Cells.RemappedCells), 100 * compared.Largest[0] / p.Range,
      100 * compared.Largest[1] / p.Range, 100 * compared.Reconstructed[0] / p.Range,
      100 * compared.Reconstructed[1] / p.Range);
    CHECK(onlyLower);
    CHECK_EQ(changedCells, static_cast<int>(reports[1].Cells.RemappedCells));
    CHECK(compared.Largest[1] <= compared.Largest[0]);
    remapped += changedCells;
    lowered += compared.Largest[1] < compared.Largest[0] ? 1 : 0;
  }
  std::printf("  %d cells remapped, the largest miss lowered on %d of 12 fields\n", remapped, lowered);
  CHECK(lowered > 0);
}

TEST_CASE(TheAxisAimIsReleasedOnlyWhereItHoldsACellOffTheData)
{
  // A cell whose fit misses by more than AxisAimTrigger x SurfaceTolerance is fitted again
  // without the aim at F rising along u and v, and keeps that fit only if its largest miss falls
  // by 10 %, its RMS does not grow and it has no more critical points deep inside. Measured here
  // from F o Phi at the vertices and the cell that gave each value, with the rule off (trigger
  // 0) and on, the other rounds and maps off in both: a cell either keeps every value bit for bit
  // or misses less by that margin, at no higher RMS; the cells that changed are the ones
  // reported; no field's largest miss grows and the critical points of F o Phi deep inside the
  // cells (this test's own count) do not grow in all. Shepard fields nothing was tuned on
  // (seeds 80-91) at 5 and 25 %.
  int released = 0, lowered = 0, deepBefore = 0, deepAfter = 0;
  ForShepardFields150(80, 92, FiveOrTwentyFive, [&](std::uint64_t seed, int percent, const GridField& shepard, Pipeline& p) {
    FieldReconstructionReport reports[2];
    ReconstructTwice(p, [](FieldReconstruction& reconstruction, int run) {
      reconstruction.AlternativeMapStrength = 0;
      reconstruction.AxisAimTrigger = run ? 5 : 0;
    }, reports);
    CHECK(reports[0].Cells.AxisFreeCells == 0);
    const CellByCell compared = CompareCellByCell(p, reports);
    const double* largest = compared.Largest;
    bool better;
    const int changedCells = compared.CountChanged(
      [&](std::size_t c) {
        return compared.Miss[1][c] < 0.9 * compared.Miss[0][c] &&
          compared.Squares[1][c] <= compared.Squares[0][c] * (1 + 1e-9);
      },
      better);
    const int nx = shepard.Dimensions[0], ny = shepard.Dimensions[1];
    const int deep[2] = { CriticalDeepInsideCells(reports[0].Exact, reports[0].CellOfVertex, nx, ny),
      CriticalDeepInsideCells(reports[1].Exact, reports[1].CellOfVertex, nx, ny) };
    std::printf("  shepard 150^2 seed %d at %d %%: %d cells released, largest miss of F o Phi %.2f -> %.2f %% of the "
                "range, critical points deep inside the cells %d -> %d\n",
      static_cast<int>(seed), percent, changedCells, 100 * largest[0] / p.Range, 100 * largest[1] / p.Range, deep[0],
      deep[1]);
    CHECK(better);
    CHECK_EQ(changedCells, static_cast<int>(reports[1].Cells.AxisFreeCells));
    CHECK(largest[1] <= largest[0]);
    released += changedCells;
    lowered += largest[1] < largest[0] ? 1 : 0;
    deepBefore += deep[0];
    deepAfter += deep[1];
  });
  std::printf("  %d cells released, the largest miss lowered on %d of 12 fields, deep critical points %d -> %d\n",
    released, lowered, deepBefore, deepAfter);
  CHECK(released > 0);
  CHECK(lowered > 0);
  CHECK(deepAfter <= deepBefore);
}

TEST_CASE(SmallCellsAreFittedWhereThePaperMisses)
{
  // Cells with few samples for their grid keep the paper's interior unless it misses their
  // samples by more than SmallCellFitTrigger x SurfaceTolerance; then the worst of them are
  // fitted, no more than a quarter of the regular fits (at least 32). Measured here from
  // F o Phi at the vertices and the cell that gave each value, with small fits off (trigger 0)
  // and on: a cell either keeps every value bit for bit or is one of the small cells reported
  // fitted and misses its vertices by no more in RMS; the number of small fits keeps to the
  // budget. On
  // Shepard fields of 150 sites nothing was tuned on (seeds 120-125, at 2 %: narrow cells
  // between close bumps) and on uniform noise, whose cells are nearly all small (the budget is
  // what holds there).
  int fittedShepard = 0, fittedNoise = 0, lowered = 0;
  auto compare = [&](const char* name, Pipeline& p, int& fitted) {
    FieldReconstructionReport reports[2];
    ReconstructTwice(p, [](FieldReconstruction& reconstruction, int run) {
      reconstruction.SmallCellFitTrigger = run ? 2 : 0;
    }, reports);
    CHECK(reports[0].Cells.SmallFittedCells == 0);
    const CellByCell compared = CompareCellByCell(p, reports);
    bool better;
    const int changedCells = compared.CountChanged(
      [&](std::size_t c) { return compared.Squares[1][c] <= compared.Squares[0][c] * (1 + 1e-9); }, better);
    const Index small = reports[1].Cells.SmallFittedCells;
    const Index regular = reports[1].Cells.FittedCells - small;
    double squares[2];
    for (int run = 0; run < 2; ++run)
    {
      squares[run] = std::accumulate(compared.Squares[run].begin(), compared.Squares[run].end(), 0.0);
    }
    const double vertices = static_cast<double>(p.Field.Values.size());
    std::printf("  %s: %d small cells fitted (%d regular), %d changed, RMS of F o Phi %.3f -> %.3f %% of the range\n",
      name, static_cast<int>(small), static_cast<int>(regular), changedCells,
      100 * std::sqrt(squares[0] / vertices) / p.Range, 100 * std::sqrt(squares[1] / vertices) / p.Range);
    CHECK(better);
    CHECK(changedCells <= static_cast<int>(small));
    CHECK(small <= std::max<Index>(32, regular / 4));
    CHECK_EQ(reports[0].Cells.FittedCells, regular);
    fitted += changedCells;
    lowered += squares[1] < squares[0] ? 1 : 0;
  };
  for (std::uint64_t seed = 120; seed < 126; ++seed)
  {
    Pipeline p;
    std::string error;
    CHECK(RunStages1To3(ShepardField(150, 2.0, 150, seed), 2, 4, p, error));
    const std::string name = "shepard 150^2 of 150 sites, seed " + std::to_string(seed) + " at 2 %";
    compare(name.c_str(), p, fittedShepard);
  }
  for (std::uint64_t seed = 5; seed < 7; ++seed)
  {
    Pipeline p;
    std::string error;
    CHECK(RunStages1To3(UniformNoise(100, seed), 5, 4, p, error));
    const std::string name = "noise 100^2 seed " + std::to_string(seed) + " at 5 %";
    compare(name.c_str(), p, fittedNoise);
  }
  std::printf("  %d small cells changed on the Shepard fields, %d on noise; RMS lower on %d of 8 fields\n",
    fittedShepard, fittedNoise, lowered);
  CHECK(fittedShepard > 0);
  CHECK(fittedNoise > 0);
  CHECK(lowered > 0);
}

TEST_CASE(AnisotropicSpacingIsReconstructedInTheComplexsFrame)
{
  // Spacing 0.01 x 3: in the image's own coordinates every 2-cell is 300 times longer than
  // wide, and its triangulation and mean value map degenerate. Stages 3 and 4 work in the
  // complex's frame (spacings divided by powers of two), where the cells have their shape on a
  // square grid again; the outputs come back in the image's coordinates.
  GridField grid = ShepardField(40, 2.0, 60, 5);
  grid.Spacing[0] = 0.01;
  grid.Spacing[1] = 3.0;
  grid.Origin[0] = -7.5;
  CheckCase("shepard 0.01 x 3", grid, 5, 4, 2);

  Pipeline p;
  std::string error;
  CHECK(RunStages1To3(grid, 5, 4, p, error));
  const PlanarFrame& frame = p.Simplified.Complex.Frame;
  // The powers of two nearest the spacings, kept through simplification.
  CHECK(frame.Scale[0] == 1.0 / 128 && frame.Scale[1] == 4);
  CHECK(p.Input.Frame.Scale[0] == frame.Scale[0] && p.Input.Frame.Scale[1] == frame.Scale[1]);
  // Exact both ways.
  std::vector<double> points = p.Field.Points;
  frame.ToFrame(points);
  frame.ToWorld(points);
  CHECK(points == p.Field.Points);
  // The smoothed curves come back in the image's coordinates: every piece ends on its nodes,
  // and its nodes that are critical points sit on their vertices.
  bool onNodes = true, onVertices = true;
  for (const SmoothedPiece& piece : p.Smoothed.Pieces)
  {
    const std::vector<double>& c = piece.Curve.ControlPoints;
    const SmoothingNode& start = p.Smoothed.Nodes[piece.StartNode];
    const SmoothingNode& end = p.Smoothed.Nodes[piece.EndNode];
    onNodes = onNodes && c[0] == start.Position[0] && c[1] == start.Position[1] &&
      c[c.size() - 2] == end.Position[0] && c[c.size() - 1] == end.Position[1];
  }
  for (const SmoothingNode& node : p.Smoothed.Nodes)
  {
    if (node.Type == SmoothingNode::Critical)
    {
      const Index v = p.Simplified.Complex.CriticalPoints[node.Source].Vertex;
      onVertices = onVertices && node.Position[0] == p.Field.Points[2 * v] &&
        node.Position[1] == p.Field.Points[2 * v + 1];
    }
  }
  CHECK(onNodes);
  CHECK(onVertices);

  // For comparison (printed): the same pipeline in the image's own coordinates.
  MorseSmaleComplex world = p.Simplified.Complex;
  world.Frame = PlanarFrame();
  OneCellSmoothing smoothing;
  smoothing.Segments = 4;
  OneCellSmoothingResult smoothedInWorld;
  FieldReconstructionReport report;
  FieldReconstruction reconstruction;
  if (smoothing.Smooth(world, p.Simplified.JunctionPoints, p.Bounds, smoothedInWorld, error) &&
    reconstruction.Run(p.Field, world, smoothedInWorld, report, error))
  {
    std::printf("  the same in the image's coordinates: %d of %d cells failed, verdict %d\n",
      report.Cells.FailedCells, report.Cells.Cells, report.Verified ? 1 : 0);
  }
  else
  {
    std::printf("  the same in the image's coordinates: %s\n", error.c_str());
  }
}

TEST_CASE(MeshFrameFollowsItsEdges)
{
  // A triangle mesh's frame: the root mean square dx and dy of its edges, to the nearest power
  // of two. The triangles of a grid of spacing 1 x 1 give 0.82 x 0.82: the identity.
  GridField grid = ShepardField(10, 2.0, 12, 1);
  PlanarScalarField mesh = FieldOnGrid(grid);
  mesh.GridDimensions[0] = mesh.GridDimensions[1] = 0;
  mesh.Triangles = GridTriangles(12, 12);
  CHECK(MorseSmaleComplexExtraction::DomainFrame(mesh).IsIdentity());
  // Stretched by 100 along y (dx 0.82, dy 82): 1 x 64 (82 is nearer 64 than 128).
  for (std::size_t v = 0; v < mesh.Values.size(); ++v)
  {
    mesh.Points[2 * v + 1] *= 100;
  }
  const PlanarFrame frame = MorseSmaleComplexExtraction::DomainFrame(mesh);
  CHECK(frame.Scale[0] == 1 && frame.Scale[1] == 64);
}

TEST_CASE(SpuriousPointsAreCountedNearAndFarFromTheOneCells)
{
  // One straight smoothed 1-cell from (0, 0) to (30, 0); points at known distances from it.
  OneCellSmoothingResult smoothed;
  SmoothedPiece piece;
  piece.Curve.Segments = 1;
  piece.Curve.Dimension = 2;
  piece.Curve.ControlPoints = { 0, 0, 10, 0, 20, 0, 30, 0 };
  smoothed.Pieces.push_back(piece);
  std::vector<CriticalPointLocation> points;
  // (The curve is sampled at most 1/8 apart, 16 samples per side 2 of the buckets: the test
  // distances stay clear of 2 by more than the sampling error.)
  for (const auto& xy : { std::array<double, 2>{ 5, 0.5 }, { 12, -1.5 }, { 29, 2.5 }, { 15, 5 }, { -1.5, 0 },
         { 33, 0 }, { -40, 7 } })
  {
    CriticalPointLocation point;
    point.Position[0] = xy[0];
    point.Position[1] = xy[1];
    points.push_back(point);
  }
  Index near = -1, far = -1;
  CountByDistanceToOneCells(points, smoothed, 2.0, near, far);
  CHECK_EQ(near, 3); // 0.5, 1.5 and 1.5 (beyond the start) away
  CHECK_EQ(far, 4);  // 2.5, 5, 3 (beyond the end) and far outside
  CountByDistanceToOneCells({}, smoothed, 2.0, near, far);
  CHECK(near == 0 && far == 0);
}

TEST_CASE(CountsNearOneCellsMatchExactDistancesOnManySegments)
{
  // A random walk of 200 straight segments of length 1.6 (16 samples each: 0.1 apart) and one
  // diagonal segment 18 x 18 (its bounding box spans more than 64 buckets of side 2; 16 samples
  // would be 1.6 apart, the nearest up to 0.8 from the curve: it gets 16 per side 2 along it),
  // against the exact distance to the segments computed here; points within 0.01 of the
  // threshold 2 are left out (the nearest sample within 1/16 of the nearest curve point moves a
  // distance of 2 by at most 0.001).
  std::mt19937 random(20261203);
  std::uniform_real_distribution<double> angle(0, 2 * 3.14159265358979), coordinate(0, 1);
  OneCellSmoothingResult smoothed;
  std::vector<std::array<double, 4>> lines; // x0, y0, x1, y1
  SmoothedPiece walk;
  walk.Curve.Dimension = 2;
  double x = 50, y = 0;
  for (int j = 0; j < 200; ++j)
  {
    const double a = angle(random);
    const double x1 = x + 1.6 * std::cos(a), y1 = y + 1.6 * std::sin(a);
    lines.push_back({ x, y, x1, y1 });
    for (int c = 0; c < 4; ++c)
    {
      walk.Curve.ControlPoints.push_back(x + (x1 - x) * c / 3.0);
      walk.Curve.ControlPoints.push_back(y + (y1 - y) * c / 3.0);
    }
    x = x1;
    y = y1;
  }
  walk.Curve.Segments = 200;
  smoothed.Pieces.push_back(walk);
  SmoothedPiece line;
  line.Curve.Dimension = 2;
  line.Curve.Segments = 1;
  line.Curve.ControlPoints = { 100, -60, 106, -54, 112, -48, 118, -42 };
  smoothed.Pieces.push_back(line);
  lines.push_back({ 100, -60, 118, -42 });
  const auto exactDistance = [&lines](double px, double py) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& l : lines)
    {
      const double dx = l[2] - l[0], dy = l[3] - l[1];
      const double t = std::clamp(((px - l[0]) * dx + (py - l[1]) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
      best = std::min(best, std::hypot(px - l[0] - t * dx, py - l[1] - t * dy));
    }
    return best;
  };
  std::vector<CriticalPointLocation> points;
  Index expectedNear = 0;
  while (points.size() < 2000)
  {
    CriticalPointLocation point;
    point.Position[0] = 95 + 30 * coordinate(random); // around the diagonal segment
    point.Position[1] = -65 + 30 * coordinate(random);
    if (points.size() % 2 == 0)
    {
      // Half of them close to the walk, where most are near.
      point.Position[0] = x - 40 + 80 * coordinate(random);
      point.Position[1] = y - 40 + 80 * coordinate(random);
    }
    const double d = exactDistance(point.Position[0], point.Position[1]);
    if (std::abs(d - 2) < 0.01)
    {
      continue;
    }
    expectedNear += d <= 2 ? 1 : 0;
    points.push_back(point);
  }
  Index near = -1, far = -1;
  CountByDistanceToOneCells(points, smoothed, 2.0, near, far);
  CHECK(expectedNear > 50);
  CHECK_EQ(near, expectedNear);
  CHECK_EQ(far, static_cast<Index>(points.size()) - expectedNear);
  // The pieces sampled on several threads, and the points' buckets kept in a sorted list instead
  // of per bucket of their box (two points 1e7 away make the box far larger than their number).
  near = far = -1;
  CountByDistanceToOneCells(points, smoothed, 2.0, near, far, ThreadedFor);
  CHECK_EQ(near, expectedNear);
  CHECK_EQ(far, static_cast<Index>(points.size()) - expectedNear);
  for (const double at : { 1e7, -1e7 })
  {
    CriticalPointLocation distant;
    distant.Position[0] = distant.Position[1] = at;
    points.push_back(distant);
  }
  for (const ParallelFor& parallel : { ParallelFor(SequentialFor), ParallelFor(ThreadedFor) })
  {
    near = far = -1;
    CountByDistanceToOneCells(points, smoothed, 2.0, near, far, parallel);
    CHECK_EQ(near, expectedNear);
    CHECK_EQ(far, static_cast<Index>(points.size()) - expectedNear);
  }
}

TEST_CASE(LongSegmentsAreSampledFinelyEnoughForTheirNeighbours)
{
  // One straight Bezier segment 300 long (a large terrain's 1-cell), its height rising from 0 to
  // 3 along it, and points within one side (1) of it between where 16 samples per segment would
  // lie (18.75 apart): each is counted near, and the nearest sample found for it is within 1/32
  // of the nearest curve point, so its height within 3 / 300 / 32 of that point's.
  OneCellSmoothingResult smoothed;
  SmoothedPiece piece;
  piece.Curve.Segments = piece.Height.Segments = 1;
  piece.Curve.Dimension = 2;
  piece.Height.Dimension = 1;
  piece.Curve.ControlPoints = { 0, 0, 100, 0, 200, 0, 300, 0 };
  piece.Height.ControlPoints = { 0, 1, 2, 3 };
  smoothed.Pieces.push_back(piece);
  std::vector<CriticalPointLocation> points;
  std::vector<double> around;
  for (int i = 0; i < 50; ++i)
  {
    CriticalPointLocation point;
    point.Position[0] = 9.375 + 18.75 * (i % 16) + 0.01 * i;
    point.Position[1] = (i % 2 ? 0.9 : -0.9) * (1 - 0.01 * i);
    points.push_back(point);
    around.insert(around.end(), point.Position, point.Position + 2);
  }
  Index near = -1, far = -1;
  CountByDistanceToOneCells(points, smoothed, 1.0, near, far);
  CHECK_EQ(near, 50);
  CHECK_EQ(far, 0);
  const OneCellSamples samples(smoothed, 1.0, around);
  for (const CriticalPointLocation& point : points)
  {
    double height = -1;
    CHECK(samples.Nearest(point.Position[0], point.Position[1], 1.0, height));
    CHECK(std::abs(height - point.Position[0] / 100) <= 3.0 / 300 / 32 + 1e-12);
  }
}

namespace
{
// The PL saddle multiplicity of every interior vertex: half the number of changes between lower
// and upper neighbours around its link (LowerLink), less one.
std::vector<int> InteriorSaddleMultiplicity(const std::vector<double>& f, int nx, int ny)
{
  std::vector<int> multiplicity(f.size(), 0);
  for (int j = 1; j + 1 < ny; ++j)
  {
    for (int i = 1; i + 1 < nx; ++i)
    {
      multiplicity[j * nx + i] = std::max(0, LinkChanges(f, nx, i, j) / 2 - 1);
    }
  }
  return multiplicity;
}

// Pairs saddles (one entry per unit of multiplicity, by vertex) of `a` with those of `b` on the
// same vertex or one of the 8 around it, within the longest edge (Kuhn's augmenting paths);
// returns, per entry of a, its partner in b or -1.
std::vector<int> PairNeighbouringSaddles(const std::vector<int>& a, const std::vector<int>& b, int nx)
{
  auto near = [nx](int v, int w) {
    const int di = w % nx - v % nx, dj = w / nx - v / nx;
    return std::abs(di) <= 1 && std::abs(dj) <= 1; // within one edge's length (the verdict's tolerance)
  };
  std::vector<int> partnerOfA(a.size(), -1), partnerOfB(b.size(), -1);
  for (std::size_t start = 0; start < a.size(); ++start)
  {
    std::vector<char> visited(b.size(), 0);
    std::function<bool(std::size_t)> augment = [&](std::size_t x) {
      for (std::size_t y = 0; y < b.size(); ++y)
      {
        if (!visited[y] && near(a[x], b[y]))
        {
          visited[y] = 1;
          if (partnerOfB[y] < 0 || augment(static_cast<std::size_t>(partnerOfB[y])))
          {
            partnerOfA[x] = static_cast<int>(y);
            partnerOfB[y] = static_cast<int>(x);
            return true;
          }
        }
      }
      return false;
    };
    augment(start);
  }
  return partnerOfA;
}
} // namespace

TEST_CASE(SaddlesStayOnTheirNodesOnWeakNoise)
{
  // Uniform noise simplified at 0.5 and 1 %: hundreds of saddles, among them monkey saddles
  // (two saddles of the complex on one vertex) and saddles a vertex apart. The sampled
  // reconstruction must have each interior saddle of the complex on its vertex or one of the 8
  // around it (the verdict's tolerance, the longest edge), and no other: checked here with the PL
  // multiplicity of every vertex and one-to-one pairings, away from the boundary rows (saddles
  // there trade places with the complex's boundary rule, not counted here). Before the carving
  // of a missing saddle went on to the saddles each carve takes away, and a monkey saddle's
  // 1-cells shared a link vertex per sector, 18 of these 24 fields passed (verdict 1 on 16).
  int cases = 0, kept = 0, monkeys = 0;
  for (int n : { 24, 32 })
  {
    for (double percent : { 0.5, 1.0 })
    {
      for (std::uint64_t seed : { 1, 2, 3, 4, 5, 6 })
      {
        Pipeline p;
        std::string error;
        CHECK(RunStages1To3(UniformNoise(n, seed), percent, 4, p, error));
        FieldReconstruction reconstruction;
        FieldReconstructionReport report;
        CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
        auto awayFromBoundary = [n](int v) { return v % n >= 4 && v % n < n - 4 && v / n >= 4 && v / n < n - 4; };
        std::vector<int> wanted, found;
        for (const CriticalPoint& cp : p.Simplified.Complex.CriticalPoints)
        {
          if (cp.MorseIndex == 1 && !cp.OnBoundary)
          {
            wanted.push_back(static_cast<int>(cp.Vertex));
          }
        }
        const std::vector<int> multiplicity = InteriorSaddleMultiplicity(report.Values, n, n);
        for (int v = 0; v < n * n; ++v)
        {
          found.insert(found.end(), multiplicity[v], v);
          monkeys += multiplicity[v] > 1 ? 1 : 0;
        }
        // Each side's saddles away from the boundary rows, paired with all of the other side's
        // (saddles near the boundary trade places with the boundary rule's).
        int unpaired = 0;
        for (const auto* side : { &wanted, &found })
        {
          const std::vector<int>& other = side == &wanted ? found : wanted;
          std::vector<int> inside;
          std::copy_if(side->begin(), side->end(), std::back_inserter(inside), awayFromBoundary);
          const std::vector<int> partner = PairNeighbouringSaddles(inside, other, n);
          for (std::size_t i = 0; i < inside.size(); ++i)
          {
            if (partner[i] < 0)
            {
              std::printf("    %s saddle at (%d, %d) with none of the %s within one edge\n",
                side == &wanted ? "complex" : "sampled", inside[i] % n, inside[i] / n,
                side == &wanted ? "sampling's" : "complex's");
              ++unpaired;
            }
          }
        }
        ++cases;
        kept += unpaired == 0 ? 1 : 0;
        if (unpaired > 0 || !report.Verified)
        {
          std::printf("  noise %d x %d seed %d at %g %%: %d saddles off their nodes, verdict %d\n", n, n,
            static_cast<int>(seed), percent, unpaired, report.Verified ? 1 : 0);
        }
        CHECK_EQ(unpaired, 0);
        CHECK(report.Verified);
      }
    }
  }
  std::printf("  %d of %d noise fields with every interior saddle on its node; %d monkey saddles sampled\n", kept,
    cases, monkeys);
  CHECK(monkeys > 0); // the case exercises what it tests
}

namespace
{
// The vertices of a triangle mesh next to each vertex (written here, from the triangles).
std::vector<std::vector<Index>> NeighboursOnMesh(const PlanarScalarField& field)
{
  std::vector<std::vector<Index>> neighbours(field.Values.size());
  for (std::size_t t = 0; t + 2 < field.Triangles.size(); t += 3)
  {
    for (int a = 0; a < 3; ++a)
    {
      for (int b = 0; b < 3; ++b)
      {
        const Index u = field.Triangles[t + a], w = field.Triangles[t + b];
        if (u != w && std::find(neighbours[u].begin(), neighbours[u].end(), w) == neighbours[u].end())
        {
          neighbours[u].push_back(w);
        }
      }
    }
  }
  return neighbours;
}

// Per vertex v, its link as successor pairs (u -> w for every triangle (v, u, w) in the
// triangle's own vertex order): a cycle round an interior vertex, a path round a boundary one.
std::vector<std::map<Index, Index>> LinkSuccessors(const PlanarScalarField& field, std::size_t n)
{
  std::vector<std::map<Index, Index>> successor(n);
  for (std::size_t t = 0; t + 2 < field.Triangles.size(); t += 3)
  {
    for (int k = 0; k < 3; ++k)
    {
      successor[field.Triangles[t + k]][field.Triangles[t + (k + 1) % 3]] = field.Triangles[t + (k + 2) % 3];
    }
  }
  return successor;
}

// The saddles of a sampling on a triangle mesh by the complex's closed-boundary rule
// (docs/MorseSmaleComplex.md; the stress test counts the same way): an interior vertex is a
// saddle of multiplicity (lower-link pieces round its link cycle) - 1; a boundary vertex, whose
// link is a path, is a saddle once when both ends of the path are lower (a maximum of the
// boundary curve), and once more per piece of its lower link that touches neither end. Ties by
// vertex id. Each saddle is listed once per multiplicity; `withBoundary` false leaves out the
// boundary vertices.
std::vector<Index> SaddlesByTheBoundaryRule(
  const PlanarScalarField& field, const std::vector<double>& values, bool withBoundary = true)
{
  const std::size_t n = values.size();
  const std::vector<std::map<Index, Index>> successor = LinkSuccessors(field, n);
  std::vector<Index> saddles;
  for (std::size_t v = 0; v < n; ++v)
  {
    const std::map<Index, Index>& next = successor[v];
    if (next.empty())
    {
      continue;
    }
    std::set<Index> targets;
    for (const auto& [from, to] : next)
    {
      targets.insert(to);
    }
    Index first = next.begin()->first;
    bool boundary = false;
    for (const auto& [from, to] : next)
    {
      if (!targets.count(from))
      {
        first = from; // the start of the link path
        boundary = true;
      }
    }
    if (boundary && !withBoundary)
    {
      continue;
    }
    std::vector<Index> walk{ first };
    for (auto it = next.find(first); it != next.end() && it->second != first && walk.size() <= next.size();
         it = next.find(walk.back()))
    {
      walk.push_back(it->second);
    }
    const auto lower = [&](Index w) {
      return values[w] < values[v] || (values[w] == values[v] && w < static_cast<Index>(v));
    };
    int count = 0;
    if (!boundary)
    {
      int rises = 0;
      for (std::size_t i = 0; i < walk.size(); ++i)
      {
        rises += lower(walk[i]) && !lower(walk[(i + walk.size() - 1) % walk.size()]) ? 1 : 0;
      }
      count = std::max(0, rises - 1);
    }
    else
    {
      count = lower(walk.front()) && lower(walk.back()) ? 1 : 0;
      for (std::size_t i = 0; i < walk.size();)
      {
        if (!lower(walk[i]))
        {
          ++i;
          continue;
        }
        std::size_t j = i;
        while (j + 1 < walk.size() && lower(walk[j + 1]))
        {
          ++j;
        }
        count += i > 0 && j + 1 < walk.size() ? 1 : 0;
        i = j + 1;
      }
    }
    saddles.insert(saddles.end(), count, static_cast<Index>(v));
  }
  return saddles;
}

// What a sampling of `complex` must have, counted as the closed-boundary rule counts: the
// complex's nodes by index, and a minimum and a saddle per boundary junction.
std::array<int, 3> WantedCounts(const MorseSmaleComplex& complex)
{
  std::array<int, 3> wanted{ { 0, 0, 0 } };
  for (const CriticalPoint& cp : complex.CriticalPoints)
  {
    ++wanted[cp.MorseIndex];
  }
  wanted[0] += static_cast<int>(complex.BoundaryJunctions.size());
  wanted[1] += static_cast<int>(complex.BoundaryJunctions.size());
  return wanted;
}

// Minima, saddles (with multiplicity) and maxima of a sampling on a triangle mesh by the
// closed-boundary rule, as SaddlesByTheBoundaryRule finds saddles: an interior vertex is a
// minimum with no lower neighbour, a maximum with no higher one; a boundary vertex is a minimum
// when both ends of its link path are higher, and a maximum when its whole link is lower.
std::array<int, 3> CriticalCountsByTheBoundaryRule(const PlanarScalarField& field, const std::vector<double>& values)
{
  const std::size_t n = values.size();
  const std::vector<std::map<Index, Index>> successor = LinkSuccessors(field, n);
  std::array<int, 3> counts{ { 0, static_cast<int>(SaddlesByTheBoundaryRule(field, values).size()), 0 } };
  for (std::size_t v = 0; v < n; ++v)
  {
    std::set<Index> link, targets;
    for (const auto& [from, to] : successor[v])
    {
      link.insert(from);
      link.insert(to);
      targets.insert(to);
    }
    if (link.empty())
    {
      continue;
    }
    const auto lower = [&](Index w) {
      return values[w] < values[v] || (values[w] == values[v] && w < static_cast<Index>(v));
    };
    const int below = static_cast<int>(std::count_if(link.begin(), link.end(), lower));
    Index first = InvalidIndex, last = InvalidIndex;
    for (const auto& [from, to] : successor[v])
    {
      first = targets.count(from) ? first : from;
      last = successor[v].count(to) ? last : to;
    }
    if (first == InvalidIndex) // interior
    {
      counts[0] += below == 0 ? 1 : 0;
    }
    else
    {
      counts[0] += !lower(first) && !lower(last) ? 1 : 0;
    }
    counts[2] += below == static_cast<int>(link.size()) ? 1 : 0;
  }
  return counts;
}

// Pairs vertices of `a` with vertices of `b` (each listed once per multiplicity) within `hops`
// mesh edges (or hopsOfA[i] for a[i]) and, given points, within distanceOfA[i], one to one, as
// many as can be (augmenting paths). Returns the partner index in b of each of a (-1: none).
std::vector<int> PairWithinHops(const std::vector<Index>& a, const std::vector<Index>& b,
  const std::vector<std::vector<Index>>& neighbours, int hops, const std::vector<int>* hopsOfA = nullptr,
  const std::vector<double>* points = nullptr, const std::vector<double>* distanceOfA = nullptr)
{
  const auto far = [&](std::size_t i, Index w) {
    return points && distanceOfA &&
      std::hypot((*points)[2 * a[i]] - (*points)[2 * w], (*points)[2 * a[i] + 1] - (*points)[2 * w + 1]) >
      (*distanceOfA)[i];
  };
  std::vector<std::vector<int>> near(a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    std::set<Index> reached{ a[i] };
    std::vector<Index> ring{ a[i] };
    for (int h = 0; h < (hopsOfA ? (*hopsOfA)[i] : hops); ++h)
    {
      std::vector<Index> outer;
      for (Index u : ring)
      {
        for (Index w : neighbours[u])
        {
          if (reached.insert(w).second)
          {
            outer.push_back(w);
          }
        }
      }
      ring.swap(outer);
    }
    for (std::size_t j = 0; j < b.size(); ++j)
    {
      if (reached.count(b[j]) && !far(i, b[j]))
      {
        near[i].push_back(static_cast<int>(j));
      }
    }
  }
  std::vector<int> partnerOfA(a.size(), -1), partnerOfB(b.size(), -1);
  std::function<bool(int, std::vector<char>&)> augment = [&](int i, std::vector<char>& seen) {
    for (int j : near[i])
    {
      if (!seen[j])
      {
        seen[j] = 1;
        if (partnerOfB[j] < 0 || augment(partnerOfB[j], seen))
        {
          partnerOfA[i] = j;
          partnerOfB[j] = i;
          return true;
        }
      }
    }
    return false;
  };
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    std::vector<char> seen(b.size(), 0);
    augment(static_cast<int>(i), seen);
  }
  return partnerOfA;
}
} // namespace

// Scattered points with the domain's corners among them, as the stress test's "delaunay"
// kind: the hull's edges run from corner to corner, so the longest edge (the verdict's
// distance tolerance) spans the whole domain and only the mesh's edges say what "next to its
// node" is. Every interior saddle of the complex must have one of the sampling's within two
// edges and the other way round (multiplicities and one-to-one pairings written here), and the
// verdict must be 1. Before topological sampling matched its saddles by the mesh's edges too
// (it took a saddle anywhere within the longest edge as on its node), 5 of the 8 Delaunay
// meshes of a stress seed with verdict 0 had a saddle 3-6 edges off (here: seed 4 at 25 %).
// Not at 50 %: there seed 1 fails for another reason, open (docs/StressTest.md): stage 2
// leaves a boundary saddle as the boundary curve's only critical point, with one descending
// 1-cell that runs round the whole domain boundary and back through the saddle's own vertex;
// no monotone height can follow it, and stage 4 reports the one 2-cell as failed.
TEST_CASE(SaddlesStayWithinTwoEdgesOnScatteredPointMeshes)
{
  int cases = 0, paired = 0, saddles = 0;
  for (std::uint64_t seed : { 1, 2, 3, 4, 5, 6, 7, 8 })
  {
    for (double percent : { 5.0, 25.0 })
    {
      PlanarScalarField field = RandomDelaunayField(700 + seed, 600);
      const std::vector<double> corners{ 0, 0, 1, 0, 0, 1, 1, 1 };
      field.Points.insert(field.Points.end(), corners.begin(), corners.end());
      for (int c = 0; c < 4; ++c)
      {
        field.Values.push_back(std::sin(6 * corners[2 * c]) * std::cos(5 * corners[2 * c + 1]));
      }
      field.Triangles = DelaunayTriangles(field.Points);
      Pipeline p;
      std::string error;
      CHECK(RunStages1To3(field, percent, 6, p, error));
      FieldReconstruction reconstruction;
      FieldReconstructionReport report;
      CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
      const std::vector<std::vector<Index>> neighbours = NeighboursOnMesh(field);
      const std::vector<Index> found = SaddlesByTheBoundaryRule(field, report.Values, false);
      std::vector<Index> wanted;
      for (const CriticalPoint& cp : p.Simplified.Complex.CriticalPoints)
      {
        if (cp.MorseIndex == 1 && !cp.OnBoundary)
        {
          wanted.push_back(cp.Vertex);
        }
      }
      const std::vector<int> partner = PairWithinHops(wanted, found, neighbours, 2);
      const int matched = static_cast<int>(std::count_if(partner.begin(), partner.end(), [](int j) { return j >= 0; }));
      const int unpaired = static_cast<int>(wanted.size() + found.size()) - 2 * matched;
      ++cases;
      saddles += static_cast<int>(wanted.size());
      paired += unpaired == 0 ? 1 : 0;
      if (unpaired > 0 || !report.Verified)
      {
        std::printf("  seed %d at %g %%: %d complex and %d sampled interior saddles, %d unpaired within two edges, "
                    "verdict %d\n",
          static_cast<int>(seed), percent, static_cast<int>(wanted.size()), static_cast<int>(found.size()), unpaired,
          report.Verified ? 1 : 0);
        for (const auto* list : { &report.Spurious, &report.Missing })
        {
          for (const CriticalPointLocation& c : *list)
          {
            std::printf("    %s index %d at (%g, %g) vertex %d\n", list == &report.Spurious ? "spurious" : "missing",
              c.MorseIndex, c.Position[0], c.Position[1], static_cast<int>(c.Vertex));
          }
        }
      }
      CHECK_EQ(unpaired, 0);
      CHECK(report.Verified);
    }
  }
  std::printf("  %d of %d scattered-point meshes with every interior saddle within two edges of its node "
              "(%d saddles)\n", paired, cases, saddles);
}

// Saddles that topological sampling leaves off their nodes are wanted one edge away in turn
// (TopologicalSampling::MoveDisplacedSaddles): beside the boundary a boundary saddle's way up
// and an interior saddle can compete for the same few vertices, and one vertex along the saddle
// leaves the way free. Uniform noise at 25 and 50 % (where most verdicts of 0 are), sampled
// three times from F o Phi: without the moves (MaximumSaddlesToMove = 0), with them, and with the
// spare saddles walked after them (WalkSpareSaddlesOntoMissing; the first two without). The oracle,
// written here: the sampling's saddles by the closed-boundary rule (SaddlesByTheBoundaryRule)
// paired one to one with the complex's saddles within a grid diagonal (a boundary junction's
// saddle within three, as the verdict allows), and the saddles left over counted. The moves never leave
// more and leave fewer in all; the walks never leave more than the moves.
TEST_CASE(DisplacedSaddlesAreWantedOneEdgeAway)
{
  int cases = 0, unpairedWith = 0, unpairedWithout = 0, unpairedWalked = 0, improved = 0;
  for (int n : { 24, 32, 48 })
  {
    for (double percent : { 25.0, 50.0 })
    {
      for (std::uint64_t seed : { 1, 2, 3, 4, 5, 6 })
      {
        const GridField grid = UniformNoise(n, seed);
        Pipeline p;
        std::string error;
        CHECK(RunStages1To3(grid, percent, 6, p, error));
        FieldReconstruction raw;
        raw.TopologicalSampling = false;
        raw.VerifyTopology = false;
        FieldReconstructionReport exact;
        CHECK(raw.Run(p.Field, p.Simplified.Complex, p.Smoothed, exact, error));
        const PlanarScalarField triangles = MeshFieldOnGrid(grid);
        const std::vector<std::vector<Index>> neighbours = NeighboursOnMesh(triangles);
        TriangleMeshTopology mesh;
        mesh.BuildGrid(n, n, SequentialFor);
        // As the verdict allows: a node's saddle within one grid diagonal (and two edges), a
        // boundary junction's within three diagonals and three edges.
        std::vector<Index> wanted;
        std::vector<int> hops;
        std::vector<double> distance;
        for (const CriticalPoint& cp : p.Simplified.Complex.CriticalPoints)
        {
          if (cp.MorseIndex == 1)
          {
            wanted.push_back(cp.Vertex);
            hops.push_back(2);
            distance.push_back(std::sqrt(2.0) * (1 + 1e-9));
          }
        }
        for (Index junction : p.Simplified.Complex.BoundaryJunctions)
        {
          wanted.push_back(junction);
          hops.push_back(3);
          distance.push_back(3 * std::sqrt(2.0) * (1 + 1e-9));
        }
        // Without the moves, with them, and with them and the walks after them.
        int unpaired[3] = { 0, 0, 0 };
        for (int moves : { 0, 1, 2 })
        {
          TopologicalSampling sampling(p.Simplified.Complex, mesh, p.Field.Points, p.Smoothed);
          sampling.Spacing = std::sqrt(2.0) * (1 + 1e-9);
          sampling.MaximumSaddlesToMove = moves == 0 ? 0 : sampling.MaximumSaddlesToMove;
          sampling.WalkSpareSaddles = moves == 2;
          std::vector<double> values = exact.Values;
          const TopologicalSamplingReport report =
            sampling.Apply(p.Field, mesh, [](Index v) { return v; }, values);
          CHECK(moves > 0 || report.MovedInteriorSaddles == 0);
          CHECK(moves == 2 || report.WalkedSaddles == 0);
          const std::vector<Index> found = SaddlesByTheBoundaryRule(triangles, values);
          const std::vector<int> partner =
            PairWithinHops(wanted, found, neighbours, 2, &hops, &triangles.Points, &distance);
          const int matched =
            static_cast<int>(std::count_if(partner.begin(), partner.end(), [](int j) { return j >= 0; }));
          unpaired[moves] = static_cast<int>(wanted.size() + found.size()) - 2 * matched;
        }
        ++cases;
        unpairedWithout += unpaired[0];
        unpairedWith += unpaired[1];
        unpairedWalked += unpaired[2];
        improved += unpaired[1] < unpaired[0] ? 1 : 0;
        if (unpaired[1] != unpaired[0] || unpaired[2] != unpaired[1])
        {
          std::printf("  noise %d x %d seed %d at %g %%: %d saddles unpaired without the moves, %d with, %d with "
                      "the walks too\n", n, n, static_cast<int>(seed), percent, unpaired[0], unpaired[1], unpaired[2]);
        }
        CHECK(unpaired[1] <= unpaired[0]);
        CHECK(unpaired[2] <= unpaired[1]); // a walk is kept only if it pairs a saddle
      }
    }
  }
  std::printf("  %d noise fields: %d saddles unpaired (the verdict's reach) without the moves, %d with (%d fields "
              "better), %d with the walks too\n", cases, unpairedWithout, unpairedWith, improved, unpairedWalked);
  CHECK(unpairedWith < unpairedWithout);
}

// A boundary junction on a vertex beside one of a grid's one-triangle corners ((0, 0) and
// (n-1, n-1) with the split along (i+1, j)-(i, j+1)) has the vertex across the corner's diagonal in
// its link, a boundary vertex but no neighbour along the boundary curve. Topological sampling
// once let the junction's descent to its pit step across that diagonal: the junction's own
// vertex, left a pit of the curve below the corner, was filled past it, and the junction's
// saddle went missing (the corner's maximum too, when it had one; stress seed 53 #13). Uniform
// noise 16² and 24² at 10, 25 and 50 %, seeds 1-150, the fields whose simplified complex has a
// junction on such a vertex. The oracles, written here: the sampling's minima, saddles and
// maxima by the closed-boundary rule are as many as the complex's nodes plus a minimum and a
// saddle per junction (the version before: 9 of these fields one minimum and one saddle short, or
// more), and every such junction's saddle pairs with a sampled saddle within three edges and
// three grid diagonals (the verdict's reach), each sampled saddle used once.
TEST_CASE(AJunctionBesideAOneTriangleCornerKeepsItsSaddle)
{
  int fields = 0, junctions = 0, unpaired = 0, unequal = 0;
  for (int n : { 16, 24 })
  {
    for (double percent : { 10.0, 25.0, 50.0 })
    {
      for (std::uint64_t seed = 1; seed <= 150; ++seed)
      {
        const GridField grid = UniformNoise(n, seed);
        Pipeline p;
        std::string error;
        if (!RunStages1To3(grid, percent, 6, p, error))
        {
          CHECK(false);
          std::printf("  noise %d seed %d at %g %%: %s\n", n, static_cast<int>(seed), percent, error.c_str());
          continue;
        }
        const Index besideCorners[4] = { 1, n, n * n - 2, n * (n - 1) - 1 };
        std::vector<Index> besideCorner;
        for (Index junction : p.Simplified.Complex.BoundaryJunctions)
        {
          if (std::find(std::begin(besideCorners), std::end(besideCorners), junction) != std::end(besideCorners))
          {
            besideCorner.push_back(junction);
          }
        }
        if (besideCorner.empty())
        {
          continue;
        }
        FieldReconstruction reconstruction;
        reconstruction.VerifyTopology = false;
        FieldReconstructionReport report;
        CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
        const PlanarScalarField triangles = MeshFieldOnGrid(grid);
        // The counts first: the complex's nodes and a minimum and a saddle per junction.
        const std::array<int, 3> wanted = WantedCounts(p.Simplified.Complex);
        const std::array<int, 3> counted = CriticalCountsByTheBoundaryRule(triangles, report.Values);
        const std::vector<Index> found = SaddlesByTheBoundaryRule(triangles, report.Values);
        const std::vector<int> hops(besideCorner.size(), 3);
        const std::vector<double> distance(besideCorner.size(), 3 * std::sqrt(2.0) * (1 + 1e-9));
        const std::vector<int> partner =
          PairWithinHops(besideCorner, found, NeighboursOnMesh(triangles), 3, &hops, &triangles.Points, &distance);
        const int missing = static_cast<int>(std::count(partner.begin(), partner.end(), -1));
        ++fields;
        junctions += static_cast<int>(besideCorner.size());
        unpaired += missing;
        unequal += counted != wanted ? 1 : 0;
        if (missing > 0 || counted != wanted)
        {
          std::printf("  noise %d seed %d at %g %%: %d of %zu junctions beside a corner without a saddle; counted "
                      "%d/%d/%d, complex %d/%d/%d\n", n, static_cast<int>(seed), percent, missing, besideCorner.size(),
            counted[0], counted[1], counted[2], wanted[0], wanted[1], wanted[2]);
        }
      }
    }
  }
  std::printf("  %d noise fields with %d junctions beside a one-triangle corner: %d without a sampled saddle, "
              "%d fields whose counts differ from the complex's\n", fields, junctions, unpaired, unequal);
  CHECK(fields > 0); // the case exercises what it tests
  CHECK_EQ(unpaired, 0);
  CHECK_EQ(unequal, 0);
}

// A triangle mesh whose corner vertices are not the corners of its bounds (a grid with jittered
// points, as the stress test makes them): the curve of a 1-cell that runs along the boundary
// round such a corner was fitted through it without a node there and cut the corner off, and the
// corner vertex lay in no 2-cell (stress seed 53 #261 and #264). Stage 3 now takes the boundary
// vertex nearest each corner of the bounds as the domain's corner. Jittered grids at 25 and
// 50 %, k = 2 and 5 (long pieces, the worst cut), eight seeds. The oracles, written here: each
// of the grid's four corner vertices is the end of a smoothed piece (the boundary is made of
// 1-cells, so one passes every corner), and every vertex lies in a reconstructed 2-cell. Without
// the mesh's corners (meshCorners false, the version before) 112 of the 128 corners had no node
// and 32 vertices over the 32 grids were in no 2-cell.
TEST_CASE(AJitteredGridKeepsItsCornerVertices)
{
  int cases = 0, cornersOff = 0, uncovered = 0, cornersOffWithout = 0, uncoveredWithout = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed)
  {
    for (const double percent : { 25.0, 50.0 })
    {
      for (const int k : { 2, 5 })
      {
        const int nx = 24 + static_cast<int>(seed % 3) * 7, ny = 30 + static_cast<int>(seed % 4) * 9;
        DeterministicRandom random(seed);
        PlanarScalarField field;
        for (int j = 0; j < ny; ++j)
        {
          for (int i = 0; i < nx; ++i)
          {
            field.Points.push_back(i + random.Uniform(-0.2, 0.2));
            field.Points.push_back(j + random.Uniform(-0.2, 0.2));
            field.Values.push_back(std::sin(i / 5.0) * std::cos(j / 7.0) + 0.3 * random.Uniform(0, 1));
          }
        }
        field.Triangles = GridTriangles(nx, ny);
        const Index corners[4] = { 0, nx - 1, nx * (ny - 1), nx * ny - 1 };
        for (const bool meshCorners : { false, true })
        {
          Pipeline p;
          std::string error;
          if (!RunStages1To3(field, percent, k, p, error, false, meshCorners))
          {
            CHECK(false);
            std::printf("  seed %d at %g %%, k = %d: %s\n", static_cast<int>(seed), percent, k, error.c_str());
            continue;
          }
          int off = 0;
          for (const Index c : corners)
          {
            const double x = field.Points[2 * c], y = field.Points[2 * c + 1];
            bool end = false;
            for (const SmoothedPiece& piece : p.Smoothed.Pieces)
            {
              const std::vector<double>& b = piece.Curve.ControlPoints;
              const std::size_t last = b.size() - 2;
              end = end || (b[0] == x && b[1] == y) || (b[last] == x && b[last + 1] == y);
            }
            off += end ? 0 : 1;
          }
          FieldReconstruction reconstruction;
          reconstruction.VerifyTopology = false;
          FieldReconstructionReport report;
          CHECK(reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error));
          const int outside = static_cast<int>(
            std::count(report.CellOfVertex.begin(), report.CellOfVertex.end(), InvalidIndex));
          if (!meshCorners)
          {
            cornersOffWithout += off;
            uncoveredWithout += outside;
            continue;
          }
          ++cases;
          cornersOff += off;
          uncovered += outside;
          if (off > 0 || outside > 0)
          {
            std::printf("  seed %d at %g %%, k = %d: %d corners without a node, %d vertices in no 2-cell\n",
              static_cast<int>(seed), percent, k, off, outside);
          }
        }
      }
    }
  }
  std::printf("  %d jittered grids: %d corner vertices without a piece ending there, %d vertices in no 2-cell "
              "(without the mesh's corners: %d and %d)\n", cases, cornersOff, uncovered, cornersOffWithout,
    uncoveredWithout);
  CHECK(cases > 0);
  CHECK_EQ(cornersOff, 0);
  CHECK_EQ(uncovered, 0);
  CHECK(uncoveredWithout > 0); // the case exercises what it tests
}

// Images only a few vertices across: strips two vertices wide (every vertex on the boundary, so
// a boundary saddle's way up must rise across the strip) and 3 x 3 to 4 x 4 grids (one to four
// interior vertices), uniform noise, k = 4. The oracles, written here: the critical points of
// the sampled field counted by the closed-boundary rule equal the complex's (its nodes and a
// minimum and a saddle per boundary junction), and each wanted saddle has a sampled one within
// two edges and two spacings (one to one). At 0 % the complex is the input's own, which the
// input itself realizes: every field must pass. At 5 % a cancellation can leave a complex no
// values on so few vertices realize (2 x 10 seed 2: two boundary saddles side by side, each the
// only way up of the other); at most one field in 25 may miss there. Every vertex of such a
// strip has only boundary neighbours, which topological sampling took for a domain corner (a
// boundary saddle there wanted on its higher neighbour and then cut to the pit beside it), and
// it had no way up across the strip.
TEST_CASE(StripsAndTinyGridsKeepTheComplexsCriticalPoints)
{
  std::vector<std::array<int, 2>> shapes;
  for (int n = 3; n <= 12; ++n)
  {
    shapes.push_back({ { 2, n } });
    shapes.push_back({ { n, 2 } });
  }
  for (const std::array<int, 2> shape : { std::array<int, 2>{ { 3, 3 } }, { { 3, 4 } }, { { 4, 3 } }, { { 4, 4 } } })
  {
    shapes.push_back(shape);
  }
  int fields[2] = { 0, 0 }, missed[2] = { 0, 0 };
  for (const std::array<int, 2>& shape : shapes)
  {
    for (const double percent : { 0.0, 5.0 })
    {
      const int p5 = percent > 0 ? 1 : 0;
      for (std::uint64_t seed = 1; seed <= 6; ++seed)
      {
        GridField grid;
        grid.Dimensions[0] = shape[0];
        grid.Dimensions[1] = shape[1];
        DeterministicRandom random(1000 * seed + 10 * shape[0] + shape[1]);
        for (int v = 0; v < shape[0] * shape[1]; ++v)
        {
          grid.Values.push_back(random.Uniform());
        }
        Pipeline p;
        std::string error;
        FieldReconstruction reconstruction;
        reconstruction.VerifyTopology = false;
        FieldReconstructionReport report;
        if (!RunStages1To3(grid, percent, 4, p, error) ||
          !reconstruction.Run(p.Field, p.Simplified.Complex, p.Smoothed, report, error))
        {
          CHECK(false);
          std::printf("  %d x %d seed %d at %g %%: %s\n", shape[0], shape[1], static_cast<int>(seed), percent,
            error.c_str());
          continue;
        }
        ++fields[p5];
        const PlanarScalarField triangles = MeshFieldOnGrid(grid);
        const std::array<int, 3> wanted = WantedCounts(p.Simplified.Complex);
        std::vector<Index> wantedSaddles = p.Simplified.Complex.BoundaryJunctions;
        for (const CriticalPoint& cp : p.Simplified.Complex.CriticalPoints)
        {
          if (cp.MorseIndex == 1)
          {
            wantedSaddles.push_back(cp.Vertex);
          }
        }
        const std::array<int, 3> counted = CriticalCountsByTheBoundaryRule(triangles, report.Values);
        const std::vector<Index> found = SaddlesByTheBoundaryRule(triangles, report.Values);
        const std::vector<double> distance(wantedSaddles.size(), 2 * std::sqrt(2.0) * (1 + 1e-9));
        const std::vector<int> partner =
          PairWithinHops(wantedSaddles, found, NeighboursOnMesh(triangles), 2, nullptr, &triangles.Points, &distance);
        const int missing = static_cast<int>(std::count(partner.begin(), partner.end(), -1));
        missed[p5] += counted != wanted || missing > 0 ? 1 : 0;
        if (counted != wanted || missing > 0)
        {
          std::printf("  %d x %d seed %d at %g %%: counted %d/%d/%d, complex %d/%d/%d, %d wanted saddles unpaired\n",
            shape[0], shape[1], static_cast<int>(seed), percent, counted[0], counted[1], counted[2], wanted[0],
            wanted[1], wanted[2], missing);
        }
      }
    }
  }
  std::printf("  at 0 %%: %d fields, %d with counts unlike the complex's or a saddle off its node; at 5 %%: %d and %d\n",
    fields[0], missed[0], fields[1], missed[1]);
  CHECK_EQ(fields[0], static_cast<int>(shapes.size()) * 6);
  CHECK_EQ(fields[1], static_cast<int>(shapes.size()) * 6);
  CHECK_EQ(missed[0], 0);
  CHECK(25 * missed[1] <= fields[1]);
}

int main()
{
  return testing_harness::RunAll();
}

