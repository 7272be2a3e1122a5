#include "vtkTopoSplineSyntheticSourceSupport.h"

#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkStreamingDemandDrivenPipeline.h>

#include <algorithm>

namespace vtkTopoSplineSyntheticSourceSupport
{
void PublishGridInformation(vtkInformation* outInfo, int resolution, double origin)
{
  int extent[6] = { 0, resolution - 1, 0, resolution - 1, 0, 0 };
  double originXYZ[3] = { origin, origin, 0 };
  double spacing[3] = { 1, 1, 1 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::ORIGIN(), originXYZ, 3);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_DOUBLE, 1);
}

void FillImage(vtkDataObject* output, vtkInformation* outInfo, const topospline::GridField& grid, const char* name)
{
  vtkImageData* image = vtkImageData::SafeDownCast(output);
  // The whole grid is always produced: the complex is a global structure.
  image->SetExtent(outInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()));
  image->SetOrigin(grid.Origin[0], grid.Origin[1], 0);
  image->SetSpacing(grid.Spacing[0], grid.Spacing[1], 1);
  vtkNew<vtkDoubleArray> values;
  values->SetName(name);
  values->SetNumberOfTuples(static_cast<vtkIdType>(grid.Values.size()));
  std::copy(grid.Values.begin(), grid.Values.end(), values->GetPointer(0));
  image->GetPointData()->SetScalars(values);
}
}
