// `fictus sweep`: a family of problems on one grid, reusing the Green's table, u₀ and (for
// obstacle sweeps) the Schur blocks.
#include "sweep.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/io/process.hpp"
#include "fictus/paper_problem.hpp"
#include "results_io.hpp"

namespace fictus::cli {

std::vector<double> parse_values(const std::string& text, const std::string& option) {
  std::vector<double> values;
  try {
    const auto colon = std::count(text.begin(), text.end(), ':');
    if (colon == 2) {  // start:stop:count
      const auto a = text.find(':'), b = text.rfind(':');
      const double start = std::stod(text.substr(0, a)), stop = std::stod(text.substr(a + 1, b - a - 1));
      const int count = std::stoi(text.substr(b + 1));
      if (count < 1 || count > 100000) throw std::invalid_argument("count");
      for (int k = 0; k < count; ++k) values.push_back(count == 1 ? start : start + (stop - start) * k / (count - 1));
    } else {
      std::stringstream in(text);
      std::string item;
      while (std::getline(in, item, ',')) {
        std::size_t used = 0;
        values.push_back(std::stod(item, &used));
        if (used != item.size()) throw std::invalid_argument(item);
      }
    }
  } catch (const std::exception&) {
    throw std::invalid_argument(option + ": expected a list a,b,c or start:stop:count, got \"" + text + "\"");
  }
  for (double v : values)
    if (!std::isfinite(v)) throw std::invalid_argument(option + ": values must be finite");
  if (values.empty()) throw std::invalid_argument(option + ": no values");
  return values;
}

int run_sweep(const SweepArguments& args, const Problem& domain, SolverOptions options) {
  const int kinds = !args.g_scale.empty() + !args.rotate.empty() + !args.move.empty();
  if (kinds != 1) throw std::invalid_argument("sweep: give exactly one of --g-scale, --rotate, --move");
  const std::string parameter = !args.g_scale.empty() ? "g_scale" : !args.rotate.empty() ? "rotate" : "move";
  const std::vector<double> values = parse_values(!args.g_scale.empty()  ? args.g_scale
                                                  : !args.rotate.empty() ? args.rotate
                                                                         : args.move,
                                                  "--" + parameter);

  if (!args.out.empty()) check_output_folder(args.out, {"sweep.csv"});
  const Problem base = paper_problem(domain.N, domain.c, domain.boundary);
  if (options.multipliers == 0) options.multipliers = paper_multipliers(domain.N);
  check_memory(base, options);
  FictitiousDomainSolver solver(base, options);
  std::ostringstream csv;
  csv.precision(12);
  csv << parameter << ",iterations,converged,n_active,min_gap,min_normal_derivative,max_complementarity,seconds\n";
  std::printf("%-10s %5s %8s %12s %12s %10s\n", parameter.c_str(), "it0", "active", "min gap", "min du/dn", "time[s]");
  double first = 0, rest = 0;
  int failures = 0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    Problem problem = base;
    const double v = values[k];
    if (parameter == "g_scale") problem.g = [g = base.g, v](double x, double y) { return v * g(x, y); };
    if (parameter == "rotate") problem.gamma = std::make_shared<TransformedCurve>(base.gamma, v, Point2{0, 0});
    if (parameter == "move") problem.gamma = std::make_shared<TransformedCurve>(base.gamma, 0.0, Point2{v, 0});
    const auto start = std::chrono::steady_clock::now();
    const Solution s = solver.solve(problem, options, false);  // boundary quantities only
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    (k == 0 ? first : rest) += seconds;
    failures += !s.newton.converged;
    const long active = std::count(s.newton.active.begin(), s.newton.active.end(), 1);
    std::printf("%-10.4g %5d %8ld %12.3e %12.3e %10.4f%s\n", v, s.newton.iterations, active, s.signorini.min_gap,
                s.signorini.min_normal_derivative, seconds, s.newton.converged ? "" : "  NOT converged");
    csv << v << ',' << s.newton.iterations << ',' << s.newton.converged << ',' << active << ',' << s.signorini.min_gap
        << ',' << s.signorini.min_normal_derivative << ',' << s.signorini.max_complementarity << ',' << seconds << '\n';
  }
  const std::size_t n_rest = values.size() - 1;
  std::printf("first problem %.3f s (grid setup included); ", first);
  if (n_rest > 0)
    std::printf("then %.4f s per problem, %.1f problems per second\n", rest / n_rest, n_rest / rest);
  else
    std::printf("\n");
  if (!args.out.empty()) {
    write_output_set(args.out, {{"sweep.csv", [&](std::ostream& out) { out << csv.str(); }}});
    std::printf("wrote %s/sweep.csv\n", args.out.c_str());
  }
  if (failures) {
    std::fprintf(stderr, "fictus: error: Newton did not converge for %d of %zu problems\n", failures, values.size());
    return 2;
  }
  return 0;
}

}  // namespace fictus::cli
