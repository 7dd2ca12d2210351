// fictus.Problem, in 2-D or 3-D: built from a dict, TOML text, a file, keyword arguments or the paper's
// experiment. Dicts and keywords are turned into the same TOML the CLI reads, so every check and
// message is the CLI's. Data may be expressions (str) or Python callables vectorized over numpy arrays:
// f(x, y) -> array (f(x, y, z) in 3-D). SurfaceProblem is a Problem whose dimension is 3 by default.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "bindings.hpp"
#include "fictus/boundary/mesh_surface.hpp"
#include "fictus/io/problem_file.hpp"
#include "fictus/io/process.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/options.hpp"
#include "fictus/solve/paper_problem.hpp"
#include "python_problem.hpp"

namespace py = pybind11;

namespace fictus::python {

namespace {

/// Where each flat keyword goes: the section of its option (options.hpp), or [data] for the data.
const char* section_of(const std::string& key) {
  if (key == "f" || key == "g" || key == "exact") return "data";
  const OptionSpec* spec = find_option(key);
  return spec ? spec->section.c_str() : nullptr;
}

/// Deeper than any problem description: a self-referential or absurdly nested value stops here.
constexpr int max_depth = 16;

void insert(toml::table& table, const std::string& key, py::handle value, const std::string& where, int depth = 0);

toml::array to_array(py::handle list, const std::string& where, int depth) {
  toml::array a;
  for (py::handle item : list) {
    toml::table wrapper;
    insert(wrapper, "v", item, where, depth + 1);
    a.push_back(*wrapper.get("v"));
  }
  return a;
}

void insert(toml::table& table, const std::string& key, py::handle value, const std::string& where, int depth) {
  if (depth > max_depth)
    throw std::invalid_argument(where.substr(0, 80) + ": nested more than " + std::to_string(max_depth) +
                                " levels deep (or it contains itself)");
  if (py::isinstance<py::bool_>(value))
    table.insert_or_assign(key, value.cast<bool>());
  else if (py::isinstance<py::int_>(value))
    table.insert_or_assign(key, value.cast<int64_t>());
  else if (py::isinstance<py::float_>(value))
    table.insert_or_assign(key, value.cast<double>());
  else if (py::isinstance<py::str>(value))
    table.insert_or_assign(key, value.cast<std::string>());
  else if (py::isinstance<py::dict>(value)) {
    toml::table sub;
    for (auto [k, v] : value.cast<py::dict>())
      insert(sub, py::str(k), v, where + "." + std::string(py::str(k)).substr(0, 40), depth + 1);
    table.insert_or_assign(key, std::move(sub));
  } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value) || py::isinstance<py::array>(value)) {
    const py::object items =
        py::isinstance<py::array>(value) ? value.attr("tolist")() : py::reinterpret_borrow<py::object>(value);
    table.insert_or_assign(key, to_array(items, where, depth));
  } else {
    throw std::invalid_argument(where + ": unsupported value of type " +
                                std::string(py::str(value.get_type().attr("__name__"))));
  }
}

}  // namespace

std::string toml_text(py::dict sections) {
  toml::table root;
  for (auto [k, v] : sections) insert(root, py::str(k), v, py::str(k));
  std::ostringstream text;
  text << root;
  return text.str();
}

void CallbackErrors::raise_if_any() {
  std::lock_guard lock(mutex);
  if (interrupted) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  if (!message.empty()) throw std::invalid_argument(message);
}

bool CallbackErrors::interrupt_requested() {
  {
    std::lock_guard lock(mutex);
    if (interrupted) return true;
  }
  py::gil_scoped_acquire gil;
  return PyErr_CheckSignals() != 0;
}

