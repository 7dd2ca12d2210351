#pragma once
// Output formats of the CLI: results.json (keys of docs/results.md), CSV tables, atomic writes.
#include <filesystem>
#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fictus/grid/distribution.hpp"
#include "fictus/io/problem_file.hpp"
#include "fictus/solve/convergence_table.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"

namespace fictus::cli {

/// Every option of options.hpp in effect that applies to the problem's dimension, by key
/// (results.json's `options`: with the problem file's [geometry] and [data], enough to solve it again).
template <int dim>
nlohmann::json options_to_json(const BasicProblem<dim>& problem, const SolverOptions& options);
/// The option descriptions (`fictus options --json`).
nlohmann::json options_schema_json();
/// results.json, the same keys in both dimensions (docs/results.md): `input` is what the problem was
/// made from (the file's geometry and data), echoed under "problem" beside its name; `input_warnings`
/// (the reader's) go first in "warnings".
template <int dim>
nlohmann::json solution_to_json(const BasicProblem<dim>& problem, const BasicSolution<dim>& solution,
                                const nlohmann::json& input = nlohmann::json::object(),
                                const std::vector<std::string>& input_warnings = {});
LevelResult level_result(const Solution& solution);

/// Newton did not converge (exit code 2): the message names the setting (describe_newton_failure).
struct NewtonFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// An output file could not be written (exit code 3).
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A file of an output set: its name in the folder and what writes it.
struct OutputFile {
  std::string name;
  std::function<void(std::ostream&)> write;
};

/// Throws OutputError "output.dir: …" unless `dir` is (or can be made as) a writable folder whose
/// listed files can be replaced (tried by making and removing a folder in it or its nearest existing
/// parent), and std::invalid_argument "output.files: … is named twice" for a repeated name. Called
/// before any work, so that a long solve does not end in a folder error.
void check_output_folder(const std::filesystem::path& dir, const std::vector<std::string>& names);

/// A run on several MPI ranks: runs `work` (a check of the file system, the printing, the files) on rank
/// 0 only, and throws on every rank when it threw there (rank 0's exception; the others' says so).
/// Collective. Serially: runs `work`.
void on_rank_0(const Distribution& distribution, const std::function<void()>& work);
/// A run on several MPI ranks: every rank takes the smallest of the ranks' thread counts. The ranks run
/// the same Newton steps, which must agree bit for bit, and the dense LU's blocking follows the thread
/// count. Collective. Serially: nothing.
void agree_on_threads(const Distribution& distribution, SolverOptions& options);

/// Writes the files as one set: all into a temporary folder inside `dir` (one file system, also when
/// `dir` is a mount point), then each earlier file set aside and the new one renamed into place; on
/// any failure the earlier files are put back, the new ones and the temporary folder removed, and
/// folders this call made removed: `dir` is as it was. Files of `dir` that `superseded` names and the
/// set does not hold (an earlier run's outputs of the same command, and plots made from them) go with
/// the earlier files: removed when the set is in place, put back on failure. Throws OutputError
/// "output: …".
void write_output_set(const std::filesystem::path& dir, const std::vector<OutputFile>& files,
                      const std::function<bool(const std::string&)>& superseded = {});

/// Whether `file` is a JSON object with `key`: a file fictus wrote (results.json: "options").
bool written_by_fictus(const std::filesystem::path& file, const std::string& key);

/// Where `dir` holds an earlier solve (its results.json), the names of that solve's files that a new
/// solve into `dir` supersedes: what `fictus solve` may write in either dimension, the ranks' parts
/// of the field its solution.pvti names, and the plots `fictus plot` makes from them. Otherwise none
/// (an empty function): a user's own files of those names stay.
std::function<bool(const std::string&)> earlier_solve_outputs(const std::filesystem::path& dir);

/// points.csv: one row per point of γ, the same columns in both dimensions (docs/usage.md).
template <int dim>
std::string points_csv(const BasicSolution<dim>& solution);
std::string levels_csv(const std::vector<LevelResult>& rows);

}  // namespace fictus::cli
