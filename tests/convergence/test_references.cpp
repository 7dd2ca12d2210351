// fictus against converged fitted-mesh references (tests/references/*.json: FreeFEM, P2 on meshes
// fitted to γ and graded at the contact ends, primal-dual active set, sampled values changing by
// < 1e-7 between the last two meshes) for four problems without a closed form: a rotated ellipse,
// a five-lobed star and a peanut (the last two non-convex), and a thin ellipse whose contact ends lie
// near its tips (curvature 10–16), with free-boundary points in general position. Errors in ω come from the reference's
// polar Gauss rule, on γ from its trace samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>

#include "fictus/boundary/surface.hpp"
#include "fictus/boundary/trace_operators.hpp"
#include "fictus/io/problem_file.hpp"
#include "reference_comparison.hpp"

namespace {

/// A reference of tests/references: its problem file's text and its fitted-mesh solution (NAME.json).
struct StoredReference {
  std::string text;
  nlohmann::json json;
};

StoredReference read_reference(const std::string& name) {
  const std::string dir = std::string(FICTUS_SOURCE_DIR) + "/tests/references/";
  std::ifstream file(dir + name + ".toml"), json_file(dir + name + ".json");
  std::stringstream text;
  text << file.rdbuf();
  return {text.str(), nlohmann::json::parse(json_file)};
}

struct ReferenceCase {
  std::string name;
  fictus::Variant variant;
  int coarsest = 256;        // N = coarsest … 8·coarsest
  double smooth_rate = 1.8;  // the smooth variant's least rate in L²(ω) and L²(γ)
  int ends_from = 0;         // the contact ends are checked from this N on
};

class References : public ::testing::TestWithParam<ReferenceCase> {};

TEST_P(References, ConvergeToTheFittedMeshSolution) {
  const ReferenceCase c = GetParam();
  const reference::Reference reference = reference::load(std::string(FICTUS_SOURCE_DIR) + "/tests/references", c.name);
  std::vector<fictus::LevelResult> rows;
  std::vector<double> end_errors, resolved_end_errors;
  std::vector<int> levels;
  for (int N = c.coarsest; N <= 8 * c.coarsest; N *= 2) {
    levels.push_back(N);
    fictus::ProblemSpec spec =
        fictus::read_problem_file(std::string(FICTUS_SOURCE_DIR) + "/tests/references/" + c.name + ".toml");
    spec.problem.N = N;
    spec.options.variant = c.variant;
    spec.options.condition_number = false;
    spec.options.error_estimate = false;  // not looked at here
    spec.options.threads = 2;
    const fictus::Solution s = fictus::solve(spec.problem, spec.options);
    ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
    const reference::Comparison cmp = reference::compare(reference, s);
    rows.push_back(cmp.level);
    end_errors.push_back(cmp.end_error_spacings);
    resolved_end_errors.push_back(cmp.resolved_end_error_spacings);
  }
  std::cout << fictus::format_convergence_table(
      c.name + " against its fitted-mesh reference, " + fictus::to_string(c.variant), rows, std::nullopt);
  std::cout << "contact ends, largest distance to the reference's in spacings s = L/m:";
  for (double e : end_errors) std::cout << ' ' << e;
  std::cout << "; located inside the arcs:";
  for (double e : resolved_end_errors) std::cout << ' ' << e;
  std::cout << '\n';
  const auto fit = fictus::fitted_rates(rows);
  if (c.variant == fictus::Variant::smooth) {
    EXPECT_GE(fit[0], c.smooth_rate);
    EXPECT_GE(fit[2], c.smooth_rate);
  } else {
    EXPECT_GE(fit[0], 0.85);
    EXPECT_GE(fit[2], 0.85);
  }
  EXPECT_GE(fit[1], 0.85);
  for (std::size_t k = 0; k < levels.size(); ++k) {
    if (levels[k] < c.ends_from) continue;
    EXPECT_LE(end_errors[k], 1.0);  // every contact end within one spacing
    // located inside the arcs: within a quarter (smooth) or half of one
    EXPECT_LE(resolved_end_errors[k], c.variant == fictus::Variant::smooth ? 0.25 : 0.45);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Problems, References,
    ::testing::Values(
        // The smooth variant over N = 512 … 4096, where the ripple of the controls overtook the
        // second-order error with Γ at δ = 1.5·s (orders 1.53 on the ellipse and 1.41 on the peanut);
        // with δ = 2·s, measured 1.87, 2.23 and 2.14 (bench/results/2026-12-06-offset-2d.md).
        ReferenceCase{.name = "ellipse", .variant = fictus::Variant::smooth, .coarsest = 512},
        ReferenceCase{.name = "star", .variant = fictus::Variant::smooth, .coarsest = 512},
        ReferenceCase{.name = "peanut", .variant = fictus::Variant::smooth, .coarsest = 512},
        ReferenceCase{"ellipse", fictus::Variant::nonsmooth}, ReferenceCase{"star", fictus::Variant::nonsmooth},
        ReferenceCase{"peanut", fictus::Variant::nonsmooth},
        // Every contact end where γ's curvature is 10–16 (the tips of a
        // thin ellipse), N = 512 … 4096. Measured: the smooth variant
        // converges at 2.37 with the contact fit and Γ at δ = 2s (7.1e-7,
        // 1.3e-7, 3.5e-8, 4.7e-9; without the fit, δ = 1.5s: 9.4e-7,
        // 1.3e-7, 1.8e-7, 2.4e-8, rate 1.53: the error swung with where
        // the ends fell between the points, TipsContactFit below); the
        // non-smooth variant misses the free zone at one tip (2.9 spacings
        // long) at N = 512 and has an end 1.2 s off at 1024 (0.70 s once
        // located inside the arcs).
        ReferenceCase{.name = "tips", .variant = fictus::Variant::smooth, .coarsest = 512},
        ReferenceCase{.name = "tips", .variant = fictus::Variant::nonsmooth, .coarsest = 512, .ends_from = 2048}),
    [](const auto& info) { return info.param.name + "_" + fictus::to_string(info.param.variant); });

// The contact fit (solver.fit_contact, docs/math.md "Fitting the points to the contact set") on the thin
// ellipse whose four contact ends lie where γ bends hard, smooth variant, N = 1024 … 1536 in steps of 128.
// Without the fit the active set is whole points, the solve puts each end on a border between two arcs,
// and the error swings with where the true ends fall between the points: error·N² varies 3.1× over these
// five grids (measured 0.21 … 0.66; 0.13 … 0.51, 3.8×, with Γ at δ = 1.5s). With the default two passes the arcs end
// just inside the located ends (s/20): error·N² within 1.5× (measured 0.117 … 0.161 with Γ at δ = 2s, 0.115 … 0.141
// at 1.5s; 0.23 … 0.27 with the arcs ending at the ends themselves), every end within 0.05 s of the reference's
// (measured 0.025 s; without: up to 0.15 s),
// the second pass moving them by under 0.05 s, each fitted solve one or two Newton steps.
TEST(ReferencesContactFit, TipsErrorsNoLongerSwingWithTheEnds) {
  const std::string dir = std::string(FICTUS_SOURCE_DIR) + "/tests/references/";
  const reference::Reference reference = reference::load(dir, "tips");
  std::array<std::vector<double>, 2> scaled;  // error·N², without and with the fit
  double worst_end = 0;
  for (int N = 1024; N <= 1536; N += 128) {
    for (int fit : {0, 1}) {
      fictus::ProblemSpec spec = fictus::read_problem_file(dir + "tips.toml");
      spec.problem.N = N;
      spec.options.variant = fictus::Variant::smooth;
      spec.options.condition_number = false;
      spec.options.error_estimate = false;
      spec.options.threads = 2;
      if (fit == 0) spec.options.fit_contact = 0;  // else the default: two passes on a curve, smooth
      const fictus::Solution s = fictus::solve(spec.problem, spec.options);
      ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
      const reference::Comparison c = reference::compare(reference, s);
      scaled[std::size_t(fit)].push_back(c.level.l2_omega * N * N);
      if (fit == 0) {
        EXPECT_FALSE(s.contact_fit.has_value());
        continue;
      }
      ASSERT_TRUE(s.contact_fit.has_value());
      EXPECT_EQ(s.options.fit_contact, 2);
      EXPECT_EQ(s.contact_fit->passes, 2);
      ASSERT_EQ(s.contact_fit->moved.size(), 2u);
      EXPECT_LT(s.contact_fit->moved[1], 0.05) << "N = " << N;
      EXPECT_LT(s.contact_fit->moved[1], s.contact_fit->moved[0]) << "N = " << N;
      ASSERT_EQ(s.contact_fit->newton_steps.size(), 3u);
      EXPECT_LE(s.contact_fit->newton_steps[1], 2);
      EXPECT_LE(s.contact_fit->newton_steps[2], 2);
      EXPECT_GT(s.contact_fit->seconds, 0);
      EXPECT_EQ(s.timings["fit_contact"], s.contact_fit->seconds);
      worst_end = std::max(worst_end, c.resolved_end_error_spacings);
    }
  }
  const auto spread = [](const std::vector<double>& v) {
    return *std::max_element(v.begin(), v.end()) / *std::min_element(v.begin(), v.end());
  };
  std::cout << "error·N², without the fit:";
  for (double v : scaled[0]) std::cout << ' ' << v;
  std::cout << "; with it:";
  for (double v : scaled[1]) std::cout << ' ' << v;
  std::cout << "; ends within " << worst_end << " s\n";
  EXPECT_GT(spread(scaled[0]), 2.5);  // what the fit removes (the test can see it): measured 3.1
  EXPECT_LT(spread(scaled[1]), 1.5);
  EXPECT_LT(worst_end, 0.05);
  for (std::size_t k = 0; k < scaled[1].size(); ++k) EXPECT_LT(scaled[1][k], 0.2);
}

// Mixed conditions in 2-D: the peanut with a Dirichlet part (the right lobe), a Neumann part (the bottom)
// and two Signorini arcs, one with a contact piece whose ends are free-boundary points in general position
// (tests/references/peanut_mixed.toml; peanut_mixed.json: FreeFEM, P2 on meshes fitted to γ with the four
// junctions as vertices and graded towards them and the contact ends; 1.2e6 dofs on the last level, u
// changing by 1.6e-8 and the fluxes by 7e-11 from the level before). Both variants, N = 256 … 2048.
TEST(ReferencesMixed, PeanutConvergesToTheFittedMeshSolution) {
  const std::string dir = std::string(FICTUS_SOURCE_DIR) + "/tests/references/";
  const reference::Reference reference = reference::load(dir, "peanut_mixed");
  std::ifstream json_file(dir + "peanut_mixed.json");
  const nlohmann::json parts = nlohmann::json::parse(json_file)["conditions"];
  const double ref_dirichlet = parts["dirichlet_part"]["flux"], ref_force = parts["signorini_part"]["flux"],
               ref_contact = parts["signorini_part"]["contact_measure"];
  for (const auto variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    std::vector<fictus::LevelResult> rows;
    std::vector<std::array<double, 3>> part_errors;
    std::vector<double> end_errors;
    for (int N = 256; N <= 2048; N *= 2) {
      fictus::ProblemSpec spec = fictus::read_problem_file(dir + "peanut_mixed.toml");
      spec.problem.N = N;
      spec.options.variant = variant;
      spec.options.condition_number = false;
      spec.options.error_estimate = false;
      spec.options.threads = 2;
      const fictus::Solution s = fictus::solve(spec.problem, spec.options);
      ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
      EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
      const reference::Comparison cmp = reference::compare(reference, s);
      rows.push_back(cmp.level);
      end_errors.push_back(cmp.resolved_end_error_spacings);
      const fictus::ContactSummary c = fictus::contact_summary(s);
      // the parts' lengths: the arcs end at the junctions (to the arc-length table)
      EXPECT_NEAR(c.dirichlet.measure, double(parts["dirichlet_part"]["measure"]), 1e-8);
      EXPECT_NEAR(c.neumann.measure, double(parts["neumann_part"]["measure"]), 1e-8);
      part_errors.push_back({std::abs(c.dirichlet.flux / ref_dirichlet - 1), std::abs(c.force / ref_force - 1),
                             std::abs(c.measure / ref_contact - 1)});
      std::cout << "N = " << N << ", " << fictus::to_string(variant) << ": Dirichlet flux "
                << c.dirichlet.flux / ref_dirichlet - 1 << ", contact force " << c.force / ref_force - 1
                << ", contact length " << c.measure / ref_contact - 1 << " (relative), contact ends within "
                << cmp.resolved_end_error_spacings << " s\n";
    }
    std::cout << fictus::format_convergence_table(
        std::string("peanut_mixed against its fitted-mesh reference, ") + fictus::to_string(variant), rows,
        std::nullopt);
    // Measured (docs/math.md, "Mixed conditions"): first order in L²(ω), the junctions' r^{1/2} singularities
    // setting it; the fluxes through the parts and the contact length within a few 1e-3 at N = 2048, the
    // force's error falling at each N.
    const bool smooth = variant == fictus::Variant::smooth;
    EXPECT_GE(fictus::fitted_rates(rows)[0], 0.9);
    EXPECT_LT(rows.back().l2_omega, smooth ? 5e-5 : 1e-4);
    EXPECT_LT(part_errors.back()[0], 2e-3);
    EXPECT_LT(part_errors.back()[1], smooth ? 2.5e-3 : 5e-3);
    EXPECT_LT(part_errors.back()[2], 5e-3);
    for (std::size_t k = 1; k < part_errors.size(); ++k) EXPECT_LT(part_errors[k][1], part_errors[k - 1][1]);
    for (double e : end_errors) EXPECT_LE(e, 0.25);
  }
}

// 3-D: the ellipsoid of tests/references/ellipsoid3d.toml against its fitted reference
// (ellipsoid3d.json: FreeFEM, P2 on curved tetrahedra fitted exactly to γ, primal-dual active set;
// ∫u, ∫u² to about 3e-6 relative, ∫|∇u|² to about 7e-5, pointwise u to a few 1e-4). The smooth
// variant at N = 96, 128, 160: the integrals approach the reference's, pointwise u converges, the
// contact flags at the reference's 300 points on γ agree more and more, and the contact area is
// within 1 % of the reference's (measured with patches of 5h: +0.42 %, +0.09 %, +0.09 %; with 8h +1.4 %,
// +1.0 %, +0.4 %). The reference's contact fraction
// is the least converged of its values: 0.5916, 0.5894, 0.5882 on its three levels, first order in its
// dof spacing, so about 0.585 in the limit. Before its indicator was corrected at the vertex dofs
// (vertex_indicator.idp) it said 0.5263, and fictus seemed 10–11 % too large.
TEST(References3d, EllipsoidConvergesToTheFittedMeshSolution) {
  const auto [text, reference] = read_reference("ellipsoid3d");
  const double ref_u = reference["values"]["int_u"], ref_u2 = reference["values"]["int_u2"],
               ref_grad2 = reference["values"]["int_grad2"];
  const double ref_area = double(reference["values"]["contact_fraction"]) * double(reference["values"]["area_gamma"]);
  std::vector<fictus::Point3> interior;
  std::vector<double> interior_u;
  for (const auto& r : reference["interior"]) interior.push_back({r[0], r[1], r[2]}), interior_u.push_back(r[3]);
  const double reference_pointwise = reference["changes"]["max_u_interior"];
  double previous_pointwise = 1;
  for (int N : {96, 128, 160}) {
    fictus::SurfaceProblemSpec spec = fictus::parse_surface_problem_text(text, "ellipsoid3d");
    // The file's f and g, compiled (muParser would spend most of the time): checked to agree.
    const fictus::ScalarField3 f = [](double x, double y, double) { return -4 + 0.5 * x * y; };
    const fictus::ScalarField3 g = [](double x, double y, double z) {
      return 1 + 0.6 * (x - 0.5) + 0.4 * (y - 0.5) - 0.5 * (z - 0.5) + 0.1 * std::sin(3 * x);
    };
    for (const fictus::Point3& x : {fictus::Point3{0.3, 0.6, 0.45}, fictus::Point3{0.71, 0.42, 0.6}}) {
      ASSERT_NEAR(f(x.x, x.y, x.z), spec.problem.f(x.x, x.y, x.z), 1e-14);
      ASSERT_NEAR(g(x.x, x.y, x.z), spec.problem.g(x.x, x.y, x.z), 1e-14);
    }
    spec.problem.f = f, spec.problem.g = g, spec.problem.N = N;
    spec.options.threads = 2;
    const fictus::SurfaceSolution s = fictus::solve(spec.problem, spec.options);
    ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
    EXPECT_LE(s.newton.iterations, 10);
    EXPECT_GT(s.signorini.min_gap, -1e-12);
    EXPECT_LT(s.signorini.max_complementarity, 1e-12);
    // ∫û², ∫|∇û|² as the errors against 0, ∫û from the errors against 1 and the volume.
    const fictus::Execution execution(2);
    const auto constant = [](double value) { return [value](double, double, double) { return value; }; };
    const auto flat = [](double, double, double) { return fictus::Point3{0, 0, 0}; };
    const fictus::Surface& gamma = *spec.problem.gamma;
    const fictus::ErrorNorms zero =
        fictus::compute_errors(s.u, s.grid, gamma, s.gamma, s.trace, constant(0), flat, 3, execution);
    const fictus::ErrorNorms one =
        fictus::compute_errors(s.u, s.grid, gamma, s.gamma, s.trace, constant(1), flat, 3, execution);
    const double volume = 4 * std::numbers::pi / 3 * 0.34 * 0.26 * 0.2;
    const double u2 = zero.l2_omega * zero.l2_omega, grad2 = zero.h1semi_omega * zero.h1semi_omega;
    const double u1 = (u2 + volume - one.l2_omega * one.l2_omega) / 2;
    std::vector<double> at_samples;
    fictus::point_value_rows(s.grid, interior).multiply(s.u, at_samples);
    double pointwise = 0;
    for (std::size_t q = 0; q < interior.size(); ++q)
      pointwise = std::max(pointwise, std::abs(at_samples[q] - interior_u[q]));
    int agree = 0;
    for (const auto& r : reference["boundary"]) {  // the flag of the nearest patch point
      const fictus::Point3 x{r[0], r[1], r[2]};
      int nearest = 0;
      for (int p = 1; p < s.gamma.m; ++p)
        if (norm(s.gamma.point[p] - x) < norm(s.gamma.point[nearest] - x)) nearest = p;
      agree += bool(s.newton.active[std::size_t(nearest)]) == (double(r[5]) != 0);
    }
    std::cout << "N = " << N << ", m = " << s.options.multipliers << ": int u " << u1 / ref_u - 1 << ", int u^2 "
              << u2 / ref_u2 - 1 << ", int |grad u|^2 " << grad2 / ref_grad2 - 1 << " (relative), max |u - u_ref| "
              << pointwise << ", contact flags agree " << agree << "/300, contact area "
              << s.contact_measure / ref_area - 1 << " (relative)\n";
    const bool finest = N == 160;
    EXPECT_LT(std::abs(u1 / ref_u - 1), finest ? 3e-5 : 3e-4);
    EXPECT_LT(std::abs(u2 / ref_u2 - 1), finest ? 5e-5 : 5e-4);
    EXPECT_LT(std::abs(grad2 / ref_grad2 - 1), finest ? 5e-4 : 5e-3);
    // Falling by a quarter per step while above the reference's own pointwise error plus fictus's: the
    // reference's largest change at its last level, 1.8e-4, is 0.5–0.8 times that error (orders 2 to 1.5
    // in its spacing: change/(1.33^p − 1)), so 3 times the change bounds the comparison's floor. With
    // patches of 5h fictus is at 1.1e-3, 2.8e-4 and 3.5e-4 at N = 96, 128 and 160.
    EXPECT_LT(pointwise, std::max(0.75 * previous_pointwise, 3 * reference_pointwise));
    EXPECT_GE(agree, finest ? 280 : 265);
    // Measured 0.42 %, 0.09 %, 0.09 %; the reference's finest level is itself about 0.6 % above its limit.
    EXPECT_LT(std::abs(s.contact_measure / ref_area - 1), 0.01);
    previous_pointwise = pointwise;
  }
  EXPECT_LT(previous_pointwise, 8e-4);
}

// 3-D: the tilted prolate spheroid of tests/references/spheroid3d.toml (axis (2, 3, 6)/7, semi-axes
// 0.32 and 0.19, data functions of the axial coordinate t and the distance from the axis, so u is
// axisymmetric but the grid is not). Its reference (spheroid3d.json, signorini_axisym.edp) is a P2
// solve in the meridian half-plane with 1.4e6 dofs: the contact set is the cap t > t* = 0.1385581
// (to 5e-7), its area 0.1733822 (to 3e-6 relative), ∫u and the force to 1e-12. Both variants at
// N = 96 and 128: the contact area inside the located boundary, a curve through the ends (measured:
// smooth +0.02 %, +0.29 % with patches of 5h, −1.7 %, −0.8 % with the earlier 8h, to which the rest of
// this sentence refers; non-smooth −0.76 %, +0.15 %; inside their polyline it was −2.7 %, −1.7 % and
// −1.0 %, −0.16 %, and the whole patches' moved by border strips −18 % and −4.5 % at 128) and closer
// than the whole patches' at 128 (+6.0 %, +3.0 %), every located end within 0.3 s
// of the contact circle (measured: 0.16 s at most; 0.14 s with 5h), the force and ∫u.
TEST(References3d, SpheroidContactSetAndForce) {
  const auto [text, reference] = read_reference("spheroid3d");
  const nlohmann::json& values = reference["values"];
  const double ref_area = values["contact_area"], ref_force = values["force"], ref_u = values["int_u"],
               t_end = values["contact_end_t"];
  const fictus::Point3 center{0.49, 0.51, 0.5}, axis{2.0 / 7, 3.0 / 7, 6.0 / 7};
  const double a = 0.19, b = 0.32, k = 1 / (b * b) - 1 / (a * a);
  const auto t_of = [=](const fictus::Point3& x) { return dot(x - center, axis); };
  const auto r2_of = [=](const fictus::Point3& x) { return dot(x - center, x - center) - t_of(x) * t_of(x); };
  // The file's level, f and g, compiled (muParser and central differences would spend most of the
  // time): checked to agree.
  const auto level = [=](double x, double y, double z) {
    const fictus::Point3 p{x, y, z};
    return t_of(p) * t_of(p) / (b * b) + r2_of(p) / (a * a) - 1;
  };
  const auto gradient = [=](double x, double y, double z) {
    const fictus::Point3 p{x, y, z};
    return (2 / (a * a)) * (p - center) + (2 * k * t_of(p)) * axis;
  };
  const auto hessian = [=](const fictus::Point3&) {
    fictus::Matrix3 h;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) h[std::size_t(i)][j] = (i == j ? 2 / (a * a) : 0.0) + 2 * k * axis[i] * axis[j];
    return h;
  };
  const fictus::ScalarField3 f = [=](double x, double y, double z) {
    const fictus::Point3 p{x, y, z};
    return 2 - 3 * r2_of(p) + 0.5 * std::sin(5 * t_of(p));
  };
  const fictus::ScalarField3 g = [=](double x, double y, double z) {
    const fictus::Point3 p{x, y, z};
    return 2.2 + 0.8 * t_of(p) + 2 * r2_of(p) + 0.05 * std::cos(7 * t_of(p));
  };
  for (fictus::Variant variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    const bool smooth = variant == fictus::Variant::smooth;
    for (int N : {96, 128}) {
      fictus::SurfaceProblemSpec spec = fictus::parse_surface_problem_text(text, "spheroid3d");
      for (const fictus::Point3& x : {fictus::Point3{0.3, 0.6, 0.45}, fictus::Point3{0.61, 0.42, 0.7}}) {
        ASSERT_NEAR(f(x.x, x.y, x.z), spec.problem.f(x.x, x.y, x.z), 1e-13);
        ASSERT_NEAR(g(x.x, x.y, x.z), spec.problem.g(x.x, x.y, x.z), 1e-13);
        ASSERT_NEAR(level(x.x, x.y, x.z), spec.problem.gamma->level(x), 1e-13);
      }
      // The file's bounds: the triangulation's lattice starts at their corner.
      const fictus::Box3 bounds{{0.05, 0.05, 0.05}, {0.95, 0.95, 0.95}};
      spec.problem.gamma = std::make_shared<fictus::ImplicitSurface>(level, bounds, gradient, hessian);
      spec.problem.f = f, spec.problem.g = g, spec.problem.N = N;
      spec.options.variant = variant;
      spec.options.threads = 2;
      spec.options.error_estimate = false;
      const fictus::SurfaceSolution s = fictus::solve(spec.problem, spec.options);
      ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
      const fictus::ContactSummary c = fictus::contact_summary(s);
      const double area = c.measure / ref_area - 1, whole = c.measure_points / ref_area - 1;
      double farthest = 0;  // of the located ends from the circle t = t*, along γ, in spacings
      const double rho = a * std::sqrt(1 - t_end * t_end / (b * b)), slope = a * a * t_end / (b * b * rho);
      for (const fictus::Point3& x : s.contact_boundary)
        farthest = std::max(farthest, std::abs(t_of(x) - t_end) * std::sqrt(1 + slope * slope) / s.spacing());
      const double force = c.force / ref_force - 1, integral_u = s.domain->integral_u / ref_u - 1;
      std::cout << fictus::to_string(variant) << " N = " << N << ", m = " << s.options.multipliers << ": contact area "
                << area << " (whole patches " << whole << "), ends within " << farthest << " s of the circle, force "
                << force << ", int u " << integral_u << " (relative)\n";
      // Measured 0.02 % and 0.29 % (smooth, patches of 5h; with 8h −1.7 % and −0.8 %), −0.76 % and +0.15 %.
      EXPECT_LT(std::abs(area), N == 128 ? 0.005 : 0.012);
      if (N == 128) EXPECT_LT(std::abs(area), std::abs(whole));
      EXPECT_FALSE(s.contact_boundary.empty());
      EXPECT_LT(farthest, 0.3);
      // ∫u and the force c∫u − ∫f (small here: 0.0204 against c∫u = 0.115) depend on the patches' layout
      // at about 3e-5 and 2e-4: with the lattice started at γ's tight box instead of the file's bounds
      // they were −3.2e-5 and −1.8e-4 (smooth, N = 128, patches of 8h) against 1.9e-6 and 9.8e-6 here;
      // with 5h here −4.4e-6 and −2.6e-5.
      EXPECT_LT(std::abs(force), N == 128 ? 1.5e-4 : 3e-4);
      EXPECT_LT(std::abs(integral_u), N == 128 ? 3e-5 : 5e-5);
    }
  }
}

// 3-D, not convex: the tilted peanut of revolution of tests/references/peanut3d.toml (a Cassini oval turned
// about the axis (2, 3, 6)/7; waist radius 0.079, lobes 0.116). Its reference (peanut3d.json,
// signorini_axisym.edp -shape peanut: P2 in the meridian half-plane, 1.0e6 dofs on the last level; the
// contact area to 8e-6, ∫u and the force to 1e-13) has two contact bands, so four contact circles: one
// on the upper lobe, one just above the waist and one at it (where γ is concave along its meridian,
// bounding a free band 0.054 wide: 1.4 spacings at N = 128), one below. The smooth variant at N = 128
// and 160: the area inside the located boundary (measured −1.0 % and −0.50 %; the whole patches +13 %
// and +14 %; with the law of a lone end, which narrowed the free band by 0.2 spacings per side, +9.4 % at
// N = 128), the ends' distance along the axis from each circle (measured: means within 0.066 s, rms within
// 0.11 s), the force and ∫u.
TEST(References3d, PeanutContactBands) {
  const auto [text, reference] = read_reference("peanut3d");
  const nlohmann::json& values = reference["values"];
  const double ref_area = values["contact_area"], ref_force = values["force"], ref_u = values["int_u"];
  std::vector<double> circles;
  for (double t : values["contact_ends_t"]) circles.push_back(t);
  ASSERT_EQ(circles.size(), 4u);
  const fictus::Point3 center{0.49, 0.51, 0.5}, axis{2.0 / 7, 3.0 / 7, 6.0 / 7};
  for (int N : {128, 160}) {
    fictus::SurfaceProblemSpec spec = fictus::parse_surface_problem_text(text, "peanut3d");
    spec.problem.N = N;
    spec.options.threads = 2;
    spec.options.error_estimate = false;
    const fictus::SurfaceSolution s = fictus::solve(spec.problem, spec.options);
    ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
    const fictus::ContactSummary c = fictus::contact_summary(s);
    std::vector<double> offset(4, 0.0), square(4, 0.0),
        count(4, 0.0);  // per circle: the ends' distances along the axis
    for (const fictus::Point3& x : s.contact_boundary) {
      const double t = dot(x - center, axis);
      std::size_t k = 0;
      for (std::size_t j = 1; j < 4; ++j)
        if (std::abs(t - circles[j]) < std::abs(t - circles[k])) k = j;
      offset[k] += t - circles[k], square[k] += (t - circles[k]) * (t - circles[k]), count[k] += 1;
    }
    const double area = c.measure / ref_area - 1, whole = c.measure_points / ref_area - 1;
    const double force = c.force / ref_force - 1, integral_u = s.domain->integral_u / ref_u - 1;
    std::cout << "N = " << N << ", m = " << s.options.multipliers << ": contact area " << area << " (whole patches "
              << whole << "), ends' mean offsets along the axis [s]";
    for (std::size_t k = 0; k < 4; ++k)
      std::cout << " " << offset[k] / std::max(count[k], 1.0) / s.spacing() << " (rms "
                << std::sqrt(square[k] / std::max(count[k], 1.0)) / s.spacing() << ")";
    std::cout << ", force " << force << ", int u " << integral_u << " (relative)\n";
    EXPECT_LT(std::abs(area), 0.02);
    EXPECT_LT(std::abs(area), std::abs(whole));
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_GE(count[k], 10) << "circle " << k;
      EXPECT_LT(std::abs(offset[k] / std::max(count[k], 1.0)), 0.15 * s.spacing()) << "circle " << k;
      EXPECT_LT(std::sqrt(square[k] / std::max(count[k], 1.0)), 0.25 * s.spacing()) << "circle " << k;
    }
    EXPECT_LT(std::abs(force), 3e-4);       // measured −1.4e-4 and +3.1e-5
    EXPECT_LT(std::abs(integral_u), 4e-5);  // measured −1.7e-5 and +3.9e-6
  }
}