namespace {

/// The callable, released under the GIL whenever the last copy of a field holding it goes.
std::shared_ptr<py::function> hold(py::function fn) {
  return std::shared_ptr<py::function>(new py::function(std::move(fn)), [](py::function* f) {
    py::gil_scoped_acquire gil;
    delete f;
  });
}

/// out[k] = fn(*coordinates)[k] for k < n. Called from solver threads: never throws through them;
/// records the error in `errors` and returns NaN.
void call_batch(const py::function& fn, const std::string& key, CallbackErrors& errors, std::size_t n,
                std::initializer_list<const double*> coordinates, double* out) {
  {  // after a failure or Ctrl-C in a callable, the solve only runs on to its next interruption check
    std::lock_guard lock(errors.mutex);
    if (errors.interrupted || !errors.message.empty()) {
      std::fill(out, out + n, std::nan(""));
      return;
    }
  }
  py::gil_scoped_acquire gil;
  std::string failure;
  try {
    py::tuple arguments(coordinates.size());
    std::size_t a = 0;
    for (const double* c : coordinates) {
      py::array_t<double> values(n);
      std::copy(c, c + n, values.mutable_data());
      arguments[a++] = values;
    }
    const py::array result = py::array::ensure(fn(*arguments));
    const char kind = result ? result.dtype().kind() : 'O';
    if (kind != 'f' && kind != 'i' && kind != 'u')
      throw std::invalid_argument("the callable must return real numbers (got " +
                                  (result ? std::string(py::str(result.dtype())) : std::string("no array")) + ")");
    const auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(result);
    if (!values || (values.size() != py::ssize_t(n) && values.size() != 1))
      throw std::invalid_argument("the callable must return one number per point (an array of " + std::to_string(n) +
                                  ")");
    for (std::size_t k = 0; k < n; ++k) out[k] = values.data()[values.size() == 1 ? 0 : k];
    return;
  } catch (py::error_already_set& e) {
    if (e.matches(PyExc_KeyboardInterrupt)) {
      std::lock_guard lock(errors.mutex);
      errors.interrupted = true;
    }
    failure = e.what();
  } catch (const std::exception& e) {
    failure = e.what();
  }
  failure = failure.substr(0, failure.find('\n'));  // the exception, without Python's traceback
  std::lock_guard lock(errors.mutex);
  if (errors.message.empty()) errors.message = (key + ": the callable failed: " + failure).substr(0, 300);
  std::fill(out, out + n, std::nan(""));
}

}  // namespace

VectorizedField wrap2(py::function fn, const std::string& key, std::shared_ptr<CallbackErrors> errors) {
  return [holder = hold(std::move(fn)), key, errors](std::size_t n, const double* x, const double* y, double* out) {
    call_batch(*holder, key, *errors, n, {x, y}, out);
  };
}

VectorizedField3 wrap3(py::function fn, const std::string& key, std::shared_ptr<CallbackErrors> errors) {
  return [holder = hold(std::move(fn)), key, errors](std::size_t n, const double* x, const double* y, const double* z,
                                                     double* out) {
    call_batch(*holder, key, *errors, n, {x, y, z}, out);
  };
}

std::map<std::string, py::function> take_callables(py::dict data) {
  std::map<std::string, py::function> callables;
  for (const char* key : {"f", "g", "exact"}) {
    if (data.contains(key) && !py::isinstance<py::str>(data[key]) && py::isinstance<py::function>(data[key])) {
      callables[key] = data[key].cast<py::function>();
      data[key] = py::str("0");
    }
  }
  return callables;
}

