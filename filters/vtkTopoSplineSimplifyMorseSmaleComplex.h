/**
 * @class vtkTopoSplineSimplifyMorseSmaleComplex
 * @brief Stage 2 of TopoSpline: persistence simplification of a Morse-Smale complex.
 *
 * Input: the multiblock of vtkTopoSplineMorseSmaleComplex. Output: the simplified complex in
 * the same form (blocks CriticalPoints, OneCells, TwoCells, Segmentation), so the later stages
 * take either, plus a block "JunctionPoints" (where 1-cells sharing an extremum merge; stage 3
 * cuts 1-cells there) and field data listing the cancellations performed.
 *
 * PersistenceThreshold is a percentage of the maximum persistence, defined as the range of the
 * critical values of the input complex (max - min critical value, i.e. the field's range): the
 * pairs cancelled are those of the hierarchy whose persistence (running maximum along the
 * hierarchy) is below PersistenceThreshold / 100 times that range. 0 cancels nothing, 100
 * performs every cancellation the rules allow. This meaning is fixed: saved states rely on it.
 *
 * The cancellation hierarchy is computed once per input; changing the threshold only replays
 * it.
 */
#pragma once

#include "TopoSplineFiltersModule.h"

#include <vtkMultiBlockDataSetAlgorithm.h>

#include <memory>

class TOPOSPLINEFILTERS_EXPORT vtkTopoSplineSimplifyMorseSmaleComplex : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkTopoSplineSimplifyMorseSmaleComplex* New();
  vtkTypeMacro(vtkTopoSplineSimplifyMorseSmaleComplex, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  //@{
  /**
   * Persistence threshold in percent of the maximum persistence (see the class description),
   * in [0, 100]. Default 2 (the paper's Mt Rainier example).
   */
  vtkSetMacro(PersistenceThreshold, double);
  vtkGetMacro(PersistenceThreshold, double);
  //@}

  /** Number of hierarchy computations so far (the threshold alone never triggers one). */
  vtkGetMacro(HierarchyComputations, int);

protected:
  vtkTopoSplineSimplifyMorseSmaleComplex();
  ~vtkTopoSplineSimplifyMorseSmaleComplex() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double PersistenceThreshold = 5.0;
  int HierarchyComputations = 0;

private:
  vtkTopoSplineSimplifyMorseSmaleComplex(const vtkTopoSplineSimplifyMorseSmaleComplex&) = delete;
  void operator=(const vtkTopoSplineSimplifyMorseSmaleComplex&) = delete;

  struct Cache;
  std::unique_ptr<Cache> Hierarchy;
};
