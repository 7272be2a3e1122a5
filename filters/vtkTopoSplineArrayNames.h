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
constexpr const char* CriticalCellId = "CriticalCellId"; // the critical vertex, edge or triangle
constexpr const char* SaddleEdgeVertexId = "SaddleEdgeVertexId"; // a saddle's other edge vertex; -1 else
constexpr const char* IsCornerTriangle = "IsCornerTriangle"; // a maximum whose triangle is its vertex's only one

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
constexpr const char* PieceSegments = "PieceSegments"; // cell data: cubic segments of the piece

// Junction points (point data of the "JunctionPoints" block; also SeparatrixType, MeshCellId
// and CriticalPointId, -1 where no saddle sits on the junction).
constexpr const char* ExtremumId = "ExtremumId";
constexpr const char* JunctionValue = "JunctionValue";
constexpr const char* NumberOfSeparatrices = "NumberOfSeparatrices";

// Reconstruction (point data of the input geometry).
constexpr const char* ReconstructedField = "Reconstructed";
constexpr const char* ReconstructionDifference = "Difference";
// F o Phi at the vertices before topological sampling.
constexpr const char* ExactReconstruction = "ReconstructedExact";
constexpr const char* ReconstructionCellId = "ReconstructionCellId";
// The resampled image: points that no reconstructed 2-cell covers are 0 here (VTK's name).
constexpr const char* ValidPointMask = "vtkValidPointMask";

// Field data of the complex: which input array it was computed from.
constexpr const char* ScalarFieldName = "TopoSplineScalarField";
// Field data of a simplified complex: vertices where boundary 1-cells turn inwards
// (MorseSmaleComplex::BoundaryJunctions).
constexpr const char* BoundaryJunctionVertexId = "BoundaryJunctionVertexId";
// The per-axis scales of the coordinates stages 3 and 4 work in (topospline::PlanarFrame).
constexpr const char* WorkingFrameScale = "WorkingFrameScale";

// Field data of "Simplify Morse-Smale Complex".
constexpr const char* CancelledLowerId = "CancelledLowerId";
constexpr const char* CancelledUpperId = "CancelledUpperId";
constexpr const char* SurvivorId = "SurvivorId";
constexpr const char* CancellationPersistence = "CancellationPersistence";
constexpr const char* AbsolutePersistenceThreshold = "AbsolutePersistenceThreshold";
constexpr const char* MaximumPersistence = "MaximumPersistence";
constexpr const char* BlockedCancellations = "BlockedCancellations";
constexpr const char* BlockedLowerId = "BlockedLowerId";
constexpr const char* BlockedUpperId = "BlockedUpperId";
constexpr const char* BlockedPersistence = "BlockedPersistence";
constexpr const char* BlockedReason = "BlockedReason";
constexpr const char* PersistenceCurvePercent = "PersistenceCurvePercent";
constexpr const char* PersistenceCurveCriticalPoints = "PersistenceCurveCriticalPoints";

// Field data of "Smooth 1-Cells".
constexpr const char* CurveSegments = "CurveSegments";
constexpr const char* NumberOfPieces = "NumberOfPieces";
constexpr const char* ShortPieces = "ShortPieces";
constexpr const char* OversegmentedPieces = "OversegmentedPieces";
constexpr const char* SuggestedCurveSegments = "SuggestedCurveSegments";
constexpr const char* SampledSamplesPerSegment = "SampledSamplesPerSegment";
constexpr const char* ErasedLoops = "ErasedLoops";
constexpr const char* DroppedCuts = "DroppedCuts";
constexpr const char* AdaptedPieces = "AdaptedPieces";
constexpr const char* RiseKnotPieces = "RiseKnotPieces";
constexpr const char* ContactKnotPieces = "ContactKnotPieces";
constexpr const char* CurveHeightPieces = "CurveHeightPieces";
constexpr const char* RefinedPieces = "RefinedPieces";
constexpr const char* PolylinePieces = "PolylinePieces";
constexpr const char* RemainingCrossings = "RemainingCrossings";
constexpr const char* PiecesOutsideDomain = "PiecesOutsideDomain";
constexpr const char* ClampedPieces = "ClampedPieces";
constexpr const char* L1Error = "L1Error";
constexpr const char* UnconstrainedL1Error = "UnconstrainedL1Error";
constexpr const char* JunctionMargin = "JunctionMargin";
constexpr const char* SpreadCriticalValues = "SpreadCriticalValues";
constexpr const char* MaximumSpread = "MaximumSpread";