namespace {

const std::vector<std::string> section_names = {"domain",     "geometry", "formulation", "data",
                                                "conditions", "solver",   "output",      "parameters"};

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

/// A mesh given as numpy arrays (geometry.vertices and geometry.faces, shape = "mesh"): built here and
/// taken out of the geometry section, which keeps its other keys for the reader.
std::shared_ptr<const Surface> take_mesh(py::dict sections, std::vector<std::string>& warnings) {
  if (!sections.contains("geometry")) return nullptr;
  py::dict geometry = sections["geometry"];
  if (!geometry.contains("vertices") && !geometry.contains("faces")) return nullptr;
  if (!geometry.contains("vertices") || !geometry.contains("faces"))
    throw std::invalid_argument("geometry.faces: vertices and faces come together");
  if (geometry.contains("file")) throw std::invalid_argument("geometry.file: a file or vertices and faces, not both");
  if (!geometry.contains("shape") || std::string(py::str(geometry["shape"])) != "mesh")
    throw std::invalid_argument("geometry.vertices: vertices and faces need shape = \"mesh\"");
  double resolution = 0;
  if (geometry.contains("resolution")) {
    if (!py::isinstance<py::int_>(geometry["resolution"]) && !py::isinstance<py::float_>(geometry["resolution"]))
      throw std::invalid_argument("geometry.resolution: expected a number");
    resolution = geometry["resolution"].cast<double>();
  }
  std::shared_ptr<const Surface> mesh = mesh_from_arrays(geometry["vertices"], geometry["faces"], resolution);
  py::dict rest;
  for (auto [k, v] : geometry)
    if (std::string(py::str(k)) != "vertices" && std::string(py::str(k)) != "faces") rest[k] = v;
  sections["geometry"] = rest;
  if (const auto* surface = dynamic_cast<const MeshSurface*>(mesh.get()))
    for (const std::string& w : surface->warnings()) warnings.push_back("geometry.vertices: " + w);
  return mesh;
}

/// The dimension a set of sections describes: domain.dim, else `implied`.
int dimension_of(py::dict sections, int implied) {
  if (!sections.contains("domain")) sections["domain"] = py::dict();
  py::dict domain = sections["domain"];
  if (!domain.contains("dim")) domain["dim"] = implied;
  if (!py::isinstance<py::int_>(domain["dim"]) ||
      (domain["dim"].cast<long long>() != 2 && domain["dim"].cast<long long>() != 3))
    throw std::invalid_argument("domain.dim: expected 2 or 3");
  return domain["dim"].cast<int>();
}

}  // namespace

PyProblem PyProblem::from_config(py::dict config, int implied_dim) {
  PyProblem p;
  py::dict sections;
  auto section = [&](const std::string& name) -> py::dict {  // created on first use, shared handle
    if (!sections.contains(name)) sections[py::str(name)] = py::dict();
    return sections[py::str(name)];
  };
  for (auto [k, v] : config) {
    const std::string key = py::str(k);
    if (std::find(section_names.begin(), section_names.end(), key) != section_names.end()) {
      if (!py::isinstance<py::dict>(v)) throw std::invalid_argument(key + ": expected a dict");
      py::dict target = section(key);  // a copy: the caller's dict stays as it was
      for (auto [kk, vv] : v.cast<py::dict>()) target[kk] = vv;
    } else if (const char* name = section_of(key)) {
      section(name)[py::str(key)] = v;
    } else {
      std::vector<std::string> known = section_names;
      known.insert(known.end(), {"f", "g", "exact"});
      for (const OptionSpec& spec : option_specs()) known.push_back(spec.key);
      throw std::invalid_argument(key + ": unknown keyword" + did_you_mean(key, known));
    }
  }
  p.dim = dimension_of(sections, implied_dim);
  // Callables in [data] are attached at each solve; the TOML gets placeholders.
  if (sections.contains("data")) p.callables = take_callables(sections["data"]);
  if (p.dim == 2) {
    p.spec2 = parse_problem_text(toml_text(sections), "problem");
  } else {
    std::vector<std::string> warnings;
    const std::shared_ptr<const Surface> mesh = take_mesh(sections, warnings);
    p.spec3 = parse_surface_problem_text(toml_text(sections), "problem", mesh);
    p.spec3.warnings.insert(p.spec3.warnings.end(), warnings.begin(), warnings.end());
  }
  return p;
}

PyProblem PyProblem::from_text(const std::string& text, const std::string& source, int implied_dim) {
  PyProblem p;
  std::string complete = text;
  if (implied_dim == 3) {  // SurfaceProblem: domain.dim = 3 unless the text says otherwise
    toml::table root;
    try {
      root = toml::parse(text, source);
    } catch (const toml::parse_error&) {
      root = {};  // the reader reports the syntax error with its line
    }
    if (!root.empty()) {
      if (!root.contains("domain")) root.insert("domain", toml::table{});
      if (toml::table* domain = root.get_as<toml::table>("domain"); domain && !domain->contains("dim")) {
        domain->insert("dim", 3);
        std::ostringstream out;
        out << root;
        complete = out.str();
      }
    }
  }
  p.dim = problem_dimension(complete, source);
  if (p.dim == 2)
    p.spec2 = parse_problem_text(complete, source);
  else
    p.spec3 = parse_surface_problem_text(complete, source);
  return p;
}

