// Stage 1 of the paper (section 3.1): the discrete Morse-Smale complex of a PL scalar field on
// a planar triangulation: critical points, 1-cells, 2-cells, and the per-vertex
// ascending/descending manifolds that embed them.
#pragma once

#include "CoreTypes.h"
#include "DiscreteGradient.h"
#include "MorseSmaleComplex.h"
#include "TriangleMeshTopology.h"

#include <string>

namespace topospline
{
class MorseSmaleComplexExtraction
{
public:
  // Returns false with a message for inputs it refuses (the caller reports it).
  bool Extract(const PlanarScalarField& field, MorseSmaleComplex& complex, std::string& error);

  ParallelFor Parallel = SequentialFor;
  ProgressHooks Hooks;
  // Only the critical points (no 1-cells, 2-cells or manifolds): what a topology check needs,
  // in a fraction of the memory (samplings of tens of millions of vertices). field.Points may
  // then be empty.
  bool CriticalPointsOnly = false;
  // A field that varies by less than NearConstantRange of its magnitude is read as the
  // constant halfway between its extremes (its complex that of a constant field: ties ordered
  // by vertex id), and ReadAsConstant says so. The filter asks for it; a topology check of a
  // reconstruction must not (it judges the values as they are).
  bool NearConstantAsConstant = false;
  bool ReadAsConstant = false;
  // The field's mesh, if the caller has it already (it must be the mesh of field.Triangles or
  // of the grid, which may then be left empty); otherwise Mesh is built. Saves a second copy
  // of the largest structure.
  const TriangleMeshTopology* GivenMesh = nullptr;

  // Sorts `oneCells`, 1-cells of `extremum` (descending ones for a minimum, ascending ones for a
  // maximum), counter-clockwise around it. `saddleEnds` holds, per 1-cell, the point (x, y)
  // where it ends at its saddle beyond its stored path (the saddle edge's midpoint).
  static void SortAroundExtremum(const MorseSmaleComplex& complex, const std::vector<double>& saddleEnds,
    Index extremum, std::vector<Index>& oneCells);

  // The frame stages 3 and 4 work in (MorseSmaleComplex::Frame): from a grid's spacings or from
  // the root mean square dx and dy of a mesh's edges.
  static PlanarFrame DomainFrame(const PlanarScalarField& field);

  // Intermediate structures, kept for tests and later stages.
  TriangleMeshTopology Mesh;
  DiscreteGradient Gradient;

private:
  bool CheckField(const PlanarScalarField& field, std::string& error) const;
  // Extract after the checks and the near-constant reading: the field's complex as it is.
  bool ExtractChecked(const PlanarScalarField& field, MorseSmaleComplex& complex, std::string& error);
  const TriangleMeshTopology* PrepareMesh(const PlanarScalarField& field, std::string& error);
};
} // namespace topospline
