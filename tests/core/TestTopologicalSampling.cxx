// Tests of topological sampling's own mechanisms on made-up fields: the floods remove the
// extrema noise adds and settle on plateaus, a dented boundary saddle gets a way up, a
// ridge running between two rows of vertices is carved in, a cut leaves no pit on its plateau
// of a triangle mesh, floods on a mesh whose ids follow no row settle (their regions spread
// harmonically), and wanted extrema taken away by
// the floods of the other kind are restored; relaxing toward the values before keeps every
// critical point; a corner saddle with no way up but through a wanted minimum is reported, one
// whose neighbour along the boundary can rise past it goes up there, and one with a free
// neighbour along the boundary moves there; a saddle lowered off its vertex comes
// back by the patterns of its link; a saddle walked a few vertex values off its node is walked
// back; a vertex a ridge and a valley both claim goes to the nearer one; a ridge carved beside a
// monkey saddle leaves the saddle's lower link whole. Each sampled result is checked by
// extracting its critical points again (stage 1) against the wanted complex. (The whole
// sequence on real reconstructions is tested in TestFieldReconstruction.)
//
// Usage: TestTopologicalSampling
// Prints figures per case, then "N passed, N failed"; returns nonzero on failure.
#include "MorseSmaleComplexExtraction.h"
#include "SyntheticFields.h"
#include "TestHarness.h"
#include "TestSupport.h"
#include "TopologicalSampling.h"
#include "TopologyVerification.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

using namespace topospline;

namespace
{
// A smooth field on a grid, its complex (the wanted one) and the sampling constraints it gives.
struct SamplingCase
{
  PlanarScalarField Field;
  MorseSmaleComplex Wanted;
  TriangleMeshTopology Mesh;
  SamplingConstraints Constraints;
};

// An nx x ny grid of unit spacing with value(i, j) at vertex (i, j).
PlanarScalarField UnitGrid(int nx, int ny, const std::function<double(int, int)>& value)
{
  PlanarScalarField field;
  field.GridDimensions[0] = nx;
  field.GridDimensions[1] = ny;
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i)
    {
      field.Points.insert(field.Points.end(), { double(i), double(j) });
      field.Values.push_back(value(i, j));
    }
  }
  return field;
}

// The triangles of an nx x ny grid with each square split along a random diagonal (valences 4
// to 8), grid vertex (i, j) numbered vertexOf(j * nx + i).
std::vector<Index> RandomDiagonalTriangles(
  int nx, int ny, std::mt19937_64& random, const std::function<Index(Index)>& vertexOf)
{
  std::vector<Index> triangles;
  std::bernoulli_distribution flip(0.5);
  for (int j = 0; j + 1 < ny; ++j)
  {
    for (int i = 0; i + 1 < nx; ++i)
    {
      const Index a = vertexOf(j * nx + i), b = vertexOf(j * nx + i + 1), c = vertexOf((j + 1) * nx + i),
                  d = vertexOf((j + 1) * nx + i + 1);
      const std::vector<Index> quad =
        flip(random) ? std::vector<Index>{ a, b, d, a, d, c } : std::vector<Index>{ a, b, c, b, d, c };
      triangles.insert(triangles.end(), quad.begin(), quad.end());
    }
  }
  return triangles;
}

// The sampling case of a smooth field on a grid: its complex and the constraints it gives.
SamplingCase SamplingCaseOf(const GridField& smooth)
{
  SamplingCase c;
  c.Field = FieldOnGrid(smooth);
  MorseSmaleComplexExtraction extraction;
  std::string error;
  CHECK(extraction.Extract(c.Field, c.Wanted, error));
  c.Mesh.BuildGrid(smooth.Dimensions[0], smooth.Dimensions[1], SequentialFor);
  c.Constraints = ComplexConstraints(c.Wanted, c.Mesh, c.Mesh, [](Index v) { return v; });
  return c;
}

// The trigonometric field on an 80 x 80 grid.
SamplingCase TrigonometricSamplingCase()
{
  return SamplingCaseOf(TrigonometricField(10, 80, -40));
}

// A seeded Shepard field of 12 sites on a 60 x 60 grid.
SamplingCase ShepardSamplingCase(std::uint64_t seed)
{
  return SamplingCaseOf(ShepardField(12, 2, 60, seed));
}
} // namespace

TEST_CASE(TopologicalSamplingRemovesNoiseExtrema)
{
  // A smooth field's complex is the wanted one; noise adds hundreds of small extrema, which
  // the flooding must remove, leaving exactly the smooth field's critical points, with values
  // moved by less than the noise amplitude.
  const SamplingCase smooth = TrigonometricSamplingCase();
  const PlanarScalarField& field = smooth.Field;
  const MorseSmaleComplex& wanted = smooth.Wanted;
  const TriangleMeshTopology& mesh = smooth.Mesh;
  const SamplingConstraints& constraints = smooth.Constraints;
  MorseSmaleComplexExtraction extraction;
  std::string error;
  for (int seed : { 1, 2, 3 })
  {
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> noise(-0.5, 0.5);
    PlanarScalarField noisy = field;
    for (double& v : noisy.Values)
    {
      v += noise(random);
    }
    MorseSmaleComplex before;
    CHECK(extraction.Extract(noisy, before, error));
    const auto report = EnforceCriticalVertices(mesh, constraints, noisy.Values);
    MorseSmaleComplex after;
    CHECK(extraction.Extract(noisy, after, error));
    const auto comparison = CompareCriticalPoints(CriticalPointLocations(wanted, field.Points),
      CriticalPointLocations(after, noisy.Points), 3.0);
    std::printf("  seed %d: %zu critical points, %zu with noise, %zu after (%d rounds, %d vertices moved, at most "
                "%.3g); %zu spurious, %zu missing within 3 spacings\n",
      seed, wanted.CriticalPoints.size(), before.CriticalPoints.size(), after.CriticalPoints.size(), report.Rounds,
      report.ChangedVertices, report.MaximumChange, comparison.Spurious.size(), comparison.Missing.size());
    CHECK(before.CriticalPoints.size() > 2 * wanted.CriticalPoints.size());
    CHECK(report.Converged);
    CHECK(comparison.Expected == comparison.Found);
    CHECK(report.MaximumChange <= 1.0 + 1e-12); // at most the noise range
  }
}

TEST_CASE(ACutLeavesNoPitOnItsPlateau)
{
  // A spurious peak B with A, C and D below it and above the outlet O: the cut lowers them to
  // O's level, ties ordered by id. A (id 0) lies inside the region, every neighbour (O, B, C, D)
  // on that level with a higher id: it was left a pit, which the next fill made a peak again,
  // round after round (a Delaunay mesh of the stress test, #288, where a vertex had those 4
  // neighbours only). Mesh: A at the centre, ring O, B, C, D at radius 1, 8 boundary vertices
  // at radius 2; the wanted complex is the one of the field without the peak.
  PlanarScalarField field;
  const Index ring1[4] = { 9, 1, 2, 3 };            // O, B, C, D at 0, 90, 180, 270 degrees
  const Index ring2[8] = { 4, 5, 6, 7, 8, 10, 11, 12 }; // every 45 degrees, from 0
  field.Points.assign(2 * 13, 0);
  for (int k = 0; k < 4; ++k)
  {
    field.Points[2 * ring1[k]] = std::cos(k * M_PI / 2);
    field.Points[2 * ring1[k] + 1] = std::sin(k * M_PI / 2);
  }
  for (int k = 0; k < 8; ++k)
  {
    field.Points[2 * ring2[k]] = 2 * std::cos(k * M_PI / 4);
    field.Points[2 * ring2[k] + 1] = 2 * std::sin(k * M_PI / 4);
  }
  for (int k = 0; k < 4; ++k)
  {
    const Index a = ring1[k], b = ring1[(k + 1) % 4];
    const Index r0 = ring2[2 * k], r1 = ring2[2 * k + 1], r2 = ring2[(2 * k + 2) % 8];
    field.Triangles.insert(field.Triangles.end(), { 0, a, b, a, r0, r1, a, r1, b, b, r1, r2 });
  }
  // Without the peak: a maximum at H (ring2 at 0 degrees), a minimum on the far side.
  field.Values = std::vector<double>(13, 0);
  const double ringValues[8] = { 2.0, 0.4, 0.3, 0.2, 0.1, 0.15, 0.25, 0.4 };
  for (int k = 0; k < 8; ++k)
  {
    field.Values[ring2[k]] = ringValues[k];
  }
  field.Values[0] = 0.35;  // A
  field.Values[9] = 0.5;   // O
  field.Values[1] = 0.33;  // B
  field.Values[2] = 0.15;  // C
  field.Values[3] = 0.3;   // D
  MorseSmaleComplexExtraction extraction;
  MorseSmaleComplex wanted;
  std::string error;
  CHECK(extraction.Extract(field, wanted, error));
  TriangleMeshTopology mesh;
  CHECK(mesh.Build(13, field.Triangles, SequentialFor, error));
  const SamplingConstraints constraints = ComplexConstraints(wanted, mesh, mesh, [](Index v) { return v; });

  PlanarScalarField peaked = field;
  peaked.Values[1] = 1.0;  // B, the spurious peak
  peaked.Values[2] = 0.9;  // C
  peaked.Values[3] = 0.85; // D
  peaked.Values[0] = 0.8;  // A
  const auto report = EnforceCriticalVertices(mesh, constraints, peaked.Values);
  MorseSmaleComplex after;
  CHECK(extraction.Extract(peaked, after, error));
  bool aIsCritical = false;
  for (const CriticalPoint& cp : after.CriticalPoints)
  {
    aIsCritical = aIsCritical || cp.Vertex == 0;
  }
  std::printf("  wanted %d/%d/%d, after the floods %d/%d/%d (%d rounds, converged %d); A critical: %d\n",
    wanted.CountByIndex()[0], wanted.CountByIndex()[1], wanted.CountByIndex()[2], after.CountByIndex()[0],
    after.CountByIndex()[1], after.CountByIndex()[2], report.Rounds, report.Converged ? 1 : 0, aIsCritical ? 1 : 0);
  CHECK(after.CountByIndex() == wanted.CountByIndex());
  CHECK(!aIsCritical);
  CHECK(report.Converged);
}