PyProblem PyProblem::paper(int N, double c, const std::string& boundary, py::dict options) {
  PyProblem p;
  Problem given;  // N, c and the box conditions through the options' checks
  set_option(*find_option("N"), given, p.spec2.options, std::int64_t(N));
  set_option(*find_option("c"), given, p.spec2.options, c);
  set_option(*find_option("boundary"), given, p.spec2.options, boundary);
  p.spec2.problem = paper_problem(given.N, given.c, given.boundary);
  // Options through the same reader: a minimal file around them.
  if (!options.empty()) {
    py::dict config;
    config["geometry"] =
        py::dict(py::arg("shape") = "circle", py::arg("center") = py::make_tuple(0.5, 0.5), py::arg("radius") = 0.25);
    config["data"] = py::dict(py::arg("f") = "0", py::arg("g") = "0");
    for (auto [k, v] : options) {
      const std::string key = py::str(k);
      const char* section = section_of(key);
      if (!section || std::string(section) == "domain" || std::string(section) == "data")
        throw std::invalid_argument(key +
                                    ": not an option of the paper's problem (use Problem(...) for data and domain)");
      if (!config.contains(section)) config[section] = py::dict();
      config[section][py::str(key)] = v;
    }
    p.spec2.options = from_config(config).spec2.options;
  }
  // The paper's m and δ unless given, as `fictus solve` without a file.
  const SolverOptions paper = paper_options(N, p.spec2.options.variant);
  if (!options.contains("multipliers")) p.spec2.options.multipliers = paper.multipliers;
  if (!options.contains("offset")) p.spec2.options.offset = paper.offset;
  return p;
}

namespace {

/// The problem with the callables bound to this solve's error slot.
template <int dim>
BasicProblem<dim> bound(const BasicProblem<dim>& given, const std::map<std::string, py::function>& callables,
                        const std::shared_ptr<CallbackErrors>& errors) {
  BasicProblem<dim> problem = given;
  for (const auto& [key, fn] : callables) {
    typename Fields<dim>::Vectorized field;
    if constexpr (dim == 2)
      field = wrap2(fn, "data." + key, errors);
    else
      field = wrap3(fn, "data." + key, errors);
    if (key == "f") problem.f = nullptr, problem.f_vectorized = field;
    if (key == "g") {
      problem.g = nullptr, problem.g_vectorized = field;
      if constexpr (dim == 2) problem.g_along_curve = nullptr;
    }
    if (key == "exact") problem.exact = nullptr, problem.exact_gradient = nullptr, problem.exact_vectorized = field;
  }
  return problem;
}

template <int dim>
std::shared_ptr<const BasicSolution<dim>> solve_in(const BasicProblemSpec<dim>& spec,
                                                   const std::map<std::string, py::function>& callables, bool field) {
  const auto errors = std::make_shared<CallbackErrors>();  // this solve's own slot
  const BasicProblem<dim> problem = bound(spec.problem, callables, errors);
  check_memory(problem, spec.options);  // before anything is allocated, as the CLI does
  std::shared_ptr<const BasicSolution<dim>> solution;
  try {
    FictitiousDomainSolver<dim> solver(problem, spec.options);
    // Ctrl-C: Python's handler runs in PyErr_CheckSignals (this thread, under the GIL) and leaves
    // KeyboardInterrupt set; the solve stops at its next check.
    solver.set_interrupt_check([errors] { return errors->interrupt_requested(); });
    py::gil_scoped_release release;
    solution = std::make_shared<const BasicSolution<dim>>(solver.solve(problem, spec.options, field, false));
  } catch (const Interrupted&) {
    if (!PyErr_Occurred()) PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  } catch (const std::invalid_argument&) {
    errors->raise_if_any();  // a NaN from a failed callable: report the callable, not the NaN
    throw;
  }
  if (PyErr_Occurred()) throw py::error_already_set();  // a signal seen after the last check
  errors->raise_if_any();
  std::const_pointer_cast<BasicSolution<dim>>(solution)->peak_memory_bytes = peak_memory_bytes();
  if (!solution->newton.converged) throw std::runtime_error(describe_newton_failure(*solution));
  return solution;
}

template <int dim>
void describe_points(const BasicSolution<dim>& s, PySolution& out) {
  for (int i = 0; i < s.n_points(); ++i)
    for (int d = 0; d < dim; ++d) {
      out.points.push_back(s.points()[i][d]);
      out.normals.push_back(s.normals()[i][d]);
    }
}

}  // namespace

