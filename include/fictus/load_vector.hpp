#pragma once
// Q1 load vector f_k = ∫_Ω f φ_k at the interior nodes, by a q×q Gauss rule on every cell.
#include <functional>

#include "fictus/grid.hpp"

namespace fictus {

using ScalarField = std::function<double(double x, double y)>;

/// q = Gauss points per direction (q = 2 is O(h⁴) per cell, enough for the Q1 rates when f is
/// smooth inside cells). f must be thread-safe (it is called from `threads` threads).
GridVector assemble_load(const Grid& grid, const ScalarField& f, int q = 2, int threads = 1);

}  // namespace fictus
