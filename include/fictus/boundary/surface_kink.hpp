#pragma once
// 3-D: traces of a grid function that is kinked on a closed surface γ (the non-smooth variant,
// docs/math.md "Three dimensions"), the surface form of kink_correction.hpp.
//
// With multipliers on the patches of γ itself, û has a jump λ_j in its normal derivative across patch
// j. Near γ write
//   û = w − Σ_j λ_j ψ_j,   ψ_j = q(d)⁺ where the nearest point of γ lies on patch j,
// d the signed distance to γ (> 0 outside ω), q(d) = d − H d²/2 + β d³, H = κ₁ + κ₂ the mean curvature
// sum at the nearest point and β = (κ₁² + κ₂² + H²)/6 (so that û + λψ has continuous normal
// derivatives up to the third across γ inside a patch, but for a c·λ term), w smooth across γ. The Q1
// Galerkin solution û_h is related to I_h w by
//   I_h w ≈ û_h + Σ_j λ_j (I_hψ_j + A⁻¹ r_j),   r_j,k = a(ψ_j − I_hψ_j, φ_k)   (on the cut voxels
//   and two rings of voxels around them),
// so a trace row R of I_h w is R û_h + R A⁻¹ Σ_j λ_j r_j + D λ with D_ij = Σ_k R_ik ψ_j(x_k).
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "fictus/boundary/surface.hpp"
#include "fictus/boundary/trace_operators.hpp"
#include "fictus/grid/distribution.hpp"
#include "fictus/grid/execution.hpp"
#include "fictus/grid/fast_solver.hpp"
#include "fictus/grid/grid.hpp"

namespace fictus {

/// The nearest point of γ to a point x near γ, and the kink function there.
struct SurfaceFoot {
  Point3 foot, normal;  // the nearest point and the outward unit normal there
  double d = 0.0;       // signed distance, > 0 outside ω
  double H = 0.0;       // κ₁ + κ₂ there (> 0 on a convex γ)
  double K2 = 0.0;      // κ₁² + κ₂² there
  /// q(d) = d − H d²/2 + β d³ with β = (κ₁² + κ₂² + H²)/6: ψ outside ω, extended smoothly inside.
  /// For −Δu + c·u the jump (outside − inside) of û's third normal derivative across γ is
  /// −(c + κ₁² + κ₂² + H²)λ + Δ_γλ (λ is constant on a patch), so q‴ = 6β makes w = û + λψ C³ across
  /// γ up to the c·λ part, which is left out (docs/math.md, "Three dimensions").
  double q() const { return d * (1.0 - d * (0.5 * H - beta() * d)); }
  double psi() const { return d > 0 ? q() : 0.0; }                               // q(d)⁺
  Point3 grad_q() const { return (1.0 - H * d + 3 * beta() * d * d) * normal; }  // ∇q, H and β taken constant
  double beta() const { return (K2 + H * H) / 6; }
};

/// W = P∇²φP/|∇φ| (P the projector onto the tangent plane) from the level function's gradient and
/// Hessian at a point of γ: the shape operator, whose tangential eigenvalues are the principal curvatures.
Eigen::Matrix3d shape_operator(const Point3& gradient, const Matrix3& hessian);

/// The nearest point of γ to x (within a few cells of γ), by Newton's method from `start` (a point
/// near the answer; x itself will do): projection onto γ along the level gradient, then a tangential
/// step (I + d·W)δ = t, W the shape operator, until the tangential residual is below `tolerance`.
SurfaceFoot nearest_point(const Surface& gamma, const Point3& x, const Point3& start, double tolerance);

/// Where nearest_point begins from `start`: the start dropped onto γ along the level gradient, with the
/// level's gradient and Hessian there. Points that share a start (a voxel's quadrature points, from the
/// foot of its centre) share these 32 evaluations of the level function.
struct SurfaceStart {
  Point3 point, gradient;
  Matrix3 hessian;
};
SurfaceStart surface_start(const Surface& gamma, const Point3& start, double tolerance);
/// nearest_point from a start made once: the same answer, to the bit, as from its point.
SurfaceFoot nearest_point(const Surface& gamma, const Point3& x, const SurfaceStart& start, double tolerance);

/// The map of patch_integrals onto γ itself: a point x of a triangle (unit normal n) goes to its nearest
/// point of γ, with dS_γ/dS_triangle = |n·n_γ|/(1 + H d) there (d the distance of x, O(h²)).
SurfaceMap onto_surface(const Surface& gamma, double tolerance);

class SurfaceKink {
 public:
  /// The kink model for the patches of γ on `grid`; computes r_j for A = K + cM. With a distributed
  /// `execution`, collective: the ranks share the work, and each holds the whole model (the serial one,
  /// bit for bit); an error on one rank is thrown on every rank.
  SurfaceKink(const Grid3& grid, const Surface& gamma, const PatchedSurface& patches, double c,
              const Execution& execution = Execution{});
  ~SurfaceKink();
  SurfaceKink(SurfaceKink&&) noexcept;
  SurfaceKink& operator=(SurfaceKink&&) noexcept;

