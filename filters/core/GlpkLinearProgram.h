// The linear-program vocabulary of the core: GLPK through CGAL's solver interface. (CGAL's own
// exact solver took 42 s for one 206-variable L1 fit here, GLPK 5 ms.) Include only from .cxx
// files: it pulls in CGAL and glpk.h.
#pragma once

#ifndef CGAL_USE_GLPK
#error "TopoSpline's linear programs need GLPK through CGAL's solver interface: define CGAL_USE_GLPK and link glpk"
#endif
#include <CGAL/GLPK_mixed_integer_program_traits.h>
#include <glpk.h>

#include <chrono>
#include <cmath>
#include <csetjmp>
#include <string>

namespace topospline
{
using LinearProgram = CGAL::GLPK_mixed_integer_program_traits<double>;
using LinearVariable = CGAL::Variable<double>;
using LinearConstraint = CGAL::Linear_constraint<double>;

namespace detail
{
// GLPK reports an internal error by calling abort() unless an error hook leaves by longjmp
// (GLPK manual, glp_error_hook); the hook then must free GLPK's environment.
inline void LeaveGlpkOnError(void* jump)
{
  glp_free_env();
  std::longjmp(*static_cast<std::jmp_buf*>(jump), 1);
}

// CGAL's interface runs glp_simplex with no time or iteration limit and messages at
// GLP_MSG_ERR. On a 79 x 59 terrain crop at 0.5 %, k = 29, the dual height fit of one piece
// did not end in 15 minutes, repeating numerical-instability warnings. Those messages pass
// through a terminal hook, which prints nothing and, once the time allowed is over, leaves the
// solver as the error hook does (the caller then solves the primal program). A simplex that
// stalls silently is not caught.
struct SolverDeadline
{
  std::jmp_buf* Jump = nullptr;
  std::chrono::steady_clock::time_point Start;
  double Seconds = 0;
};

inline int InterceptGlpkOutput(void* info, const char*)
{
  const auto* deadline = static_cast<const SolverDeadline*>(info);
  if (std::chrono::duration<double>(std::chrono::steady_clock::now() - deadline->Start).count() > deadline->Seconds)
  {
    glp_free_env();
    std::longjmp(*deadline->Jump, 2);
  }
  return 1; // nothing printed
}
}

// Solves `program`, never aborting the process: a program GLPK would refuse (no variables or
// no rows, a non-finite coefficient or bound) is rejected first, an internal GLPK error is
// caught by an error hook, and a simplex still reporting trouble after 10 s (plus 1 ms per
// variable and row) is left (SolverDeadline). Returns false with `error` set on failure.
inline bool SolveLinearProgram(LinearProgram& program, std::string& error)
{
  if (program.number_of_variables() == 0 || program.number_of_constraints() == 0)
  {
    error = "the linear program is empty (" + std::to_string(program.number_of_variables()) + " variables, " +
      std::to_string(program.number_of_constraints()) + " constraints)";
    return false;
  }
  for (const LinearConstraint* constraint : program.constraints())
  {
    double lower, upper;
    constraint->get_bounds(lower, upper);
    bool finite = !std::isnan(lower) && !std::isnan(upper);
    for (const auto& term : constraint->coefficients())
    {
      finite = finite && std::isfinite(term.second);
    }
    if (!finite)
    {
      error = "the linear program has a non-finite coefficient or bound";
      return false;
    }
  }
  for (const auto& term : program.objective()->coefficients())
  {
    if (!std::isfinite(term.second))
    {
      error = "the linear program has a non-finite objective coefficient";
      return false;
    }
  }
  std::jmp_buf jump;
  // A few milliseconds per program here; the time allowed grows with the program's size (the
  // junction-value program of a large terrain has 1e5 unknowns).
  detail::SolverDeadline deadline;
  deadline.Jump = &jump;
  deadline.Start = std::chrono::steady_clock::now();
  deadline.Seconds = 10 + 1e-3 * static_cast<double>(program.number_of_variables() + program.number_of_constraints());
  const int left = setjmp(jump);
  if (left != 0)
  {
    // Reached from a hook, which freed GLPK's memory (and its hooks with it).
    glp_error_hook(nullptr, nullptr);
    glp_term_hook(nullptr, nullptr);
    error = left == 2 ? "GLPK did not finish within " + std::to_string(static_cast<int>(deadline.Seconds)) +
        " s (a degenerate program)"
                      : "GLPK stopped with an internal error";
    return false;
  }
  glp_error_hook(detail::LeaveGlpkOnError, &jump);
  glp_term_hook(detail::InterceptGlpkOutput, &deadline);
  glp_term_out(GLP_ON);
  const bool solved = program.solve();
  glp_term_out(GLP_OFF);
  glp_term_hook(nullptr, nullptr);
  glp_error_hook(nullptr, nullptr);
  if (!solved)
  {
    error = program.error_message();
  }
  return solved;
}
}
