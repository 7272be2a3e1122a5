#include "vtkTopoSplineTrigonometricSource.h"

#include "vtkTopoSplineArrayNames.h"
#include "vtkTopoSplineSyntheticSourceSupport.h"

#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkTopoSplineTrigonometricSource);

vtkTopoSplineTrigonometricSource::vtkTopoSplineTrigonometricSource()
{
  this->SetNumberOfInputPorts(0);
}

int vtkTopoSplineTrigonometricSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkTopoSplineSyntheticSourceSupport::PublishGridInformation(
    outputVector->GetInformationObject(0), this->Resolution, this->Origin);
  return 1;
}

void vtkTopoSplineTrigonometricSource::ExecuteDataWithInformation(vtkDataObject* output, vtkInformation* outInfo)
{
  const auto grid = topospline::TrigonometricField(this->Amplitude, this->Resolution, this->Origin);
  vtkTopoSplineSyntheticSourceSupport::FillImage(output, outInfo, grid, vtkTopoSplineArrayNames::TrigonometricField);
}

void vtkTopoSplineTrigonometricSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Amplitude: " << this->Amplitude << "\n"
     << indent << "Resolution: " << this->Resolution << "\n"
     << indent << "Origin: " << this->Origin << "\n";
}
