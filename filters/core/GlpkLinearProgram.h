// The linear-program vocabulary of the core: GLPK through CGAL's solver interface. (CGAL's own
// exact solver took 42 s for one 206-variable L1 fit here, GLPK 5 ms.) Include only from .cxx
// files: it pulls in CGAL and glpk.h.
#pragma once

#ifndef CGAL_USE_GLPK
#error "TopoSpline's linear programs need GLPK through CGAL's solver interface: define CGAL_USE_GLPK and link glpk"
#endif
#include <CGAL/GLPK_mixed_integer_program_traits.h>
#include <glpk.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csetjmp>
#include <limits>
#include <string>
#include <vector>

namespace topospline
{
using LinearVariable = CGAL::Variable<double>;
using LinearConstraint = CGAL::Linear_constraint<double>;

// CGAL's solver interface (Mixed_integer_program_traits) on GLPK's simplex, as CGAL's
// GLPK_mixed_integer_program_traits solves a continuous program (the same rows, columns,
// bounds and options, so the same solutions), with limits on the simplex's iterations and
// time. CGAL's runs glp_simplex with none and no way to set them: on a jittered 104 x 47 grid
// at 1 %, k = 10 (stress seed 67 #268) the dual height fit of one piece stalled silently in
// glp_simplex for over 15 minutes, and nothing could stop it. Programs with integer variables
// are refused (the core has none).
class GlpkProgramWithLimits : public CGAL::Mixed_integer_program_traits<double>
{
public:
  int IterationLimit = std::numeric_limits<int>::max();
  double SecondsLimit = std::numeric_limits<double>::infinity();
  bool StoppedAtALimit = false; // the last solve() ended at IterationLimit or SecondsLimit

  bool solve() override
  {
    this->error_message_.clear();
    this->StoppedAtALimit = false;
    for (const LinearVariable* variable : this->variables_)
    {
      if (variable->variable_type() != LinearVariable::CONTINUOUS)
      {
        this->error_message_ = "integer variables are not supported";
        return false;
      }
    }
    glp_prob* lp = glp_create_prob();
    if (lp == nullptr)
    {
      this->error_message_ = "failed creating GLPK program";
      return false;
    }
    const int columns = static_cast<int>(this->variables_.size());
    glp_add_cols(lp, columns);
    for (int i = 0; i < columns; ++i)
    {
      double lower, upper;
      this->variables_[i]->get_bounds(lower, upper);
      glp_set_col_kind(lp, i + 1, GLP_CV);
      glp_set_col_bnds(lp, i + 1, CGAL::internal::bound_type(lower, upper), lower, upper);
    }
    const int rows = static_cast<int>(this->constraints_.size());
    glp_add_rows(lp, rows);
    std::vector<int> indices;
    std::vector<double> coefficients;
    for (int r = 0; r < rows; ++r)
    {
      const LinearConstraint* constraint = this->constraints_[r];
      indices.assign(1, 0); // GLPK's arrays start at 1
      coefficients.assign(1, 0.0);
      for (const auto& [variable, coefficient] : constraint->coefficients())
      {
        indices.push_back(variable->index() + 1);
        coefficients.push_back(coefficient);
      }
      glp_set_mat_row(lp, r + 1, static_cast<int>(indices.size()) - 1, indices.data(), coefficients.data());
      double lower, upper;
      constraint->get_bounds(lower, upper);
      glp_set_row_bnds(lp, r + 1, CGAL::internal::bound_type(lower, upper), lower, upper);
    }
    for (const auto& [variable, coefficient] : this->objective_->coefficients())
    {
      glp_set_obj_coef(lp, variable->index() + 1, coefficient);
    }
    glp_set_obj_dir(lp, this->objective_->sense() == CGAL::Linear_objective<double>::MINIMIZE ? GLP_MIN : GLP_MAX);
    glp_smcp options;
    glp_init_smcp(&options);
    options.msg_lev = GLP_MSG_ERR;
    options.it_lim = this->IterationLimit;
    options.tm_lim = static_cast<int>(std::min(1000.0 * this->SecondsLimit, 2e9));
    const int status = glp_simplex(lp, &options);

    if (status == 0)
    {
      this->result_.resize(columns);
      for (int i = 0; i < columns; ++i)
      {
        this->result_[i] = glp_get_col_prim(lp, i + 1);
        this->variables_[i]->set_solution_value(this->result_[i]);
      }
    }
    else
    {
      this->StoppedAtALimit = status == GLP_EITLIM || status == GLP_ETMLIM;
      this->error_message_ = status == GLP_EITLIM ? "the simplex reached its iteration limit"
        : status == GLP_ETMLIM                   ? "the simplex reached its time limit"
                                                 : "glp_simplex stopped with status code " + std::to_string(status);
    }
    glp_delete_prob(lp);
    return status == 0;
  }
};
using LinearProgram = GlpkProgramWithLimits;

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
// stalls silently is stopped by its own limits (GlpkProgramWithLimits).
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
// caught by an error hook, and a simplex that runs past 10 s (plus 1 ms per variable and row)
// or past its iteration limit is stopped (its own limits, and SolverDeadline where it keeps
// reporting trouble). Returns false with `error` set on failure.
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
  // The simplex's own limits end a stall that prints nothing: the same time, and 100 iterations
  // per row and column (the 41 292 programs of the CI stress subset took at most 3.3; the one
  // that stalled on seed 67 #268, 45 columns and 18 rows, is stopped after 16 300).
  program.SecondsLimit = deadline.Seconds;
  program.IterationLimit = static_cast<int>(std::min<double>(
    10000 + 100.0 * static_cast<double>(program.number_of_variables() + program.number_of_constraints()),
    std::numeric_limits<int>::max()));
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