TEST_CASE(FloodsOnAnIrregularMeshSettle)
{
  // On a mesh whose vertex ids follow no row, a region re-valued on one level with ties ordered
  // by id is in a random order: a vertex inside it can have every neighbour before it (or after
  // it), the next flood of the other kind undoes the last by an ulp, and the rounds end without
  // converging, a spurious extremum left (stress seeds 41 and 67, Delaunay meshes). The floods
  // spread such regions by a harmonic order between their bounds instead. Here: a smooth field
  // on a jittered 40 x 40 grid with random diagonals (valences 4 to 8) and shuffled vertex ids,
  // noise and 30 bumps added (wide cuts and fills), 30 seeds; the wanted complex is the smooth
  // field's. Oracle, written here: the floods converge and leave no unwanted interior extremum
  // by (value, id) over whole links. The same inputs with ties first (as on an image) must fail
  // somewhere, or the case does not exercise what it tests.
  const int nx = 40, ny = 40;
  const Index n = Index(nx) * ny;
  MorseSmaleComplexExtraction extraction;
  std::string error;
  int spreadBad = 0, tiedBad = 0, cases = 0;
  const int bumps = 30;
  const double amplitude = 0.3;
  for (int seed = 1; seed <= 30; ++seed)
  {
    std::mt19937_64 random(seed);
    std::vector<Index> id(n);
    std::iota(id.begin(), id.end(), Index{ 0 });
    std::shuffle(id.begin(), id.end(), random);
    PlanarScalarField field;
    field.Points.resize(2 * n);
    field.Values.resize(n);
    std::uniform_real_distribution<double> jitter(-0.2, 0.2); // no triangle folds
    for (int j = 0; j < ny; ++j)
    {
      for (int i = 0; i < nx; ++i)
      {
        const Index v = id[j * nx + i];
        const bool edge = i == 0 || j == 0 || i == nx - 1 || j == ny - 1;
        const double x = i + (edge ? 0.0 : jitter(random)), y = j + (edge ? 0.0 : jitter(random));
        field.Points[2 * v] = x;
        field.Points[2 * v + 1] = y;
        field.Values[v] = std::sin(x / 6.0) * std::cos(y / 7.0) + 0.01 * x;
      }
    }
    field.Triangles = RandomDiagonalTriangles(nx, ny, random, [&id](Index v) { return id[v]; });
    TriangleMeshTopology mesh;
    CHECK(mesh.Build(n, field.Triangles, SequentialFor, error));
    MorseSmaleComplex wanted;
    if (!extraction.Extract(field, wanted, error))
    {
      std::printf("  seed %d: %s\n", seed, error.c_str());
      CHECK(false);
      continue;
    }
    const SamplingConstraints constraints = ComplexConstraints(wanted, mesh, mesh, [](Index v) { return v; });
    std::uniform_real_distribution<double> noise(-amplitude, amplitude), where(5, 35), sign(-1, 1);
    std::vector<double> noisy = field.Values;
    for (double& v : noisy)
    {
      v += noise(random);
    }
    for (int b = 0; b < bumps; ++b)
    {
      const double cx = where(random), cy = where(random), h = sign(random) > 0 ? 0.6 : -0.6;
      for (Index v = 0; v < n; ++v)
      {
        const double dx = field.Points[2 * v] - cx, dy = field.Points[2 * v + 1] - cy;
        noisy[v] += h * std::exp(-(dx * dx + dy * dy) / 6.0);
      }
    }
    std::vector<double> spread = noisy, tied = noisy;
    const auto a = EnforceCriticalVertices(mesh, constraints, spread, 6, nullptr, false);
    const auto t = EnforceCriticalVertices(mesh, constraints, tied, 6, nullptr, true);
    std::vector<std::vector<Index>> link(n);
    for (std::size_t tr = 0; tr < field.Triangles.size(); tr += 3)
    {
      for (int k = 0; k < 3; ++k)
      {
        for (int l = 1; l < 3; ++l)
        {
          link[field.Triangles[tr + k]].push_back(field.Triangles[tr + (k + l) % 3]);
        }
      }
    }
    std::vector<char> wantedExtremum(n, 0);
    for (const auto* list : { &constraints.Minima, &constraints.Maxima })
    {
      for (Index v : *list)
      {
        wantedExtremum[v] = 1;
      }
    }
    auto spurious = [&](const std::vector<double>& f) {
      int count = 0;
      for (Index v = 0; v < n; ++v)
      {
        if (mesh.IsBoundaryVertex(v) || wantedExtremum[v])
        {
          continue;
        }
        int lower = 0;
        for (Index w : link[v])
        {
          lower += (f[w] < f[v] || (f[w] == f[v] && w < v)) ? 1 : 0;
        }
        count += lower == 0 || lower == int(link[v].size()) ? 1 : 0;
      }
      return count;
    };
    const int sa = spurious(spread), st = spurious(tied);
    const bool badA = !a.Converged || sa > 0;
    const bool badT = !t.Converged || st > 0;
    spreadBad += badA ? 1 : 0;
    tiedBad += badT ? 1 : 0;
    ++cases;
    if (badA || badT)
    {
      std::printf("  seed %d: spread converged %d, %d spurious; tied converged %d, %d spurious\n", seed,
        int(a.Converged), sa, int(t.Converged), st);
    }
  }
  std::printf("  %d fields: unconverged or with a spurious extremum: %d spread, %d with ties first\n", cases,
    spreadBad, tiedBad);
  CHECK_EQ(spreadBad, 0);
  CHECK(tiedBad > 0);
}

TEST_CASE(BoundarySaddleAboveItsLinkGetsAWayUp)
{
  // A wanted boundary saddle (a maximum of the boundary curve) whose interior neighbours all
  // lie below it is a maximum of the sampling. Cutting it made it a pit of the boundary curve,
  // which the boundary pass filled again: the passes undid each other and never converged.
  // It must keep its value and get a rising path into the domain instead.
  const SamplingCase smooth = TrigonometricSamplingCase();
  const PlanarScalarField& field = smooth.Field;
  const TriangleMeshTopology& mesh = smooth.Mesh;
  const SamplingConstraints& constraints = smooth.Constraints;
  MorseSmaleComplexExtraction extraction;
  std::string error;
  CHECK(!constraints.BoundaryMaxima.empty());
  int tried = 0;
  for (Index saddle : constraints.BoundaryMaxima)
  {
    PlanarScalarField dented = field;
    for (Index i = mesh.VertexTriangleBegin(saddle); i < mesh.VertexTriangleEnd(saddle); ++i)
    {
      for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
      {
        if (!mesh.IsBoundaryVertex(w))
        {
          dented.Values[w] = std::min(dented.Values[w], field.Values[saddle] - 0.25);
        }
      }
    }
    const auto report = EnforceCriticalVertices(mesh, constraints, dented.Values);
    MorseSmaleComplex after;
    CHECK(extraction.Extract(dented, after, error));
    CHECK(report.Converged);
    CHECK(after.CountByIndex() == smooth.Wanted.CountByIndex());
    CHECK_EQ(dented.Values[saddle], field.Values[saddle]);
    ++tried;
  }
  std::printf("  %d boundary saddles dented, each converged with the wanted counts\n", tried);
}

TEST_CASE(TopologicalSamplingSettlesOnPlateaus)
{
  // Flat areas (terraces, lakes: thousands of vertices of one value) with pits and peaks in
  // them: filling a pit to just above the plateau made it a peak of the plateau, cutting that
  // made a pit again, by a few ulps per round, without end. The sweeps must settle and leave
  // exactly the wanted critical points.
  const SamplingCase smooth = TrigonometricSamplingCase();
  const PlanarScalarField& field = smooth.Field;
  const TriangleMeshTopology& mesh = smooth.Mesh;
  MorseSmaleComplexExtraction extraction;
  std::string error;
  const int nx = field.GridDimensions[0], ny = field.GridDimensions[1];
  int settled = 0, cases = 0;
  for (int seed : { 1, 2, 3, 4, 5, 6 })
  {
    std::mt19937_64 random(seed);
    PlanarScalarField terraced = field;
    std::uniform_int_distribution<int> centre(8, std::min(nx, ny) - 9);
    for (int disk = 0; disk < 6; ++disk)
    {
      const int ci = centre(random), cj = centre(random);
      const Index c = static_cast<Index>(cj) * nx + ci;
      // Far from wanted critical points, so that the flat area only adds spurious ones.
      bool nearWanted = false;
      for (const CriticalPoint& cp : smooth.Wanted.CriticalPoints)
      {
        nearWanted = nearWanted || std::hypot(field.Points[2 * cp.Vertex] - field.Points[2 * c],
                                     field.Points[2 * cp.Vertex + 1] - field.Points[2 * c + 1]) < 8;
      }
      if (nearWanted)
      {
        continue;
      }
      const double level = field.Values[c];
      for (int j = cj - 5; j <= cj + 5; ++j)
      {
        for (int i = ci - 5; i <= ci + 5; ++i)
        {
          if ((i - ci) * (i - ci) + (j - cj) * (j - cj) <= 25)
          {
            terraced.Values[static_cast<Index>(j) * nx + i] = level;
          }
        }
      }
      terraced.Values[c + 1] = level - 0.1; // a pit
      terraced.Values[c - 2 * nx] = level - 0.1;
      terraced.Values[c + 2 * nx] = level + 0.1; // a peak
    }
    const auto report = EnforceCriticalVertices(mesh, smooth.Constraints, terraced.Values);
    MorseSmaleComplex after;
    CHECK(extraction.Extract(terraced, after, error));
    const bool exact = after.CountByIndex() == smooth.Wanted.CountByIndex();
    std::printf("  seed %d: %d rounds, converged %d, counts %s\n", seed, report.Rounds, report.Converged ? 1 : 0,
      exact ? "exact" : "wrong");
    CHECK(report.Converged);
    CHECK(exact);
    settled += report.Converged && exact ? 1 : 0;
    ++cases;
  }
  std::printf("  %d of %d terraced fields settled with the wanted counts\n", settled, cases);
}