// Mixed conditions in 3-D: the ellipsoid with a Dirichlet cap below, a Neumann cap above and the
// Signorini belt between (tests/references/ellipsoid3d_mixed.toml; ellipsoid3d_mixed.json: FreeFEM, P2 on
// curved elements fitted exactly to γ with the junction curves as element edges; ∫u to 2e-5 relative,
// the fluxes through the parts to 1e-4, pointwise u to 1.3e-4 in ω). The smooth variant at N = 96, 128.
TEST(References3d, MixedEllipsoidConvergesToTheFittedMeshSolution) {
  const auto [text, reference] = read_reference("ellipsoid3d_mixed");
  const nlohmann::json& values = reference["values"];
  const double ref_u = values["int_u"], ref_grad2 = values["int_grad2"], ref_dirichlet = values["flux_dirichlet"],
               ref_force = values["flux_signorini"], ref_contact = values["contact_area"];
  std::vector<fictus::Point3> interior;
  std::vector<double> interior_u;
  for (const auto& r : reference["interior"]) interior.push_back({r[0], r[1], r[2]}), interior_u.push_back(r[3]);
  double previous_pointwise = 1;
  std::array<double, 3> previous_part_errors{};
  for (int N : {96, 128}) {
    fictus::SurfaceProblemSpec spec = fictus::parse_surface_problem_text(text, "ellipsoid3d_mixed");
    // The file's f and g, compiled (muParser would spend most of the time): checked to agree.
    const fictus::ScalarField3 f = [](double x, double y, double) { return -4 + 0.5 * x * y; };
    const fictus::ScalarField3 g = [](double x, double y, double z) {
      return 1 + 0.6 * (x - 0.5) + 0.4 * (y - 0.5) - 0.5 * (z - 0.5) + 0.1 * std::sin(3 * x);
    };
    for (const fictus::Point3& x : {fictus::Point3{0.3, 0.6, 0.45}, fictus::Point3{0.71, 0.42, 0.6}}) {
      ASSERT_NEAR(f(x.x, x.y, x.z), spec.problem.f(x.x, x.y, x.z), 1e-14);
      ASSERT_NEAR(g(x.x, x.y, x.z), spec.problem.g(x.x, x.y, x.z), 1e-14);
    }
    spec.problem.f = f, spec.problem.g = g, spec.problem.N = N;
    spec.options.threads = 2;
    spec.options.error_estimate = false;
    const fictus::SurfaceSolution s = fictus::solve(spec.problem, spec.options);
    ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
    std::vector<double> at_samples;
    fictus::point_value_rows(s.grid, interior).multiply(s.u, at_samples);
    double pointwise = 0;
    for (std::size_t q = 0; q < interior.size(); ++q)
      pointwise = std::max(pointwise, std::abs(at_samples[q] - interior_u[q]));
    int agree = 0, samples = 0;  // contact flags on the Signorini part (boundary_part 1)
    for (std::size_t k = 0; k < reference["boundary"].size(); ++k) {
      if (int(reference["boundary_part"][k]) != 1) continue;
      const auto& r = reference["boundary"][k];
      const fictus::Point3 x{r[0], r[1], r[2]};
      int nearest = 0;
      for (int p = 1; p < s.gamma.m; ++p)
        if (norm(s.gamma.point[p] - x) < norm(s.gamma.point[nearest] - x)) nearest = p;
      ++samples;
      agree += s.in_contact(nearest) == (double(r[5]) != 0);
    }
    const fictus::ContactSummary c = fictus::contact_summary(s);
    const double rel_u = s.domain->integral_u / ref_u - 1, rel_grad2 = s.domain->integral_grad2 / ref_grad2 - 1;
    std::cout << "N = " << N << ", m = " << s.options.multipliers << ": int u " << rel_u << ", int |grad u|^2 "
              << rel_grad2 << " (relative), max |u - u_ref| " << pointwise << ", Dirichlet flux "
              << c.dirichlet.flux / ref_dirichlet - 1 << ", contact force " << c.force / ref_force - 1
              << ", contact area " << c.measure / ref_contact - 1 << " (relative), contact flags agree " << agree << "/"
              << samples << "\n";
    // Measured (docs/math.md, "Mixed conditions"): the patches follow the junction curves to within a
    // triangle, so the caps' areas are right to 1e-3; the fluxes through them and the contact area are
    // still first-order (the junctions are singular points of u) and far off at these N (contact area
    // +10 %, +5.3 % with the smooth patches of 5h; +24 %, +18 % with 8h); they fall with N, and so does the largest
    // pointwise error (beside the junction curves).
    const nlohmann::json& parts = reference["conditions"];
    EXPECT_NEAR(c.dirichlet.measure / double(parts["dirichlet_part"]["measure"]), 1, 2e-3);
    EXPECT_NEAR(c.neumann.measure / double(parts["neumann_part"]["measure"]), 1, 2e-3);
    const std::array<double, 3> part_errors = {std::abs(c.dirichlet.flux / ref_dirichlet - 1),
                                               std::abs(c.force / ref_force - 1),
                                               std::abs(c.measure / ref_contact - 1)};
    EXPECT_LT(std::abs(rel_u), 6e-3);
    EXPECT_LT(std::abs(rel_grad2), 0.04);
    EXPECT_LT(pointwise, 0.9 * previous_pointwise);
    EXPECT_LT(part_errors[0], 0.08);
    EXPECT_LT(part_errors[1], 0.3);
    EXPECT_LT(part_errors[2], 0.3);
    for (int k = 0; k < 3 && N > 96; ++k) EXPECT_LT(part_errors[std::size_t(k)], previous_part_errors[std::size_t(k)]);
    EXPECT_GE(agree, 180);
    previous_pointwise = pointwise;
    previous_part_errors = part_errors;
  }
}

