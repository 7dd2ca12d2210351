#pragma once
// The paper's table layout (h, n/m, it₀/it₁, time, errors in L²(ω), H¹(ω), L²(γ), rates), shared
// by `fictus reproduce` and the convergence tests. Formatting only: returns text.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "fictus/solve/paper_problem.hpp"

namespace fictus {

struct LevelResult {
  int N = 0;
  std::size_t n_nodes = 0;
  int m = 0;
  int it0 = 0;
  std::size_t it1 = 0;
  double time = 0;
  double l2_omega = 0, h1_omega = 0, l2_gamma = 0;  // relative errors
};

/// log₂(e_k/e_{k+1}) between successive levels (N doubling), for L²(ω), H¹(ω), L²(γ).
std::vector<std::array<double, 3>> observed_rates(const std::vector<LevelResult>& rows);
/// Least-squares slope of log e against log h over all levels.
std::array<double, 3> fitted_rates(const std::vector<LevelResult>& rows);

/// The paper's rates over the levels of `rows`: its printed rates when the rows cover all six of its
/// levels, else the least-squares slope of its figures at the levels shown (nothing when fewer than
/// two of them are the paper's).
std::optional<std::array<double, 3>> paper_rates_over(Variant variant, const std::vector<LevelResult>& rows);

/// Our rows, with the paper's figures for the same h beside them where it has them.
std::string format_convergence_table(const std::string& title, const std::vector<LevelResult>& rows,
                                     std::optional<Variant> paper_variant);

}  // namespace fictus
