// The Python module `fictus`: Problem (from a dict, TOML text, keyword arguments or the paper),
// Problem.solve() → Solution with numpy arrays, in 2-D or 3-D. No numerics here: everything
// calls the library.
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(fictus, m) {
  m.doc() = "fictus: Signorini problems on curved domains by a fictitious domain method";
  m.attr("__version__") = FICTUS_PY_VERSION;
  fictus::python::bind_problem(m);
  fictus::python::bind_solution(m);
}
