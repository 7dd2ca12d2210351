#pragma once
#include <string>
#include <vector>

#include "fictus/problem.hpp"

namespace fictus::cli {

struct SweepArguments {
  int N = 256;
  double c = 1.0;
  Boundary boundary = Boundary::dirichlet;
  std::string g_scale, rotate, move;  // lists "a,b,c" or "start:stop:count"
  bool field = false;                 // also compute û (one fast solve per problem)
  std::string out = "results/sweep";
};

/// Values of a list option: "a,b,c" or "start:stop:count" (count points, both ends included).
std::vector<double> parse_values(const std::string& text, const std::string& option);

int run_sweep(const SweepArguments& args, SolverOptions options);

}  // namespace fictus::cli
