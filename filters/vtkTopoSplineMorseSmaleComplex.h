/**
 * @class vtkTopoSplineMorseSmaleComplex
 * @brief Stage 1 of TopoSpline: the discrete Morse-Smale complex of a 2D scalar field.
 *
 * Input: a point scalar field (any real type, chosen with SetInputArrayToProcess(0, ...)) on a
 * 2D vtkImageData (one layer; each quad split along its (i+1,j)-(i,j+1) diagonal) or on a
 * planar triangle vtkPolyData / vtkUnstructuredGrid.
 *
 * Output: one vtkMultiBlockDataSet holding the whole complex, so the next stage takes a single
 * input. Blocks (names and arrays in vtkTopoSplineArrayNames.h):
 *  0 "CriticalPoints"   vertices: CriticalPointId (stable), CriticalIndex (0/1/2),
 *                       CriticalValue, VertexId, IsOnBoundary, CriticalCellId,
 *                       SaddleEdgeVertexId (a saddle's other edge vertex, -1 for extrema),
 *                       IsCornerTriangle (a maximum whose triangle is its vertex's only one)
 *  1 "OneCells"         polylines (the 1-cells) from the lower to the higher critical point: cell data
 *                       SeparatrixId, SourceId, DestinationId, SeparatrixType (0 descending
 *                       minimum-saddle, 1 ascending saddle-maximum); point data ScalarValue
 *  2 "TwoCells"         one point per 2-cell at its centroid: MinimumId, MaximumId, SaddleIds,
 *                       BoundarySeparatrixIds, IsPouch, NumberOfVertices
 *  3 "Segmentation"     the input geometry with AscendingManifoldId, DescendingManifoldId and
 *                       TwoCellId per point
 *
 * The discrete gradient and the boundary rule are described in core/DiscreteGradient.h.
 *
 * Distributed runs: the complex is a global structure. Every process asks for the whole input
 * and the process that renders piece 0 computes the complex; the others produce an empty one.
 */
#pragma once

#include "TopoSplineFiltersModule.h"

#include <vtkMultiBlockDataSetAlgorithm.h>

class TOPOSPLINEFILTERS_EXPORT vtkTopoSplineMorseSmaleComplex : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkTopoSplineMorseSmaleComplex* New();
  vtkTypeMacro(vtkTopoSplineMorseSmaleComplex, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

protected:
  vtkTopoSplineMorseSmaleComplex();
  ~vtkTopoSplineMorseSmaleComplex() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkTopoSplineMorseSmaleComplex(const vtkTopoSplineMorseSmaleComplex&) = delete;
  void operator=(const vtkTopoSplineMorseSmaleComplex&) = delete;
};
