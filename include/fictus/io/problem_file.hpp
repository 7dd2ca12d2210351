#pragma once
// Problem files (TOML). Every key, its default and unit: docs/problem_files.md.
#include <functional>
#include <map>
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
  std::string input_json;             // the file's [geometry], [data] and [parameters] as JSON (results.json echoes it)
  std::map<std::string, double> parameters;  // [parameters] as in effect (the file's values, or the overrides)
  /// For each parameter, the keys of the expressions that name it ("data.g", "geometry.r", …).
  std::map<std::string, std::vector<std::string>> parameter_uses;
  /// The file's obstacle g(x, y, s) with phi measured about `center` (for the curve moved there).
  std::function<std::function<double(double, double, double)>(Point2)> g_about;
};

/// Values for some of a file's [parameters], replacing the file's (fictus sweep --parameter).
using ParameterValues = std::map<std::string, double>;

/// Reads and checks a problem file. Throws std::invalid_argument with a one-line message naming the
/// key ("data.f: cannot parse …", "geometry.shape: unknown shape …", "solver.tolerance: unknown
/// key", …) on any error: unknown keys, wrong types, NaN/Inf, unparsable expressions.
/// `parameters` replace values of the file's [parameters] (each must be one of them).
ProblemSpec read_problem_file(const std::string& path, const ParameterValues& parameters = {});
/// `curve`: use it for γ instead of reading [geometry] again (a sweep whose parameter is not in the
/// geometry: the table was checked when the file was first read).
ProblemSpec parse_problem_text(const std::string& text, const std::string& source = "problem",
                               const ParameterValues& parameters = {}, std::shared_ptr<const Curve> curve = nullptr);

/// The file as text (at most 64 MiB; a folder or an unreadable file is an error naming the path).
std::string read_problem_text(const std::string& path);

/// The names `[output] files` accepts.
const std::vector<std::string>& output_file_names();

/// `[domain] dim` of a problem file's text: 2 (the default) or 3; throws naming domain.dim otherwise.
int problem_dimension(const std::string& text, const std::string& source = "problem");

/// A 3-D problem file (`[domain] dim = 3`): the surface, the data in x, y, z, the options.
struct SurfaceProblemSpec {
  SurfaceProblem problem;
  SolverOptions options;
  OutputOptions output;
  std::string name;                   // the file's name without .toml
  std::string input_json;             // [geometry] and [data] as JSON (results.json echoes it)
  std::vector<std::string> warnings;  // e.g. a mesh that was reoriented
};
/// Reads and checks one; errors as read_problem_file's, naming the key. A mesh's `geometry.file` is
/// relative to the folder of `source` when that names a file, else to the working folder. `mesh`:
/// the surface for shape = "mesh" without a file (vertices and faces given by a caller).
SurfaceProblemSpec parse_surface_problem_text(const std::string& text, const std::string& source = "problem",
                                              std::shared_ptr<const Surface> mesh = nullptr);
/// The names a 3-D problem's `[output] files` accepts.
const std::vector<std::string>& surface_output_file_names();

}  // namespace fictus
