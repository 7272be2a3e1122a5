// The linear-program vocabulary of the core: GLPK through CGAL's solver interface. (CGAL's own
// exact solver took 42 s for one 206-variable L1 fit here, GLPK 5 ms.) Include only from .cxx
// files: it pulls in CGAL and glpk.h.
#pragma once

#ifndef CGAL_USE_GLPK
#error "TopoSpline's linear programs need GLPK through CGAL's solver interface: define CGAL_USE_GLPK and link glpk"
#endif
#include <CGAL/GLPK_mixed_integer_program_traits.h>
#include <glpk.h>

namespace topospline
{
using LinearProgram = CGAL::GLPK_mixed_integer_program_traits<double>;
using LinearVariable = CGAL::Variable<double>;
using LinearConstraint = CGAL::Linear_constraint<double>;
}