TEST_CASE(NarrowRidgeBetweenRowsIsCarvedIn)
{
  // A ridge (an ascending 1-cell) rising slowly along x while it wanders between two rows of
  // vertices: every vertex lies on a flank, at a distance from the crest that changes from
  // column to column, so the sampled ridge breaks into islands, each a spurious maximum that
  // the floods would cut down. Carving the 1-cell in must leave one rising chain of vertices
  // along it: no maximum on the way, values changed by less than the ridge's relief there.
  const int nx = 60, ny = 11;
  const double startX = 5, endX = 50;
  auto crest = [](double x) { return 5 + 0.45 * std::sin(0.7 * x); };
  auto height = [&](double x) { return 0.01 * std::min(x, endX) - 0.05 * std::max(0.0, x - endX); };
  PlanarScalarField field = UnitGrid(nx, ny, [&](int i, int j) { return height(i) - 10 * std::abs(j - crest(i)); });
  TriangleMeshTopology mesh;
  mesh.BuildGrid(nx, ny, SequentialFor);
  auto vertexNear = [&](double x, double y) { return static_cast<Index>(std::lround(y)) * nx + std::lround(x); };
  SamplingConstraints constraints;
  SaddleOneCell ridge;
  ridge.Saddle = vertexNear(startX, crest(startX));
  ridge.Ascending = true;
  for (double x = startX; x <= endX + 1e-9; x += 0.125)
  {
    ridge.Points.insert(ridge.Points.end(), { x, crest(x), height(x) });
  }
  constraints.OneCells.push_back(ridge);
  constraints.Saddles.push_back(ridge.Saddle);
  constraints.Maxima.push_back(vertexNear(endX, crest(endX)));
  // Interior maxima along the ridge, away from its two ends.
  auto maximaOnTheWay = [&](const std::vector<double>& values) {
    int count = 0;
    for (int j = 1; j + 1 < ny; ++j)
    {
      for (int i = static_cast<int>(startX) + 2; i <= static_cast<int>(endX) - 2; ++i)
      {
        const Index v = static_cast<Index>(j) * nx + i;
        bool highest = true;
        for (Index i2 = mesh.VertexTriangleBegin(v); i2 < mesh.VertexTriangleEnd(v); ++i2)
        {
          for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i2)])
          {
            highest = highest && (w == v || values[w] < values[v] || (values[w] == values[v] && w < v));
          }
        }
        count += highest ? 1 : 0;
      }
    }
    return count;
  };
  // The wanted maximum carries its critical value, the ridge's height at its end, as
  // TopologicalSampling::Apply gives every node's vertex before carving.
  field.Values[constraints.Maxima[0]] = height(endX);
  std::vector<double> carved = field.Values;
  const int before = maximaOnTheWay(carved);
  const Index changed = CarveOneCells(field, mesh, constraints, 1.0, carved);
  const int after = maximaOnTheWay(carved);
  // Carved only where the walk turns back: no maximum left either, and no more vertices changed.
  std::vector<double> gently = field.Values;
  const Index gentlyChanged = CarveOneCells(field, mesh, constraints, 1.0, gently, OneCellCarving::JustPastTheWalk);
  std::printf("  carved only where the walk turns back: %d maxima along the ridge, %d vertices raised\n",
    maximaOnTheWay(gently), gentlyChanged);
  CHECK_EQ(maximaOnTheWay(gently), 0);
  CHECK(gentlyChanged <= changed);
  double largestChange = 0;
  for (std::size_t v = 0; v < carved.size(); ++v)
  {
    largestChange = std::max(largestChange, std::abs(carved[v] - field.Values[v]));
  }
  std::printf("  %d maxima along the ridge before carving, %d after; %d vertices raised, by at most %.3g\n", before,
    after, changed, largestChange);
  CHECK(before >= 5);
  CHECK_EQ(after, 0);
  CHECK(largestChange <= 10 * 0.5 + 1e-9); // at most the fall from the crest to a vertex half a row away
  CHECK_EQ(carved[ridge.Saddle], field.Values[ridge.Saddle]);
}

TEST_CASE(RidgeOnTheBoundaryRowIsNotCarvedBesideIt)
{
  // An ascending 1-cell a third of a row inside the top boundary, rising along x; the first row
  // inside dips at every other vertex, so that a walk along it turns back down there. Where the
  // boundary row is the crest (as high as the 1-cell), carving only where needed leaves the
  // first row inside as it is: raising it would only put a second ridge beside the boundary
  // one. Where the crest lies inside and the boundary row runs lower, the dips of that row are
  // raised to the 1-cell.
  const int nx = 40, ny = 8;
  const double crestY = ny - 1 - 1.0 / 3;
  auto height = [](double x) { return 0.01 * x; };
  for (const bool onBoundary : { true, false })
  {
    const PlanarScalarField field = UnitGrid(nx, ny, [&](int i, int j) {
      return height(i) - 10 * std::abs(j - (onBoundary ? ny - 1 : crestY)) - (j == ny - 2 && i % 2 == 1 ? 0.03 : 0.0);
    });
    TriangleMeshTopology mesh;
    mesh.BuildGrid(nx, ny, SequentialFor);
    SamplingConstraints constraints;
    SaddleOneCell ridge;
    ridge.Saddle = static_cast<Index>(ny - 2) * nx + 2;
    ridge.Ascending = true;
    for (double x = 2; x <= nx - 3 + 1e-9; x += 0.125)
    {
      ridge.Points.insert(ridge.Points.end(), { x, crestY, height(x) });
    }
    constraints.OneCells.push_back(ridge);
    constraints.Saddles.push_back(ridge.Saddle);
    std::vector<double> carved = field.Values;
    CarveOneCells(field, mesh, constraints, 1.0, carved, OneCellCarving::WhereNeeded);
    std::vector<double> carvedEverywhere = field.Values;
    CarveOneCells(field, mesh, constraints, 1.0, carvedEverywhere, OneCellCarving::Everywhere);
    int raisedInside = 0, changedOnBoundary = 0, raisedInsideEverywhere = 0;
    for (int i = 0; i < nx; ++i)
    {
      raisedInside += carved[static_cast<Index>(ny - 2) * nx + i] > field.Values[static_cast<Index>(ny - 2) * nx + i];
      raisedInsideEverywhere +=
        carvedEverywhere[static_cast<Index>(ny - 2) * nx + i] > field.Values[static_cast<Index>(ny - 2) * nx + i];
      changedOnBoundary += carved[static_cast<Index>(ny - 1) * nx + i] != field.Values[static_cast<Index>(ny - 1) * nx + i];
    }
    std::printf("  crest %s: %d vertices of the first row inside raised (carving every walked vertex: %d), %d "
                "boundary vertices changed\n",
      onBoundary ? "on the boundary row" : "a third of a row inside", raisedInside, raisedInsideEverywhere,
      changedOnBoundary);
    CHECK_EQ(changedOnBoundary, 0);
    CHECK(onBoundary ? raisedInside == 0 : raisedInside > nx / 4);
    // Apply's fallback carves every walked vertex, as before.
    CHECK(raisedInsideEverywhere > nx / 2);
  }
}

TEST_CASE(WantedExtremaSurviveTheOtherKindsFloods)
{
  // Noise as strong as the field: a wanted minimum often ends up beside a spurious peak that
  // the downward flood cuts below it (and a wanted maximum beside a filled pit). After the
  // floods, RestoreWantedExtrema with floods again (as TopologicalSampling::Apply runs them)
  // must leave every wanted extremum an extremum and no other one, checked here on the links.
  // Extrema every few vertices (an egg crate on 40 x 40), so that they are often neighbours
  // of the noise's spurious ones.
  const int n = 40;
  SamplingCase smooth;
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      smooth.Field.Points.insert(smooth.Field.Points.end(), { double(i), double(j) });
      smooth.Field.Values.push_back(std::sin(0.9 * i + 0.3) * std::cos(0.8 * j + 0.2) + 0.01 * i);
    }
  }
  smooth.Field.GridDimensions[0] = smooth.Field.GridDimensions[1] = n;
  MorseSmaleComplexExtraction extraction;
  std::string error;
  CHECK(extraction.Extract(smooth.Field, smooth.Wanted, error));
  smooth.Mesh.BuildGrid(n, n, SequentialFor);
  smooth.Constraints = ComplexConstraints(smooth.Wanted, smooth.Mesh, smooth.Mesh, [](Index v) { return v; });
  const TriangleMeshTopology& mesh = smooth.Mesh;
  const SamplingConstraints& constraints = smooth.Constraints;
  const double amplitude = 1.0; // half the field's range
  // Interior extrema by their whole link, in (value, id) order; boundary vertices are left to
  // the boundary rule.
  auto interiorExtrema = [&](const std::vector<double>& values, bool minimum) {
    std::vector<Index> found;
    for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
    {
      if (mesh.IsBoundaryVertex(v))
      {
        continue;
      }
      bool extremum = true;
      for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v) && extremum; ++i)
      {
        for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
        {
          const bool below = values[w] < values[v] || (values[w] == values[v] && w < v);
          extremum = extremum && (w == v || below != minimum);
        }
      }
      if (extremum)
      {
        found.push_back(v);
      }
    }
    return found;
  };
  auto interiorOnly = [&](std::vector<Index> wanted) {
    wanted.erase(std::remove_if(wanted.begin(), wanted.end(), [&](Index v) { return mesh.IsBoundaryVertex(v); }),
      wanted.end());
    std::sort(wanted.begin(), wanted.end());
    return wanted;
  };
  int lostByFloods = 0;
  for (int seed : { 1, 2, 3, 4 })
  {
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> noise(-amplitude, amplitude);
    std::vector<double> values = smooth.Field.Values;
    for (double& v : values)
    {
      v += noise(random);
    }
    for (const auto* wanted : { &constraints.Minima, &constraints.Maxima })
    {
      for (Index v : *wanted)
      {
        values[v] = smooth.Field.Values[v]; // the nodes carry their critical values
      }
    }
    EnforceCriticalVertices(mesh, constraints, values);
    const auto minimaAfterFloods = interiorExtrema(values, true);
    const auto maximaAfterFloods = interiorExtrema(values, false);
    const int lost = static_cast<int>(interiorOnly(constraints.Minima).size() - minimaAfterFloods.size() +
      interiorOnly(constraints.Maxima).size() - maximaAfterFloods.size());
    lostByFloods += lost;
    int rounds = 0;
    while (rounds < 4 && RestoreWantedExtrema(mesh, constraints, values) > 0)
    {
      EnforceCriticalVertices(mesh, constraints, values);
      ++rounds;
    }
    const auto minima = interiorExtrema(values, true);
    const auto maxima = interiorExtrema(values, false);
    std::printf("  seed %d: %d wanted interior extrema lost by the floods alone, %d restoring round(s); %zu/%zu "
                "interior minima/maxima, %zu/%zu wanted\n",
      seed, lost, rounds, minima.size(), maxima.size(), interiorOnly(constraints.Minima).size(),
      interiorOnly(constraints.Maxima).size());
    CHECK(minima == interiorOnly(constraints.Minima));
    CHECK(maxima == interiorOnly(constraints.Maxima));
  }
  CHECK(lostByFloods > 0); // the case exercises what it tests
}

