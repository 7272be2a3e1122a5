// Conversions between VTK data and the pure C++ core: input domains to PlanarScalarField, the
// plane the domain lies in, vtkSMPTools as the core's ParallelFor, freed memory handed back to
// the system, and small array helpers.
// (The multiblock that flows between the stages is read and written in vtkTopoSplineWireFormat.)
#pragma once

#include "MorseSmaleComplex.h" // core

#include <vtkSmartPointer.h>

#include <initializer_list>
#include <string>

class vtkAbstractArray;
class vtkDataArray;
class vtkInformation;
class vtkDataSet;
class vtkFieldData;
class vtkMultiBlockDataSet;

namespace vtkTopoSplineDomainConversion
{
// vtkSMPTools-backed loop (results are identical with every backend: see CoreTypes.h).
topospline::ParallelFor SMPParallelFor();

// Hands the heap memory freed so far back to the system (glibc's malloc_trim; nothing
// elsewhere). Stages 3 and 4 allocate and free gigabytes in many small blocks, from several
// threads' arenas; without it glibc keeps most of it: 300 x 300 noise at 5 % left the process
// at 1.65 GB resident after stage 4, 0.89 GB of it live. Stage 4 also calls it once its 2-cells
// are released, before the topological sampling (FieldReconstruction::ReleaseFreedMemory).
void ReleaseFreedMemory();

// Calls ReleaseFreedMemory when it goes out of scope, at the end of a filter's run: a ParaView
// session then stays at its largest run's size, after an error as well.
struct ReleaseFreedMemoryOnReturn
{
  ReleaseFreedMemoryOnReturn() = default;
  ReleaseFreedMemoryOnReturn(const ReleaseFreedMemoryOnReturn&) = delete;
  ReleaseFreedMemoryOnReturn& operator=(const ReleaseFreedMemoryOnReturn&) = delete;
  ~ReleaseFreedMemoryOnReturn();
};

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

// The coordinate plane of a domain: which two axes span it (U, V: the (u, v) of
// PlanarScalarField::Points) and where the third one (W) sits.
struct DomainPlane
{
  int U = 0, V = 1, W = 2;
  double WValue = 0;
  void To3D(const double uv[2], double xyz[3]) const
  {
    xyz[this->U] = uv[0];
    xyz[this->V] = uv[1];
    xyz[this->W] = this->WValue;
  }
  void ToPlanar(const double xyz[3], double uv[2]) const
  {
    uv[0] = xyz[this->U];
    uv[1] = xyz[this->V];
  }
};

// The plane of `domain` (the input geometry or a complex's Segmentation block): an image's
// one-point axis, else the axis along which the points have no extent.
DomainPlane PlaneOf(vtkDataSet* domain);

// The domain's bounds in its plane: umin, umax, vmin, vmax.
void PlanarBounds(vtkDataSet* domain, double bounds[4]);

// A new named array with `components` components and `tuples` tuples.
template <typename ArrayT>
vtkSmartPointer<ArrayT> NewArray(const char* name, int components = 1, vtkIdType tuples = 0)
{
  auto array = vtkSmartPointer<ArrayT>::New();
  array->SetName(name);
  array->SetNumberOfComponents(components);
  array->SetNumberOfTuples(tuples);
  return array;
}

// Input ports of the filters that take a field: 2D images and planar triangle meshes.
void AcceptPlanarDomains(vtkInformation* inputPortInformation);

// The complex is global: every process asks for the whole input (RequestUpdateExtent).
void RequestWholeInput(vtkInformation* inputInformation);

// Adds the arrays (smart pointers or raw) to `data` in the given order.
void AddArrays(vtkFieldData* data, std::initializer_list<vtkAbstractArray*> arrays);

// Field data: a double array `name` holding `values`.
void AddFieldNumbers(vtkFieldData* fieldData, const char* name, std::initializer_list<double> values);
}
