#include "vtkTopoSplineReconstructTwoCells.h"

#include "vtkTopoSplineArrayNames.h"
#include "vtkTopoSplineDomainConversion.h"

#include "vtkTopoSplineWireFormat.h"

#include "FieldReconstruction.h" // core

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkCharArray.h>
#include <vtkDataSet.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkIntArray.h>
#include <vtkLogger.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSMPTools.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>
#include <vtksys/SystemInformation.hxx>
#include <vtkUnstructuredGrid.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <sstream>

namespace names = vtkTopoSplineArrayNames;
namespace conversion = vtkTopoSplineDomainConversion;
namespace wire = vtkTopoSplineWireFormat;
using topospline::Index;

vtkStandardNewMacro(vtkTopoSplineReconstructTwoCells);

vtkTopoSplineReconstructTwoCells::vtkTopoSplineReconstructTwoCells()
{
  this->SetNumberOfOutputPorts(3);
}

int vtkTopoSplineReconstructTwoCells::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkMultiBlockDataSet");
  return 1;
}

int vtkTopoSplineReconstructTwoCells::FillOutputPortInformation(int port, vtkInformation* info)
{
  const char* types[3] = { "vtkDataSet", "vtkUnstructuredGrid", "vtkImageData" };
  info->Set(vtkDataObject::DATA_TYPE_NAME(), types[port]);
  return 1;
}

namespace
{
// Port 0 has the type of the input geometry (the complex's "Segmentation" block). Before the
// first update of the upstream filters the block is not there yet: an image is assumed, and
// RequestData replaces the output if the geometry turns out to be another type.
vtkDataSet* EnsureGeometryOutput(vtkInformation* info, vtkDataSet* domain)
{
  vtkDataObject* current = info->Get(vtkDataObject::DATA_OBJECT());
  const char* wanted = domain ? domain->GetClassName() : "vtkImageData";
  if (!current || std::string(current->GetClassName()) != wanted)
  {
    vtkSmartPointer<vtkDataSet> created;
    if (domain)
    {
      created.TakeReference(domain->NewInstance());
    }
    else
    {
      created = vtkSmartPointer<vtkImageData>::New();
    }
    info->Set(vtkDataObject::DATA_OBJECT(), created);
    current = created;
  }
  return vtkDataSet::SafeDownCast(current);
}

// VTK_BEZIER_TRIANGLE point order for degree 3 (corners, edge points from each edge's first
// corner, centre) as ordinate indices b_ijk, with A, B, C the VTK corners 0, 1, 2.
constexpr int VtkBezierTriangleOrder[10] = { topospline::BezierOrdinateIndex(3, 0),
  topospline::BezierOrdinateIndex(0, 3), topospline::BezierOrdinateIndex(0, 0),
  topospline::BezierOrdinateIndex(2, 1), topospline::BezierOrdinateIndex(1, 2),
  topospline::BezierOrdinateIndex(0, 2), topospline::BezierOrdinateIndex(0, 1),
  topospline::BezierOrdinateIndex(1, 0), topospline::BezierOrdinateIndex(2, 0),
  topospline::BezierOrdinateIndex(1, 1) };
} // namespace

int vtkTopoSplineReconstructTwoCells::RequestDataObject(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkMultiBlockDataSet* input = vtkMultiBlockDataSet::GetData(inputVector[0], 0);
  EnsureGeometryOutput(outputVector->GetInformationObject(0), input ? wire::SegmentationOf(input) : nullptr);
  for (int port = 1; port < 3; ++port)
  {
    vtkInformation* info = outputVector->GetInformationObject(port);
    if (!info->Get(vtkDataObject::DATA_OBJECT()))
    {
      vtkSmartPointer<vtkDataObject> created;
      if (port == 1)
      {
        created = vtkSmartPointer<vtkUnstructuredGrid>::New();
      }
      else
      {
        created = vtkSmartPointer<vtkImageData>::New();
      }
      info->Set(vtkDataObject::DATA_OBJECT(), created);
    }
  }
  return 1;
}

