// fictus: command-line front end. Owns argument parsing, printing and files; the numerics live in
// the library.
#include <CLI/CLI.hpp>

#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef FICTUS_WITH_MPI
#include <fcntl.h>

#include "fictus/mpi/communicator.hpp"
#include "fictus/mpi/distribution.hpp"
#include "fictus/mpi/slab_solver.hpp"
#endif
#include "fictus/io/problem_file.hpp"
#include "fictus/io/process.hpp"
#include "fictus/solve/convergence_table.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/options.hpp"
#include "fictus/solve/paper_problem.hpp"
#include "option_flags.hpp"
#include "results_io.hpp"
#include "sweep.hpp"
#include "vtk_io.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Exit codes, one per class of failure (docs/usage.md).
constexpr int exit_bad_input = 1, exit_newton = 2, exit_output = 3, exit_internal = 4;

using fictus::cli::NewtonFailure;

/// The one error line: "fictus: error: <message>", at most 240 bytes, on stderr. A longer message is cut
/// at a character boundary (never inside a UTF-8 sequence) and ends in "...".
int report(const std::string& message, int code) {
  constexpr std::size_t max_message = 240 - std::char_traits<char>::length("fictus: error: ");
  std::string line = message;
  if (line.size() > max_message) {
    std::size_t cut = max_message - 3;
    while (cut > 0 && (static_cast<unsigned char>(line[cut]) & 0xC0) == 0x80) --cut;
    line = line.substr(0, cut) + "...";
  }
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  std::fprintf(stderr, "fictus: error: %s\n", line.c_str());
  return code;
}

#ifdef FICTUS_WITH_MPI
/// A run on several MPI ranks: rank 0 prints and writes; the others' stdout and stderr go to /dev/null
/// (`own_stderr` keeps theirs for a failure of their own), and `errors` is a communicator of its own for
/// agreeing on a failure (never matched against the solve's collectives).
struct Ranks {
  int rank = 0, size = 1;
  int own_stderr = -1;
  MPI_Comm errors = MPI_COMM_NULL;
};
Ranks ranks;

/// A failure under mpirun. Every check a solve makes on one rank's part is agreed by all ranks
/// (Distribution::all), so a failure normally reaches every rank at the same step: rank 0 prints the
/// line, and all return rank 0's exit code. A rank that fails alone (the others do not join within
/// `wait`) says so on its own stderr and stops every rank with MPI_Abort: none is left waiting.
int distributed_failure(const std::string& message, int code) {
  if (ranks.rank == 0) report(message, code);
  MPI_Request request;
  MPI_Ibarrier(ranks.errors, &request);
  const auto start = std::chrono::steady_clock::now();
  constexpr double wait = 10;  // seconds
  int joined = 0;
  while (!joined && std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < wait) {
    MPI_Test(&request, &joined, MPI_STATUS_IGNORE);
    if (!joined) usleep(2000);
  }
  if (joined) {
    MPI_Bcast(&code, 1, MPI_INT, 0, ranks.errors);
    return code;
  }
  if (ranks.rank != 0)
    dprintf(ranks.own_stderr, "fictus: error: rank %d of %d: %s\n", ranks.rank, ranks.size,
            message.substr(0, 200).c_str());
  dprintf(ranks.own_stderr, "fictus: error: rank %d failed alone: stopping all %d ranks\n", ranks.rank, ranks.size);
  MPI_Abort(MPI_COMM_WORLD, code);
  return code;
}
#endif

/// The error line and exit code of a command that failed (under mpirun: agreed by the ranks).
int fail(const std::string& message, int code) {
#ifdef FICTUS_WITH_MPI
  if (ranks.size > 1) return distributed_failure(message, code);
#endif
  return report(message, code);
}

/// CLI11's parse errors in the "<what>: <why>" form of every other error; an unknown flag names the
/// nearest of `flags` (the command's long flags).
std::string parse_error_line(const std::string& message, const std::vector<std::string>& flags) {
  static const std::regex extras(R"(The following arguments? (?:was|were) not expected: (.*))");
  static const std::regex at_most(R"((\S+): At Most 1 required but received (\d+))");
  std::smatch match;
  if (std::regex_match(message, match, extras)) {
    std::istringstream words(match[1].str());
    std::string word, first;
    while (words >> word)
      if (first.empty() && word.size() > 1 && word[0] == '-') first = word;
    if (first == "--dim" || first.rfind("--dim=", 0) == 0)  // the dimension is the problem's, not a flag
      return "--dim: not a flag; the problem file sets the dimension ([domain] dim = 3 for a surface)";
    if (!first.empty()) return first.substr(0, 60) + ": not expected" + fictus::did_you_mean(first, flags);
    const std::string what = match[1].str();
    return what.find(' ') == std::string::npos && !what.empty() ? what.substr(0, 60) + ": not expected"
                                                                : "arguments: not expected: " + what.substr(0, 60);
  }
  if (std::regex_match(message, match, at_most))
    return match[1].str() + ": given " + match[2].str() + " times; it takes one value";
  const std::size_t colon = message.find(": ");
  if (colon == std::string::npos || message.find(' ') < colon) return "arguments: " + message;
  return message;
}

bool formulation_or_solver(const fictus::OptionSpec& s) { return s.section == "formulation" || s.section == "solver"; }

