// fictus: command-line front end. Owns argument parsing, printing and files; the numerics live in
// the library.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <filesystem>
#include <iostream>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "fictus/convergence_table.hpp"
#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/paper_problem.hpp"
#include "fictus/problem_file.hpp"
#include "results_io.hpp"
#include "vtk_io.hpp"
#include "sweep.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct SolveArguments {
  std::string problem_path;
  int N = 256;
  double c = 1.0;
  std::string boundary = "dirichlet";
  std::string variant = "smooth";
  std::string schur = "green";
  std::string start = "all";
  std::string normal_derivative = "reconstructed";
  std::string out;
  std::vector<std::string> files;
};

/// Flags that override a problem file: applied only when given on the command line.
struct Overrides {
  std::vector<std::pair<CLI::Option*, std::function<void(fictus::ProblemSpec&)>>> items;
  void apply(fictus::ProblemSpec& spec) const {
    for (const auto& [option, set] : items)
      if (option->count() > 0) set(spec);
  }
};

void add_solver_options(CLI::App& cmd, fictus::SolverOptions& o, SolveArguments& a, Overrides* overrides = nullptr) {
  auto add = [&](CLI::Option* option, std::function<void(fictus::ProblemSpec&)> set) {
    option->capture_default_str();
    if (overrides) overrides->items.emplace_back(option, std::move(set));
  };
  add(cmd.add_option("--variant", a.variant, "smooth (controls on Γ outside ω) or nonsmooth (Γ = γ)"),
      [&](fictus::ProblemSpec& s) { s.options.variant = fictus::parse_variant(a.variant); });
  add(cmd.add_option("--m,--multipliers", o.multipliers, "number of multipliers m (0: default rule)"),
      [&](fictus::ProblemSpec& s) { s.options.multipliers = o.multipliers; });
  add(cmd.add_option("--offset", o.offset, "smooth variant: distance of Γ from γ in units of the spacing L/m"),
      [&](fictus::ProblemSpec& s) { s.options.offset = o.offset; });
  add(cmd.add_option("--rho", o.rho, "ρ > 0 of the projection"), [&](fictus::ProblemSpec& s) { s.options.rho = o.rho; });
  add(cmd.add_option("--normal-derivative", a.normal_derivative,
                     "traces: reconstructed (consistent at x_i) or shifted (cell gradient normal_shift·h inside ω)"),
      [&](fictus::ProblemSpec& s) { s.options.normal_derivative = fictus::parse_normal_derivative(a.normal_derivative); });
  add(cmd.add_option("--normal-shift", o.normal_shift, "shifted rule: C_γ is taken this many cells h inside ω"),
      [&](fictus::ProblemSpec& s) { s.options.normal_shift = o.normal_shift; });
  add(cmd.add_option("--start", a.start, "Newton start: all (every point active) or zero (λ = 0)"),
      [&](fictus::ProblemSpec& s) { s.options.start_all_active = a.start == "all"; });
  add(cmd.add_option("--schur", a.schur, "inner solver: green (explicit Schur complement) or krylov (GMRES, paper)"),
      [&](fictus::ProblemSpec& s) { s.options.inner = fictus::parse_inner_solver(a.schur); });
  add(cmd.add_option("--krylov-tol", o.krylov_tolerance, "relative GMRES tolerance"),
      [&](fictus::ProblemSpec& s) { s.options.krylov_tolerance = o.krylov_tolerance; });
  add(cmd.add_option("--krylov-max-iterations", o.krylov_max_iterations, "GMRES operator applications per solve"),
      [&](fictus::ProblemSpec& s) { s.options.krylov_max_iterations = o.krylov_max_iterations; });
  add(cmd.add_option("--load-quadrature", o.load_quadrature, "Gauss points per direction for the load"),
      [&](fictus::ProblemSpec& s) { s.options.load_quadrature = o.load_quadrature; });
  add(cmd.add_option("--error-quadrature", o.error_quadrature, "Gauss points per direction for the errors"),
      [&](fictus::ProblemSpec& s) { s.options.error_quadrature = o.error_quadrature; });
  add(cmd.add_option("--newton-tol", o.newton_tolerance, "relative Newton residual tolerance"),
      [&](fictus::ProblemSpec& s) { s.options.newton_tolerance = o.newton_tolerance; });
  add(cmd.add_option("--max-newton", o.max_newton, "maximum Newton steps"),
      [&](fictus::ProblemSpec& s) { s.options.max_newton = o.max_newton; });
  add(cmd.add_option("--threads", o.threads, "threads for transforms and loops"),
      [&](fictus::ProblemSpec& s) { s.options.threads = o.threads; });
  CLI::Option* no_condition = cmd.add_flag("!--no-condition", o.condition_number, "skip the condition number of the Newton matrix");
  if (overrides) overrides->items.emplace_back(no_condition, [&](fictus::ProblemSpec& s) { s.options.condition_number = false; });
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
  if (s.check)
    std::printf("  with an independent du/dn (%s): min du/dn %.2e, max |complementarity| %.2e, "
                "max |difference| %.2e\n",
                s.check->rule.c_str(), s.check->min_normal_derivative, s.check->max_complementarity,
                s.check->max_difference);
  if (s.errors)
    std::printf("relative errors: L2(omega) %.3e, H1(omega) %.3e (semi %.3e), L2(gamma) %.3e\n", s.errors->rel_l2_omega,
                s.errors->rel_h1_omega, s.errors->rel_h1semi_omega, s.errors->rel_l2_gamma);
  std::printf("time %.3f s (", s.timings.total);
  for (std::size_t k = 0; k < s.timings.phases.size(); ++k)
    std::printf("%s%s %.3f", k ? ", " : "", s.timings.phases[k].first.c_str(), s.timings.phases[k].second);
  std::printf("), peak memory %.1f MiB\n", s.peak_memory_bytes / 1048576.0);
}

