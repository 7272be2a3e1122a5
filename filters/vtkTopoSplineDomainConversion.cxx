#include "vtkTopoSplineDomainConversion.h"

#include "vtkTopoSplineArrayNames.h"

#include "SyntheticFields.h" // core: GridTriangles

#include <vtkAlgorithm.h>
#include <vtkArrayDispatch.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCharArray.h>
#include <vtkDataArrayRange.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkIdTypeArray.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkInformation.h>
#include <vtkIntArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSMPTools.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>

#include <algorithm>
#include <cmath>

namespace names = vtkTopoSplineArrayNames;
using topospline::Index;

namespace
{
bool DetectEmbedding(vtkDataSet* data, vtkTopoSplineDomainConversion::DomainPlane& embedding)
{
  double bounds[6];
  data->GetBounds(bounds);
  for (int w = 2; w >= 0; --w)
  {
    if (bounds[2 * w + 1] - bounds[2 * w] == 0.0)
    {
      embedding.W = w;
      embedding.U = w == 0 ? 1 : 0;
      embedding.V = w == 2 ? 1 : 2;
      embedding.WValue = bounds[2 * w];
      return true;
    }
  }
  return false;
}

} // namespace

// The image rule is the axes choice ToPlanarScalarField makes (the two axes with several points).
vtkTopoSplineDomainConversion::DomainPlane vtkTopoSplineDomainConversion::PlaneOf(vtkDataSet* domain)
{
  DomainPlane embedding;
  if (auto* image = vtkImageData::SafeDownCast(domain))
  {
    int dims[3], extent[6];
    image->GetDimensions(dims);
    image->GetExtent(extent);
    double origin[3], spacing[3];
    image->GetOrigin(origin);
    image->GetSpacing(spacing);
    for (int w = 2; w >= 0; --w)
    {
      if (dims[w] == 1)
      {
        embedding.W = w;
        embedding.U = w == 0 ? 1 : 0;
        embedding.V = w == 2 ? 1 : 2;
        // the layer's coordinate: the extent need not start at 0
        embedding.WValue = origin[w] + extent[2 * w] * spacing[w];
        break;
      }
    }
  }
  else
  {
    DetectEmbedding(domain, embedding);
  }
  return embedding;
}

namespace
{
struct CopyToDouble
{
  template <typename ArrayT>
  void operator()(ArrayT* array, std::vector<double>& out) const
  {
    const auto values = vtk::DataArrayValueRange<1>(array);
    std::copy(values.begin(), values.end(), out.begin());
  }
};

// Adds the arrays (smart pointers or raw) to `data` in the given order.
void AddArrays(vtkFieldData* data, std::initializer_list<vtkAbstractArray*> arrays)
{
  for (vtkAbstractArray* array : arrays)
  {
    data->AddArray(array);
  }
}

vtkDataArray* RequireArray(vtkFieldData* data, const char* name, std::string& error)
{
  vtkDataArray* array = data ? data->GetArray(name) : nullptr;
  if (!array && error.empty())
  {
    error = std::string("array \"") + name + "\" is missing";
  }
  return array;
}
} // namespace

