// Junction points of a Morse-Smale complex (paper, section 4; the input of stage 3): where the
// 1-cells that share an extremum split apart when followed from it. Stage 2 reports them with
// the simplified complex; stage 3 needs them for any complex, simplified or not, and cuts the
// 1-cells into pieces there.
#pragma once

#include "MorseSmaleComplex.h"

#include <vector>

namespace topospline
{
// The junction points of `complex`, in the form stage 1 and stage 2 produce (references to
// critical points are positions in its CriticalPoints). Reads only the critical points and
// the 1-cells (MeshCells, Points, Values), so a complex read back from its VTK form will do.
// Junctions come per kind (descending 1-cells first), each in the order in which the 1-cells
// (in order, followed from their extremum) first reach it; JunctionPoint::OneCells ascending.
std::vector<JunctionPoint> DetectJunctionPoints(const MorseSmaleComplex& complex);
} // namespace topospline
