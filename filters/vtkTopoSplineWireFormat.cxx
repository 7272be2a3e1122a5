#include "vtkTopoSplineWireFormat.h"

#include "vtkTopoSplineArrayNames.h"
#include "vtkTopoSplineDomainConversion.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkCharArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkIdTypeArray.h>
#include <vtkInformation.h>
#include <vtkIntArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSMPThreadLocalObject.h>
#include <vtkSMPTools.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>

#include <algorithm>
#include <atomic>

namespace names = vtkTopoSplineArrayNames;
namespace conversion = vtkTopoSplineDomainConversion;
using topospline::Index;

namespace
{
vtkDataArray* RequireArray(vtkFieldData* data, const char* name, std::string& error)
{
  vtkDataArray* array = data ? data->GetArray(name) : nullptr;
  if (!array && error.empty())
  {
    error = std::string("array \"") + name + "\" is missing";
  }
  return array;
}

// VTK orders the points of a VTK_BEZIER_CURVE as both ends first, then the interior ones:
// VTK point m is control point CurvePointOfVtkPoint[m] of the cubic.
constexpr int CurvePointOfVtkPoint[4] = { 0, 3, 1, 2 };
} // namespace

namespace vtkTopoSplineWireFormat
{
namespace
{
// Block 0: one vertex per critical point, at its vertex of the domain.
vtkSmartPointer<vtkPolyData> CriticalPointsBlock(const topospline::MorseSmaleComplex& complex, vtkDataSet* domain)
{
  const auto& cps = complex.CriticalPoints;
  auto critical = vtkSmartPointer<vtkPolyData>::New();
  const vtkIdType n = static_cast<vtkIdType>(cps.size());
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  vtkNew<vtkCellArray> verts;
  auto id = conversion::NewArray<vtkIntArray>(names::CriticalPointId, 1, n);
  auto index = conversion::NewArray<vtkIntArray>(names::CriticalIndex, 1, n);
  auto value = conversion::NewArray<vtkDoubleArray>(names::CriticalValue, 1, n);
  auto vertex = conversion::NewArray<vtkIdTypeArray>(names::VertexId, 1, n);
  auto cell = conversion::NewArray<vtkIdTypeArray>(names::CriticalCellId, 1, n);
  auto boundary = conversion::NewArray<vtkCharArray>(names::IsOnBoundary, 1, n);
  auto edgeVertex = conversion::NewArray<vtkIdTypeArray>(names::SaddleEdgeVertexId, 1, n);
  auto corner = conversion::NewArray<vtkCharArray>(names::IsCornerTriangle, 1, n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    points->SetPoint(i, domain->GetPoint(cps[i].Vertex));
    verts->InsertNextCell(1, &i);
    id->SetValue(i, cps[i].Id);
    index->SetValue(i, cps[i].MorseIndex);
    value->SetValue(i, cps[i].Value);
    vertex->SetValue(i, cps[i].Vertex);
    cell->SetValue(i, cps[i].Cell);
    boundary->SetValue(i, cps[i].OnBoundary ? 1 : 0);
    edgeVertex->SetValue(i, cps[i].EdgeVertex);
    corner->SetValue(i, cps[i].CornerTriangle ? 1 : 0);
  }
  critical->SetPoints(points);
  critical->SetVerts(verts);
  conversion::AddArrays(critical->GetPointData(), { id, index, value, vertex, cell, boundary, edgeVertex, corner });
  critical->GetPointData()->SetActiveScalars(names::CriticalIndex);
  return critical;
}

// Block 1: the 1-cells as polylines, from source to destination.
vtkSmartPointer<vtkPolyData> OneCellsBlock(
  const topospline::MorseSmaleComplex& complex, const conversion::DomainPlane& embedding)
{
  const auto& cps = complex.CriticalPoints;
  auto oneCells = vtkSmartPointer<vtkPolyData>::New();
  vtkIdType nPoints = 0;
  for (const auto& oneCell : complex.OneCells)
  {
    nPoints += static_cast<vtkIdType>(oneCell.Values.size());
  }
  const vtkIdType n = static_cast<vtkIdType>(complex.OneCells.size());
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(nPoints);
  vtkNew<vtkCellArray> lines;
  auto along = conversion::NewArray<vtkDoubleArray>(names::ScalarAlong, 1, nPoints);
  auto meshCell = conversion::NewArray<vtkIdTypeArray>(names::MeshCellId, 1, nPoints);
  auto id = conversion::NewArray<vtkIntArray>(names::SeparatrixId, 1, n);
  auto source = conversion::NewArray<vtkIntArray>(names::SourceId, 1, n);
  auto destination = conversion::NewArray<vtkIntArray>(names::DestinationId, 1, n);
  auto type = conversion::NewArray<vtkIntArray>(names::SeparatrixType, 1, n);
  vtkIdType next = 0;
  std::vector<vtkIdType> ids;
  for (vtkIdType a = 0; a < n; ++a)
  {
    const auto& oneCell = complex.OneCells[a];
    const vtkIdType count = static_cast<vtkIdType>(oneCell.Values.size());
    // Ascending sides carry one more point at each end than mesh cells (saddle, maximum).
    const vtkIdType offset = oneCell.Type == topospline::OneCell::Ascending ? 1 : 0;
    ids.resize(count);
    for (vtkIdType p = 0; p < count; ++p)
    {
      double xyz[3];
      embedding.To3D(&oneCell.Points[2 * p], xyz);
      points->SetPoint(next, xyz);
      along->SetValue(next, oneCell.Values[p]);
      const vtkIdType c = p - offset;
      const bool inMesh = c >= 0 && c < static_cast<vtkIdType>(oneCell.MeshCells.size());
      meshCell->SetValue(next, inMesh ? oneCell.MeshCells[c] : -1);
      ids[p] = next++;
    }
    lines->InsertNextCell(count, ids.data());
    id->SetValue(a, static_cast<int>(a));
    source->SetValue(a, cps[oneCell.Source].Id);
    destination->SetValue(a, cps[oneCell.Destination].Id);
    type->SetValue(a, oneCell.Type);
  }
  oneCells->SetPoints(points);
  oneCells->SetLines(lines);
  oneCells->GetPointData()->AddArray(along);
  oneCells->GetPointData()->AddArray(meshCell);
  oneCells->GetPointData()->SetActiveScalars(names::ScalarAlong);
  conversion::AddArrays(oneCells->GetCellData(), { id, source, destination, type });
  return oneCells;
}

// Block 2: one point per 2-cell at its centroid, carrying its corners and sides.
vtkSmartPointer<vtkPolyData> TwoCellsBlock(
  const topospline::MorseSmaleComplex& complex, const conversion::DomainPlane& embedding)
{
  const auto& cps = complex.CriticalPoints;
  auto twoCells = vtkSmartPointer<vtkPolyData>::New();
  const vtkIdType n = static_cast<vtkIdType>(complex.TwoCells.size());
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  vtkNew<vtkCellArray> verts;
  auto id = conversion::NewArray<vtkIntArray>(names::TwoCellId, 1, n);
  auto minimum = conversion::NewArray<vtkIntArray>(names::MinimumId, 1, n);
  auto maximum = conversion::NewArray<vtkIntArray>(names::MaximumId, 1, n);
  auto saddles = conversion::NewArray<vtkIntArray>(names::SaddleIds, 2, n);
  auto sides = conversion::NewArray<vtkIntArray>(names::BoundarySeparatrices, 4, n);
  auto pouch = conversion::NewArray<vtkCharArray>(names::IsPouch, 1, n);
  auto size = conversion::NewArray<vtkIdTypeArray>(names::NumberOfVertices, 1, n);
  auto stable = [&](Index cp) { return cp == topospline::InvalidIndex ? -1 : cps[cp].Id; };
  for (vtkIdType c = 0; c < n; ++c)
  {
    const auto& cell = complex.TwoCells[c];
    double xyz[3];
    embedding.To3D(cell.Centroid, xyz);
    points->SetPoint(c, xyz);
    verts->InsertNextCell(1, &c);
    id->SetValue(c, static_cast<int>(c));
    minimum->SetValue(c, stable(cell.Minimum));
    maximum->SetValue(c, stable(cell.Maximum));
    saddles->SetTypedComponent(c, 0, stable(cell.Saddles[0]));
    saddles->SetTypedComponent(c, 1, stable(cell.Saddles[1]));
    for (int k = 0; k < 4; ++k)
    {
      sides->SetTypedComponent(c, k, cell.BoundaryOneCells[k]);
    }
    pouch->SetValue(c, cell.Pouch ? 1 : 0);
    size->SetValue(c, cell.NumberOfVertices);
  }
  twoCells->SetPoints(points);
  twoCells->SetVerts(verts);
  conversion::AddArrays(twoCells->GetPointData(), { id, minimum, maximum, saddles, sides, pouch, size });
  return twoCells;
}

// Block 3: the input geometry with the per-vertex segmentation.
vtkSmartPointer<vtkDataSet> SegmentationBlock(const topospline::MorseSmaleComplex& complex, vtkDataSet* domain)
{
  const auto& cps = complex.CriticalPoints;
  vtkSmartPointer<vtkDataSet> segmentation = vtkSmartPointer<vtkDataSet>::Take(domain->NewInstance());
  segmentation->ShallowCopy(domain);
  const vtkIdType n = domain->GetNumberOfPoints();
  auto ascending = conversion::NewArray<vtkIntArray>(names::AscendingManifoldId, 1, n);
  auto descending = conversion::NewArray<vtkIntArray>(names::DescendingManifoldId, 1, n);
  auto cell = conversion::NewArray<vtkIntArray>(names::TwoCellId, 1, n);
  for (vtkIdType v = 0; v < n; ++v)
  {
    ascending->SetValue(v, cps[complex.AscendingManifold[v]].Id);
    descending->SetValue(v, cps[complex.DescendingManifold[v]].Id);
    cell->SetValue(v, complex.TwoCellId[v]);
  }
  segmentation->GetPointData()->AddArray(ascending);
  segmentation->GetPointData()->AddArray(descending);
  segmentation->GetPointData()->AddArray(cell);
  return segmentation;
}

} // namespace

void WriteComplex(const topospline::MorseSmaleComplex& complex, vtkDataSet* domain, const char* scalarName,
  vtkMultiBlockDataSet* output)
{
  const conversion::DomainPlane embedding = conversion::PlaneOf(domain);
  const auto critical = CriticalPointsBlock(complex, domain);
  const auto oneCells = OneCellsBlock(complex, embedding);
  const auto twoCells = TwoCellsBlock(complex, embedding);
  const auto segmentation = SegmentationBlock(complex, domain);

  output->SetNumberOfBlocks(names::NumberOfBlocks);
  const std::pair<vtkDataObject*, const char*> blocks[] = { { critical.Get(), names::CriticalPointsBlock },
    { oneCells.Get(), names::OneCellsBlock }, { twoCells.Get(), names::TwoCellsBlock },
    { segmentation.Get(), names::SegmentationBlock } };
  for (unsigned int b = 0; b < names::NumberOfBlocks; ++b)
  {
    output->SetBlock(b, blocks[b].first);
    output->GetMetaData(b)->Set(vtkCompositeDataSet::NAME(), blocks[b].second);
  }
  vtkNew<vtkStringArray> scalarField;
  scalarField->SetName(names::ScalarFieldName);
  scalarField->InsertNextValue(scalarName ? scalarName : "");
  output->GetFieldData()->AddArray(scalarField);
  if (!complex.BoundaryJunctions.empty())
  {
    auto junctions = conversion::NewArray<vtkIntArray>(names::BoundaryJunctionVertexId);
    for (Index v : complex.BoundaryJunctions)
    {
      junctions->InsertNextValue(v);
    }
    output->GetFieldData()->AddArray(junctions);
  }
  auto frame = conversion::NewArray<vtkDoubleArray>(names::WorkingFrameScale);
  frame->InsertNextValue(complex.Frame.Scale[0]);
  frame->InsertNextValue(complex.Frame.Scale[1]);
  output->GetFieldData()->AddArray(frame);
}

vtkDataSet* SegmentationOf(vtkMultiBlockDataSet* input)
{
  if (!input || input->GetNumberOfBlocks() < names::NumberOfBlocks)
  {
    return nullptr;
  }
  return vtkDataSet::SafeDownCast(input->GetBlock(names::SegmentationIndex));
}

namespace
{
// The arrays of blocks 0-3, all looked up before any is read (the first missing one is named).
struct ComplexArrays
{
  vtkPolyData* CriticalPoints = nullptr;
  vtkPolyData* OneCells = nullptr;
  vtkPolyData* TwoCells = nullptr;
  vtkDataSet* Segmentation = nullptr;
  vtkDataArray *Id, *Index, *Value, *Vertex, *Cell, *Boundary;       // critical points
  vtkDataArray* EdgeVertex = nullptr; // optional: complexes written before it existed
  vtkDataArray* CornerTriangle = nullptr; // optional, as EdgeVertex
  vtkDataArray *Source, *Destination, *Type, *Along, *MeshCell;       // 1-cells
  vtkDataArray *Ascending, *Descending, *TwoCellOfVertex;             // segmentation
  vtkDataArray *Minimum, *Maximum, *Saddles, *Sides, *Pouch, *Size;   // 2-cells

