#include "vtkTopoSplineSmoothOneCells.h"

#include "vtkTopoSplineArrayNames.h"
#include "vtkTopoSplineDomainConversion.h"

#include "MorseSmaleComplexSimplification.h" // core
#include "OneCellSmoothing.h"                // core

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataSet.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
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
// The junction points of a simplified complex's "JunctionPoints" block, with the 1-cells
// through each (those of the same kind and extremum whose path holds the junction's cell).
bool ReadJunctions(vtkMultiBlockDataSet* input, const topospline::MorseSmaleComplex& complex,
  std::vector<topospline::JunctionPoint>& junctions)
{
  auto* block = input->GetNumberOfBlocks() > names::JunctionPointsIndex
    ? vtkPolyData::SafeDownCast(input->GetBlock(names::JunctionPointsIndex))
    : nullptr;
  if (!block)
  {
    return false;
  }
  auto* pd = block->GetPointData();
  vtkDataArray* type = pd->GetArray(names::SeparatrixType);
  vtkDataArray* extremum = pd->GetArray("ExtremumId");
  vtkDataArray* cell = pd->GetArray(names::MeshCellId);
  vtkDataArray* value = pd->GetArray("JunctionValue");
  vtkDataArray* critical = pd->GetArray(names::CriticalPointId);
  if (!type || !extremum || !cell || !value || !critical)
  {
    return false;
  }
  std::map<Index, Index> position; // stable id -> position
  for (Index i = 0; i < static_cast<Index>(complex.CriticalPoints.size()); ++i)
  {
    position[complex.CriticalPoints[i].Id] = i;
  }
  std::map<Index, std::vector<Index>> arcsOfExtremum;
  for (Index a = 0; a < static_cast<Index>(complex.OneCells.size()); ++a)
  {
    const auto& arc = complex.OneCells[a];
    arcsOfExtremum[arc.Type == topospline::OneCell::Descending ? arc.Source : arc.Destination].push_back(a);
  }
  const auto plane = vtkTopoSplineDomainConversion::PlaneOf(vtkTopoSplineDomainConversion::SegmentationOf(input));
  for (vtkIdType j = 0; j < block->GetNumberOfPoints(); ++j)
  {
    topospline::JunctionPoint junction;
    junction.Type = type->GetComponent(j, 0) == 0 ? topospline::OneCell::Descending : topospline::OneCell::Ascending;
    const auto ext = position.find(static_cast<Index>(extremum->GetComponent(j, 0)));
    const auto cp = position.find(static_cast<Index>(critical->GetComponent(j, 0)));
    if (ext == position.end())
    {
      return false;
    }
    junction.Extremum = ext->second;
    junction.CriticalPoint = cp == position.end() ? topospline::InvalidIndex : cp->second;
    junction.Cell = static_cast<Index>(cell->GetComponent(j, 0));
    junction.Value = value->GetComponent(j, 0);
    double xyz[3];
    block->GetPoint(j, xyz);
    plane.ToPlanar(xyz, junction.Position);
    for (Index a : arcsOfExtremum[junction.Extremum])
    {
      const auto& arc = complex.OneCells[a];
      if (arc.Type == junction.Type &&
        std::find(arc.MeshCells.begin(), arc.MeshCells.end(), junction.Cell) != arc.MeshCells.end())
      {
        junction.OneCells.push_back(a);
      }
    }
    junctions.push_back(std::move(junction));
  }
  return true;
}

} // namespace

