#include "FieldReconstruction.h"

#include "CompressedGraph.h"
#include "MorseSmaleComplexExtraction.h"
#include "PlanarGeometry.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

namespace topospline
{
namespace
{
double SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Stage 1 on `sampling`, compared with the complex's critical points (within `tolerance`, and
// within their Hops of `mesh` when the sampling is on the input's vertices).
SamplingTopologyCheck CheckSampling(const PlanarScalarField& sampling,
  const std::vector<CriticalPointLocation>& expected, double tolerance, const ParallelFor& parallel,
  const TriangleMeshTopology* mesh = nullptr)
{
  SamplingTopologyCheck check;
  MorseSmaleComplexExtraction extraction;
  extraction.Parallel = parallel;
  extraction.CriticalPointsOnly = true;
  // The sampling's mesh is the reconstruction's (built from the same grid or triangles, so
  // numbered alike): building it twice more took about a second on 1000 x 1000 noise.
  extraction.GivenMesh = mesh;
  MorseSmaleComplex found;
  if (!extraction.Extract(sampling, found, check.Error))
  {
    return check;
  }
  check.Comparison =
    CompareCriticalPoints(expected, CriticalPointLocations(found, sampling.Points), tolerance, mesh, parallel);
  check.Ran = true;
  return check;
}

// The field with other values at the same vertices (copied whole, so that no member of the
// field's geometry is left behind; the input's values are small beside its points).
PlanarScalarField WithValues(const PlanarScalarField& field, const std::vector<double>& values)
{
  PlanarScalarField sampling = field;
  sampling.Values = values;
  return sampling;
}

// The global minimum and maximum of a field are critical points of its complex, and no
// simplification cancels them: critical values that are all equal make a constant field (or
// one stage 1 read as constant, MorseSmaleComplexExtraction::NearConstantAsConstant).
bool IsConstantComplex(const MorseSmaleComplex& complex)
{
  const auto& points = complex.CriticalPoints;
  return !points.empty() && std::all_of(points.begin(), points.end(),
                              [&](const CriticalPoint& p) { return p.Value == points.front().Value; });
}
} // namespace

double LargestEdgeLength(const PlanarScalarField& field)
{
  if (field.IsGrid())
  {
    return std::hypot(field.GridSpacing[0], field.GridSpacing[1]);
  }
  double longest = 0;
  const auto& p = field.Points;
  for (std::size_t t = 0; t + 2 < field.Triangles.size(); t += 3)
  {
    for (int e = 0; e < 3; ++e)
    {
      const Index a = field.Triangles[t + e], b = field.Triangles[t + (e + 1) % 3];
      longest = std::max(longest, std::hypot(p[2 * a] - p[2 * b], p[2 * a + 1] - p[2 * b + 1]));
    }
  }
  return longest;
}

double MeanEdgeLength(const PlanarScalarField& field)
{
  const auto& p = field.Points;
  if (field.IsGrid())
  {
    // The grid's triangles: both axes and the (i+1,j)-(i,j+1) diagonal.
    const double dx = std::abs(p[2] - p[0]);
    const double dy = std::abs(p[2 * field.GridDimensions[0] + 1] - p[1]);
    return (dx + dy + std::hypot(dx, dy)) / 3;
  }
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t t = 0; t + 2 < field.Triangles.size(); t += 3)
  {
    for (int e = 0; e < 3; ++e)
    {
      const Index a = field.Triangles[t + e], b = field.Triangles[t + (e + 1) % 3];
      sum += std::hypot(p[2 * a] - p[2 * b], p[2 * a + 1] - p[2 * b + 1]);
      ++count;
    }
  }
  return count ? sum / count : 0;
}

bool BuildMesh(const PlanarScalarField& field, TriangleMeshTopology& mesh, const ParallelFor& parallel,
  std::string& error)
{
  if (field.IsGrid())
  {
    mesh.BuildGrid(field.GridDimensions[0], field.GridDimensions[1], parallel);
    return true;
  }
  return mesh.Build(static_cast<Index>(field.Points.size() / 2), field.Triangles, parallel, error);
}

double FieldReconstruction::MemoryEstimate(double vertices, double cells, double finerPoints)
{
  return 800.0 * vertices + 6.5e3 * cells + 260.0 * finerPoints;
}

