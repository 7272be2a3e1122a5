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

#if defined(__GLIBC__)
#include <malloc.h> // malloc_trim
#endif

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

// The points of a 2D image, placed by its origin, spacing and extent, as a grid field.
bool ImageToField(vtkImageData* image, topospline::PlanarScalarField& field, std::string& error)
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
  field.GridSpacing[0] = spacing[axes[0]];
  field.GridSpacing[1] = spacing[axes[1]];
  return true;
}

// The points and triangles of a planar triangle mesh.
bool MeshToField(vtkDataSet* input, topospline::PlanarScalarField& field, std::string& error)
{
  const vtkIdType nPoints = input->GetNumberOfPoints();
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

} // namespace

namespace vtkTopoSplineDomainConversion
{
void ReleaseFreedMemory()
{
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

ReleaseFreedMemoryOnReturn::~ReleaseFreedMemoryOnReturn()
{
  ReleaseFreedMemory();
}

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
    return ImageToField(image, field, error);
  }
  return MeshToField(input, field, error);
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

void AddArrays(vtkFieldData* data, std::initializer_list<vtkAbstractArray*> arrays)
{
  for (vtkAbstractArray* array : arrays)
  {
    data->AddArray(array);
  }
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
