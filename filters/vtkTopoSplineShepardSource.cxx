#include "vtkTopoSplineShepardSource.h"

#include "vtkTopoSplineArrayNames.h"
#include "vtkTopoSplineDomainConversion.h"
#include "vtkTopoSplineSyntheticSourceSupport.h"

#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkTopoSplineShepardSource);

vtkTopoSplineShepardSource::vtkTopoSplineShepardSource()
{
  this->SetNumberOfInputPorts(0);
}

int vtkTopoSplineShepardSource::RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkTopoSplineSyntheticSourceSupport::PublishGridInformation(outputVector->GetInformationObject(0), this->Resolution, 0.0);
  return 1;
}

void vtkTopoSplineShepardSource::ExecuteDataWithInformation(vtkDataObject* output, vtkInformation* outInfo)
{
  const auto grid = topospline::ShepardField(this->NumberOfSites, this->Power, this->Resolution,
    static_cast<std::uint64_t>(this->Seed), vtkTopoSplineDomainConversion::SMPParallelFor());
  vtkTopoSplineSyntheticSourceSupport::FillImage(output, outInfo, grid, vtkTopoSplineArrayNames::ShepardField);
}

void vtkTopoSplineShepardSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfSites: " << this->NumberOfSites << "\n"
     << indent << "Power: " << this->Power << "\n"
     << indent << "Resolution: " << this->Resolution << "\n"
     << indent << "Seed: " << this->Seed << "\n";
}
