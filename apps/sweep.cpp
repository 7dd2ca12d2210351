// `fictus sweep`: a family of problems on one grid, reusing the Green's table, u₀ and (for
// obstacle sweeps) the Schur blocks.
#include "sweep.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "fictus/boundary/shapes.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/io/process.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "results_io.hpp"

namespace fictus::cli {

namespace {

/// The whole text as a number (std::stod alone stops at the first character it cannot read).
double whole_number(const std::string& text) {
  std::size_t used = 0;
  const double v = std::stod(text, &used);
  if (used != text.size()) throw std::invalid_argument(text);
  return v;
}

}  // namespace

std::vector<double> parse_values(const std::string& text, const std::string& option) {
  std::vector<double> values;
  try {
    const auto colon = std::count(text.begin(), text.end(), ':');
    if (colon == 2) {  // start:stop:count
      const auto a = text.find(':'), b = text.rfind(':');
      const double start = whole_number(text.substr(0, a)), stop = whole_number(text.substr(a + 1, b - a - 1));
      const double count_value = whole_number(text.substr(b + 1));
      if (!(count_value >= 1 && count_value <= 100000) || count_value != std::floor(count_value))
        throw std::invalid_argument("count");
      const int count = int(count_value);
      for (int k = 0; k < count; ++k) values.push_back(count == 1 ? start : start + (stop - start) * k / (count - 1));
    } else {
      std::stringstream in(text);
      std::string item;
      while (std::getline(in, item, ',')) {
        values.push_back(whole_number(item));
      }
    }
  } catch (const std::exception&) {
    throw std::invalid_argument(option + ": expected a list a,b,c or start:stop:count, got \"" + text + "\"");
  }
  for (double v : values)
    if (!std::isfinite(v) || std::abs(v) > 1e100)
      throw std::invalid_argument(option + ": values must be finite and at most 1e100 in size");
  if (values.empty()) throw std::invalid_argument(option + ": no values");
  return values;
}

namespace {

/// What a sweep varies, and how much of the solver's work each member can reuse.
struct Family {
  std::string kind;  // g_scale, rotate, move or parameter
  std::string name;  // the CSV's first column: the kind, or the parameter's name
  std::vector<double> values;
  bool moves_curve = false;   // new trace rows and Schur blocks per member
  bool changes_load = false;  // a new u₀ per member
};

template <int dim>
Family family_of(const SweepArguments& args, const BasicProblemSpec<dim>& base) {
  const int kinds = !args.g_scale.empty() + !args.rotate.empty() + !args.move.empty() + !args.parameter.empty();
  if (kinds != 1) throw std::invalid_argument("sweep: give exactly one of --g-scale, --rotate, --move, --parameter");
  Family f;
  if (!args.g_scale.empty()) f = {"g_scale", "g_scale", parse_values(args.g_scale, "--g-scale"), false, false};
  if (!args.rotate.empty()) {
    f = {"rotate", "rotate", parse_values(args.rotate, "--rotate"), true, false};
    for (double v : f.values)
      if (std::abs(v) > 1e4)
        throw std::invalid_argument("--rotate: angles are in radians; |angle| <= 1e4 (cos and sin lose digits beyond)");
  }
  if (!args.move.empty()) f = {"move", "move", parse_values(args.move, "--move"), true, false};
  if (!args.parameter.empty()) {
    const std::size_t equals = args.parameter.find('=');
    if (equals == std::string::npos || equals == 0)
      throw std::invalid_argument("--parameter: expected NAME=LIST, e.g. a=0.1,0.2 or a=0:1:11, got \"" +
                                  args.parameter.substr(0, 60) + "\"");
    f.kind = "parameter";
    f.name = args.parameter.substr(0, equals);
    f.values = parse_values(args.parameter.substr(equals + 1), "--parameter");
    if (args.problem_path.empty())
      throw std::invalid_argument("--parameter: needs a problem file with a [parameters] section");
    if (!base.parameters.count(f.name)) {
      std::string known;
      for (const auto& [n, v] : base.parameters) known += (known.empty() ? "" : ", ") + n;
      throw std::invalid_argument("--parameter: " + f.name.substr(0, 40) +
                                  " is not in the problem file's [parameters] (" +
                                  (known.empty() ? "it has none" : known) + ")");
    }
    for (const char* column :
         {"converged", "newton_steps", "multipliers", "contact_points", "contact_measure", "contact_force",
          "lambda_integral", "min_gap", "max_gap", "min_normal_derivative", "max_complementarity", "seconds"})
      if (f.name == column)
        throw std::invalid_argument("--parameter: a parameter named " + f.name +
                                    " would clash with that column of sweep.csv; rename it in [parameters]");
    const auto uses = base.parameter_uses.find(f.name);
    if (uses == base.parameter_uses.end())
      throw std::invalid_argument("--parameter: no expression of the problem file uses " + f.name);
    for (const std::string& key : uses->second) {
      f.moves_curve |= key.rfind("geometry.", 0) == 0;
      f.changes_load |= key == "data.f";
    }
  }
  return f;
}

/// The axis of a 3-D rotation: x, y or z.
int axis_of(const std::string& axis) {
  if (axis.empty()) return 2;  // z
  if (axis == "x" || axis == "y" || axis == "z") return axis[0] - 'x';
  throw std::invalid_argument("--axis: expected x, y or z, got \"" + axis.substr(0, 40) + "\"");
}

/// Member k of the family: the base problem changed by one value.
template <int dim>
BasicProblem<dim> member(const Family& family, const BasicProblemSpec<dim>& base, const SweepArguments& args,
                         const std::string& text, const OptionFlags& flags, double v) {
  BasicProblem<dim> problem = base.problem;
  if (family.kind == "g_scale") {
    problem.g_vectorized = nullptr;  // the batch form of the file's g would be used instead of the scaled g
    if constexpr (dim == 2) {
      if (problem.g) problem.g = [g = base.problem.g, v](double x, double y) { return v * g(x, y); };
      if (problem.g_along_curve)
        problem.g_along_curve = [g = base.problem.g_along_curve, v](double x, double y, double s) {
          return v * g(x, y, s);
        };
    } else {
      problem.g = [g = base.problem.g, v](double x, double y, double z) { return v * g(x, y, z); };
    }
  } else if (family.kind == "rotate" || family.kind == "move") {
    const double angle = family.kind == "rotate" ? v : 0.0, shift = family.kind == "move" ? v : 0.0;
    if constexpr (dim == 2) {
      problem.gamma = std::make_shared<TransformedCurve>(base.problem.gamma, angle, Point2{shift, 0});
      if (base.g_about) problem.g_along_curve = base.g_about(problem.gamma->center());  // phi about the moved center
    } else {
      problem.gamma =
          std::make_shared<TransformedSurface>(base.problem.gamma, axis_of(args.axis), angle, Point3{shift, 0, 0});
    }
  } else {
    // The base boundary unless the parameter is in the geometry: the same rows and Schur blocks, and
    // the geometry is not read and checked again.
    std::shared_ptr<const typename BoundaryShape<dim>::type> keep;
    if (!family.moves_curve) keep = base.problem.gamma;
    problem = problem_from_text<dim>(text, args.problem_path, flags, {{family.name, v}}, keep).problem;
  }
  if (family.kind != "parameter")  // the exact solution is the base problem's
    problem.exact = nullptr, problem.exact_vectorized = nullptr;
  return problem;
}

const char* const columns =
    "converged,newton_steps,multipliers,contact_points,contact_measure,contact_force,lambda_integral,min_gap,max_gap,"
    "min_normal_derivative,max_complementarity,reused_boundary,seconds";

/// One member's line of sweep.csv and its row of sweep.json.
template <int dim>
void record(const Family& family, double v, const BasicSolution<dim>& s, double seconds, std::ostringstream& csv,
            nlohmann::json& rows) {
  const ContactSummary c = contact_summary(s);
  std::printf("%-12.6g %5d %7ld %11.4e %11.4e %11.3e %11.3e %9.4f%s\n", v, s.newton.iterations, c.points, c.measure,
              c.force, c.min_gap, c.max_gap, seconds, s.newton.converged ? "" : "  NOT converged");
  csv << v << ',' << s.newton.converged << ',' << s.newton.iterations << ',' << s.n_points() << ',' << c.points << ','
      << c.measure << ',' << c.force << ',' << c.lambda << ',' << c.min_gap << ',' << c.max_gap << ','
      << s.signorini.min_normal_derivative << ',' << s.signorini.max_complementarity << ',' << int(s.reused_curve)
      << ',' << seconds << '\n';
  rows.push_back({{family.name, v},
                  {"converged", s.newton.converged},
                  {"newton_steps", s.newton.iterations},
                  {"multipliers", s.n_points()},
                  {"contact_points", c.points},
                  {"contact_measure", c.measure},
                  {"contact_force", c.force},
                  {"lambda_integral", c.lambda},
                  {"min_gap", c.min_gap},
                  {"max_gap", c.max_gap},
                  {"min_normal_derivative", s.signorini.min_normal_derivative},
                  {"max_complementarity", s.signorini.max_complementarity},
                  {"reused_boundary", s.reused_curve},
                  {"seconds", seconds}});
}

/// The first member that did not converge, as the failure's one line (exit code 2).
[[noreturn]] void fail_sweep(const Family& family, double value, std::string line, int failures) {
  std::ostringstream at;  // after the key of the failure: "solver.max_newton: at rotate = 0 (…): …"
  at.precision(12);
  at << "at " << family.name << " = " << value << " (" << failures << " of " << family.values.size()
     << " did not converge; converged = 0 in sweep.csv): ";
  const std::size_t key_end = line.find(": ");
  line.insert(key_end == std::string::npos ? 0 : key_end + 2, at.str());
  throw NewtonFailure(line);
}

template <int dim>
int run_sweep_in(const std::string& text, const SweepArguments& args, const OptionFlags& flags) {
  if (dim == 2 && !args.axis.empty())
    throw std::invalid_argument("--axis: applies to 3-D sweeps only (this one is 2-D)");
  if (!args.axis.empty() && args.rotate.empty())
    throw std::invalid_argument("--axis: the axis of --rotate; give --rotate");
  axis_of(args.axis);  // a bad axis before any work
  const BasicProblemSpec<dim> base = problem_from_text<dim>(text, args.problem_path, flags);
  const Family family = family_of(args, base);
  if (flags.given("condition_number") && base.options.condition_number)
    throw std::invalid_argument("solver.condition_number: not computed in a sweep (solve one problem for cond(S))");
  if (flags.given("error_estimate") && base.options.error_estimate)
    throw std::invalid_argument("solver.error_estimate: not computed in a sweep (solve one member for its estimate)");
  for (const std::string& w : base.warnings) std::fprintf(stderr, "fictus: warning: %s\n", w.c_str());
  // Under mpirun on several ranks every member is solved on the ranks' slabs; rank 0 checks and writes.
  const Distribution& distribution = *process_distribution();
  if (!args.out.empty()) on_rank_0(distribution, [&] { check_output_folder(args.out, {"sweep.csv", "sweep.json"}); });
  SolverOptions options = base.options;
  agree_on_threads(distribution, options);
  options.condition_number = false;  // not a column of the sweep
  options.error_estimate = false;    // nor is the estimate: a member's N/2 solve would not reuse the blocks
  on_rank_0(distribution, [&] { check_memory(base.problem, options); });
  const auto setup_start = std::chrono::steady_clock::now();
  FictitiousDomainSolver<dim> solver(base.problem, options);
  // The base problem first: its own errors (a smooth variant on a polygon, Γ leaving the box) are
  // not a member's. For an obstacle family its rows and blocks serve every member.
  const BasicSolution<dim> first = solver.solve(base.problem, options, false);
  for (const std::string& w : first.warnings) std::fprintf(stderr, "fictus: warning: %s\n", w.c_str());
  const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
  std::ostringstream csv;
  csv.precision(12);
  csv << family.name << ',' << columns << '\n';
  nlohmann::json rows = nlohmann::json::array();
  std::printf("%-12s %5s %7s %11s %11s %11s %11s %9s\n", family.name.substr(0, 12).c_str(), "it0", "contact", "measure",
              "force", "min gap", "max gap", "time[s]");
  double total = 0;
  int failures = 0;
  // A member's warnings that the base problem did not give: each text once, the first few on stderr
  // (with the member), every member's own in its row of sweep.json.
  std::set<std::string> said(first.warnings.begin(), first.warnings.end());
  said.insert(base.warnings.begin(), base.warnings.end());
  constexpr int warnings_shown = 5;
  int warnings_new = 0;
  std::optional<std::pair<double, std::string>> first_failure;
  for (const double v : family.values) {
    const auto start = std::chrono::steady_clock::now();
    BasicSolution<dim> s(solver.grid());
    try {
      const BasicProblem<dim> problem = member(family, base, args, text, flags, v);
      if (family.changes_load) solver.replace_load(problem);
      s = solver.solve(problem, options);  // with the field, for the force c∫û − ∫f
    } catch (const std::invalid_argument& e) {
      std::ostringstream at;
      at.precision(12);
      at << " (at " << family.name << " = " << v << ")";
      throw std::invalid_argument(e.what() + at.str());
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    total += seconds;
    failures += !s.newton.converged;
    if (!s.newton.converged && !first_failure) first_failure = std::pair{v, describe_newton_failure(s)};
    record(family, v, s, seconds, csv, rows);
    rows.back()["warnings"] = s.warnings;
    for (const std::string& w : s.warnings)
      if (said.insert(w).second && ++warnings_new <= warnings_shown) {
        std::ostringstream at;
        at.precision(12);
        at << " (at " << family.name << " = " << v << ")";
        std::fprintf(stderr, "fictus: warning: %s%s\n", w.c_str(), at.str().c_str());
      }
  }
  if (warnings_new > warnings_shown)
    std::fprintf(stderr, "fictus: warning: %d more members' warnings%s\n", warnings_new - warnings_shown,
                 args.out.empty() ? " not shown" : ": sweep.json's rows hold them");
  std::printf("grid setup and the base problem %.3f s; then %.4f s per problem (%s%s), %.1f problems per second\n",
              setup, total / family.values.size(),
              family.changes_load  ? "new u0 and Newton"
              : family.moves_curve ? "new boundary rows, Schur blocks and Newton"
                                   : "Newton only",
              first.options.fit_contact > 0 ? "; then the contact fit's rows, blocks and Newton" : "",
              family.values.size() / total);
  if (!args.out.empty()) {
    nlohmann::json j{{"version", FICTUS_VERSION},
                     {"commit", FICTUS_GIT_COMMIT},
                     {"dim", dim},
                     {"problem", nlohmann::json::parse(base.input_json)},
                     {"options", options_to_json(base.problem, options)},
                     {"sweep", {{"kind", family.kind}, {"name", family.name}, {"values", family.values}}},
                     {"rows", rows}};
    if (family.kind == "rotate" && dim == 3) j["sweep"]["axis"] = std::string(1, char('x' + axis_of(args.axis)));
    j["problem"]["name"] = base.problem.name;
    on_rank_0(distribution, [&] {
      write_output_set(args.out,
                       {{"sweep.csv", [&](std::ostream& out) { out << csv.str(); }},
                        {"sweep.json", [&](std::ostream& out) { out << j.dump(2) << '\n'; }}},
                       [earlier = written_by_fictus(std::filesystem::path(args.out) / "sweep.json", "rows")](
                           const std::string& name) { return earlier && name == "sweep.png"; });  // its plot
      std::printf("wrote sweep.csv and sweep.json to %s/\n", args.out.c_str());
    });
  }
  if (first_failure) fail_sweep(family, first_failure->first, first_failure->second, failures);
  return 0;
}

}  // namespace

int run_sweep(const SweepArguments& args, const OptionFlags& flags) {
  const std::string text = args.problem_path.empty() ? "" : read_problem_text(args.problem_path);
  if (!text.empty() && problem_dimension(text, args.problem_path) == 3) return run_sweep_in<3>(text, args, flags);
  return run_sweep_in<2>(text, args, flags);
}

}  // namespace fictus::cli
