// Stage 3 of the paper (section 4, step 1): new scalar values for the junction points, where
// 1-cells merge or split, so that the values strictly increase along every 1-cell.
//
// The nodes are the critical points (fixed values) and the junction points (free values with
// their original field value f_j); a relation (lower, higher) says that two nodes follow each
// other along some 1-cell, lower first. Relations from all 1-cells form a DAG. The program is
// the paper's, written in inequality form (docs/Algorithms.md, 3.4):
//   minimize sum_j |x_j - f_j| over the free nodes, subject to
//   x_higher - x_lower >= margin for every relation, fixed nodes keeping their value.
// A junction shared by several 1-cells is one node, hence one value for all of them.
#pragma once

#include "CoreTypes.h"

#include <array>
#include <string>
#include <vector>

namespace topospline
{
struct JunctionValueNode
{
  double Value = 0;   // the fixed value of a critical point, or f_j of a junction point
  bool Fixed = false; // true for a critical point
};

class JunctionValueProgram
{
public:
  // The margin is MarginFraction times the value range of all nodes (max - min of their
  // values), so the result does not depend on the units of the field. 0.1% keeps the
  // junction values close to f_j while every piece of a 1-cell still rises by a visible
  // amount. When two fixed nodes are too close for that along some chain (d relations
  // between values f_a < f_b need f_b - f_a >= d * margin), the margin shrinks to
  // MarginSafety * min over such chains of (f_b - f_a) / d, so the program stays feasible
  // with room to spare; Margin below reports the value used.
  double MarginFraction = 1e-3;
  double MarginSafety = 0.5;
  // Fixed values closer than this fraction of the value scale (max of the range and of the
  // largest magnitude) per relation along a chain are spread apart (see Solve). 1e-11 leaves
  // the fits' smallest steps (MonotoneBSplineFit: 0.01 of a piece's rise / k, k <= 30) several
  // ulps apart, and keeps the raise well inside stage 4's consistency tolerance (1e-9 of a
  // cell's range): 1e-9 broke the paper's trigonometric field, whose extrema tie.
  static constexpr double SpreadingGap = 1e-11;

  // Relations only couple the free nodes of one connected component: by default every
  // component is its own (small) linear program and a lone junction is solved in closed
  // form (its value clamped to the bounds set by its fixed neighbours). The optimum is that
  // of the single global program; false builds that single program instead (for testing).
  bool SplitIntoComponents = true;
  // The components' programs are independent: solved on these threads (the same values).
  ParallelFor Parallel = SequentialFor;

  // values receives one value per node. Fixed nodes keep theirs exactly, unless two of them
  // are closer along a chain of d relations than d * SpreadingGap of the value scale (equal
  // values on plateaus and constant fields, which the complex orders by vertex id): the higher
  // ones are then raised just enough (SpreadCriticalValues, MaximumSpread). Returns false with
  // a message when the relations are not satisfiable: a cycle, a self relation, fixed nodes
  // in the wrong order along a chain (lower by more than the spreading allows), an index out
  // of range, non-finite values, or a solver failure.
  bool Solve(const std::vector<JunctionValueNode>& nodes, const std::vector<std::array<Index, 2>>& lowerThan,
    std::vector<double>& values, std::string& error);

  // About the last successful Solve.
  double Margin = 0;
  // The last Solve failed because the relations order nodes against each other: a cycle, or
  // fixed values in the wrong order along a chain.
  bool FoundOrderConflict = false;
  int SpreadCriticalValues = 0; // fixed values raised by the value spreading
  double MaximumSpread = 0;     // the largest such raise
  double TotalChange = 0;   // sum over free nodes of |x_j - f_j|
  double MaximumChange = 0; // max over free nodes of |x_j - f_j|
  int NumberOfPrograms = 0; // linear programs solved (components with more than one node)
  int LargestProgram = 0;   // free nodes in the largest of them
};
} // namespace topospline
