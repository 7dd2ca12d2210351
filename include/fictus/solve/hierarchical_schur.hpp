#pragma once
// The Schur blocks kept compressed, for large m (docs/math.md, "The compressed Schur complement"): m grows
// like N^(dim−1), so the dense blocks (m² entries, an m³ LU per Newton step) end the method at 3-D
// N ≈ 512, while the blocks couple well-separated points through the box's smooth Green's function.
//   storage   the cluster trees and the interpolated far field of the dense assembly, with a partition
//             for memory: every admissible pair of clusters (radius ≤ eta·distance) is far, kept of low
//             rank by adaptive cross approximation of its interpolated block (far_field_recompression),
//             or dense where its rank is too high to save memory; near pairs dense, their entries made
//             as the dense assembly makes them (most interpolated, the nearest exact)
//             (CompressedBlocks, schur_complement.hpp);
//   solves    GMRES on S̃_𝒜 = rows of S̃_B (𝒜) and S̃_C (the rest), right-preconditioned by the LUs of
//             S̃_𝒜's diagonal blocks over groups of at most `group` nearby points (block Jacobi; a group's
//             LU is made again only where 𝒜 changed in it).
// The solver runs Newton on it and finishes on the exact S (one fast solve per refinement step,
// RefinedSchur, its corrections by GMRES to refinement_correction_tolerance), as with the dense
// interpolated far field: the answer is that of the exact S.
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "fictus/grid/green_table.hpp"
#include "fictus/solve/gmres.hpp"
#include "fictus/solve/schur_complement.hpp"

namespace fictus {

/// The partition of the compressed blocks: admissible pairs with radius ≤ eta·distance, leaves of 16
/// (measured on the sphere at m = 804 and 3217: bench/results/2026-11-27-compressed-schur.md).
inline constexpr FarField hierarchical_far_field{0, 1.0, 16};

/// RefinedSchur's GMRES tolerance for each correction (relative to its residual).
inline constexpr double refinement_correction_tolerance = 1e-4;

/// The GMRES tolerance of the Newton steps on S̃ alone, before the exact S takes over (SettlingSchur).
inline constexpr double settling_tolerance = 1e-6;

/// The relative residual of the Newton steps on the exact S while they may still change the active set
/// (RefinedSchur::set_tolerance); the step that confirms the set is solved to the full tolerance.
inline constexpr double exact_search_tolerance = 1e-8;

struct HierarchicalOptions {
  FarField far_field;                         // how the entries are made: the dense assembly's far field (order > 0)
  FarField storage = hierarchical_far_field;  // the storage's partition (eta, leaf)
  int group = 256;                            // points per preconditioner block at most
};

class HierarchicalSchur final : public SchurComplement {
 public:
  /// Assembles S_B = B_γ G loadsᵀ + D_B and S_C = C_γ G loadsᵀ + D_C from the Green's table (G is not
  /// kept) and the diagonal blocks of the preconditioner. Any dimension.
  template <int dim>
  HierarchicalSchur(const GreenTable<dim>& green, const SparseRows& B_gamma, const SparseRows& C_gamma,
                    const SparseRows& loads, const Execution& execution, const DirectTerms& direct,
                    const HierarchicalOptions& options, const GmresOptions& gmres);
  ~HierarchicalSchur() override;
  HierarchicalSchur(const HierarchicalSchur&) = delete;
  HierarchicalSchur& operator=(const HierarchicalSchur&) = delete;

  int size() const override;
  void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const override;
  /// GMRES to the options' tolerance relative to ‖d‖; no bordering (a singular A takes the dense blocks).
  LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                          Eigen::VectorXd& lambda, double& alpha) const override;
  /// The same to another relative tolerance (a refinement's correction needs no more than S̃'s accuracy).
  LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, Eigen::VectorXd& lambda,
                          double relative_tolerance) const;
  std::size_t fast_solves() const override { return 0; }
  std::optional<double> condition_number(const ActiveSet&, const ConstantMode*) const override { return std::nullopt; }
  const SchurStorage& storage() const;
  /// Block LUs of the preconditioner made so far.
  int factorizations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The exact S with the compressed one for the solves: `apply` is the exact S (one fast solve), `solve`
/// is flexible GMRES on S_𝒜 from the given x, right-preconditioned by S̃_𝒜⁻¹ (each by GMRES to
/// `correction_tolerance`), until ‖rhs − S_𝒜 x‖ ≤ tolerance·‖rhs‖, at most `max_steps` steps. Each step
/// costs one fast solve and gains at least about the factor ‖I − S_𝒜 S̃_𝒜⁻¹‖ + correction_tolerance of
/// the refinement x ← x + S̃_𝒜⁻¹(rhs − S_𝒜 x) (the sphere at N = 512: 9 fast solves instead of 11); a direction solved
/// further than S̃'s own accuracy (the far field's interpolation, 1e-4 … 1e-2) gains nothing. The exact
/// products of the directions are kept, so λ's product, Newton's residual at a solve's answer and the
/// next solve's first residual cost no fast solve.
class RefinedSchur final : public SchurComplement {
 public:
  RefinedSchur(const HierarchicalSchur& approximate, const ImplicitSchur& exact, double tolerance,
               double correction_tolerance = refinement_correction_tolerance, int max_steps = 30)
      : approximate_(approximate),
        exact_(exact),
        tolerance_(tolerance),
        correction_tolerance_(correction_tolerance),
        max_steps_(max_steps) {}
  int size() const override { return exact_.size(); }
  /// The relative residual of the solves from now on (the exact products kept so far stay valid).
  void set_tolerance(double tolerance) { tolerance_ = tolerance; }
  void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const override;
  LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                          Eigen::VectorXd& lambda, double& alpha) const override;
  std::size_t fast_solves() const override { return exact_.fast_solves(); }
  std::optional<double> condition_number(const ActiveSet& active, const ConstantMode* mode) const override {
    return approximate_.condition_number(active, mode);
  }

 private:
  const HierarchicalSchur& approximate_;
  const ImplicitSchur& exact_;
  double tolerance_, correction_tolerance_;
  int max_steps_;
  mutable Eigen::VectorXd last_lambda_, last_sb_, last_sc_;  // the last exact product
};

/// S̃ with each Newton step solved to `tolerance` only: the run on S̃ that seeks the active set before
/// the exact S takes over. Its λ differs from S̃'s exact answer by about `tolerance`, far below S̃'s own
/// error against S (1e-4 … 1e-2), which the exact run's refinement removes anyway.
class SettlingSchur final : public SchurComplement {
 public:
  SettlingSchur(const HierarchicalSchur& approximate, double tolerance)
      : approximate_(approximate), tolerance_(tolerance) {}
  int size() const override { return approximate_.size(); }
  void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const override {
    approximate_.apply(lambda, sb, sc);
  }
  LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                          Eigen::VectorXd& lambda, double& alpha) const override;
  std::size_t fast_solves() const override { return 0; }
  std::optional<double> condition_number(const ActiveSet&, const ConstantMode*) const override { return std::nullopt; }

 private:
  const HierarchicalSchur& approximate_;
  double tolerance_;
};

}  // namespace fictus
