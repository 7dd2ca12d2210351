#pragma once
// Shared declarations of the binding files (one file per concept: problem.cpp, solution.cpp).
#include <pybind11/pybind11.h>

namespace fictus::python {

void bind_problem(pybind11::module_& m);
void bind_solution(pybind11::module_& m);

}  // namespace fictus::python
