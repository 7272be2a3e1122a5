#include "vtkTopoSplineSmoothOneCells.h"

#include "vtkTopoSplineArrayNames.h"
#include "vtkTopoSplineDomainConversion.h"
#include "vtkTopoSplineWireFormat.h"

#include "JunctionPointDetection.h" // core
#include "OneCellSmoothing.h"                // core
#include "PiecewiseLinearField.h"            // core

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
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
#include <vtkPolyData.h>
#include <vtkUnstructuredGrid.h>

#include <algorithm>
#include <map>
#include <memory>
#include <string>

namespace names = vtkTopoSplineArrayNames;
using topospline::Index;

vtkStandardNewMacro(vtkTopoSplineSmoothOneCells);

int vtkTopoSplineSmoothOneCells::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkMultiBlockDataSet");
  return 1;
}

namespace
{
void WriteSmoothingReport(const topospline::OneCellSmoothingResult& result, int curveSegments, vtkFieldData* fd)
{
  double l1 = 0, free = 0;
  for (const auto& p : result.Pieces)
  {
    l1 += p.L1Error;
    free += p.UnconstrainedL1Error;
  }
  using vtkTopoSplineDomainConversion::AddFieldNumbers;
  AddFieldNumbers(fd, names::CurveSegments, { static_cast<double>(curveSegments) });
  AddFieldNumbers(fd, names::NumberOfPieces, { static_cast<double>(result.Pieces.size()) });
  AddFieldNumbers(fd, names::ShortPieces, { static_cast<double>(result.ShortPieces) });
  AddFieldNumbers(fd, names::OversegmentedPieces, { static_cast<double>(result.OversegmentedPieces) });
  AddFieldNumbers(fd, names::SuggestedCurveSegments, { static_cast<double>(result.SuggestedSegments) });
  AddFieldNumbers(fd, names::ErasedLoops, { static_cast<double>(result.ErasedLoops) });
  AddFieldNumbers(fd, names::DroppedCuts, { static_cast<double>(result.DroppedCuts) });
  AddFieldNumbers(fd, names::AdaptedPieces, { static_cast<double>(result.AdaptedPieces) });
  AddFieldNumbers(fd, names::RiseKnotPieces, { static_cast<double>(result.RiseKnotPieces) });
  AddFieldNumbers(fd, names::ContactKnotPieces, { static_cast<double>(result.ContactKnotPieces) });
  AddFieldNumbers(fd, names::CurveHeightPieces, { static_cast<double>(result.CurveHeightPieces) });
  AddFieldNumbers(fd, names::RefinedPieces, { static_cast<double>(result.RefinedPieces) });
  AddFieldNumbers(fd, names::PolylinePieces, { static_cast<double>(result.PolylinePieces) });
  AddFieldNumbers(fd, names::RemainingCrossings, { static_cast<double>(result.RemainingCrossings) });
  AddFieldNumbers(fd, names::PiecesOutsideDomain, { static_cast<double>(result.PiecesOutsideDomain) });
  AddFieldNumbers(fd, names::ClampedPieces, { static_cast<double>(result.ClampedPieces) });
  AddFieldNumbers(fd, names::L1Error, { l1 });
  AddFieldNumbers(fd, names::UnconstrainedL1Error, { free });
  AddFieldNumbers(fd, names::JunctionMargin, { result.JunctionMargin });
  AddFieldNumbers(fd, names::SpreadCriticalValues, { static_cast<double>(result.SpreadCriticalValues) });
  AddFieldNumbers(fd, names::MaximumSpread, { result.MaximumSpread });
}
} // namespace

