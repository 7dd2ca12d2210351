// fictus.Solution, one class for both dimensions: the grid field û as a numpy array with its
// coordinates, the per-point quantities on γ (views of the solver's arrays, no copies), Newton's
// report, checks, timings, errors and the options in effect. SurfaceSolution is its 3-D name.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "bindings.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/options.hpp"
#include "python_problem.hpp"

namespace py = pybind11;

namespace fictus::python {

py::object solution_object(PySolution s) {
  if (s.dim == 3) return py::cast(PySurfaceSolution{std::move(s)});
  return py::cast(std::move(s));
}

namespace {

/// `f(solution)` on the solution of either dimension (f is generic over BasicSolution<dim>).
template <class F>
decltype(auto) on(const PySolution& p, F&& f) {
  if (p.dim == 2) return f(*p.s2);
  return f(*p.s3);
}

template <class F>
decltype(auto) on(py::handle self, F&& f) {
  return on(self.cast<const PySolution&>(), std::forward<F>(f));
}

py::array_t<double> read_only(py::array_t<double> a) {
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

/// A read-only 1-D view of a vector owned by the Solution object `owner` (no copy).
py::array_t<double> view(const std::vector<double>& v, py::handle owner) {
  return read_only(py::array_t<double>({py::ssize_t(v.size())}, {py::ssize_t(sizeof(double))}, v.data(), owner));
}

/// A read-only (n, dim) view of interleaved coordinates owned by `owner` (no copy).
py::array_t<double> rows_view(const std::vector<double>& v, int dim, py::handle owner) {
  return read_only(py::array_t<double>({py::ssize_t(v.size() / std::size_t(dim)), py::ssize_t(dim)},
                                       {py::ssize_t(dim * sizeof(double)), py::ssize_t(sizeof(double))}, v.data(),
                                       owner));
}

/// The node coordinates along axis d (0: x, 1: y, 2: z).
template <int dim>
py::array_t<double> axis(const Grid<dim>& g, int d) {
  py::array_t<double> x(g.n(d) + 1);
  for (int i = 0; i <= g.n(d); ++i) x.mutable_data()[i] = g.coordinate(d, i);
  return x;
}

/// û at every node, indexed [j, i] in 2-D and [k, j, i] in 3-D (zero on a Dirichlet boundary).
template <int dim>
py::array_t<double> field(const BasicSolution<dim>& s) {
  if (s.u.empty()) throw std::invalid_argument("u: the field was not computed (solve(field=True))");
  const Grid<dim>& g = s.grid;
  std::vector<py::ssize_t> shape;
  for (int d = dim - 1; d >= 0; --d) shape.push_back(g.n(d) + 1);
  py::array_t<double> u(shape);
  double* out = u.mutable_data();
  std::size_t nodes = 1;
  for (int d = 0; d < dim; ++d) nodes *= std::size_t(g.n(d) + 1);
  for (std::size_t flat = 0; flat < nodes; ++flat) {  // row-major over ((z,) y, x): x fastest
    typename Grid<dim>::Index node;
    std::size_t rest = flat;
    for (int d = 0; d < dim; ++d) node[d] = int(rest % std::size_t(g.n(d) + 1)), rest /= std::size_t(g.n(d) + 1);
    out[flat] = g.has_unknown(node) ? s.u[g.index(node)] : 0.0;
  }
  return u;
}

/// The points of Γ carrying λ (= the points of γ in the non-smooth variant), (m, dim).
py::array_t<double> gamma_points(const PySolution& p) {
  const int m = on(p, [](const auto& s) { return s.n_points(); });
  py::array_t<double> a({py::ssize_t(m), py::ssize_t(p.dim)});
  auto r = a.mutable_unchecked<2>();
  if (p.dim == 2) {
    const Solution& s = *p.s2;
    for (int i = 0; i < m; ++i) {
      const Point2 q = s.Gamma->position(s.collocation.t[i]);
      r(i, 0) = q.x, r(i, 1) = q.y;
    }
  } else {
    const SurfaceSolution& s = *p.s3;
    for (int i = 0; i < m; ++i)
      for (int d = 0; d < 3; ++d) r(i, d) = s.Gamma.point[i][d];
  }
  return a;
}

template <int dim>
py::dict signorini(const BasicSolution<dim>& s) {
  py::dict d;
  d["min_gap"] = s.signorini.min_gap;
  d["min_normal_derivative"] = s.signorini.min_normal_derivative;
  d["max_complementarity"] = s.signorini.max_complementarity;
  if (const auto& k = s.check) {
    py::dict check;
    check["rule"] = k->rule;
    check["min_normal_derivative"] = k->min_normal_derivative;
    check["max_complementarity"] = k->max_complementarity;
    check["max_difference"] = k->max_difference;
    check["rms_difference"] = k->rms_difference;
    check["relative_difference"] = k->relative_difference;
    d["check"] = check;
  }
  return d;
}

template <int dim>
py::dict contact(const BasicSolution<dim>& s) {
  const ContactSummary c = contact_summary(s);
  py::dict d;
  d["points"] = c.points;
  d["measure"] = c.measure;
  d["measure_points"] = c.measure_points;
  py::array_t<double> ends({py::ssize_t(s.contact_boundary.size()), py::ssize_t(dim)});
  for (std::size_t k = 0; k < s.contact_boundary.size(); ++k)
    for (int a = 0; a < dim; ++a) ends.mutable_at(py::ssize_t(k), py::ssize_t(a)) = s.contact_boundary[k][a];
  d["boundary"] = ends;  // the located contact ends, one row per point
  py::array_t<long long> lines({py::ssize_t(s.contact_boundary_lines.size()), py::ssize_t(2)});
  for (std::size_t k = 0; k < s.contact_boundary_lines.size(); ++k)
    for (int a = 0; a < 2; ++a)
      lines.mutable_at(py::ssize_t(k), py::ssize_t(a)) = s.contact_boundary_lines[k][std::size_t(a)];
  d["boundary_lines"] = lines;  // 3-D: the rows of consecutive ends
  d["fit"] = py::none();        // solver.fit_contact: the solves placed to the contact boundary
  if (const auto& f = s.contact_fit) {
    py::dict fit;
    fit["passes"] = f->passes;
    fit["moved"] = f->moved;
    fit["newton_steps"] = f->newton_steps;
    fit["seconds"] = f->seconds;
    d["fit"] = fit;
  }
  d["force"] = c.force;
  d["force_patches"] = c.force_patches;
  d["force_rule"] = c.force_from_domain ? "domain" : "patches";
  d["lambda_integral"] = c.lambda;
  d["min_gap"] = c.min_gap;
  d["max_gap"] = c.max_gap;
  py::dict parts;
  for (const auto& [name, part] : {std::pair<const char*, const PartSummary*>{"signorini", &c.signorini},
                                   {"dirichlet", &c.dirichlet},
                                   {"neumann", &c.neumann}})
    parts[name] =
        py::dict(py::arg("points") = part->points, py::arg("measure") = part->measure, py::arg("flux") = part->flux);
  py::array_t<double> junctions({py::ssize_t(s.junctions.size()), py::ssize_t(dim)});
  for (std::size_t k = 0; k < s.junctions.size(); ++k)
    for (int a = 0; a < dim; ++a) junctions.mutable_at(py::ssize_t(k), py::ssize_t(a)) = s.junctions[k].at[a];
  parts["junctions"] = junctions;  // where the parts meet, located between the points
  d["conditions"] = parts;
  return d;
}

template <int dim>
py::object domain(const BasicSolution<dim>& s) {
  if (!s.domain) return py::none();
  const DomainQuantities& q = *s.domain;
  py::dict d;
  d["volume"] = q.volume, d["integral_u"] = q.integral_u, d["integral_u2"] = q.integral_u2;
  d["integral_grad2"] = q.integral_grad2, d["integral_f"] = q.integral_f, d["integral_fu"] = q.integral_fu;
  d["energy"] = q.energy, d["flux"] = q.flux;
  return std::move(d);
}

template <int dim>
py::object estimate(const BasicSolution<dim>& s) {
  if (!s.estimate) return py::none();
  const ErrorEstimate& e = *s.estimate;
  py::dict d;
  if (!e.skipped.empty()) {
    d["skipped"] = e.skipped, d["seconds"] = e.seconds;
    return std::move(d);
  }
  d["N"] = e.N, d["l2_omega"] = e.l2_omega, d["rel_l2_omega"] = e.rel_l2_omega, d["force"] = e.force;
  d["measure"] = e.measure, d["energy"] = e.energy, d["integral_u"] = e.integral_u, d["seconds"] = e.seconds;
  if (!e.caveat.empty()) d["caveat"] = e.caveat;
  return std::move(d);
}

template <int dim>
py::object errors(const BasicSolution<dim>& s) {
  if (!s.errors) return py::none();
  const ErrorNorms& e = *s.errors;
  py::dict d;
  d["l2_omega"] = e.l2_omega, d["h1_omega"] = e.h1_omega, d["h1semi_omega"] = e.h1semi_omega;
  d["l2_gamma"] = e.l2_gamma, d["rel_l2_omega"] = e.rel_l2_omega;
  d["rel_h1_omega"] = e.rel_h1_omega, d["rel_h1semi_omega"] = e.rel_h1semi_omega;
  d["rel_l2_gamma"] = e.rel_l2_gamma;
  d["integral_u"] = e.integral_u, d["force"] = e.force, d["energy"] = e.energy;
  if (const auto& pe = s.point_errors) {
    d["max_trace_at_points"] = pe->max_trace;
    d["max_normal_derivative_at_points"] = pe->max_normal_derivative;
  }
  return d;
}

template <int dim>
py::object nested_start(const BasicSolution<dim>& s) {
  const auto& n = s.nested_start;
  if (!n) return py::none();
  py::dict d;
  if (n->skipped.empty())
    d["N"] = n->N, d["multipliers"] = n->multipliers, d["newton_steps"] = n->newton_steps, d["active"] = n->active;
  else
    d["skipped"] = n->skipped;
  d["seconds"] = n->seconds;
  return d;
}

template <int dim>
py::object flux_balance(const BasicSolution<dim>& s) {
  const auto& b = s.flux_balance;
  if (!b) return py::none();
  py::dict d;
  d["scatter"] = b->scatter, d["mean"] = b->mean, d["data_shift"] = b->data_shift;
  return d;
}

/// The options in effect that apply to this dimension, by key (as results.json's `options`).
py::dict options(const PySolution& p) {
  const SolverOptions& o = on(p, [](const auto& s) -> const SolverOptions& { return s.options; });
  py::dict d;
  for (const OptionSpec& spec : option_specs())
    if (spec.applies_to(p.dim))
      std::visit([&](const auto& v) { d[py::str(spec.key)] = py::cast(v); }, spec.get(p.domain, o));
  return d;
}

/// Raised for what one dimension has and the other not (x.s in 3-D, x.area in 2-D).
[[noreturn]] void only_in(int dim, const std::string& what, const std::string& instead) {
  throw py::attribute_error(what + ": exists in " + std::to_string(dim) + "-D solutions only; " + instead);
}

}  // namespace

void bind_solution(py::module_& m) {
  py::class_<PySolution>(m, "Solution", R"doc(The result of Problem.solve(), in 2-D or 3-D; arrays are numpy arrays.

    u: û at every node, indexed [j, i] (2-D) or [k, j, i] (3-D); x, y, z / axes: the node coordinates.
    points, normals (m, dim): the points of γ the values belong to; weights: the part of γ each owns
    (an arc length in 2-D, a patch area in 3-D); g, u_gamma (B_γû), dudn (C_γû), lambda_, contact.
)doc")
      .def_property_readonly("dim", [](const PySolution& p) { return p.dim; })
      .def_property_readonly(
          "u", [](const PySolution& p) { return on(p, [](const auto& s) { return field(s); }); },
          "û at every node, indexed [j, i] = (y, x) in 2-D and [k, j, i] = (z, y, x) in 3-D (zero on a Dirichlet "
          "boundary)")
      .def_property_readonly(
          "axes",
          [](const PySolution& p) {
            py::list axes;
            for (int d = 0; d < p.dim; ++d) axes.append(on(p, [d](const auto& s) { return axis(s.grid, d); }));
            return py::tuple(axes);
          },
          "the node coordinates along each axis: (x, y) or (x, y, z)")
      .def_property_readonly("x",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return axis(s.grid, 0); }); })
      .def_property_readonly("y",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return axis(s.grid, 1); }); })
      .def_property_readonly("z",
                             [](const PySolution& p) {
                               if (p.dim != 3) only_in(3, "z", "a 2-D grid has x and y");
                               return axis(p.s3->grid, 2);
                             })
      .def_property_readonly(
          "points",
          [](py::object self) {
            return rows_view(self.cast<const PySolution&>().points, self.cast<const PySolution&>().dim, self);
          },
          "the point of γ each value belongs to, (m, dim): a collocation point (2-D) or a patch's point (3-D)")
      .def_property_readonly("normals",
                             [](py::object self) {
                               const PySolution& p = self.cast<const PySolution&>();
                               return rows_view(p.normals, p.dim, self);
                             })
      .def_property_readonly(
          "weights", [](py::object self) { return on(self, [&](const auto& s) { return view(s.weights(), self); }); },
          "the part of γ each point owns: an arc length (2-D) or a patch area (3-D)")
      .def_property_readonly(
          "s",
          [](py::object self) {
            const PySolution& p = self.cast<const PySolution&>();
            if (p.dim != 2) only_in(2, "s", "a surface's points have weights (patch areas)");
            return view(p.s2->collocation.s, self);
          },
          "the arc length of each collocation point (2-D)")
      .def_property_readonly(
          "area",
          [](py::object self) {
            const PySolution& p = self.cast<const PySolution&>();
            if (p.dim != 3) only_in(3, "area", "a curve's points have s (arc length) and weights (arcs)");
            return view(p.s3->gamma.area, self);
          },
          "the area of each patch (3-D; the same as weights)")
      .def_property_readonly("g",
                             [](py::object self) { return on(self, [&](const auto& s) { return view(s.g, self); }); })
      .def_property_readonly(
          "u_gamma", [](py::object self) { return on(self, [&](const auto& s) { return view(s.trace, self); }); },
          "B_γû at the points")
      .def_property_readonly(
          "dudn",
          [](py::object self) { return on(self, [&](const auto& s) { return view(s.normal_derivative, self); }); },
          "C_γû at the points")
      .def_property_readonly(
          "lambda_", [](py::object self) { return on(self, [&](const auto& s) { return view(s.lambda, self); }); },
          "the multipliers (controls on Γ in the smooth variant)")
      .def_property_readonly("contact",
                             [](const PySolution& p) {
                               return on(p, [](const auto& s) {
                                 py::array_t<bool> a(py::ssize_t(s.n_points()));
                                 for (int i = 0; i < s.n_points(); ++i) a.mutable_data()[i] = s.in_contact(i);
                                 return a;
                               });
                             })
      .def_property_readonly(
          "condition",
          [](const PySolution& p) {
            return on(p, [](const auto& s) {
              py::array_t<int> a(py::ssize_t(s.n_points()));
              for (int i = 0; i < s.n_points(); ++i) a.mutable_data()[i] = int(s.condition(i));
              return a;
            });
          },
          "each point's condition: 0 Signorini, 1 Dirichlet, 2 Neumann")
      .def_property_readonly("gamma_points", &gamma_points,
                             "the points of Γ carrying λ (= points in the non-smooth variant)")
      .def_property_readonly(
          "iterations", [](const PySolution& p) { return on(p, [](const auto& s) { return s.newton.iterations; }); })
      .def_property_readonly(
          "converged", [](const PySolution& p) { return on(p, [](const auto& s) { return s.newton.converged; }); })
      .def_property_readonly("fast_solves",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return s.fast_solves; }); })
      .def_property_readonly("multipliers",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return s.n_points(); }); })
      .def_property_readonly("delta", [](const PySolution& p) { return on(p, [](const auto& s) { return s.delta; }); })
      .def_property_readonly(
          "condition_number",
          [](const PySolution& p) { return on(p, [](const auto& s) { return s.condition_number; }); })
      .def_property_readonly(
          "peak_memory_bytes",
          [](const PySolution& p) { return on(p, [](const auto& s) { return s.peak_memory_bytes; }); })
      .def_property_readonly("warnings",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return s.warnings; }); })
      .def_property_readonly("timings",
                             [](const PySolution& p) {
                               const Timings& t = on(p, [](const auto& s) -> const Timings& { return s.timings; });
                               py::dict d;
                               for (const auto& [phase, seconds] : t.phases) d[py::str(phase)] = seconds;
                               d["total"] = t.total;
                               return d;
                             })
      .def_property_readonly("nested_start",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return nested_start(s); }); })
      .def_property_readonly("flux_balance",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return flux_balance(s); }); })
      .def_property_readonly("signorini",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return signorini(s); }); })
      .def_property_readonly("contact_summary",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return contact(s); }); })
      .def_property_readonly("domain",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return domain(s); }); })
      .def_property_readonly("estimate",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return estimate(s); }); })
      .def_property_readonly("errors",
                             [](const PySolution& p) { return on(p, [](const auto& s) { return errors(s); }); })
      .def_property_readonly("options", &options, "the options in effect that apply to this dimension, by key")
      .def("__repr__", [](const PySolution& p) {
        return on(p, [&](const auto& s) {
          return std::string(p.dim == 2 ? "<fictus.Solution" : "<fictus.SurfaceSolution") +
                 " N=" + std::to_string(s.grid.n(0)) + " m=" + std::to_string(s.n_points()) +
                 " newton=" + std::to_string(s.newton.iterations) +
                 " active=" + std::to_string(std::count(s.newton.active.begin(), s.newton.active.end(), 1)) + ">";
        });
      });

  py::class_<PySurfaceSolution, PySolution>(m, "SurfaceSolution", "The Solution of a 3-D problem.");
}

}  // namespace fictus::python
