#include "fictus/grid/quadrature.hpp"

#include <array>
#include <cmath>
#include <mutex>
#include <numbers>
#include <stdexcept>

namespace fictus {

namespace {
GaussRule compute_rule(int n) {
  // Newton's method on the Legendre polynomial P_n, from the Chebyshev-like initial guesses.
  GaussRule rule;
  rule.nodes.resize(n);
  rule.weights.resize(n);
  for (int k = 0; k < n; ++k) {
    double x = std::cos(std::numbers::pi * (k + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int j = 2; j <= n; ++j) {
        const double p2 = ((2.0 * j - 1.0) * x * p1 - (j - 1.0) * p0) / j;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) p0 = 1.0, p1 = x;
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    // node on [0,1], increasing order
    rule.nodes[n - 1 - k] = 0.5 * (1.0 + x);
    rule.weights[n - 1 - k] = 1.0 / ((1.0 - x * x) * dp * dp);  // (2/((1−x²)P'²)) / 2
  }
  return rule;
}
}  // namespace

const GaussRule& gauss_legendre(int n) {
  if (n < 1 || n > 64) throw std::invalid_argument("gauss_legendre: need 1 <= n <= 64");
  static std::array<GaussRule, 65> cache;
  static std::array<std::once_flag, 65> flags;
  std::call_once(flags[n], [n] { cache[n] = compute_rule(n); });
  return cache[n];
}

}  // namespace fictus