namespace vtkTopoSplineDomainConversion
{
topospline::ParallelFor SMPParallelFor()
{
  return [](Index begin, Index end, const topospline::RangeBody& body) {
    vtkSMPTools::For(begin, end, [&](vtkIdType b, vtkIdType e) { body(static_cast<Index>(b), static_cast<Index>(e)); });
  };
}

vtkDataArray* SelectedPointScalars(vtkDataArray* chosen, vtkInformation* info, vtkDataSet* input, std::string& note)
{
  if (chosen)
  {
    return chosen;
  }
  const char* name = info && info->Has(vtkDataObject::FIELD_NAME()) ? info->Get(vtkDataObject::FIELD_NAME()) : nullptr;
  vtkPointData* pd = input->GetPointData();
  vtkDataArray* fallback = nullptr;
  if (pd->GetScalars() && pd->GetScalars()->GetNumberOfComponents() == 1)
  {
    fallback = pd->GetScalars();
  }
  for (int i = 0; !fallback && i < pd->GetNumberOfArrays(); ++i)
  {
    vtkDataArray* array = pd->GetArray(i);
    if (array && array->GetNumberOfComponents() == 1)
    {
      fallback = array;
    }
  }
  if (fallback && name && name[0] != '\0')
  {
    // ParaView may hand a filter created on a never-updated source a stale array name.
    note = std::string("point array \"") + name + "\" not found; using \"" +
      (fallback->GetName() ? fallback->GetName() : "") + "\"";
  }
  return fallback;
}

bool ToPlanarScalarField(vtkDataSet* input, vtkDataArray* scalars, topospline::PlanarScalarField& field,
  std::string& error)
{
  field = topospline::PlanarScalarField();
  const vtkIdType nPoints = input->GetNumberOfPoints();
  if (nPoints == 0)
  {
    error = "the input is empty";
    return false;
  }
  if (!scalars)
  {
    error = "no point scalar array selected (the input has no point data array to process)";
    return false;
  }
  if (scalars->GetNumberOfComponents() != 1)
  {
    error = std::string("the scalar array \"") + (scalars->GetName() ? scalars->GetName() : "") + "\" has " +
      std::to_string(scalars->GetNumberOfComponents()) + " components; select a 1-component point array";
    return false;
  }
  if (scalars->GetNumberOfTuples() != nPoints)
  {
    error = "the scalar array must be point data (one value per point)";
    return false;
  }
  if (nPoints >= std::numeric_limits<Index>::max() / 4)
  {
    error = "the input has too many points (" + std::to_string(nPoints) + ")";
    return false;
  }

  field.Values.resize(nPoints);
  if (!vtkArrayDispatch::DispatchByValueType<vtkArrayDispatch::Reals>::Execute(scalars, CopyToDouble{}, field.Values))
  {
    CopyToDouble{}(scalars, field.Values);
  }

  field.Points.resize(2 * nPoints);
  if (auto* image = vtkImageData::SafeDownCast(input))
  {
    int dims[3];
    image->GetDimensions(dims);
    int axes[2], nAxes = 0;
    for (int a = 0; a < 3; ++a)
    {
      if (dims[a] > 1)
      {
        if (nAxes == 2)
        {
          error = "the image is 3D (" + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
            std::to_string(dims[2]) + "); TopoSpline works on 2D images (one layer): extract a slice first";
          return false;
        }
        axes[nAxes++] = a;
      }
    }
    if (nAxes < 2)
    {
      error = "the image has fewer than two dimensions with more than one point";
      return false;
    }
    const int n0 = dims[axes[0]], n1 = dims[axes[1]];
    double origin[3], spacing[3];
    int extent[6];
    image->GetOrigin(origin);
    image->GetSpacing(spacing);
    image->GetExtent(extent);
    if (!image->GetDirectionMatrix()->IsIdentity())
    {
      // A rotated image is not in the coordinate plane the outputs are written in.
      error = "the image's direction matrix is not the identity; TopoSpline needs an axis-aligned image "
              "(resample it, e.g. with Resample To Image, or clear its direction)";
      return false;
    }
    for (const int a : axes)
    {
      if (!std::isfinite(origin[a]) || !std::isfinite(spacing[a]) || !(spacing[a] > 0))
      {
        error = "the image's spacing (" + std::to_string(spacing[a]) + ") or origin (" + std::to_string(origin[a]) +
          ") along axis " + std::to_string(a) + " is not a finite positive spacing and finite origin";
        return false;
      }
      // Coordinates are subtracted all along the pipeline: with an origin 1e12 spacings away,
      // differences of neighbouring points keep fewer than 4 significant digits.
      const double farthest = std::max(std::abs(origin[a] + extent[2 * a] * spacing[a]),
        std::abs(origin[a] + extent[2 * a + 1] * spacing[a]));
      if (farthest > 1e12 * spacing[a])
      {
        error = "the image's coordinates along axis " + std::to_string(a) + " reach " + std::to_string(farthest) +
          ", more than 1e12 spacings (" + std::to_string(spacing[a]) +
          ") from 0: neighbouring points cannot be told apart precisely; shift the origin";
        return false;
      }
    }
    const double ratio = spacing[axes[0]] / spacing[axes[1]];
    if (ratio > 1e4 || ratio < 1e-4)
    {
      error = "the image's spacings differ by a factor above 1e4 (" + std::to_string(spacing[axes[0]]) + " and " +
        std::to_string(spacing[axes[1]]) + "); the reconstruction's geometry cannot be resolved; rescale one axis";
      return false;
    }
    vtkSMPTools::For(0, n1, [&](vtkIdType begin, vtkIdType end) {
      for (vtkIdType b = begin; b < end; ++b)
      {
        for (vtkIdType a = 0; a < n0; ++a)
        {
          const vtkIdType id = b * n0 + a;
          // the extent need not start at 0
          field.Points[2 * id] = origin[axes[0]] + (extent[2 * axes[0]] + a) * spacing[axes[0]];
          field.Points[2 * id + 1] = origin[axes[1]] + (extent[2 * axes[1]] + b) * spacing[axes[1]];
        }
      }
    });
    // The quads are split along their (i+1,j)-(i,j+1) diagonal: GridTriangles(n0, n1).
    field.GridDimensions[0] = n0;
    field.GridDimensions[1] = n1;
    return true;
  }

  vtkTopoSplineDomainConversion::DomainPlane embedding;
  if (!DetectEmbedding(input, embedding))
  {
    error = "the points do not lie in a coordinate plane (x, y or z constant); TopoSpline needs a planar "
            "triangulation (use the mesh before any Warp By Scalar)";
    return false;
  }
  for (vtkIdType id = 0; id < nPoints; ++id)
  {
    double p[3];
    input->GetPoint(id, p);
    field.Points[2 * id] = p[embedding.U];
    field.Points[2 * id + 1] = p[embedding.V];
  }
  const vtkIdType nCells = input->GetNumberOfCells();
  if (nCells == 0)
  {
    error = "the input has no cells; TopoSpline needs a triangulation";
    return false;
  }
  field.Triangles.resize(3 * nCells);
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < nCells; ++c)
  {
    const int type = input->GetCellType(c);
    if (type != VTK_TRIANGLE)
    {
      error = "cell " + std::to_string(c) + " is not a triangle (VTK cell type " + std::to_string(type) +
        "); apply the Triangulate filter first";
      return false;
    }
    input->GetCellPoints(c, ids);
    for (int k = 0; k < 3; ++k)
    {
      field.Triangles[3 * c + k] = static_cast<Index>(ids->GetId(k));
    }
  }
  return true;
}