GridField FieldReconstruction::FinerGrid(const PlanarScalarField& field) const
{
  GridField grid;
  const int f = this->OutputResolution;
  if (field.IsGrid())
  {
    // From the grid's first point: an image's extent need not start at 0 (a cropped image).
    for (int axis = 0; axis < 2; ++axis)
    {
      grid.Origin[axis] = field.Points[axis];
      grid.Spacing[axis] = field.GridSpacing[axis] / f;
      grid.Dimensions[axis] = (field.GridDimensions[axis] - 1) * f + 1;
    }
    return grid;
  }
  double bounds[4] = { field.Points[0], field.Points[0], field.Points[1], field.Points[1] };
  for (std::size_t v = 0; 2 * v < field.Points.size(); ++v)
  {
    bounds[0] = std::min(bounds[0], field.Points[2 * v]);
    bounds[1] = std::max(bounds[1], field.Points[2 * v]);
    bounds[2] = std::min(bounds[2], field.Points[2 * v + 1]);
    bounds[3] = std::max(bounds[3], field.Points[2 * v + 1]);
  }
  const double h = std::max(MeanEdgeLength(field) / f, 1e-12 * (bounds[1] - bounds[0] + bounds[3] - bounds[2]));
  for (int axis = 0; axis < 2; ++axis)
  {
    const double low = bounds[2 * axis], high = bounds[2 * axis + 1];
    grid.Origin[axis] = low;
    grid.Dimensions[axis] = std::max(2, static_cast<int>(std::ceil((high - low) / h)) + 1);
    grid.Spacing[axis] = (high - low) / (grid.Dimensions[axis] - 1);
  }
  return grid;
}

topospline::TopologicalSampling FieldReconstruction::SamplingOf(const MorseSmaleComplex& complex,
  const TriangleMeshTopology& mesh, const PlanarScalarField& field, const OneCellSmoothingResult& smoothed,
  double progressFrom, double progressTo) const
{
  topospline::TopologicalSampling sampling(complex, mesh, field.Points, smoothed);
  sampling.Spacing = this->Spacing;
  sampling.Parallel = this->Parallel;
  sampling.Hooks.Progress = [this, progressFrom, progressTo](double f) {
    this->Hooks.Report(progressFrom + (progressTo - progressFrom) * f);
  };
  sampling.Hooks.AbortRequested = this->Hooks.AbortRequested;
  return sampling;
}

namespace
{
// SquareBucket (PlanarGeometry.h) is the one rule by which BucketIndex registers points and
// OneCellSamples keeps and looks up its samples (they must agree, see BucketIndex).

// The square buckets of side `side` that hold points (x, y) at (floor(x / side), floor(y / side)),
// and which items are registered in each. Items register in the buckets as OneCellSamples::
// Nearest looks into them: the bucket of each point (x + dx side, y + dy side), dx and dy in
// {-1, 0, 1} (not floor(x / side) + dx, which may round differently). A sample of a smoothed
// curve in bucket B is then seen by exactly the items registered in B. Per bucket of the box
// they span when that box is not much larger than their number (a grid's points), by a sorted
// list otherwise (a few points far apart). Looked up once per Bezier segment of every smoothed
// 1-cell: on 1000 x 1000 noise a hash set of the buckets was a third of counting the spurious
// points of F o Phi.
class BucketIndex
{
public:
  BucketIndex(double side, const std::vector<double>& around)
    : Side(side)
  {
    std::vector<std::array<long long, 3>> entries; // i, j, item
    entries.reserve(9 * (around.size() / 2));
    for (std::size_t p = 0; p + 1 < around.size(); p += 2)
    {
      for (int dx = -1; dx <= 1; ++dx)
      {
        for (int dy = -1; dy <= 1; ++dy)
        {
          const auto [i, j] = this->BucketOf(around[p] + dx * side, around[p + 1] + dy * side);
          entries.push_back({ i, j, static_cast<long long>(p / 2) });
        }
      }
    }
    if (entries.empty())
    {
      return;
    }
    this->I0 = this->I1 = entries[0][0];
    this->J0 = this->J1 = entries[0][1];
    for (const auto& e : entries)
    {
      this->I0 = std::min(this->I0, e[0]);
      this->I1 = std::max(this->I1, e[0]);
      this->J0 = std::min(this->J0, e[1]);
      this->J1 = std::max(this->J1, e[1]);
    }
    const double box = (static_cast<double>(this->I1 - this->I0) + 1) * (static_cast<double>(this->J1 - this->J0) + 1);
    this->Dense = box <= std::max(1.0 * (1 << 20), 16.0 * static_cast<double>(entries.size())) &&
      box < static_cast<double>(std::numeric_limits<Index>::max());
    if (this->Dense)
    {
      // Rows per bucket of the box, items in each in the order they registered (increasing).
      std::vector<std::array<Index, 2>> itemInBucket(entries.size());
      for (std::size_t k = 0; k < entries.size(); ++k)
      {
        itemInBucket[k] = { static_cast<Index>(this->Slot(entries[k][0], entries[k][1])),
          static_cast<Index>(entries[k][2]) };
      }
      CompressedGraph rows(static_cast<Index>(box), itemInBucket);
      this->Offsets = std::move(rows.Offsets);
      this->Items = std::move(rows.Targets);
    }
    else
    {
      std::sort(entries.begin(), entries.end());
      this->Items.resize(entries.size());
      this->Keys.resize(entries.size());
      for (std::size_t k = 0; k < entries.size(); ++k)
      {
        this->Keys[k] = { entries[k][0], entries[k][1] };
        this->Items[k] = static_cast<Index>(entries[k][2]);
      }
    }
  }