TEST_CASE(RelaxingTowardTargetsKeepsEveryCriticalPoint)
{
  // The steps around the floods move values past what the critical points need;
  // RelaxTowardTargets moves them back toward the values before. Oracle, written here: every
  // vertex keeps the shape of its lower link (counted from the triangle list), edges at the
  // boundary keep their order, stage 1 finds the same critical cells, no vertex ends farther
  // from its target, and
  // wanted extrema that a step before lifted out of their pits (peaks) go back to their values.
  // On the trigonometric field with noise, flooded to the smooth field's critical points, on its
  // grid and on the same points with random diagonals, with values as they come and rounded to
  // a few levels (ties everywhere, ordered by id).
  const GridField smooth = TrigonometricField(10, 40, -20);
  const int nx = smooth.Dimensions[0], ny = smooth.Dimensions[1];
  MorseSmaleComplexExtraction extraction;
  std::string error;
  for (int seed : { 1, 2, 3 })
  {
    for (bool randomDiagonals : { false, true })
    {
      for (bool rounded : { false, true })
      {
        std::mt19937_64 random(seed);
        PlanarScalarField field = FieldOnGrid(smooth);
        TriangleMeshTopology mesh;
        if (randomDiagonals)
        {
          field.Triangles = RandomDiagonalTriangles(nx, ny, random, [](Index v) { return v; });
          field.GridDimensions[0] = field.GridDimensions[1] = 0;
          CHECK(mesh.Build(nx * ny, field.Triangles, SequentialFor, error));
        }
        else
        {
          mesh.BuildGrid(nx, ny, SequentialFor);
        }
        MorseSmaleComplex wanted;
        CHECK(extraction.Extract(field, wanted, error));
        const SamplingConstraints constraints = ComplexConstraints(wanted, mesh, mesh, [](Index v) { return v; });
        std::uniform_real_distribution<double> noise(-0.3, 0.3);
        PlanarScalarField noisy = field;
        for (double& v : noisy.Values)
        {
          v += noise(random);
          v = rounded ? std::round(4 * v) / 4 : v;
        }
        const std::vector<double> targets = noisy.Values;
        // On the grid its ids run along the rows (ties on one level); with random diagonals the
        // floods spread what they re-value (as on any mesh but an image).
        EnforceCriticalVertices(mesh, constraints, noisy.Values, 6, nullptr, !randomDiagonals);
        // The floods alone change nothing they need not; the steps around them do (a carved
        // chain lifts a wanted minimum, RestoreWantedExtrema puts it just below its lowest
        // neighbour; a vertex beside a chain is raised past it). Such slack, made here without
        // changing any order: every second interior wanted extremum goes just past its extreme
        // neighbour, and a third of the other vertices to a random value between their
        // neighbours below and above.
        auto link = [&mesh](Index v) {
          std::vector<Index> result;
          for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v); ++i)
          {
            for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
            {
              if (w != v)
              {
                result.push_back(w);
              }
            }
          }
          return result;
        };
        auto below = [](const std::vector<double>& f, Index a, Index b) { return f[a] < f[b] || (f[a] == f[b] && a < b); };
        const double infinity = std::numeric_limits<double>::infinity();
        std::vector<std::pair<Index, double>> lifted; // vertex, value after the floods
        std::vector<char> extremum(noisy.Values.size(), 0);
        for (const auto* extrema : { &constraints.Minima, &constraints.Maxima })
        {
          const bool minima = extrema == &constraints.Minima;
          for (std::size_t e = 0; e < extrema->size(); ++e)
          {
            const Index v = (*extrema)[e];
            extremum[v] = 1;
            if (e % 2 == 1 || mesh.IsBoundaryVertex(v))
            {
              continue;
            }
            double extreme = minima ? infinity : -infinity;
            bool isExtremum = true; // the floods may leave a few without converging
            for (Index w : link(v))
            {
              extreme = minima ? std::min(extreme, noisy.Values[w]) : std::max(extreme, noisy.Values[w]);
              isExtremum = isExtremum && below(noisy.Values, v, w) == minima;
            }
            if (isExtremum)
            {
              lifted.emplace_back(v, noisy.Values[v]);
              noisy.Values[v] = std::nextafter(extreme, minima ? -infinity : infinity);
            }
          }
        }
        std::uniform_real_distribution<double> unit(0, 1);
        for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
        {
          if (extremum[v] || unit(random) > 1.0 / 3)
          {
            continue;
          }
          double low = noisy.Values[v] - 1, high = noisy.Values[v] + 1;
          for (Index w : link(v))
          {
            (below(noisy.Values, w, v) ? low : high) = below(noisy.Values, w, v)
              ? std::max(low, std::nextafter(noisy.Values[w], infinity))
              : std::min(high, std::nextafter(noisy.Values[w], -infinity));
          }
          noisy.Values[v] = low < high ? low + (high - low) * unit(random) : noisy.Values[v];
        }
        const std::vector<double> flooded = noisy.Values;
        MorseSmaleComplex before;
        CHECK(extraction.Extract(noisy, before, error));
        const Index moves = RelaxTowardTargets(mesh, targets, noisy.Values);
        MorseSmaleComplex after;
        CHECK(extraction.Extract(noisy, after, error));

        // Every vertex keeps its lower link's shape: the number of pieces (vertices below less
        // link edges below: the link is a cycle or, on the boundary, a path) and whether it is
        // empty or whole, counted here from the triangle list. Edges at the boundary keep their
        // order (stage 1 judges boundary vertices along the boundary curve too); inside, edges
        // may flip where no kind changes.
        const std::vector<Index> triangles = randomDiagonals ? field.Triangles : GridTriangles(nx, ny);
        auto shapes = [&](const std::vector<double>& f) {
          std::vector<std::array<int, 3>> linkBelow(f.size(), { 0, 0, 0 }); // vertices, edges, all
          std::vector<std::vector<Index>> link(f.size());
          for (std::size_t t = 0; t < triangles.size(); t += 3)
          {
            for (int k = 0; k < 3; ++k)
            {
              const Index u = triangles[t + k], a = triangles[t + (k + 1) % 3], b = triangles[t + (k + 2) % 3];
              link[u].push_back(a);
              link[u].push_back(b);
              linkBelow[u][1] += below(f, a, u) && below(f, b, u) ? 1 : 0;
            }
          }
          std::vector<std::array<int, 3>> shape(f.size());
          for (std::size_t u = 0; u < f.size(); ++u)
          {
            std::sort(link[u].begin(), link[u].end());
            link[u].erase(std::unique(link[u].begin(), link[u].end()), link[u].end());
            int lower = 0;
            for (Index a : link[u])
            {
              lower += below(f, a, Index(u)) ? 1 : 0;
            }
            shape[u] = { lower - linkBelow[u][1], lower == 0 ? 1 : 0, lower == int(link[u].size()) ? 1 : 0 };
          }
          return shape;
        };
        const auto shapesBefore = shapes(flooded), shapesAfter = shapes(noisy.Values);
        Index reshaped = 0, flipped = 0, flippedAtBoundary = 0;
        for (std::size_t u = 0; u < shapesBefore.size(); ++u)
        {
          reshaped += shapesBefore[u] != shapesAfter[u] ? 1 : 0;
        }
        for (std::size_t t = 0; t < triangles.size(); t += 3)
        {
          for (int e = 0; e < 3; ++e)
          {
            const Index a = triangles[t + e], b = triangles[t + (e + 1) % 3];
            const bool flip = below(flooded, a, b) != below(noisy.Values, a, b);
            flipped += flip ? 1 : 0;
            flippedAtBoundary += flip && (mesh.IsBoundaryVertex(a) || mesh.IsBoundaryVertex(b)) ? 1 : 0;
          }
        }
        auto cells = [](const MorseSmaleComplex& complex) {
          std::vector<std::pair<Index, int>> result;
          for (const CriticalPoint& cp : complex.CriticalPoints)
          {
            result.emplace_back(cp.Vertex, cp.MorseIndex);
          }
          std::sort(result.begin(), result.end());
          return result;
        };
        double farther = 0, distanceBefore = 0, distanceAfter = 0;
        Index changedBefore = 0, changedAfter = 0;
        for (std::size_t v = 0; v < targets.size(); ++v)
        {
          const double d0 = std::abs(flooded[v] - targets[v]), d1 = std::abs(noisy.Values[v] - targets[v]);
          farther = std::max(farther, d1 - d0);
          distanceBefore += d0;
          distanceAfter += d1;
          changedBefore += d0 > 0 ? 1 : 0;
          changedAfter += d1 > 0 ? 1 : 0;
        }
        std::printf("  seed %d, %s, %s: %zu critical points; flooding changed %d vertices (sum %.3f), after %d "
                    "moves %d (sum %.3f); %d edge sides flipped, %d at the boundary; %d vertices reshaped\n",
          seed, randomDiagonals ? "random diagonals" : "grid", rounded ? "rounded" : "continuous",
          after.CriticalPoints.size(), int(changedBefore), distanceBefore, int(moves), int(changedAfter),
          distanceAfter, int(flipped), int(flippedAtBoundary), int(reshaped));
        Index back = 0; // lifted extrema back on their values after the floods, or nearer their targets
        for (const auto& [v, value] : lifted)
        {
          // Within an ulp: a pit the floods filled beside it may stand on its value, above it by
          // id. Nearer: where the floods spread a cut beside it, the extremum may follow its
          // neighbours on toward its own target.
          back += std::abs(noisy.Values[v] - targets[v]) <= std::abs(value - targets[v]) + 1e-15 * (1 + std::abs(value))
            ? 1
            : 0;
        }
        std::printf("    %zu extrema lifted, %d back on their values\n", lifted.size(), int(back));
        CHECK(!lifted.empty() && back == Index(lifted.size()));
        CHECK_EQ(reshaped, Index(0));
        CHECK_EQ(flippedAtBoundary, Index(0));
        CHECK(cells(after) == cells(before));
        CHECK(farther <= 0);
        CHECK(moves > 0 && distanceAfter < 0.9 * distanceBefore); // the case exercises what it tests
      }
    }
  }
}

