#pragma once
#include <pybind11/pybind11.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/io/problem_file.hpp"

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

/// A numpy callable fn(x, y, z) -> array as a batch field; errors go to `errors` (the field returns NaN).
VectorizedField3 wrap3(pybind11::function fn, const std::string& key, std::shared_ptr<CallbackErrors> errors);

/// The callables among data's f, g and exact, by key; each is replaced in `data` by the placeholder
/// expression "0" for the reader.
std::map<std::string, pybind11::function> take_callables(pybind11::dict data);

/// A solved problem, as Python sees it.
class PySolution {
 public:
  PySolution(std::shared_ptr<const Solution> s, Problem problem) : s_(std::move(s)), problem_(std::move(problem)) {
    const int m = s_->collocation.m;
    contact_.assign(s_->newton.active.begin(), s_->newton.active.end());
    points_.resize(2 * m);
    normals_.resize(2 * m);
    for (int i = 0; i < m; ++i) {
      points_[2 * i] = s_->collocation.point[i].x, points_[2 * i + 1] = s_->collocation.point[i].y;
      normals_[2 * i] = s_->collocation.normal[i].x, normals_[2 * i + 1] = s_->collocation.normal[i].y;
    }
  }
  const Solution& s() const { return *s_; }
  const Problem& problem() const { return problem_; }
  const std::vector<double>& points() const { return points_; }
  const std::vector<double>& normals() const { return normals_; }
  const std::vector<bool>& contact_flags() const { return contact_; }

 private:
  std::shared_ptr<const Solution> s_;
  Problem problem_;
  std::vector<double> points_, normals_;
  std::vector<bool> contact_;
};

/// A dict of sections ({"domain": {...}, "data": {...}}) as the TOML text of a problem file.
std::string toml_text(pybind11::dict sections);

struct PyProblem {
  ProblemSpec spec;
  std::map<std::string, pybind11::function> callables;  // data key ("f", "g", "exact") → numpy callable

  static PyProblem from_config(pybind11::dict config);
  static PyProblem paper(int N, double c, const std::string& boundary, pybind11::dict options);
  /// The problem with the callables bound to this solve's error slot.
  Problem bound(const std::shared_ptr<CallbackErrors>& errors) const;
  static VectorizedField wrap(pybind11::function fn, const std::string& key, std::shared_ptr<CallbackErrors> errors);
  PySolution solve(bool field);
};

}  // namespace fictus::python