/// What a solve adds to the summary: the nested start, the contact fit, the flux balance, the far field.
template <int dim>
void print_solver_extras(const fictus::BasicSolution<dim>& s) {
  if (s.nested_start && s.nested_start->skipped.empty())
    std::printf("Newton started from the contact set of the N = %d solve (m = %d, %d Newton steps, %.2f s)\n",
                s.nested_start->N, s.nested_start->multipliers, s.nested_start->newton_steps, s.nested_start->seconds);
  else if (s.nested_start)
    std::printf("no nested start (%s)\n", s.nested_start->skipped.c_str());
  if (s.contact_fit)
    std::printf(
        "points fitted to the contact boundary: %d more solve(s), %.2f s; the ends then moved by %.3f spacings\n",
        s.contact_fit->passes, s.contact_fit->seconds,
        s.contact_fit->moved.empty() ? 0.0 : s.contact_fit->moved.back());
  if (s.flux_balance)
    std::printf(
        "flux balance: before it each patch's reading missed its share of the flux by %.2e (scatter), "
        "a constant layer's by %.2e; the data's readings moved by %.2e\n",
        s.flux_balance->scatter, s.flux_balance->mean, s.flux_balance->data_shift);
  if (s.far_field) {
    const fictus::FarFieldReport& a = s.far_field->assembly;
    std::printf("Schur complement: %.1f%% of the pairs interpolated; the last %d Newton steps on the exact one\n",
                100 * a.far_pairs / (a.far_pairs + a.near_pairs), s.far_field->exact_steps);
  }
  if (s.schur_storage && s.schur_storage->kind == "hierarchical") {
    const fictus::SchurStorage& t = *s.schur_storage;
    std::printf(
        "Schur complement: hierarchical, %.3g MiB (%.1f%% of dense), %.1f%% of the pairs interpolated, %.0f "
        "factored blocks up to rank %d; %d block LUs, %d Krylov iterations\n",
        t.bytes / 1048576, 100 * t.bytes / t.dense_bytes, 100 * t.far_fraction, t.low_rank_blocks, t.largest_rank,
        s.factorizations, s.inner_iterations);
  }
  if (s.condition_number) std::printf("condition number of the Newton matrix: %.3e\n", *s.condition_number);
}

template <int dim>
void print_summary(const fictus::BasicSolution<dim>& s) {
  std::printf("%sN = %d (h = %.3g), n = %zu nodes, m = %d%s, variant %s, inner solver %s\n", dim == 3 ? "3-D, " : "",
              s.grid.nx(), s.grid.h(), s.grid.n_nodes(), s.n_points(), dim == 3 ? " patches" : "",
              fictus::to_string(s.options.variant), fictus::to_string(s.options.inner));
  const fictus::ContactSummary c = fictus::contact_summary(s);
  std::printf("Newton: %d steps, %s, %ld active of %ld%s; fast solves %zu, Krylov iterations %d\n", s.newton.iterations,
              s.newton.converged ? "converged" : "NOT converged", c.points, c.signorini.points,
              c.signorini.points < s.n_points() ? " Signorini points" : "", s.fast_solves, s.inner_iterations);
  const char* measure = dim == 2 ? "length" : "area";
  if (c.dirichlet.points > 0 || c.neumann.points > 0)
    std::printf(
        "parts of gamma: Signorini %ld points (%s %.6g), Dirichlet %ld (%.6g, flux %.6g), Neumann %ld (%.6g, flux "
        "%.6g)\n",
        c.signorini.points, measure, c.signorini.measure, c.dirichlet.points, c.dirichlet.measure, c.dirichlet.flux,
        c.neumann.points, c.neumann.measure, c.neumann.flux);
  print_solver_extras(s);
  std::printf("Signorini checks: min gap %.2e, min du/dn %.2e, max |complementarity| %.2e\n", s.signorini.min_gap,
              s.signorini.min_normal_derivative, s.signorini.max_complementarity);
  if (s.check)
    std::printf(
        "  with an independent du/dn (%s): min du/dn %.2e, max |complementarity| %.2e, "
        "max |difference| %.2e (rms %.2g %% of max |du/dn|)\n",
        s.check->rule.c_str(), s.check->min_normal_derivative, s.check->max_complementarity, s.check->max_difference,
        100 * s.check->relative_difference);
  std::printf("contact: %ld points, %s %.6g (whole points %.6g), force %.9g (%s; patch sum %.9g)\n", c.points, measure,
              c.measure, c.measure_points, c.force, c.force_from_domain ? "c int u - int f over omega" : "patch sum",
              c.force_patches);
  if (s.domain)
    std::printf("over omega: int u %.9g, int |grad u|^2 %.9g, energy %.9g\n", s.domain->integral_u,
                s.domain->integral_grad2, s.domain->energy);
  if (s.estimate && s.estimate->skipped.empty()) {
    std::printf(
        "estimated errors (from N = %d): u %.2e relative in L2(omega), force %.2e, contact %s %.2e, energy %.2e\n",
        s.estimate->N, s.estimate->rel_l2_omega, s.estimate->force, dim == 2 ? "length" : "area", s.estimate->measure,
        s.estimate->energy);
    if (!s.estimate->caveat.empty())  // (no warning: on coarse grids it is common)
      std::printf("  an order of magnitude only: the solve at N = %d did not follow this grid's rule (%s)\n",
                  s.estimate->N, s.estimate->caveat.c_str());
  } else if (s.estimate)
    std::printf("no error estimate (%s)\n", s.estimate->skipped.c_str());
  if (s.errors)
    std::printf("relative errors: L2(omega) %.3e, H1(omega) %.3e (semi %.3e), L2(gamma) %.3e\n", s.errors->rel_l2_omega,
                s.errors->rel_h1_omega, s.errors->rel_h1semi_omega, s.errors->rel_l2_gamma);
  std::printf("time %.3f s (", s.timings.total);
  for (std::size_t k = 0; k < s.timings.phases.size(); ++k)
    std::printf("%s%s %.3f", k ? ", " : "", s.timings.phases[k].first.c_str(), s.timings.phases[k].second);
  std::printf("), peak memory %.1f MiB\n", s.peak_memory_bytes / 1048576.0);
}

