// 3-D: the manufactured Signorini solutions of manufactured3d.py (∂²u/∂n² ≠ 0 on the free part, the
// contact boundary a plane section in general position) converge at the smooth variant's order on a
// sphere and an ellipsoid (the non-smooth variant on the sphere); Newton stays short; the discrete Signorini conditions
// hold to round-off; the two inner solvers agree. Small N here (the large ones are in the benchmark).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "fictus/boundary/mesh_surface.hpp"
#include "fictus/grid/execution.hpp"
#include "fictus/grid/load_vector.hpp"
#include "fictus/solve/convergence_table.hpp"
#include "manufactured_solutions_3d.hpp"

namespace {

fictus::SurfaceProblem problem(const std::string& name, int N) {
  for (const auto& p : manufactured3d::all(N))
    if (p.name == name) return p.problem;
  throw std::invalid_argument(name);
}

/// `name` at N in `variant` with the default options, on 2 threads.
fictus::SurfaceSolution solve_with_defaults(const std::string& name, int N, fictus::Variant variant) {
  fictus::SolverOptions o;
  o.threads = 2;
  o.error_estimate = false;  // rates of the solve itself; the estimate: test_quantities.cpp
  o.variant = variant;
  return fictus::solve(problem(name, N), o);
}

fictus::LevelResult level_of(const fictus::SurfaceSolution& s) {
  fictus::LevelResult r;
  r.N = s.grid.nx();
  r.n_nodes = s.grid.n_nodes();
  r.m = s.options.multipliers;
  r.it0 = s.newton.iterations;
  r.it1 = s.fast_solves;
  r.time = s.timings.total;
  r.l2_omega = s.errors->rel_l2_omega;
  r.h1_omega = s.errors->rel_h1semi_omega;
  r.l2_gamma = s.errors->rel_l2_gamma;
  return r;
}

/// max |λ_a − λ_b| / max |λ_b|.
double lambda_difference(const fictus::SurfaceSolution& a, const fictus::SurfaceSolution& b) {
  double largest = 0, difference = 0;
  for (std::size_t i = 0; i < b.lambda.size(); ++i) {
    largest = std::max(largest, std::abs(b.lambda[i]));
    difference = std::max(difference, std::abs(a.lambda[i] - b.lambda[i]));
  }
  return difference / largest;
}

void expect_signorini_at_round_off(const fictus::SurfaceSolution& s) {
  EXPECT_GT(s.signorini.min_gap, -1e-12);
  EXPECT_GT(s.signorini.min_normal_derivative, -1e-10);
  EXPECT_LT(s.signorini.max_complementarity, 1e-12);
}

struct Bands {
  double lowest_rate, highest_rate;  // L²(ω)
  double lowest_h1_rate, lowest_gamma_rate;
  int fewest_active_tenths;  // at least m·fewest/10 points in contact (the contact set is there)
  int check_from = 0;        // the independent check's bounds from this N on (its own fit resolved)
};

void converges(const std::string& name, const std::vector<int>& sizes, fictus::Variant variant, const Bands& bands,
               double largest_finest_error = 1.0) {
  std::vector<fictus::LevelResult> rows;
  std::vector<double> check_differences;
  for (int N : sizes) {
    const fictus::SurfaceSolution s = solve_with_defaults(name, N, variant);
    ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
    EXPECT_LE(s.newton.iterations, 10);
    expect_signorini_at_round_off(s);
    int active = 0;
    for (char a : s.newton.active) active += a;
    EXPECT_GT(10 * active, s.options.multipliers * bands.fewest_active_tenths);  // both parts of γ are there
    EXPECT_LT(active, s.options.multipliers * 4 / 5);
    // The independent check (docs/math.md, "Checks"): under its warning, and within 6× of the readings'
    // true largest error either way (measured 0.2–3.5× on the sphere and the ellipsoid, both variants).
    ASSERT_TRUE(s.check.has_value() && s.point_errors.has_value()) << "N = " << N;
    if (N >= bands.check_from) {
      EXPECT_LT(s.check->relative_difference, fictus::check_warning) << "N = " << N;
      EXPECT_LT(s.check->max_difference, 6 * s.point_errors->max_normal_derivative) << "N = " << N;
      EXPECT_GT(s.check->max_difference, s.point_errors->max_normal_derivative / 6) << "N = " << N;
    }
    check_differences.push_back(s.check->relative_difference);
    rows.push_back(level_of(s));
  }
  EXPECT_LT(check_differences.back(), check_differences.front());  // the check falls with h
  const char* label = variant == fictus::Variant::smooth ? ", smooth, 3-D" : ", non-smooth, 3-D";
  std::cout << fictus::format_convergence_table(name + label, rows, std::nullopt);
  const auto fit = fictus::fitted_rates(rows);
  EXPECT_LT(rows.back().l2_omega, largest_finest_error);
  EXPECT_GE(fit[0], bands.lowest_rate);
  EXPECT_LE(fit[0], bands.highest_rate);
  EXPECT_GE(fit[1], bands.lowest_h1_rate);
  EXPECT_GE(fit[2], bands.lowest_gamma_rate);
  EXPECT_LE(rows.back().it0, rows.front().it0 + 2);  // Newton does not grow with N
}

// At these N the contact set (patches of 5h) is still being resolved and the L²(ω) rate is above its
// asymptotic 2 (sphere, with the earlier patches of 8h: 2.5 over N = 96 … 160, 2.02 over 128 … 256 in the
// benchmark).
void converges(const std::string& name, const std::vector<int>& sizes, double highest_rate, int check_from = 0) {
  converges(name, sizes, fictus::Variant::smooth, {1.8, highest_rate, 0.85, 1.8, 2, check_from});
}

TEST(Manufactured3d, SphereConvergesAtSecondOrder) { converges("sphere", {96, 128, 160}, 3.0); }

TEST(Manufactured3d, EllipsoidConvergesAtSecondOrder) { converges("ellipsoid", {112, 128, 160}, 4.0); }

// The torus (genus one, saddle-shaped inner side) over N = 128 … 256 takes about 2.5 minutes: label
// slow (ctest -L slow). Measured: L²(ω) 2.2, L²(γ) 2.2, H¹(ω) 1.0; Newton 9–10 steps. The independent
// check's one-sided fit resolves the inner side from N = 192: at N = 128 and 160 its largest difference
// from the readings was 8.1× and 8.7× the readings' own largest error (0.031 against 0.0039, 0.030 against
// 0.0035; measured with the patches of 5h), so its bounds hold from 192.
TEST(Manufactured3dSlow, DISABLED_TorusConvergesAtSecondOrder) { converges("torus", {128, 160, 192, 256}, 3.0, 192); }

TEST(Manufactured3d, GreenAndKrylovAgree) {
  fictus::SolverOptions o;
  o.threads = 2;
  o.error_estimate = false;  // rates of the solve itself; the estimate: test_quantities.cpp
  o.multipliers = 129;       // patches of 6h (chosen when the default 8h left Γ no room at N = 64)
  const fictus::SurfaceSolution green = fictus::solve(problem("sphere", 64), o);
  o.inner = fictus::InnerSolver::krylov;
  o.krylov_tolerance = 1e-12;
  const fictus::SurfaceSolution krylov = fictus::solve(problem("sphere", 64), o);
  ASSERT_TRUE(green.newton.converged && krylov.newton.converged);
  EXPECT_EQ(green.newton.active, krylov.newton.active);
  EXPECT_LT(lambda_difference(krylov, green), 1e-7);
  EXPECT_GT(krylov.fast_solves, 20u);
}

TEST(Manufactured3d, InterpolatedFarFieldGivesTheExactAnswer) {
  // solver.far_field: S̃ with its far pairs interpolated, Newton on S̃ and then on the exact S (S̃ as
  // GMRES's preconditioner). The answer is the exact assembly's, in at most one Newton step more.
  for (const auto variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    fictus::SolverOptions o;
    o.threads = 2;
    o.error_estimate = false;  // rates of the solve itself; the estimate: test_quantities.cpp
    o.variant = variant;
    o.multipliers = variant == fictus::Variant::smooth ? 129 : 0;
    o.far_field = false;
    const fictus::SurfaceSolution exact = fictus::solve(problem("sphere", 64), o);
    o.far_field = true;
    const fictus::SurfaceSolution far = fictus::solve(problem("sphere", 64), o);
    ASSERT_TRUE(exact.newton.converged && far.newton.converged);
    ASSERT_TRUE(far.far_field.has_value());
    EXPECT_FALSE(exact.far_field.has_value());
    EXPECT_GT(far.far_field->assembly.far_pairs, far.far_field->assembly.near_pairs);
    EXPECT_GE(far.far_field->exact_steps, 1);
    EXPECT_EQ(far.newton.active, exact.newton.active);
    EXPECT_LE(far.newton.iterations, exact.newton.iterations + 1);
    EXPECT_LT(lambda_difference(far, exact), 1e-10);
    expect_signorini_at_round_off(far);
    EXPECT_NEAR(far.errors->rel_l2_omega, exact.errors->rel_l2_omega, 1e-6 * exact.errors->rel_l2_omega);
  }
}

TEST(Manufactured3d, NestedStartGivesTheSameAnswerInFewerSteps) {
  // solver.nested_start: Newton starts from the active set of the same problem solved on the grid of
  // N/2. It solves the same discrete problem, so the answer is the plain start's (λ to GMRES's
  // tolerance, the same active set), in fewer steps on this grid. The smooth variant's m is given (150,
  // patches of 8.3h): the coarse solve takes m/4 = 38, with Γ at the same distance from γ, inside the
  // box (chosen when the default patches were 8h; the default m at N = 48 is now 104).
  for (const auto variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    const bool smooth = variant == fictus::Variant::smooth;
    const int N = smooth ? 96 : 80;
    fictus::SolverOptions o;
    o.threads = 2;
    o.error_estimate = false;  // rates of the solve itself; the estimate: test_quantities.cpp
    o.variant = variant;
    o.multipliers = smooth ? 150 : 0;
    o.nested_start = 0;
    const fictus::SurfaceSolution plain = fictus::solve(problem("sphere", N), o);
    o.nested_start = N;
    const fictus::SurfaceSolution nested = fictus::solve(problem("sphere", N), o);
    ASSERT_TRUE(plain.newton.converged && nested.newton.converged);
    EXPECT_FALSE(plain.nested_start.has_value());
    ASSERT_TRUE(nested.nested_start.has_value());
    EXPECT_EQ(nested.nested_start->skipped, "");
    EXPECT_EQ(nested.nested_start->N, N / 2);
    EXPECT_EQ(nested.nested_start->multipliers,
              smooth ? 38 : fictus::default_patches(problem("sphere", N / 2).gamma->area(), 2.0 / N, variant));
    EXPECT_GE(nested.nested_start->newton_steps, 1);
    EXPECT_GT(nested.nested_start->active, 0);
    EXPECT_EQ(nested.newton.active, plain.newton.active);
    EXPECT_LT(nested.newton.iterations, plain.newton.iterations);
    EXPECT_LT(lambda_difference(nested, plain), 1e-10);
    expect_signorini_at_round_off(nested);
  }
}

fictus::SolverOptions nonsmooth_options(int nested_start) {
  fictus::SolverOptions o;
  o.threads = 2;
  o.error_estimate = false;  // rates of the solve itself; the estimate: test_quantities.cpp
  o.variant = fictus::Variant::nonsmooth;
  o.nested_start = nested_start;
  return o;
}

TEST(Manufactured3d, NestedStartSkipsAGridTooCoarseForTheSurface) {
  // The torus's tube (r = 0.1) is too thin for the non-smooth variant's band at N = 32: the nested
  // start says why it was skipped, and Newton starts as solver.start says (the plain start's run).
  fictus::SolverOptions o = nonsmooth_options(0);
  const fictus::SurfaceSolution plain = fictus::solve(problem("torus", 64), o);
  o.nested_start = 64;
  const fictus::SurfaceSolution skipped = fictus::solve(problem("torus", 64), o);
  ASSERT_TRUE(skipped.nested_start.has_value());
  EXPECT_NE(skipped.nested_start->skipped.find("formulation.variant: the surface folds"), std::string::npos)
      << skipped.nested_start->skipped;
  EXPECT_EQ(skipped.newton.iterations, plain.newton.iterations);
  EXPECT_EQ(skipped.newton.active, plain.newton.active);
  EXPECT_LT(lambda_difference(skipped, plain), 1e-12);
}

TEST(Manufactured3d, NestedStartSkipsAnOddGrid) {
  fictus::SolverOptions o = nonsmooth_options(60);
  const fictus::SurfaceSolution s = fictus::solve(problem("sphere", 63), o);
  ASSERT_TRUE(s.nested_start.has_value());
  EXPECT_EQ(s.nested_start->skipped, "N is odd");
  EXPECT_TRUE(s.newton.converged);
}

TEST(Manufactured3d, AnInterruptInTheNestedStartEndsTheSolve) {
  // Asked while the N/2 solve runs (after its geometry), the interrupt ends the whole solve: no skip
  // and no fine Newton.
  fictus::SolverOptions o = nonsmooth_options(64);
  std::vector<std::string> phases;
  const auto progress = [&phases](const std::string& phase, double) { phases.push_back(phase); };
  const auto interrupt = [&phases] { return std::find(phases.begin(), phases.end(), "N/2 geometry") != phases.end(); };
  EXPECT_THROW(fictus::solve(problem("sphere", 64), o, progress, interrupt), fictus::Interrupted);
  EXPECT_NE(std::find(phases.begin(), phases.end(), "N/2 geometry"), phases.end());
  EXPECT_EQ(std::find(phases.begin(), phases.end(), "nested_start"), phases.end());
}

TEST(Manufactured3d, NonSmoothVariantConvergesWithTheKinkCorrection) {
  // Multipliers on γ itself, traces of the kink-corrected field (surface_kink.hpp: q(d) with its cubic
  // term; a voxel with corners on both sides of γ is cut), patches of 4h, the flux balance. Measured
  // L²(ω) 2.35e-4, 1.01e-4, 5.24e-5 (rate 2.2 here, 2.15 over N = 64 … 192 in docs/notes/3d-manufactured-solutions.md)
  // with 32–34 % of the points in contact (40 % of γ is): the bands leave room of about 2× in the rates' spread and
  // 1.5× in the error, and a stalled error (3e-4 at N = 96) or a lagging contact set (29 %) fails them.
  converges("sphere", {64, 96, 128}, fictus::Variant::nonsmooth, {1.5, 3.5, 0.8, 1.5, 3}, 8e-5);
}

// The torus over N = 128 … 256 in the non-smooth variant takes about 3 minutes: label slow. Measured
// L²(ω) 2.00e-4, 1.43e-4, 7.84e-5, 3.86e-5 (rate 2.4; without the flux balance 5.2e-4, 1.1e-4, 1.4e-4,
// 1.2e-4, a plateau), 30–34 % of the points in contact, Newton 10 steps at N = 128 and 7 with the
// nested start from N = 160 on. The independent check passes its warning at N = 128 and 160 (relative
// difference 6.7 % and 6.1 %; docs/math.md, "Checks", records the torus at 128), its largest difference
// 6.3× the readings' at 160: its bounds hold from 192.
TEST(Manufactured3dSlow, DISABLED_NonSmoothTorusConverges) {
  converges("torus", {128, 160, 192, 256}, fictus::Variant::nonsmooth, {1.5, 3.5, 0.8, 1.5, 2, 192}, 6e-5);
}

/// The relative L²(ω) errors of `name` (no contact: ∂u/∂n = 0 on all of γ) at each N.
std::vector<double> pure_neumann_errors(const std::string& name, const std::vector<int>& sizes,
                                        fictus::Variant variant) {
  std::vector<double> errors;
  for (int N : sizes) {
    const fictus::SurfaceSolution s = solve_with_defaults(name, N, variant);
    EXPECT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
    EXPECT_EQ(std::count(s.newton.active.begin(), s.newton.active.end(), char(1)), 0) << "N = " << N;
    std::cout << name << ", N = " << N << ": L2(omega) " << s.errors->rel_l2_omega << "\n";
    errors.push_back(s.errors->rel_l2_omega);
  }
  return errors;
}

TEST(Manufactured3d, PureNeumannSphereConvergesInTheSmoothVariant) {
  // ∂u/∂n = 0 on all of γ and c = 1: a bias ε in the mean of the discrete ∂u/∂n moves u by about 10ε,
  // which a contact part would hide. Measured: 2.54e-4 and 6.49e-5 (4.42e-5 at N = 160: the fall from
  // 96 to 128 is faster than the asymptotic rate, so only the finest error and the fall are asserted).
  const std::vector<double> e = pure_neumann_errors("sphere_neumann", {96, 128}, fictus::Variant::smooth);
  EXPECT_LT(e[1], 1e-4);
  EXPECT_LT(e[1], 0.5 * e[0]);
}

TEST(Manufactured3d, PureNeumannSphereConvergesInTheNonSmoothVariant) {
  // The same in the non-smooth variant, which needs the flux balance (docs/math.md, "The flux balance
  // of the patches"): measured 7.32e-5 and 3.97e-5 (rate 2.1; 2.40e-5 and 1.63e-5 at N = 160 and 192),
  // against 1.59e-3 and 1.87e-3 without it.
  const std::vector<double> e = pure_neumann_errors("sphere_neumann", {96, 128}, fictus::Variant::nonsmooth);
  EXPECT_LT(e[1], 6e-5);
  EXPECT_GT(std::log(e[0] / e[1]) / std::log(128.0 / 96), 1.5);
}

TEST(Manufactured3d, TheFluxBalanceHoldsOnTheSolution) {
  // With the flux balance the readings Newton enforces sum, weighted by the patch areas, to the
  // discrete field's own flux c∫_ω û − ∫_ω f (the same rules for ℓ_k = ∫_ω φ_k and ∫_ω f as the
  // solver's). On the pure Neumann sphere every reading is 0, so the flux must vanish to Newton's
  // tolerance; without the balance it does not.
  const fictus::SurfaceProblem p = problem("sphere_neumann", 48);
  const auto flux = [&p](bool balance) {
    fictus::SolverOptions o;
    o.threads = 2;
    o.error_estimate = false;  // rates of the solve itself; the estimate: test_quantities.cpp
    o.variant = fictus::Variant::nonsmooth;
    o.flux_balance = balance;
    const fictus::SurfaceSolution s = fictus::solve(p, o);
    EXPECT_TRUE(s.newton.converged);
    EXPECT_EQ(s.flux_balance.has_value(), balance);
    const fictus::Execution execution(2);
    const fictus::GridVector load = fictus::omega_load(s.grid, *p.gamma, 3, execution);
    double u_integral = 0, readings = 0;
    for (std::size_t k = 0; k < load.size(); ++k) u_integral += load[k] * s.u[k];
    for (int i = 0; i < s.gamma.m; ++i) readings += s.gamma.area[std::size_t(i)] * s.normal_derivative[std::size_t(i)];
    const double f_integral =
        fictus::omega_integral(s.grid, *p.gamma, fictus::vectorize(p.f), o.load_quadrature, execution);
    std::cout << (balance ? "balanced" : "without") << ": c∫u − ∫f = " << p.c * u_integral - f_integral
              << ", Σ a_i ∂u/∂n_i = " << readings << ", ∫f = " << f_integral << "\n";
    return std::abs(p.c * u_integral - f_integral - readings) / std::abs(f_integral);
  };
  EXPECT_LT(flux(true), 1e-8);
  EXPECT_GT(flux(false), 1e-6);
}

TEST(Manufactured3d, NonSmoothShiftedRuleStallsWithoutTheKinkCorrection) {
  // The paper's shifted C_γ on the same problem: Newton and the discrete conditions are fine, the
  // error does not converge (docs/math.md), as with the 2-D shifted rule on such problems.
  fictus::SolverOptions o;
  o.threads = 2;
  o.error_estimate = false;  // rates of the solve itself; the estimate: test_quantities.cpp
  o.variant = fictus::Variant::nonsmooth;
  o.normal_derivative = fictus::NormalDerivative::shifted;
  const fictus::SurfaceSolution s = fictus::solve(problem("sphere", 48), o);
  ASSERT_TRUE(s.newton.converged);
  EXPECT_LE(s.newton.iterations, 10);
  expect_signorini_at_round_off(s);
  EXPECT_GT(s.errors->rel_l2_omega, 5e-3);
  EXPECT_LT(s.errors->rel_l2_omega, 0.05);
}

// A user's mesh: the sphere as an icosphere of 20 480 triangles (edges about 0.6h at N = 64) gives
// the analytic sphere's answer up to the facets' sag (about 9e-5), with the same Newton behaviour.
TEST(Manufactured3d, SphereFromAMeshSolvesLikeTheSphere) {
  fictus::SolverOptions o;
  o.threads = 2;
  o.error_estimate = false;  // rates of the solve itself; the estimate: test_quantities.cpp
  o.multipliers = 129;       // patches of 6h (chosen when the default 8h left Γ no room at N = 64)
  fictus::SurfaceProblem p = problem("sphere", 64);
  const fictus::SurfaceSolution exact_shape = fictus::solve(p, o);
  p.gamma = std::make_shared<fictus::MeshSurface>(fictus::icosphere({0.5, 0.5, 0.5}, 0.3, 5));
  const fictus::SurfaceSolution s = fictus::solve(p, o);
  ASSERT_TRUE(s.newton.converged) << s.newton.failure;
  EXPECT_LE(s.newton.iterations, exact_shape.newton.iterations + 2);
  expect_signorini_at_round_off(s);
  EXPECT_LT(s.errors->rel_l2_omega, 1.3 * exact_shape.errors->rel_l2_omega);
  EXPECT_LT(s.errors->rel_l2_gamma, 1.5 * exact_shape.errors->rel_l2_gamma);
  EXPECT_LT(s.errors->rel_h1semi_omega, 1.05 * exact_shape.errors->rel_h1semi_omega);
  int active = 0, active_exact = 0;
  for (char a : s.newton.active) active += a;
  for (char a : exact_shape.newton.active) active_exact += a;
  EXPECT_NEAR(active, active_exact, 0.15 * active_exact);
}

}  // namespace
