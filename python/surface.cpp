// fictus.SurfaceProblem and fictus.SurfaceSolution: 3-D problems (a closed surface in a box)
// from a dict or TOML text, through the CLI's reader; û as an (N+1)³ numpy array and the per-patch
// quantities on γ.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "bindings.hpp"
#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/io/problem_file.hpp"
#include "fictus/io/process.hpp"
#include "fictus/mesh_surface.hpp"
#include "fictus/omega_quadrature.hpp"
#include "fictus/options.hpp"
#include "fictus/surface.hpp"
#include "fictus/surface_discretization.hpp"
#include "python_problem.hpp"

namespace py = pybind11;

namespace fictus::python {

namespace {

/// A MeshSurface from a float array (n, 3) of vertices and an integer array (k, 3) of triangles.
std::shared_ptr<const Surface> mesh_from_arrays(py::handle vertices, py::handle faces, double resolution) {
  const auto v = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(vertices);
  if (!v || v.ndim() != 2 || v.shape(1) != 3)
    throw std::invalid_argument("geometry.vertices: expected an (n, 3) array");
  const py::array given = py::array::ensure(faces);
  if (given && given.dtype().kind() != 'i' && given.dtype().kind() != 'u')
    throw std::invalid_argument("geometry.faces: expected integer vertex indices, got " +
                                std::string(py::str(given.dtype())));
  const auto f = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(faces);
  if (!f || f.ndim() != 2 || f.shape(1) != 3)
    throw std::invalid_argument("geometry.faces: expected a (k, 3) array of vertex indices");
  check_mesh_resolution(resolution);
  PolygonSoup soup;
  for (py::ssize_t i = 0; i < v.shape(0); ++i) soup.vertices.push_back({v.at(i, 0), v.at(i, 1), v.at(i, 2)});
  for (py::ssize_t i = 0; i < f.shape(0); ++i) {
    std::vector<std::size_t> face;
    for (int k = 0; k < 3; ++k) {
      const long long index = f.at(i, k);
      if (index < 0 || index >= (long long)soup.vertices.size())
        throw std::invalid_argument("geometry.faces: vertex index " + std::to_string(index) + " out of range");
      face.push_back(std::size_t(index));
    }
    soup.faces.push_back(std::move(face));
  }
  py::gil_scoped_release release;
  return std::make_shared<MeshSurface>(soup, int(resolution), "geometry.vertices");
}

struct PySurfaceProblem {
  SurfaceProblemSpec spec;
  std::map<std::string, py::function> callables;  // data key ("f", "g", "exact") → numpy callable fn(x, y, z)

  /// The problem with the callables bound to this solve's error slot.
  SurfaceProblem bound(const std::shared_ptr<CallbackErrors>& errors) const {
    SurfaceProblem problem = spec.problem;
    for (const auto& [key, fn] : callables) {
      VectorizedField3 field = wrap3(fn, "data." + key, errors);
      if (key == "f") problem.f = nullptr, problem.f_vectorized = field;
      if (key == "g") problem.g = nullptr, problem.g_vectorized = field;
      if (key == "exact") problem.exact = nullptr, problem.exact_gradient = nullptr, problem.exact_vectorized = field;
    }
    return problem;
  }

