// fictus: command-line front end. Owns argument parsing, printing and files; the numerics live in
// the library.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "fictus/convergence_table.hpp"
#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/paper_problem.hpp"
#include "results_io.hpp"
#include "sweep.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct SolveArguments {
  int N = 256;
  std::string variant = "smooth";
  std::string schur = "green";
  std::string start = "all";
  std::string out;
};

void add_solver_options(CLI::App& cmd, fictus::SolverOptions& o, SolveArguments& a) {
  cmd.add_option("--variant", a.variant, "smooth (controls on Γ outside ω) or nonsmooth (Γ = γ)")
      ->capture_default_str();
  cmd.add_option("--m,--multipliers", o.multipliers, "number of multipliers m (0: default rule)")->capture_default_str();
  cmd.add_option("--offset", o.offset, "smooth variant: distance of Γ from γ in units of the spacing L/m")
      ->capture_default_str();
  cmd.add_option("--rho", o.rho, "ρ > 0 of the projection")->capture_default_str();
  cmd.add_option("--normal-shift", o.normal_shift, "C_γ is taken this many cells h inside ω")->capture_default_str();
  cmd.add_option("--start", a.start, "Newton start: all (every point active) or zero (λ = 0)")->capture_default_str();
  cmd.add_option("--schur", a.schur, "inner solver: green (explicit Schur complement) or krylov (GMRES, paper)")
      ->capture_default_str();
  cmd.add_option("--krylov-tol", o.krylov_tolerance, "relative GMRES tolerance")->capture_default_str();
  cmd.add_option("--newton-tol", o.newton_tolerance, "relative Newton residual tolerance")->capture_default_str();
  cmd.add_option("--max-newton", o.max_newton, "maximum Newton steps")->capture_default_str();
  cmd.add_option("--threads", o.threads, "threads for transforms and loops")->capture_default_str();
  cmd.add_flag("!--no-condition", o.condition_number, "skip the condition number of the Newton matrix");
}

void resolve(fictus::SolverOptions& o, const SolveArguments& a) {
  o.variant = fictus::parse_variant(a.variant);
  o.inner = fictus::parse_inner_solver(a.schur);
  if (a.start != "all" && a.start != "zero")
    throw std::invalid_argument("solver.start: expected \"all\" or \"zero\", got \"" + a.start + "\"");
  o.start_all_active = a.start == "all";
}

void print_summary(const fictus::Solution& s) {
  std::printf("N = %d (h = %.3g), n = %zu nodes, m = %d, variant %s, inner solver %s\n", s.grid.nx(), s.grid.h(),
              s.grid.n_nodes(), s.collocation.m, fictus::to_string(s.options.variant), fictus::to_string(s.options.inner));
  std::printf("Newton: %d steps, %s, %ld active of %d; fast solves %zu, Krylov iterations %d\n", s.newton.iterations,
              s.newton.converged ? "converged" : "NOT converged",
              long(std::count(s.newton.active.begin(), s.newton.active.end(), 1)), s.collocation.m, s.fast_solves,
              s.inner_iterations);
  if (s.condition_number) std::printf("condition number of the Newton matrix: %.3e\n", *s.condition_number);
  std::printf("Signorini checks: min gap %.2e, min du/dn %.2e, max |complementarity| %.2e\n", s.signorini.min_gap,
              s.signorini.min_normal_derivative, s.signorini.max_complementarity);
  if (s.errors)
    std::printf("relative errors: L2(omega) %.3e, H1(omega) %.3e (semi %.3e), L2(gamma) %.3e\n", s.errors->rel_l2_omega,
                s.errors->rel_h1_omega, s.errors->rel_h1semi_omega, s.errors->rel_l2_gamma);
  std::printf("time %.3f s (", s.timings.total);
  for (std::size_t k = 0; k < s.timings.phases.size(); ++k)
    std::printf("%s%s %.3f", k ? ", " : "", s.timings.phases[k].first.c_str(), s.timings.phases[k].second);
  std::printf("), peak memory %.1f MiB\n", s.peak_memory_bytes / 1048576.0);
}

std::pair<int, int> parse_levels(const std::string& text) {
  static const std::regex pattern(R"((\d+)(?:-(\d+))?)");
  std::smatch match;
  if (!std::regex_match(text, match, pattern)) throw std::invalid_argument("--levels: expected A-B, e.g. 7-10");
  const int a = std::stoi(match[1]), b = match[2].matched ? std::stoi(match[2]) : a;
  if (a < 3 || b > 15 || a > b) throw std::invalid_argument("--levels: need 3 <= A <= B <= 15 (h = 2^-level)");
  return {a, b};
}

int run_solve(fictus::SolverOptions options, const SolveArguments& args) {
  resolve(options, args);
  const fictus::Problem problem = fictus::paper_problem(args.N);
  const fictus::Solution solution = fictus::solve(problem, options);
  print_summary(solution);
  if (!args.out.empty()) {
    fs::create_directories(args.out);
    fictus::cli::write_atomically(fs::path(args.out) / "results.json",
                                  fictus::cli::solution_to_json(problem, solution).dump(2) + "\n");
    fictus::cli::write_atomically(fs::path(args.out) / "points.csv", fictus::cli::points_csv(solution));
    std::printf("wrote %s/results.json and points.csv\n", args.out.c_str());
  }
  if (!solution.newton.converged) {
    std::fprintf(stderr, "fictus: error: Newton did not converge: %s\n", solution.newton.failure.c_str());
    return 2;
  }
  return 0;
}

