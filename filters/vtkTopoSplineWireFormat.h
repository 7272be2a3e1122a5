// The data that flows between the TopoSpline filters: one vtkMultiBlockDataSet whose blocks
// (named and numbered in vtkTopoSplineArrayNames.h) hold the complex and what the later stages
// add to it. Every block has its writer and its reader here, side by side, so that a block is
// read exactly as it was written:
//   0-3  CriticalPoints, OneCells, TwoCells, Segmentation   "Morse-Smale Complex" and later
//   4    JunctionPoints (for display)                       "Simplify Morse-Smale Complex"
//   5    SmoothedOneCells (cubic Bezier curves, heights)    "Smooth 1-Cells"
//   6    SampledOneCells (the same, densely sampled)        "Smooth 1-Cells", for display only
#pragma once

#include "MorseSmaleComplex.h" // core
#include "OneCellSmoothing.h"  // core

#include <vtkType.h>

#include <string>
#include <vector>

class vtkDataSet;
class vtkMultiBlockDataSet;

namespace vtkTopoSplineWireFormat
{
// Blocks 0-3. `domain` is the input geometry: it is shallow-copied into the "Segmentation"
// block with the per-vertex ids. `scalarName` names the input array the complex was computed
// from (field data), so that stage 4 can measure its errors against it.
void WriteComplex(const topospline::MorseSmaleComplex& complex, vtkDataSet* domain, const char* scalarName,
  vtkMultiBlockDataSet* output);
// Returns false with a message when `input` is not a complex.
bool ReadComplex(vtkMultiBlockDataSet* input, topospline::MorseSmaleComplex& complex, std::string& error);
// The "Segmentation" block (the input geometry), or nullptr.
vtkDataSet* SegmentationOf(vtkMultiBlockDataSet* input);
// The name of the input array the complex was computed from ("" if unknown).
std::string ScalarFieldNameOf(vtkMultiBlockDataSet* input);
// Copies blocks [0, count) of `input` (with their names) and its field data into `output`.
void PassBlocks(vtkMultiBlockDataSet* input, unsigned int count, vtkMultiBlockDataSet* output);

// Block 4: where 1-cells sharing an extremum merge (positions of `complex`, which the
// junctions refer to, are written as its stable ids). For display: stage 3 finds the junction
// points of any complex itself (JunctionPointDetection), so no filter reads this block back.
void WriteJunctionPoints(const topospline::MorseSmaleComplex& complex,
  const std::vector<topospline::JunctionPoint>& junctions, vtkMultiBlockDataSet* output);

// Blocks 5 and 6: every piece as VTK_BEZIER_CURVE cells of degree 3 with their heights, the
// pieces of every 1-cell, and (block 6) every 1-cell sampled at `samplesPerSegment` points per
// Bezier segment (0: block 6 left empty).
void WriteSmoothedOneCells(const topospline::MorseSmaleComplex& complex,
  const topospline::OneCellSmoothingResult& smoothed, int samplesPerSegment, vtkMultiBlockDataSet* output);
// The points block 6 takes at `samplesPerSegment` per Bezier segment: a piece is sampled once
// for every 1-cell that runs through it (merged 1-cells share pieces).
vtkIdType SampledOneCellPoints(
  const topospline::MorseSmaleComplex& complex, const topospline::OneCellSmoothingResult& smoothed, int samplesPerSegment);
// Returns false with a message when block 5 is absent or does not match `complex`.
bool ReadSmoothedOneCells(vtkMultiBlockDataSet* input, const topospline::MorseSmaleComplex& complex,
  topospline::OneCellSmoothingResult& smoothed, std::string& error);
}