void PlanarBounds(vtkDataSet* domain, double bounds[4])
{
  const vtkTopoSplineDomainConversion::DomainPlane embedding = PlaneOf(domain);
  double b[6];
  domain->GetBounds(b);
  bounds[0] = b[2 * embedding.U];
  bounds[1] = b[2 * embedding.U + 1];
  bounds[2] = b[2 * embedding.V];
  bounds[3] = b[2 * embedding.V + 1];
}

void ToMultiBlock(const topospline::MorseSmaleComplex& complex, vtkDataSet* domain, const char* scalarName,
  vtkMultiBlockDataSet* output)
{
  const vtkTopoSplineDomainConversion::DomainPlane embedding = PlaneOf(domain);
  const auto& cps = complex.CriticalPoints;

  // Critical points.
  vtkNew<vtkPolyData> critical;
  {
    const vtkIdType n = static_cast<vtkIdType>(cps.size());
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(n);
    vtkNew<vtkCellArray> verts;
    auto id = NewArray<vtkIntArray>(names::CriticalPointId, 1, n);
    auto index = NewArray<vtkIntArray>(names::CriticalIndex, 1, n);
    auto value = NewArray<vtkDoubleArray>(names::CriticalValue, 1, n);
    auto vertex = NewArray<vtkIdTypeArray>(names::VertexId, 1, n);
    auto cell = NewArray<vtkIdTypeArray>("CriticalCellId", 1, n);
    auto boundary = NewArray<vtkCharArray>(names::IsOnBoundary, 1, n);
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
    }
    critical->SetPoints(points);
    critical->SetVerts(verts);
    AddArrays(critical->GetPointData(), { id, index, value, vertex, cell, boundary });
    critical->GetPointData()->SetActiveScalars(names::CriticalIndex);
  }

  // 1-cells as polylines.
  vtkNew<vtkPolyData> oneCells;
  {
    vtkIdType nPoints = 0;
    for (const auto& arc : complex.OneCells)
    {
      nPoints += static_cast<vtkIdType>(arc.Values.size());
    }
    const vtkIdType n = static_cast<vtkIdType>(complex.OneCells.size());
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(nPoints);
    vtkNew<vtkCellArray> lines;
    auto along = NewArray<vtkDoubleArray>(names::ScalarAlong, 1, nPoints);
    auto meshCell = NewArray<vtkIdTypeArray>(names::MeshCellId, 1, nPoints);
    auto id = NewArray<vtkIntArray>(names::SeparatrixId, 1, n);
    auto source = NewArray<vtkIntArray>(names::SourceId, 1, n);
    auto destination = NewArray<vtkIntArray>(names::DestinationId, 1, n);
    auto type = NewArray<vtkIntArray>(names::SeparatrixType, 1, n);
    vtkIdType next = 0;
    std::vector<vtkIdType> ids;
    for (vtkIdType a = 0; a < n; ++a)
    {
      const auto& arc = complex.OneCells[a];
      const vtkIdType count = static_cast<vtkIdType>(arc.Values.size());
      // Ascending arcs carry one more point at each end than mesh cells (saddle, maximum).
      const vtkIdType offset = arc.Type == topospline::OneCell::Ascending ? 1 : 0;
      ids.resize(count);
      for (vtkIdType p = 0; p < count; ++p)
      {
        double xyz[3];
        embedding.To3D(&arc.Points[2 * p], xyz);
        points->SetPoint(next, xyz);
        along->SetValue(next, arc.Values[p]);
        const vtkIdType c = p - offset;
        meshCell->SetValue(next, c >= 0 && c < static_cast<vtkIdType>(arc.MeshCells.size()) ? arc.MeshCells[c] : -1);
        ids[p] = next++;
      }
      lines->InsertNextCell(count, ids.data());
      id->SetValue(a, static_cast<int>(a));
      source->SetValue(a, cps[arc.Source].Id);
      destination->SetValue(a, cps[arc.Destination].Id);
      type->SetValue(a, arc.Type);
    }
    oneCells->SetPoints(points);
    oneCells->SetLines(lines);
    oneCells->GetPointData()->AddArray(along);
    oneCells->GetPointData()->AddArray(meshCell);
    oneCells->GetPointData()->SetActiveScalars(names::ScalarAlong);
    AddArrays(oneCells->GetCellData(), { id, source, destination, type });
  }

  // 2-cells: one point per cell at its centroid, carrying its corners and sides.
  vtkNew<vtkPolyData> twoCells;
  {
    const vtkIdType n = static_cast<vtkIdType>(complex.TwoCells.size());
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(n);
    vtkNew<vtkCellArray> verts;
    auto id = NewArray<vtkIntArray>(names::TwoCellId, 1, n);
    auto minimum = NewArray<vtkIntArray>(names::MinimumId, 1, n);
    auto maximum = NewArray<vtkIntArray>(names::MaximumId, 1, n);
    auto saddles = NewArray<vtkIntArray>(names::SaddleIds, 2, n);
    auto arcs = NewArray<vtkIntArray>(names::BoundarySeparatrices, 4, n);
    auto pouch = NewArray<vtkCharArray>(names::IsPouch, 1, n);
    auto size = NewArray<vtkIdTypeArray>(names::NumberOfVertices, 1, n);
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
        arcs->SetTypedComponent(c, k, cell.BoundaryOneCells[k]);
      }
      pouch->SetValue(c, cell.Pouch ? 1 : 0);
      size->SetValue(c, cell.NumberOfVertices);
    }
    twoCells->SetPoints(points);
    twoCells->SetVerts(verts);
    AddArrays(twoCells->GetPointData(), { id, minimum, maximum, saddles, arcs, pouch, size });
  }

  // The input geometry with the per-vertex segmentation.
  vtkSmartPointer<vtkDataSet> segmentation = vtkSmartPointer<vtkDataSet>::Take(domain->NewInstance());
  segmentation->ShallowCopy(domain);
  {
    const vtkIdType n = domain->GetNumberOfPoints();
    auto ascending = NewArray<vtkIntArray>(names::AscendingManifoldId, 1, n);
    auto descending = NewArray<vtkIntArray>(names::DescendingManifoldId, 1, n);
    auto cell = NewArray<vtkIntArray>(names::TwoCellId, 1, n);
    for (vtkIdType v = 0; v < n; ++v)
    {
      ascending->SetValue(v, cps[complex.AscendingManifold[v]].Id);
      descending->SetValue(v, cps[complex.DescendingManifold[v]].Id);
      cell->SetValue(v, complex.TwoCellId[v]);
    }
    segmentation->GetPointData()->AddArray(ascending);
    segmentation->GetPointData()->AddArray(descending);
    segmentation->GetPointData()->AddArray(cell);
  }

  output->SetNumberOfBlocks(names::NumberOfBlocks);
  const std::pair<vtkDataObject*, const char*> blocks[] = { { critical, names::CriticalPointsBlock },
    { oneCells, names::OneCellsBlock }, { twoCells, names::TwoCellsBlock },
    { segmentation, names::SegmentationBlock } };
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
    auto junctions = NewArray<vtkIntArray>(names::BoundaryJunctionVertexId);
    for (Index v : complex.BoundaryJunctions)
    {
      junctions->InsertNextValue(v);
    }
    output->GetFieldData()->AddArray(junctions);
  }
}

