// What the two synthetic sources share: publishing a grid's extent and filling the image.
#pragma once

#include "SyntheticFields.h" // core

class vtkDataObject;
class vtkInformation;

namespace vtkTopoSplineSyntheticSourceSupport
{
void PublishGridInformation(vtkInformation* outInfo, int resolution, double origin);
void FillImage(vtkDataObject* output, vtkInformation* outInfo, const topospline::GridField& grid, const char* name);
}
