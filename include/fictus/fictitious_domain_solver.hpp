#pragma once
// The whole method on one problem: curves and collocation → trace rows → load → u₀ = A⁻¹f →
// Schur complement (implicit or from the Green's table) → semismooth Newton on λ →
// û = A⁻¹(f + B_Γᵀλ) → Signorini checks and errors.
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "fictus/collocation.hpp"
#include "fictus/error_norms.hpp"
#include "fictus/problem.hpp"
#include "fictus/semismooth_newton.hpp"

namespace fictus {

struct SignoriniCheck {
  double min_gap = 0;                // min_i (B_γ û − g)_i        (≥ −tol)
  double min_normal_derivative = 0;  // min_i (C_γ û)_i             (≥ −tol)
  double max_complementarity = 0;    // max_i |(C_γ û)_i (B_γ û − g)_i|
};

struct Timings {
  std::vector<std::pair<std::string, double>> phases;  // seconds, in execution order
  double total = 0;
  double operator[](const std::string& name) const;
};

struct Solution {
  explicit Solution(const Grid& g) : grid(g) {}
  Grid grid;
  SolverOptions options;                // in effect (m and δ resolved)
  GridVector u;                         // û at the interior nodes
  Collocation collocation;              // points on γ
  std::shared_ptr<const Curve> Gamma;   // the curve carrying λ (γ itself in the non-smooth variant)
  double delta = 0;                     // distance of Γ from γ
  std::vector<double> lambda, g, trace, normal_derivative;  // per point: λ, g, B_γû, C_γû
  NewtonResult newton;
  std::size_t fast_solves = 0;          // applications of A⁻¹ (the paper's it₁)
  int inner_iterations = 0;             // Krylov iterations over all Newton steps
  std::optional<double> condition_number;
  SignoriniCheck signorini;
  std::optional<ErrorNorms> errors;
  Timings timings;
  std::size_t peak_memory_bytes = 0;    // of the process so far (VmHWM)
};

/// Throws std::invalid_argument with a message naming the offending field on bad input.
Solution solve(const Problem& problem, SolverOptions options);

/// Peak resident memory of this process in bytes (0 where unknown).
std::size_t peak_memory_bytes();

}  // namespace fictus
