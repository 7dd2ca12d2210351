#pragma once
#include <string>
#include <vector>

#include "option_flags.hpp"

namespace fictus::cli {

struct SweepArguments {
  std::string problem_path;                      // "" = the paper's problem
  std::string g_scale, rotate, move, parameter;  // lists "a,b,c" or "start:stop:count"; parameter "NAME=LIST"
  std::string axis;                              // 3-D: the axis of --rotate (x, y or z; "" = z)
  std::string out = "results/sweep";
};

/// Values of a list option: "a,b,c" or "start:stop:count" (count points, both ends included).
std::vector<double> parse_values(const std::string& text, const std::string& option);

/// A family of problems on one grid, in 2-D or 3-D: the problem file (or the paper's problem) with its
/// obstacle scaled, its boundary rotated (a surface about --axis through the centre of its bounds) or
/// moved along x, or one of its [parameters] set to each value. One solver serves all: the Green's
/// table always, u₀ unless the parameter is in f, the boundary's rows and Schur blocks unless the
/// boundary changes. Prints a line per member, writes sweep.csv and sweep.json.
int run_sweep(const SweepArguments& args, const OptionFlags& flags);

}  // namespace fictus::cli
