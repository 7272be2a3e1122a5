/**
 * @class vtkTopoSplineTrigonometricSource
 * @brief The paper's "Trigo" test field: a * sin(x/a) * sin(y/a) on a grid of spacing 1.
 *
 * Resolution x Resolution samples starting at (Origin, Origin). The paper: a = 10, 100 samples
 * on [-49, 50]^2. Point array "Trigonometric".
 */
#pragma once

#include "TopoSplineFiltersModule.h"

#include <vtkImageAlgorithm.h>

class TOPOSPLINEFILTERS_EXPORT vtkTopoSplineTrigonometricSource : public vtkImageAlgorithm
{
public:
  static vtkTopoSplineTrigonometricSource* New();
  vtkTypeMacro(vtkTopoSplineTrigonometricSource, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  vtkSetClampMacro(Amplitude, double, 1e-6, 1e6);
  vtkGetMacro(Amplitude, double);
  vtkSetClampMacro(Resolution, int, 2, 20000);
  vtkGetMacro(Resolution, int);
  vtkSetMacro(Origin, double);
  vtkGetMacro(Origin, double);

protected:
  vtkTopoSplineTrigonometricSource();
  ~vtkTopoSplineTrigonometricSource() override = default;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  void ExecuteDataWithInformation(vtkDataObject* output, vtkInformation* outInfo) override;

  double Amplitude = 10.0;
  int Resolution = 100;
  double Origin = -49.0;

private:
  vtkTopoSplineTrigonometricSource(const vtkTopoSplineTrigonometricSource&) = delete;
  void operator=(const vtkTopoSplineTrigonometricSource&) = delete;
};
