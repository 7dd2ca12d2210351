// 3-D kink correction (the non-smooth variant's traces): the nearest point of γ and its curvature,
// and the corrected traces of a layer potential with a known solution (through the kink values, the
// Galerkin rows r_j and the patch integrals over γ: uncorrected, the mean error is 0.58).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "fictus/boundary/omega_quadrature.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/boundary/surface_integrals.hpp"
#include "fictus/boundary/surface_kink.hpp"
#include "fictus/boundary/trace_operators.hpp"
#include "fictus/grid/fast_solver.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/surface_discretization.hpp"

namespace {

using fictus::Point3;

/// An ellipsoid that leaves its Hessian to the base class (central differences).
class PlainEllipsoid final : public fictus::Surface {
 public:
  PlainEllipsoid(Point3 c, Point3 a) : e_(c, a) {}
  double level(const Point3& p) const override { return e_.level(p); }
  Point3 level_gradient(const Point3& p) const override { return e_.level_gradient(p); }
  fictus::PatchedSurface patches(int m, double edge) const override { return e_.patches(m, edge); }
  double area() const override { return e_.area(); }
  fictus::Box3 bounds() const override { return e_.bounds(); }

 private:
  fictus::Ellipsoid e_;
};

TEST(SurfaceKink, NearestPointDistanceAndCurvature) {
  const Point3 c{0.5, 0.5, 0.5};
  // Sphere: d = |x − c| − R, H = 2/R, the foot on the ray.
  const fictus::Ellipsoid sphere(c, {0.3, 0.3, 0.3});
  for (double d : {-0.02, 0.0, 0.013}) {
    const Point3 direction{0.48, 0.6, 0.64};  // unit
    const Point3 x = c + (0.3 + d) * direction;
    const fictus::SurfaceFoot f = fictus::nearest_point(sphere, x, x, 1e-15);
    EXPECT_NEAR(f.d, d, 1e-14);
    EXPECT_NEAR(f.H, 2 / 0.3, 1e-10);
    EXPECT_NEAR(f.K2, 2 / 0.09, 1e-8);  // κ₁² + κ₂²
    EXPECT_NEAR(norm(f.foot - (c + 0.3 * direction)), 0.0, 1e-14);
    // q = d − H d²/2 + β d³, β = (κ₁² + κ₂² + H²)/6 = 1/(3·0.09) + 4/(6·0.09), and ∇q = q′(d)·n.
    const double beta = (2 / 0.09 + 4 / 0.09) / 6;
    EXPECT_NEAR(f.q(), d - d * d / 0.3 + beta * d * d * d, 1e-15);
    EXPECT_NEAR(dot(f.grad_q(), f.normal), 1 - 2 * d / 0.3 + 3 * beta * d * d, 1e-13);
  }
  // Ellipsoid: x − foot along the normal, foot on γ; the default Hessian gives the same H.
  const fictus::Ellipsoid ellipsoid(c, {0.34, 0.26, 0.2});
  const PlainEllipsoid plain(c, {0.34, 0.26, 0.2});
  const Point3 x{0.5 + 0.3, 0.5 + 0.1, 0.5 + 0.1};
  const fictus::SurfaceFoot f = fictus::nearest_point(ellipsoid, x, x, 1e-15);
  EXPECT_NEAR(ellipsoid.level(f.foot), 0.0, 1e-13);
  const Point3 r = x - f.foot;
  EXPECT_NEAR(norm(r - f.d * f.normal), 0.0, 1e-13);
  EXPECT_GT(f.d, 0);
  const fictus::SurfaceFoot g = fictus::nearest_point(plain, x, x, 1e-15);
  EXPECT_NEAR(g.d, f.d, 1e-12);
  EXPECT_NEAR(g.H, f.H, 1e-6 * f.H);
  // Torus: κ₁ + κ₂ = 1/r + 1/(R + r) on the outer equator and 1/r − 1/(R − r) on the inner one (a saddle).
  const double R = 0.25, rt = 0.1;
  const fictus::Torus torus(c, R, rt);
  const fictus::SurfaceFoot outer =
      fictus::nearest_point(torus, c + Point3{R + rt + 0.01, 0, 0}, c + Point3{R + rt + 0.01, 0, 0}, 1e-15);
  EXPECT_NEAR(outer.d, 0.01, 1e-13);
  EXPECT_NEAR(outer.H, 1 / rt + 1 / (R + rt), 1e-9);
  EXPECT_NEAR(outer.K2, 1 / (rt * rt) + 1 / ((R + rt) * (R + rt)), 1e-7);
  const Point3 inner_x = c + Point3{0, R - rt - 0.01, 0};
  const fictus::SurfaceFoot inner = fictus::nearest_point(torus, inner_x, inner_x, 1e-15);
  EXPECT_NEAR(inner.d, 0.01, 1e-13);
  EXPECT_NEAR(inner.H, 1 / rt - 1 / (R - rt), 1e-9);
  EXPECT_NEAR(inner.K2, 1 / (rt * rt) + 1 / ((R - rt) * (R - rt)), 1e-7);
}

/// A sphere whose level gradient vanishes on part of it (a singular level function).
class BrokenGradient final : public fictus::Surface {
 public:
  double level(const Point3& p) const override { return e_.level(p); }
  Point3 level_gradient(const Point3& p) const override { return p.x > 0.75 ? Point3{} : e_.level_gradient(p); }
  fictus::PatchedSurface patches(int m, double edge) const override { return e_.patches(m, edge); }
  double area() const override { return e_.area(); }
  fictus::Box3 bounds() const override { return e_.bounds(); }

