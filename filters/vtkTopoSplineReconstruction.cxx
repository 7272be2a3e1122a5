#include "vtkTopoSplineReconstruction.h"

#include "vtkTopoSplineDomainConversion.h"
#include "vtkTopoSplineMorseSmaleComplex.h"
#include "vtkTopoSplineReconstructTwoCells.h"
#include "vtkTopoSplineSimplifyMorseSmaleComplex.h"
#include "vtkTopoSplineSmoothOneCells.h"

#include <vtkDataSet.h>
#include <vtkDataSetAttributes.h>
#include <vtkSmartPointer.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkLogger.h>
#include <vtkObjectFactory.h>


vtkStandardNewMacro(vtkTopoSplineReconstruction);

vtkTopoSplineReconstruction::vtkTopoSplineReconstruction()
  : Complex(vtkTopoSplineMorseSmaleComplex::New())
  , Simplify(vtkTopoSplineSimplifyMorseSmaleComplex::New())
  , Smooth(vtkTopoSplineSmoothOneCells::New())
  , Reconstruct(vtkTopoSplineReconstructTwoCells::New())
{
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
  this->Simplify->SetInputConnection(this->Complex->GetOutputPort());
  this->Smooth->SetInputConnection(this->Simplify->GetOutputPort());
  this->Reconstruct->SetInputConnection(this->Smooth->GetOutputPort());
}

vtkTopoSplineReconstruction::~vtkTopoSplineReconstruction()
{
  this->Reconstruct->Delete();
  this->Smooth->Delete();
  this->Simplify->Delete();
  this->Complex->Delete();
}

int vtkTopoSplineReconstruction::FillInputPortInformation(int, vtkInformation* info)
{
  vtkTopoSplineDomainConversion::AcceptPlanarDomains(info);
  return 1;
}

int vtkTopoSplineReconstruction::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // Like "Morse-Smale Complex": the complex needs the whole domain.
  vtkTopoSplineDomainConversion::RequestWholeInput(inputVector[0]->GetInformationObject(0));
  return 1;
}

int vtkTopoSplineReconstruction::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkLogScopeFunction(TRACE);
  vtkDataSet* input = vtkDataSet::GetData(inputVector[0], 0);
  vtkDataSet* output = vtkDataSet::GetData(outputVector, 0);
  if (!input || !output)
  {
    vtkErrorMacro("Missing input or output.");
    return 0;
  }
  // The inner pipeline gets a new input only when ours changed, so that a new threshold or k
  // alone reuses the complex (and the threshold alone the cancellation hierarchy).
  if (input != this->LastInput || input->GetMTime() != this->LastInputTime)
  {
    vtkSmartPointer<vtkDataSet> copy = vtkSmartPointer<vtkDataSet>::Take(input->NewInstance());
    copy->ShallowCopy(input);
    this->Complex->SetInputDataObject(copy);
    this->LastInput = input;
    this->LastInputTime = input->GetMTime();
  }
  this->Complex->SetInputArrayToProcess(0, this->GetInputArrayInformation(0));
  this->Simplify->SetPersistenceThreshold(this->PersistenceThreshold);
  this->Smooth->SetCurveSegments(this->CurveSegments);
  this->Reconstruct->SetInterior(this->Interior);
  this->Reconstruct->SetSurfaceTolerance(this->SurfaceTolerance);
  this->Reconstruct->SetAlternativeMapStrength(this->AlternativeMapStrength);
  this->Reconstruct->SetVerifyTopology(this->VerifyTopology);
  this->UpdateProgress(0.0);
  this->Reconstruct->Update();
  vtkDataSet* result = vtkDataSet::SafeDownCast(this->Reconstruct->GetOutputDataObject(0));
  if (result && std::string(result->GetClassName()) == output->GetClassName())
  {
    output->ShallowCopy(result);
  }
  else if (result && result->GetNumberOfPoints() > 0)
  {
    vtkErrorMacro("TopoSpline Reconstruction: the reconstruction is a " << result->GetClassName()
                                                                      << ", not a " << output->GetClassName() << ".");
  }
  this->UpdateProgress(1.0);
  return 1;
}

void vtkTopoSplineReconstruction::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "PersistenceThreshold: " << this->PersistenceThreshold << "\n"
     << indent << "CurveSegments: " << this->CurveSegments << "\n"
     << indent << "Interior: " << (this->Interior ? "Fitted" : "Paper") << "\n"
     << indent << "SurfaceTolerance: " << this->SurfaceTolerance << "\n"
     << indent << "AlternativeMapStrength: " << this->AlternativeMapStrength << "\n"
     << indent << "VerifyTopology: " << this->VerifyTopology << "\n";
}
