// The linear-program vocabulary of the core: GLPK through CGAL's solver interface. (CGAL's own
// exact solver took 42 s for one 206-variable L1 fit here, GLPK 5 ms.) Include only from .cxx
// files: it pulls in CGAL and glpk.h.
#pragma once

#ifndef CGAL_USE_GLPK
#error "TopoSpline's linear programs need GLPK through CGAL's solver interface: define CGAL_USE_GLPK and link glpk"
#endif
#include <CGAL/GLPK_mixed_integer_program_traits.h>
#include <glpk.h>

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
}

// Solves `program`, never aborting the process: a program GLPK would refuse (no variables or
// no rows, a non-finite coefficient or bound) is rejected first, and an internal GLPK error is
// caught by an error hook. Returns false with `error` set on failure.
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
  glp_term_out(GLP_OFF);
  std::jmp_buf jump;
  if (setjmp(jump) != 0)
  {
    // Reached from LeaveGlpkOnError: GLPK's memory is already freed.
    glp_error_hook(nullptr, nullptr);
    error = "GLPK stopped with an internal error";
    return false;
  }
  glp_error_hook(detail::LeaveGlpkOnError, &jump);
  const bool solved = program.solve();
  glp_error_hook(nullptr, nullptr);
  if (!solved)
  {
    error = program.error_message();
  }
  return solved;
}
}
