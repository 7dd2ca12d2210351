#pragma once
// What the binding files share: the problem and solution as Python sees them, in either dimension,
// numpy callables as batch fields, and dicts as the TOML text the CLI's reader reads.
#include <pybind11/pybind11.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "fictus/io/problem_file.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/options.hpp"

namespace fictus::python {

/// Errors raised inside Python callables while the solver ran (they cannot cross its threads).
/// One per solve, so that two solves of one Problem (two threads) never see each other's errors.
struct CallbackErrors {
  std::mutex mutex;
  std::string message;
  bool interrupted = false;  // Ctrl-C (KeyboardInterrupt) inside a callable

  /// Raises what a callable raised: KeyboardInterrupt, or ValueError with `message`; else nothing.
  void raise_if_any();
  /// The solver's interruption check: Ctrl-C seen by Python, or a KeyboardInterrupt raised inside a
  /// callable (which consumed the signal). Takes the GIL; never holds the mutex and the GIL together.
  bool interrupt_requested();
};

/// A numpy callable fn(x, y) or fn(x, y, z) -> array as a batch field; errors go to `errors` (the field
/// returns NaN).
VectorizedField wrap2(pybind11::function fn, const std::string& key, std::shared_ptr<CallbackErrors> errors);
VectorizedField3 wrap3(pybind11::function fn, const std::string& key, std::shared_ptr<CallbackErrors> errors);

/// The callables among data's f, g and exact, by key; each is replaced in `data` by the placeholder
/// expression "0" for the reader.
std::map<std::string, pybind11::function> take_callables(pybind11::dict data);

/// A dict of sections ({"domain": {...}, "data": {...}}) as the TOML text of a problem file.
std::string toml_text(pybind11::dict sections);

/// A solved problem, as Python sees it: a 2-D or a 3-D solution and the grid-level settings it had.
struct PySolution {
  int dim = 2;
  std::shared_ptr<const Solution> s2;
  std::shared_ptr<const SurfaceSolution> s3;
  DomainSettings domain;
  std::vector<double> points, normals;  // (m, dim), interleaved
};

/// A problem and its solver options, as Python sees it, in either dimension.
struct PyProblem {
  int dim = 2;
  ProblemSpec spec2;
  SurfaceProblemSpec spec3;
  std::map<std::string, pybind11::function> callables;  // data key ("f", "g", "exact") → numpy callable

  /// From sections and flat keywords; `implied_dim` when domain.dim is not given (SurfaceProblem: 3).
  static PyProblem from_config(pybind11::dict config, int implied_dim = 2);
  /// From a problem file's text; `source` its path (a mesh file is relative to its folder).
  static PyProblem from_text(const std::string& text, const std::string& source = "problem", int implied_dim = 2);
  static PyProblem paper(int N, double c, const std::string& boundary, pybind11::dict options);
  const SolverOptions& options() const { return dim == 2 ? spec2.options : spec3.options; }
  const std::vector<std::string>& warnings() const { return dim == 2 ? spec2.warnings : spec3.warnings; }
  int N() const { return dim == 2 ? spec2.problem.N : spec3.problem.N; }
  /// Solves with the callables bound to this solve's error slot (the GIL released meanwhile).
  PySolution solve(bool field) const;
};

/// SurfaceProblem: a Problem whose dimension is 3 unless its description says otherwise.
struct PySurfaceProblem : PyProblem {};
/// SurfaceSolution: the Solution of a 3-D problem (the class Python sees for dim = 3).
struct PySurfaceSolution : PySolution {};

/// A solution as its Python object: a SurfaceSolution in 3-D, a Solution in 2-D.
pybind11::object solution_object(PySolution s);

}  // namespace fictus::python
