#pragma once
// fictus for users of the C++ library: the one header to include.
//
//   #include <fictus/fictus.hpp>
//   fictus::Problem p = fictus::paper_problem(256);          // or your own: box, N, curve, c, f, g
//   fictus::SolverOptions o;                                  // defaults and rules: options.hpp
//   fictus::Solution s = fictus::solve(p, o);                 // λ, traces, field û, checks, errors
//
// One problem and one solution type for both dimensions: BasicProblem<dim> and BasicSolution<dim>
// (Problem, Solution in 2-D; SurfaceProblem, SurfaceSolution in 3-D), SolverOptions and their checks
// (problem.hpp, solution.hpp, solver_options.hpp, options.hpp); the curves (curve.hpp, shapes.hpp)
// and surfaces (surface.hpp, mesh_surface.hpp); the solver FictitiousDomainSolver<dim>
// (fictitious_domain_solver.hpp), which also serves many obstacles or boundaries on one grid; the paper's experiment
// (paper_problem.hpp) and its convergence tables (convergence_table.hpp). Problem files and expressions are in the
// fictus_io library (fictus/io/). The other headers are the building blocks of the method (grids, fast solvers, Green's
// table, trace rows, Schur complements): installed for those who build on them, but they may change between versions.
#include "fictus/convergence_table.hpp"
#include "fictus/curve.hpp"
#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/options.hpp"
#include "fictus/paper_problem.hpp"
#include "fictus/problem.hpp"
#include "fictus/shapes.hpp"
#include "fictus/solution.hpp"
#include "fictus/solver_options.hpp"
#include "fictus/surface.hpp"