// The error estimate of û (from the same problem solved at N/2, docs/math.md "The error estimate") against
// the true error on every 2-D reference, smooth variant, N = 2048: within a factor 3 (measured
// estimated/true 0.63 ellipse, 1.97 peanut, 0.69 star, 1.11 tips). Over all references, both variants and
// N = 256 … 2048, and for the other quantities: bench/results/2026-12-06-estimate-quality.md.
TEST(ReferencesEstimate, EstimateOfUWithinAFactorThree) {
  const std::string folder = std::string(FICTUS_SOURCE_DIR) + "/tests/references";
  for (const char* name : {"ellipse", "peanut", "star", "tips"}) {
    const reference::Reference reference = reference::load(folder, name);
    fictus::ProblemSpec spec = fictus::read_problem_file(folder + "/" + name + ".toml");
    spec.problem.N = 2048;
    spec.options.variant = fictus::Variant::smooth;
    spec.options.condition_number = false;
    spec.options.threads = 2;
    const fictus::Solution s = fictus::solve(spec.problem, spec.options);
    ASSERT_TRUE(s.newton.converged) << name;
    ASSERT_TRUE(s.estimate && s.estimate->skipped.empty()) << name;
    EXPECT_EQ(s.estimate->N, 1024) << name;
    const double ratio = s.estimate->rel_l2_omega / reference::compare(reference, s).level.l2_omega;
    std::cout << name << ": estimated/true relative L2(omega) error of u " << ratio << '\n';
    EXPECT_GT(ratio, 1.0 / 3) << name;
    EXPECT_LT(ratio, 3.0) << name;
  }
}

}  // namespace
