#include "fictus/solve/semismooth_newton.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace fictus {

namespace {

/// Step 0: every point active, or the sign test at λ = 0, or the given active set or result.
ActiveSet starting_active_set(const Eigen::VectorXd& b0, const Eigen::VectorXd& c0, const Eigen::VectorXd& g,
                              const NewtonOptions& options, NewtonResult& result) {
  const int m = int(b0.size());
  ActiveSet active(m, 1);
  if (!options.start_all_active)
    for (int i = 0; i < m; ++i) active[i] = (c0(i) - options.rho * (b0(i) - g(i))) > 0;
  if (options.start_active) {
    if (Eigen::Index(options.start_active->size()) != m)
      throw std::invalid_argument("solve_semismooth_newton: the start's active set is of another size");
    active = *options.start_active;
  }
  if (options.start) {
    if (options.start->lambda.size() != m || Eigen::Index(options.start->active.size()) != m)
      throw std::invalid_argument("solve_semismooth_newton: the start is of another size");
    active = options.start->active;
    result.lambda = options.start->lambda;
    result.alpha = options.start->alpha;
  }
  if (const PointConditions* fixed = options.conditions) {
    if (Eigen::Index(fixed->kind.size()) != m || fixed->flux.size() != m)
      throw std::invalid_argument("solve_semismooth_newton: the conditions are of another size");
    for (int i = 0; i < m; ++i)
      if (fixed->fixed(i)) active[std::size_t(i)] = fixed->row(i);
  }
  return active;
}

/// Step 2: the traces b = B_γu, c = C_γu at the new λ (stored in `result`), the shifted readings
/// c − ρ(b − g), the residual ‖F‖∞ of F = c − max(0, c − ρ(b − g)) (at fixed points ρ(b − g) or c − q)
/// and the scale it is judged against.
Eigen::VectorXd residual(const SchurComplement& schur, const Eigen::VectorXd& b0, const Eigen::VectorXd& c0,
                         const Eigen::VectorXd& g, double rho, const ConstantMode* mode, const PointConditions* fixed,
                         NewtonResult& result, double& scale) {
  Eigen::VectorXd sb, sc;
  schur.apply(result.lambda, sb, sc);
  Eigen::VectorXd b = b0 + sb, c = c0 + sc;
  if (mode) {
    b += result.alpha * mode->trace_B;
    c += result.alpha * mode->trace_C;
  }
  result.trace = b;
  result.normal_derivative = c;
  Eigen::VectorXd shifted = c - rho * (b - g);
  Eigen::VectorXd F = c - shifted.cwiseMax(0.0);
  double flux = 0;
  if (fixed) {
    for (Eigen::Index i = 0; i < F.size(); ++i)
      if (fixed->fixed(int(i))) F(i) = fixed->row(int(i)) ? rho * (b(i) - g(i)) : c(i) - fixed->flux(i);
    flux = fixed->flux.lpNorm<Eigen::Infinity>();
  }
  result.residual = F.lpNorm<Eigen::Infinity>();
  scale =
      std::max({b.lpNorm<Eigen::Infinity>(), c.lpNorm<Eigen::Infinity>(), g.lpNorm<Eigen::Infinity>(), flux, 1e-300});
  return shifted;
}

}  // namespace

NewtonResult solve_semismooth_newton(const SchurComplement& schur, const Eigen::VectorXd& b0, const Eigen::VectorXd& c0,
                                     const Eigen::VectorXd& g, const NewtonOptions& options, const ConstantMode* mode) {
  if (!(options.rho > 0)) throw std::invalid_argument("formulation.rho: must be > 0");
  if (options.max_iterations < 1) throw std::invalid_argument("solver.max_newton: must be >= 1");
  const int m = schur.size();
  const double rho = options.rho;
  NewtonResult result;
  result.lambda = Eigen::VectorXd::Zero(m);

  ActiveSet active = starting_active_set(b0, c0, g, options, result);  // 0. Start.
  std::vector<ActiveSet> seen{active};

  const PointConditions* fixed = options.conditions;
  Eigen::VectorXd d(m);
  for (int k = 0; k < options.max_iterations; ++k) {
    if (options.between_steps) options.between_steps();
    // 1. Linear solve for the current active set.
    for (int i = 0; i < m; ++i) d(i) = active[i] ? g(i) - b0(i) : (fixed ? fixed->flux(i) : 0.0) - c0(i);
    const LinearSolveReport linear = schur.solve(active, d, mode, result.lambda, result.alpha);
    ++result.iterations;

    // 2. Residual at the new λ.
    double scale = 0;
    const Eigen::VectorXd shifted = residual(schur, b0, c0, g, rho, mode, fixed, result, scale);

    // 3. New active set.
    ActiveSet next(m);
    int changed = 0;
    for (int i = 0; i < m; ++i) {
      next[i] = fixed && fixed->fixed(i) ? fixed->row(i) : shifted(i) > 0;
      changed += next[i] != active[i];
    }
    result.history.push_back(
        {int(std::count(active.begin(), active.end(), 1)), linear.inner_iterations, result.residual, changed});
    result.inner_failed = result.inner_failed || !linear.converged;

    // 4. Stopping test.
    if (changed <= options.hand_on_at_changes) {
      result.active = next;
      result.handed_on = true;
      return result;
    }
    if (changed == 0) {
      result.active = active;
      if (result.residual <= options.tolerance * scale) {
        result.converged = true;
      } else {
        char residual[32];
        std::snprintf(residual, sizeof residual, "%.3e", result.residual);
        result.stalled = true;
        result.failure = std::string("the active set repeats but the residual ") + residual +
                         " is above the tolerance (inner solver " +
                         (linear.converged ? "converged" : "did not converge") + ")";
      }
      return result;
    }
    if (std::find(seen.begin(), seen.end(), next) != seen.end()) {
      result.active = next;
      result.failure = "the active sets cycle (step " + std::to_string(k + 1) + " returns to an earlier set)";
      return result;
    }
    seen.push_back(next);
    active = std::move(next);
  }
  result.active = active;
  result.failure = "no convergence in " + std::to_string(options.max_iterations) + " Newton steps";
  return result;
}

}  // namespace fictus
