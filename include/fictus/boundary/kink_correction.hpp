#pragma once
// Traces of a grid function that is kinked on γ (the non-smooth variant, docs/math.md).
//
// With multipliers on γ itself, û has a jump λ in its normal derivative across γ. Near γ write
//   û = w − Σ_j λ_j ψ_j,   ψ_j = q(d)⁺ on the part of a band around γ that projects onto arc j,
// with d the signed distance to γ (> 0 outside ω), q(d) = d − κd²/2 + κ²d³/3 and w smooth across γ. The
// inside traces of û are those of w, which a centered stencil reproduces. Two corrections relate
// the Q1 nodal values û_h to I_h w:
//   I_h w ≈ û_h + Σ_j λ_j (I_hψ_j + A⁻¹ r_j),   r_j,k = a(ψ_j − I_hψ_j, φ_k),
// the second one being the Galerkin response to the kink that Q1 cannot resolve in the cut cells.
// So a trace row R of I_h w is  R û_h + (R A⁻¹ Σ_j λ_j r_j) + D λ  with D_ij = Σ_k R_ik ψ_j(x_k):
// the rows r_j are added to those of B_Γ in the Schur complement, and D is added to its blocks.
#include <memory>
#include <optional>

#include <Eigen/Sparse>

#include "fictus/boundary/collocation.hpp"
#include "fictus/boundary/curve_grid_intersection.hpp"
#include "fictus/boundary/trace_operators.hpp"
#include "fictus/grid/execution.hpp"

namespace fictus {

class KinkCorrection {
 public:
  /// The kink model for the arcs of `arcs` on the curve of `gamma`; computes r_j for A = K + cM.
  KinkCorrection(const CurveGridIntersection& gamma, const Collocation& arcs, double c,
                 const Execution& execution = Execution{});
  ~KinkCorrection();
  KinkCorrection(KinkCorrection&&) noexcept;
  KinkCorrection& operator=(KinkCorrection&&) noexcept;

  /// r_j over the grid nodes, one row per arc (m rows): added to B_Γ in the Schur complement.
  const SparseRows& galerkin() const;
  /// D (m × m) for trace rows R built on the same grid, one row per collocation point:
  /// D_ij = Σ_k R_ik ψ_j(x_k). Not thread-safe (caches the nodes it meets).
  Eigen::SparseMatrix<double> direct(const SparseRows& rows) const;
  /// u += Σ_j λ_j ψ_j at the nodes within two cells of the cut cells (the band where the kink
  /// model holds): turns u₀ + A⁻¹(B_Γ + R)ᵀλ into the kink-corrected field I_h w. With `slab`, u holds
  /// that slab's layers (a rank's) and only their nodes change.
  void add_kinks(const std::vector<double>& lambda, GridVector& u, std::optional<Slab> slab = std::nullopt) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace fictus
