// Tests of the core's linear programs' solver (GlpkLinearProgram.h: GLPK's simplex behind CGAL's
// solver interface, with limits): on seeded random programs it gives what CGAL's own GLPK
// traits give (the oracle: the same simplex as CGAL runs it), its iteration limit stops the
// simplex and says so, and SolveLinearProgram refuses programs GLPK would abort on.
//
// Usage: TestGlpkLinearProgram
// Prints figures per case, then "N passed, N failed"; returns nonzero on failure.
#include "GlpkLinearProgram.h"
#include "TestHarness.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

using namespace topospline;

namespace
{
// A seeded random program: minimize c x over A x >= b (some rows two-sided), 0 <= x <= 10,
// with c >= 0 so that it is bounded; b <= A 1 so that x = 1 is feasible.
template <typename Program>
void BuildRandomProgram(Program& program, std::uint64_t seed, int variables, int rows)
{
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> coefficient(-1, 1), cost(0, 1);
  std::vector<CGAL::Variable<double>*> x;
  for (int i = 0; i < variables; ++i)
  {
    x.push_back(program.create_variable(CGAL::Variable<double>::CONTINUOUS, 0.0, 10.0));
  }
  for (int r = 0; r < rows; ++r)
  {
    double atOne = 0;
    std::vector<std::pair<int, double>> terms;
    for (int i = 0; i < variables; ++i)
    {
      if (random() % 3 == 0)
      {
        terms.emplace_back(i, coefficient(random));
        atOne += terms.back().second;
      }
    }
    const bool twoSided = random() % 4 == 0;
    auto* row = program.create_constraint(atOne - 0.5, twoSided ? atOne + 0.5 : CGAL::Linear_constraint<double>::infinity());
    for (const auto& [i, a] : terms)
    {
      row->add_coefficient(x[i], a);
    }
  }
  auto* objective = program.create_objective(CGAL::Linear_objective<double>::MINIMIZE);
  for (int i = 0; i < variables; ++i)
  {
    objective->add_coefficient(x[i], cost(random));
  }
}
} // namespace

TEST_CASE(SolvesAsCGALsGlpkTraits)
{
  int programs = 0, equal = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed)
  {
    const int variables = 2 + int(seed % 40), rows = 1 + int((seed * 7) % 60);
    LinearProgram ours;
    CGAL::GLPK_mixed_integer_program_traits<double> theirs;
    BuildRandomProgram(ours, seed, variables, rows);
    BuildRandomProgram(theirs, seed, variables, rows);
    const bool solvedByOurs = ours.solve(), solvedByTheirs = theirs.solve();
    ++programs;
    equal += solvedByOurs == solvedByTheirs && ours.solution() == theirs.solution() ? 1 : 0;
  }
  std::printf("  %d random programs, %d with the same status and the same solution bit for bit\n", programs, equal);
  CHECK_EQ(equal, programs);
}

TEST_CASE(TheIterationLimitStopsTheSimplex)
{
  LinearProgram program;
  BuildRandomProgram(program, 7, 40, 60);
  CHECK(program.solve());
  CHECK(!program.StoppedAtALimit);
  program.IterationLimit = 1;
  const bool solved = program.solve();
  std::printf("  with one iteration allowed: solved %d, stopped at a limit %d, \"%s\"\n", int(solved),
    int(program.StoppedAtALimit), program.error_message().c_str());
  CHECK(!solved);
  CHECK(program.StoppedAtALimit);
  CHECK(program.error_message().find("iteration limit") != std::string::npos);
}

TEST_CASE(ProgramsGlpkWouldAbortOnAreRefused)
{
  std::string error;
  LinearProgram empty;
  CHECK(!SolveLinearProgram(empty, error));
  std::printf("  empty: %s\n", error.c_str());
  LinearProgram notFinite;
  auto* x = notFinite.create_variable(CGAL::Variable<double>::CONTINUOUS, 0.0, 1.0);
  auto* row = notFinite.create_constraint(0.0, 1.0);
  row->add_coefficient(x, std::nan(""));
  notFinite.create_objective(CGAL::Linear_objective<double>::MINIMIZE)->add_coefficient(x, 1.0);
  CHECK(!SolveLinearProgram(notFinite, error));
  std::printf("  non-finite: %s\n", error.c_str());
}

int main()
{
  return testing_harness::RunAll();
}
