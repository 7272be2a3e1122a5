#include "vtkTopoSplineMorseSmaleComplex.h"

#include "vtkTopoSplineDomainConversion.h"
#include "vtkTopoSplineWireFormat.h"

#include "MorseSmaleComplexExtraction.h" // core

#include <vtkCompositeDataSet.h>
#include <vtkDataArray.h>
#include <vtkDataObject.h>
#include <vtkDataSet.h>
#include <vtkDataSetAttributes.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkLogger.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkObjectFactory.h>
#include <vtkStreamingDemandDrivenPipeline.h>

vtkStandardNewMacro(vtkTopoSplineMorseSmaleComplex);

vtkTopoSplineMorseSmaleComplex::vtkTopoSplineMorseSmaleComplex()
{
  // Default: the active point scalars.
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

int vtkTopoSplineMorseSmaleComplex::FillInputPortInformation(int, vtkInformation* info)
{
  vtkTopoSplineDomainConversion::AcceptPlanarDomains(info);
  // Taken whole, so that RequestData can say what is wrong with it: otherwise the pipeline
  // would run the filter once per block and the next filter would get a multiblock of
  // complexes it cannot read.
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkCompositeDataSet");
  return 1;
}

int vtkTopoSplineMorseSmaleComplex::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // The complex is global: the whole input, on every process (see RequestData).
  vtkTopoSplineDomainConversion::RequestWholeInput(inputVector[0]->GetInformationObject(0));
  return 1;
}

int vtkTopoSplineMorseSmaleComplex::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkLogScopeFunction(TRACE);
  vtkDataSet* input = vtkDataSet::GetData(inputVector[0], 0);
  vtkMultiBlockDataSet* output = vtkMultiBlockDataSet::GetData(outputVector, 0);
  if (vtkCompositeDataSet::GetData(inputVector[0], 0))
  {
    vtkErrorMacro("Morse-Smale Complex: the input is a composite data set ("
      << vtkCompositeDataSet::GetData(inputVector[0], 0)->GetClassName()
      << "); the complex needs one 2D image or triangle mesh: pick one block (Extract Block) or merge "
         "them (Merge Blocks) first.");
    return 1;
  }
  if (!input || !output)
  {
    vtkErrorMacro("Missing input or output.");
    return 0;
  }
  // In a distributed run only the process of piece 0 computes the complex.
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()) &&
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()) > 0)
  {
    return 1;
  }

  // On bad input: a clear error and an empty output (returning 1 keeps the pipeline alive).
  std::string note;
  vtkDataArray* scalars = vtkTopoSplineDomainConversion::SelectedPointScalars(
    this->GetInputArrayToProcess(0, inputVector), this->GetInputArrayInformation(0), input, note);
  if (!note.empty())
  {
    vtkWarningMacro("Morse-Smale Complex: " << note << ".");
  }
  topospline::PlanarScalarField field;
  std::string error;
  {
    vtkLogScopeF(TRACE, "convert input");
    if (!vtkTopoSplineDomainConversion::ToPlanarScalarField(input, scalars, field, error))
    {
      vtkErrorMacro("Morse-Smale Complex: " << error << ".");
      return 1;
    }
  }

  topospline::MorseSmaleComplexExtraction extraction;
  extraction.Parallel = vtkTopoSplineDomainConversion::SMPParallelFor();
  // The core reports between its passes, on this thread.
  extraction.Hooks.Progress = [this](double fraction) { this->UpdateProgress(0.05 + 0.85 * fraction); };
  extraction.Hooks.AbortRequested = [this]() { return this->GetAbortExecute() != 0; };
  extraction.NearConstantAsConstant = true;
  topospline::MorseSmaleComplex complex;
  {
    vtkLogScopeF(TRACE, "extract Morse-Smale complex");
    if (!extraction.Extract(field, complex, error))
    {
      if (error != "aborted")
      {
        vtkErrorMacro("Morse-Smale Complex: " << error << ".");
      }
      return 1;
    }
  }
  if (extraction.ReadAsConstant)
  {
    vtkWarningMacro("Morse-Smale Complex: the field varies by less than "
      << topospline::NearConstantRange
      << " of its magnitude, too little for strictly monotone 1-cells and 2-cells in double precision; "
         "it is read as the constant halfway between its extremes (a flat reconstruction).");
  }
  const auto counts = complex.CountByIndex();
  vtkLog(TRACE, "Morse-Smale complex: " << counts[0] << " minima, " << counts[1] << " saddles, " << counts[2]
                                       << " maxima, " << complex.OneCells.size() << " 1-cells, "
                                       << complex.TwoCells.size() << " 2-cells");
  {
    vtkLogScopeF(TRACE, "build output");
    vtkTopoSplineWireFormat::WriteComplex(complex, input, scalars->GetName(), output);
  }
  this->UpdateProgress(1.0);
  return 1;
}

void vtkTopoSplineMorseSmaleComplex::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