int vtkTopoSplineSmoothOneCells::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkLogScopeFunction(TRACE);
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
  if (!vtkTopoSplineDomainConversion::FromMultiBlock(input, complex, error))
  {
    vtkErrorMacro("Smooth 1-Cells: " << error << ".");
    return 1;
  }
  vtkDataSet* domain = vtkTopoSplineDomainConversion::SegmentationOf(input);

  // Junction points: from the simplified complex, or (for an unsimplified one) from the
  // simplification at 0 %, which finds where its 1-cells merge.
  std::vector<topospline::JunctionPoint> junctions;
  if (!ReadJunctions(input, complex, junctions))
  {
    vtkLogScopeF(TRACE, "find junction points");
    topospline::MorseSmaleComplexSimplification simplification;
    topospline::SimplificationOutput none;
    if (!simplification.ComputeHierarchy(complex, error) || !simplification.Simplify(0.0, none, error))
    {
      vtkErrorMacro("Smooth 1-Cells: " << error << ".");
      return 1;
    }
    junctions = std::move(none.JunctionPoints);
    complex = std::move(none.Complex);
  }

  double bounds[4];
  vtkTopoSplineDomainConversion::PlanarBounds(domain, bounds);
  const auto plane = vtkTopoSplineDomainConversion::PlaneOf(domain);
  topospline::OneCellSmoothing smoothing;
  smoothing.Segments = this->CurveSegments;
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
  if (result.RemainingCrossings > 0)
  {
    vtkWarningMacro("Smooth 1-Cells: " << result.RemainingCrossings
                                       << " pair(s) of smoothed 1-cells still cross after adapting "
                                       << result.AdaptedPieces << " piece(s).");
  }

  // The input's blocks pass through.
  output->SetNumberOfBlocks(names::SampledOneCellsIndex + 1);
  for (unsigned int b = 0; b < input->GetNumberOfBlocks() && b < names::SmoothedOneCellsIndex; ++b)
  {
    output->SetBlock(b, input->GetBlock(b));
    output->GetMetaData(b)->Set(vtkCompositeDataSet::NAME(), input->GetMetaData(b)->Get(vtkCompositeDataSet::NAME()));
  }
  output->GetFieldData()->PassData(input->GetFieldData());

  // Bezier cells: one VTK_BEZIER_CURVE of degree 3 per segment; VTK orders a curve's points
  // as both ends first, then the interior ones.
  vtkNew<vtkUnstructuredGrid> bezier;
  {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    auto height = vtkTopoSplineDomainConversion::NewArray<vtkDoubleArray>(names::Height);
    auto piece = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::PieceId);
    auto segments = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>("PieceSegments");
    auto type = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::SeparatrixType);
    vtkNew<vtkCellArray> cells;
    for (Index p = 0; p < static_cast<Index>(result.Pieces.size()); ++p)
    {
      const auto& smoothed = result.Pieces[p];
      for (int s = 0; s < smoothed.Curve.Segments; ++s)
      {
        const double* curve = smoothed.Curve.Segment(s);
        const double* h = smoothed.Height.Segment(s);
        vtkIdType ids[4];
        const int vtkOrder[4] = { 0, 3, 1, 2 };
        for (int m = 0; m < 4; ++m)
        {
          double xyz[3];
          plane.To3D(curve + 2 * vtkOrder[m], xyz);
          ids[m] = points->InsertNextPoint(xyz);
          height->InsertNextValue(h[vtkOrder[m]]);
        }
        cells->InsertNextCell(4, ids);
        piece->InsertNextValue(p);
        segments->InsertNextValue(smoothed.Segments);
        type->InsertNextValue(smoothed.Type);
      }
    }
    bezier->SetPoints(points);
    bezier->SetCells(VTK_BEZIER_CURVE, cells);
    bezier->GetPointData()->AddArray(height);
    bezier->GetPointData()->SetActiveScalars(names::Height);
    bezier->GetCellData()->AddArray(piece);
    bezier->GetCellData()->AddArray(segments);
    bezier->GetCellData()->AddArray(type);
    // Which pieces make up every 1-cell, in order from its source: stage 4 assembles the
    // sides of the 2-cells from them. 1-cell a is SeparatrixPieces[offsets[a] .. offsets[a+1]).
    auto offsets = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::SeparatrixPieceOffsets);
    auto list = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::SeparatrixPieces);
    offsets->InsertNextValue(0);
    for (const auto& pieces : result.PiecesOfOneCell)
    {
      for (Index p : pieces)
      {
        list->InsertNextValue(p);
      }
      offsets->InsertNextValue(static_cast<int>(list->GetNumberOfTuples()));
    }
    bezier->GetFieldData()->AddArray(offsets);
    bezier->GetFieldData()->AddArray(list);
  }
  output->SetBlock(names::SmoothedOneCellsIndex, bezier);
  output->GetMetaData(static_cast<unsigned int>(names::SmoothedOneCellsIndex))
    ->Set(vtkCompositeDataSet::NAME(), names::SmoothedOneCellsBlock);

  // Every 1-cell sampled densely, through its pieces.
  vtkNew<vtkPolyData> sampled;
  {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    vtkNew<vtkCellArray> lines;
    auto height = vtkTopoSplineDomainConversion::NewArray<vtkDoubleArray>(names::Height);
    auto id = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::SeparatrixId);
    auto source = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::SourceId);
    auto destination = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::DestinationId);
    auto type = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::SeparatrixType);
    std::vector<vtkIdType> ids;
    for (Index a = 0; a < static_cast<Index>(complex.OneCells.size()); ++a)
    {
      ids.clear();
      for (Index p : result.PiecesOfOneCell[a])
      {
        const auto& smoothed = result.Pieces[p];
        const int count = smoothed.Curve.Segments * this->SamplesPerSegment;
        for (int s = ids.empty() ? 0 : 1; s <= count; ++s)
        {
          const double t = static_cast<double>(s) / count;
          double uv[2], xyz[3];
          smoothed.Curve.Evaluate(t, uv);
          plane.To3D(uv, xyz);
          ids.push_back(points->InsertNextPoint(xyz));
          height->InsertNextValue(smoothed.Height.Value(t));
        }
      }
      const auto& arc = complex.OneCells[a];
      if (ids.empty())
      {
        // A 1-cell of one point (a saddle on its minimum's vertex, zero persistence).
        double xyz[3];
        plane.To3D(arc.Points.data(), xyz);
        ids.push_back(points->InsertNextPoint(xyz));
        height->InsertNextValue(arc.Values.front());
      }
      lines->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
      id->InsertNextValue(a);
      source->InsertNextValue(complex.CriticalPoints[arc.Source].Id);
      destination->InsertNextValue(complex.CriticalPoints[arc.Destination].Id);
      type->InsertNextValue(arc.Type);
    }
    sampled->SetPoints(points);
    sampled->SetLines(lines);
    sampled->GetPointData()->AddArray(height);
    sampled->GetPointData()->SetActiveScalars(names::Height);
    for (vtkAbstractArray* a : std::initializer_list<vtkAbstractArray*>{ id, source, destination, type })
    {
      sampled->GetCellData()->AddArray(a);
    }
  }
  output->SetBlock(names::SampledOneCellsIndex, sampled);
  output->GetMetaData(static_cast<unsigned int>(names::SampledOneCellsIndex))
    ->Set(vtkCompositeDataSet::NAME(), names::SampledOneCellsBlock);

  double l1 = 0, free = 0;
  for (const auto& p : result.Pieces)
  {
    l1 += p.L1Error;
    free += p.UnconstrainedL1Error;
  }
  vtkFieldData* fd = output->GetFieldData();
  using vtkTopoSplineDomainConversion::AddFieldNumbers;
  AddFieldNumbers(fd, "CurveSegments", { static_cast<double>(this->CurveSegments) });
  AddFieldNumbers(fd, "NumberOfPieces", { static_cast<double>(result.Pieces.size()) });
  AddFieldNumbers(fd, "AdaptedPieces", { static_cast<double>(result.AdaptedPieces) });
  AddFieldNumbers(fd, "RemainingCrossings", { static_cast<double>(result.RemainingCrossings) });
  AddFieldNumbers(fd, "PiecesOutsideDomain", { static_cast<double>(result.PiecesOutsideDomain) });
  AddFieldNumbers(fd, "ClampedPieces", { static_cast<double>(result.ClampedPieces) });
  AddFieldNumbers(fd, "L1Error", { l1 });
  AddFieldNumbers(fd, "UnconstrainedL1Error", { free });
  AddFieldNumbers(fd, "JunctionMargin", { result.JunctionMargin });
  AddFieldNumbers(fd, "SpreadCriticalValues", { static_cast<double>(result.SpreadCriticalValues) });
  AddFieldNumbers(fd, "MaximumSpread", { result.MaximumSpread });
  this->UpdateProgress(1.0);
  return 1;
}

void vtkTopoSplineSmoothOneCells::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "CurveSegments: " << this->CurveSegments << "\n"
     << indent << "SamplesPerSegment: " << this->SamplesPerSegment << "\n";
}