  std::pair<long long, long long> BucketOf(double x, double y) const { return SquareBucket(x, y, this->Side); }

  // The items registered in bucket (i, j): [first, last).
  std::pair<const Index*, const Index*> ItemsIn(long long i, long long j) const
  {
    if (this->Items.empty() || i < this->I0 || i > this->I1 || j < this->J0 || j > this->J1)
    {
      return { nullptr, nullptr };
    }
    if (this->Dense)
    {
      const std::size_t slot = this->Slot(i, j);
      return { this->Items.data() + this->Offsets[slot], this->Items.data() + this->Offsets[slot + 1] };
    }
    const std::pair<long long, long long> key(i, j);
    const auto range = std::equal_range(this->Keys.begin(), this->Keys.end(), key);
    return { this->Items.data() + (range.first - this->Keys.begin()),
      this->Items.data() + (range.second - this->Keys.begin()) };
  }
  bool Contains(long long i, long long j) const
  {
    const auto [first, last] = this->ItemsIn(i, j);
    return first != last;
  }
  bool Empty() const { return this->Items.empty(); }

  // Calls visit(xy, i, j, piece, segment, s) for the samples xy of the smoothed pieces [begin,
  // end) that lie in a bucket (i, j) with items (s: the parameter on the piece's segment). A
  // segment lies in its control points' bounding box (widened against rounding): it is sampled
  // only if a bucket of that box has items (or the box spans over 64 buckets). Samples per
  // segment: SamplesPerSegment, or more where the segment is long: its speed is at most 3 times
  // its longest control leg, so with m >= SamplesPerSide x 3 x leg / side equal parameter steps
  // consecutive samples are at most 1/16 of a side apart along the curve, and a sample lies
  // within 1/32 of a side of every curve point. (A fixed 16 per segment put samples up to about
  // 19 grid spacings apart on the 2000 x 2000 terrain's 1-cells, whose control legs reach 100
  // spacings: points next to a curve were counted as far from it.)
  static constexpr int SamplesPerSegment = 16;
  static constexpr double SamplesPerSide = 16;
  template <typename Visit>
  void ForEachSampleInBuckets(const OneCellSmoothingResult& smoothed, Index begin, Index end, const Visit& visit) const
  {
    for (Index p = begin; p < end; ++p)
    {
      const SmoothedPiece& piece = smoothed.Pieces[p];
      for (int j = 0; j < piece.Curve.Segments; ++j)
      {
        const double* control = piece.Curve.Segment(j);
        if (!this->MayHoldItems(control))
        {
          continue;
        }
        double leg = 0;
        for (int c = 0; c < 3; ++c)
        {
          leg = std::max(leg, std::hypot(control[2 * c + 2] - control[2 * c], control[2 * c + 3] - control[2 * c + 1]));
        }
        // (The curves lie in the domain: at most about 50 samples per side of its diameter.)
        const int perSegment = static_cast<int>(
          std::clamp(std::ceil(SamplesPerSide * 3 * leg / this->Side), static_cast<double>(SamplesPerSegment), 1e8));
        for (int m = 0; m <= perSegment; ++m)
        {
          const double s = static_cast<double>(m) / perSegment;
          double xy[2];
          CubicBezierSpline::EvaluateSegment(piece.Curve.Segment(j), 2, s, xy);
          const auto [bi, bj] = this->BucketOf(xy[0], xy[1]);
          if (this->Contains(bi, bj))
          {
            visit(xy, bi, bj, p, j, s);
          }
        }
      }
    }
  }

private:
  bool MayHoldItems(const double* control) const
  {
    double low[2] = { control[0], control[1] }, high[2] = { control[0], control[1] };
    for (int c = 1; c < 4; ++c)
    {
      for (int axis = 0; axis < 2; ++axis)
      {
        low[axis] = std::min(low[axis], control[2 * c + axis]);
        high[axis] = std::max(high[axis], control[2 * c + axis]);
      }
    }
    const double margin = 1e-6 * this->Side;
    const long long i0 = static_cast<long long>(std::floor((low[0] - margin) / this->Side));
    const long long i1 = static_cast<long long>(std::floor((high[0] + margin) / this->Side));
    const long long j0 = static_cast<long long>(std::floor((low[1] - margin) / this->Side));
    const long long j1 = static_cast<long long>(std::floor((high[1] + margin) / this->Side));
    if ((i1 - i0 + 1) * (j1 - j0 + 1) > 64)
    {
      return true; // a long segment: sampled, its samples filtered one by one
    }
    for (long long i = i0; i <= i1; ++i)
    {
      for (long long j = j0; j <= j1; ++j)
      {
        if (this->Contains(i, j))
        {
          return true;
        }
      }
    }
    return false;
  }
  std::size_t Slot(long long i, long long j) const
  {
    return static_cast<std::size_t>(j - this->J0) * static_cast<std::size_t>(this->I1 - this->I0 + 1) +
      static_cast<std::size_t>(i - this->I0);
  }
  double Side;
  long long I0 = 0, I1 = -1, J0 = 0, J1 = -1;
  bool Dense = false;
  std::vector<Index> Offsets;                          // dense: per bucket of the box
  std::vector<std::pair<long long, long long>> Keys;   // sparse: each item's bucket, sorted
  std::vector<Index> Items;
};
} // namespace

