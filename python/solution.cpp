// fictus.Solution: the grid field û as a 2-D numpy array with its coordinates, the per-point
// quantities on γ (views of the solver's arrays, no copies), iterations, timings, errors, options.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "bindings.hpp"
#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/io/process.hpp"
#include "fictus/options.hpp"
#include "python_problem.hpp"

namespace py = pybind11;

namespace fictus::python {

PySolution PyProblem::solve(bool field) {
  const auto errors = std::make_shared<CallbackErrors>();  // this solve's own slot
  const Problem problem = bound(errors);
  check_memory(problem, spec.options);
  std::shared_ptr<const Solution> solution;
  try {
    FictitiousDomainSolver solver(problem, spec.options);
    // Ctrl-C: Python's handler runs in PyErr_CheckSignals (this thread, under the GIL) and leaves
    // KeyboardInterrupt set; the solve stops at its next check.
    solver.set_interrupt_check([errors] { return errors->interrupt_requested(); });
    py::gil_scoped_release release;
    solution = std::make_shared<const Solution>(solver.solve(problem, spec.options, field));
  } catch (const Interrupted&) {
    if (!PyErr_Occurred()) PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  } catch (const std::invalid_argument&) {
    errors->raise_if_any();  // a NaN from a failed callable: report the callable, not the NaN
    throw;
  }
  errors->raise_if_any();
  std::const_pointer_cast<Solution>(solution)->peak_memory_bytes = peak_memory_bytes();
  if (!solution->newton.converged) throw std::runtime_error(describe_newton_failure(*solution));
  return PySolution(solution, problem);
}

namespace {

/// A 1-D view of a vector owned by the Solution object `owner` (no copy).
py::array_t<double> read_only(py::array_t<double> a) {
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

/// A read-only 1-D view of a vector owned by the Solution object `owner` (no copy).
py::array_t<double> view(const std::vector<double>& v, py::handle owner) {
  return read_only(py::array_t<double>({py::ssize_t(v.size())}, {py::ssize_t(sizeof(double))}, v.data(), owner));
}

/// An (n, 2) view of interleaved pairs owned by `owner` (no copy).
py::array_t<double> pairs_view(const std::vector<double>& v, py::handle owner) {
  return read_only(py::array_t<double>({py::ssize_t(v.size() / 2), py::ssize_t(2)},
                                       {py::ssize_t(2 * sizeof(double)), py::ssize_t(sizeof(double))}, v.data(),
                                       owner));
}

/// Every option of options.hpp in effect, by key (as results.json's `options`).
py::dict options_dict(const Problem& problem, const SolverOptions& o) {
  py::dict d;
  for (const OptionSpec& spec : option_specs())
    std::visit([&](const auto& v) { d[py::str(spec.key)] = py::cast(v); }, spec.get(problem, o));
  return d;
}

}  // namespace

void bind_solution(py::module_& m) {
  py::class_<PySolution>(m, "Solution", "The result of Problem.solve(); arrays are numpy arrays.")
      .def_property_readonly("u",
                             [](const PySolution& p) {
                               // û at all (ny+1) × (nx+1) nodes, row j = y_j (zero on a Dirichlet boundary).
                               const Solution& s = p.s();
                               if (s.u.empty())
                                 throw std::invalid_argument("u: the field was not computed (solve(field=True))");
                               const Grid2& g = s.grid;
                               py::array_t<double> u({g.ny() + 1, g.nx() + 1});
                               auto a = u.mutable_unchecked<2>();
                               for (int j = 0; j <= g.ny(); ++j)
                                 for (int i = 0; i <= g.nx(); ++i)
                                   a(j, i) = g.has_unknown(i, j) ? s.u[g.index(i, j)] : 0.0;
                               return u;
                             })
      .def_property_readonly("x",
                             [](const PySolution& p) {
                               const Grid2& g = p.s().grid;
                               py::array_t<double> x(g.nx() + 1);
                               for (int i = 0; i <= g.nx(); ++i) x.mutable_data()[i] = g.x(i);
                               return x;
                             })
      .def_property_readonly("y",
                             [](const PySolution& p) {
                               const Grid2& g = p.s().grid;
                               py::array_t<double> y(g.ny() + 1);
                               for (int j = 0; j <= g.ny(); ++j) y.mutable_data()[j] = g.y(j);
                               return y;
                             })
      .def_property_readonly("points",
                             [](py::object self) { return pairs_view(self.cast<const PySolution&>().points(), self); })
      .def_property_readonly("normals",
                             [](py::object self) { return pairs_view(self.cast<const PySolution&>().normals(), self); })
      .def_property_readonly(
          "s", [](py::object self) { return view(self.cast<const PySolution&>().s().collocation.s, self); },
          "arc length of each collocation point")
      .def_property_readonly("g", [](py::object self) { return view(self.cast<const PySolution&>().s().g, self); })
      .def_property_readonly(
          "u_gamma", [](py::object self) { return view(self.cast<const PySolution&>().s().trace, self); },
          "B_γû at the collocation points")
      .def_property_readonly(
          "dudn", [](py::object self) { return view(self.cast<const PySolution&>().s().normal_derivative, self); },
          "C_γû at the collocation points")
      .def_property_readonly(
          "lambda_", [](py::object self) { return view(self.cast<const PySolution&>().s().lambda, self); },
          "the multipliers (controls on Γ in the smooth variant)")
      .def_property_readonly("contact",
                             [](const PySolution& p) {
                               const auto& c = p.contact_flags();
                               py::array_t<bool> a(py::ssize_t(c.size()));
                               for (std::size_t i = 0; i < c.size(); ++i) a.mutable_data()[i] = c[i];
                               return a;
                             })
      .def_property_readonly(
          "gamma_points",
          [](const PySolution& p) {
            const Solution& s = p.s();
            py::array_t<double> a({py::ssize_t(s.collocation.m), py::ssize_t(2)});
            auto r = a.mutable_unchecked<2>();
            for (int i = 0; i < s.collocation.m; ++i) {
              const Point2 q = s.Gamma->position(s.collocation.t[i]);
              r(i, 0) = q.x, r(i, 1) = q.y;
            }
            return a;
          },
          "the points of Γ carrying λ (= points in the non-smooth variant)")
      .def_property_readonly("iterations", [](const PySolution& p) { return p.s().newton.iterations; })
      .def_property_readonly("converged", [](const PySolution& p) { return p.s().newton.converged; })
      .def_property_readonly("fast_solves", [](const PySolution& p) { return p.s().fast_solves; })
      .def_property_readonly("multipliers", [](const PySolution& p) { return p.s().collocation.m; })
      .def_property_readonly("delta", [](const PySolution& p) { return p.s().delta; })
      .def_property_readonly("condition_number", [](const PySolution& p) { return p.s().condition_number; })
      .def_property_readonly("peak_memory_bytes", [](const PySolution& p) { return p.s().peak_memory_bytes; })
      .def_property_readonly("warnings", [](const PySolution& p) { return p.s().warnings; })
      .def_property_readonly("timings",
                             [](const PySolution& p) {
                               py::dict d;
                               for (const auto& [phase, seconds] : p.s().timings.phases) d[py::str(phase)] = seconds;
                               d["total"] = p.s().timings.total;
                               return d;
                             })
      .def_property_readonly("signorini",
                             [](const PySolution& p) {
                               const SignoriniCheck& c = p.s().signorini;
                               py::dict d;
                               d["min_gap"] = c.min_gap;
                               d["min_normal_derivative"] = c.min_normal_derivative;
                               d["max_complementarity"] = c.max_complementarity;
                               if (const auto& k = p.s().check) {
                                 py::dict check;
                                 check["rule"] = k->rule;
                                 check["min_normal_derivative"] = k->min_normal_derivative;
                                 check["max_complementarity"] = k->max_complementarity;
                                 check["max_difference"] = k->max_difference;
                                 check["rms_difference"] = k->rms_difference;
                                 d["check"] = check;
                               }
                               return d;
                             })
      .def_property_readonly("contact_summary",
                             [](const PySolution& p) {
                               const ContactSummary c = contact_summary(p.s());
                               py::dict d;
                               d["points"] = c.points;
                               d["measure"] = c.measure;
                               d["force"] = c.force;
                               d["lambda_integral"] = c.lambda;
                               d["min_gap"] = c.min_gap;
                               d["max_gap"] = c.max_gap;
                               return d;
                             })
      .def_property_readonly("errors",
                             [](const PySolution& p) -> py::object {
                               if (!p.s().errors) return py::none();
                               const ErrorNorms& e = *p.s().errors;
                               py::dict d;
                               d["l2_omega"] = e.l2_omega, d["h1_omega"] = e.h1_omega,
                               d["h1semi_omega"] = e.h1semi_omega;
                               d["l2_gamma"] = e.l2_gamma, d["rel_l2_omega"] = e.rel_l2_omega;
                               d["rel_h1_omega"] = e.rel_h1_omega, d["rel_h1semi_omega"] = e.rel_h1semi_omega;
                               d["rel_l2_gamma"] = e.rel_l2_gamma;
                               if (const auto& pe = p.s().point_errors) {
                                 d["max_trace_at_points"] = pe->max_trace;
                                 d["max_normal_derivative_at_points"] = pe->max_normal_derivative;
                               }
                               return d;
                             })
      .def_property_readonly("options",
                             [](const PySolution& p) {
                               py::dict d = options_dict(p.problem(), p.s().options);
                               d["N"] = p.problem().N;
                               d["c"] = p.problem().c;
                               d["boundary"] = p.problem().boundary == Boundary::periodic ? "periodic" : "dirichlet";
                               return d;
                             })
      .def("__repr__", [](const PySolution& p) {
        const Solution& s = p.s();
        return "<fictus.Solution N=" + std::to_string(s.grid.nx()) + " m=" + std::to_string(s.collocation.m) +
               " newton=" + std::to_string(s.newton.iterations) +
               " active=" + std::to_string(std::count(s.newton.active.begin(), s.newton.active.end(), 1)) + ">";
      });
}

}  // namespace fictus::python