TEST_CASE(ACornerSaddleWithoutAWayUpIsReported)
{
  // A wanted boundary saddle at (0, 1) of a 5 x 5 ramp stands above its whole link, and its only
  // interior neighbour, (1, 1), is a wanted minimum (stress case #38 had this in a corner): its
  // way up can only run through the minimum, which no value at these vertices can keep, and
  // EnforceCriticalVertices names it. With (1, 1) not wanted the way up runs through it
  // unreported.
  constexpr int n = 5;
  const PlanarScalarField field = UnitGrid(n, n, [](int i, int j) {
    return i == 0 && j == 1 ? 5.0 : (i == 1 && j == 1 ? -1.0 : double(i + j));
  });
  TriangleMeshTopology mesh;
  mesh.BuildGrid(n, n, SequentialFor);
  const Index corner = 0, saddle = n, pit = n + 1, top = n * n - 1, side = 2 * n;
  for (bool pitWanted : { true, false })
  {
    SamplingConstraints constraints;
    constraints.Minima = pitWanted ? std::vector<Index>{ pit } : std::vector<Index>{};
    constraints.Maxima = { top };
    constraints.BoundaryMinima = { corner, side };
    constraints.BoundaryMaxima = { saddle, top };
    std::vector<double> values = field.Values;
    std::vector<Index> blocked;
    EnforceCriticalVertices(mesh, constraints, values, 6, &blocked);
    std::sort(blocked.begin(), blocked.end());
    blocked.erase(std::unique(blocked.begin(), blocked.end()), blocked.end());
    std::printf("  minimum at (1, 1) wanted: %d; blocked ways up: %zu (saddle %s); (1, 1) now %.3g, (0, 1) %.3g\n",
      pitWanted ? 1 : 0, blocked.size(), blocked.empty() ? "-" : std::to_string(blocked[0]).c_str(), values[pit],
      values[saddle]);
    CHECK(blocked == (pitWanted ? std::vector<Index>{ saddle } : std::vector<Index>{}));
  }
}

TEST_CASE(ACornerSaddleGoesUpAlongTheBoundaryWhereItCan)
{
  // The corner of the test above, on a ramp that rises faster along i: the boundary vertex
  // (1, 0) lies between (0, 0) and (2, 0) along the boundary, and (2, 0) stands above the
  // saddle, so raising (1, 0) past the saddle changes nothing along the boundary and gives it a
  // way up that takes no wanted point (stress seed 29, #57: the interior search raised the
  // minimum instead). The oracle: stage 1 run again on the result has a minimum at (1, 1), a
  // saddle at (0, 1) and no maximum there, and the counts of the wanted complex.
  constexpr int n = 5;
  const PlanarScalarField field = UnitGrid(n, n, [](int i, int j) {
    return i == 0 && j == 1 ? 5.0 : (i == 1 && j == 1 ? -1.0 : double(3 * i + j));
  });
  TriangleMeshTopology mesh;
  mesh.BuildGrid(n, n, SequentialFor);
  const Index corner = 0, saddle = n, pit = n + 1, top = n * n - 1, side = 2 * n, along = 1;
  SamplingConstraints constraints;
  constraints.Minima = { pit };
  constraints.Maxima = { top };
  constraints.BoundaryMinima = { corner, side };
  constraints.BoundaryMaxima = { saddle, top };
  MorseSmaleComplexExtraction extraction;
  MorseSmaleComplex wanted, after;
  std::string error;
  CHECK(extraction.Extract(field, wanted, error)); // the input's, with the pair below
  PlanarScalarField sampled = field;
  std::vector<Index> blocked;
  const auto report = EnforceCriticalVertices(mesh, constraints, sampled.Values, 6, &blocked);
  CHECK(report.Converged);
  CHECK(blocked.empty());
  CHECK_EQ(sampled.Values[pit], -1.0);
  CHECK(sampled.Values[along] > sampled.Values[saddle] && sampled.Values[along] < sampled.Values[2]);
  CHECK(extraction.Extract(sampled, after, error));
  std::vector<std::pair<Index, int>> atTheCorner;
  for (const CriticalPoint& point : after.CriticalPoints)
  {
    if (point.Vertex == saddle || point.Vertex == pit || point.Vertex == along)
    {
      atTheCorner.emplace_back(point.Vertex, point.MorseIndex);
    }
  }
  std::sort(atTheCorner.begin(), atTheCorner.end());
  CHECK(atTheCorner == (std::vector<std::pair<Index, int>>{ { saddle, 1 }, { pit, 0 } }));
  // The input's own complex less the pair the sampling takes out: the maximum at (0, 1) (its
  // whole link lies below it) and the saddle at (1, 0) (the pit (1, 1) is a piece of its lower
  // link that touches neither boundary neighbour).
  const auto pointsOf = [](const MorseSmaleComplex& complex) {
    std::vector<std::pair<Index, int>> points;
    for (const CriticalPoint& point : complex.CriticalPoints)
    {
      points.emplace_back(point.Vertex, point.MorseIndex);
    }
    std::sort(points.begin(), points.end());
    return points;
  };
  std::vector<std::pair<Index, int>> expected = pointsOf(wanted);
  CHECK(std::count(expected.begin(), expected.end(), std::pair<Index, int>{ saddle, 2 }) == 1);
  CHECK(std::count(expected.begin(), expected.end(), std::pair<Index, int>{ along, 1 }) == 1);
  expected.erase(std::remove_if(expected.begin(), expected.end(),
                   [&](const std::pair<Index, int>& p) {
                     return p == std::pair<Index, int>{ saddle, 2 } || p == std::pair<Index, int>{ along, 1 };
                   }),
    expected.end());
  CHECK(pointsOf(after) == expected);
  std::printf("  (1, 0) raised from %g to %.6g past the saddle's %g; (1, 1) kept at %g\n", field.Values[along],
    sampled.Values[along], sampled.Values[saddle], sampled.Values[pit]);
}

TEST_CASE(ABlockedBoundarySaddleMovesOneStepAlongTheBoundary)
{
  // The blocked saddle at (0, 1) of a 5 x 5 ramp, as above, with the left side falling from
  // (0, 2) to a wanted boundary minimum at (0, 3): (0, 2) is free, and its interior neighbour
  // (1, 2) leads up. The saddle is wanted there instead, at its value; settled again from the
  // moved start, nothing is blocked, the minimum at (1, 1) stays, and the stage-1 extraction of
  // the result finds the wanted counts with the boundary saddle at (0, 2), one spacing from its node.
  constexpr int n = 5;
  PlanarScalarField field = UnitGrid(n, n, [](int i, int j) {
    if (i == 0 && j > 0 && j < 4)
    {
      return j == 1 ? 5.0 : (j == 2 ? 4.5 : 1.0);
    }
    return i == 1 && j == 1 ? -1.0 : double(i + j);
  });
  TriangleMeshTopology mesh;
  mesh.BuildGrid(n, n, SequentialFor);
  const Index corner = 0, saddle = n, pit = n + 1, top = n * n - 1, free = 2 * n, side = 3 * n;
  SamplingConstraints constraints;
  constraints.Minima = { pit };
  constraints.Maxima = { top };
  constraints.BoundaryMinima = { corner, side };
  constraints.BoundaryMaxima = { saddle, top };
  constraints.Saddles = { saddle };
  std::vector<double> settled = field.Values;
  std::vector<Index> blocked;
  EnforceCriticalVertices(mesh, constraints, settled, 6, &blocked);
  CHECK(std::find(blocked.begin(), blocked.end(), saddle) != blocked.end());
  std::vector<double> start = field.Values;
  const int moved = MoveBlockedBoundarySaddles(mesh, blocked, settled, constraints, start);
  CHECK_EQ(moved, 1);
  CHECK(constraints.BoundaryMaxima == (std::vector<Index>{ free, top }));
  CHECK(constraints.Saddles == std::vector<Index>{ free });
  CHECK_EQ(start[free], field.Values[saddle]);
  std::vector<Index> blockedAfter;
  const auto report = EnforceCriticalVertices(mesh, constraints, start, 6, &blockedAfter);
  CHECK(report.Converged);
  CHECK(blockedAfter.empty());
  field.Values = start;
  MorseSmaleComplexExtraction extraction;
  std::string error;
  MorseSmaleComplex after;
  CHECK(extraction.Extract(field, after, error));
  std::vector<Index> found[3];
  for (const CriticalPoint& cp : after.CriticalPoints)
  {
    found[cp.MorseIndex].push_back(cp.Vertex);
  }
  for (std::vector<Index>& list : found)
  {
    std::sort(list.begin(), list.end());
  }
  std::printf("  moved %d; after: %zu minima, %zu saddles, %zu maxima; pit (1, 1) %.3g, (0, 1) %.3g, (0, 2) %.3g\n",
    moved, found[0].size(), found[1].size(), found[2].size(), start[pit], start[saddle], start[free]);
  CHECK(found[0] == (std::vector<Index>{ corner, pit, side }));
  CHECK(found[2] == std::vector<Index>{ top });
  CHECK(std::find(found[1].begin(), found[1].end(), free) != found[1].end());
  CHECK(std::find(found[1].begin(), found[1].end(), saddle) == found[1].end());
}

