#include "vtkTopoSplineReconstructTwoCells.h"

#include "vtkTopoSplineArrayNames.h"
#include "vtkTopoSplineDomainConversion.h"

#include "TopologicalSampling.h"    // core
#include "TopologyVerification.h"   // core
#include "TwoCellReconstruction.h"  // core

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
#include <functional>

namespace names = vtkTopoSplineArrayNames;
namespace conversion = vtkTopoSplineDomainConversion;
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

// The smoothed pieces written by "Smooth 1-Cells" (Bezier curves with their heights, and the
// pieces of every 1-cell), back into the core's form.
bool ReadSmoothedPieces(vtkMultiBlockDataSet* input, const topospline::MorseSmaleComplex& complex,
  const conversion::DomainPlane& plane, topospline::OneCellSmoothingResult& result, std::string& error)
{
  auto* block = input->GetNumberOfBlocks() > names::SmoothedOneCellsIndex
    ? vtkUnstructuredGrid::SafeDownCast(input->GetBlock(names::SmoothedOneCellsIndex))
    : nullptr;
  vtkDataArray* piece = block ? block->GetCellData()->GetArray(names::PieceId) : nullptr;
  vtkDataArray* height = block ? block->GetPointData()->GetArray(names::Height) : nullptr;
  vtkDataArray* offsets = block ? block->GetFieldData()->GetArray(names::SeparatrixPieceOffsets) : nullptr;
  vtkDataArray* list = block ? block->GetFieldData()->GetArray(names::SeparatrixPieces) : nullptr;
  if (!piece || !height || !offsets || !list)
  {
    error = "the input has no smoothed 1-cells (expected the output of \"Smooth 1-Cells\")";
    return false;
  }
  const vtkIdType arcs = offsets->GetNumberOfTuples() - 1;
  if (arcs != static_cast<vtkIdType>(complex.OneCells.size()))
  {
    error = "the smoothed 1-cells do not match the complex";
    return false;
  }
  Index pieces = 0;
  for (vtkIdType c = 0; c < block->GetNumberOfCells(); ++c)
  {
    pieces = std::max(pieces, static_cast<Index>(piece->GetComponent(c, 0)) + 1);
  }
  result = topospline::OneCellSmoothingResult();
  result.Pieces.resize(pieces);
  for (auto& p : result.Pieces)
  {
    p.Curve.Dimension = 2;
    p.Height.Dimension = 1;
  }
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < block->GetNumberOfCells(); ++c)
  {
    block->GetCellPoints(c, ids);
    const Index p = static_cast<Index>(piece->GetComponent(c, 0));
    if (block->GetCellType(c) != VTK_BEZIER_CURVE || ids->GetNumberOfIds() != 4 || p < 0)
    {
      error = "the smoothed 1-cells are not cubic Bezier curves";
      return false;
    }
    auto& smoothed = result.Pieces[p];
    // VTK orders a curve's points as both ends first, then the interior ones.
    const int order[4] = { 0, 2, 3, 1 };
    for (int m = 0; m < 4; ++m)
    {
      const vtkIdType id = ids->GetId(order[m]);
      double xyz[3], uv[2];
      block->GetPoint(id, xyz);
      plane.ToPlanar(xyz, uv);
      smoothed.Curve.ControlPoints.insert(smoothed.Curve.ControlPoints.end(), uv, uv + 2);
      smoothed.Height.ControlPoints.push_back(height->GetComponent(id, 0));
    }
    ++smoothed.Curve.Segments;
    ++smoothed.Height.Segments;
  }
  result.PiecesOfOneCell.resize(arcs);
  for (vtkIdType a = 0; a < arcs; ++a)
  {
    const vtkIdType begin = static_cast<vtkIdType>(offsets->GetComponent(a, 0));
    const vtkIdType end = static_cast<vtkIdType>(offsets->GetComponent(a + 1, 0));
    for (vtkIdType i = begin; i < end && i < list->GetNumberOfTuples(); ++i)
    {
      const Index p = static_cast<Index>(list->GetComponent(i, 0));
      if (p < 0 || p >= pieces)
      {
        error = "the smoothed 1-cells list unknown pieces";
        return false;
      }
      result.PiecesOfOneCell[a].push_back(p);
    }
  }
  return true;
}