void resolve(fictus::SolverOptions& o, const SolveArguments& a) {
  o.variant = fictus::parse_variant(a.variant);
  o.inner = fictus::parse_inner_solver(a.schur);
  o.normal_derivative = fictus::parse_normal_derivative(a.normal_derivative);
  if (a.start != "all" && a.start != "zero")
    throw std::invalid_argument("solver.start: expected \"all\" or \"zero\", got \"" + a.start + "\"");
  o.start_all_active = a.start == "all";
}

std::pair<int, int> parse_levels(const std::string& text) {
  static const std::regex pattern(R"((\d+)(?:-(\d+))?)");
  std::smatch match;
  if (!std::regex_match(text, match, pattern)) throw std::invalid_argument("--levels: expected A-B, e.g. 7-10");
  const int a = std::stoi(match[1]), b = match[2].matched ? std::stoi(match[2]) : a;
  if (a < 3 || b > 15 || a > b) throw std::invalid_argument("--levels: need 3 <= A <= B <= 15 (h = 2^-level)");
  return {a, b};
}

int run_solve(const fictus::SolverOptions& cli_options, const SolveArguments& args, const Overrides& overrides,
              CLI::Option* out_option) {
  fictus::ProblemSpec spec;
  if (!args.problem_path.empty()) {
    spec = fictus::read_problem_file(args.problem_path);
  } else {
    if (args.boundary != "dirichlet" && args.boundary != "periodic")
      throw std::invalid_argument("domain.boundary: expected \"dirichlet\" or \"periodic\", got \"" + args.boundary + "\"");
    spec.problem = fictus::paper_problem(
        args.N, args.c, args.boundary == "periodic" ? fictus::Boundary::periodic : fictus::Boundary::dirichlet);
    spec.options = cli_options;
    resolve(spec.options, args);
    // The paper's m and δ unless --m or --offset say otherwise (applied by the overrides below).
    const fictus::SolverOptions paper = fictus::paper_options(args.N, spec.options.variant);
    spec.options.multipliers = paper.multipliers;
    spec.options.offset = paper.offset;
  }
  overrides.apply(spec);
  if (out_option->count() > 0) spec.output.dir = args.out;
  spec.options.validate();
  for (const std::string& w : spec.warnings) std::fprintf(stderr, "fictus: warning: %s\n", w.c_str());

  const fictus::Problem& problem = spec.problem;
  const fictus::Solution solution = fictus::solve(problem, spec.options);
  if (!solution.newton.converged) throw std::runtime_error(fictus::describe_newton_failure(solution));
  print_summary(solution);
  if (!spec.output.dir.empty()) {
    const fs::path dir = spec.output.dir;
    fs::create_directories(dir);
    for (const std::string& name : spec.output.files) {
      if (name == "results.json")
        fictus::cli::write_atomically(dir / name, fictus::cli::solution_to_json(problem, solution).dump(2) + "\n");
      else if (name == "points.csv")
        fictus::cli::write_atomically(dir / name, fictus::cli::points_csv(solution));
      else if (name == "solution.vti")
        fictus::cli::write_atomically(dir / name, [&](std::ostream& out) { fictus::cli::write_vti(out, problem, solution); });
      else if (name == "curves.vtp")
        fictus::cli::write_atomically(dir / name, [&](std::ostream& out) { fictus::cli::write_vtp(out, solution); });
    }
    std::printf("wrote %zu files to %s/\n", spec.output.files.size(), spec.output.dir.c_str());
  }
  return 0;
}

