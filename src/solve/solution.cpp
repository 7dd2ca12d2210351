#include "fictus/solve/solution.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>

namespace fictus {

double Timings::operator[](const std::string& name) const {
  for (const auto& [phase, seconds] : phases)
    if (phase == name) return seconds;
  return 0.0;
}

template <int dim>
ContactSummary contact_summary(const BasicSolution<dim>& s) {
  ContactSummary c;
  c.min_gap = std::numeric_limits<double>::infinity();
  c.max_gap = -c.min_gap;
  const std::vector<double>& part = s.weights();
  for (int i = 0; i < s.n_points(); ++i) {
    const double gap = s.trace[i] - s.g[i];
    c.min_gap = std::min(c.min_gap, gap);
    c.max_gap = std::max(c.max_gap, gap);
    if (s.newton.active[i] == 1) {
      ++c.points;
      c.force_patches += s.normal_derivative[i] * part[i];
      c.measure += part[i];
    }
  }
  c.force_from_domain = s.domain.has_value();
  c.force = s.domain ? s.domain->flux : c.force_patches;
  c.lambda = s.lambda_total;
  return c;
}

template <int dim>
std::string describe_newton_failure(const BasicSolution<dim>& s) {
  // Blame the setting at fault: a Krylov solve stopped short makes Newton wander, whatever its cap.
  std::string line =
      s.newton.inner_failed
          ? "solver.krylov_max_iterations: GMRES stopped at its cap of " +
                std::to_string(s.options.krylov_max_iterations) +
                " iterations before solver.krylov_tolerance (raise the cap, or use schur = green); then Newton: " +
                s.newton.failure + "; history (active points, residual):"
          : "solver.max_newton: Newton did not converge: " + s.newton.failure + "; history (active points, residual):";
  for (const NewtonStep& step : s.newton.history) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, " (%d, %.2e)", step.n_active, step.residual);
    line += buffer;
  }
  return line;
}

template ContactSummary contact_summary(const BasicSolution<2>&);
template ContactSummary contact_summary(const BasicSolution<3>&);
template std::string describe_newton_failure(const BasicSolution<2>&);
template std::string describe_newton_failure(const BasicSolution<3>&);

}  // namespace fictus