// Largest edge of the triangulation (images: the grid's diagonal): the distance within which
// a critical point of a sampling of the reconstruction must sit from its node.
double GridSpacing(vtkDataSet* domain, const topospline::PlanarScalarField& field)
{
  if (auto* image = vtkImageData::SafeDownCast(domain))
  {
    const auto plane = conversion::PlaneOf(domain);
    const double* s = image->GetSpacing();
    return std::hypot(s[plane.U], s[plane.V]);
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

double MeanEdgeLength(const topospline::PlanarScalarField& field)
{
  if (field.IsGrid())
  {
    // The grid's triangles: both axes and the (i+1,j)-(i,j+1) diagonal.
    const auto& p = field.Points;
    const double dx = std::abs(p[2] - p[0]);
    const double dy = std::abs(p[2 * field.GridDimensions[0] + 1] - p[1]);
    return (dx + dy + std::hypot(dx, dy)) / 3;
  }
  double sum = 0;
  std::size_t count = 0;
  const auto& p = field.Points;
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

// VTK_BEZIER_TRIANGLE point order for degree 3 (corners, edge points from each edge's first
// corner, centre) as ordinate indices b_ijk, with A, B, C the VTK corners 0, 1, 2.
constexpr int VtkBezierTriangleOrder[10] = { topospline::BezierOrdinateIndex(3, 0),
  topospline::BezierOrdinateIndex(0, 3), topospline::BezierOrdinateIndex(0, 0),
  topospline::BezierOrdinateIndex(2, 1), topospline::BezierOrdinateIndex(1, 2),
  topospline::BezierOrdinateIndex(0, 2), topospline::BezierOrdinateIndex(0, 1),
  topospline::BezierOrdinateIndex(1, 0), topospline::BezierOrdinateIndex(2, 0),
  topospline::BezierOrdinateIndex(1, 1) };

struct TopologyCheck
{
  topospline::TopologyComparison Comparison;
  bool Ran = false;
  std::string Error;
};

// Stage 1 on a sampling of the reconstruction, compared with the complex's critical points.
TopologyCheck CheckTopology(vtkDataSet* sampling, vtkDataArray* values,
  const std::vector<topospline::CriticalPointLocation>& expected, double tolerance)
{
  TopologyCheck check;
  topospline::PlanarScalarField field;
  topospline::MorseSmaleComplexExtraction extraction;
  extraction.Parallel = conversion::SMPParallelFor();
  extraction.CriticalPointsOnly = true;
  topospline::MorseSmaleComplex found;
  if (!conversion::ToPlanarScalarField(sampling, values, field, check.Error) ||
    !extraction.Extract(field, found, check.Error))
  {
    return check;
  }
  check.Comparison =
    topospline::CompareCriticalPoints(expected, topospline::CriticalPointLocations(found, field.Points), tolerance);
  check.Ran = true;
  return check;
}

// The mesh topology of a sampling (closed form for grids).
void BuildTopology(const topospline::PlanarScalarField& field, topospline::TriangleMeshTopology& mesh, std::string& error)
{
  if (field.IsGrid())
  {
    mesh.BuildGrid(field.GridDimensions[0], field.GridDimensions[1], conversion::SMPParallelFor());
  }
  else
  {
    mesh.Build(static_cast<Index>(field.Points.size() / 2), field.Triangles, conversion::SMPParallelFor(), error);
  }
}

// Topological sampling: the complex's critical points, placed on the sampling's vertices by
// `vertexAt` (a vertex of the domain to one of the sampling), become the only extrema of the
// sampled values (TopologicalSampling.h).
topospline::TopologicalSamplingReport EnforceComplexTopology(const topospline::MorseSmaleComplex& complex,
  const topospline::OneCellSmoothingResult& smoothed, const topospline::TriangleMeshTopology& domainMesh,
  const std::vector<double>& domainPoints, const topospline::PlanarScalarField& sampling,
  const topospline::TriangleMeshTopology& mesh, const std::function<Index(Index)>& vertexAt, double spacing,
  vtkDoubleArray* values, int& displacedSaddles)
{
  std::vector<double> sampled(values->GetPointer(0), values->GetPointer(0) + values->GetNumberOfTuples());
  const auto report = topospline::SampleTopologically(complex, domainMesh, domainPoints, smoothed, sampling, mesh,
    vertexAt, spacing, sampled, displacedSaddles, conversion::SMPParallelFor());
  std::copy(sampled.begin(), sampled.end(), values->GetPointer(0));
  return report;
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
} // namespace

int vtkTopoSplineReconstructTwoCells::RequestDataObject(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkMultiBlockDataSet* input = vtkMultiBlockDataSet::GetData(inputVector[0], 0);
  EnsureGeometryOutput(outputVector->GetInformationObject(0), input ? conversion::SegmentationOf(input) : nullptr);
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

int vtkTopoSplineReconstructTwoCells::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkLogScopeFunction(TRACE);
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
  if (!conversion::FromMultiBlock(input, complex, error))
  {
    vtkErrorMacro("Reconstruct 2-Cells: " << error << ".");
    return 1;
  }
  vtkDataSet* domain = conversion::SegmentationOf(input);
  const auto plane = conversion::PlaneOf(domain);
  topospline::OneCellSmoothingResult smoothed;
  if (!ReadSmoothedPieces(input, complex, plane, smoothed, error))
  {
    vtkErrorMacro("Reconstruct 2-Cells: " << error << ".");
    return 1;
  }
  auto* nameArray = vtkStringArray::SafeDownCast(input->GetFieldData()->GetAbstractArray(names::ScalarFieldName));
  const std::string scalarName = nameArray && nameArray->GetNumberOfValues() > 0 ? nameArray->GetValue(0) : "";
  vtkDataArray* original = domain->GetPointData()->GetArray(scalarName.c_str());
  if (!original || original->GetNumberOfComponents() != 1)
  {
    vtkErrorMacro("Reconstruct 2-Cells: the input field \"" << scalarName << "\" is missing from the complex.");
    return 1;
  }
  topospline::PlanarScalarField domainField;
  if (!conversion::ToPlanarScalarField(domain, original, domainField, error))
  {
    vtkErrorMacro("Reconstruct 2-Cells: " << error << ".");
    return 1;
  }
  {
    // Refused before anything is allocated, with the estimate. Measured: about 230 kB per
    // 2-cell (its triangulation, parameterization, Sibson grid and Bezier patches; uniform
    // noise 100 x 100 to 300 x 300 at 5 %: 1.5 to 10.7 GB for 5 000 to 45 000 cells), and
    // about 200 bytes per vertex of the finer sampling (values, mask, its critical point check).
    const double fineVertices =
      static_cast<double>(domain->GetNumberOfPoints()) * this->OutputResolution * this->OutputResolution;
    const double cells = static_cast<double>(complex.TwoCells.size());
    const double needed = 230e3 * cells + (this->OutputResolution > 1 ? 260.0 * fineVertices : 0.0);
    vtksys::SystemInformation system;
    const double available = 1024.0 * static_cast<double>(system.GetAvailablePhysicalMemory()) * 1024.0;
    if (available > 0 && needed > 0.8 * available)
    {
      vtkErrorMacro("Reconstruct 2-Cells: " << cells << " 2-cells"
                    << (this->OutputResolution > 1 ? " and the finer sampling" : "") << " need about "
                    << needed / 1e9 << " GB; this machine has " << available / 1e9
                    << " GB available. Simplify further (a higher Persistence Threshold)"
                    << (this->OutputResolution > 1 ? " or choose a lower Output Resolution" : "") << ".");
      return 1;
    }
  }

  // The 2-cells, in parallel.
  topospline::TwoCellReconstruction reconstruction;
  reconstruction.BoundarySamples = this->BoundarySamples;
  // One grid spacing: how far a vertex may lie outside the smoothed cells, and how far a
  // critical point of a sampling may lie from its node.
  const double gridSpacing = GridSpacing(domain, domainField);
  reconstruction.SnapDistance = gridSpacing;
  const double edge = MeanEdgeLength(domainField);
  reconstruction.MinimumMeshEdgeLength = 2 * edge;
  reconstruction.NegligibleArea = edge * edge;
  reconstruction.Parallel = conversion::SMPParallelFor();
  reconstruction.Hooks.Progress = [this](double f) { this->UpdateProgress(0.6 * f); };
  reconstruction.Hooks.AbortRequested = [this]() { return this->GetAbortExecute() != 0; };
  {
    vtkLogScopeF(TRACE, "reconstruct %d 2-cells", static_cast<int>(complex.TwoCells.size()));
    if (!reconstruction.Reconstruct(complex, smoothed, error))
    {
      if (error != "aborted")
      {
        vtkErrorMacro("Reconstruct 2-Cells: " << error << ".");
      }
      return 1;
    }
  }
  const auto& report = reconstruction.Report();
  if (report.FailedCells > 0)
  {
    for (Index c = 0; c < reconstruction.NumberOfCells(); ++c)
    {
      if (!reconstruction.Cell(c).Valid && !reconstruction.Cell(c).Negligible)
      {
        vtkWarningMacro("Reconstruct 2-Cells: 2-cell " << c << " was not reconstructed: "
                                                       << reconstruction.Cell(c).Error << ".");
      }
    }
  }

  // F o Phi at every input vertex; the vertex's 2-cell of the jagged complex is the first guess.
  vtkDataSet* output = EnsureGeometryOutput(outputVector->GetInformationObject(0), domain);
  output->ShallowCopy(domain);
  const vtkIdType n = domain->GetNumberOfPoints();
  auto values = conversion::NewArray<vtkDoubleArray>(names::ReconstructedField, 1, n);
  auto difference = conversion::NewArray<vtkDoubleArray>(names::ReconstructionDifference, 1, n);
  auto cellIds = conversion::NewArray<vtkIntArray>("ReconstructionCellId", 1, n);
  std::atomic<vtkIdType> snapped(0), missed(0);
  const auto evaluationStart = std::chrono::steady_clock::now();
  {
    vtkLogScopeF(TRACE, "evaluate at %lld vertices", static_cast<long long>(n));
    vtkDataArray* hints = domain->GetPointData()->GetArray(names::TwoCellId);
    vtkSMPTools::For(0, n, [&](vtkIdType begin, vtkIdType end) {
      vtkIdType localSnapped = 0, localMissed = 0;
      for (vtkIdType v = begin; v < end; ++v)
      {
        const double* xy = &domainField.Points[2 * v];
        const Index hint = hints ? static_cast<Index>(hints->GetComponent(v, 0)) : topospline::InvalidIndex;
        const auto e = reconstruction.Evaluate(xy[0], xy[1], hint);
        const double f = original->GetComponent(v, 0);
        if (e.Cell == topospline::InvalidIndex)
        {
          // No reconstructed cell here (a failed cell): the input value, reported.
          ++localMissed;
          values->SetValue(v, f);
        }
        else
        {
          localSnapped += e.Inside ? 0 : 1;
          values->SetValue(v, e.Value);
        }
        difference->SetValue(v, values->GetValue(v) - f);
        cellIds->SetValue(v, e.Cell);
      }
      snapped += localSnapped;
      missed += localMissed;
    });
  }
  const double evaluationSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - evaluationStart).count();
  // Topological sampling of the input geometry; the raw values are kept for the report.
  topospline::TriangleMeshTopology domainMesh;
  BuildTopology(domainField, domainMesh, error);
  vtkSmartPointer<vtkDoubleArray> rawValues;
  topospline::TopologicalSamplingReport sampling;
  int displacedSaddles = 0;
  if (this->TopologicalSampling)
  {
    vtkLogScopeF(TRACE, "topological sampling");
    // F o Phi itself stays available (it interpolates the critical values exactly; the
    // flooding may move a node's value when the node sits in a spurious pit or peak).
    rawValues = vtkSmartPointer<vtkDoubleArray>::New();
    rawValues->DeepCopy(values);
    rawValues->SetName(names::ExactReconstruction);
    output->GetPointData()->AddArray(rawValues);
    sampling = EnforceComplexTopology(complex, smoothed, domainMesh, domainField.Points, domainField, domainMesh,
      [](Index v) { return v; },
      gridSpacing, values, displacedSaddles);
    for (vtkIdType v = 0; v < n; ++v)
    {
      difference->SetValue(v, values->GetValue(v) - original->GetComponent(v, 0));
    }
  }
  output->GetPointData()->AddArray(values);
  output->GetPointData()->AddArray(difference);
  output->GetPointData()->AddArray(cellIds);
  output->GetPointData()->SetActiveScalars(names::ReconstructedField);
  this->UpdateProgress(0.7);

  double maximumError = 0, squares = 0, range[2];
  original->GetRange(range, 0);
  for (vtkIdType v = 0; v < n; ++v)
  {
    const double d = difference->GetValue(v);
    maximumError = std::max(maximumError, std::abs(d));
    squares += d * d;
  }
  const double rmsError = n ? std::sqrt(squares / n) : 0;

  // The Bezier triangles of every cell, in the plane of the input.
  {
    vtkLogScopeF(TRACE, "Bezier triangles");
    std::vector<std::vector<topospline::PlanarBezierTriangle>> perCell(reconstruction.NumberOfCells());
    vtkSMPTools::For(0, reconstruction.NumberOfCells(), [&](vtkIdType begin, vtkIdType end) {
      for (vtkIdType c = begin; c < end; ++c)
      {
        perCell[c] = reconstruction.PlanarBezierTriangles(static_cast<Index>(c));
      }
    });
    vtkIdType total = 0;
    for (const auto& list : perCell)
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
    for (Index c = 0; c < static_cast<Index>(perCell.size()); ++c)
    {
      for (const auto& triangle : perCell[c])
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
    patchesOutput->Initialize();
    patchesOutput->SetPoints(points);
    patchesOutput->SetCells(VTK_BEZIER_TRIANGLE, cells);
    patchesOutput->GetPointData()->AddArray(height);
    patchesOutput->GetPointData()->SetActiveScalars(names::Height);
    patchesOutput->GetCellData()->AddArray(cellOf);
  }
  this->UpdateProgress(0.75);

  // The resampled image.
  resampledOutput->Initialize();
  vtkSmartPointer<vtkDoubleArray> resampled;
  if (this->OutputResolution > 1)
  {
    vtkLogScopeF(TRACE, "resample x%d", this->OutputResolution);
    const int f = this->OutputResolution;
    int dims[3] = { 1, 1, 1 };
    double origin[3] = { 0, 0, 0 }, spacing[3] = { 1, 1, 1 };
    if (auto* image = vtkImageData::SafeDownCast(domain))
    {
      // From the image's first point: its extent need not start at 0 (e.g. a cropped image).
      image->GetDimensions(dims);
      image->GetPoint(0, origin);
      image->GetSpacing(spacing);
      for (int axis : { plane.U, plane.V })
      {
        dims[axis] = (dims[axis] - 1) * f + 1;
        spacing[axis] /= f;
      }
      // Direction matrices are not honoured by stage 1 either: axis-aligned images only.
    }
    else
    {
      double bounds[4];
      conversion::PlanarBounds(domain, bounds);
      const double h = std::max(MeanEdgeLength(domainField) / f, 1e-12 * (bounds[1] - bounds[0] + bounds[3] - bounds[2]));
      origin[plane.U] = bounds[0];
      origin[plane.V] = bounds[2];
      origin[plane.W] = plane.WValue;
      dims[plane.U] = std::max(2, static_cast<int>(std::ceil((bounds[1] - bounds[0]) / h)) + 1);
      dims[plane.V] = std::max(2, static_cast<int>(std::ceil((bounds[3] - bounds[2]) / h)) + 1);
      spacing[plane.U] = (bounds[1] - bounds[0]) / (dims[plane.U] - 1);
      spacing[plane.V] = (bounds[3] - bounds[2]) / (dims[plane.V] - 1);
    }
    resampledOutput->SetDimensions(dims);
    resampledOutput->SetOrigin(origin);
    resampledOutput->SetSpacing(spacing);
    const vtkIdType m = resampledOutput->GetNumberOfPoints();
    resampled = conversion::NewArray<vtkDoubleArray>(names::ReconstructedField, 1, m);
    auto valid = conversion::NewArray<vtkCharArray>("vtkValidPointMask", 1, m);
    vtkSMPTools::For(0, m, [&](vtkIdType begin, vtkIdType end) {
      for (vtkIdType p = begin; p < end; ++p)
      {
        double xyz[3], uv[2];
        resampledOutput->GetPoint(p, xyz);
        plane.ToPlanar(xyz, uv);
        const auto e = reconstruction.Evaluate(uv[0], uv[1]);
        resampled->SetValue(p, e.Cell == topospline::InvalidIndex ? 0.0 : e.Value);
        valid->SetValue(p, e.Cell == topospline::InvalidIndex ? 0 : 1);
      }
    });
    if (this->TopologicalSampling)
    {
      topospline::PlanarScalarField fine;
      std::string ignored;
      conversion::ToPlanarScalarField(resampledOutput, resampled, fine, ignored);
      topospline::TriangleMeshTopology fineMesh;
      BuildTopology(fine, fineMesh, ignored);
      const double* o = resampledOutput->GetOrigin();
      const double* h = resampledOutput->GetSpacing();
      const int ni = dims[plane.U], nj = dims[plane.V];
      int fineDisplaced = 0;
      const auto fineReport = EnforceComplexTopology(complex, smoothed, domainMesh, domainField.Points, fine, fineMesh,
        [&](Index v) {
          const double* xy = &domainField.Points[2 * static_cast<std::size_t>(v)];
          const int i = std::clamp(static_cast<int>(std::lround((xy[0] - o[plane.U]) / h[plane.U])), 0, ni - 1);
          const int j = std::clamp(static_cast<int>(std::lround((xy[1] - o[plane.V]) / h[plane.V])), 0, nj - 1);
          return static_cast<Index>(j * ni + i);
        },
        gridSpacing, resampled, fineDisplaced);
      displacedSaddles += fineDisplaced;
      sampling.ChangedVertices += fineReport.ChangedVertices;
      sampling.MaximumChange = std::max(sampling.MaximumChange, fineReport.MaximumChange);
      sampling.Converged = sampling.Converged && fineReport.Converged;
    }
    resampledOutput->GetPointData()->AddArray(resampled);
    resampledOutput->GetPointData()->AddArray(valid);
    resampledOutput->GetPointData()->SetActiveScalars(names::ReconstructedField);
  }
  this->UpdateProgress(0.85);

  // Field data: what was done and how well.
  vtkFieldData* fd = output->GetFieldData();
  fd->PassData(input->GetFieldData());
  conversion::AddFieldNumbers(fd, "TwoCells", { static_cast<double>(report.Cells) });
  conversion::AddFieldNumbers(fd, "FailedTwoCells", { static_cast<double>(report.FailedCells) });
  conversion::AddFieldNumbers(fd, "NegligibleTwoCells", { static_cast<double>(report.NegligibleCells) });
  conversion::AddFieldNumbers(fd, "SlitTwoCells", { static_cast<double>(report.SlitCells) });
  conversion::AddFieldNumbers(fd, "ShiftedCorners", { static_cast<double>(report.ShiftedCorners) });
  conversion::AddFieldNumbers(fd, "ViolatingPatches", { static_cast<double>(report.ViolatingPatches) });
  conversion::AddFieldNumbers(fd, "LinearizedDiagonals", { static_cast<double>(report.LinearizedDiagonals) });
  conversion::AddFieldNumbers(fd, "BezierTriangles", { static_cast<double>(report.BezierTriangles) });
  conversion::AddFieldNumbers(fd, "MeshTriangles", { static_cast<double>(report.MeshTriangles) });
  conversion::AddFieldNumbers(fd, "MaximumGridSize", { static_cast<double>(report.MaximumGridSize) });
  conversion::AddFieldNumbers(fd, "SnappedPoints", { static_cast<double>(snapped.load()) });
  conversion::AddFieldNumbers(fd, "UnreconstructedPoints", { static_cast<double>(missed.load()) });
  conversion::AddFieldNumbers(fd, "MaximumError", { maximumError });
  conversion::AddFieldNumbers(fd, "RMSError", { rmsError });
  conversion::AddFieldNumbers(fd, "ValueRange", { range[0], range[1] });
  conversion::AddFieldNumbers(fd, "ParameterizationSeconds", { report.ParameterizationSeconds });
  conversion::AddFieldNumbers(fd, "SurfaceSeconds", { report.SurfaceSeconds });
  conversion::AddFieldNumbers(fd, "EvaluationSeconds", { evaluationSeconds });
  if (this->TopologicalSampling)
  {
    conversion::AddFieldNumbers(fd, "SamplingChangedVertices", { static_cast<double>(sampling.ChangedVertices) });
    conversion::AddFieldNumbers(fd, "SamplingMaximumChange", { sampling.MaximumChange });
    conversion::AddFieldNumbers(fd, "SamplingConverged", { sampling.Converged ? 1.0 : 0.0 });
    conversion::AddFieldNumbers(fd, "SamplingDisplacedSaddles", { static_cast<double>(displacedSaddles) });
  }
  if (report.ViolatingPatches > 0)
  {
    vtkWarningMacro("Reconstruct 2-Cells: " << report.ViolatingPatches
                                            << " Sibson grid cell(s) fail the monotonicity conditions.");
  }
  if (missed > 0)
  {
    vtkWarningMacro("Reconstruct 2-Cells: " << missed.load()
                                            << " vertices lie in no reconstructed 2-cell and keep their input value.");
  }

  if (this->VerifyTopology)
  {
    vtkLogScopeF(TRACE, "verify topology");
    const auto verifyStart = std::chrono::steady_clock::now();
    const auto expected = topospline::CriticalPointLocations(complex, domainField.Points);
    const double tolerance = gridSpacing * (1 + 1e-9);
    // The verdict covers the whole reconstruction: a failed 2-cell or a vertex outside every
    // reconstructed cell keeps input values, which no critical-point count can vouch for.
    bool verified = report.FailedCells == 0 && missed == 0;
    std::vector<topospline::CriticalPointLocation> spurious, missing;
    // `judged`: the check is on an output (the raw sampling before topological sampling is
    // only reported).
    auto record = [&](const char* prefix, const TopologyCheck& check, bool judged) {
      const std::string p(prefix);
      if (!check.Ran && !judged)
      {
        return;
      }
      if (!check.Ran)
      {
        vtkWarningMacro("Reconstruct 2-Cells: topology check on the " << prefix << " sampling failed: " << check.Error);
        verified = false;
        return;
      }
      const auto& c = check.Comparison;
      conversion::AddFieldNumbers(fd, (p + "CriticalPoints").c_str(),
        { static_cast<double>(c.Found[0]), static_cast<double>(c.Found[1]), static_cast<double>(c.Found[2]) });
      conversion::AddFieldNumbers(fd, (p + "CriticalPointDistance").c_str(), { c.MaximumDistance });
      if (!judged)
      {
        return;
      }
      if (!c.Identical())
      {
        verified = false;
        vtkWarningMacro("Reconstruct 2-Cells: the " << prefix << " sampling of the reconstruction has "
                                                    << c.Spurious.size() << " spurious and " << c.Missing.size()
                                                    << " missing critical point(s) (found " << c.Found[0] << "/"
                                                    << c.Found[1] << "/" << c.Found[2] << ", expected "
                                                    << c.Expected[0] << "/" << c.Expected[1] << "/" << c.Expected[2]
                                                    << ").");
      }
      spurious.insert(spurious.end(), c.Spurious.begin(), c.Spurious.end());
      missing.insert(missing.end(), c.Missing.begin(), c.Missing.end());
    };
    if (rawValues)
    {
      record("RawInput", CheckTopology(output, rawValues, expected, tolerance), false);
    }
    record("Input", CheckTopology(output, values, expected, tolerance), true);
    if (resampled)
    {
      record("Resampled", CheckTopology(resampledOutput, resampled, expected, tolerance), true);
    }
    conversion::AddFieldNumbers(fd, "ExpectedCriticalPoints", { 0, 0, 0 });
    {
      auto* e = vtkDoubleArray::SafeDownCast(fd->GetArray("ExpectedCriticalPoints"));
      for (const auto& cp : expected)
      {
        e->SetValue(cp.MorseIndex, e->GetValue(cp.MorseIndex) + 1);
      }
    }
    conversion::AddFieldNumbers(fd, "TopologyVerified", { verified ? 1.0 : 0.0 });
    AddPoints(fd, "SpuriousCriticalPoints", spurious);
    AddPoints(fd, "MissingCriticalPoints", missing);
    conversion::AddFieldNumbers(fd, "VerificationSeconds",
      { std::chrono::duration<double>(std::chrono::steady_clock::now() - verifyStart).count() });
  }
  this->UpdateProgress(1.0);
  return 1;
}

void vtkTopoSplineReconstructTwoCells::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "BoundarySamples: " << this->BoundarySamples << "\n"
     << indent << "OutputResolution: " << this->OutputResolution << "\n"
     << indent << "TopologicalSampling: " << this->TopologicalSampling << "\n"
     << indent << "VerifyTopology: " << this->VerifyTopology << "\n";
}