  static PySurfaceProblem from_config(py::dict config) {
    py::dict sections;
    for (auto [k, v] : config) {
      const std::string key = py::str(k);
      if (key != "domain" && key != "geometry" && key != "formulation" && key != "data" && key != "solver" &&
          key != "output")
        throw std::invalid_argument(
            key + ": unknown section (domain, geometry, formulation, data, solver, output)" +
            did_you_mean(key, {"domain", "geometry", "formulation", "data", "solver", "output"}));
      if (!py::isinstance<py::dict>(v)) throw std::invalid_argument(key + ": expected a dict");
      py::dict copy;  // the caller's dict stays as it was (callables are replaced by placeholders below)
      for (auto [kk, vv] : v.cast<py::dict>()) copy[kk] = vv;
      sections[py::str(key)] = copy;
    }
    if (!sections.contains("domain")) sections["domain"] = py::dict();
    py::dict domain = sections["domain"];
    if (!domain.contains("dim")) domain["dim"] = 3;
    // Callables in [data] are attached at each solve; the TOML gets placeholders.
    std::map<std::string, py::function> callables;
    if (sections.contains("data")) callables = take_callables(sections["data"]);
    // A mesh from numpy arrays: geometry.vertices (n, 3) and geometry.faces (k, 3), built here and
    // handed to the reader as the surface of shape = "mesh".
    std::shared_ptr<const Surface> mesh;
    if (sections.contains("geometry")) {
      py::dict geometry = sections["geometry"];
      if (geometry.contains("vertices") || geometry.contains("faces")) {
        if (!geometry.contains("vertices") || !geometry.contains("faces"))
          throw std::invalid_argument("geometry.faces: vertices and faces come together");
        if (geometry.contains("file"))
          throw std::invalid_argument("geometry.file: a file or vertices and faces, not both");
        if (!geometry.contains("shape") || std::string(py::str(geometry["shape"])) != "mesh")
          throw std::invalid_argument("geometry.vertices: vertices and faces need shape = \"mesh\"");
        double resolution = 0;
        if (geometry.contains("resolution")) {
          if (!py::isinstance<py::int_>(geometry["resolution"]) && !py::isinstance<py::float_>(geometry["resolution"]))
            throw std::invalid_argument("geometry.resolution: expected a number");
          resolution = geometry["resolution"].cast<double>();
        }
        mesh = mesh_from_arrays(geometry["vertices"], geometry["faces"], resolution);
        py::dict rest;
        for (auto [k, v] : geometry)
          if (std::string(py::str(k)) != "vertices" && std::string(py::str(k)) != "faces") rest[k] = v;
        sections["geometry"] = rest;
      }
    }
    PySurfaceProblem p;
    p.spec = parse_surface_problem_text(toml_text(sections), "problem", mesh);
    p.callables = std::move(callables);
    if (const auto* surface = dynamic_cast<const MeshSurface*>(mesh.get()))
      for (const std::string& w : surface->warnings()) p.spec.warnings.push_back("geometry.vertices: " + w);
    return p;
  }
};

struct PySurfaceSolution {
  std::shared_ptr<const SurfaceSolution> s;
  std::vector<double> points, normals;  // (m, 3), interleaved
};

PySurfaceSolution solve(const PySurfaceProblem& p) {
  const auto errors = std::make_shared<CallbackErrors>();  // this solve's own slot
  const SurfaceProblem problem = p.bound(errors);
  check_memory(problem, p.spec.options);  // before anything is allocated, as the CLI does
  std::shared_ptr<const SurfaceSolution> solution;
  try {
    // Ctrl-C: Python's handler runs in PyErr_CheckSignals (this thread, under the GIL) and leaves
    // KeyboardInterrupt set; the solve stops at its next check.
    const auto interrupt = [errors] { return errors->interrupt_requested(); };
    py::gil_scoped_release release;
    solution = std::make_shared<const SurfaceSolution>(fictus::solve(problem, p.spec.options, {}, interrupt));
  } catch (const Interrupted&) {
    if (!PyErr_Occurred()) PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  } catch (const std::invalid_argument&) {
    errors->raise_if_any();  // a NaN from a failed callable: report the callable, not the NaN
    throw;
  }
  if (PyErr_Occurred()) throw py::error_already_set();  // a signal seen after the last check
  errors->raise_if_any();
  std::const_pointer_cast<SurfaceSolution>(solution)->peak_memory_bytes = peak_memory_bytes();
  if (!solution->newton.converged)
    throw std::runtime_error("solver.max_newton: Newton did not converge: " + solution->newton.failure);
  PySurfaceSolution out{solution, {}, {}};
  for (int i = 0; i < solution->gamma.m; ++i)
    for (int d = 0; d < 3; ++d) {
      out.points.push_back(solution->gamma.point[i][d]);
      out.normals.push_back(solution->gamma.normal[i][d]);
    }
  return out;
}

/// A read-only view of `v` owned by `owner`, of shape (n) or (n/3, 3).
py::array_t<double> view(const std::vector<double>& v, py::handle owner, bool triples = false) {
  py::array_t<double> a =
      triples ? py::array_t<double>({py::ssize_t(v.size() / 3), py::ssize_t(3)},
                                    {py::ssize_t(3 * sizeof(double)), py::ssize_t(sizeof(double))}, v.data(), owner)
              : py::array_t<double>({py::ssize_t(v.size())}, {py::ssize_t(sizeof(double))}, v.data(), owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

const SurfaceSolution& of(py::handle self) { return *self.cast<const PySurfaceSolution&>().s; }

}  // namespace

void bind_surface(py::module_& m) {
  py::class_<PySurfaceProblem>(m, "SurfaceProblem", R"doc(A 3-D Signorini problem: a closed surface in a box.

    SurfaceProblem(domain=..., geometry=..., formulation=..., data=..., solver=...)
        Sections as dicts with the keys of a 3-D problem file (docs/problem_files.md, "3-D problems");
        domain.dim = 3 is implied. f, g, exact: expressions in x, y, z (str) or numpy callables
        f(x, y, z) -> array, called in batches. A mesh: geometry =
        {"shape": "mesh", "file": path} or {"shape": "mesh", "vertices": (n, 3) array, "faces": (k, 3)
        integer array}, optional "resolution".
    SurfaceProblem.from_dict(d), SurfaceProblem.from_toml(text)
)doc")
      .def(py::init([](py::kwargs kwargs) { return PySurfaceProblem::from_config(kwargs); }))
      .def_static(
          "from_dict", [](py::dict d) { return PySurfaceProblem::from_config(d); }, py::arg("config"))
      .def_static(
          "from_toml",
          [](const std::string& text) { return PySurfaceProblem{parse_surface_problem_text(text, "problem")}; },
          py::arg("text"))
      .def_property_readonly("N", [](const PySurfaceProblem& p) { return p.spec.problem.N; })
      .def_property_readonly(
          "warnings", [](const PySurfaceProblem& p) { return p.spec.warnings; },
          "What the reader changed (e.g. a mesh oriented inward, reoriented).")
      .def("solve", &solve,
           "Solves (the GIL is released meanwhile) and returns a SurfaceSolution; raises ValueError on bad input "
           "and RuntimeError when Newton does not converge, with the CLI's messages.");

  m.def(
      "icosphere",
      [](int levels, std::array<double, 3> center, double radius) {
        const PolygonSoup soup = icosphere({center[0], center[1], center[2]}, radius, levels);
        py::array_t<double> vertices({py::ssize_t(soup.vertices.size()), py::ssize_t(3)});
        py::array_t<long long> faces({py::ssize_t(soup.faces.size()), py::ssize_t(3)});
        for (std::size_t i = 0; i < soup.vertices.size(); ++i)
          for (int d = 0; d < 3; ++d) vertices.mutable_at(i, d) = soup.vertices[i][d];
        for (std::size_t i = 0; i < soup.faces.size(); ++i)
          for (int d = 0; d < 3; ++d) faces.mutable_at(i, d) = (long long)soup.faces[i][std::size_t(d)];
        return py::make_tuple(vertices, faces);
      },
      py::arg("levels"), py::arg("center"), py::arg("radius"),
      "A sphere as (vertices (n, 3), faces (k, 3)): the icosahedron's faces split in four `levels` times "
      "(20·4^levels triangles), for geometry=dict(shape=\"mesh\", vertices=..., faces=...).");

  py::class_<PySurfaceSolution>(m, "SurfaceSolution", "The result of SurfaceProblem.solve(); arrays are numpy arrays.")
      .def_property_readonly(
          "u",
          [](py::object self) {
            const SurfaceSolution& s = of(self);
            const Grid3& g = s.grid;
            py::array_t<double> u({g.nz() + 1, g.ny() + 1, g.nx() + 1});
            auto a = u.mutable_unchecked<3>();
            for (int k = 0; k <= g.nz(); ++k)
              for (int j = 0; j <= g.ny(); ++j)
                for (int i = 0; i <= g.nx(); ++i) {
                  const Grid3::Index node{i, j, k};
                  a(k, j, i) = g.has_unknown(node) ? s.u[g.index(node)] : 0.0;
                }
            return u;
          },
          "û at all (N+1)³ nodes, indexed [k, j, i] = (z, y, x) (zero on a Dirichlet boundary)")
      .def_property_readonly(
          "axes",
          [](py::object self) {
            const Grid3& g = of(self).grid;
            py::list axes;
            for (int d = 0; d < 3; ++d) {
              py::array_t<double> x(g.n(d) + 1);
              for (int i = 0; i <= g.n(d); ++i) x.mutable_data()[i] = g.coordinate(d, i);
              axes.append(x);
            }
            return py::tuple(axes);
          },
          "the node coordinates (x, y, z)")
      .def_property_readonly(
          "points", [](py::object self) { return view(self.cast<const PySurfaceSolution&>().points, self, true); },
          "the collocation point of each patch, (m, 3)")
      .def_property_readonly(
          "normals", [](py::object self) { return view(self.cast<const PySurfaceSolution&>().normals, self, true); })
      .def_property_readonly("area", [](py::object self) { return view(of(self).gamma.area, self); })
      .def_property_readonly("g", [](py::object self) { return view(of(self).g, self); })
      .def_property_readonly("u_gamma", [](py::object self) { return view(of(self).trace, self); })
      .def_property_readonly("dudn", [](py::object self) { return view(of(self).normal_derivative, self); })
      .def_property_readonly("lambda_", [](py::object self) { return view(of(self).lambda, self); })
      .def_property_readonly("contact",
                             [](py::object self) {
                               const SurfaceSolution& s = of(self);
                               py::array_t<bool> c(s.gamma.m);
                               for (int i = 0; i < s.gamma.m; ++i) c.mutable_data()[i] = s.newton.active[i] == 1;
                               return c;
                             })
      .def_property_readonly("iterations", [](py::object self) { return of(self).newton.iterations; })
      .def_property_readonly("multipliers", [](py::object self) { return of(self).gamma.m; })
      .def_property_readonly("delta", [](py::object self) { return of(self).delta; })
      .def_property_readonly("peak_memory_bytes", [](py::object self) { return of(self).peak_memory_bytes; })
      .def_property_readonly("warnings", [](py::object self) { return of(self).warnings; })
      .def_property_readonly("timings",
                             [](py::object self) {
                               py::dict d;
                               for (const auto& [phase, seconds] : of(self).timings.phases) d[py::str(phase)] = seconds;
                               d["total"] = of(self).timings.total;
                               return d;
                             })
      .def_property_readonly("nested_start",
                             [](py::object self) -> py::object {
                               const auto& n = of(self).nested_start;
                               if (!n) return py::none();
                               py::dict d;
                               if (n->skipped.empty())
                                 d["N"] = n->N, d["multipliers"] = n->multipliers, d["newton_steps"] = n->newton_steps,
                                 d["active"] = n->active;
                               else
                                 d["skipped"] = n->skipped;
                               d["seconds"] = n->seconds;
                               return d;
                             })
      .def_property_readonly("flux_balance",
                             [](py::object self) -> py::object {
                               const auto& b = of(self).flux_balance;
                               if (!b) return py::none();
                               py::dict d;
                               d["scatter"] = b->scatter, d["mean"] = b->mean, d["data_shift"] = b->data_shift;
                               return d;
                             })
      .def_property_readonly("signorini",
                             [](py::object self) {
                               const SignoriniCheck& c = of(self).signorini;
                               py::dict d;
                               d["min_gap"] = c.min_gap;
                               d["min_normal_derivative"] = c.min_normal_derivative;
                               d["max_complementarity"] = c.max_complementarity;
                               return d;
                             })
      .def_property_readonly("errors",
                             [](py::object self) -> py::object {
                               const auto& e = of(self).errors;
                               if (!e) return py::none();
                               py::dict d;
                               d["l2_omega"] = e->l2_omega, d["h1_omega"] = e->h1_omega;
                               d["h1semi_omega"] = e->h1semi_omega, d["l2_gamma"] = e->l2_gamma;
                               d["rel_l2_omega"] = e->rel_l2_omega, d["rel_h1_omega"] = e->rel_h1_omega;
                               d["rel_h1semi_omega"] = e->rel_h1semi_omega, d["rel_l2_gamma"] = e->rel_l2_gamma;
                               return d;
                             })
      .def("__repr__", [](py::object self) {
        const SurfaceSolution& s = of(self);
        return "<fictus.SurfaceSolution N=" + std::to_string(s.grid.nx()) + " m=" + std::to_string(s.gamma.m) +
               " newton=" + std::to_string(s.newton.iterations) +
               " active=" + std::to_string(std::count(s.newton.active.begin(), s.newton.active.end(), 1)) + ">";
      });
}

}  // namespace fictus::python