  bool Find(std::string& error)
  {
    auto* pd = this->CriticalPoints->GetPointData();
    this->Id = RequireArray(pd, names::CriticalPointId, error);
    this->Index = RequireArray(pd, names::CriticalIndex, error);
    this->Value = RequireArray(pd, names::CriticalValue, error);
    this->Vertex = RequireArray(pd, names::VertexId, error);
    this->Cell = RequireArray(pd, names::CriticalCellId, error);
    this->Boundary = RequireArray(pd, names::IsOnBoundary, error);
    this->EdgeVertex = pd->GetArray(names::SaddleEdgeVertexId);
    this->CornerTriangle = pd->GetArray(names::IsCornerTriangle);
    auto* cd = this->OneCells->GetCellData();
    this->Source = RequireArray(cd, names::SourceId, error);
    this->Destination = RequireArray(cd, names::DestinationId, error);
    this->Type = RequireArray(cd, names::SeparatrixType, error);
    this->Along = RequireArray(this->OneCells->GetPointData(), names::ScalarAlong, error);
    this->MeshCell = RequireArray(this->OneCells->GetPointData(), names::MeshCellId, error);
    auto* sd = this->Segmentation->GetPointData();
    this->Ascending = RequireArray(sd, names::AscendingManifoldId, error);
    this->Descending = RequireArray(sd, names::DescendingManifoldId, error);
    this->TwoCellOfVertex = RequireArray(sd, names::TwoCellId, error);
    auto* td = this->TwoCells->GetPointData();
    this->Minimum = RequireArray(td, names::MinimumId, error);
    this->Maximum = RequireArray(td, names::MaximumId, error);
    this->Saddles = RequireArray(td, names::SaddleIds, error);
    this->Sides = RequireArray(td, names::BoundarySeparatrices, error);
    this->Pouch = RequireArray(td, names::IsPouch, error);
    this->Size = RequireArray(td, names::NumberOfVertices, error);
    return error.empty();
  }
};

// Stable critical point ids (which survive simplification) to positions in the complex read.
class PositionOfId
{
public:
  bool Add(Index id, Index position)
  {
    if (id < 0)
    {
      return false;
    }
    if (static_cast<size_t>(id) >= this->Positions.size())
    {
      this->Positions.resize(id + 1, topospline::InvalidIndex);
    }
    this->Positions[id] = position;
    return true;
  }
  Index operator()(double stableId) const
  {
    const auto s = static_cast<long long>(stableId);
    return s >= 0 && s < static_cast<long long>(this->Positions.size()) ? this->Positions[s] : topospline::InvalidIndex;
  }

private:
  std::vector<Index> Positions;
};

bool ReadCriticalPoints(const ComplexArrays& in, topospline::MorseSmaleComplex& complex, PositionOfId& local,
  std::string& error)
{
  const vtkIdType nCP = in.CriticalPoints->GetNumberOfPoints();
  for (vtkIdType i = 0; i < nCP; ++i)
  {
    topospline::CriticalPoint cp;
    cp.Id = static_cast<Index>(in.Id->GetComponent(i, 0));
    cp.MorseIndex = static_cast<int>(in.Index->GetComponent(i, 0));
    cp.Value = in.Value->GetComponent(i, 0);
    cp.Vertex = static_cast<Index>(in.Vertex->GetComponent(i, 0));
    cp.Cell = static_cast<Index>(in.Cell->GetComponent(i, 0));
    cp.OnBoundary = in.Boundary->GetComponent(i, 0) != 0;
    cp.EdgeVertex = in.EdgeVertex ? static_cast<Index>(in.EdgeVertex->GetComponent(i, 0)) : topospline::InvalidIndex;
    cp.CornerTriangle = in.CornerTriangle && in.CornerTriangle->GetComponent(i, 0) != 0;
    if (!local.Add(cp.Id, static_cast<Index>(i)))
    {
      error = "the input is not a Morse-Smale complex: negative critical point id";
      return false;
    }
    complex.CriticalPoints.push_back(cp);
  }
  return true;
}

// visit(c, size, ids) for every cell c of `cells`, in parallel (vtkSMPTools), with the overload of
// GetCellAtId that is safe on several threads.
template <typename Visit>
void ForEachCellInParallel(vtkCellArray* cells, const Visit& visit)
{
  vtkSMPThreadLocalObject<vtkIdList> scratch;
  vtkSMPTools::For(0, cells->GetNumberOfCells(), [&](vtkIdType begin, vtkIdType end) {
    vtkIdList* copied = scratch.Local();
    for (vtkIdType c = begin; c < end; ++c)
    {
      vtkIdType size = 0;
      const vtkIdType* ids = nullptr;
      cells->GetCellAtId(c, size, ids, copied);
      visit(c, size, ids);
    }
  });
}

bool ReadOneCells(const ComplexArrays& in, const conversion::DomainPlane& embedding, const PositionOfId& local,
  topospline::MorseSmaleComplex& complex, std::string& error)
{
  // Every 1-cell on its own, in parallel (1000^2 noise: about a million 1-cells, 1.5 s on one
  // thread).
  vtkCellArray* lines = in.OneCells->GetLines();
  complex.OneCells.resize(static_cast<std::size_t>(lines->GetNumberOfCells()));
  std::atomic<bool> missingEnd(false);
  ForEachCellInParallel(lines, [&](vtkIdType a, vtkIdType size, const vtkIdType* ids) {
    topospline::OneCell& oneCell = complex.OneCells[a];
    oneCell.Type = in.Type->GetComponent(a, 0) == 0 ? topospline::OneCell::Descending : topospline::OneCell::Ascending;
    oneCell.Source = local(in.Source->GetComponent(a, 0));
    oneCell.Destination = local(in.Destination->GetComponent(a, 0));
    oneCell.Points.reserve(2 * size);
    oneCell.Values.reserve(size);
    oneCell.MeshCells.reserve(size);
    for (vtkIdType k = 0; k < size; ++k)
    {
      double xyz[3];
      in.OneCells->GetPoint(ids[k], xyz);
      oneCell.Points.push_back(xyz[embedding.U]);
      oneCell.Points.push_back(xyz[embedding.V]);
      oneCell.Values.push_back(in.Along->GetComponent(ids[k], 0));
      const auto c = static_cast<Index>(in.MeshCell->GetComponent(ids[k], 0));
      if (c >= 0)
      {
        oneCell.MeshCells.push_back(c);
      }
    }
    if (oneCell.Source == topospline::InvalidIndex || oneCell.Destination == topospline::InvalidIndex)
    {
      missingEnd = true;
    }
  });
  if (missingEnd)
  {
    error = "the input is not a Morse-Smale complex: a 1-cell refers to a missing critical point";
    return false;
  }
  return true;
}

void ReadTwoCells(const ComplexArrays& in, const conversion::DomainPlane& embedding, const PositionOfId& local,
  topospline::MorseSmaleComplex& complex)
{
  const vtkIdType nCells = in.TwoCells->GetNumberOfPoints();
  for (vtkIdType c = 0; c < nCells; ++c)
  {
    topospline::TwoCell twoCell;
    twoCell.Minimum = local(in.Minimum->GetComponent(c, 0));
    twoCell.Maximum = local(in.Maximum->GetComponent(c, 0));
    twoCell.Saddles = { local(in.Saddles->GetComponent(c, 0)), local(in.Saddles->GetComponent(c, 1)) };
    for (int k = 0; k < 4; ++k)
    {
      twoCell.BoundaryOneCells[k] = static_cast<Index>(in.Sides->GetComponent(c, k));
    }
    twoCell.Pouch = in.Pouch->GetComponent(c, 0) != 0;
    twoCell.NumberOfVertices = static_cast<Index>(in.Size->GetComponent(c, 0));
    double xyz[3];
    in.TwoCells->GetPoint(c, xyz);
    twoCell.Centroid[0] = xyz[embedding.U];
    twoCell.Centroid[1] = xyz[embedding.V];
    twoCell.Sectors = twoCell.Saddles[1] == topospline::InvalidIndex ? 1 : 2;
    complex.TwoCells.push_back(twoCell);
  }
}

bool ReadSegmentation(const ComplexArrays& in, vtkFieldData* fieldData, const PositionOfId& local,
  topospline::MorseSmaleComplex& complex, std::string& error)
{
  const vtkIdType nV = in.Segmentation->GetNumberOfPoints();
  complex.AscendingManifold.resize(nV);
  complex.DescendingManifold.resize(nV);
  complex.TwoCellId.resize(nV);
  for (vtkIdType v = 0; v < nV; ++v)
  {
    complex.AscendingManifold[v] = local(in.Ascending->GetComponent(v, 0));
    complex.DescendingManifold[v] = local(in.Descending->GetComponent(v, 0));
    complex.TwoCellId[v] = static_cast<Index>(in.TwoCellOfVertex->GetComponent(v, 0));
  }
  if (vtkDataArray* junctions = fieldData->GetArray(names::BoundaryJunctionVertexId))
  {
    for (vtkIdType j = 0; j < junctions->GetNumberOfTuples(); ++j)
    {
      const auto v = static_cast<Index>(junctions->GetComponent(j, 0));
      if (v < 0 || v >= nV)
      {
        error = "the input is not a Morse-Smale complex: a boundary junction names no vertex";
        return false;
      }
      complex.BoundaryJunctions.push_back(v);
    }
  }
  if (vtkDataArray* frame = fieldData->GetArray(names::WorkingFrameScale))
  {
    // Powers of two; anything else is not a frame stage 1 wrote.
    for (int axis = 0; axis < 2 && frame->GetNumberOfTuples() == 2; ++axis)
    {
      const double scale = frame->GetComponent(axis, 0);
      if (topospline::PlanarFrame::PowerOfTwoNear(scale) != scale)
      {
        error = "the input is not a Morse-Smale complex: its working frame's scales are not powers of two";
        return false;
      }
      complex.Frame.Scale[axis] = scale;
    }
  }
  return true;
}
} // namespace

bool ReadComplex(vtkMultiBlockDataSet* input, topospline::MorseSmaleComplex& complex, std::string& error)
{
  complex = topospline::MorseSmaleComplex();
  ComplexArrays in;
  in.CriticalPoints = input ? vtkPolyData::SafeDownCast(input->GetBlock(names::CriticalPointsIndex)) : nullptr;
  in.OneCells = input ? vtkPolyData::SafeDownCast(input->GetBlock(names::OneCellsIndex)) : nullptr;
  in.TwoCells = input ? vtkPolyData::SafeDownCast(input->GetBlock(names::TwoCellsIndex)) : nullptr;
  in.Segmentation = SegmentationOf(input);
  if (!in.CriticalPoints || !in.OneCells || !in.TwoCells || !in.Segmentation)
  {
    error = "the input is not a Morse-Smale complex (expected the output of the \"Morse-Smale Complex\" filter)";
    return false;
  }
  if (!in.Find(error))
  {
    error = "the input is not a Morse-Smale complex: " + error;
    return false;
  }
  const conversion::DomainPlane embedding = conversion::PlaneOf(in.Segmentation);
  PositionOfId local;
  if (!ReadCriticalPoints(in, complex, local, error) || !ReadOneCells(in, embedding, local, complex, error))
  {
    return false;
  }
  ReadTwoCells(in, embedding, local, complex);
  return ReadSegmentation(in, input->GetFieldData(), local, complex, error);
}

std::string ScalarFieldNameOf(vtkMultiBlockDataSet* input)
{
  auto* name = input ? vtkStringArray::SafeDownCast(input->GetFieldData()->GetAbstractArray(names::ScalarFieldName))
                     : nullptr;
  return name && name->GetNumberOfValues() > 0 ? name->GetValue(0) : std::string();
}

void PassBlocks(vtkMultiBlockDataSet* input, unsigned int count, vtkMultiBlockDataSet* output)
{
  for (unsigned int b = 0; b < input->GetNumberOfBlocks() && b < count; ++b)
  {
    output->SetBlock(b, input->GetBlock(b));
    output->GetMetaData(b)->Set(vtkCompositeDataSet::NAME(), input->GetMetaData(b)->Get(vtkCompositeDataSet::NAME()));
  }
  output->GetFieldData()->PassData(input->GetFieldData());
}

void WriteJunctionPoints(const topospline::MorseSmaleComplex& complex,
  const std::vector<topospline::JunctionPoint>& junctions, vtkMultiBlockDataSet* output)
{
  const auto& cps = complex.CriticalPoints;
  const auto plane = conversion::PlaneOf(SegmentationOf(output));
  vtkNew<vtkPolyData> block;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> verts;
  auto type = conversion::NewArray<vtkIntArray>(names::SeparatrixType);
  auto extremum = conversion::NewArray<vtkIntArray>(names::ExtremumId);
  auto cell = conversion::NewArray<vtkIntArray>(names::MeshCellId);
  auto value = conversion::NewArray<vtkDoubleArray>(names::JunctionValue);
  auto critical = conversion::NewArray<vtkIntArray>(names::CriticalPointId);
  auto count = conversion::NewArray<vtkIntArray>(names::NumberOfSeparatrices);
  for (const auto& junction : junctions)
  {
    double xyz[3];
    plane.To3D(junction.Position, xyz);
    const vtkIdType id = points->InsertNextPoint(xyz);
    verts->InsertNextCell(1, &id);
    type->InsertNextValue(junction.Type);
    extremum->InsertNextValue(cps[junction.Extremum].Id);
    cell->InsertNextValue(junction.Cell);
    value->InsertNextValue(junction.Value);
    critical->InsertNextValue(junction.CriticalPoint == topospline::InvalidIndex ? -1 : cps[junction.CriticalPoint].Id);
    count->InsertNextValue(static_cast<int>(junction.OneCells.size()));
  }
  block->SetPoints(points);
  block->SetVerts(verts);
  conversion::AddArrays(block->GetPointData(), { type, extremum, cell, value, critical, count });
  output->SetNumberOfBlocks(std::max<unsigned int>(output->GetNumberOfBlocks(), names::JunctionPointsIndex + 1));
  output->SetBlock(names::JunctionPointsIndex, block);
  output->GetMetaData(static_cast<unsigned int>(names::JunctionPointsIndex))
    ->Set(vtkCompositeDataSet::NAME(), names::JunctionPointsBlock);
}

namespace
{
vtkSmartPointer<vtkUnstructuredGrid> SmoothedOneCellsBlock(
  const topospline::OneCellSmoothingResult& smoothed, const conversion::DomainPlane& plane)
{
  auto bezier = vtkSmartPointer<vtkUnstructuredGrid>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  auto height = conversion::NewArray<vtkDoubleArray>(names::Height);
  auto piece = conversion::NewArray<vtkIntArray>(names::PieceId);
  auto segments = conversion::NewArray<vtkIntArray>(names::PieceSegments);
  auto type = conversion::NewArray<vtkIntArray>(names::SeparatrixType);
  vtkNew<vtkCellArray> cells;
  // Allocated at their final sizes: grown by doubling, these blocks (kept as long as the
  // pipeline) held up to twice what they need.
  vtkIdType segmentCount = 0;
  for (const auto& smoothedPiece : smoothed.Pieces)
  {
    segmentCount += smoothedPiece.Curve.Segments;
  }
  points->Allocate(4 * segmentCount);
  height->Allocate(4 * segmentCount);
  cells->AllocateExact(segmentCount, 4 * segmentCount);
  for (auto* array : { piece.GetPointer(), segments.GetPointer(), type.GetPointer() })
  {
    array->Allocate(segmentCount);
  }
  for (Index p = 0; p < static_cast<Index>(smoothed.Pieces.size()); ++p)
  {
    const auto& smoothedPiece = smoothed.Pieces[p];
    for (int s = 0; s < smoothedPiece.Curve.Segments; ++s)
    {
      const double* curve = smoothedPiece.Curve.Segment(s);
      const double* h = smoothedPiece.Height.Segment(s);
      vtkIdType ids[4];
      for (int m = 0; m < 4; ++m)
      {
        double xyz[3];
        plane.To3D(curve + 2 * CurvePointOfVtkPoint[m], xyz);
        ids[m] = points->InsertNextPoint(xyz);
        height->InsertNextValue(h[CurvePointOfVtkPoint[m]]);
      }
      cells->InsertNextCell(4, ids);
      piece->InsertNextValue(p);
      segments->InsertNextValue(smoothedPiece.Segments);
      type->InsertNextValue(smoothedPiece.Type);
    }
  }
  bezier->SetPoints(points);
  bezier->SetCells(VTK_BEZIER_CURVE, cells);
  bezier->GetPointData()->AddArray(height);
  bezier->GetPointData()->SetActiveScalars(names::Height);
  conversion::AddArrays(bezier->GetCellData(), { piece, segments, type });
  // Which pieces make up every 1-cell, in order from its source: stage 4 assembles the sides of
  // the 2-cells from them. 1-cell a is SeparatrixPieces[offsets[a] .. offsets[a+1]).
  auto offsets = conversion::NewArray<vtkIntArray>(names::SeparatrixPieceOffsets);
  auto list = conversion::NewArray<vtkIntArray>(names::SeparatrixPieces);
  offsets->InsertNextValue(0);
  for (const auto& pieces : smoothed.PiecesOfOneCell)
  {
    for (Index p : pieces)
    {
      list->InsertNextValue(p);
    }
    offsets->InsertNextValue(static_cast<int>(list->GetNumberOfTuples()));
  }
  conversion::AddArrays(bezier->GetFieldData(), { offsets, list });
  return bezier;
}

vtkSmartPointer<vtkPolyData> SampledOneCellsBlock(const topospline::MorseSmaleComplex& complex,
  const topospline::OneCellSmoothingResult& smoothed, int samplesPerSegment, const conversion::DomainPlane& plane)
{
  auto sampled = vtkSmartPointer<vtkPolyData>::New();
  if (samplesPerSegment <= 0)
  {
    return sampled;
  }
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  auto height = conversion::NewArray<vtkDoubleArray>(names::Height);
  auto id = conversion::NewArray<vtkIntArray>(names::SeparatrixId);
  auto source = conversion::NewArray<vtkIntArray>(names::SourceId);
  auto destination = conversion::NewArray<vtkIntArray>(names::DestinationId);
  auto type = conversion::NewArray<vtkIntArray>(names::SeparatrixType);
  std::vector<vtkIdType> ids;
  // Allocated at their final sizes: grown by doubling, this block (kept as long as the
  // pipeline) held up to twice what it needs.
  const vtkIdType pointCount = vtkTopoSplineWireFormat::SampledOneCellPoints(complex, smoothed, samplesPerSegment);
  const auto oneCellCount = static_cast<vtkIdType>(complex.OneCells.size());
  points->Allocate(pointCount);
  height->Allocate(pointCount);
  lines->AllocateExact(oneCellCount, pointCount);
  for (auto* array : { id.GetPointer(), source.GetPointer(), destination.GetPointer(), type.GetPointer() })
  {
    array->Allocate(oneCellCount);
  }
  for (Index a = 0; a < static_cast<Index>(complex.OneCells.size()); ++a)
  {
    ids.clear();
    for (Index p : smoothed.PiecesOfOneCell[a])
    {
      const auto& piece = smoothed.Pieces[p];
      const int count = piece.Curve.Segments * samplesPerSegment;
      for (int s = ids.empty() ? 0 : 1; s <= count; ++s)
      {
        const double t = static_cast<double>(s) / count;
        double uv[2], xyz[3];
        piece.Curve.Evaluate(t, uv);
        plane.To3D(uv, xyz);
        ids.push_back(points->InsertNextPoint(xyz));
        height->InsertNextValue(piece.Height.Value(t));
      }
    }
    const auto& oneCell = complex.OneCells[a];
    if (ids.empty())
    {
      // A 1-cell of one point (a saddle on its minimum's vertex, zero persistence).
      double xyz[3];
      plane.To3D(oneCell.Points.data(), xyz);
      ids.push_back(points->InsertNextPoint(xyz));
      height->InsertNextValue(oneCell.Values.front());
    }
    lines->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
    id->InsertNextValue(a);
    source->InsertNextValue(complex.CriticalPoints[oneCell.Source].Id);
    destination->InsertNextValue(complex.CriticalPoints[oneCell.Destination].Id);
    type->InsertNextValue(oneCell.Type);
  }
  sampled->SetPoints(points);
  sampled->SetLines(lines);
  sampled->GetPointData()->AddArray(height);
  sampled->GetPointData()->SetActiveScalars(names::Height);
  conversion::AddArrays(sampled->GetCellData(), { id, source, destination, type });
  return sampled;
}
} // namespace

void WriteSmoothedOneCells(const topospline::MorseSmaleComplex& complex,
  const topospline::OneCellSmoothingResult& smoothed, int samplesPerSegment, vtkMultiBlockDataSet* output)
{
  const auto plane = conversion::PlaneOf(SegmentationOf(output));
  output->SetNumberOfBlocks(std::max<unsigned int>(output->GetNumberOfBlocks(), names::SampledOneCellsIndex + 1));
  output->SetBlock(names::SmoothedOneCellsIndex, SmoothedOneCellsBlock(smoothed, plane));
  output->GetMetaData(static_cast<unsigned int>(names::SmoothedOneCellsIndex))
    ->Set(vtkCompositeDataSet::NAME(), names::SmoothedOneCellsBlock);
  output->SetBlock(names::SampledOneCellsIndex, SampledOneCellsBlock(complex, smoothed, samplesPerSegment, plane));
  output->GetMetaData(static_cast<unsigned int>(names::SampledOneCellsIndex))
    ->Set(vtkCompositeDataSet::NAME(), names::SampledOneCellsBlock);
}

vtkIdType SampledOneCellPoints(
  const topospline::MorseSmaleComplex& complex, const topospline::OneCellSmoothingResult& smoothed, int samplesPerSegment)
{
  vtkIdType points = 0;
  for (std::size_t a = 0; a < complex.OneCells.size() && a < smoothed.PiecesOfOneCell.size(); ++a)
  {
    vtkIdType segments = 0;
    for (Index p : smoothed.PiecesOfOneCell[a])
    {
      segments += smoothed.Pieces[p].Curve.Segments;
    }
    points += 1 + segments * samplesPerSegment;
  }
  return points;
}

bool ReadSmoothedOneCells(vtkMultiBlockDataSet* input, const topospline::MorseSmaleComplex& complex,
  topospline::OneCellSmoothingResult& smoothed, std::string& error)
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
  const vtkIdType oneCells = offsets->GetNumberOfTuples() - 1;
  if (oneCells != static_cast<vtkIdType>(complex.OneCells.size()))
  {
    error = "the smoothed 1-cells do not match the complex";
    return false;
  }
  // Each Bezier cell's piece and its place in it (its piece's cells come in the order of the
  // block); then the cells in parallel, each to its own place (1000^2 noise: 3.2 million cells).
  const vtkIdType cells = block->GetNumberOfCells();
  std::vector<Index> pieceOf(static_cast<std::size_t>(cells));
  Index pieces = 0;
  for (vtkIdType c = 0; c < cells; ++c)
  {
    pieceOf[c] = static_cast<Index>(piece->GetComponent(c, 0));
    if (pieceOf[c] < 0 || block->GetCellType(c) != VTK_BEZIER_CURVE || block->GetCellSize(c) != 4)
    {
      error = "the smoothed 1-cells are not cubic Bezier curves";
      return false;
    }
    pieces = std::max(pieces, pieceOf[c] + 1);
  }
  smoothed = topospline::OneCellSmoothingResult();
  smoothed.Pieces.resize(pieces);
  std::vector<int> slotOf(static_cast<std::size_t>(cells));
  for (vtkIdType c = 0; c < cells; ++c)
  {
    slotOf[c] = smoothed.Pieces[pieceOf[c]].Curve.Segments++;
  }
  for (auto& p : smoothed.Pieces)
  {
    p.Curve.Dimension = 2;
    p.Height.Dimension = 1;
    p.Height.Segments = p.Curve.Segments;
    p.Curve.ControlPoints.resize(8 * static_cast<std::size_t>(p.Curve.Segments));
    p.Height.ControlPoints.resize(4 * static_cast<std::size_t>(p.Height.Segments));
  }
  const auto plane = conversion::PlaneOf(SegmentationOf(input));
  ForEachCellInParallel(block->GetCells(), [&](vtkIdType c, vtkIdType, const vtkIdType* ids) {
    auto& smoothedPiece = smoothed.Pieces[pieceOf[c]];
    double* uv = smoothedPiece.Curve.ControlPoints.data() + 8 * static_cast<std::size_t>(slotOf[c]);
    double* h = smoothedPiece.Height.ControlPoints.data() + 4 * static_cast<std::size_t>(slotOf[c]);
    for (int m = 0; m < 4; ++m)
    {
      double xyz[3];
      block->GetPoint(ids[m], xyz);
      plane.ToPlanar(xyz, uv + 2 * CurvePointOfVtkPoint[m]);
      h[CurvePointOfVtkPoint[m]] = height->GetComponent(ids[m], 0);
    }
  });
  smoothed.PiecesOfOneCell.resize(oneCells);
  for (vtkIdType a = 0; a < oneCells; ++a)
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
      smoothed.PiecesOfOneCell[a].push_back(p);
      // The same relation from the pieces' side, as stage 3 fills it (stage 4 once looked for
      // a piece's cells through it and found it empty).
      smoothed.Pieces[p].OneCells.push_back(static_cast<Index>(a));
    }
  }
  return true;
}
} // namespace vtkTopoSplineWireFormat
