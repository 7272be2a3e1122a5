/**
 * @class vtkTopoSplineSmoothOneCells
 * @brief Stage 3 of TopoSpline: smooth, strictly monotone 1-cells (the paper's section 4).
 *
 * Input: a complex from "Morse-Smale Complex" or "Simplify Morse-Smale Complex". The 1-cells
 * are cut into pieces at their junction points (where 1-cells sharing an extremum merge); the
 * junction values come from one global linear program (minimum L1 change, strictly
 * increasing along every 1-cell); every piece gets a strictly increasing uniform quadratic
 * B-spline height (L1 fit, He & Shi) and a least-squares quadratic B-spline curve in the
 * plane with the same CurveSegments knots, both converted to CurveSegments cubic Beziers.
 * Pieces of fewer jagged edges than CurveSegments get the smallest divisor of it that gives
 * each edge a segment (at least 2).
 * Where smoothed curves would cross, the pieces involved get more segments (on long pieces,
 * crowded where the other piece comes near).
 *
 * Output: the input blocks, plus "SmoothedOneCells" (one VTK_BEZIER_CURVE cell of degree 3
 * per Bezier segment, control points in the plane of the input, point data "Height": the
 * height's Bezier ordinates) and "SampledOneCells" (every 1-cell densely sampled as a
 * polyline with "Height"). Field data: CurveSegments, ShortPieces, AdaptedPieces,
 * RiseKnotPieces, ContactKnotPieces, CurveHeightPieces, RefinedPieces, RemainingCrossings, PiecesOutsideDomain, L1Error and
 * UnconstrainedL1Error (sums over the pieces).
 */
#pragma once

#include "TopoSplineFiltersModule.h"

#include <vtkMultiBlockDataSetAlgorithm.h>

namespace topospline
{
struct MorseSmaleComplex;
struct OneCellSmoothingResult;
}

class TOPOSPLINEFILTERS_EXPORT vtkTopoSplineSmoothOneCells : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkTopoSplineSmoothOneCells* New();
  vtkTypeMacro(vtkTopoSplineSmoothOneCells, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  //@{
  /** k, cubic Bezier segments per piece of 1-cell (the paper uses 4 and 7). In [2, 30]. */
  vtkSetMacro(CurveSegments, int);
  vtkGetMacro(CurveSegments, int);
  //@}

  //@{
  /** Points per Bezier segment of the "SampledOneCells" polylines (fewer, with a warning, where
   * they would exceed MaximumSampledPoints; field data SampledSamplesPerSegment says how many). */
  vtkSetClampMacro(SamplesPerSegment, int, 1, 1000);
  vtkGetMacro(SamplesPerSegment, int);
  //@}

  //@{
  /** The "SampledOneCells" display block's point budget (default 2^20, about 40 MB with the
   * heights and lines): on a large noisy complex merged 1-cells run through thousands of pieces
   * each, and sampling every one at 16 points per segment took more than 13 GB (1000 x 1000
   * noise at 25 %, k = 29); at the budget of 2^23 before, the block of 300 x 300 noise at 5 %
   * (6.8 million points) held 275 MB for as long as the pipeline. */
  vtkSetClampMacro(MaximumSampledPoints, vtkIdType, 1, VTK_ID_MAX);
  vtkGetMacro(MaximumSampledPoints, vtkIdType);
  //@}

protected:
  vtkTopoSplineSmoothOneCells() = default;
  ~vtkTopoSplineSmoothOneCells() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int CurveSegments = 4;
  int SamplesPerSegment = 16;
  vtkIdType MaximumSampledPoints = vtkIdType(1) << 20;

private:
  void ReportAdjustments(
    const topospline::MorseSmaleComplex& complex, const topospline::OneCellSmoothingResult& result);
  int SamplesWithinBudget(
    const topospline::MorseSmaleComplex& complex, const topospline::OneCellSmoothingResult& result);

  vtkTopoSplineSmoothOneCells(const vtkTopoSplineSmoothOneCells&) = delete;
  void operator=(const vtkTopoSplineSmoothOneCells&) = delete;
};
