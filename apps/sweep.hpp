#pragma once
#include <string>
#include <vector>

#include "fictus/problem.hpp"

namespace fictus::cli {

struct SweepArguments {
  std::string g_scale, rotate, move;  // lists "a,b,c" or "start:stop:count"
  std::string out = "results/sweep";
};

/// Values of a list option: "a,b,c" or "start:stop:count" (count points, both ends included).
std::vector<double> parse_values(const std::string& text, const std::string& option);

/// The paper's problem on the grid of `domain` (its N, c and boundary conditions), one solver for all.
int run_sweep(const SweepArguments& args, const Problem& domain, SolverOptions options);

}  // namespace fictus::cli
