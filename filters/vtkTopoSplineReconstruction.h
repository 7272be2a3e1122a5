/**
 * @class vtkTopoSplineReconstruction
 * @brief The whole TopoSpline pipeline in one filter, for users who want the result in one
 * click: "Morse-Smale Complex", "Simplify Morse-Smale Complex", "Smooth 1-Cells" and
 * "Reconstruct 2-Cells" with their defaults, driven by the two main properties.
 *
 * Input: what "Morse-Smale Complex" takes (2D image or planar triangle mesh with a point
 * scalar field). Output: output 0 of "Reconstruct 2-Cells" (the input geometry with
 * "Reconstructed", "Difference", "ReconstructionCellId" and the field data of all stages).
 * The four stage filters are kept between runs, so changing only the threshold or k reuses
 * the complex (and the threshold alone reuses the cancellation hierarchy).
 */
#pragma once

#include "TopoSplineFiltersModule.h"

#include <vtkDataSetAlgorithm.h>
#include <vtkNew.h>

class vtkTopoSplineMorseSmaleComplex;
class vtkTopoSplineSimplifyMorseSmaleComplex;
class vtkTopoSplineSmoothOneCells;
class vtkTopoSplineReconstructTwoCells;

class TOPOSPLINEFILTERS_EXPORT vtkTopoSplineReconstruction : public vtkDataSetAlgorithm
{
public:
  static vtkTopoSplineReconstruction* New();
  vtkTypeMacro(vtkTopoSplineReconstruction, vtkDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  //@{
  /** Persistence threshold in percent of the maximum persistence (stage 2). */
  vtkSetMacro(PersistenceThreshold, double);
  vtkGetMacro(PersistenceThreshold, double);
  //@}

  //@{
  /** k, cubic segments per 1-cell piece (stage 3). */
  vtkSetMacro(CurveSegments, int);
  vtkGetMacro(CurveSegments, int);
  //@}

  //@{
  /** Stage 4: fitted (1, default) or paper (0) 2-cell interiors; see vtkTopoSplineReconstructTwoCells. */
  vtkSetClampMacro(Interior, int, 0, 1);
  vtkGetMacro(Interior, int);
  //@}

  //@{
  /** Stage 4: refinement tolerance of fitted interiors, % of the value range (0: none). */
  vtkSetClampMacro(SurfaceTolerance, double, 0.0, 100.0);
  vtkGetMacro(SurfaceTolerance, double);
  //@}

  //@{
  /** Stage 4: strength of the alternative maps of fitted interiors (0: none); see vtkTopoSplineReconstructTwoCells. */
  vtkSetClampMacro(AlternativeMapStrength, double, 0.0, 1000.0);
  vtkGetMacro(AlternativeMapStrength, double);
  //@}

  //@{
  /** The built-in topology check of stage 4. */
  vtkSetMacro(VerifyTopology, bool);
  vtkGetMacro(VerifyTopology, bool);
  //@}

protected:
  vtkTopoSplineReconstruction();
  ~vtkTopoSplineReconstruction() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double PersistenceThreshold = 5.0;
  int CurveSegments = 4;
  int Interior = 1;
  double SurfaceTolerance = 1.0;
  double AlternativeMapStrength = 30.0;
  bool VerifyTopology = true;

private:
  vtkTopoSplineReconstruction(const vtkTopoSplineReconstruction&) = delete;
  void operator=(const vtkTopoSplineReconstruction&) = delete;

  vtkTopoSplineMorseSmaleComplex* Complex;
  vtkTopoSplineSimplifyMorseSmaleComplex* Simplify;
  vtkTopoSplineSmoothOneCells* Smooth;
  vtkTopoSplineReconstructTwoCells* Reconstruct;
  const void* LastInput = nullptr;
  vtkMTimeType LastInputTime = 0;
};