// The smoothed curves, sampled finely enough that the nearest sample is within 1/32 of `side` of
// the nearest curve point (BucketIndex::ForEachSampleInBuckets), with their heights, in square
// buckets of side `side`: the samples within `side` of a point lie in its bucket or the 8 around
// it.
OneCellSamples::OneCellSamples(const OneCellSmoothingResult& smoothed, double side, const std::vector<double>& around)
  : Side(side > 0 ? side : 1.0)
{
  // Only the buckets Nearest looks into for the points around.
  const BucketIndex wanted(this->Side, around);
  if (wanted.Empty())
  {
    return;
  }
  wanted.ForEachSampleInBuckets(smoothed, 0, static_cast<Index>(smoothed.Pieces.size()),
    [&](const double* xy, long long bi, long long bj, Index p, int j, double s) {
      const SmoothedPiece& piece = smoothed.Pieces[p];
      Sample sample;
      sample.XY[0] = xy[0];
      sample.XY[1] = xy[1];
      sample.Height = piece.Height.Segments > 0 ? piece.Height.Value((j + s) / piece.Curve.Segments) : 0;
      this->Buckets[this->KeyOf(bi, bj)].push_back(sample);
    });
}

long long OneCellSamples::Key(double x, double y) const
{
  const auto [i, j] = SquareBucket(x, y, this->Side);
  return this->KeyOf(i, j);
}

long long OneCellSamples::KeyOf(long long i, long long j) const
{
  return SquareBucketKey(i, j);
}

bool OneCellSamples::Nearest(double x, double y, double distance, double& height) const
{
  double best = std::min(distance, this->Side);
  bool found = false;
  for (int dx = -1; dx <= 1; ++dx)
  {
    for (int dy = -1; dy <= 1; ++dy)
    {
      const auto bucket = this->Buckets.find(this->Key(x + dx * this->Side, y + dy * this->Side));
      if (bucket == this->Buckets.end())
      {
        continue;
      }
      for (const Sample& sample : bucket->second)
      {
        const double d = std::hypot(sample.XY[0] - x, sample.XY[1] - y);
        if (d <= best)
        {
          best = d;
          height = sample.Height;
          found = true;
        }
      }
    }
  }
  return found;
}

bool FieldReconstruction::Run(const PlanarScalarField& field, const MorseSmaleComplex& complex,
  const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report, std::string& error)
{
  const PlanarFrame& frame = complex.Frame;
  if (frame.IsIdentity())
  {
    return this->RunInFrame(field, complex, smoothed, report, error);
  }
  // Triangulations, mean value maps, fits and "one spacing" in the complex's frame (see
  // PlanarFrame); values are the same in both, positions are mapped back.
  PlanarScalarField framedField = field;
  frame.ToFrame(framedField.Points);
  framedField.GridSpacing[0] /= frame.Scale[0];
  framedField.GridSpacing[1] /= frame.Scale[1];
  MorseSmaleComplex framedComplex = complex;
  GeometryToFrame(frame, framedComplex);
  OneCellSmoothingResult framedSmoothed = smoothed;
  MapSmoothedGeometry(framedSmoothed, [&frame](double* xy) { frame.ToFrame(xy); });
  if (!this->RunInFrame(framedField, framedComplex, framedSmoothed, report, error))
  {
    return false;
  }
  for (int axis = 0; axis < 2; ++axis)
  {
    report.Finer.Origin[axis] *= frame.Scale[axis];
    report.Finer.Spacing[axis] *= frame.Scale[axis];
  }
  for (auto& patches : report.Patches)
  {
    for (PlanarBezierTriangle& triangle : patches)
    {
      for (auto& point : triangle.Points)
      {
        frame.ToWorld(point.data());
      }
    }
  }
  const auto toWorld = [&frame](std::vector<CriticalPointLocation>& points) {
    for (CriticalPointLocation& point : points)
    {
      frame.ToWorld(point.Position);
    }
  };
  toWorld(report.Expected);
  toWorld(report.Spurious);
  toWorld(report.Missing);
  for (SamplingTopologyCheck* check : { &report.RawInput, &report.Input, &report.Resampled })
  {
    toWorld(check->Comparison.Spurious);
    toWorld(check->Comparison.Missing);
    // Distances do not map through a scaling per axis: this bounds the world distance.
    check->Comparison.MaximumDistance *= std::max(frame.Scale[0], frame.Scale[1]);
  }
  return true;
}