int vtkTopoSplineReconstructTwoCells::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The resampled image's extent: the input grid's refined by Output Resolution, from 0 (see
  // RequestData), or empty. Left as copied from the input, the port would ask for an extent
  // its data never covers and the whole filter would run again at every update of it.
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  vtkInformation* resampledInfo = outputVector->GetInformationObject(2);
  const int f = this->OutputResolution;
  const bool image = inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()) != 0;
  if (f > 1 && !image)
  {
    // Not an image: the extent is known only once the domain's bounds are.
    resampledInfo->Remove(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT());
    return 1;
  }
  int extent[6] = { 0, -1, 0, -1, 0, -1 };
  if (f > 1)
  {
    int input[6];
    inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), input);
    for (int axis = 0; axis < 3; ++axis)
    {
      extent[2 * axis] = 0;
      extent[2 * axis + 1] = std::max(0, input[2 * axis + 1] - input[2 * axis]) * f;
    }
  }
  resampledInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  return 1;
}

namespace
{
// Point data of the input geometry: the reconstruction, its difference to the input and the
// 2-cell of each vertex (and F o Phi before topological sampling, when that ran).
void WriteVertexValues(const topospline::FieldReconstructionReport& report, vtkDataSet* output)
{
  const auto n = static_cast<vtkIdType>(report.Values.size());
  auto values = conversion::NewArray<vtkDoubleArray>(names::ReconstructedField, 1, n);
  auto difference = conversion::NewArray<vtkDoubleArray>(names::ReconstructionDifference, 1, n);
  auto cellIds = conversion::NewArray<vtkIntArray>(names::ReconstructionCellId, 1, n);
  std::copy(report.Values.begin(), report.Values.end(), values->GetPointer(0));
  std::copy(report.Difference.begin(), report.Difference.end(), difference->GetPointer(0));
  std::copy(report.CellOfVertex.begin(), report.CellOfVertex.end(), cellIds->GetPointer(0));
  if (report.Sampled)
  {
    auto exact = conversion::NewArray<vtkDoubleArray>(names::ExactReconstruction, 1, n);
    std::copy(report.Exact.begin(), report.Exact.end(), exact->GetPointer(0));
    output->GetPointData()->AddArray(exact);
  }
  conversion::AddArrays(output->GetPointData(), { values, difference, cellIds });
  output->GetPointData()->SetActiveScalars(names::ReconstructedField);
}

// The Bezier triangles of every cell, in the plane of the input.
void WritePatches(const topospline::FieldReconstructionReport& report, const conversion::DomainPlane& plane,
  vtkUnstructuredGrid* patches)
{
  vtkIdType total = 0;
  for (const auto& list : report.Patches)
  {
    total += static_cast<vtkIdType>(list.size());
  }
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(10 * total);
  auto height = conversion::NewArray<vtkDoubleArray>(names::Height, 1, 10 * total);
  auto cellOf = conversion::NewArray<vtkIntArray>(names::TwoCellId, 1, total);
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(total, 10 * total);
  vtkIdType next = 0, t = 0;
  for (Index c = 0; c < static_cast<Index>(report.Patches.size()); ++c)
  {
    for (const auto& triangle : report.Patches[c])
    {
      vtkIdType ids[10];
      for (int m = 0; m < 10; ++m)
      {
        const auto& control = triangle.Points[VtkBezierTriangleOrder[m]];
        double xyz[3];
        plane.To3D(control.data(), xyz);
        points->SetPoint(next, xyz);
        height->SetValue(next, control[2]);
        ids[m] = next++;
      }
      cells->InsertNextCell(10, ids);
      cellOf->SetValue(t++, c);
    }
  }
  patches->Initialize();
  patches->SetPoints(points);
  patches->SetCells(VTK_BEZIER_TRIANGLE, cells);
  patches->GetPointData()->AddArray(height);
  patches->GetPointData()->SetActiveScalars(names::Height);
  patches->GetCellData()->AddArray(cellOf);
}

// The finer grid as an image in the plane of the input (an image input keeps its third axis).
void WriteResampled(const topospline::FieldReconstructionReport& report, vtkDataSet* domain,
  const conversion::DomainPlane& plane, vtkImageData* resampled)
{
  int dims[3] = { 1, 1, 1 };
  double origin[3], spacing[3] = { 1, 1, 1 };
  if (auto* image = vtkImageData::SafeDownCast(domain))
  {
    image->GetSpacing(spacing);
  }
  plane.To3D(report.Finer.Origin, origin);
  dims[plane.U] = report.Finer.Dimensions[0];
  dims[plane.V] = report.Finer.Dimensions[1];
  spacing[plane.U] = report.Finer.Spacing[0];
  spacing[plane.V] = report.Finer.Spacing[1];
  resampled->SetDimensions(dims);
  resampled->SetOrigin(origin);
  resampled->SetSpacing(spacing);
  const auto m = static_cast<vtkIdType>(report.Finer.Values.size());
  auto values = conversion::NewArray<vtkDoubleArray>(names::ReconstructedField, 1, m);
  auto valid = conversion::NewArray<vtkCharArray>(names::ValidPointMask, 1, m);
  std::copy(report.Finer.Values.begin(), report.Finer.Values.end(), values->GetPointer(0));
  std::copy(report.FinerValid.begin(), report.FinerValid.end(), valid->GetPointer(0));
  conversion::AddArrays(resampled->GetPointData(), { values, valid });
  resampled->GetPointData()->SetActiveScalars(names::ReconstructedField);
}

void AddPoints(vtkFieldData* fd, const char* name, const std::vector<topospline::CriticalPointLocation>& points)
{
  // x, y, Morse index, value per point.
  auto array = conversion::NewArray<vtkDoubleArray>(name, 4);
  for (const auto& p : points)
  {
    const double tuple[4] = { p.Position[0], p.Position[1], static_cast<double>(p.MorseIndex), p.Value };
    array->InsertNextTuple(tuple);
  }
  fd->AddArray(array);
}

// Field data: what was done and how well.
void WriteReport(const topospline::FieldReconstructionReport& report, vtkFieldData* fd)
{
  using conversion::AddFieldNumbers;
  const auto& cells = report.Cells;
  AddFieldNumbers(fd, names::TwoCells, { static_cast<double>(cells.Cells) });
  AddFieldNumbers(fd, names::FailedTwoCells, { static_cast<double>(cells.FailedCells) });
  AddFieldNumbers(fd, names::NegligibleTwoCells, { static_cast<double>(cells.NegligibleCells) });
  AddFieldNumbers(fd, names::SlitTwoCells, { static_cast<double>(cells.SlitCells) });
  AddFieldNumbers(fd, names::ShiftedCorners, { static_cast<double>(cells.ShiftedCorners) });
  AddFieldNumbers(fd, names::ViolatingPatches, { static_cast<double>(cells.ViolatingPatches) });
  AddFieldNumbers(fd, names::LinearizedDiagonals, { static_cast<double>(cells.LinearizedDiagonals) });
  AddFieldNumbers(fd, names::BezierTriangles, { static_cast<double>(cells.BezierTriangles) });
  AddFieldNumbers(fd, names::MeshTriangles, { static_cast<double>(cells.MeshTriangles) });
  AddFieldNumbers(fd, names::CrowdedTriangles, { static_cast<double>(cells.CrowdedTriangles) });
  AddFieldNumbers(fd, names::PinchedTwoCells, { static_cast<double>(cells.PinchedCells) });
  AddFieldNumbers(fd, names::ResampledTwoCells, { static_cast<double>(cells.ResampledCells) });
  AddFieldNumbers(fd, names::OutsideSlitTwoCells, { static_cast<double>(cells.OutsideSlitCells) });
  AddFieldNumbers(fd, names::MaximumGridSize, { static_cast<double>(cells.MaximumGridSize) });
  AddFieldNumbers(fd, names::FittedCells, { static_cast<double>(cells.FittedCells) });
  AddFieldNumbers(fd, names::RefinedCells, { static_cast<double>(cells.RefinedCells) });
  AddFieldNumbers(fd, names::StiffenedCells, { static_cast<double>(cells.StiffenedCells) });
  AddFieldNumbers(fd, names::OrderedCells, { static_cast<double>(cells.OrderedCells) });
  AddFieldNumbers(fd, names::RemappedCells, { static_cast<double>(cells.RemappedCells) });
  AddFieldNumbers(fd, names::AxisFreeCells, { static_cast<double>(cells.AxisFreeCells) });
  AddFieldNumbers(fd, names::SmallFittedCells, { static_cast<double>(cells.SmallFittedCells) });
  AddFieldNumbers(fd, names::SnappedPoints, { static_cast<double>(report.SnappedPoints) });
  AddFieldNumbers(fd, names::PointsOnOneCells, { static_cast<double>(report.PointsOnOneCells) });
  AddFieldNumbers(fd, names::UnreconstructedPoints, { static_cast<double>(report.UnreconstructedPoints) });
  AddFieldNumbers(fd, names::MaximumError, { report.MaximumError });
  AddFieldNumbers(fd, names::RMSError, { report.RMSError });
  AddFieldNumbers(fd, names::ValueRange, { report.ValueRange[0], report.ValueRange[1] });
  AddFieldNumbers(fd, names::ParameterizationSeconds, { cells.ParameterizationSeconds });
  AddFieldNumbers(fd, names::SurfaceSeconds, { cells.SurfaceSeconds });
  AddFieldNumbers(fd, names::EvaluationSeconds, { report.EvaluationSeconds });
  if (report.Sampled)
  {
    AddFieldNumbers(fd, names::SamplingChangedVertices, { static_cast<double>(report.Sampling.ChangedVertices) });
    AddFieldNumbers(fd, names::SamplingMaximumChange, { report.Sampling.MaximumChange });
    AddFieldNumbers(fd, names::SamplingChangedFraction,
      { report.Values.empty() ? 0.0 : static_cast<double>(report.Sampling.ChangedVertices) / report.Values.size() });
    AddFieldNumbers(fd, names::SamplingConverged, { report.Sampling.Converged ? 1.0 : 0.0 });
    AddFieldNumbers(fd, names::SamplingDisplacedSaddles, { static_cast<double>(report.Sampling.DisplacedSaddles) });
    AddFieldNumbers(fd, names::SamplingBlockedWaysUp, { static_cast<double>(report.Sampling.BlockedWaysUp.size() / 2) });
    AddFieldNumbers(fd, names::SamplingMovedBoundarySaddles, { static_cast<double>(report.Sampling.MovedBoundarySaddles) });
    AddFieldNumbers(fd, names::SamplingMovedInteriorSaddles, { static_cast<double>(report.Sampling.MovedInteriorSaddles) });
    AddFieldNumbers(fd, names::SamplingWalkedSaddles, { static_cast<double>(report.Sampling.WalkedSaddles) });
    AddFieldNumbers(fd, names::SamplingKeptExact, { report.Sampling.KeptExact ? 1.0 : 0.0 });
  }
  if (!report.VerificationRan)
  {
    return;
  }
  if (report.RawInput.Ran)
  {
    AddFieldNumbers(fd, names::RawSpuriousNearOneCells, { static_cast<double>(report.RawSpuriousNearOneCells) });
    AddFieldNumbers(fd, names::RawSpuriousFarFromOneCells, { static_cast<double>(report.RawSpuriousFarFromOneCells) });
  }
  for (const auto& [prefix, check] : { std::make_pair(names::RawInputSampling, &report.RawInput),
         std::make_pair(names::InputSampling, &report.Input),
         std::make_pair(names::ResampledSampling, &report.Resampled) })
  {
    if (check->Ran)
    {
      const auto& found = check->Comparison.Found;
      const std::string p(prefix);
      AddFieldNumbers(fd, (p + names::CriticalPointsSuffix).c_str(),
        { static_cast<double>(found[0]), static_cast<double>(found[1]), static_cast<double>(found[2]) });
      AddFieldNumbers(fd, (p + names::CriticalPointDistanceSuffix).c_str(), { check->Comparison.MaximumDistance });
    }
  }
  double expected[3] = { 0, 0, 0 };
  for (const auto& cp : report.Expected)
  {
    expected[cp.MorseIndex] += 1;
  }
  AddFieldNumbers(fd, names::ExpectedCriticalPoints, { expected[0], expected[1], expected[2] });
  AddFieldNumbers(fd, names::TopologyVerified, { report.Verified ? 1.0 : 0.0 });
  AddPoints(fd, names::SpuriousCriticalPoints, report.Spurious);
  AddPoints(fd, names::MissingCriticalPoints, report.Missing);
  AddFieldNumbers(fd, names::VerificationSeconds, { report.VerificationSeconds });
}

// Physical memory available now (0 if unknown), or less if the environment variable
// TOPOSPLINE_MEMORY_LIMIT (bytes) says so: a share of a machine that others use too.
// SystemInformation reports 0 until its memory check has run: without it every memory check
// here passed.
double AvailableBytes()
{
  vtksys::SystemInformation system;
  system.RunMemoryCheck();
  double available = 1024.0 * static_cast<double>(system.GetAvailablePhysicalMemory()) * 1024.0;
  if (const char* limit = std::getenv("TOPOSPLINE_MEMORY_LIMIT"))
  {
    const double bytes = std::atof(limit);
    available = bytes > 0 && (available <= 0 || bytes < available) ? bytes : available;
  }
  return available;
}
} // namespace

