// Conversions between VTK data and the pure C++ core: input domains to PlanarScalarField,
// MorseSmaleComplex to and from the multiblock that flows between the pipeline stages, and
// vtkSMPTools as the core's ParallelFor.
#pragma once

#include "MorseSmaleComplexExtraction.h" // core

#include <string>

class vtkDataArray;
class vtkInformation;
class vtkDataSet;
class vtkMultiBlockDataSet;

namespace vtkTopoSplineDomainConversion
{
// vtkSMPTools-backed loop (results are identical with every backend: see CoreTypes.h).
topospline::ParallelFor SMPParallelFor();

// The point array chosen with SetInputArrayToProcess(0, ...). When none was chosen or the
// chosen name does not exist (a pvpython filter created before its source ever ran may get a
// stale name), the active point scalars, else the first 1-component point array; `note` then
// says so when a name had been given. nullptr when the input has no usable point array.
vtkDataArray* SelectedPointScalars(
  vtkDataArray* chosen, vtkInformation* arrayInformation, vtkDataSet* input, std::string& note);

// Fills `field` from a 2D vtkImageData (one layer) or a planar triangle vtkPolyData /
// vtkUnstructuredGrid and a point scalar array. Returns false with a user-facing message.
bool ToPlanarScalarField(vtkDataSet* input, vtkDataArray* scalars, topospline::PlanarScalarField& field,
  std::string& error);

// Writes the complex into `output` (blocks named in vtkTopoSplineArrayNames.h). `domain` is the
// input geometry: it is shallow-copied into the "Segmentation" block with the per-vertex ids.
void ToMultiBlock(const topospline::MorseSmaleComplex& complex, vtkDataSet* domain, const char* scalarName,
  vtkMultiBlockDataSet* output);

// Reads a complex written by ToMultiBlock back (for the later stages). Returns false with a
// message when `input` is not such a complex.
bool FromMultiBlock(vtkMultiBlockDataSet* input, topospline::MorseSmaleComplex& complex, std::string& error);

// A point of the field's plane, (u, v) as in PlanarScalarField::Points, in the 3D coordinates
// of `domain` (the input geometry or the Segmentation block).
void PlanarToDomainPoint(vtkDataSet* domain, const double uv[2], double xyz[3]);

// The inverse of PlanarToDomainPoint, and the bounds (umin, umax, vmin, vmax) in the plane.
void DomainToPlanarPoint(vtkDataSet* domain, const double xyz[3], double uv[2]);
void PlanarBounds(vtkDataSet* domain, double bounds[4]);

// The "Segmentation" block of a complex, or nullptr.
vtkDataSet* SegmentationOf(vtkMultiBlockDataSet* input);
}
