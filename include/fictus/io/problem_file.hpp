#pragma once
// Problem files (TOML). Every key, its default and unit: docs/problem_files.md.
#include <string>
#include <vector>

#include "fictus/problem.hpp"

namespace fictus {

struct OutputOptions {
  std::string dir = "results/solve";
  std::vector<std::string> files = {"results.json", "points.csv", "solution.vti", "curves.vtp"};
};

struct ProblemSpec {
  Problem problem;
  SolverOptions options;
  OutputOptions output;
  std::vector<std::string> warnings;  // e.g. a clockwise curve that was reoriented
  std::string input_json;             // the file's [geometry] and [data] as a JSON object (results.json echoes it)
};

/// Reads and checks a problem file. Throws std::invalid_argument with a one-line message naming the
/// key ("data.f: cannot parse …", "geometry.shape: unknown shape …", "solver.tolerance: unknown
/// key", …) on any error: unknown keys, wrong types, NaN/Inf, unparsable expressions.
ProblemSpec read_problem_file(const std::string& path);
ProblemSpec parse_problem_text(const std::string& text, const std::string& source = "problem");

/// The names `[output] files` accepts.
const std::vector<std::string>& output_file_names();

}  // namespace fictus