int vtkTopoSplineSmoothOneCells::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkLogScopeFunction(TRACE);
  // Declared first, so that it runs last: after every core object of the run is gone.
  const vtkTopoSplineDomainConversion::ReleaseFreedMemoryOnReturn releaseFreedMemory;
  vtkMultiBlockDataSet* input = vtkMultiBlockDataSet::GetData(inputVector[0], 0);
  vtkMultiBlockDataSet* output = vtkMultiBlockDataSet::GetData(outputVector, 0);
  if (!input || !output)
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
  if (this->CurveSegments < 2 || this->CurveSegments > topospline::OneCellSmoothing::MaximumCurveSegments)
  {
    vtkErrorMacro("Smooth 1-Cells: Curve Segments must be in [2, " << topospline::OneCellSmoothing::MaximumCurveSegments
                                                                   << "], not " << this->CurveSegments << ".");
    return 1;
  }
  std::string error;
  topospline::MorseSmaleComplex complex;
  if (!vtkTopoSplineWireFormat::ReadComplex(input, complex, error))
  {
    vtkErrorMacro("Smooth 1-Cells: " << error << ".");
    return 1;
  }
  vtkDataSet* domain = vtkTopoSplineWireFormat::SegmentationOf(input);

  // Where 1-cells sharing an extremum split: the pieces' ends (any complex, simplified or not).
  const std::vector<topospline::JunctionPoint> junctions = topospline::DetectJunctionPoints(complex);

  double bounds[4];
  vtkTopoSplineDomainConversion::PlanarBounds(domain, bounds);
  topospline::OneCellSmoothing smoothing;
  smoothing.Segments = this->CurveSegments;
  if (vtkDataArray* threshold = input->GetFieldData()->GetArray(names::AbsolutePersistenceThreshold))
  {
    smoothing.HeightTolerance = threshold->GetNumberOfTuples() > 0 ? threshold->GetComponent(0, 0) : 0.0;
  }
  // The input field between its vertices, where the smoothed curves run (kept for as long as
  // the smoothing runs; without it the heights follow the jagged paths alone).
  topospline::PlanarScalarField field;
  std::unique_ptr<topospline::PiecewiseLinearField> between;
  vtkDataArray* original = domain->GetPointData()->GetArray(vtkTopoSplineWireFormat::ScalarFieldNameOf(input).c_str());
  std::string fieldError;
  if (original && original->GetNumberOfComponents() == 1 &&
    vtkTopoSplineDomainConversion::ToPlanarScalarField(domain, original, field, fieldError))
  {
    between = std::make_unique<topospline::PiecewiseLinearField>(field);
    smoothing.FieldAt = [at = between.get(), frame = complex.Frame](double x, double y, double& value) {
      double xy[2] = { x, y };
      frame.ToWorld(xy);
      return at->ValueAt(xy[0], xy[1], value);
    };
  }
  // A mesh's corners need not be those of its bounds (a jittered grid): the boundary vertices
  // nearest them are taken instead. An image keeps the corners of its bounds.
  if (between && !vtkImageData::SafeDownCast(domain))
  {
    smoothing.BoundaryPoints = topospline::OneCellSmoothing::BoundaryPointsOf(field);
  }
  smoothing.Parallel = vtkTopoSplineDomainConversion::SMPParallelFor();
  smoothing.Hooks.Progress = [this](double f) { this->UpdateProgress(0.9 * f); };
  smoothing.Hooks.AbortRequested = [this]() { return this->GetAbortExecute() != 0; };
  topospline::OneCellSmoothingResult result;
  {
    vtkLogScopeF(TRACE, "smooth 1-cells (k = %d)", this->CurveSegments);
    if (!smoothing.Smooth(complex, junctions, bounds, result, error))
    {
      if (error != "aborted")
      {
        vtkErrorMacro("Smooth 1-Cells: " << error << ".");
      }
      return 1;
    }
  }
  this->ReportAdjustments(complex, result);

  // The input's blocks pass through; the smoothed 1-cells are added.
  output->SetNumberOfBlocks(names::SampledOneCellsIndex + 1);
  vtkTopoSplineWireFormat::PassBlocks(input, names::SmoothedOneCellsIndex, output);
  const int samples = this->SamplesWithinBudget(complex, result);
  vtkTopoSplineWireFormat::WriteSmoothedOneCells(complex, result, samples, output);

  WriteSmoothingReport(result, this->CurveSegments, output->GetFieldData());
  vtkTopoSplineDomainConversion::AddFieldNumbers(
    output->GetFieldData(), names::SampledSamplesPerSegment, { static_cast<double>(samples) });
  this->UpdateProgress(1.0);
  return 1;
}

