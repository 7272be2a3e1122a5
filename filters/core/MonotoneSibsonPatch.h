// Stage 4 of the paper (section 5.2): one element of the monotone surface on the unit square
// (MonotoneSibsonSurface.h builds the whole grid of them), a "modified Sibson" element after
// reference [2] of the paper (Allemand-Giorgis, Bonneau, Hahmann, Vivodtzev 2014;
// reconstructed in docs/Algorithms.md, 1).
//
// The element (one grid cell, local coordinates X, Y in [0,1], corners V00, V10, V11, V01,
// centre C) is cut by both diagonals into the cubic Bezier triangles
//   South (V00, V10, C), East (V10, V11, C), North (V11, V01, C), West (V01, V00, C).
// It is fixed by the value z and the scaled partials p = h dz/dx, q = h dz/dy at the corners.
// Every ordinate follows from C1 continuity except one per outer edge (b111), which is chosen
// so that the derivative D_(1,1)F = F_x + F_y is linear along every outer edge: the element is
// then C1 across grid edges, and h D_(1,1)F is a quadratic whose Bernstein coefficients are
// linear in the data. Their non-negativity gives the sufficient conditions (s = p + q,
// Delta = z11 - z00):
//   (C0) Delta > 0;
//   (C1) s >= 0 at the four corners (the surface builder asks s > 0 at interior grid nodes);
//   (C2) (5 p00 + q00)/4 + s10/2 + (p11 + 5 q11)/4 <= 3 Delta;
//   (C3) (p00 + 5 q00)/4 + s01/2 + (5 p11 + q11)/4 <= 3 Delta;
//   and (C2) or (C3) strict, which makes the coefficient at the centre positive.
// Under them D_(1,1)F > 0 on the open cell, so the gradient never vanishes there. The unit
// tests prove all of this numerically; nothing here is quoted from [2].
#pragma once

#include "CoreTypes.h"

#include <array>

namespace topospline
{
// Ordinates of a cubic Bezier triangle (A, B, C), b_ijk with i <-> A, j <-> B, k <-> C, stored
// in the order b300 b210 b201 b120 b111 b102 b030 b021 b012 b003.
constexpr int BezierOrdinateIndex(int i, int j)
{
  return (3 - i) * (4 - i) / 2 + (3 - i - j);
}
using CubicTriangleOrdinates = std::array<double, 10>;

// Corner data of one grid cell, corners in the order V00, V10, V11, V01 (counterclockwise).
struct SibsonCellData
{
  std::array<double, 4> Z = { { 0, 0, 0, 0 } };
  std::array<double, 4> P = { { 0, 0, 0, 0 } }; // h * dz/dx
  std::array<double, 4> Q = { { 0, 0, 0, 0 } }; // h * dz/dy
};

enum class SibsonTriangle
{
  South = 0,
  East = 1,
  North = 2,
  West = 3
};

// Which sufficient condition a cell violates (the first one, in this order).
enum class MonotonicityCondition
{
  Satisfied = 0,
  C0,              // z11 <= z00
  C1,              // p + q < 0 at a corner
  C2,              // (C2) fails
  C3,              // (C3) fails
  CentreNotPositive // (C2) and (C3) both hold with equality: D_(1,1)F(C) = 0
};
const char* MonotonicityConditionName(MonotonicityCondition condition);

// Left-hand sides of (C2) and (C3), to be compared with 3 (z11 - z00).
double ConditionC2LeftSide(const SibsonCellData& cell);
double ConditionC3LeftSide(const SibsonCellData& cell);

// Checks (C0)-(C3) of one cell; `tolerance` loosens every inequality by that amount (0: exact).
MonotonicityCondition CheckMonotonicityConditions(const SibsonCellData& cell, double tolerance = 0);

class MonotoneSibsonPatch
{
public:
  MonotoneSibsonPatch() = default;
  explicit MonotoneSibsonPatch(const SibsonCellData& cell) { this->SetData(cell); }

  // Computes the 40 ordinates (25 distinct) of the modified element.
  void SetData(const SibsonCellData& cell);
  const SibsonCellData& GetData() const { return this->Data; }

  const CubicTriangleOrdinates& GetOrdinates(SibsonTriangle t) const
  {
    return this->Ordinates[static_cast<int>(t)];
  }
  // Vertices A, B, C of a sub-triangle in local coordinates.
  static void GetTriangleVertices(SibsonTriangle t, double vertices[3][2]);
  // The sub-triangle that owns (X, Y) (points on a diagonal go to either; both agree).
  static SibsonTriangle LocateTriangle(double X, double Y);

  // Value at (X, Y) in [0,1]^2, and its gradient with respect to the local coordinates
  // (that is h * grad F: divide by h for the gradient in the grid's units).
  double Evaluate(double X, double Y) const;
  void EvaluateWithGradient(double X, double Y, double& value, double localGradient[2]) const;
  // Evaluate(X, Y) of `count` elements at once, bit for bit, with the point located once: the
  // fits weigh every sample by the 12 elements of unit corner data.
  static void EvaluateMany(const MonotoneSibsonPatch* patches, int count, double X, double Y, double* values);
  // The same restricted to one sub-triangle (extended polynomially outside it), so that both
  // sides of an interior half-diagonal can be compared.
  void EvaluateTriangle(SibsonTriangle t, double X, double Y, double& value, double localGradient[2]) const;

  // Bernstein coefficients of the quadratic h * D_(1,1)F on a sub-triangle, in the order
  // c200 c110 c101 c020 c011 c002 (i <-> A, j <-> B, k <-> C).
  std::array<double, 6> DiagonalDerivativeCoefficients(SibsonTriangle t) const;

private:
  SibsonCellData Data;
  std::array<CubicTriangleOrdinates, 4> Ordinates;
};
} // namespace topospline
