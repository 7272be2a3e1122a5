// Stage 4 of the paper (section 5) from end to end, as the "Reconstruct 2-Cells" filter runs
// it: every 2-cell reconstructed (TwoCellReconstruction), the result F o Phi evaluated at the
// input vertices and on a finer grid, both samplings given exactly the complex's critical points
// (TopologicalSampling), their topology verified against the complex (TopologyVerification),
// and the errors against the input measured. One call, one report; the VTK filter only converts
// the input and writes the report out.
#pragma once

#include "CoreTypes.h"
#include "MorseSmaleComplex.h"
#include "OneCellSmoothing.h"
#include "SyntheticFields.h" // GridField, FieldOnGrid
#include "TopologicalSampling.h"
#include "TopologyVerification.h"
#include "TwoCellReconstruction.h"

#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace topospline
{
// Stage 1 run again on one sampling of the reconstruction, compared with the complex.
struct SamplingTopologyCheck
{
  bool Ran = false;  // false: the sampling could not be extracted (Error says why)
  std::string Error;
  TopologyComparison Comparison;
};

struct FieldReconstructionReport
{
  TwoCellReconstructionReport Cells;
  std::vector<std::pair<Index, std::string>> FailedCells; // cell, why (negligible cells excluded)

  // At the input vertices.
  std::vector<double> Values;     // Reconstructed: after topological sampling when it ran
  std::vector<double> Exact;      // ReconstructedExact: F o Phi (empty without topological sampling)
  std::vector<double> Difference; // Values - input
  std::vector<Index> CellOfVertex; // the 2-cell whose surface gave the value, or InvalidIndex
  Index SnappedPoints = 0;         // outside every cell by at most a grid spacing
  Index PointsOnOneCells = 0;      // in no reconstructed cell (a negligible one), within a spacing
                                   // of a smoothed 1-cell: the 1-cell's height there
  Index UnreconstructedPoints = 0; // in no reconstructed cell, far from the 1-cells: they keep the
                                   // input value
  double MaximumError = 0;
  double RMSError = 0;
  double ValueRange[2] = { 0, 0 };
  double EvaluationSeconds = 0;

  // The finer grid (OutputResolution > 1) with its values, and whether a cell covers each point.
  GridField Finer;
  std::vector<char> FinerValid;

  // The Bezier triangles of every cell, in the plane; none when there are more than
  // FieldReconstruction::MaximumPatchTriangles (PatchesOmitted).
  std::vector<std::vector<PlanarBezierTriangle>> Patches;
  bool PatchesOmitted = false;

  // Topological sampling (both samplings summed).
  bool Sampled = false;
  TopologicalSamplingReport Sampling;

  // Verification.
  bool Verified = false;
  bool VerificationRan = false;
  SamplingTopologyCheck RawInput;  // F o Phi at the input vertices: reported, not judged
  // Its spurious critical points within two grid spacings of a smoothed 1-cell (creases and
  // curves crossing the grid) and farther (a surface that is not monotone enough inside).
  Index RawSpuriousNearOneCells = 0;
  Index RawSpuriousFarFromOneCells = 0;
  SamplingTopologyCheck Input;     // Values
  // x, y: of Sampling.BlockedWaysUp, those within 3 spacings of a spurious or missing critical
  // point of Input (a likely cause of it, which a warning names).
  std::vector<double> BlockedWaysUpNearMisses;
  SamplingTopologyCheck Resampled; // Finer.Values
  std::vector<CriticalPointLocation> Expected;
  std::vector<CriticalPointLocation> Spurious, Missing; // of the judged samplings
  double VerificationSeconds = 0;
};

class FieldReconstruction
{
public:
  int BoundarySamples = 5;     // c in the paper: samples per boundary Bezier segment
  // Fitted interiors: no more boundary samples than one per this fraction of the input's mean
  // edge length (divided by OutputResolution) where c per segment would put them closer
  // (TwoCellReconstruction::BoundarySampleSpacing); the paper's interior, or <= 0: c everywhere.
  double BoundarySampleEdges = 0.5;
  int OutputResolution = 1;    // finer grid: input spacing / OutputResolution; 1: none
  // The 2-cell interiors (TwoCellReconstruction::Interior): fitted to the input by default, the
  // paper's boundary-only construction on request (Table 1 as the paper defines it).
  TwoCellInterior Interior = TwoCellInterior::Fitted;
  // Fitted interiors: the cells that miss the data most are fitted again on alternative maps
  // onto the square (TwoCellReconstruction::AlternativeMapStrength); 0: the mean value map.
  double AlternativeMapStrength = 30;
  // Fitted interiors: a cell's grid is refined while its largest residual exceeds this fraction
  // of the input's value range (<= 0: no refinement).
  double SurfaceTolerance = 0.01;
  // Fitted interiors: rounds of stiffening where a fit, sampled at the input's vertices, has
  // critical points deep inside its cell (TwoCellReconstruction::StiffeningRounds; 0: none).
  int StiffeningRounds = 5;
  // Then the ordering rounds of the points left (TwoCellReconstruction::OrderingRounds; 0: none).
  int OrderingRounds = 8;
  // Both also treat critical points farther than this many grid spacings from the smoothed
  // 1-cells where two rings of neighbours reach past a 1-cell (TwoCellReconstruction::
  // FarFromOneCells; 2: where Verify's count calls them far; 0: the two rings only).
  double FarFromOneCellsSpacings = 2;
  // Fitted interiors: cells whose fit misses by more than this times SurfaceTolerance are fitted
  // again without the aim at F rising along u and v (TwoCellReconstruction::AxisAimTrigger; <= 0:
  // never).
  double AxisAimTrigger = 5;
  // Fitted interiors: small cells (few samples for their grid) are fitted where the paper's
  // interior misses their samples by more than this times SurfaceTolerance, within a budget
  // (TwoCellReconstruction::SmallCellFitTrigger; <= 0: never). Off by default: at 2 it took
  // ttk_happi at 2 % from 7.14 to 3.16 eps with stage 3's rise knots, but on a scattered-point
  // mesh (SaddlesStayWithinTwoEdgesOnScatteredPointMeshes, seed 2 at 5 %) a small cell's fit
  // left an interior saddle more than two edges from its node, verdict still 1.
  double SmallCellFitTrigger = 0;
  bool TopologicalSampling = true;
  bool VerifyTopology = true;
  double MemoryBudget = 0; // bytes for the 2-cells' surfaces (TwoCellReconstruction::MemoryBudget)
  // The planar Bezier triangles (the filter's "Bezier Patches") are collected up to this many:
  // each costs about 600 bytes more with its VTK output, three times its surface's share, and
  // millions of them are more than anyone inspects. Beyond it the patches are left out.
  static constexpr double MaximumPatchTriangles = 4e6;
  ParallelFor Parallel = SequentialFor;
  ProgressHooks Hooks;
  // Called once the 2-cells are evaluated and released, before the topological sampling (the
  // filter hands the freed heap back to the system there: on 1000 x 1000 noise the cells hold
  // gigabytes in small blocks of two threads' arenas, which the sampling's large arrays would
  // not reuse). Optional.
  std::function<void()> ReleaseFreedMemory;

  // About how many bytes the reconstruction of `cells` 2-cells over an input of `vertices`
  // vertices and a finer grid of `finerPoints` points take, on top of what is resident before
  // it: 800 bytes per input vertex (its evaluation and sampling arrays, the mesh, and the
  // cells' meshes and fits, whose size follows the input where cells are large), 6.5 kB per
  // cell (a cell's sides, walk, mesh, map and Sibson node data, since the Bezier elements are
  // made when evaluated) and 260 bytes per finer point (its values, mask and critical point
  // check). Measured as the peak resident memory of stage 4 above the memory before it
  // (2026-12-06): uniform noise at 5 %, k = 4 (two vertices per cell), 7.1-7.2 kB per cell at
  // 300², 500² and 1000² (1000²: 3.63 GB; this estimate 4.09), 5.8 kB at 1000² since stage 4
  // holds less (2.94 GB; docs/Reconstruction.md, "Where the rest of stage 4 goes"); a jittered-grid mesh of noise
  // 8.0 kB per cell; smooth inputs 380-960 bytes per vertex (the 2000² terrain at 2 %: 1.53 GB,
  // estimate 3.2; the Rainier crop at 2 %, k = 7; a Shepard field at 25 %; a 500² jittered-grid
  // mesh at 2 %: 0.24 GB, estimate 0.21). The filter refuses above 80 % of the available
  // memory. The Bezier Patches output comes on top, at most MaximumPatchTriangles of about 600
  // bytes.
  static double MemoryEstimate(double vertices, double cells, double finerPoints);

  // Reconstructs `complex` (smoothed into `smoothed`) over `field` (the input). Works in
  // complex.Frame; the report's positions are in the field's coordinates. Fails only on
  // malformed input or abort ("aborted"); failed cells are reported.
  bool Run(const PlanarScalarField& field, const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed,
    FieldReconstructionReport& report, std::string& error);

  // The finer grid of OutputResolution over `field` (no values yet): a grid's own points
  // refined, or for a triangle mesh a grid over its bounding box at the mean edge length /
  // OutputResolution.
  GridField FinerGrid(const PlanarScalarField& field) const;

private:
  // Run in the coordinates given (Run maps everything into complex.Frame and back).
  bool RunInFrame(const PlanarScalarField& field, const MorseSmaleComplex& complex,
    const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report, std::string& error);
  void ReconstructConstant(const PlanarScalarField& field, const TriangleMeshTopology& mesh,
    const MorseSmaleComplex& complex, FieldReconstructionReport& report) const;
  void EvaluateAtVertices(const PlanarScalarField& field, const MorseSmaleComplex& complex,
    const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report) const;
  void SampleTopologicallyAtVertices(const PlanarScalarField& field, const TriangleMeshTopology& mesh,
    const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report) const;
  void MeasureErrors(const PlanarScalarField& field, FieldReconstructionReport& report) const;
  void CollectPatches(FieldReconstructionReport& report) const;
  void EvaluateOnFinerGrid(const PlanarScalarField& field, FieldReconstructionReport& report) const;
  void SampleFinerGrid(const PlanarScalarField& field, const TriangleMeshTopology& mesh,
    const MorseSmaleComplex& complex, const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report) const;
  void Verify(const PlanarScalarField& field, const TriangleMeshTopology& mesh, const MorseSmaleComplex& complex,
    const OneCellSmoothingResult& smoothed, FieldReconstructionReport& report) const;

  // The topological sampling of `complex`, its progress reported as [progressFrom, progressTo]
  // of the reconstruction's.
  topospline::TopologicalSampling SamplingOf(const MorseSmaleComplex& complex, const TriangleMeshTopology& mesh,
    const PlanarScalarField& field, const OneCellSmoothingResult& smoothed, double progressFrom,
    double progressTo) const;

  TwoCellReconstruction Cells; // during Run, until every evaluation is done
  double Spacing = 0; // the tolerance of every "near its node": one grid spacing
};

// Largest edge of the triangulation (grids: the cell diagonal).
double LargestEdgeLength(const PlanarScalarField& field);
// Mean edge length of the triangulation (grids: of the two axes and the diagonal).
double MeanEdgeLength(const PlanarScalarField& field);
// The grid spacing (the larger axis), or the mean edge length of a triangle mesh.
double GridSpacing(const PlanarScalarField& field);
// The smoothed 1-cell curves sampled with their heights, bucketed for nearest-sample queries
// within `side`.
class OneCellSamples
{
public:
  // Only the samples that Nearest can return for the points `around` (x, y pairs) are kept,
  // and only the Bezier segments that can hold one are sampled: every curve of 1000 x 1000
  // noise at 16 samples per segment is 76 million samples (9 s), for the few vertices of
  // negligible 2-cells.
  OneCellSamples(const OneCellSmoothingResult& smoothed, double side, const std::vector<double>& around);
  // The height of the sample nearest to (x, y) within `distance` (at most `side`); false if none.
  bool Nearest(double x, double y, double distance, double& height) const;

private:
  struct Sample
  {
    double XY[2] = { 0, 0 };
    double Height = 0;
  };
  long long Key(double x, double y) const;
  long long KeyOf(long long i, long long j) const;
  double Side;
  std::unordered_map<long long, std::vector<Sample>> Buckets;
};

// Counts `points` within `distance` of a smoothed 1-cell curve (near) and beyond it (far).
void CountByDistanceToOneCells(const std::vector<CriticalPointLocation>& points, const OneCellSmoothingResult& smoothed,
  double distance, Index& near, Index& far, const ParallelFor& parallel = SequentialFor);
// The mesh of a field (closed form for grids).
bool BuildMesh(const PlanarScalarField& field, TriangleMeshTopology& mesh, const ParallelFor& parallel,
  std::string& error);
} // namespace topospline