bool FieldReconstruction::RunInFrame(const PlanarScalarField& field, const MorseSmaleComplex& complex,
  const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report, std::string& error)
{
  report = FieldReconstructionReport();
  // One grid spacing: how far a vertex may lie outside the smoothed cells, and how far a
  // critical point of a sampling may lie from its node.
  this->Spacing = LargestEdgeLength(field);
  this->Cells = TwoCellReconstruction();
  this->Cells.BoundarySamples = this->BoundarySamples;
  this->Cells.SnapDistance = this->Spacing;
  const double edge = MeanEdgeLength(field);
  this->Cells.MinimumMeshEdgeLength = 2 * edge;
  this->Cells.NegligibleArea = edge * edge;
  // The paper's interior keeps the paper's c on every segment (Table 1 as the paper defines it).
  this->Cells.BoundarySampleSpacing = this->Interior == TwoCellInterior::Fitted && this->BoundarySampleEdges > 0
    ? this->BoundarySampleEdges * edge / std::max(1, this->OutputResolution)
    : 0;
  this->Cells.Interior = this->Interior;
  this->Cells.AlternativeMapStrength = this->AlternativeMapStrength;
  this->Cells.MemoryBudget = this->MemoryBudget;
  if (!field.Values.empty())
  {
    const auto [lowest, highest] = std::minmax_element(field.Values.begin(), field.Values.end());
    this->Cells.SurfaceTolerance = this->SurfaceTolerance * (*highest - *lowest);
  }
  this->Cells.Parallel = this->Parallel;
  this->Cells.Hooks.Progress = [this](double f) { this->Hooks.Report(0.6 * f); };
  this->Cells.Hooks.AbortRequested = this->Hooks.AbortRequested;
  TriangleMeshTopology mesh;
  std::string ignored; // the input's mesh was checked by stage 1
  BuildMesh(field, mesh, this->Parallel, ignored);
  if (IsConstantComplex(complex))
  {
    this->ReconstructConstant(field, mesh, complex, report);
    return true;
  }
  this->Cells.Mesh = &mesh; // for the stiffening rounds: which vertices are neighbours
  this->Cells.StiffeningRounds = this->StiffeningRounds;
  this->Cells.OrderingRounds = this->OrderingRounds;
  this->Cells.FarFromOneCells = this->FarFromOneCellsSpacings * GridSpacing(field);
  this->Cells.AxisAimTrigger = this->AxisAimTrigger;
  this->Cells.SmallCellFitTrigger = this->SmallCellFitTrigger;
  const bool reconstructed = this->Cells.Reconstruct(complex, smoothed, error, &field);
  this->Cells.Mesh = nullptr; // a local
  if (!reconstructed)
  {
    return false;
  }
  report.Cells = this->Cells.Report();
  for (Index c = 0; c < this->Cells.NumberOfCells(); ++c)
  {
    if (!this->Cells.Cell(c).Valid && !this->Cells.Cell(c).Negligible)
    {
      report.FailedCells.emplace_back(c, this->Cells.Cell(c).Error);
    }
  }

  // Everything that needs the cells first (F o Phi at the vertices and on the finer grid, the
  // patches); then they are released: on large noise they are half the memory, and the
  // sampling and the check would come on top of them.
  this->EvaluateAtVertices(field, complex, smoothed, report);
  if (this->OutputResolution > 1)
  {
    this->EvaluateOnFinerGrid(field, report);
  }
  this->CollectPatches(report);
  this->Cells = TwoCellReconstruction();
  if (this->ReleaseFreedMemory)
  {
    this->ReleaseFreedMemory();
  }
  // Topological sampling, the resampling and the verification each take seconds on large
  // noise: an abort is honoured between them (and between the sampling's passes).
  if (this->TopologicalSampling)
  {
    this->SampleTopologicallyAtVertices(field, mesh, complex, smoothed, report);
  }
  if (report.Sampling.Aborted || this->Hooks.Aborted())
  {
    error = "aborted";
    return false;
  }
  this->Hooks.Report(0.7);
  this->MeasureErrors(field, report);
  this->Hooks.Report(0.75);
  if (this->OutputResolution > 1 && this->TopologicalSampling)
  {
    this->SampleFinerGrid(field, mesh, complex, smoothed, report);
  }
  if (report.Sampling.Aborted || this->Hooks.Aborted())
  {
    error = "aborted";
    return false;
  }
  this->Hooks.Report(0.85);
  if (this->VerifyTopology)
  {
    this->Verify(field, mesh, complex, smoothed, report);
  }
  this->Hooks.Report(1.0);
  return true;
}