 private:
  fictus::Ellipsoid e_{{0.5, 0.5, 0.5}, {0.3, 0.3, 0.3}};
};

TEST(SurfaceKink, AVanishingGradientIsAnErrorNotACrash) {
  // nearest_point throws inside the parallel loops; the exception must reach the caller.
  const BrokenGradient gamma;
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, 32);
  try {
    const fictus::SurfaceKink kink(grid, gamma, gamma.patches(40, grid.h()), 1.0, fictus::Execution(2));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("geometry: no nearest point of the surface"), std::string::npos) << e.what();
  }
}

/// The mean and the largest error over the points of ∂û/∂n inside γ for a layer of density 1 on a
/// sphere of radius 0.3 with −Δu + k²u = 0 (k = 20, the box far away in units of 1/k): û = A i₀(kr)
/// inside, B k₀(kr) outside, with ∂û/∂n jumping by −1 across γ. corrected = false: the Q1 field
/// itself, whose traces straddle the kink.
std::pair<double, double> layer_normal_derivative_error(int N, bool corrected) {
  const double k = 20, R = 0.3;
  // A sinh(kR)/R = B e^{−kR}/R and −B(kR + 1)e^{−kR}/R² − A(kR cosh kR − sinh kR)/R² = −1.
  const double s = std::sinh(k * R), ch = std::cosh(k * R);
  const double A = R * R / ((k * R + 1) * s + (k * R * ch - s));  // B eliminated
  const double exact = A * (k * R * ch - s) / (R * R);
  const fictus::Ellipsoid gamma({0.5, 0.5, 0.5}, {R, R, R});
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, N);
  const fictus::Execution execution(2);
  const int m = fictus::default_patches(gamma.area(), grid.h(), fictus::Variant::nonsmooth);
  const fictus::PatchedSurface patches = gamma.patches(m, grid.h());
  const fictus::SurfaceKink kink(grid, gamma, patches, k * k, execution);
  const fictus::SparseRows B_Gamma = fictus::patch_integral_rows(
      grid, fictus::patch_integrals(grid, patches.triangles, patches.patch_of, m, fictus::onto_surface(gamma, 1e-15)),
      m);
  const fictus::SparseRows loads = corrected ? fictus::add_rows(B_Gamma, kink.galerkin()) : B_Gamma;
  const std::vector<double> lambda(m, 1.0);
  fictus::GridVector u(grid.n_unknowns(), 0.0);
  loads.add_transposed(lambda, u);
  fictus::make_fast_solver(grid, k * k, execution)->solve_in_place(u);
  if (corrected) kink.add_kinks(lambda, u);
  std::vector<double> dn;
  fictus::normal_derivative_rows_centered(grid, patches.point, patches.normal).multiply(u, dn);
  double mean = 0, area = 0, largest = 0;
  for (int i = 0; i < m; ++i) {
    mean += patches.area[i] * (dn[i] - exact);
    area += patches.area[i];
    largest = std::max(largest, std::abs(dn[i] - exact));
  }
  return {std::abs(mean / area), largest};
}