TEST_CASE(OneCellsAsRunsOfASharedStoreCarveAsTheirOwnPoints)
{
  // Stage 4 gives CarveOneCells every smoothed 1-cell as runs of one store in which each piece
  // is sampled once (merged 1-cells share their first pieces), not as points of its own. Here
  // a family of 1-cells on noise, several of them sharing a first stretch (a merged stem), is
  // carved once as points and once as runs that point into one store for the shared stretches:
  // every vertex must end with the same value, bit for bit, for every carving.
  const int nx = 60, ny = 48;
  std::mt19937 generator(2026);
  std::uniform_real_distribution<double> noise(0, 1);
  PlanarScalarField field = UnitGrid(nx, ny, [&](int, int) { return noise(generator); });
  TriangleMeshTopology mesh;
  mesh.BuildGrid(nx, ny, SequentialFor);
  auto vertexNear = [&](double x, double y) { return static_cast<Index>(std::lround(y)) * nx + std::lround(x); };
  SamplingConstraints own, shared;
  auto store = std::make_shared<std::vector<double>>();
  for (int family = 0; family < 6; ++family)
  {
    const bool up = family % 2 == 1;
    const double y0 = 6 + 7 * family, phase = 0.7 * family;
    // The stem: from the saddle at x = 4 to x = 20, shared by three branches.
    std::vector<double> stem;
    for (double x = 4; x <= 20 + 1e-9; x += 0.45)
    {
      stem.insert(stem.end(), { x, y0 + 0.8 * std::sin(0.3 * x + phase), (up ? 1e-2 : -1e-2) * x });
    }
    const std::size_t stemFirst = store->size();
    store->insert(store->end(), stem.begin(), stem.end());
    const std::size_t stemLast = store->size();
    for (int branch = 0; branch < 3; ++branch)
    {
      std::vector<double> rest;
      const double yEnd = stem[stem.size() - 2];
      for (double x = 20.4; x <= 50 + 1e-9; x += 0.45)
      {
        rest.insert(rest.end(), { x, yEnd + (branch - 1) * 0.12 * (x - 20), (up ? 1e-2 : -1e-2) * x });
      }
      SaddleOneCell points;
      points.Ascending = up;
      points.Saddle = vertexNear(stem[0], stem[1]);
      points.Points = stem;
      points.Points.insert(points.Points.end(), rest.begin(), rest.end());
      SaddleOneCell runs = points;
      runs.Points.clear();
      // The stem and then the branch's own stretch, each in runs of a few points (pieces of a
      // few samples): a walk that lost or repeated a point at a run's end would go elsewhere.
      for (std::size_t first = stemFirst; first < stemLast; first += 9)
      {
        runs.Runs.emplace_back(first, std::min(first + 9, stemLast));
      }
      const std::size_t restFirst = store->size();
      store->insert(store->end(), rest.begin(), rest.end());
      for (std::size_t first = restFirst; first < store->size(); first += 12)
      {
        runs.Runs.emplace_back(first, std::min(first + 12, store->size()));
      }
      own.OneCells.push_back(points);
      shared.OneCells.push_back(runs);
      const Index end = vertexNear(rest[rest.size() - 3], rest[rest.size() - 2]);
      for (SamplingConstraints* c : { &own, &shared })
      {
        c->Saddles.push_back(points.Saddle);
        (up ? c->Maxima : c->Minima).push_back(end);
      }
    }
  }
  shared.SharedOneCellSamples = store;
  for (const OneCellCarving carving :
    { OneCellCarving::JustPastTheWalk, OneCellCarving::WhereNeeded, OneCellCarving::Everywhere })
  {
    std::vector<double> a = field.Values, b = field.Values;
    const Index changedA = CarveOneCells(field, mesh, own, 1.0, a, carving);
    const Index changedB = CarveOneCells(field, mesh, shared, 1.0, b, carving);
    std::printf("  carving %d: %d vertices changed from the points, %d from the runs\n", static_cast<int>(carving),
      static_cast<int>(changedA), static_cast<int>(changedB));
    CHECK(changedA > 100);
    CHECK_EQ(changedA, changedB);
    CHECK(a == b);
  }
}

TEST_CASE(AValleyBesideARidgeGoesRoundTheVerticesBothClaim)
{
  // A valley (a descending 1-cell) and a ridge (an ascending one) run side by side less than a
  // spacing apart over nearly flat data, as on a terraced crop: where a vertex is the nearest
  // to both curves, both walks claim it, it keeps its value, and the chain breaks there unless
  // it goes round. After carving, each 1-cell must leave a strictly monotone chain of vertices
  // from near its saddle to its extremum: checked here by searching the mesh for a path that
  // falls (rises) at every step, in the stage-1 order (value, then vertex id), from the vertex
  // nearest the curve two spacings past its saddle to the extremum. The data is 1e-3 of noise,
  // the 1-cells fall (rise) 1e-3 per spacing, so no such path exists off the carved chains.
  const int nx = 44, ny = 12;
  const double startX = 3, endX = 38;
  auto valleyY = [](double x) { return 5.0 + 0.45 * std::sin(0.5 * x); };
  auto ridgeY = [&](double x) { return valleyY(x) + 0.7; };
  PlanarScalarField field =
    UnitGrid(nx, ny, [](int i, int j) { return 1e-3 * std::sin(1.3 * i + 0.7 * j) * std::cos(0.9 * j - 0.4 * i); });
  TriangleMeshTopology mesh;
  mesh.BuildGrid(nx, ny, SequentialFor);
  auto vertexNear = [&](double x, double y) { return static_cast<Index>(std::lround(y)) * nx + std::lround(x); };
  SamplingConstraints constraints;
  for (bool up : { false, true })
  {
    SaddleOneCell cell;
    cell.Ascending = up;
    for (double x = startX; x <= endX + 1e-9; x += 0.125)
    {
      const double y = up ? ridgeY(x) : valleyY(x);
      cell.Points.insert(cell.Points.end(), { x, y, (up ? 1e-3 : -1e-3) * (x - startX) });
    }
    cell.Saddle = vertexNear(startX, up ? ridgeY(startX) : valleyY(startX));
    constraints.OneCells.push_back(cell);
    constraints.Saddles.push_back(cell.Saddle);
    const Index end = vertexNear(endX, up ? ridgeY(endX) : valleyY(endX));
    (up ? constraints.Maxima : constraints.Minima).push_back(end);
    field.Values[cell.Saddle] = 0;
    field.Values[end] = up ? 1 : -1;
  }
  // Whether a strictly falling (rising) path leads from `from` to `to`.
  auto monotonePath = [&](const std::vector<double>& values, Index from, Index to, bool up) {
    auto before = [&](Index a, Index b) { return values[a] < values[b] || (values[a] == values[b] && a < b); };
    std::vector<char> seen(values.size(), 0);
    std::vector<Index> stack{ from };
    seen[from] = 1;
    while (!stack.empty())
    {
      const Index v = stack.back();
      stack.pop_back();
      if (v == to)
      {
        return true;
      }
      for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v); ++i)
      {
        for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
        {
          if (!seen[w] && (up ? before(v, w) : before(w, v)))
          {
            seen[w] = 1;
            stack.push_back(w);
          }
        }
      }
    }
    return false;
  };
  for (const OneCellCarving carving :
    { OneCellCarving::JustPastTheWalk, OneCellCarving::WhereNeeded, OneCellCarving::Everywhere })
  {
    std::vector<double> values = field.Values;
    const Index changed = CarveOneCells(field, mesh, constraints, 1.0, values, carving);
    bool valley = false, ridge = false;
    for (bool up : { false, true })
    {
      const double x = startX + 2;
      const Index from = vertexNear(x, up ? ridgeY(x) : valleyY(x));
      const Index to = up ? constraints.Maxima[0] : constraints.Minima[0];
      (up ? ridge : valley) = monotonePath(values, from, to, up);
    }
    std::printf("  carving %d: %d vertices changed; falling chain along the valley: %d, rising along the ridge: %d\n",
      static_cast<int>(carving), static_cast<int>(changed), valley ? 1 : 0, ridge ? 1 : 0);
    CHECK(valley);
    CHECK(ridge);
  }
}