/// With any VTK file among `files`, solution.vtm naming them all (one file opens the run in ParaView).
void add_multiblock(std::vector<fictus::cli::OutputFile>& files) {
  static const std::vector<std::pair<std::string, std::string>> blocks = {{"solution.vti", "field"},
                                                                          {"solution.pvti", "field"},
                                                                          {"curves.vtp", "gamma"},
                                                                          {"offset_curve.vtp", "Gamma"},
                                                                          {"surface.vtp", "gamma"},
                                                                          {"offset_surface.vtp", "Gamma"},
                                                                          {"contact_boundary.vtp", "contact boundary"}};
  std::vector<std::pair<std::string, std::string>> named;  // (block, file)
  for (const auto& [file, block] : blocks)
    if (std::any_of(files.begin(), files.end(), [&](const auto& f) { return f.name == file; }))
      named.emplace_back(block, file);
  if (!named.empty())
    files.push_back({"solution.vtm", [named](std::ostream& out) { fictus::cli::write_vtm(out, named); }});
}

std::pair<int, int> parse_levels(const std::string& text) {
  static const std::regex pattern(R"((\d+)(?:-(\d+))?)");
  std::smatch match;
  if (!std::regex_match(text, match, pattern)) throw std::invalid_argument("--levels: expected A-B, e.g. 7-10");
  const auto level = [](std::string digits) {
    digits.erase(0, std::min(digits.find_first_not_of('0'), digits.size() - 1));  // "0009" is 9
    return digits.size() > 3 ? 999 : std::stoi(digits);
  };
  const int a = level(match[1]), b = match[2].matched ? level(match[2]) : a;
  if (a < 3 || b > 14 || a > b) throw std::invalid_argument("--levels: need 3 <= A <= B <= 14 (h = 2^-level)");
  return {a, b};
}

/// What `fictus solve` was given on the command line.
struct SolveCommand {
  std::string problem_path, out = "results/solve";
  std::string mesh_file;                       // --file: geometry.file of a 3-D mesh problem
  double mesh_resolution = 0;                  // --resolution: geometry.resolution (where given)
  std::vector<std::string> files, parameters;  // parameters: NAME=VALUE
  bool quiet = false;
  fictus::cli::OptionFlags flags;
  CLI::Option* out_option = nullptr;
  CLI::Option* files_option = nullptr;
  CLI::Option* resolution_option = nullptr;
};

/// Progress on stderr, flushed (also when redirected): each step of a long solve as it ends, with
/// the time since the start and the peak memory so far.
std::function<void(const std::string&, double)> progress_lines() {
  const auto start = std::chrono::steady_clock::now();
  return [start](const std::string& phase, double seconds) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "fictus:   %-16s %8.2f s   (elapsed %.1f s, peak memory %.2f GiB)\n", phase.c_str(), seconds,
                 elapsed, fictus::peak_memory_bytes() / double(1 << 30));
    std::fflush(stderr);
  };
}

