#include "vtkTopoSplineSimplifyMorseSmaleComplex.h"

#include "vtkTopoSplineArrayNames.h"
#include "vtkTopoSplineDomainConversion.h"
#include "vtkTopoSplineWireFormat.h"

#include "MorseSmaleComplexSimplification.h" // core

#include <vtkCellArray.h>
#include <vtkDataSet.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkIntArray.h>
#include <vtkLogger.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>

#include <cmath>

namespace names = vtkTopoSplineArrayNames;

// The hierarchy of the last input, and what identifies that input.
struct vtkTopoSplineSimplifyMorseSmaleComplex::Cache
{
  topospline::MorseSmaleComplexSimplification Simplification;
  vtkMTimeType InputTime = 0;
  const void* InputObject = nullptr;
};

vtkStandardNewMacro(vtkTopoSplineSimplifyMorseSmaleComplex);

vtkTopoSplineSimplifyMorseSmaleComplex::vtkTopoSplineSimplifyMorseSmaleComplex()
  : Hierarchy(new Cache)
{
}

vtkTopoSplineSimplifyMorseSmaleComplex::~vtkTopoSplineSimplifyMorseSmaleComplex() = default;

int vtkTopoSplineSimplifyMorseSmaleComplex::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkMultiBlockDataSet");
  return 1;
}

namespace
{
// The pairs below the threshold that the paper's rules kept, and why: users see what
// survived although its persistence is small.
void AddBlockedPairs(const topospline::SimplificationOutput& result, vtkFieldData* fd)
{
  auto count = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::BlockedCancellations);
  count->InsertNextValue(static_cast<int>(result.Blocked.size()));
  auto lower = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::BlockedLowerId);
  auto upper = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::BlockedUpperId);
  auto persistence = vtkTopoSplineDomainConversion::NewArray<vtkDoubleArray>(names::BlockedPersistence);
  auto reason = vtkTopoSplineDomainConversion::NewArray<vtkStringArray>(names::BlockedReason);
  for (size_t i = 0; i < result.Blocked.size(); ++i)
  {
    lower->InsertNextValue(result.Blocked[i].Lower);
    upper->InsertNextValue(result.Blocked[i].Upper);
    persistence->InsertNextValue(result.Blocked[i].Persistence);
    reason->InsertNextValue(topospline::BlockReasonName(result.BlockReasons[i]));
  }
  for (vtkAbstractArray* a : std::initializer_list<vtkAbstractArray*>{ count, lower, upper, persistence, reason })
  {
    fd->AddArray(a);
  }
}

// The persistence curve: how many critical points remain above each threshold, one point per
// distinct threshold of the hierarchy (a step function, constant up to the next point).
void AddPersistenceCurve(const topospline::MorseSmaleComplexSimplification& simplification, vtkFieldData* fd)
{
  auto percent = vtkTopoSplineDomainConversion::NewArray<vtkDoubleArray>(names::PersistenceCurvePercent);
  auto remaining = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::PersistenceCurveCriticalPoints);
  const auto& hierarchy = simplification.Hierarchy();
  const double maximum = simplification.MaximumPersistence();
  auto left = static_cast<int>(simplification.NumberOfInputCriticalPoints());
  percent->InsertNextValue(0);
  remaining->InsertNextValue(left);
  for (size_t k = 0; k < hierarchy.size(); ++k)
  {
    left -= 2;
    if (k + 1 < hierarchy.size() && hierarchy[k + 1].Threshold == hierarchy[k].Threshold)
    {
      continue;
    }
    // Performed for every threshold strictly above this one.
    percent->InsertNextValue(maximum > 0 ? 100 * hierarchy[k].Threshold / maximum : 0);
    remaining->InsertNextValue(left);
  }
  fd->AddArray(percent);
  fd->AddArray(remaining);
}

void AddCancellations(const topospline::SimplificationOutput& result, double maximumPersistence, vtkFieldData* fd)
{
  auto lower = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::CancelledLowerId);
  auto upper = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::CancelledUpperId);
  auto survivor = vtkTopoSplineDomainConversion::NewArray<vtkIntArray>(names::SurvivorId);
  auto persistence = vtkTopoSplineDomainConversion::NewArray<vtkDoubleArray>(names::CancellationPersistence);
  for (const auto& c : result.Cancellations)
  {
    lower->InsertNextValue(c.Lower);
    upper->InsertNextValue(c.Upper);
    survivor->InsertNextValue(c.Survivor);
    persistence->InsertNextValue(c.Persistence);
  }
  auto absolute = vtkTopoSplineDomainConversion::NewArray<vtkDoubleArray>(names::AbsolutePersistenceThreshold);
  absolute->InsertNextValue(result.AbsoluteThreshold);
  auto maximum = vtkTopoSplineDomainConversion::NewArray<vtkDoubleArray>(names::MaximumPersistence);
  maximum->InsertNextValue(maximumPersistence);
  for (vtkAbstractArray* a : std::initializer_list<vtkAbstractArray*>{ lower, upper, survivor, persistence, absolute, maximum })
  {
    fd->AddArray(a);
  }
}
} // namespace