TEST_CASE(AVertexBothClaimGoesToTheOneCellPassingNearer)
{
  // A valley runs along row 5 through its vertices; a ridge runs 0.6 spacings above it, along
  // row 6, but dips to 0.4 above it at x = 10, where its walk steps onto (10, 5) and (11, 5).
  // Both claim those two vertices. The valley passes them at no distance, the ridge at 0.4 and
  // 0.6: they are the valley's, lowered along it, and the ridge, walked again round them,
  // rises along row 6. Left to neither (as when neither passes clearly nearer), they would keep
  // the data's values, and row 5 would not fall along the valley.
  const int nx = 20, ny = 10;
  auto id = [&](int i, int j) { return static_cast<Index>(j) * nx + i; };
  PlanarScalarField field =
    UnitGrid(nx, ny, [](int i, int j) { return 1e-4 * std::sin(1.3 * i + 0.7 * j) * std::cos(0.9 * j - 0.4 * i); });
  TriangleMeshTopology mesh;
  mesh.BuildGrid(nx, ny, SequentialFor);
  SamplingConstraints constraints;
  for (const bool up : { false, true })
  {
    SaddleOneCell cell;
    cell.Ascending = up;
    cell.Saddle = id(2, up ? 6 : 5);
    for (double x = 2; x <= 17 + 1e-9; x += 0.125)
    {
      const double dip = 0.2 * std::max(0.0, 1 - std::abs(x - 10) / 0.5);
      cell.Points.insert(cell.Points.end(), { x, up ? 5.6 - dip : 5.0, (up ? 1e-3 : -1e-3) * (x - 2) });
    }
    constraints.OneCells.push_back(cell);
    constraints.Saddles.push_back(cell.Saddle);
    const Index end = id(17, up ? 6 : 5);
    (up ? constraints.Maxima : constraints.Minima).push_back(end);
    field.Values[cell.Saddle] = 0;
    field.Values[end] = up ? 1 : -1;
  }
  for (const OneCellCarving carving :
    { OneCellCarving::JustPastTheWalk, OneCellCarving::WhereNeeded, OneCellCarving::Everywhere })
  {
    std::vector<double> values = field.Values;
    const Index changed = CarveOneCells(field, mesh, constraints, 1.0, values, carving);
    bool valley = true, ridge = true;
    for (int i = 5; i <= 15; ++i)
    {
      valley = valley && values[id(i, 5)] < 0 && values[id(i, 5)] < values[id(i - 1, 5)];
      ridge = ridge && values[id(i, 6)] > 0 && values[id(i, 6)] > values[id(i - 1, 6)];
    }
    std::printf("  carving %d: %d vertices changed; row 5 falls: %d, row 6 rises: %d\n", static_cast<int>(carving),
      static_cast<int>(changed), valley ? 1 : 0, ridge ? 1 : 0);
    CHECK(valley);
    CHECK(ridge);
  }
}

TEST_CASE(ARidgeBesideASaddleLeavesItsLowerLinkWhole)
{
  // A ridge (another saddle's ascending 1-cell) runs through a vertex of a wanted saddle's link
  // that lies below the saddle. Raised to the ridge's height, that vertex would join the upper
  // link, and a monkey saddle (wanted twice: three pieces of lower link) would be left a simple
  // saddle, formed again a few vertices away by the floods. Carving leaves such a link as it
  // is, and carves the rest of the ridge; a simple saddle (wanted once), which two pieces keep,
  // lets the ridge through. The pieces of the lower link are counted here around the grid's
  // cyclic link of six: (i+1, j), (i, j+1), (i-1, j+1), (i-1, j), (i, j-1), (i+1, j-1).
  const int nx = 12, ny = 12;
  auto id = [&](int i, int j) { return static_cast<Index>(j) * nx + i; };
  const Index saddle = id(6, 6);
  PlanarScalarField field = UnitGrid(nx, ny, [](int, int) { return 0.1; });
  const std::array<std::array<int, 2>, 6> around{ { { 7, 6 }, { 6, 7 }, { 5, 7 }, { 5, 6 }, { 6, 5 }, { 7, 5 } } };
  field.Values[saddle] = 0.5;
  for (std::size_t k = 0; k < around.size(); ++k)
  {
    field.Values[id(around[k][0], around[k][1])] = k % 2 == 0 ? 0.2 : 0.8;
  }
  auto lowerPieces = [&](const std::vector<double>& values) {
    int pieces = 0;
    for (std::size_t k = 0; k < around.size(); ++k)
    {
      const Index a = id(around[k][0], around[k][1]), b = id(around[(k + 5) % 6][0], around[(k + 5) % 6][1]);
      pieces += values[a] < values[saddle] && !(values[b] < values[saddle]) ? 1 : 0;
    }
    return pieces;
  };
  TriangleMeshTopology mesh;
  mesh.BuildGrid(nx, ny, SequentialFor);
  // The ridge: from a saddle at (2, 7) along row 7 to (5, 7), then up column 5 to a maximum at
  // (5, 11), rising from 0.85 to 0.99.
  SaddleOneCell ridge;
  ridge.Saddle = id(2, 7);
  ridge.Ascending = true;
  std::vector<std::array<double, 2>> path;
  for (double x = 2; x < 5; x += 0.125)
  {
    path.push_back({ x, 7 });
  }
  for (double y = 7; y <= 11 + 1e-9; y += 0.125)
  {
    path.push_back({ 5, y });
  }
  for (std::size_t p = 0; p < path.size(); ++p)
  {
    ridge.Points.insert(ridge.Points.end(), { path[p][0], path[p][1], 0.85 + 0.14 * p / (path.size() - 1) });
  }
  const Index ridgeMaximum = id(5, 11);
  field.Values[ridge.Saddle] = 0.85;
  field.Values[ridgeMaximum] = 0.99;
  CHECK_EQ(lowerPieces(field.Values), 3);
  for (const int wanted : { 2, 1 })
  {
    SamplingConstraints constraints;
    constraints.OneCells.push_back(ridge);
    constraints.Saddles = { ridge.Saddle };
    constraints.Saddles.insert(constraints.Saddles.end(), wanted, saddle);
    constraints.Maxima = { ridgeMaximum };
    for (const OneCellCarving carving :
      { OneCellCarving::JustPastTheWalk, OneCellCarving::WhereNeeded, OneCellCarving::Everywhere })
    {
      std::vector<double> values = field.Values;
      const Index changed = CarveOneCells(field, mesh, constraints, 1.0, values, carving);
      std::printf("  saddle wanted %d time(s), carving %d: %d vertices changed, %d pieces of its lower link\n", wanted,
        static_cast<int>(carving), static_cast<int>(changed), lowerPieces(values));
      // The ridge is carved past the link: (4, 7) before it, (5, 9) after it.
      CHECK(values[id(4, 7)] > 0.85 && values[id(5, 9)] > 0.85);
      CHECK_EQ(values[saddle], 0.5);
      if (wanted == 2)
      {
        CHECK_EQ(lowerPieces(values), 3);
      }
      else
      {
        CHECK(values[id(5, 7)] > 0.85);
        CHECK_EQ(lowerPieces(values), 2);
      }
    }
  }
}

TEST_CASE(ASaddleLoweredOntoItsLinkComesBackByItsLink)
{
  // Each wanted interior saddle of the trigonometric field and of 3 seeded Shepard fields in
  // turn loses its saddle: the one vertex of one of its upper link pieces is put just below it
  // (as sampling can leave a link vertex exactly at the saddle's value, stress case #17), and the
  // floods settle the extrema. The wanted saddle is then off its vertex (the lowered vertex is a
  // saddle instead, so saddles are matched on their vertex here: tolerance 0.5). Trying the
  // patterns of its link must bring it back: checked by the test's own count of the link's
  // pieces above the saddle (the grid's split along (i+1, j)-(i, j+1), ties by vertex id) and by
  // stage 1's counts.
  int tried = 0, restored = 0;
  for (int seed = -1; seed < 3; ++seed)
  {
    const SamplingCase smooth = seed < 0 ? TrigonometricSamplingCase() : ShepardSamplingCase(seed);
    const PlanarScalarField& field = smooth.Field;
    const TriangleMeshTopology& mesh = smooth.Mesh;
    const SamplingConstraints& constraints = smooth.Constraints;
    const int nx = field.GridDimensions[0], ny = field.GridDimensions[1];
    // The link of interior (i, j) in turning order.
    const auto linkOf = [nx](Index v) {
      const int i = static_cast<int>(v % nx), j = static_cast<int>(v / nx);
      const int di[6] = { 1, 0, -1, -1, 0, 1 }, dj[6] = { 0, 1, 1, 0, -1, -1 };
      std::array<Index, 6> link;
      for (int k = 0; k < 6; ++k)
      {
        link[k] = static_cast<Index>((j + dj[k]) * nx + i + di[k]);
      }
      return link;
    };
    const auto above = [](const std::vector<double>& values, Index a, Index b) {
      return values[a] > values[b] || (values[a] == values[b] && a > b);
    };
    // The pieces of the link above v.
    const auto upperPieces = [&](const std::vector<double>& values, Index v) {
      const auto link = linkOf(v);
      int changes = 0;
      for (int k = 0; k < 6; ++k)
      {
        changes += above(values, link[k], v) != above(values, link[(k + 1) % 6], v) ? 1 : 0;
      }
      return changes / 2;
    };
    const auto wanted = [&constraints](Index v) {
      for (const std::vector<Index>* kind : { &constraints.Minima, &constraints.Maxima, &constraints.Saddles })
      {
        if (std::find(kind->begin(), kind->end(), v) != kind->end())
        {
          return true;
        }
      }
      return false;
    };
    MorseSmaleComplexExtraction extraction;
    std::string error;
    for (Index w : constraints.Saddles)
    {
      const int i = static_cast<int>(w % nx), j = static_cast<int>(w / nx);
      if (i < 2 || j < 2 || i >= nx - 2 || j >= ny - 2 || upperPieces(field.Values, w) != 2 ||
        std::count(constraints.Saddles.begin(), constraints.Saddles.end(), w) != 1)
      {
        continue;
      }
      // A link vertex above w whose turning neighbours in the link are both below it.
      const auto link = linkOf(w);
      Index lone = InvalidIndex;
      for (int k = 0; k < 6 && lone == InvalidIndex; ++k)
      {
        if (above(field.Values, link[k], w) && !above(field.Values, link[(k + 1) % 6], w) &&
          !above(field.Values, link[(k + 5) % 6], w))
        {
          lone = link[k];
        }
      }
      if (lone == InvalidIndex || wanted(lone))
      {
        continue; // a wanted extremum or saddle beside the saddle is not lowered
      }
      std::vector<double> values = field.Values;
      values[lone] = std::nextafter(values[w], -std::numeric_limits<double>::infinity());
      EnforceCriticalVertices(mesh, constraints, values);
      if (upperPieces(values, w) == 2)
      {
        continue; // the floods brought it back themselves
      }
      ++tried;
      const int missing = PlaceMissingSaddlesByTheirLinks(field, mesh, constraints, 0.5, values, 4, 6);
      PlanarScalarField after = field;
      after.Values = values;
      MorseSmaleComplex found;
      CHECK(extraction.Extract(after, found, error));
      const bool back = upperPieces(values, w) == 2 && found.CountByIndex() == smooth.Wanted.CountByIndex();
      restored += back ? 1 : 0;
      if (!back)
      {
        std::printf("  saddle (%d, %d) not restored: %d upper pieces, %d wanted saddles off\n", i, j,
          upperPieces(values, w), missing);
      }
      CHECK(back);
      CHECK_EQ(missing, 0);
    }
  }
  std::printf("  %d interior saddles lowered off their vertex (the trigonometric field, 3 seeded Shepard "
              "fields), %d back on it by their links\n", tried, restored);
  CHECK(tried >= 5);
}

