/**
 * @class vtkTopoSplineReconstructTwoCells
 * @brief Stage 4 of TopoSpline: the reconstructed field, one monotone surface per 2-cell (the
 * paper's section 5).
 *
 * Input: the output of "Smooth 1-Cells". Every 2-cell of the smoothed complex is sampled along
 * its boundary Bezier curves (BoundarySamples per segment), triangulated (CGAL constrained
 * Delaunay + refinement), mapped onto the unit square with Floater's mean value coordinates
 * (minimum at (0,0), maximum at (1,1), saddles at the other corners; a junction point takes the
 * minimum's or maximum's corner where 1-cells merge before it), and given a monotone C1 cubic
 * Sibson surface F that interpolates the smoothed 1-cells and has no interior critical point.
 * The reconstruction is F o Phi. Cells are built in parallel (vtkSMPTools).
 *
 * Outputs:
 *  0. The input geometry with point data "Reconstructed" (F o Phi at every vertex),
 *     "Difference" (Reconstructed minus the input field) and "ReconstructionCellId" (the
 *     smoothed 2-cell holding the vertex), and field data with the errors, timings and the
 *     topology verdict (see VerifyTopology).
 *  1. The surface itself: every Sibson sub-triangle as a VTK_BEZIER_TRIANGLE of degree 3, with
 *     point data "Height" (its Bezier ordinates, exact) and cell data "TwoCellId".
 *  2. With OutputResolution > 1: the reconstruction sampled on an image grid OutputResolution
 *     times finer than the input (images: the same origin, spacing / OutputResolution; meshes:
 *     a grid over the bounds at the mean edge length / OutputResolution, with
 *     "vtkValidPointMask" 0 outside the domain). Otherwise an empty image.
 */
#pragma once

#include "TopoSplineFiltersModule.h"

#include <vtkDataObjectAlgorithm.h>

class vtkDataSet;
namespace topospline
{
struct FieldReconstructionReport;
}

class TOPOSPLINEFILTERS_EXPORT vtkTopoSplineReconstructTwoCells : public vtkDataObjectAlgorithm
{
public:
  static vtkTopoSplineReconstructTwoCells* New();
  vtkTypeMacro(vtkTopoSplineReconstructTwoCells, vtkDataObjectAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  //@{
  /**
   * c: samples per boundary Bezier segment for the triangulation (the paper uses 5); with the
   * fitted interior, fewer on the short pieces around small 2-cells (at most one per half input
   * edge, FieldReconstruction::BoundarySampleEdges).
   */
  vtkSetMacro(BoundarySamples, int);
  vtkGetMacro(BoundarySamples, int);
  //@}

  //@{
  /**
   * What decides a 2-cell's interior: INTERIOR_FITTED (default) fits the free Bezier ordinates
   * of its Sibson surface to the input samples inside the cell (least squares under the
   * monotonicity conditions, so still no interior critical point); INTERIOR_PAPER is the
   * paper's construction from the boundary curves alone (its Table 1).
   */
  enum InteriorModes
  {
    INTERIOR_PAPER = 0,
    INTERIOR_FITTED = 1
  };
  vtkSetClampMacro(Interior, int, INTERIOR_PAPER, INTERIOR_FITTED);
  vtkGetMacro(Interior, int);
  //@}

  //@{
  /**
   * Fitted interiors: a cell's Sibson grid is refined (doubled, its boundary Beziers split
   * exactly) while the fit misses the input by more than this percentage of the input's value
   * range, up to 32 x 32, while each doubling gains at least 10 %. 0: no refinement.
   */
  vtkSetClampMacro(SurfaceTolerance, double, 0.0, 100.0);
  vtkGetMacro(SurfaceTolerance, double);
  //@}

  //@{
  /**
   * Fitted interiors: the cell whose fit misses the input most is fitted again on two other
   * maps onto the square, the mean value weights reweighted by the input's gradient (edges
   * along its gradient, then edges along its level sets, pulling up to this factor + 1 times
   * harder than the others), and keeps a fit whose largest miss is at least 10 % smaller; then
   * the next, while each is improved and misses by more than three times the surface
   * tolerance. Field data "RemappedCells" counts them. 0: the mean value map everywhere (the
   * paper's).
   */
  vtkSetClampMacro(AlternativeMapStrength, double, 0.0, 1000.0);
  vtkGetMacro(AlternativeMapStrength, double);
  //@}

  //@{
  /** Refinement factor of the resampled image on output port 2; 1 produces no image. */
  vtkSetMacro(OutputResolution, int);
  vtkGetMacro(OutputResolution, int);
  //@}

  //@{
  /**
   * Extract the Morse-Smale complex of the reconstruction (on the input geometry, and on the
   * resampled image when there is one) and compare its critical points with the input
   * complex's: field data "TopologyVerified" (1 when every critical point is found within one
   * grid spacing of its node and no other exists), the counts, and the spurious and missing
   * points; a warning when it fails.
   */
  vtkSetMacro(VerifyTopology, bool);
  vtkGetMacro(VerifyTopology, bool);
  vtkBooleanMacro(VerifyTopology, bool);
  //@}

  //@{
  /**
   * Flatten the spurious critical pairs that sampling F o Phi creates (nearly flat stretches,
   * 1-cells crossing the grid obliquely) out of the sampled values, by the flooding of Tierny
   * and Pascucci from the complex's extrema, so that the outputs' samplings have exactly the
   * complex's extrema. The analytic patches (output 1) are not changed. Field data
   * "SamplingChangedVertices" and "SamplingMaximumChange" report what it moved; with
   * VerifyTopology, "RawInputCriticalPoints" gives the counts before it.
   */
  vtkSetMacro(TopologicalSampling, bool);
  vtkGetMacro(TopologicalSampling, bool);
  vtkBooleanMacro(TopologicalSampling, bool);
  //@}

protected:
  vtkTopoSplineReconstructTwoCells();
  ~vtkTopoSplineReconstructTwoCells() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int BoundarySamples = 5;
  int Interior = INTERIOR_FITTED;
  double SurfaceTolerance = 1.0;
  double AlternativeMapStrength = 30.0;
  int OutputResolution = 1;
  bool VerifyTopology = true;
  bool TopologicalSampling = true;

private:
  // False, with an error naming the estimate, when the reconstruction would not fit in the
  // `available` bytes.
  bool FitsInMemory(vtkIdType points, std::size_t twoCells, double available);
  void WarnAbout(const topospline::FieldReconstructionReport& report);

  vtkTopoSplineReconstructTwoCells(const vtkTopoSplineReconstructTwoCells&) = delete;
  void operator=(const vtkTopoSplineReconstructTwoCells&) = delete;
};