int run_reproduce(fictus::SolverOptions base, const SolveArguments& args, const std::string& table,
                  const std::string& levels_text) {
  const auto [first, last] = parse_levels(levels_text);
  std::vector<fictus::Variant> variants;
  if (table == "1" || table == "both") variants.push_back(fictus::Variant::nonsmooth);
  if (table == "2" || table == "both") variants.push_back(fictus::Variant::smooth);
  if (variants.empty()) throw std::invalid_argument("--table: expected 1, 2 or both");
  SolveArguments a = args;
  int status = 0;
  json summary;
  std::vector<std::pair<std::string, std::string>> files;
  for (fictus::Variant variant : variants) {
    const int number = variant == fictus::Variant::nonsmooth ? 1 : 2;
    std::vector<fictus::LevelResult> rows;
    json levels = json::array();
    for (int level = first; level <= last; ++level) {
      const int N = 1 << level;
      fictus::SolverOptions options = base;
      a.variant = fictus::to_string(variant);
      resolve(options, a);
      options.multipliers = fictus::paper_multipliers(N);
      const fictus::Problem problem = fictus::paper_problem(N);
      const fictus::Solution s = fictus::solve(problem, options);
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
    std::printf("%s\n", fictus::format_convergence_table(title, rows, variant).c_str());
    json rates = json::array();
    for (const auto& r : fictus::observed_rates(rows)) rates.push_back(r);
    json out{{"table", number}, {"variant", fictus::to_string(variant)}, {"levels", levels},
             {"observed_rates", rates}, {"fitted_rates", fictus::fitted_rates(rows)},
             {"paper_rates", fictus::paper_rates(variant)}};
    files.emplace_back("table" + std::to_string(number) + ".json", out.dump(2) + "\n");
    files.emplace_back("table" + std::to_string(number) + ".csv", fictus::cli::levels_csv(rows));
  }
  if (!args.out.empty()) {
    fs::create_directories(args.out);
    for (const auto& [name, text] : files) fictus::cli::write_atomically(fs::path(args.out) / name, text);
    std::printf("wrote %zu files to %s/\n", files.size(), args.out.c_str());
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fictus: Signorini problems on curved domains by a fictitious domain method"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(FICTUS_VERSION));

  fictus::SolverOptions solve_options;
  SolveArguments solve_args;
  CLI::App* solve_cmd = app.add_subcommand("solve", "solve the paper's problem on one grid");
  solve_cmd->add_option("--N", solve_args.N, "cells per side (h = 1/N)")->capture_default_str();
  solve_args.out = "results/solve";
  solve_cmd->add_option("--out", solve_args.out, "write results.json and points.csv into this folder (\"\": none)")
      ->capture_default_str();
  add_solver_options(*solve_cmd, solve_options, solve_args);

  fictus::SolverOptions reproduce_options;
  SolveArguments reproduce_args;
  std::string table = "both", levels = "7-12";
  CLI::App* reproduce_cmd = app.add_subcommand("reproduce", "reproduce the paper's Table 1 and/or Table 2");
  reproduce_cmd->add_option("--table", table, "1 (non-smooth), 2 (smooth) or both")->capture_default_str();
  reproduce_cmd->add_option("--levels", levels, "levels A-B, h = 2^-level")->capture_default_str();
  reproduce_cmd->add_option("--out", reproduce_args.out, "write table<k>.json and table<k>.csv here");
  reproduce_cmd->add_option("--schur", reproduce_args.schur, "inner solver: green or krylov")->capture_default_str();
  reproduce_cmd->add_option("--threads", reproduce_options.threads, "threads")->capture_default_str();
  reproduce_cmd->add_option("--offset", reproduce_options.offset, "smooth variant: δ in units of L/m")
      ->capture_default_str();
  reproduce_cmd->add_option("--normal-shift", reproduce_options.normal_shift, "C_γ shift in cells")->capture_default_str();

  fictus::SolverOptions sweep_options;
  SolveArguments sweep_solver_args;
  fictus::cli::SweepArguments sweep_args;
  CLI::App* sweep_cmd = app.add_subcommand(
      "sweep", "solve a family of problems on one grid (paper's problem; g scaled, or the curve rotated or moved)");
  sweep_cmd->add_option("--N", sweep_args.N, "cells per side")->capture_default_str();
  sweep_cmd->add_option("--g-scale", sweep_args.g_scale, "obstacle factors: a,b,c or start:stop:count");
  sweep_cmd->add_option("--rotate", sweep_args.rotate, "rotations of γ about its center [rad]: a,b,c or start:stop:count");
  sweep_cmd->add_option("--move", sweep_args.move, "shifts of γ along x: a,b,c or start:stop:count");
  sweep_cmd->add_flag("--field", sweep_args.field, "also compute the grid field û for every problem");
  sweep_cmd->add_option("--out", sweep_args.out, "write sweep.csv here (\"\": none)")->capture_default_str();
  add_solver_options(*sweep_cmd, sweep_options, sweep_solver_args);
  sweep_options.condition_number = false;

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*solve_cmd) return run_solve(solve_options, solve_args);
    if (*reproduce_cmd) return run_reproduce(reproduce_options, reproduce_args, table, levels);
    if (*sweep_cmd) {
      resolve(sweep_options, sweep_solver_args);
      return fictus::cli::run_sweep(sweep_args, sweep_options);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fictus: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