PySolution PyProblem::solve(bool field) const {
  PySolution out;
  out.dim = dim;
  if (dim == 2) {
    out.s2 = solve_in(spec2, callables, field);
    out.domain = domain_of(spec2.problem);
    describe_points(*out.s2, out);
  } else {
    out.s3 = solve_in(spec3, callables, field);
    out.domain = domain_of(spec3.problem);
    describe_points(*out.s3, out);
  }
  return out;
}

void bind_problem(py::module_& m) {
  py::class_<PyProblem>(m, "Problem", R"doc(A Signorini problem and the solver options, in 2-D or 3-D.

    Problem(domain=..., geometry=..., formulation=..., data=..., solver=..., parameters=..., **flat)
        Sections as dicts with the keys of a problem file (docs/problem_files.md), and/or flat
        keywords (N, box, boundary, variant, multipliers, offset, rho, normal_shift, c, f, g, exact,
        schur, krylov_tolerance, newton_tolerance, max_newton, start, threads, ...). domain.dim = 3
        (or domain={"dim": 3}) makes a 3-D problem: a closed surface in a box.
        f, g, exact: expressions (str) or callables vectorized over numpy arrays, f(x, y) -> array
        (f(x, y, z) in 3-D). A 3-D mesh: geometry={"shape": "mesh", "file": path} or
        {"shape": "mesh", "vertices": (n, 3) array, "faces": (k, 3) integer array}.
    Problem.from_dict(d), Problem.from_toml(text), Problem.from_file(path),
    Problem.paper(N=256, c=1.0, boundary="dirichlet", **options)
)doc")
      .def(py::init([](py::kwargs kwargs) { return PyProblem::from_config(kwargs); }))
      .def_static(
          "from_dict", [](py::dict d) { return PyProblem::from_config(d); }, py::arg("config"))
      .def_static(
          "from_toml", [](const std::string& text) { return PyProblem::from_text(text); }, py::arg("text"))
      .def_static(
          "from_file", [](const std::string& path) { return PyProblem::from_text(read_problem_text(path), path); },
          py::arg("path"), "A problem file (a mesh file named in it is relative to its folder).")
      .def_static(
          "paper",
          [](int N, double c, const std::string& boundary, py::kwargs options) {
            return PyProblem::paper(N, c, boundary, options);
          },
          py::arg("N") = Problem{}.N, py::arg("c") = Problem{}.c,
          py::arg("boundary") = std::string(to_string(Problem{}.boundary)))
      .def_property_readonly("dim", [](const PyProblem& p) { return p.dim; })
      .def_property_readonly("N", [](const PyProblem& p) { return p.N(); })
      .def_property_readonly(
          "warnings", [](const PyProblem& p) { return p.warnings(); },
          "What the reader changed (a clockwise curve or an inward mesh, reoriented).")
      .def(
          "solve", [](const PyProblem& p, bool field) { return solution_object(p.solve(field)); },
          py::arg("field") = true,
          "Solves (the GIL is released meanwhile) and returns a Solution (a SurfaceSolution in 3-D); raises "
          "ValueError on bad input and RuntimeError when Newton does not converge, with the CLI's messages.");

  py::class_<PySurfaceProblem, PyProblem>(m, "SurfaceProblem",
                                          "A Problem whose domain.dim is 3 unless its description says otherwise.")
      .def(py::init([](py::kwargs kwargs) { return PySurfaceProblem{PyProblem::from_config(kwargs, 3)}; }))
      .def_static(
          "from_dict", [](py::dict d) { return PySurfaceProblem{PyProblem::from_config(d, 3)}; }, py::arg("config"))
      .def_static(
          "from_toml",
          [](const std::string& text) { return PySurfaceProblem{PyProblem::from_text(text, "problem", 3)}; },
          py::arg("text"))
      .def_static(
          "from_file",
          [](const std::string& path) {
            return PySurfaceProblem{PyProblem::from_text(read_problem_text(path), path, 3)};
          },
          py::arg("path"));

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
}

}  // namespace fictus::python