TEST_CASE(ASpareSaddleWalksOntoItsMissingNode)
{
  // Seeded noise on grids and on grids split along random diagonals: the field's own critical
  // points are the wanted ones. An interior saddle is walked two steps away from its vertex
  // (each step one vertex set into another gap between its neighbours' values, found here by the
  // test's own count of link pieces: no extremum changes, the saddle alone moves away, farther
  // than the verdict's pairing reaches). WalkSpareSaddlesOntoMissing must walk it back within
  // reach, with every other critical point where it was and the wanted points' values
  // untouched: checked by the test's count and by stage 1. With a reach of one edge it must
  // leave the values exactly as they were.
  const double tolerance = std::sqrt(2.0) * (1 + 1e-9); // one grid diagonal, as the verdict
  int displaced = 0, walked = 0, onRandomDiagonals = 0, fields = 0;
  for (std::uint64_t seed = 1; seed <= 80 && displaced < 50; ++seed)
  {
    ++fields;
    const int n = 20;
    const bool randomDiagonals = seed % 2 == 0;
    PlanarScalarField field = FieldOnGrid(UniformNoise(n, 3000 + seed));
    TriangleMeshTopology mesh;
    std::string error;
    if (randomDiagonals)
    {
      std::mt19937_64 random(seed);
      field.Triangles = RandomDiagonalTriangles(n, n, random, [](Index v) { return v; });
      field.GridDimensions[0] = field.GridDimensions[1] = 0; // a triangle mesh, not an image
      CHECK(mesh.Build(n * n, field.Triangles, SequentialFor, error));
    }
    else
    {
      mesh.BuildGrid(n, n, SequentialFor);
      field.Triangles = GridTriangles(n, n); // for the test's own link count; the field stays an image
    }
    // The test's own classification of an interior vertex from the triangles (its link walked
    // round as a cycle; ties by vertex id): -1 minimum, -2 maximum, else the saddles.
    const std::vector<Index>& triangles = field.Triangles;
    const auto kindOf = [&triangles](const std::vector<double>& values, Index v) {
      std::vector<std::pair<Index, Index>> opposite; // each triangle's edge across from v
      for (std::size_t t = 0; t + 2 < triangles.size(); t += 3)
      {
        for (int k = 0; k < 3; ++k)
        {
          if (triangles[t + k] == v)
          {
            opposite.emplace_back(triangles[t + (k + 1) % 3], triangles[t + (k + 2) % 3]);
          }
        }
      }
      std::vector<Index> cycle{ opposite.front().first, opposite.front().second };
      while (cycle.size() < opposite.size())
      {
        for (const auto& edge : opposite)
        {
          if (edge.first == cycle.back())
          {
            cycle.push_back(edge.second);
            break;
          }
        }
      }
      int lower = 0, changes = 0;
      const auto below = [&](Index w) { return values[w] < values[v] || (values[w] == values[v] && w < v); };
      for (std::size_t k = 0; k < cycle.size(); ++k)
      {
        lower += below(cycle[k]) ? 1 : 0;
        changes += below(cycle[k]) != below(cycle[(k + 1) % cycle.size()]) ? 1 : 0;
      }
      return lower == 0 ? -1 : (lower == static_cast<int>(cycle.size()) ? -2 : changes / 2 - 1);
    };
    const auto inside = [n](Index v, int margin) {
      const int i = static_cast<int>(v % n), j = static_cast<int>(v / n);
      return i >= margin && j >= margin && i < n - margin && j < n - margin;
    };
    const auto starOf = [&mesh](Index v) {
      std::vector<Index> star{ v };
      for (Index i = mesh.VertexTriangleBegin(v); i < mesh.VertexTriangleEnd(v); ++i)
      {
        for (Index w : mesh.TriangleVertices[mesh.VertexTriangle(i)])
        {
          if (std::find(star.begin(), star.end(), w) == star.end())
          {
            star.push_back(w);
          }
        }
      }
      return star;
    };
    const auto gridDistance = [n](Index a, Index b) {
      return std::hypot(double(a % n) - double(b % n), double(a / n) - double(b / n));
    };
    MorseSmaleComplexExtraction extraction;
    extraction.CriticalPointsOnly = true;
    MorseSmaleComplex own;
    CHECK(extraction.Extract(field, own, error));
    const std::vector<CriticalPointLocation> expected = CriticalPointLocations(own, field.Points);
    std::vector<unsigned char> critical(field.Values.size(), 0);
    for (const CriticalPointLocation& p : expected)
    {
      critical[p.Vertex] = 1;
    }
    // One step of the saddle at `at` away from w (farther from it), by the test's count.
    const auto stepAway = [&](std::vector<double>& values, Index& at, Index w) {
      for (Index c : starOf(at))
      {
        if (critical[c] || !inside(c, 3))
        {
          continue;
        }
        std::vector<double> levels;
        for (Index u : starOf(c))
        {
          levels.push_back(values[u]);
        }
        for (double level : levels)
        {
          for (double x : { std::nextafter(level, 2.0), std::nextafter(level, -1.0) })
          {
            const std::vector<Index> star = starOf(c);
            std::vector<int> before;
            for (Index u : star)
            {
              before.push_back(kindOf(values, u));
            }
            const double own = values[c];
            values[c] = x;
            Index gained = InvalidIndex;
            bool lost = false, other = false;
            for (std::size_t k = 0; k < star.size(); ++k)
            {
              const int now = kindOf(values, star[k]);
              if (now == before[k])
              {
                continue;
              }
              if (star[k] == at && before[k] == 1 && now == 0)
              {
                lost = true;
              }
              else if (now == 1 && before[k] == 0 && gained == InvalidIndex)
              {
                gained = star[k];
              }
              else
              {
                other = true;
              }
            }
            if (lost && !other && gained != InvalidIndex && gridDistance(gained, w) > gridDistance(at, w))
            {
              at = gained;
              return true;
            }
            values[c] = own;
          }
        }
      }
      return false;
    };
    for (const CriticalPointLocation& p : expected)
    {
      const Index w = p.Vertex;
      if (p.MorseIndex != 1 || !inside(w, 4) || kindOf(field.Values, w) != 1 || displaced >= 50)
      {
        continue;
      }
      std::vector<double> values = field.Values;
      Index at = w;
      if (!stepAway(values, at, w) || !stepAway(values, at, w) || gridDistance(at, w) <= tolerance)
      {
        continue;
      }
      PlanarScalarField off = field;
      off.Values = values;
      MorseSmaleComplex offComplex;
      CHECK(extraction.Extract(off, offComplex, error));
      if (CompareCriticalPoints(expected, CriticalPointLocations(offComplex, field.Points), tolerance, &mesh)
            .Missing.size() != 1)
      {
        continue; // the verdict pairs the moved saddle with another node, and w with another saddle
      }
      ++displaced;
      onRandomDiagonals += randomDiagonals ? 1 : 0;
      // Reached by one edge only: nothing walks, nothing changes.
      std::vector<double> unchanged = values;
      CHECK_EQ(WalkSpareSaddlesOntoMissing(mesh, field.Points, expected, tolerance, unchanged, SequentialFor, 1), 0);
      CHECK(unchanged == values);
      const int kept = WalkSpareSaddlesOntoMissing(mesh, field.Points, expected, tolerance, values);
      walked += kept;
      // The test's count: every interior vertex as in the field, but near w (as many saddles
      // as there).
      Index saddleNearW = 0, saddlesNearWBefore = 0, differences = 0;
      for (Index v = 0; v < mesh.NumberOfVertices(); ++v)
      {
        if (critical[v])
        {
          CHECK_EQ(values[v], field.Values[v]);
        }
        if (!inside(v, 1))
        {
          continue;
        }
        const int now = kindOf(values, v), before = kindOf(field.Values, v);
        if (gridDistance(v, w) <= tolerance)
        {
          saddleNearW += now > 0 ? now : 0;
          saddlesNearWBefore += before > 0 ? before : 0;
        }
        if (now != before && gridDistance(v, w) > tolerance)
        {
          ++differences;
        }
      }
      PlanarScalarField after = field;
      after.Values = values;
      MorseSmaleComplex found;
      CHECK(extraction.Extract(after, found, error));
      const TopologyComparison comparison =
        CompareCriticalPoints(expected, CriticalPointLocations(found, field.Points), tolerance, &mesh);
      if (kept != 1 || saddleNearW != saddlesNearWBefore || differences != 0 || !comparison.Identical())
      {
        std::printf("  seed %llu%s, saddle (%lld, %lld) off to (%lld, %lld): walked %d, %lld saddles near it, "
                    "%lld other changes, %zu missing\n", static_cast<unsigned long long>(seed),
          randomDiagonals ? " (random diagonals)" : "",
          static_cast<long long>(w % n), static_cast<long long>(w / n), static_cast<long long>(at % n),
          static_cast<long long>(at / n), kept, static_cast<long long>(saddleNearW),
          static_cast<long long>(differences), comparison.Missing.size());
      }
      CHECK_EQ(kept, 1);
      CHECK_EQ(saddleNearW, saddlesNearWBefore);
      CHECK_EQ(differences, 0);
      CHECK(comparison.Identical());
    }
  }
  std::printf("  %d saddles walked two steps off their node on %d seeded noise fields (%d saddles on random "
              "diagonals), %d walked back\n", displaced, fields, onRandomDiagonals, walked);
  CHECK(displaced >= 40);
  CHECK(onRandomDiagonals >= 15);
}

int main()
{
  return testing_harness::RunAll();
}