vtkDataSet* SegmentationOf(vtkMultiBlockDataSet* input)
{
  if (!input || input->GetNumberOfBlocks() < names::NumberOfBlocks)
  {
    return nullptr;
  }
  return vtkDataSet::SafeDownCast(input->GetBlock(names::SegmentationIndex));
}

bool FromMultiBlock(vtkMultiBlockDataSet* input, topospline::MorseSmaleComplex& complex, std::string& error)
{
  complex = topospline::MorseSmaleComplex();
  auto* critical = input ? vtkPolyData::SafeDownCast(input->GetBlock(names::CriticalPointsIndex)) : nullptr;
  auto* oneCells = input ? vtkPolyData::SafeDownCast(input->GetBlock(names::OneCellsIndex)) : nullptr;
  auto* twoCells = input ? vtkPolyData::SafeDownCast(input->GetBlock(names::TwoCellsIndex)) : nullptr;
  vtkDataSet* segmentation = SegmentationOf(input);
  if (!critical || !oneCells || !twoCells || !segmentation)
  {
    error = "the input is not a Morse-Smale complex (expected the output of the \"Morse-Smale Complex\" filter)";
    return false;
  }
  const vtkTopoSplineDomainConversion::DomainPlane embedding = PlaneOf(segmentation);

  auto* pd = critical->GetPointData();
  vtkDataArray* id = RequireArray(pd, names::CriticalPointId, error);
  vtkDataArray* index = RequireArray(pd, names::CriticalIndex, error);
  vtkDataArray* value = RequireArray(pd, names::CriticalValue, error);
  vtkDataArray* vertex = RequireArray(pd, names::VertexId, error);
  vtkDataArray* cell = RequireArray(pd, "CriticalCellId", error);
  vtkDataArray* boundary = RequireArray(pd, names::IsOnBoundary, error);
  auto* cd = oneCells->GetCellData();
  vtkDataArray* source = RequireArray(cd, names::SourceId, error);
  vtkDataArray* destination = RequireArray(cd, names::DestinationId, error);
  vtkDataArray* type = RequireArray(cd, names::SeparatrixType, error);
  vtkDataArray* along = RequireArray(oneCells->GetPointData(), names::ScalarAlong, error);
  vtkDataArray* meshCell = RequireArray(oneCells->GetPointData(), names::MeshCellId, error);
  auto* sd = segmentation->GetPointData();
  vtkDataArray* ascending = RequireArray(sd, names::AscendingManifoldId, error);
  vtkDataArray* descending = RequireArray(sd, names::DescendingManifoldId, error);
  vtkDataArray* cellId = RequireArray(sd, names::TwoCellId, error);
  auto* td = twoCells->GetPointData();
  vtkDataArray* minimum = RequireArray(td, names::MinimumId, error);
  vtkDataArray* maximum = RequireArray(td, names::MaximumId, error);
  vtkDataArray* saddles = RequireArray(td, names::SaddleIds, error);
  vtkDataArray* arcs = RequireArray(td, names::BoundarySeparatrices, error);
  vtkDataArray* pouch = RequireArray(td, names::IsPouch, error);
  vtkDataArray* size = RequireArray(td, names::NumberOfVertices, error);
  if (!error.empty())
  {
    error = "the input is not a Morse-Smale complex: " + error;
    return false;
  }

  // Stable id -> position in this complex.
  std::vector<Index> position;
  const vtkIdType nCP = critical->GetNumberOfPoints();
  for (vtkIdType i = 0; i < nCP; ++i)
  {
    topospline::CriticalPoint cp;
    cp.Id = static_cast<Index>(id->GetComponent(i, 0));
    cp.MorseIndex = static_cast<int>(index->GetComponent(i, 0));
    cp.Value = value->GetComponent(i, 0);
    cp.Vertex = static_cast<Index>(vertex->GetComponent(i, 0));
    cp.Cell = static_cast<Index>(cell->GetComponent(i, 0));
    cp.OnBoundary = boundary->GetComponent(i, 0) != 0;
    if (cp.Id < 0)
    {
      error = "the input is not a Morse-Smale complex: negative critical point id";
      return false;
    }
    if (static_cast<size_t>(cp.Id) >= position.size())
    {
      position.resize(cp.Id + 1, topospline::InvalidIndex);
    }
    position[cp.Id] = static_cast<Index>(i);
    complex.CriticalPoints.push_back(cp);
  }
  auto local = [&](double stableId) {
    const auto s = static_cast<long long>(stableId);
    return s >= 0 && s < static_cast<long long>(position.size()) ? position[s] : topospline::InvalidIndex;
  };

  vtkCellArray* lines = oneCells->GetLines();
  vtkNew<vtkIdList> ids;
  lines->InitTraversal();
  for (vtkIdType a = 0; lines->GetNextCell(ids); ++a)
  {
    topospline::OneCell arc;
    arc.Type = type->GetComponent(a, 0) == 0 ? topospline::OneCell::Descending : topospline::OneCell::Ascending;
    arc.Source = local(source->GetComponent(a, 0));
    arc.Destination = local(destination->GetComponent(a, 0));
    for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k)
    {
      double xyz[3];
      oneCells->GetPoint(ids->GetId(k), xyz);
      arc.Points.push_back(xyz[embedding.U]);
      arc.Points.push_back(xyz[embedding.V]);
      arc.Values.push_back(along->GetComponent(ids->GetId(k), 0));
      const auto c = static_cast<Index>(meshCell->GetComponent(ids->GetId(k), 0));
      if (c >= 0)
      {
        arc.MeshCells.push_back(c);
      }
    }
    if (arc.Source == topospline::InvalidIndex || arc.Destination == topospline::InvalidIndex)
    {
      error = "the input is not a Morse-Smale complex: a 1-cell refers to a missing critical point";
      return false;
    }
    complex.OneCells.push_back(std::move(arc));
  }

  const vtkIdType nCells = twoCells->GetNumberOfPoints();
  for (vtkIdType c = 0; c < nCells; ++c)
  {
    topospline::TwoCell twoCell;
    twoCell.Minimum = local(minimum->GetComponent(c, 0));
    twoCell.Maximum = local(maximum->GetComponent(c, 0));
    twoCell.Saddles = { local(saddles->GetComponent(c, 0)), local(saddles->GetComponent(c, 1)) };
    for (int k = 0; k < 4; ++k)
    {
      twoCell.BoundaryOneCells[k] = static_cast<Index>(arcs->GetComponent(c, k));
    }
    twoCell.Pouch = pouch->GetComponent(c, 0) != 0;
    twoCell.NumberOfVertices = static_cast<Index>(size->GetComponent(c, 0));
    double xyz[3];
    twoCells->GetPoint(c, xyz);
    twoCell.Centroid[0] = xyz[embedding.U];
    twoCell.Centroid[1] = xyz[embedding.V];
    twoCell.Sectors = twoCell.Saddles[1] == topospline::InvalidIndex ? 1 : 2;
    complex.TwoCells.push_back(twoCell);
  }

  const vtkIdType nV = segmentation->GetNumberOfPoints();
  complex.AscendingManifold.resize(nV);
  complex.DescendingManifold.resize(nV);
  complex.TwoCellId.resize(nV);
  for (vtkIdType v = 0; v < nV; ++v)
  {
    complex.AscendingManifold[v] = local(ascending->GetComponent(v, 0));
    complex.DescendingManifold[v] = local(descending->GetComponent(v, 0));
    complex.TwoCellId[v] = static_cast<Index>(cellId->GetComponent(v, 0));
  }
  if (vtkDataArray* junctions = input->GetFieldData()->GetArray(names::BoundaryJunctionVertexId))
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
  return true;
}

void AcceptPlanarDomains(vtkInformation* info)
{
  info->Remove(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE());
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkUnstructuredGrid");
}

void RequestWholeInput(vtkInformation* inInfo)
{
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
  if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
  {
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
      inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
  }
}

void AddFieldNumbers(vtkFieldData* fieldData, const char* name, std::initializer_list<double> values)
{
  auto array = NewArray<vtkDoubleArray>(name);
  for (double v : values)
  {
    array->InsertNextValue(v);
  }
  fieldData->AddArray(array);
}
}