int run_plot(const std::string& folder) {
  if (!fs::is_directory(folder)) throw std::invalid_argument("plot: " + folder + " is not a folder");
  const std::string command = std::string("'") + FICTUS_PYTHON + "' '" + FICTUS_PLOT_SCRIPT + "' '" + folder + "'";
  const int status = std::system(command.c_str());
  return status == 0 ? 0 : 1;
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
  Overrides overrides;
  CLI::App* solve_cmd = app.add_subcommand("solve", "solve a problem file, or the paper's problem without one");
  solve_cmd->add_option("problem", solve_args.problem_path, "problem file (TOML, see docs/problem_files.md)")
      ->check(CLI::ExistingFile);
  solve_args.out = "results/solve";
  CLI::Option* out_option =
      solve_cmd->add_option("--out", solve_args.out, "folder for the output files (\"\": none; default: output.dir)")
          ->capture_default_str();
  overrides.items.emplace_back(
      solve_cmd->add_option("--N", solve_args.N, "cells along x (h = (x1 - x0)/N)")->capture_default_str(),
      [&](fictus::ProblemSpec& s) { s.problem.N = solve_args.N; });
  overrides.items.emplace_back(
      solve_cmd->add_option("--c", solve_args.c, "reaction coefficient c >= 0 (paper's problem: f = -Δu_ex + c·u_ex follows)")
          ->capture_default_str(),
      [&](fictus::ProblemSpec& s) { s.problem.c = solve_args.c; });
  overrides.items.emplace_back(
      solve_cmd->add_option("--boundary", solve_args.boundary,
                            "box conditions: dirichlet, or periodic (c = 0 allowed: singular A, bordered Newton)")
          ->capture_default_str(),
      [&](fictus::ProblemSpec& s) {
        if (solve_args.boundary != "dirichlet" && solve_args.boundary != "periodic")
          throw std::invalid_argument("domain.boundary: expected \"dirichlet\" or \"periodic\"");
        s.problem.boundary = solve_args.boundary == "periodic" ? fictus::Boundary::periodic : fictus::Boundary::dirichlet;
      });
  add_solver_options(*solve_cmd, solve_options, solve_args, &overrides);
  overrides.items.emplace_back(
      solve_cmd->add_option("--files", solve_args.files, "output files, comma-separated (results.json,points.csv,solution.vti,curves.vtp)")
          ->delimiter(','),
      [&](fictus::ProblemSpec& s) {
        for (const std::string& f : solve_args.files)
          if (std::find(fictus::output_file_names().begin(), fictus::output_file_names().end(), f) ==
              fictus::output_file_names().end())
            throw std::invalid_argument("output.files: unknown file \"" + f + "\"");
        s.output.files = solve_args.files;
      });

  std::string plot_dir;
  CLI::App* plot_cmd = app.add_subcommand("plot", "PNG plots of the results in a folder (matplotlib)");
  plot_cmd->add_option("dir", plot_dir, "folder written by solve or reproduce")->required();

  fictus::SolverOptions reproduce_options = fictus::paper_options(128, fictus::Variant::smooth);  // the paper's δ = L/m
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
  reproduce_cmd->add_option("--normal-derivative", reproduce_args.normal_derivative, "reconstructed or shifted")
      ->capture_default_str();
  reproduce_cmd->add_option("--normal-shift", reproduce_options.normal_shift, "shifted rule: C_γ shift in cells")
      ->capture_default_str();

  // The paper's problem: its δ = L/m, and its m unless --m is given (0 is resolved per N in run_sweep).
  fictus::SolverOptions sweep_options = fictus::paper_options(128, fictus::Variant::smooth);
  sweep_options.multipliers = 0;
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
    if (*solve_cmd) return run_solve(solve_options, solve_args, overrides, out_option);
    if (*plot_cmd) return run_plot(plot_dir);
    if (*reproduce_cmd) return run_reproduce(reproduce_options, reproduce_args, table, levels);
    if (*sweep_cmd) {
      resolve(sweep_options, sweep_solver_args);
      return fictus::cli::run_sweep(sweep_args, sweep_options);
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "fictus: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fictus: error: %s\n", e.what());
    return 2;
  }
  return 0;
}