int vtkTopoSplineReconstructTwoCells::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkLogScopeFunction(TRACE);
  // Declared first, so that it runs last: after every core object of the run is gone.
  const vtkTopoSplineDomainConversion::ReleaseFreedMemoryOnReturn releaseFreedMemory;
  vtkMultiBlockDataSet* input = vtkMultiBlockDataSet::GetData(inputVector[0], 0);
  auto* patchesOutput = vtkUnstructuredGrid::GetData(outputVector, 1);
  auto* resampledOutput = vtkImageData::GetData(outputVector, 2);
  if (!input || !patchesOutput || !resampledOutput)
  {
    vtkErrorMacro("Missing input or output.");
    return 0;
  }
  if (input->GetNumberOfBlocks() == 0)
  {
    // An empty complex: another process's share in a distributed run, or an upstream failure
    // that was already reported. Nothing to do.
    return 1;
  }
  if (this->BoundarySamples < 1 || this->BoundarySamples > 1000)
  {
    vtkErrorMacro("Reconstruct 2-Cells: Boundary Samples must be in [1, 1000], not " << this->BoundarySamples << ".");
    return 1;
  }
  if (this->OutputResolution < 1 || this->OutputResolution > 16)
  {
    vtkErrorMacro("Reconstruct 2-Cells: Output Resolution must be in [1, 16], not " << this->OutputResolution << ".");
    return 1;
  }
  std::string error;
  topospline::MorseSmaleComplex complex;
  topospline::OneCellSmoothingResult smoothed;
  if (!wire::ReadComplex(input, complex, error) || !wire::ReadSmoothedOneCells(input, complex, smoothed, error))
  {
    vtkErrorMacro("Reconstruct 2-Cells: " << error << ".");
    return 1;
  }
  vtkDataSet* domain = wire::SegmentationOf(input);
  const std::string scalarName = wire::ScalarFieldNameOf(input);
  vtkDataArray* original = domain->GetPointData()->GetArray(scalarName.c_str());
  if (!original || original->GetNumberOfComponents() != 1)
  {
    vtkErrorMacro("Reconstruct 2-Cells: the input field \"" << scalarName << "\" is missing from the complex.");
    return 1;
  }
  topospline::PlanarScalarField field;
  if (!conversion::ToPlanarScalarField(domain, original, field, error))
  {
    vtkErrorMacro("Reconstruct 2-Cells: " << error << ".");
    return 1;
  }
  const double available = AvailableBytes();
  if (!this->FitsInMemory(domain->GetNumberOfPoints(), complex.TwoCells.size(), available))
  {
    return 1;
  }

  topospline::FieldReconstruction reconstruction;
  reconstruction.BoundarySamples = this->BoundarySamples;
  reconstruction.Interior = this->Interior == INTERIOR_PAPER ? topospline::TwoCellInterior::Paper
                                                              : topospline::TwoCellInterior::Fitted;
  reconstruction.AlternativeMapStrength = this->AlternativeMapStrength;
  reconstruction.SurfaceTolerance = this->SurfaceTolerance / 100.0;
  reconstruction.OutputResolution = this->OutputResolution;
  reconstruction.TopologicalSampling = this->TopologicalSampling != 0;
  reconstruction.VerifyTopology = this->VerifyTopology != 0;
  // The surfaces' own check, once their grid sizes are known (FitsInMemory counts vertices and cells only);
  // half of what is available: the sampling, verification and outputs come on top.
  reconstruction.MemoryBudget = 0.5 * available;
  reconstruction.Parallel = conversion::SMPParallelFor();
  reconstruction.Hooks.Progress = [this](double f) { this->UpdateProgress(f); };
  reconstruction.Hooks.AbortRequested = [this]() { return this->GetAbortExecute() != 0; };
  reconstruction.ReleaseFreedMemory = conversion::ReleaseFreedMemory;
  topospline::FieldReconstructionReport report;
  {
    vtkLogScopeF(TRACE, "reconstruct %d 2-cells", static_cast<int>(complex.TwoCells.size()));
    if (!reconstruction.Run(field, complex, smoothed, report, error))
    {
      if (error != "aborted")
      {
        vtkErrorMacro("Reconstruct 2-Cells: " << error << ".");
      }
      return 1;
    }
  }
  this->WarnAbout(report);

  const auto plane = conversion::PlaneOf(domain);
  vtkDataSet* output = EnsureGeometryOutput(outputVector->GetInformationObject(0), domain);
  output->ShallowCopy(domain);
  WriteVertexValues(report, output);
  WritePatches(report, plane, patchesOutput);
  resampledOutput->Initialize();
  if (this->OutputResolution > 1)
  {
    WriteResampled(report, domain, plane, resampledOutput);
  }
  output->GetFieldData()->PassData(input->GetFieldData());
  WriteReport(report, output->GetFieldData());
  return 1;
}

