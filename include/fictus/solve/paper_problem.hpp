#pragma once
// The experiment of the paper (Haslinger, Kozubek, Kučera), §3:
//   Ω = (0,1)², ω = {(x−½)²/0.4² + (y−½)²/0.2² < 1}, c = 1,
//   u_ex = ((x−½)⁺)³ + ½((y−½)⁺)³,  f = −Δu_ex + u_ex on Ω,
//   g = u_ex on γ₁ = γ \ γ̄₂,  g = sin(−2φ) on γ₂ = {x < ½, y < ½} (φ: polar angle about (½,½)).
// And the paper's Tables 1 (non-smooth) and 2 (smooth) for comparison.
#include <array>
#include <optional>

#include "fictus/solve/problem.hpp"

namespace fictus {

/// The paper's problem; c and the box conditions may be changed (f = −Δu_ex + c·u_ex follows c),
/// e.g. c = 0 on a periodic box: the singular setting of the paper's reference [1].
Problem paper_problem(int N, double c = 1.0, Boundary boundary = Boundary::dirichlet);

struct PaperRow {
  int N, m, it0, it1;
  double time, l2_omega, h1_omega, l2_gamma;
};

/// Rows for h = 1/128 … 1/4096 of Table 1 (variant nonsmooth) or Table 2 (smooth).
const std::array<PaperRow, 6>& paper_table(Variant variant);
/// The paper's row for this N, if it has one.
std::optional<PaperRow> paper_row(Variant variant, int N);
/// The paper's m for N = 128 … 4096, otherwise its growth extrapolated: m = 34·(N/128)^0.85.
int paper_multipliers(int N);
/// Options for the paper's experiment: the paper's m, and at the paper's grids (h = 1/128 … 1/4096) Γ
/// one spacing outside γ (δ = L/m; the default 2 spacings would put Γ within 2h of ∂Ω at h = 1/128);
/// at other grids the default rule for δ, which fits itself to the room (spacing_rule.hpp).
SolverOptions paper_options(int N, Variant variant);
/// The paper's rates (last row of each table): L²(ω), H¹(ω), L²(γ).
std::array<double, 3> paper_rates(Variant variant);

}  // namespace fictus