// A constant field's complex is that of its ties ordered by vertex id, which the constant
// itself has: every 2-cell and 1-cell is flat at it, on every sampling. (The paper's surfaces
// cannot be flat: strictly monotone 1-cells of a constant field rise by a spreading of 1e-11
// of its magnitude, and a 2-cell's Sibson grid of over 500 steps, as at k = 30, leaves too few
// ulps per step for its monotonicity conditions.)
void FieldReconstruction::ReconstructConstant(const PlanarScalarField& field, const TriangleMeshTopology& mesh,
  const MorseSmaleComplex& complex, FieldReconstructionReport& report) const
{
  const double value = complex.CriticalPoints.front().Value;
  const Index n = static_cast<Index>(field.Values.size());
  report.Values.assign(n, value);
  report.Exact = report.Values;
  report.Difference.resize(n);
  for (Index v = 0; v < n; ++v)
  {
    report.Difference[v] = value - field.Values[v];
  }
  report.CellOfVertex.assign(n, 0);
  if (complex.TwoCellId.size() == field.Values.size())
  {
    std::copy(complex.TwoCellId.begin(), complex.TwoCellId.end(), report.CellOfVertex.begin());
  }
  this->MeasureErrors(field, report);
  if (this->OutputResolution > 1)
  {
    report.Finer = this->FinerGrid(field);
    const std::size_t m = static_cast<std::size_t>(report.Finer.Dimensions[0]) * report.Finer.Dimensions[1];
    report.Finer.Values.assign(m, value);
    report.FinerValid.assign(m, 1);
  }
  if (this->VerifyTopology)
  {
    this->Verify(field, mesh, complex, OneCellSmoothingResult(), report);
  }
  this->Hooks.Report(1.0);
}

// F o Phi at every input vertex; the vertex's 2-cell of the jagged complex is the first guess.
void FieldReconstruction::EvaluateAtVertices(const PlanarScalarField& field, const MorseSmaleComplex& complex,
  const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report) const
{
  const auto start = std::chrono::steady_clock::now();
  const Index n = static_cast<Index>(field.Values.size());
  const bool hints = complex.TwoCellId.size() == field.Values.size();
  report.Values.resize(n);
  report.Difference.resize(n);
  report.CellOfVertex.resize(n);
  std::atomic<Index> snapped(0), missed(0);
  this->Parallel(0, n, [&](Index begin, Index end) {
    Index localSnapped = 0, localMissed = 0;
    for (Index v = begin; v < end; ++v)
    {
      const double* xy = &field.Points[2 * static_cast<std::size_t>(v)];
      const auto e = this->Cells.Evaluate(xy[0], xy[1], hints ? complex.TwoCellId[v] : InvalidIndex);
      const double f = field.Values[v];
      if (e.Cell == InvalidIndex)
      {
        // No reconstructed cell here (a failed cell): the input value, reported.
        ++localMissed;
        report.Values[v] = f;
      }
      else
      {
        localSnapped += e.Inside ? 0 : 1;
        report.Values[v] = e.Value;
      }
      report.Difference[v] = report.Values[v] - f;
      report.CellOfVertex[v] = e.Cell;
    }
    snapped += localSnapped;
    missed += localMissed;
  });
  report.SnappedPoints = snapped.load();
  report.UnreconstructedPoints = missed.load();
  if (report.UnreconstructedPoints > 0)
  {
    // A cell too small to reconstruct (NegligibleArea) holds a vertex or two, all within a
    // spacing of its boundary: they take the height of the nearest smoothed 1-cell. So does
    // any vertex within a spacing of one; the rest keep their input value and are reported.
    std::vector<Index> missed;
    std::vector<double> missedPoints;
    for (Index v = 0; v < n; ++v)
    {
      if (report.CellOfVertex[v] == InvalidIndex)
      {
        missed.push_back(v);
        missedPoints.insert(missedPoints.end(), &field.Points[2 * static_cast<std::size_t>(v)],
          &field.Points[2 * static_cast<std::size_t>(v)] + 2);
      }
    }
    const OneCellSamples samples(smoothed, this->Spacing, missedPoints);
    for (std::size_t m = 0; m < missed.size(); ++m)
    {
      const Index v = missed[m];
      double height;
      if (samples.Nearest(missedPoints[2 * m], missedPoints[2 * m + 1], this->Spacing, height))
      {
        report.Values[v] = height;
        report.Difference[v] = height - field.Values[v];
        ++report.PointsOnOneCells;
        --report.UnreconstructedPoints;
      }
    }
  }
  report.EvaluationSeconds = SecondsSince(start);
}