TEST(SurfaceKink, CorrectedNormalDerivativeOfALayerConverges) {
  // The exact inside ∂û/∂n is 0.4167. Measured: uncorrected mean error 0.58 at every N; corrected
  // 6.8e-4 (N = 32), 2.1e-4 (N = 64), largest 7.7e-3 and 3.1e-3.
  const auto [raw_mean, raw_largest] = layer_normal_derivative_error(32, false);
  EXPECT_GT(raw_mean, 0.3);
  const auto [mean32, largest32] = layer_normal_derivative_error(32, true);
  const auto [mean64, largest64] = layer_normal_derivative_error(64, true);
  std::cout << "layer: mean error of the corrected dudn " << mean32 << " (N = 32), " << mean64 << " (N = 64); largest "
            << largest32 << ", " << largest64 << "\n";
  EXPECT_LT(mean32, 1.5e-3);
  EXPECT_LT(mean64, 4e-4);
  EXPECT_LT(mean64, 0.5 * mean32);
  EXPECT_LT(largest64, 0.6 * largest32);
  EXPECT_LT(largest64, 5e-3);
}

/// The mean of the kink-corrected ∂û/∂n over γ for a layer of density λ_j on the patches of the
/// sphere r = 0.3 in the unit box with c = 1, against its exact value: for f = 0, ∫_γ ∂u/∂n = c∫_ω u
/// = c Σ_j λ_j ∫_{P_j} Φ with −ΔΦ + cΦ = 1_ω in the box (Φ = 0 on the walls; C¹ across γ, its Q1
/// solution converges at h²). One adjoint solve gives every patch's share:
/// b_j = Σ_i a_i S_ij − c∫_{P_j}Φ, S the map from λ to the readings C_γ, a_i the areas of the patches
/// on γ (B_Γ's row sums). Returns the constant-λ bias Σ_j b_j / |γ|, the scatter (standard deviation)
/// of b_j / a_j, and the mean of Φ on γ (1.380921e-2 from the box's eigenfunction series). With
/// `balanced`, S includes the flux balance's X (fictus::flux_balance, which takes ℓ_ω from the
/// library's omega_load; Φ here has its own load, by the error integrals' rule with 4 points).
struct FluxShares {
  double bias, scatter, phi;
};
FluxShares mean_flux_shares(int N, bool balanced = false) {
  const double R = 0.3, c = 1;
  const fictus::Ellipsoid gamma({0.5, 0.5, 0.5}, {R, R, R});
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, N);
  const fictus::Execution execution(2);
  const double h = grid.h();
  const int m = fictus::default_patches(gamma.area(), h, fictus::Variant::nonsmooth);
  const fictus::PatchedSurface patches = gamma.patches(m, h);
  const fictus::SurfaceKink kink(grid, gamma, patches, c, execution);
  const fictus::SparseRows B_Gamma = fictus::patch_integral_rows(
      grid, fictus::patch_integrals(grid, patches.triangles, patches.patch_of, m, fictus::onto_surface(gamma, 1e-15)),
      m);
  const fictus::SparseRows C = fictus::normal_derivative_rows_centered(grid, patches.point, patches.normal);
  const auto solver = fictus::make_fast_solver(grid, c, execution);
  // Φ: the load ∫_ω φ_k by the cut-voxel rule of the error integrals (one thread: one sum).
  fictus::GridVector phi(grid.n_unknowns(), 0.0);
  fictus::for_each_omega_point(
      grid, gamma, 4, fictus::Execution(1), [&](int, const fictus::Grid3::Index& cell, const Point3& x, double w) {
        const Point3 t = (1 / h) * (x - Point3{grid.x(cell[0]), grid.y(cell[1]), grid.z(cell[2])});
        for (int l = 0; l < 8; ++l) {
          const fictus::Grid3::Index node{cell[0] + (l & 1), cell[1] + ((l >> 1) & 1), cell[2] + ((l >> 2) & 1)};
          double v = w;
          for (int d = 0; d < 3; ++d) v *= (l >> d) & 1 ? t[d] : 1 - t[d];
          if (grid.has_unknown(node)) phi[grid.index(node)] += v;
        }
      });
  solver->solve_in_place(phi);
  std::vector<double> phi_on_patches, from_B, from_R;
  B_Gamma.multiply(phi, phi_on_patches);
  std::vector<double> a(static_cast<std::size_t>(m), 0.0);  // ∫_{P_j} 1 dS on γ (no wall node is near γ)
  for (int j = 0; j < m; ++j)
    for (std::size_t e = B_Gamma.row_begin[std::size_t(j)]; e < B_Gamma.row_begin[std::size_t(j) + 1]; ++e)
      a[std::size_t(j)] += B_Gamma.entries[e].value;
  // The adjoint: y = A⁻¹Cᵀa, then Σ_i a_i S_ij = (B_Γ + R)_j·y + (Dᵀa)_j.
  fictus::GridVector y(grid.n_unknowns(), 0.0);
  C.add_transposed(a, y);
  solver->solve_in_place(y);
  B_Gamma.multiply(y, from_B);
  kink.galerkin().multiply(y, from_R);
  Eigen::SparseMatrix<double> D = kink.direct(C);
  if (balanced) {
    fictus::GridVector load = fictus::omega_load(grid, gamma, 3, execution);
    D +=
        fictus::flux_balance(kink, B_Gamma, C, fictus::add_rows(B_Gamma, kink.galerkin()), D, load, *solver).correction;
  }
  const Eigen::VectorXd from_D = D.transpose() * Eigen::Map<const Eigen::VectorXd>(a.data(), Eigen::Index(m));
  double area = 0, bias = 0, mean_share = 0, mean_phi = 0;
  std::vector<double> share(static_cast<std::size_t>(m));
  for (int j = 0; j < m; ++j) {
    const double b = from_B[std::size_t(j)] + from_R[std::size_t(j)] + from_D[j] - c * phi_on_patches[std::size_t(j)];
    share[std::size_t(j)] = b / a[std::size_t(j)];
    area += a[std::size_t(j)];
    bias += b;
    mean_share += share[std::size_t(j)] / m;
    mean_phi += phi_on_patches[std::size_t(j)];
  }
  double scatter = 0;
  for (double s : share) scatter += (s - mean_share) * (s - mean_share) / m;
  return {bias / area, std::sqrt(scatter), mean_phi / area};
}

}  // namespace

