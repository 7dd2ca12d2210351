// fictus.Problem: built from a dict, TOML text, keyword arguments or the paper's experiment. Dicts
// and keywords are turned into the same TOML the CLI reads, so every check and message is the CLI's.
// Data may be expressions (str) or Python callables vectorized over numpy arrays: f(x, y) -> array.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <toml++/toml.h>

#include <cmath>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "bindings.hpp"
#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/io/problem_file.hpp"
#include "fictus/options.hpp"
#include "fictus/paper_problem.hpp"
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

VectorizedField PyProblem::wrap(py::function fn, const std::string& key, std::shared_ptr<CallbackErrors> errors) {
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

Problem PyProblem::bound(const std::shared_ptr<CallbackErrors>& errors) const {
  Problem problem = spec.problem;
  for (const auto& [key, fn] : callables) {
    VectorizedField field = wrap(fn, "data." + key, errors);
    if (key == "f") problem.f = nullptr, problem.f_vectorized = field;
    if (key == "g") problem.g = nullptr, problem.g_along_curve = nullptr, problem.g_vectorized = field;
    if (key == "exact") problem.exact = nullptr, problem.exact_vectorized = field;
  }
  return problem;
}

PyProblem PyProblem::from_config(py::dict config) {
  PyProblem p;
  py::dict sections;
  std::map<std::string, py::function>& callables = p.callables;
  auto section = [&](const std::string& name) -> py::dict {  // created on first use, shared handle
    if (!sections.contains(name)) sections[py::str(name)] = py::dict();
    return sections[py::str(name)];
  };
  for (auto [k, v] : config) {
    const std::string key = py::str(k);
    if (key == "domain" || key == "geometry" || key == "formulation" || key == "data" || key == "solver" ||
        key == "output" || key == "parameters") {
      if (!py::isinstance<py::dict>(v)) throw std::invalid_argument(key + ": expected a dict");
      py::dict target = section(key);
      for (auto [kk, vv] : v.cast<py::dict>()) target[kk] = vv;
    } else if (const char* name = section_of(key)) {
      section(name)[py::str(key)] = v;
    } else {
      std::vector<std::string> known = {"f",           "g",    "exact",  "domain", "geometry",
                                        "formulation", "data", "solver", "output", "parameters"};
      for (const OptionSpec& spec : option_specs()) known.push_back(spec.key);
      throw std::invalid_argument(key + ": unknown keyword" + did_you_mean(key, known));
    }
  }
  // Callables in [data] are attached after parsing; the TOML gets placeholders.
  if (sections.contains("data")) callables = take_callables(sections["data"]);
  p.spec = parse_problem_text(toml_text(sections), "problem");
  return p;
}

PyProblem PyProblem::paper(int N, double c, const std::string& boundary, py::dict options) {
  PyProblem p;
  Problem given;  // N, c and the box conditions through the options' checks
  set_option(*find_option("N"), given, p.spec.options, std::int64_t(N));
  set_option(*find_option("c"), given, p.spec.options, c);
  set_option(*find_option("boundary"), given, p.spec.options, boundary);
  p.spec.problem = paper_problem(given.N, given.c, given.boundary);
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
    p.spec.options = from_config(config).spec.options;
  }
  // The paper's m and δ unless given, as `fictus solve` without a file.
  const SolverOptions paper = paper_options(N, p.spec.options.variant);
  if (!options.contains("multipliers")) p.spec.options.multipliers = paper.multipliers;
  if (!options.contains("offset")) p.spec.options.offset = paper.offset;
  return p;
}

void bind_problem(py::module_& m) {
  py::class_<PyProblem>(m, "Problem", R"doc(A Signorini problem and the solver options.

    Problem(domain=..., geometry=..., formulation=..., data=..., solver=..., **flat)
        Sections as dicts with the keys of a problem file (docs/problem_files.md), and/or flat
        keywords (N, box, boundary, variant, multipliers, offset, rho, normal_shift, c, f, g, exact,
        schur, krylov_tolerance, newton_tolerance, max_newton, start, threads, ...).
        f, g, exact: expressions (str) or callables vectorized over numpy arrays, f(x, y) -> array.
    Problem.from_dict(d), Problem.from_toml(text), Problem.paper(N=256, c=1.0, boundary="dirichlet", **options)
)doc")
      .def(py::init([](py::kwargs kwargs) { return PyProblem::from_config(kwargs); }))
      .def_static(
          "from_dict", [](py::dict d) { return PyProblem::from_config(d); }, py::arg("config"))
      .def_static(
          "from_toml",
          [](const std::string& text) {
            PyProblem p;
            p.spec = parse_problem_text(text, "problem");
            return p;
          },
          py::arg("text"))
      .def_static(
          "paper",
          [](int N, double c, const std::string& boundary, py::kwargs options) {
            return PyProblem::paper(N, c, boundary, options);
          },
          py::arg("N") = Problem{}.N, py::arg("c") = Problem{}.c,
          py::arg("boundary") = std::string(to_string(Problem{}.boundary)))
      .def_property_readonly("N", [](const PyProblem& p) { return p.spec.problem.N; })
      .def_property_readonly("warnings", [](const PyProblem& p) { return p.spec.warnings; })
      .def("solve", &PyProblem::solve, py::arg("field") = true,
           "Solves (the GIL is released meanwhile) and returns a Solution; raises ValueError on bad input "
           "and RuntimeError when Newton does not converge, with the CLI's messages.");
}

}  // namespace fictus::python
