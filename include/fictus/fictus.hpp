#pragma once
// fictus for users of the C++ library: the one header to include.
//
//   #include <fictus/fictus.hpp>
//   fictus::Problem p = fictus::paper_problem(256);          // or your own: box, N, curve, c, f, g
//   fictus::SolverOptions o;                                  // defaults and rules: options.hpp
//   fictus::Solution s = fictus::solve(p, o);                 // λ, traces, field û, checks, errors
//
// Problem, SolverOptions and their checks (problem.hpp, solver_options.hpp, options.hpp); the curves
// (curve.hpp, shapes.hpp); the solver and its Solution (fictitious_domain_solver.hpp), which also
// serves many obstacles or curves on one grid; the paper's experiment (paper_problem.hpp) and its
// convergence tables (convergence_table.hpp). Problem files and expressions are in the fictus_io
// library (fictus/io/). The other headers are the building blocks of the method (grids, fast
// solvers, Green's table, trace rows, Schur complements): installed for those who build on them,
// but they may change between versions.
#include "fictus/convergence_table.hpp"
#include "fictus/curve.hpp"
#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/options.hpp"
#include "fictus/paper_problem.hpp"
#include "fictus/problem.hpp"
#include "fictus/shapes.hpp"
#include "fictus/solver_options.hpp"
