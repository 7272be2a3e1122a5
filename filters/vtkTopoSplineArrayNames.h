// Names of the blocks and arrays TopoSpline filters produce, defined once: downstream
// filters, tests and states rely on them, so never rename one that has shipped.
#pragma once

namespace vtkTopoSplineArrayNames
{
// Blocks of the complex (a vtkMultiBlockDataSet, in this order). The names are valid
// data-assembly node names, so ParaView selectors are simply "/Root/OneCells" etc.
constexpr const char* CriticalPointsBlock = "CriticalPoints";
constexpr const char* OneCellsBlock = "OneCells";
constexpr const char* TwoCellsBlock = "TwoCells";
constexpr const char* SegmentationBlock = "Segmentation";
enum BlockIndex
{
  CriticalPointsIndex = 0,
  OneCellsIndex = 1,
  TwoCellsIndex = 2,
  SegmentationIndex = 3,
  NumberOfBlocks = 4,
  // Only in simplified complexes: where 1-cells sharing an extremum merge.
  JunctionPointsIndex = 4,
  // Only after "Smooth 1-Cells".
  SmoothedOneCellsIndex = 5,
  SampledOneCellsIndex = 6
};
constexpr const char* JunctionPointsBlock = "JunctionPoints";
constexpr const char* SmoothedOneCellsBlock = "SmoothedOneCells";
constexpr const char* SampledOneCellsBlock = "SampledOneCells";

// Critical points (point data of the "CriticalPoints" block).
constexpr const char* CriticalPointId = "CriticalPointId";
constexpr const char* CriticalIndex = "CriticalIndex";
constexpr const char* CriticalValue = "CriticalValue";
constexpr const char* VertexId = "VertexId";
constexpr const char* IsOnBoundary = "IsOnBoundary";

// 1-cells (cell data of the "OneCells" block; point data: the scalar along the 1-cell).
constexpr const char* SeparatrixId = "SeparatrixId";
constexpr const char* SourceId = "SourceId";
constexpr const char* DestinationId = "DestinationId";
constexpr const char* SeparatrixType = "SeparatrixType"; // 0 descending (min-saddle), 1 ascending
constexpr const char* ScalarAlong = "ScalarValue";
constexpr const char* MeshCellId = "MeshCellId"; // vertex (descending) or triangle (ascending) id

// 2-cells (point data of the "TwoCells" block: one point per cell, at its centroid).
constexpr const char* TwoCellId = "TwoCellId";
constexpr const char* MinimumId = "MinimumId";
constexpr const char* MaximumId = "MaximumId";
constexpr const char* SaddleIds = "SaddleIds";             // 2 components
constexpr const char* BoundarySeparatrices = "BoundarySeparatrixIds"; // 4 components
constexpr const char* IsPouch = "IsPouch";
constexpr const char* NumberOfVertices = "NumberOfVertices";

// Segmentation (point data of the input geometry).
constexpr const char* AscendingManifoldId = "AscendingManifoldId";
constexpr const char* DescendingManifoldId = "DescendingManifoldId";

// Smoothed 1-cells (the "SmoothedOneCells" block): cell data PieceId, point data Height; field
// data listing every 1-cell's pieces.
constexpr const char* PieceId = "PieceId";
constexpr const char* Height = "Height";
constexpr const char* SeparatrixPieceOffsets = "SeparatrixPieceOffsets";
constexpr const char* SeparatrixPieces = "SeparatrixPieces";

// Reconstruction (point data of the input geometry).
constexpr const char* ReconstructedField = "Reconstructed";
constexpr const char* ReconstructionDifference = "Difference";
// F o Phi at the vertices before topological sampling.
constexpr const char* ExactReconstruction = "ReconstructedExact";

// Field data of the complex: which input array it was computed from.
constexpr const char* ScalarFieldName = "TopoSplineScalarField";
// Field data of a simplified complex: vertices where boundary 1-cells turn inwards
// (MorseSmaleComplex::BoundaryJunctions).
constexpr const char* BoundaryJunctionVertexId = "BoundaryJunctionVertexId";
}
