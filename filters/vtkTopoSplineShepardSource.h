/**
 * @class vtkTopoSplineShepardSource
 * @brief The paper's "Shepard" test field: Shepard's inverse-distance interpolant of random sites.
 *
 * F(x) = sum_k f_k |x - x_k|^-mu / sum_j |x - x_j|^-mu over NumberOfSites random sites with
 * random values in [0, 1], sampled on a Resolution x Resolution image of spacing 1. For mu > 1
 * every site is an extremum. The paper: 50 sites, mu = 2, 250 x 250. Point array "Shepard".
 */
#pragma once

#include "TopoSplineFiltersModule.h"

#include <vtkImageAlgorithm.h>

class TOPOSPLINEFILTERS_EXPORT vtkTopoSplineShepardSource : public vtkImageAlgorithm
{
public:
  static vtkTopoSplineShepardSource* New();
  vtkTypeMacro(vtkTopoSplineShepardSource, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  vtkSetClampMacro(NumberOfSites, int, 1, 100000);
  vtkGetMacro(NumberOfSites, int);
  vtkSetClampMacro(Power, double, 0.01, 100.0);
  vtkGetMacro(Power, double);
  vtkSetClampMacro(Resolution, int, 2, 20000);
  vtkGetMacro(Resolution, int);
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);

protected:
  vtkTopoSplineShepardSource();
  ~vtkTopoSplineShepardSource() override = default;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  void ExecuteDataWithInformation(vtkDataObject* output, vtkInformation* outInfo) override;

  int NumberOfSites = 50;
  double Power = 2.0;
  int Resolution = 250;
  int Seed = 1;

private:
  vtkTopoSplineShepardSource(const vtkTopoSplineShepardSource&) = delete;
  void operator=(const vtkTopoSplineShepardSource&) = delete;
};