TEST(SurfaceKink, MeanFluxOfAConstantLayerConvergesAgainstItsExactValue) {
  // The mean of ∂û/∂n carries no flux error a multiplier could hide: with c = 1 and a free γ it sets
  // the level of u. Measured with Φ on the same grid: −1.35e-4 (N = 64), −5.6e-5 (N = 96). (The table
  // of docs/notes/3d-kink-and-neumann-bias.md, "An exact reference for the mean flux", takes Φ on a grid of 192 and
  // weights with the flat triangles' areas: −1.47e-4, −6.1e-5.)
  const FluxShares coarse = mean_flux_shares(64), fine = mean_flux_shares(96);
  std::cout << "mean flux bias of a constant layer: " << coarse.bias << " (N = 64), " << fine.bias
            << " (N = 96); per-patch scatter " << coarse.scatter << ", " << fine.scatter << " against Φ on γ "
            << fine.phi << "\n";
  EXPECT_NEAR(fine.phi, 1.380921e-2, 5e-6);  // the exact mean flux of a unit layer (the series value)
  EXPECT_LT(std::abs(coarse.bias), 2.5e-4);
  EXPECT_LT(std::abs(fine.bias), std::abs(coarse.bias) / 1.8);  // rate ≥ 1.45 (2.2 measured)
}

// Known defect of the kink model alone, kept as a reproducer and not run by ctest: each patch's
// multiplier should move the mean of the readings by c∫_{P_j}Φ, about 1.38e-2 per unit area. The
// piecewise-constant kink model scatters about that by 9e-3 (N = 64 … 160), not falling with h, so a
// multiplier that varies over γ shifts the mean flux (docs/math.md, "The non-smooth variant's Neumann
// bias"). The solver corrects it by the flux balance (the next test). Fails today. Run with
// --gtest_also_run_disabled_tests --gtest_filter='SurfaceKinkKnownDefect.*'.
TEST(SurfaceKinkKnownDefect, DISABLED_EveryPatchMovesTheMeanFluxByItsShare) {
  const FluxShares shares = mean_flux_shares(96);
  EXPECT_LT(shares.scatter, 0.1 * shares.phi);
}

TEST(SurfaceKink, TheFluxBalanceMovesTheMeanFluxByEachPatchsShare) {
  // With the flux balance's X in D_C each patch's share meets c∫_ω of its own field by construction;
  // measured here against the independent c∫_{P_j}Φ: the scatter falls from 9.0e-3 to 2.1e-4 (1.5 % of
  // Φ; 2.5e-4 at N = 64) and a constant layer's bias from −5.6e-5 to 3.1e-6 (7.4e-6 at N = 64).
  const FluxShares raw = mean_flux_shares(96), balanced = mean_flux_shares(96, true);
  std::cout << "per-patch scatter " << raw.scatter << " raw, " << balanced.scatter
            << " balanced; constant layer's bias " << raw.bias << ", " << balanced.bias << "\n";
  EXPECT_LT(balanced.scatter, 0.03 * balanced.phi);
  EXPECT_LT(balanced.scatter, raw.scatter / 20);
  EXPECT_LT(std::abs(balanced.bias), 1e-5);
}