  /// r_j over the grid nodes, one row per patch (m rows): added to B_Γ in the Schur complement.
  const SparseRows& galerkin() const;
  /// D (rows × m) for trace rows R on the same grid: D_ij = Σ_k R_ik ψ_j(x_k).
  Eigen::SparseMatrix<double> direct(const SparseRows& rows) const;
  /// u += Σ_j λ_j ψ_j at the nodes of the band (0 < d ≤ 6h: every trace stencil and the voxels of
  /// r stay in it): turns u₀ + A⁻¹(B_Γ + R)ᵀλ into the kink-corrected field I_h w. With `slab`, u holds
  /// that slab's layers (a rank's) and only their nodes change.
  void add_kinks(const std::vector<double>& lambda, GridVector& u, std::optional<Slab> slab = std::nullopt) const;
  /// Σ_k ψ_j(x_k)·weights_k over the band's nodes, per patch (with weights ℓ_k = ∫_ω φ_k: ∫_ω I_hψ_j).
  /// With `slab`: weights holds that slab's layers, and the sums are over its nodes.
  std::vector<double> band_sums(const GridVector& weights, std::optional<Slab> slab = std::nullopt) const;
  /// The number of cut voxels (for reports).
  std::size_t cut_voxels() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// The flux balance of the patches (docs/math.md, "The flux balance of the patches"). For f = 0 the
/// flux through γ of the field of a unit layer on patch j, I_h w_j = A⁻¹(B_Γ + R)ᵀe_j + I_hψ_j, is
/// c∫_ω I_h w_j; the readings S = C_γ A⁻¹(B_Γ + R)ᵀ + D_C give it as Σ_i a_i S_ij (a_i the patch
/// areas) and miss it by β_j. X, added to D_C, makes every column right (Σ_i a_i (S + X)_ij =
/// c∫_ω I_h w_j) and shifts the readings of a constant λ by the same −μλ at every point: each pair of
/// neighbouring patches (W_ij = Σ_k (B_Γ)_ik (B_Γ)_jk > 0, their rows' overlap) adds the same
/// W_ij(φ_i − φ_j)(λ_j − λ_i) to both of their area-weighted readings (nothing when λ_i = λ_j), with
/// Lφ = (β − μa)/2 for the weighted graph Laplacian L of W on each connected part of γ and μ = Σβ/Σa
/// there. load_of_omega: ℓ_k = ∫_ω φ_k (unused when c = 0), on the solver's slab. One fast solve
/// (collective when distributed); throws std::invalid_argument for a singular A.
struct FluxBalance {
  Eigen::SparseMatrix<double> correction;  // X, m × m
  Eigen::VectorXd area;                    // a_j = ∫_{P_j} 1 dS, B_Γ's row sums
  double scatter = 0;                      // the standard deviation of β_j/a_j: each patch's error
  double mean = 0;                         // μ over all of γ: a constant layer's error per unit λ
  int fast_solves = 0;
};
FluxBalance flux_balance(const SurfaceKink& kink, const SparseRows& B_Gamma, const SparseRows& C_gamma,
                         const SparseRows& loads, const Eigen::SparseMatrix<double>& D_C,
                         const GridVector& load_of_omega, const FastSolver<3>& fast,
                         const Distribution& distribution = Distribution{});

}  // namespace fictus