// SamplesPerSegment, or fewer where the display block would exceed its point budget (0: the
// block is left empty), with a warning.
int vtkTopoSplineSmoothOneCells::SamplesWithinBudget(
  const topospline::MorseSmaleComplex& complex, const topospline::OneCellSmoothingResult& result)
{
  const vtkIdType wanted = vtkTopoSplineWireFormat::SampledOneCellPoints(complex, result, this->SamplesPerSegment);
  if (wanted <= this->MaximumSampledPoints)
  {
    return this->SamplesPerSegment;
  }
  // The block holds one point per 1-cell plus `samples` per segment it runs through: the
  // largest count within the budget follows from the counts at 0 and at SamplesPerSegment (the
  // proportional guess it replaces left 500 x 500 noise at 5 % with budget 2^23 empty, 7 per
  // segment being just over it, where 6 fitted).
  const vtkIdType ends = vtkTopoSplineWireFormat::SampledOneCellPoints(complex, result, 0);
  const vtkIdType perSample = (wanted - ends) / this->SamplesPerSegment;
  // Below SamplesPerSegment, since `wanted` is over the budget.
  const int samples = perSample > 0 && this->MaximumSampledPoints > ends
    ? static_cast<int>((this->MaximumSampledPoints - ends) / perSample)
    : 0;
  vtkWarningMacro("Smooth 1-Cells: the SampledOneCells display block would hold "
    << wanted << " points at " << this->SamplesPerSegment << " per segment (merged 1-cells share pieces), more than "
    << this->MaximumSampledPoints << "; "
    << (samples > 0 ? "sampled at " + std::to_string(samples) + " per segment instead"
                    : std::string("left empty (the Bezier block has every curve)"))
    << ".");
  return samples;
}

// Not errors, but changes a user should know of: critical values spread apart, crossings left.
void vtkTopoSplineSmoothOneCells::ReportAdjustments(
  const topospline::MorseSmaleComplex& complex, const topospline::OneCellSmoothingResult& result)
{
  if (result.SpreadCriticalValues > 0)
  {
    // Not an error: equal or nearly equal critical values (a plateau, a constant field) that
    // the complex orders by point id get numbers that strictly increase. Said aloud only where
    // it shows (above 1e-6 of the range: constant and near-constant fields); terrain plateaus
    // move by about 1e-11 of the range, reported in field data and at TRACE level.
    const auto [low, high] = std::minmax_element(complex.CriticalPoints.begin(), complex.CriticalPoints.end(),
      [](const auto& a, const auto& b) { return a.Value < b.Value; });
    vtkVLog(result.MaximumSpread > 1e-6 * (high->Value - low->Value) ? vtkLogger::VERBOSITY_INFO
                                                                      : vtkLogger::VERBOSITY_TRACE,
      "Smooth 1-Cells: " << result.SpreadCriticalValues << " critical value(s) raised by at most "
                         << result.MaximumSpread << " so that values strictly increase along every 1-cell.");
  }
  if (result.SuggestedSegments > 0)
  {
    vtkWarningMacro("Smooth 1-Cells: " << result.OversegmentedPieces << " of " << result.Pieces.size()
                    << " pieces of 1-cells have more than twice as many segments as jagged edges, most of all "
                       "segments (Curve Segments "
                    << this->CurveSegments
                    << " has no divisor to give them fewer), and Reconstruct 2-Cells' grids grow with the square "
                       "of a side's segments; Curve Segments "
                    << result.SuggestedSegments << " gives nearly every piece at most twice its edges.");
  }
  if (result.RemainingCrossings > 0)
  {
    vtkWarningMacro("Smooth 1-Cells: " << result.RemainingCrossings
                                       << " pair(s) of smoothed 1-cells still cross after adapting "
                                       << result.AdaptedPieces << " piece(s).");
  }
}

void vtkTopoSplineSmoothOneCells::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "CurveSegments: " << this->CurveSegments << "\n"
     << indent << "SamplesPerSegment: " << this->SamplesPerSegment << "\n"
     << indent << "MaximumSampledPoints: " << this->MaximumSampledPoints << "\n";
}
