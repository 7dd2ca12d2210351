#pragma once
// Traces of a grid function that is kinked on γ (the non-smooth variant, docs/math.md).
//
// With multipliers on γ itself, û has a jump λ in its normal derivative across γ. Near γ write
//   û = w − Σ_j λ_j ψ_j,   ψ_j = q(d)⁺ on the part of a band around γ that projects onto arc j,
// with d the signed distance to γ (> 0 outside ω), q(d) = d − κd²/2 and w smooth across γ. The
// inside traces of û are those of w, which a centered stencil reproduces. Two corrections relate
// the Q1 nodal values û_h to I_h w:
//   I_h w ≈ û_h + Σ_j λ_j (I_hψ_j + A⁻¹ r_j),   r_j,k = a(ψ_j − I_hψ_j, φ_k),
// the second one being the Galerkin response to the kink that Q1 cannot resolve in the cut cells.
// So a trace row R of I_h w is  R û_h + (R A⁻¹ Σ_j λ_j r_j) + D λ  with D_ij = Σ_k R_ik ψ_j(x_k):
// the rows r_j are added to those of B_Γ in the Schur complement, and D is added to its blocks.
#include "fictus/collocation.hpp"
#include "fictus/curve_grid_intersection.hpp"
#include "fictus/schur_complement.hpp"
#include "fictus/trace_operators.hpp"

namespace fictus {

struct KinkCorrection {
  SparseRows galerkin;     // r_j over the grid nodes, one row per arc (m rows)
  DirectTerms direct;      // D for B_γ and for C_γ (m × m each)
};

/// Builds the corrections for the arcs of `arcs` on the curve of `gamma`, for trace rows B_γ and
/// C_γ built on the same grid. c is the coefficient of A = K + cM.
KinkCorrection kink_correction(const CurveGridIntersection& gamma, const Collocation& arcs, const SparseRows& B_gamma,
                               const SparseRows& C_gamma, double c, int threads = 1);

/// Row-wise sum a + b of two sets of rows with the same number of rows (entries of a node merged).
SparseRows add_rows(const SparseRows& a, const SparseRows& b);

}  // namespace fictus
