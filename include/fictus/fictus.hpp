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
// (solve/: problem.hpp, solution.hpp, solver_options.hpp, options.hpp); the curves (boundary/curve.hpp,
// shapes.hpp) and surfaces (boundary/surface.hpp, mesh_surface.hpp); the solver FictitiousDomainSolver<dim>
// (solve/fictitious_domain_solver.hpp), which also serves many obstacles or boundaries on one grid; the paper's
// experiment (solve/paper_problem.hpp) and its convergence tables (solve/convergence_table.hpp). Problem files and
// expressions are in the fictus_io library (io/). The other headers are the building blocks of the method in their
// layers (grid/: grids, fast solvers, Green's table; boundary/: trace rows, kink corrections; solve/: Schur
// complements, Newton): installed for those who build on them, but they may change between versions.
#include "fictus/boundary/curve.hpp"
#include "fictus/boundary/shapes.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/solve/convergence_table.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/options.hpp"
#include "fictus/solve/paper_problem.hpp"
#include "fictus/solve/problem.hpp"
#include "fictus/solve/solution.hpp"
#include "fictus/solve/solver_options.hpp"
