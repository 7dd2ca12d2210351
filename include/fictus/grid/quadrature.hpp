#pragma once
// Gauss–Legendre rules on [0, 1].
#include <vector>

namespace fictus {

struct GaussRule {
  std::vector<double> nodes;    // in (0, 1), increasing
  std::vector<double> weights;  // sum to 1
};

/// n-point Gauss–Legendre rule on [0, 1] (exact for polynomials of degree 2n − 1); 1 ≤ n ≤ 64.
/// Rules are computed once per n and cached.
const GaussRule& gauss_legendre(int n);

}  // namespace fictus