int vtkTopoSplineSimplifyMorseSmaleComplex::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkLogScopeFunction(TRACE);
  vtkMultiBlockDataSet* input = vtkMultiBlockDataSet::GetData(inputVector[0], 0);
  vtkMultiBlockDataSet* output = vtkMultiBlockDataSet::GetData(outputVector, 0);
  if (!input || !output)
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
  if (!std::isfinite(this->PersistenceThreshold) || this->PersistenceThreshold < 0 ||
    this->PersistenceThreshold > 100)
  {
    vtkErrorMacro("Simplify Morse-Smale Complex: the persistence threshold must be a percentage in [0, 100], not "
      << this->PersistenceThreshold << ".");
    return 1;
  }
  vtkDataSet* domain = vtkTopoSplineWireFormat::SegmentationOf(input);
  std::string error;
  Cache& cache = *this->Hierarchy;
  if (!cache.Simplification.HasHierarchy() || cache.InputObject != input || cache.InputTime != input->GetMTime())
  {
    vtkLogScopeF(TRACE, "compute cancellation hierarchy");
    topospline::MorseSmaleComplex complex;
    if (!vtkTopoSplineWireFormat::ReadComplex(input, complex, error))
    {
      vtkErrorMacro("Simplify Morse-Smale Complex: " << error << ".");
      cache.InputObject = nullptr;
      return 1;
    }
    cache.Simplification = topospline::MorseSmaleComplexSimplification();
    cache.Simplification.Hooks.Progress = [this](double f) { this->UpdateProgress(0.8 * f); };
    cache.Simplification.Hooks.AbortRequested = [this]() { return this->GetAbortExecute() != 0; };
    if (!cache.Simplification.ComputeHierarchy(complex, error))
    {
      vtkErrorMacro("Simplify Morse-Smale Complex: " << error << ".");
      cache.InputObject = nullptr;
      return 1;
    }
    cache.InputObject = input;
    cache.InputTime = input->GetMTime();
    ++this->HierarchyComputations;
  }

  double percent = this->PersistenceThreshold;
  if (cache.Simplification.NearConstant() && percent < 100)
  {
    vtkWarningMacro("Simplify Morse-Smale Complex: the field varies by less than "
      << topospline::MorseSmaleComplexSimplification::NearConstantRange
      << " of its magnitude, too little for strictly monotone 1-cells and 2-cells in double precision; "
         "simplified completely (100 %) instead of "
      << percent << " %.");
    percent = 100;
  }
  topospline::SimplificationOutput result;
  {
    vtkLogScopeF(TRACE, "replay cancellations to %g%%", percent);
    if (!cache.Simplification.Simplify(percent, result, error))
    {
      vtkErrorMacro("Simplify Morse-Smale Complex: " << error << ".");
      return 1;
    }
  }
  const auto before = static_cast<long long>(cache.Simplification.Hierarchy().size());
  const auto counts = result.Complex.CountByIndex();
  vtkLog(TRACE, "simplified to " << counts[0] << " minima, " << counts[1] << " saddles, " << counts[2]
                                 << " maxima (" << result.Cancellations.size() << " of " << before
                                 << " cancellations, " << result.Blocked.size()
                                 << " pairs below the threshold blocked by the cancellation rules)");
  {
    vtkLogScopeF(TRACE, "build output");
    vtkTopoSplineWireFormat::WriteComplex(
      result.Complex, domain, vtkTopoSplineWireFormat::ScalarFieldNameOf(input).c_str(), output);
    vtkTopoSplineWireFormat::WriteJunctionPoints(result.Complex, result.JunctionPoints, output);
    AddCancellations(result, cache.Simplification.MaximumPersistence(), output->GetFieldData());
    AddBlockedPairs(result, output->GetFieldData());
    AddPersistenceCurve(cache.Simplification, output->GetFieldData());
  }
  this->UpdateProgress(1.0);
  return 1;
}

void vtkTopoSplineSimplifyMorseSmaleComplex::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "PersistenceThreshold: " << this->PersistenceThreshold << "\n";
}
