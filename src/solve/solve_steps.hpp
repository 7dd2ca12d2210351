#pragma once
// What the steps of a solve share (fictitious_domain_solver.cpp and the boundaries' files): the phase
// clock, the Newton and GMRES settings from the options, and the Signorini checks at the points.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "fictus/boundary/trace_operators.hpp"
#include "fictus/grid/execution.hpp"
#include "fictus/solve/gmres.hpp"
#include "fictus/solve/semismooth_newton.hpp"
#include "fictus/solve/solution.hpp"
#include "fictus/solve/solver_options.hpp"

namespace fictus::detail {

/// The largest |u₀|, |g|, |λ| a solve accepts: the Newton residuals, the LU and the norms square
/// these values, which must stay far from the overflow at 1.8e308.
inline constexpr double largest_scale = 1e100;

/// "(x, y)" or "(x, y, z)", 6 digits each: a point in a message.
template <int dim>
std::string format_point(const Point<dim>& p) {
  std::string text = "(";
  for (int d = 0; d < dim; ++d) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.6g", p[d]);
    text += (d ? ", " : "") + std::string(buffer);
  }
  return text + ")";
}

/// Throws naming data.g where the obstacle at a boundary point is not finite or beyond largest_scale.
template <int dim>
void check_obstacle(const std::vector<double>& g, const std::vector<Point<dim>>& points) {
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (!std::isfinite(g[i])) throw std::invalid_argument("data.g: not finite at the point " + format_point(points[i]));
    if (std::abs(g[i]) > largest_scale) {
      char buffer[64];
      std::snprintf(buffer, sizeof buffer, "%.3g is beyond %.0e", g[i], largest_scale);
      throw std::invalid_argument("data.g: " + std::string(buffer) + " at " + format_point(points[i]) +
                                  ": rescale the problem (u, f and g by one factor)");
    }
  }
}

/// The largest |B_γû − u| and |C_γû − ∂u/∂n| over the points, from the exact u and ∂u/∂n there; throws
/// naming data.exact where either is not finite.
template <int dim>
PointErrors point_errors_at(const std::vector<Point<dim>>& points, const std::vector<double>& trace,
                            const std::vector<double>& normal_derivative, const std::vector<double>& u,
                            const std::vector<double>& dudn) {
  PointErrors pe;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!std::isfinite(u[i])) throw std::invalid_argument("data.exact: not finite at " + format_point(points[i]));
    if (!std::isfinite(dudn[i]))
      throw std::invalid_argument("data.exact: its normal derivative is not finite near " + format_point(points[i]));
    pe.max_trace = std::max(pe.max_trace, std::abs(trace[i] - u[i]));
    pe.max_normal_derivative = std::max(pe.max_normal_derivative, std::abs(normal_derivative[i] - dudn[i]));
  }
  return pe;
}

/// Records each step's seconds into `timings` as it ends, and reports it (the progress lines).
class PhaseClock {
 public:
  PhaseClock(Timings& timings, const Execution& execution)
      : timings_(timings), execution_(execution), start_(now()), last_(start_) {}
  void mark(const std::string& phase) {
    const auto t = now();
    timings_.phases.emplace_back(phase, seconds(last_, t));
    timings_.total = seconds(start_, t);
    last_ = t;
    execution_.report(phase, timings_.phases.back().second);
  }

 private:
  using Clock = std::chrono::steady_clock;
  static Clock::time_point now() { return Clock::now(); }
  static double seconds(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  }
  Timings& timings_;
  const Execution& execution_;
  Clock::time_point start_, last_;
};

inline Eigen::VectorXd to_eigen(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), Eigen::Index(v.size()));
}

/// R·1: the sum of each row's entries.
inline Eigen::VectorXd row_sums(const SparseRows& rows) { return to_eigen(rows.row_sums()); }

inline NewtonOptions newton_options(const SolverOptions& options, const Execution& execution) {
  NewtonOptions n;
  n.between_steps = [&execution] { execution.throw_if_interrupted(); };
  n.rho = options.rho;
  n.max_iterations = options.max_newton;
  n.start_all_active = options.start_all_active;
  n.tolerance = options.newton_tolerance;
  return n;
}

/// GMRES for the implicit Schur complement of m points (restart m + 1: no restart in practice).
inline GmresOptions gmres_options(const SolverOptions& options, int m, const Execution& execution) {
  GmresOptions g;
  g.relative_tolerance = options.krylov_tolerance;
  g.max_iterations = options.krylov_max_iterations;
  g.restart = m + 1;
  g.between_iterations = [&execution] { execution.throw_if_interrupted(); };
  return g;
}

/// The discrete Signorini conditions at the points: gap = B_γû − g ≥ 0, C_γû ≥ 0, their product 0.
/// (at the Signorini points: `kind` empty, or the points it marks signorini; 0 where there are none).
inline SignoriniCheck signorini_check(const std::vector<double>& trace, const std::vector<double>& normal_derivative,
                                      const std::vector<double>& g, const std::vector<PointCondition>& kind = {}) {
  SignoriniCheck s;
  s.min_gap = s.min_normal_derivative = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (!kind.empty() && kind[i] != PointCondition::signorini) continue;
    const double gap = trace[i] - g[i], dn = normal_derivative[i];
    s.min_gap = std::min(s.min_gap, gap);
    s.min_normal_derivative = std::min(s.min_normal_derivative, dn);
    s.max_complementarity = std::max(s.max_complementarity, std::abs(gap * dn));
  }
  if (!std::isfinite(s.min_gap)) s.min_gap = s.min_normal_derivative = 0;
  return s;
}

}  // namespace fictus::detail
