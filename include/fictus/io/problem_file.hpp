#pragma once
// Problem files (TOML). Every key, its default and unit: docs/problem_files.md.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fictus/solve/problem.hpp"

namespace fictus {

/// Where a solve writes and which files (the names a dimension accepts: output_file_names(dim)).
struct OutputOptions {
  std::string dir = "results/solve";
  std::vector<std::string> files = {"results.json", "points.csv", "solution.vti", "curves.vtp"};
};

/// Values for some of a file's [parameters], replacing the file's (fictus sweep --parameter).
using ParameterValues = std::map<std::string, double>;

/// A problem file read and checked, in either dimension.
template <int dim>
struct BasicProblemSpec {
  BasicProblem<dim> problem;  // problem.name: the file's name without .toml (set by read_problem_file)
  SolverOptions options;
  OutputOptions output;
  std::vector<std::string> warnings;  // e.g. a clockwise curve or an inward mesh that was reoriented
  std::string input_json;             // the file's [geometry], [data] and [parameters] as JSON (results.json echoes it)
  std::map<std::string, double> parameters;  // [parameters] as in effect (the file's values, or the overrides)
  /// For each parameter, the keys of the expressions that name it ("data.g", "geometry.r", …).
  std::map<std::string, std::vector<std::string>> parameter_uses;
  /// 2-D: the file's obstacle g(x, y, s) with phi measured about `center` (for the curve moved there).
  std::function<std::function<double(double, double, double)>(Point2)> g_about;
};
using ProblemSpec = BasicProblemSpec<2>;
using SurfaceProblemSpec = BasicProblemSpec<3>;

/// Reads and checks the text of a problem file of dimension dim ([domain] dim, problem_dimension).
/// Throws std::invalid_argument with a one-line message naming the key ("data.f: cannot parse …",
/// "geometry.shape: unknown shape …", "solver.tolerance: unknown key (did you mean …?)", an option
/// of the other dimension, …) on any error: unknown keys, wrong types, NaN/Inf, unparsable
/// expressions. `parameters` replace values of the file's [parameters] (each must be one of them).
/// `shape`: use it for γ instead of reading [geometry] (2-D: a sweep whose parameter is not in the
/// geometry, the table checked when the file was first read; 3-D: shape = "mesh" without a file, the
/// vertices and faces given by a caller). A mesh's geometry.file is relative to the folder of `source`
/// when that names a file, else to the working folder; results.json echoes it as an absolute path.
template <int dim>
BasicProblemSpec<dim> parse_problem(const std::string& text, const std::string& source = "problem",
                                    const ParameterValues& parameters = {},
                                    std::shared_ptr<const typename BoundaryShape<dim>::type> shape = nullptr);
/// The 2-D and 3-D forms of parse_problem.
ProblemSpec parse_problem_text(const std::string& text, const std::string& source = "problem",
                               const ParameterValues& parameters = {}, std::shared_ptr<const Curve> curve = nullptr);
SurfaceProblemSpec parse_surface_problem_text(const std::string& text, const std::string& source = "problem",
                                              std::shared_ptr<const Surface> mesh = nullptr,
                                              const ParameterValues& parameters = {});

/// read_problem_text then parse_problem, with problem.name the file's name without .toml.
ProblemSpec read_problem_file(const std::string& path, const ParameterValues& parameters = {});

/// The file as text (at most 64 MiB; a folder or an unreadable file is an error naming the path).
std::string read_problem_text(const std::string& path);

/// The names `[output] files` accepts in a dimension.
const std::vector<std::string>& output_file_names(int dim = 2);

/// The text of a 3-D mesh problem file with [geometry] file (made absolute against the working folder;
/// "" keeps the file's) and resolution (none keeps the file's) replaced: the flags --file and --resolution.
std::string with_mesh_overrides(const std::string& text, const std::string& source, const std::string& file,
                                std::optional<double> resolution);

/// `[domain] dim` of a problem file's text: 2 (the default) or 3; throws naming domain.dim otherwise.
int problem_dimension(const std::string& text, const std::string& source = "problem");

}  // namespace fictus