// F o Phi itself stays available as Exact (it interpolates the critical values exactly; the
// flooding may move a node's value when the node sits in a spurious pit or peak).
void FieldReconstruction::SampleTopologicallyAtVertices(const PlanarScalarField& field,
  const TriangleMeshTopology& mesh, const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed,
  FieldReconstructionReport& report) const
{
  report.Sampled = true;
  report.Exact = report.Values;
  const auto sameVertex = [](Index v) { return v; };
  report.Sampling =
    this->SamplingOf(complex, mesh, field, smoothed, 0.6, 0.7).Apply(field, mesh, sameVertex, report.Values);
  for (std::size_t v = 0; v < report.Values.size(); ++v)
  {
    report.Difference[v] = report.Values[v] - field.Values[v];
  }
}

void FieldReconstruction::MeasureErrors(const PlanarScalarField& field, FieldReconstructionReport& report) const
{
  if (!field.Values.empty())
  {
    const auto range = std::minmax_element(field.Values.begin(), field.Values.end());
    report.ValueRange[0] = *range.first;
    report.ValueRange[1] = *range.second;
  }
  double squares = 0;
  for (const double d : report.Difference)
  {
    report.MaximumError = std::max(report.MaximumError, std::abs(d));
    squares += d * d;
  }
  const std::size_t n = report.Difference.size();
  report.RMSError = n ? std::sqrt(squares / n) : 0;
}

void FieldReconstruction::CollectPatches(FieldReconstructionReport& report) const
{
  report.PatchesOmitted = static_cast<double>(report.Cells.BezierTriangles) > this->MaximumPatchTriangles;
  if (report.PatchesOmitted)
  {
    return;
  }
  report.Patches.resize(this->Cells.NumberOfCells());
  this->Parallel(0, this->Cells.NumberOfCells(), [&](Index begin, Index end) {
    for (Index c = begin; c < end; ++c)
    {
      report.Patches[c] = this->Cells.PlanarBezierTriangles(c);
    }
  });
}

// F o Phi on the finer grid (0 where no cell covers a point).
void FieldReconstruction::EvaluateOnFinerGrid(const PlanarScalarField& field, FieldReconstructionReport& report) const
{
  const GridField grid = this->FinerGrid(field);
  PlanarScalarField fine = FieldOnGrid(grid);
  const Index m = static_cast<Index>(fine.Points.size() / 2);
  fine.Values.resize(m);
  report.FinerValid.resize(m);
  this->Parallel(0, m, [&](Index begin, Index end) {
    for (Index p = begin; p < end; ++p)
    {
      const auto e = this->Cells.Evaluate(fine.Points[2 * static_cast<std::size_t>(p)],
        fine.Points[2 * static_cast<std::size_t>(p) + 1]);
      fine.Values[p] = e.Cell == InvalidIndex ? 0.0 : e.Value;
      report.FinerValid[p] = e.Cell == InvalidIndex ? 0 : 1;
    }
  });
  report.Finer = grid;
  report.Finer.Values = std::move(fine.Values);
}

// The topological sampling of the finer grid, with each node on the grid point nearest to it.
void FieldReconstruction::SampleFinerGrid(const PlanarScalarField& field, const TriangleMeshTopology& mesh,
  const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report) const
{
  // The grid's values move into the sampled field and back (no second copy of a fine grid).
  std::vector<double> values = std::move(report.Finer.Values);
  const GridField& grid = report.Finer;
  const int ni = grid.Dimensions[0], nj = grid.Dimensions[1];
  PlanarScalarField fine = FieldOnGrid(grid);
  fine.Values = std::move(values);
  TriangleMeshTopology fineMesh;
  fineMesh.BuildGrid(ni, nj, this->Parallel);
  const auto fineReport = this->SamplingOf(complex, mesh, field, smoothed, 0.75, 0.85).Apply(fine, fineMesh,
    [&](Index v) {
      const double* xy = &field.Points[2 * static_cast<std::size_t>(v)];
      const int i = std::clamp(static_cast<int>(std::lround((xy[0] - grid.Origin[0]) / grid.Spacing[0])), 0, ni - 1);
      const int j = std::clamp(static_cast<int>(std::lround((xy[1] - grid.Origin[1]) / grid.Spacing[1])), 0, nj - 1);
      return static_cast<Index>(j * ni + i);
    },
    fine.Values);
  report.Sampling.DisplacedSaddles += fineReport.DisplacedSaddles;
  report.Sampling.MovedBoundarySaddles += fineReport.MovedBoundarySaddles;
  report.Sampling.ChangedVertices += fineReport.ChangedVertices;
  report.Sampling.MaximumChange = std::max(report.Sampling.MaximumChange, fineReport.MaximumChange);
  report.Sampling.Converged = report.Sampling.Converged && fineReport.Converged;
  report.Sampling.Aborted = report.Sampling.Aborted || fineReport.Aborted;
  report.Finer.Values = std::move(fine.Values);
}