/// --parameter NAME=VALUE, each checked.
fictus::ParameterValues parameter_values(const std::vector<std::string>& given) {
  fictus::ParameterValues parameters;
  for (const std::string& p : given) {
    const std::size_t equals = p.find('=');
    std::size_t used = 0;
    double value = 0;
    try {
      if (equals != std::string::npos && equals > 0) value = std::stod(p.substr(equals + 1), &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != p.size() - equals - 1 || !std::isfinite(value))
      throw std::invalid_argument("--parameter: expected NAME=VALUE with a finite number, e.g. a=0.25, got \"" +
                                  p.substr(0, 60) + "\"");
    parameters[p.substr(0, equals)] = value;
  }
  return parameters;
}

/// The files of a run: results.json, points.csv, the VTK files (and Γ's in the smooth variant), and
/// solution.vtm naming the VTK files.
/// `field_files`: what replaces solution.vti (a run on several ranks: solution.pvti and its pieces).
template <int dim>
std::vector<fictus::cli::OutputFile> output_files(const fictus::BasicProblemSpec<dim>& spec,
                                                  const fictus::BasicSolution<dim>& s, const json& input,
                                                  const std::vector<fictus::cli::OutputFile>& field_files = {}) {
  const char* boundary_file = dim == 2 ? "curves.vtp" : "surface.vtp";
  std::vector<fictus::cli::OutputFile> files;
  for (const std::string& name : spec.output.files) {
    if (name == "results.json")
      files.push_back({name, [&](std::ostream& out) {
                         out << fictus::cli::solution_to_json(spec.problem, s, input, spec.warnings).dump(2) << "\n";
                       }});
    else if (name == "points.csv")
      files.push_back({name, [&](std::ostream& out) { out << fictus::cli::points_csv(s); }});
    else if (name == "solution.vti" && !field_files.empty())
      files.insert(files.end(), field_files.begin(), field_files.end());
    else if (name == "solution.vti")
      files.push_back({name, [&](std::ostream& out) { fictus::cli::write_vti(out, spec.problem, s); }});
    if (name != boundary_file) continue;
    files.push_back(
        {"contact_boundary.vtp", [&](std::ostream& out) { fictus::cli::write_contact_boundary_vtp(out, s); }});
    if constexpr (dim == 2) {
      files.push_back({name, [&](std::ostream& out) { fictus::cli::write_curve_vtp(out, s); }});
      if (s.delta > 0)
        files.push_back({"offset_curve.vtp", [&](std::ostream& out) { fictus::cli::write_offset_curve_vtp(out, s); }});
    } else {
      files.push_back({name, [&](std::ostream& out) { fictus::cli::write_surface_vtp(out, s); }});
      if (s.delta > 0)
        files.push_back(
            {"offset_surface.vtp", [&](std::ostream& out) { fictus::cli::write_offset_surface_vtp(out, s); }});
    }
  }
  add_multiblock(files);
  return files;
}

/// The problem a solve command names: the file (with --file and --resolution in a 3-D mesh problem)
/// or the paper's problem, the flags applied; --out and --files.
template <int dim>
fictus::BasicProblemSpec<dim> solve_spec(std::string text, const SolveCommand& command) {
  const bool resolution_given = command.resolution_option->count() > 0;
  if (command.mesh_file.size() || resolution_given) {
    if (dim != 3)
      throw std::invalid_argument(std::string(command.mesh_file.size() ? "--file" : "--resolution") +
                                  ": applies to a mesh, the geometry of 3-D problems only ([domain] dim = 3)");
    text =
        fictus::with_mesh_overrides(text, command.problem_path, command.mesh_file,
                                    resolution_given ? std::optional<double>(command.mesh_resolution) : std::nullopt);
  }
  fictus::BasicProblemSpec<dim> spec = fictus::cli::problem_from_text<dim>(text, command.problem_path, command.flags,
                                                                           parameter_values(command.parameters));
  if (command.out_option->count() > 0) spec.output.dir = command.out;
  if (command.files_option->count() > 0) {
    const std::vector<std::string>& names = fictus::output_file_names(dim);
    for (const std::string& f : command.files)
      if (std::find(names.begin(), names.end(), f) == names.end())
        throw std::invalid_argument("output.files: unknown file \"" + f.substr(0, 40) + "\" (" + names[0] + ", " +
                                    names[1] + ", " + names[2] + ", " + names[3] + ")" +
                                    fictus::did_you_mean(f, names));
    spec.output.files = command.files;
  }
  return spec;
}

#ifdef FICTUS_WITH_MPI
/// The field of a run on several ranks, as ParaView's parallel image: solution.pvti naming one piece per
/// rank that holds layers, solution_<rank>.vti, the node planes of its layers and the next one. Rank 0
/// writes them all (in the output set, so that nothing is half-written): each rank sends it its layers
/// and the next one, and rank 0 takes them one piece at a time, so it never holds the whole field.
template <int dim>
class FieldPieces {
 public:
  /// Collective (the next layers); then each rank but 0 sends its piece.
  FieldPieces(const fictus::Distribution& distribution, const fictus::Grid<dim>& grid, const fictus::GridVector& u)
      : grid_(grid),
        rank_(distribution.rank()),
        size_(distribution.size()),
        held_(distribution.with_next_layer(grid, u)),
        taken_(std::size_t(size_), false) {
    MPI_Comm_dup(MPI_COMM_WORLD, &comm_);  // the pieces' messages on a communicator of their own
    MPI_Type_contiguous(int(grid.layer_size()), MPI_DOUBLE, &layer_);
    MPI_Type_commit(&layer_);
    if (rank_ != 0 && slab(rank_).count > 0)
      MPI_Isend(held_.data(), slab(rank_).count + 1, layer_, 0, tag, comm_, &send_);
  }
  /// Rank 0 takes every piece not taken yet, and the others' sends end, whatever happened in between
  /// (a failed write included): no message is left over.
  ~FieldPieces() {
    if (rank_ == 0) {
      for (int r = 1; r < size_; ++r)
        if (!taken_[std::size_t(r)]) values(r);
    } else if (send_ != MPI_REQUEST_NULL) {
      MPI_Wait(&send_, MPI_STATUS_IGNORE);
    }
    MPI_Type_free(&layer_);
    MPI_Comm_free(&comm_);
  }
  FieldPieces(const FieldPieces&) = delete;
  FieldPieces& operator=(const FieldPieces&) = delete;

  /// Rank 0: solution.pvti and the pieces, for output_files.
  std::vector<fictus::cli::OutputFile> files(const fictus::BasicProblem<dim>& problem,
                                             const fictus::BasicSolution<dim>& s) {
    std::vector<std::pair<std::array<int, 2>, std::string>> pieces;
    std::vector<fictus::cli::OutputFile> files;
    for (int r = 0; r < size_; ++r) {
      if (slab(r).count == 0) continue;
      const std::string name = "solution_" + std::to_string(r) + ".vti";
      pieces.push_back({planes(r), name});
      files.push_back({name, [this, r, &problem, &s](std::ostream& out) {
                         const fictus::cli::FieldPiece piece{planes(r)[0], planes(r)[1], slab(r), &values(r)};
                         fictus::cli::write_vti(out, problem, s, &piece);
                       }});
    }
    files.insert(files.begin(), {"solution.pvti", [pieces, &problem, &s](std::ostream& out) {
                                   fictus::cli::write_pvti(out, problem, s, pieces);
                                 }});
    return files;
  }

 private:
  static constexpr int tag = 7;
  fictus::Slab slab(int r) const { return fictus::mpi::default_slab(grid_.layers(), r, size_); }
  /// The node planes of rank r's piece: its layers' and the next one (a Dirichlet box's first piece also
  /// the wall's plane 0).
  std::array<int, 2> planes(int r) const {
    const fictus::Slab s = slab(r);
    if (grid_.periodic()) return {s.first, s.first + s.count};
    return {s.first == 0 ? 0 : s.first + 1, s.first + s.count + 1};
  }
  /// Rank 0: rank r's layers and the next one, received at the first call (one piece is kept: the last
  /// one received).
  const fictus::GridVector& values(int r) {
    if (r == 0) return held_;
    if (!taken_[std::size_t(r)] && slab(r).count > 0) {
      received_.resize(grid_.slab_size(slab(r)) + grid_.layer_size());
      MPI_Recv(received_.data(), slab(r).count + 1, layer_, r, tag, comm_, MPI_STATUS_IGNORE);
      taken_[std::size_t(r)] = true;
      last_ = r;
    } else if (slab(r).count > 0 && last_ != r) {
      throw std::logic_error("FieldPieces: a piece asked for again after another one");
    }
    return received_;
  }

  fictus::Grid<dim> grid_;
  int rank_, size_;
  fictus::GridVector held_, received_;
  std::vector<bool> taken_;
  int last_ = -1;  // the rank whose piece received_ holds
  MPI_Comm comm_;
  MPI_Datatype layer_;
  MPI_Request send_ = MPI_REQUEST_NULL;
};
#endif

/// `fictus solve` in either dimension: the problem, the estimate before any work, the solve with
/// progress lines on long runs, the summary and the output files.
template <int dim>
int run_solve_in(const std::string& text, const SolveCommand& command) {
  fictus::BasicProblemSpec<dim> spec = solve_spec<dim>(text, command);
  for (const std::string& w : spec.warnings) std::fprintf(stderr, "fictus: warning: %s\n", w.c_str());
  const json input = json::parse(spec.input_json);
  const fictus::Distribution& distribution = *fictus::process_distribution();
  fictus::cli::agree_on_threads(distribution, spec.options);
  if (!spec.output.dir.empty())
    fictus::cli::on_rank_0(distribution, [&] { fictus::cli::check_output_folder(spec.output.dir, spec.output.files); });
  fictus::cli::on_rank_0(distribution, [&] { fictus::check_memory(spec.problem, spec.options); });  // rank 0's node
  const double seconds = fictus::estimated_seconds(spec.problem, spec.options);
  const bool long_run = seconds >= 2 && !command.quiet;
  if (long_run) {  // long runs say what is coming before the work starts
    std::fprintf(stderr, "fictus: solving %sN = %d: estimated %.2g GiB and %.2g s\n", dim == 3 ? "a 3-D problem, " : "",
                 spec.problem.N, fictus::estimated_peak_bytes(spec.problem, spec.options) / double(1 << 30), seconds);
    std::fflush(stderr);
  }
  fictus::FictitiousDomainSolver<dim> solver(spec.problem, spec.options);
  if (long_run) solver.set_progress(progress_lines());
#ifdef FICTUS_WITH_MPI
  // The tests' way to make one rank fail alone while the others are in the solve's collectives.
  if (const char* rank = std::getenv("FICTUS_TEST_FAIL_ON_RANK"); rank && distribution.distributed())
    if (std::atoi(rank) == distribution.rank()) throw std::runtime_error("a failure of this rank alone (the tests')");
#endif
  fictus::BasicSolution<dim> s = solver.solve(spec.problem, spec.options, true, false);
  s.peak_memory_bytes = fictus::peak_memory_bytes();
  if (distribution.distributed()) {  // each rank's peak; the field on rank 0 for the files
    std::vector<double> peaks(std::size_t(distribution.size()), 0.0);
    peaks[std::size_t(distribution.rank())] = double(s.peak_memory_bytes);
    distribution.sum(peaks);
    for (double p : peaks) s.rank_peak_memory_bytes.push_back(std::size_t(p));
    s.peak_memory_bytes = s.rank_peak_memory_bytes[0];
  }
#ifdef FICTUS_WITH_MPI
  std::optional<FieldPieces<dim>> pieces;  // the field in pieces, one per rank
  if (distribution.distributed() && !spec.output.dir.empty() &&
      std::count(spec.output.files.begin(), spec.output.files.end(), "solution.vti") > 0)
    pieces.emplace(distribution, s.grid, s.u);
#endif
  for (const std::string& w : s.warnings) std::fprintf(stderr, "fictus: warning: %s\n", w.c_str());
  if (!s.newton.converged) throw NewtonFailure(fictus::describe_newton_failure(s));  // the same on every rank
  fictus::cli::on_rank_0(distribution, [&] {                                         // rank 0 speaks and writes for all
    if (!command.quiet) print_summary(s);
    if (spec.output.dir.empty()) return;
    std::vector<fictus::cli::OutputFile> field_files;
#ifdef FICTUS_WITH_MPI
    if (pieces) field_files = pieces->files(spec.problem, s);
#endif
    const std::vector<fictus::cli::OutputFile> files = output_files(spec, s, input, field_files);
    fictus::cli::write_output_set(spec.output.dir, files, fictus::cli::earlier_solve_outputs(spec.output.dir));
    if (command.quiet) return;
    std::uintmax_t bytes = 0;
    std::error_code error;
    for (const auto& f : files) {
      const std::uintmax_t size = fs::file_size(fs::path(spec.output.dir) / f.name, error);
      if (!error) bytes += size;
    }
    std::printf("wrote %zu files to %s/ (%.3g MiB; the VTK files are zlib-compressed)\n", files.size(),
                spec.output.dir.c_str(), bytes / 1048576.0);
  });
  return 0;
}

int run_solve(const SolveCommand& command) {
  const std::string text = command.problem_path.empty() ? "" : fictus::read_problem_text(command.problem_path);
  if (!text.empty() && fictus::problem_dimension(text, command.problem_path) == 3)
    return run_solve_in<3>(text, command);
  return run_solve_in<2>(text, command);
}

/// Runs the plot script with an argument vector (no shell: any folder name is safe).
int run_plot(const std::string& folder, bool with_lambda) {
  if (!fs::is_directory(folder)) throw std::invalid_argument("plot: " + folder + " is not a folder");
  // An installed fictus (cmake --install) finds its script beside it in share/fictus; the build tree's
  // uses the one in the sources.
  std::error_code error;
  const fs::path installed = fs::read_symlink("/proc/self/exe", error).parent_path() / "../share/fictus/plot.py";
  const std::string script = !error && fs::exists(installed, error) ? installed.string() : FICTUS_PLOT_SCRIPT;
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error("plot: cannot start " FICTUS_PYTHON);
  if (child == 0) {
    const char* argv[] = {FICTUS_PYTHON, script.c_str(), folder.c_str(), with_lambda ? "--lambda" : nullptr, nullptr};
    execv(FICTUS_PYTHON, const_cast<char* const*>(argv));
    std::fprintf(stderr, "fictus: error: plot: cannot run %s\n", FICTUS_PYTHON);
    _exit(127);
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0)
    if (errno != EINTR) return 2;
  // The script's own codes: 0, 1 (what it reads is bad) and 3 (a plot cannot be written).
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 1;
  return code == 0 || code == 3 ? code : 1;
}

int run_reproduce(const fictus::cli::OptionFlags& flags, const std::string& out, const std::string& table,
                  const std::string& levels_text) {
  const auto [first, last] = parse_levels(levels_text);
  // Under mpirun each level is a distributed solve; rank 0 checks, prints and writes for all.
  const fictus::Distribution& distribution = *fictus::process_distribution();
  if (!out.empty())
    fictus::cli::on_rank_0(distribution, [&] {
      fictus::cli::check_output_folder(out, {"table1.json", "table1.csv", "table2.json", "table2.csv"});
    });
  std::vector<fictus::Variant> variants;
  if (table == "1" || table == "both") variants.push_back(fictus::Variant::nonsmooth);
  if (table == "2" || table == "both") variants.push_back(fictus::Variant::smooth);
  if (variants.empty()) throw std::invalid_argument("--table: expected 1, 2 or both");
  int status = 0;
  json summary;
  std::vector<std::pair<std::string, std::string>> files;
  for (fictus::Variant variant : variants) {
    const int number = variant == fictus::Variant::nonsmooth ? 1 : 2;
    std::vector<fictus::LevelResult> rows;
    json levels = json::array();
    for (int level = first; level <= last; ++level) {
      const int N = 1 << level;
      fictus::Problem problem = fictus::paper_problem(N);
      fictus::SolverOptions options = fictus::paper_options(N, variant);  // the paper's m and δ
      options.error_estimate = false;  // the tables time the paper's method; --error_estimate true adds it
      options.fit_contact = 0;         // (one solve; --fit_contact adds passes)
      flags.apply(problem, options);
      fictus::cli::agree_on_threads(distribution, options);
      fictus::cli::on_rank_0(distribution, [&] { fictus::check_memory(problem, options); });  // rank 0's node
      fictus::Solution s = fictus::solve(problem, options);
      s.peak_memory_bytes = fictus::peak_memory_bytes();
      if (!s.newton.converged) {
        std::fprintf(stderr, "fictus: error: Newton did not converge at h = 1/%d: %s\n", N, s.newton.failure.c_str());
        status = 2;
      }
      rows.push_back(fictus::cli::level_result(s));
      levels.push_back(fictus::cli::solution_to_json(problem, s));
      std::fprintf(stderr, "  table %d, h = 1/%d done in %.2f s\n", number, N, s.timings.total);
    }
    const std::string title = number == 1 ? "Table 1: non-smooth fictitious domain formulation (Gamma = gamma)"
                                          : "Table 2: smooth fictitious domain formulation (Gamma outside omega)";
    std::printf("%s", fictus::format_convergence_table(title, rows, variant).c_str());
    std::printf(
        "  it0 = Newton steps; it1 = applications of A^-1 (u0, every Krylov product, the final u; the green solver\n"
        "  needs 2). Errors are relative, in L2(omega), the full H1(omega) norm and L2(gamma). The paper's H1 column\n"
        "  is not a relative error (it exceeds 1 at h = 1/128): compare its rate, not its values. The paper's rate\n"
        "  is its own over the levels shown. More in docs/reproduction.md.\n\n");
    json rates = json::array();
    for (const auto& r : fictus::observed_rates(rows)) rates.push_back(r);
    json out{{"table", number},
             {"variant", fictus::to_string(variant)},
             {"levels", levels},
             {"observed_rates", rates},
             {"fitted_rates", fictus::fitted_rates(rows)},
             {"paper_rates", fictus::paper_rates_over(variant, rows) ? json(*fictus::paper_rates_over(variant, rows))
                                                                     : json(nullptr)}};
    files.emplace_back("table" + std::to_string(number) + ".json", out.dump(2) + "\n");
    files.emplace_back("table" + std::to_string(number) + ".csv", fictus::cli::levels_csv(rows));
  }
  if (!out.empty()) {
    std::vector<fictus::cli::OutputFile> set;
    for (const auto& [name, text] : files) set.push_back({name, [&text](std::ostream& o) { o << text; }});
    // An earlier reproduction's tables and plot, where its table<k>.json says it was one.
    const bool earlier = fictus::cli::written_by_fictus(fs::path(out) / "table1.json", "observed_rates") ||
                         fictus::cli::written_by_fictus(fs::path(out) / "table2.json", "observed_rates");
    const auto reproduced = [earlier](const std::string& name) {
      static const std::regex table(R"(table[12]\.(csv|json)|convergence\.png)");
      return earlier && std::regex_match(name, table);
    };
    fictus::cli::on_rank_0(distribution, [&] { fictus::cli::write_output_set(out, set, reproduced); });
    std::printf("wrote %zu files to %s/\n", files.size(), out.c_str());
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // a line at a time, also into a file or a pipe
#ifdef FICTUS_WITH_MPI
  // Under mpirun (or srun): MPI for the life of the process. On more than one rank, `fictus solve` and
  // `fictus sweep` run distributed (the process's Distribution is the ranks' slabs); rank 0 prints and
  // writes.
  std::optional<fictus::mpi::Environment> mpi;
  if (fictus::mpi::launched()) {
    try {
      mpi.emplace(argc, argv);
    } catch (const std::exception& e) {
      return report(e.what(), exit_internal);
    }
    const fictus::mpi::Communicator world;
    const int declared = fictus::mpi::declared_size();
    if (declared > world.size())  // every process alone: each says so
      return report("started as one of " + std::to_string(declared) +
                        " tasks, but MPI sees this process alone: the launcher is not the MPI fictus was built "
                        "with (another MPI's mpirun, or srun without its MPI plugin)",
                    exit_bad_input);
    if (world.size() > 1) {
      ranks.rank = world.rank(), ranks.size = world.size();
      MPI_Comm_dup(MPI_COMM_WORLD, &ranks.errors);
      if (ranks.rank != 0) {  // quiet: rank 0 speaks for all
        std::fflush(stdout), std::fflush(stderr);
        ranks.own_stderr = dup(STDERR_FILENO);
        const int null = open("/dev/null", O_WRONLY);
        if (null >= 0) dup2(null, STDOUT_FILENO), dup2(null, STDERR_FILENO), close(null);
      } else {
        ranks.own_stderr = STDERR_FILENO;
      }
      fictus::set_process_distribution(std::make_shared<fictus::mpi::SlabDistribution>(world));
      const std::string command = argc > 1 ? argv[1] : "";
      if (command == "plot")
        return fail("started on " + std::to_string(ranks.size) +
                        " MPI ranks: fictus plot runs on one rank (without mpirun, or mpirun -np 1); solve, sweep "
                        "and reproduce run distributed",
                    exit_bad_input);
    }
  }
#endif
  CLI::App app{"fictus: Signorini problems on curved domains by a fictitious domain method"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(FICTUS_VERSION));

  // solve: every option of options.hpp as --key; without a file the paper's problem.
  SolveCommand solve;
  CLI::App* solve_cmd = app.add_subcommand("solve", "solve a problem file, or the paper's problem without one");
  // Existence is checked by the reader, after the parse: an unknown flag before a stray argument is
  // reported as such, not as a missing file.
  solve_cmd->add_option("problem", solve.problem_path, "problem file (TOML, see docs/problem_files.md)");
  solve.out_option = solve_cmd->add_option("--out", solve.out, "output.dir: folder for the output files (\"\": none)")
                         ->capture_default_str();
  solve_cmd->add_option("--dir", solve.out, "alias of --out")->group("");
  solve_cmd->add_option("--file", solve.mesh_file,
                        "geometry.file of a 3-D mesh problem: a .off, .stl, .obj or .ply file (relative to here)");
  solve.resolution_option =
      solve_cmd->add_option("--resolution", solve.mesh_resolution,
                            "geometry.resolution of a 3-D mesh problem: lattice cells across the mesh (0: automatic)");
  solve_cmd
      ->add_option("--parameter", solve.parameters,
                   "NAME=VALUE: a value for an entry of the problem file's [parameters] (repeatable)")
      ->allow_extra_args(false);
  solve_cmd->add_flag("--quiet", solve.quiet, "print only warnings and errors (no estimate, progress or summary)");
  solve.files_option =
      solve_cmd
          ->add_option(
              "--files", solve.files,
              "output.files, comma-separated: results.json,points.csv,solution.vti,curves.vtp (3-D: surface.vtp)")
          ->delimiter(',')
          ->allow_extra_args(false);
  const std::map<std::string, std::string> paper_note = {{"multipliers", "without a problem file: the paper's m"},
                                                         {"offset", "without a problem file: 1 (the paper's δ = L/m)"}};
  solve.flags.add(
      *solve_cmd, [](const fictus::OptionSpec&) { return true; }, paper_note);

  std::string plot_dir;
  bool plot_lambda = false;
  CLI::App* plot_cmd = app.add_subcommand("plot", "PNG plots of the results in a folder (matplotlib)");
  plot_cmd->add_option("dir", plot_dir, "folder written by solve, reproduce or sweep")->required();
  plot_cmd->add_flag("--lambda", plot_lambda, "also draw the multipliers λ (not a contact pressure)");

  // reproduce: the paper's problem at each level, its m and δ; the other options as flags.
  std::string table = "both", levels = "7-12", reproduce_out;
  fictus::cli::OptionFlags reproduce_flags;
  CLI::App* reproduce_cmd = app.add_subcommand("reproduce", "reproduce the paper's Table 1 and/or Table 2");
  reproduce_cmd->add_option("--table", table, "1 (non-smooth), 2 (smooth) or both")->capture_default_str();
  reproduce_cmd->add_option("--levels", levels, "levels A-B, h = 2^-level")->capture_default_str();
  reproduce_cmd->add_option("--out", reproduce_out, "write table<k>.json and table<k>.csv here");
  reproduce_flags.add(*reproduce_cmd,
                      [](const fictus::OptionSpec& s) {
                        return formulation_or_solver(s) && s.key != "variant" && s.key != "multipliers";
                      },
                      {{"offset", "here: 1 (the paper's δ = L/m)"}});

  // sweep: a problem file (or the paper's problem) varied by one quantity, on one grid.
  fictus::cli::OptionFlags sweep_flags;
  fictus::cli::SweepArguments sweep_args;
  CLI::App* sweep_cmd = app.add_subcommand(
      "sweep",
      "solve a family of problems on one grid: the obstacle scaled, the curve rotated or moved, or a parameter");
  sweep_cmd->add_option("problem", sweep_args.problem_path, "problem file (default: the paper's problem)");
  sweep_cmd->add_option("--g-scale", sweep_args.g_scale, "obstacle factors: a,b,c or start:stop:count");
  sweep_cmd->add_option("--rotate", sweep_args.rotate,
                        "rotations of γ about its center [rad] (3-D: about --axis): a,b,c or start:stop:count");
  sweep_cmd->add_option("--move", sweep_args.move, "shifts of γ along x: a,b,c or start:stop:count");
  sweep_cmd->add_option("--axis", sweep_args.axis,
                        "3-D: the axis of --rotate through the centre of γ's bounding box: x, y or z (default z)");
  sweep_cmd->add_option("--parameter", sweep_args.parameter,
                        "NAME=LIST: values of a [parameters] entry of the problem file, e.g. a=0:0.2:11");
  sweep_cmd->add_option("--out", sweep_args.out, "write sweep.csv and sweep.json here (\"\": none)")
      ->capture_default_str();
  sweep_flags.add(*sweep_cmd, [](const fictus::OptionSpec&) { return true; },
                  {{"multipliers", "without a problem file: the paper's m"},
                   {"offset", "without a problem file: 1 (the paper's δ = L/m)"},
                   {"condition_number", "here: false"},
                   {"error_estimate", "here: false"}});

  CLI::App* options_cmd = app.add_subcommand("options", "list every option: key, default, allowed values, meaning");
  bool markdown = false, as_json = false;
  options_cmd->add_flag("--markdown", markdown, "as the Markdown table of docs/problem_files.md");
  options_cmd->add_flag("--json", as_json, "as JSON: section, key, type, default, allowed values, meaning, aliases");

  const std::set<std::string> commands = {"solve", "plot", "reproduce", "sweep", "options"};
  if (argc > 1 && argv[1][0] != '-' && !commands.count(argv[1]))
    return fail(std::string(argv[1]) + ": not a command (solve, plot, reproduce, sweep, options; see fictus --help)",
                exit_bad_input);
  // "--key=" gives an option that takes a value the empty value: CLI11 would take the next argument
  // as its value instead. (Flags, and everything after a bare "--", pass as they are.)
  std::set<std::string> valued;
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; }))
    for (const CLI::Option* option : command->get_options())
      if (option->get_items_expected_max() > 0)
        for (const std::string& name : option->get_lnames()) valued.insert("--" + name + "=");
  std::vector<std::string> arguments(argv + 1, argv + argc);
  for (std::size_t k = 0; k < arguments.size() && arguments[k] != "--"; ++k)
    if (valued.count(arguments[k])) {
      arguments[k].pop_back();
      arguments.insert(arguments.begin() + std::ptrdiff_t(k) + 1, "");
      ++k;
    }
  std::reverse(arguments.begin(), arguments.end());  // CLI11 takes the arguments last first
  app.name("fictus");                                // (parse(argc, argv) would take argv[0])
  try {
    app.parse(arguments);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --version
  } catch (const CLI::ParseError& e) {
    std::vector<std::string> flags;  // the long flags of the command given (or of fictus itself)
    const std::vector<CLI::App*> given = app.get_subcommands();
    for (const CLI::Option* option : (given.empty() ? &app : given.front())->get_options())
      for (const std::string& name : option->get_lnames()) flags.push_back("--" + name);
    return fail(parse_error_line(e.what(), flags) + " (see fictus --help)", exit_bad_input);
  }
  try {
    if (*solve_cmd) return run_solve(solve);
    if (*plot_cmd) return run_plot(plot_dir, plot_lambda);
    if (*reproduce_cmd) return run_reproduce(reproduce_flags, reproduce_out, table, levels);
    if (*sweep_cmd) return fictus::cli::run_sweep(sweep_args, sweep_flags);
    if (*options_cmd) {
      if (markdown) {
        std::printf("%s", fictus::options_markdown().c_str());
      } else if (as_json) {
        std::printf("%s\n", fictus::cli::options_schema_json().dump(1).c_str());
      } else {
        for (const fictus::OptionSpec& s : fictus::option_specs()) {
          std::string dims;  // "2-D", "3-D" or "2-D, 3-D"
          for (int d : s.dims) dims += (dims.empty() ? "" : ", ") + std::to_string(d) + "-D";
          std::printf("%-34s %-10s default %s\n    %s\n    %s\n", s.name().c_str(), dims.c_str(),
                      fictus::cli::plain(fictus::default_text(s)).c_str(), s.rule.c_str(), s.meaning.c_str());
        }
      }
      return 0;
    }
  } catch (const std::invalid_argument& e) {
    return fail(e.what(), exit_bad_input);
  } catch (const NewtonFailure& e) {
    return fail(e.what(), exit_newton);
  } catch (const fictus::cli::OutputError& e) {
    return fail(e.what(), exit_output);
  } catch (const std::bad_alloc&) {
    return fail("out of memory (a smaller N, or check solver.max_memory)", exit_internal);
  } catch (const std::exception& e) {
    return fail(e.what(), exit_internal);
  }
  return 0;
}