// Refused before anything is allocated, with the estimate.
bool vtkTopoSplineReconstructTwoCells::FitsInMemory(vtkIdType points, std::size_t twoCells, double available)
{
  const double f = this->OutputResolution;
  const double finer = f > 1 ? static_cast<double>(points) * f * f : 0.0;
  const double cells = static_cast<double>(twoCells);
  const double needed = topospline::FieldReconstruction::MemoryEstimate(static_cast<double>(points), cells, finer);
  if (available > 0 && needed > 0.8 * available)
  {
    vtkErrorMacro("Reconstruct 2-Cells: " << cells << " 2-cells" << (f > 1 ? " and the finer sampling" : "")
                  << " need about " << needed / 1e9 << " GB; this machine has " << available / 1e9
                  << " GB available. Simplify further (a higher Persistence Threshold)"
                  << (f > 1 ? " or choose a lower Output Resolution" : "") << ".");
    return false;
  }
  return true;
}

// What did not go as it should, as warnings: failed cells, patches that break the
// monotonicity conditions, vertices left with their input value, samplings whose critical
// points differ from the complex's.
void vtkTopoSplineReconstructTwoCells::WarnAbout(const topospline::FieldReconstructionReport& report)
{
  for (const auto& [cell, why] : report.FailedCells)
  {
    vtkWarningMacro("Reconstruct 2-Cells: 2-cell " << cell << " was not reconstructed: " << why << ".");
  }
  if (report.PatchesOmitted)
  {
    vtkWarningMacro("Reconstruct 2-Cells: the Bezier Patches output is left empty: "
      << report.Cells.BezierTriangles << " Bezier triangles are more than "
      << static_cast<long long>(topospline::FieldReconstruction::MaximumPatchTriangles)
      << " (fewer Curve Segments or a higher Persistence Threshold give fewer).");
  }
  if (report.Cells.ViolatingPatches > 0)
  {
    vtkWarningMacro("Reconstruct 2-Cells: " << report.Cells.ViolatingPatches
                                            << " Sibson grid cell(s) fail the monotonicity conditions.");
  }
  if (report.UnreconstructedPoints > 0)
  {
    vtkWarningMacro("Reconstruct 2-Cells: " << report.UnreconstructedPoints
                                            << " vertices lie in no reconstructed 2-cell and keep their input value.");
  }
  for (const auto& [prefix, check] : { std::make_pair(names::InputSampling, &report.Input),
         std::make_pair(names::ResampledSampling, &report.Resampled) })
  {
    const bool judged = report.VerificationRan && (check == &report.Input || this->OutputResolution > 1);
    const auto& c = check->Comparison;
    if (judged && !check->Ran)
    {
      vtkWarningMacro("Reconstruct 2-Cells: topology check on the " << prefix << " sampling failed: " << check->Error);
    }
    else if (judged && !c.Identical())
    {
      // The first few of each, with their place, so that a user can look there.
      std::ostringstream where;
      constexpr std::size_t shown = 4;
      static const char* const kinds[] = { "minimum", "saddle", "maximum" };
      for (const auto& [label, points] :
        { std::make_pair("spurious", &c.Spurious), std::make_pair("missing", &c.Missing) })
      {
        for (std::size_t i = 0; i < points->size() && i < shown; ++i)
        {
          const auto& p = (*points)[i];
          where << (where.tellp() > 0 ? "; " : "") << label << " " << kinds[std::clamp(p.MorseIndex, 0, 2)] << " at ("
                << p.Position[0] << ", " << p.Position[1] << ")";
        }
      }
      // A likely cause the sampling saw itself: a wanted boundary saddle with no way into the
      // domain but through a wanted minimum or saddle (a corner saddle whose only interior
      // neighbour is a wanted minimum): no value at these vertices holds the complex there.
      std::ostringstream why;
      const auto& blocked = report.BlockedWaysUpNearMisses;
      if (check == &report.Input && !blocked.empty())
      {
        why << " Near them, " << blocked.size() / 2 << " boundary saddle(s) of the complex stand above every neighbour with"
            << " no way into the domain but through a minimum or saddle it also wants (the first at (" << blocked[0]
            << ", " << blocked[1] << ")): the input's vertices are too few there for this complex (a finer"
            << " Output Resolution gives the resampled output room, a higher Persistence Threshold fewer"
            << " critical points).";
      }
      vtkWarningMacro("Reconstruct 2-Cells: the " << prefix << " sampling of the reconstruction has "
                      << c.Spurious.size() << " spurious and " << c.Missing.size()
                      << " missing critical point(s) (found "
                      << c.Found[0] << "/" << c.Found[1] << "/" << c.Found[2] << ", expected " << c.Expected[0] << "/"
                      << c.Expected[1] << "/" << c.Expected[2] << "): " << where.str() << "." << why.str());
    }
  }
}

void vtkTopoSplineReconstructTwoCells::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "BoundarySamples: " << this->BoundarySamples << "\n"
     << indent << "Interior: " << (this->Interior == INTERIOR_PAPER ? "Paper" : "Fitted") << "\n"
     << indent << "SurfaceTolerance: " << this->SurfaceTolerance << "\n"
     << indent << "AlternativeMapStrength: " << this->AlternativeMapStrength << "\n"
     << indent << "OutputResolution: " << this->OutputResolution << "\n"
     << indent << "TopologicalSampling: " << this->TopologicalSampling << "\n"
     << indent << "VerifyTopology: " << this->VerifyTopology << "\n";
}