double GridSpacing(const PlanarScalarField& field)
{
  return field.IsGrid() ? std::max(field.GridSpacing[0], field.GridSpacing[1]) : MeanEdgeLength(field);
}

void CountByDistanceToOneCells(const std::vector<CriticalPointLocation>& points, const OneCellSmoothingResult& smoothed,
  double distance, Index& near, Index& far, const ParallelFor& parallel)
{
  near = far = 0;
  if (points.empty())
  {
    return;
  }
  // What OneCellSamples::Nearest would find within `distance` for each point, turned around:
  // each curve sample marks the points that see its bucket (those would look into it) and lie
  // within reach. Nothing is kept but a flag per point, and the pieces go in parallel (the
  // samples of 1000 x 1000 noise kept in buckets were several hundred MB).
  // (Nearest's reach, min(distance, side), is `distance` itself.)
  const double side = distance > 0 ? distance : 1.0;
  std::vector<double> around;
  around.reserve(2 * points.size());
  for (const CriticalPointLocation& point : points)
  {
    around.insert(around.end(), point.Position, point.Position + 2);
  }
  const BucketIndex index(side, around);
  std::vector<std::atomic<unsigned char>> isNear(points.size());
  for (auto& flag : isNear)
  {
    flag.store(0, std::memory_order_relaxed);
  }
  parallel(0, static_cast<Index>(smoothed.Pieces.size()), [&](Index begin, Index end) {
    index.ForEachSampleInBuckets(smoothed, begin, end, [&](const double* xy, long long bi, long long bj, Index, int, double) {
      const auto [first, last] = index.ItemsIn(bi, bj);
      for (const Index* item = first; item != last; ++item)
      {
        const double* at = points[*item].Position;
        if (isNear[*item].load(std::memory_order_relaxed) == 0 && std::hypot(xy[0] - at[0], xy[1] - at[1]) <= distance)
        {
          isNear[*item].store(1, std::memory_order_relaxed);
        }
      }
    });
  });
  for (const auto& flag : isNear)
  {
    ++(flag.load(std::memory_order_relaxed) != 0 ? near : far);
  }
}

// The verdict covers the whole reconstruction: a failed 2-cell or a vertex outside every
// reconstructed cell keeps input values, which no critical-point count can vouch for. The raw
// F o Phi before topological sampling is only reported.
void FieldReconstruction::Verify(const PlanarScalarField& field, const TriangleMeshTopology& mesh,
  const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report) const
{
  const auto start = std::chrono::steady_clock::now();
  report.VerificationRan = true;
  report.Expected = CriticalPointLocations(complex, field.Points);
  const double tolerance = this->Spacing * (1 + 1e-9);
  report.Verified = report.Cells.FailedCells == 0 && report.UnreconstructedPoints == 0;
  const auto judge = [&](const SamplingTopologyCheck& check) {
    if (!check.Ran)
    {
      report.Verified = false;
      return;
    }
    const auto& c = check.Comparison;
    report.Verified = report.Verified && c.Identical();
    report.Spurious.insert(report.Spurious.end(), c.Spurious.begin(), c.Spurious.end());
    report.Missing.insert(report.Missing.end(), c.Missing.begin(), c.Missing.end());
  };
  if (report.Sampled)
  {
    report.RawInput =
      CheckSampling(WithValues(field, report.Exact), report.Expected, tolerance, this->Parallel, &mesh);
    if (report.RawInput.Ran)
    {
      CountByDistanceToOneCells(report.RawInput.Comparison.Spurious, smoothed, 2 * GridSpacing(field),
        report.RawSpuriousNearOneCells, report.RawSpuriousFarFromOneCells, this->Parallel);
    }
  }
  report.Input = CheckSampling(WithValues(field, report.Values), report.Expected, tolerance, this->Parallel, &mesh);
  judge(report.Input);
  const auto& blocked = report.Sampling.BlockedWaysUp;
  const auto& c = report.Input.Comparison;
  for (std::size_t b = 0; b + 1 < blocked.size(); b += 2)
  {
    const auto near = [&](const CriticalPointLocation& p) {
      return std::hypot(p.Position[0] - blocked[b], p.Position[1] - blocked[b + 1]) <= 3 * tolerance;
    };
    if (std::any_of(c.Missing.begin(), c.Missing.end(), near) || std::any_of(c.Spurious.begin(), c.Spurious.end(), near))
    {
      report.BlockedWaysUpNearMisses.insert(report.BlockedWaysUpNearMisses.end(), { blocked[b], blocked[b + 1] });
    }
  }
  if (this->OutputResolution > 1)
  {
    report.Resampled = CheckSampling(FieldOnGrid(report.Finer), report.Expected, tolerance, this->Parallel);
    judge(report.Resampled);
  }
  report.VerificationSeconds = SecondsSince(start);
}
} // namespace topospline