// Field data of "Reconstruct 2-Cells" (on output port 0).
constexpr const char* TwoCells = "TwoCells";
constexpr const char* FailedTwoCells = "FailedTwoCells";
constexpr const char* NegligibleTwoCells = "NegligibleTwoCells";
constexpr const char* SlitTwoCells = "SlitTwoCells";
constexpr const char* ShiftedCorners = "ShiftedCorners";
constexpr const char* ViolatingPatches = "ViolatingPatches";
constexpr const char* LinearizedDiagonals = "LinearizedDiagonals";
constexpr const char* BezierTriangles = "BezierTriangles";
constexpr const char* MeshTriangles = "MeshTriangles";
constexpr const char* CrowdedTriangles = "CrowdedTriangles";
constexpr const char* PinchedTwoCells = "PinchedTwoCells";
constexpr const char* ResampledTwoCells = "ResampledTwoCells";
constexpr const char* OutsideSlitTwoCells = "OutsideSlitTwoCells";
constexpr const char* MaximumGridSize = "MaximumGridSize";
constexpr const char* FittedCells = "FittedCells";
constexpr const char* RefinedCells = "RefinedCells";
constexpr const char* StiffenedCells = "StiffenedCells";
constexpr const char* OrderedCells = "OrderedCells";
constexpr const char* RemappedCells = "RemappedCells";
constexpr const char* AxisFreeCells = "AxisFreeCells";
constexpr const char* SmallFittedCells = "SmallFittedCells";
constexpr const char* SnappedPoints = "SnappedPoints";
constexpr const char* PointsOnOneCells = "PointsOnOneCells";
constexpr const char* UnreconstructedPoints = "UnreconstructedPoints";
constexpr const char* MaximumError = "MaximumError";
constexpr const char* RMSError = "RMSError";
constexpr const char* ValueRange = "ValueRange";
constexpr const char* ParameterizationSeconds = "ParameterizationSeconds";
constexpr const char* SurfaceSeconds = "SurfaceSeconds";
constexpr const char* EvaluationSeconds = "EvaluationSeconds";
constexpr const char* SamplingChangedVertices = "SamplingChangedVertices";
constexpr const char* SamplingMaximumChange = "SamplingMaximumChange";
constexpr const char* SamplingChangedFraction = "SamplingChangedFraction";
constexpr const char* SamplingConverged = "SamplingConverged";
constexpr const char* SamplingDisplacedSaddles = "SamplingDisplacedSaddles";
constexpr const char* SamplingBlockedWaysUp = "SamplingBlockedWaysUp";
constexpr const char* SamplingMovedBoundarySaddles = "SamplingMovedBoundarySaddles";
constexpr const char* SamplingMovedInteriorSaddles = "SamplingMovedInteriorSaddles";
constexpr const char* SamplingWalkedSaddles = "SamplingWalkedSaddles";
constexpr const char* SamplingKeptExact = "SamplingKeptExact";
// Spurious critical points of F o Phi at the input vertices, within two grid spacings of a
// smoothed 1-cell and farther.
constexpr const char* RawSpuriousNearOneCells = "RawSpuriousNearOneCells";
constexpr const char* RawSpuriousFarFromOneCells = "RawSpuriousFarFromOneCells";
// Topology verification: per sampling (the prefixes RawInput, Input, Resampled), the found
// counts of minima, saddles, maxima and the largest distance of a matched point to its node.
constexpr const char* RawInputSampling = "RawInput";
constexpr const char* InputSampling = "Input";
constexpr const char* ResampledSampling = "Resampled";
constexpr const char* CriticalPointsSuffix = "CriticalPoints";
constexpr const char* CriticalPointDistanceSuffix = "CriticalPointDistance";
constexpr const char* ExpectedCriticalPoints = "ExpectedCriticalPoints";
constexpr const char* TopologyVerified = "TopologyVerified";
constexpr const char* SpuriousCriticalPoints = "SpuriousCriticalPoints"; // x, y, index, value
constexpr const char* MissingCriticalPoints = "MissingCriticalPoints";   // x, y, index, value
constexpr const char* VerificationSeconds = "VerificationSeconds";

// Point arrays of the synthetic sources.
constexpr const char* ShepardField = "Shepard";
constexpr const char* TrigonometricField = "Trigonometric";
}
