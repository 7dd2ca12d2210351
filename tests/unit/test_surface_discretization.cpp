// The 3-D boundary (SurfaceDiscretization) and what it rests on: trace rows on the trilinear grid, the quadrature over
// ω, and the solver's checks of its input.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "fictus/boundary/omega_quadrature.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/boundary/trace_operators.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/surface_discretization.hpp"

namespace {

using fictus::Point3;

std::string error_of(const fictus::SurfaceProblem& p, const fictus::SolverOptions& o);

double apply_row(const fictus::SparseRows& rows, int r, const fictus::Grid3& grid,
                 double (*u)(double, double, double)) {
  double sum = 0;
  for (std::size_t k = rows.row_begin[r]; k < rows.row_begin[r + 1]; ++k) {
    const auto& e = rows.entries[k];
    sum += e.value * u(grid.x(e.i), grid.y(e.j), grid.z(e.k));
  }
  return sum;
}

std::vector<Point3> random_points(int n, double lo, double hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coordinate(lo, hi);
  std::vector<Point3> points(n);
  for (Point3& p : points) p = {coordinate(rng), coordinate(rng), coordinate(rng)};
  return points;
}

std::vector<Point3> random_normals(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<Point3> normals(n);
  for (Point3& v : normals) {
    v = {normal(rng), normal(rng), normal(rng)};
    v = (1.0 / fictus::norm(v)) * v;
  }
  return normals;
}

const fictus::Grid3 grid(fictus::Box3{}, 16);

TEST(SurfaceRows, PointValuesAreExactForTrilinearFunctions) {
  auto u = [](double x, double y, double z) { return 1 + 2 * x - y + 3 * z + 5 * x * y * z - x * z; };
  const auto points = random_points(50, 0.2, 0.8, 1);
  const fictus::SparseRows rows = fictus::point_value_rows(grid, points);
  ASSERT_EQ(rows.n_rows(), 50);
  for (int r = 0; r < 50; ++r) {
    EXPECT_EQ(rows.row_begin[r + 1] - rows.row_begin[r], 8u);
    EXPECT_NEAR(apply_row(rows, r, grid, u), u(points[r].x, points[r].y, points[r].z), 1e-13);
  }
}

TEST(SurfaceRows, CenteredNormalDerivativeIsExactForQuadratics) {
  auto u = [](double x, double y, double z) { return x * x + y * z - 2 * z * z + x - 3 * x * y + 0.5 * y * y; };
  auto gradient = [](const Point3& p) { return Point3{2 * p.x + 1 - 3 * p.y, p.z - 3 * p.x + p.y, p.y - 4 * p.z}; };
  const auto points = random_points(50, 0.2, 0.8, 2);
  const auto normals = random_normals(50, 3);
  const fictus::SparseRows centered = fictus::normal_derivative_rows_centered(grid, points, normals);
  for (int r = 0; r < 50; ++r)
    EXPECT_NEAR(apply_row(centered, r, grid, u), fictus::dot(normals[r], gradient(points[r])), 1e-11);
  // The shifted rule is the voxel's gradient: exact for linear functions only.
  auto linear = [](double x, double y, double z) { return 0.5 + x - 2 * y + 4 * z; };
  const fictus::SparseRows shifted = fictus::normal_derivative_rows(grid, points, normals, grid.h());
  for (int r = 0; r < 50; ++r)
    EXPECT_NEAR(apply_row(shifted, r, grid, linear), fictus::dot(normals[r], Point3{1, -2, 4}), 1e-11);
}

TEST(SurfaceRows, OneSidedRowsUseNodesOfOmegaOnlyAndReproduceQuadratics) {
  // The independent check's ∂u/∂n (docs/math.md, "Checks"): a quadratic inside ω and anything outside.
  const fictus::Ellipsoid ellipsoid({0.52, 0.49, 0.5}, {0.3, 0.25, 0.2});
  const fictus::Grid3 fine(fictus::Box3{}, 32);
  const fictus::PatchedSurface patches = ellipsoid.patches(60, fine.h());
  const auto D =
      fictus::one_sided_rows(fine, ellipsoid, patches.point, patches.normal, fictus::OneSidedTrace::normal_derivative);
  const auto V = fictus::one_sided_rows(fine, ellipsoid, patches.point, patches.normal, fictus::OneSidedTrace::value);
  ASSERT_EQ(D.n_rows(), 60);
  auto inside = [&](const auto& e) { return ellipsoid.level({fine.x(e.i), fine.y(e.j), fine.z(e.k)}) < 0; };
  for (const auto& e : D.entries) EXPECT_TRUE(inside(e));
  auto u = [](double x, double y, double z) { return x * x + y * z - 2 * z * z + x - 3 * x * y + 0.5 * y * y; };
  auto gradient = [](const Point3& p) { return Point3{2 * p.x + 1 - 3 * p.y, p.z - 3 * p.x + p.y, p.y - 4 * p.z}; };
  for (int r = 0; r < 60; ++r) {
    const Point3 p = patches.point[r];
    EXPECT_NEAR(apply_row(V, r, fine, u), u(p.x, p.y, p.z), 1e-11);
    EXPECT_NEAR(apply_row(D, r, fine, u), fictus::dot(patches.normal[r], gradient(p)), 1e-9);
    EXPECT_GE(D.row_begin[r + 1] - D.row_begin[r], 20u);  // at least twice the 10 terms
  }
  // The independent check's cubic fit reproduces cubics (at least twice its 20 terms in nodes).
  const auto D3 =
      fictus::one_sided_rows(fine, ellipsoid, patches.point, patches.normal, fictus::OneSidedTrace::normal_derivative,
                             fictus::check_fit_degree, fictus::check_fit_radius);
  for (const auto& e : D3.entries) EXPECT_TRUE(inside(e));
  auto c = [](double x, double y, double z) { return x * x * x - 2 * x * y * z + y * y * z + z - 0.5 * y * y * y; };
  auto c_gradient = [](const Point3& p) {
    return Point3{3 * p.x * p.x - 2 * p.y * p.z, -2 * p.x * p.z + 2 * p.y * p.z - 1.5 * p.y * p.y,
                  -2 * p.x * p.y + p.y * p.y + 1};
  };
  for (int r = 0; r < 60; ++r) {
    EXPECT_NEAR(apply_row(D3, r, fine, c), fictus::dot(patches.normal[r], c_gradient(patches.point[r])), 1e-8);
    EXPECT_GE(D3.row_begin[r + 1] - D3.row_begin[r], 40u);
  }
  // A point with no node of ω near it: no fit, an error the check turns into "no check".
  const std::vector<Point3> far = {{0.05, 0.05, 0.05}};
  EXPECT_THROW(fictus::one_sided_rows(fine, ellipsoid, far, {{1, 0, 0}}, fictus::OneSidedTrace::value),
               std::runtime_error);
  const std::vector<Point3> nan = {{std::nan(""), 0.5, 0.5}};
  EXPECT_THROW(fictus::one_sided_rows(fine, ellipsoid, nan, {{1, 0, 0}}, fictus::OneSidedTrace::value),
               std::runtime_error);
}

TEST(SurfaceRows, PatchRowsAddUpToThePatchAreas) {
  const fictus::Ellipsoid ellipsoid({0.5, 0.5, 0.5}, {0.3, 0.25, 0.2});
  const fictus::PatchedSurface patches = ellipsoid.patches(20, grid.h());
  const fictus::SparseRows rows = fictus::patch_integral_rows(
      grid, fictus::patch_integrals(grid, patches.triangles, patches.patch_of, patches.m), patches.m);
  ASSERT_EQ(rows.n_rows(), 20);
  for (int p = 0; p < 20; ++p) {  // the basis sums to one (every node of these patches is interior)
    double sum = 0;
    for (std::size_t k = rows.row_begin[p]; k < rows.row_begin[p + 1]; ++k) sum += rows.entries[k].value;
    EXPECT_NEAR(sum, patches.area[p], 1e-13);
  }
}

TEST(OmegaQuadrature, VolumeOfASphereAndAnEllipsoid) {
  const fictus::Ellipsoid sphere({0.51, 0.47, 0.5}, {0.3, 0.3, 0.3});
  const double exact = 4.0 / 3.0 * std::numbers::pi * 0.027;
  // The inside lengths of the Gauss lines are clamped where γ meets a half-voxel's faces across the
  // axis, a kink the Gauss rule does not see: about 1e-6 relative (measured 2.4e-6, 1.8e-7, 8.2e-7).
  EXPECT_NEAR(fictus::omega_volume(fictus::Grid3(fictus::Box3{}, 16), sphere) / exact, 1.0, 4e-6);
  EXPECT_NEAR(fictus::omega_volume(fictus::Grid3(fictus::Box3{}, 32), sphere) / exact, 1.0, 2e-6);
  EXPECT_NEAR(fictus::omega_volume(fictus::Grid3(fictus::Box3{}, 64), sphere) / exact, 1.0, 2e-6);
  const fictus::Ellipsoid ellipsoid({0.5, 0.5, 0.5}, {0.34, 0.26, 0.2});
  const double volume = 4.0 / 3.0 * std::numbers::pi * 0.34 * 0.26 * 0.2;
  EXPECT_NEAR(fictus::omega_volume(fictus::Grid3(fictus::Box3{}, 48), ellipsoid, 4) / volume, 1.0, 2e-6);
}

TEST(Torus, PatchesQuadratureAndOffsetLimit) {
  const fictus::Torus torus({0.5, 0.5, 0.5}, 0.25, 0.1);
  const double R = 0.25, r = 0.1, pi = std::numbers::pi;
  // A tube of 9.6 cells (at N = 48, 4.8 cells: 9.5e-6).
  EXPECT_NEAR(fictus::omega_volume(fictus::Grid3(fictus::Box3{}, 96), torus) / (2 * pi * pi * R * r * r), 1.0, 2e-6);
  const fictus::PatchedSurface patches = torus.patches(60, 1.0 / 64);
  double area = 0;
  for (double a : patches.area) area += a;
  EXPECT_NEAR(area / torus.area(), 1.0, 2e-3);  // the chart's flat triangles, edges h/4 of the tube
  for (int p = 0; p < patches.m; ++p) {
    EXPECT_NEAR(torus.level(patches.point[p]), 0.0, 1e-14);
    const Point3 g = torus.level_gradient(patches.point[p]);
    EXPECT_NEAR(fictus::dot(g, patches.normal[p]) / fictus::norm(g), 1.0, 1e-12);  // outward
  }
  // Γ may not go round the tube past the axis: the offset is limited by R − r (a given offset
  // beyond it is refused; the default rule fits itself below it: spacing_rule.hpp).
  fictus::SurfaceProblem p;
  p.N = 64;
  p.gamma = std::make_shared<fictus::Torus>(Point3{0.5, 0.5, 0.5}, 0.25, 0.1);
  p.f = [](double, double, double) { return 1.0; };
  p.g = [](double, double, double) { return 0.0; };
  fictus::SolverOptions o;
  o.offset = 2.5;  // δ = 2.5·s = 12.5h ≈ 0.195 with the default patches of 5h, past R − r − 2h ≈ 0.119
  EXPECT_EQ(error_of(p, o).rfind("formulation.offset: Γ at δ = offset·s", 0), 0u) << error_of(p, o);
  EXPECT_NE(error_of(p, o).find("has no room"), std::string::npos) << error_of(p, o);
  EXPECT_THROW(fictus::Torus({0.5, 0.5, 0.5}, 0.1, 0.2), std::invalid_argument);
}

TEST(OmegaQuadrature, ErrorsOfTheInterpolantOfATrilinearFunctionVanish) {
  const fictus::Grid3 g(fictus::Box3{}, 20);
  auto u = [](double x, double y, double z) { return 1 + x - 2 * y * z + x * y * z; };
  fictus::GridVector nodal(g.n_unknowns());
  for (int k = 1; k < g.nz(); ++k)
    for (int j = 1; j < g.ny(); ++j)
      for (int i = 1; i < g.nx(); ++i) nodal[g.index(i, j, k)] = u(g.x(i), g.y(j), g.z(k));
  const fictus::Ellipsoid sphere({0.5, 0.5, 0.5}, {0.3, 0.3, 0.3});
  const fictus::PatchedSurface patches = sphere.patches(10, 0.05);
  std::vector<double> trace;
  fictus::point_value_rows(g, patches.point).multiply(nodal, trace);
  const fictus::ErrorNorms e =
      fictus::compute_errors(nodal, g, sphere, patches, trace, u, [](double x, double y, double z) {
        return Point3{1 + y * z, -2 * z + x * z, -2 * y + x * y};
      });
  EXPECT_LT(e.rel_l2_omega, 1e-13);
  EXPECT_LT(e.rel_h1semi_omega, 1e-13);
  EXPECT_LT(e.rel_l2_gamma, 1e-13);
}

fictus::SurfaceProblem small_problem(double radius, int N) {
  fictus::SurfaceProblem p;
  p.N = N;
  p.gamma = std::make_shared<fictus::Ellipsoid>(Point3{0.5, 0.5, 0.5}, Point3{radius, radius, radius});
  p.f = [](double, double, double) { return 1.0; };
  p.g = [](double x, double, double) { return 0.05 * x; };
  return p;
}

std::string error_of(const fictus::SurfaceProblem& p, const fictus::SolverOptions& o) {
  try {
    fictus::solve(p, o);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(SurfaceSolver, NamesWhatIsWrongWithItsInput) {
  fictus::SolverOptions o;
  o.variant = fictus::Variant::nonsmooth;
  o.normal_derivative = fictus::NormalDerivative::shifted;
  EXPECT_EQ(error_of(small_problem(0.49, 16), o).rfind("geometry: the surface comes within", 0), 0u);
  o.multipliers = 5000;
  EXPECT_EQ(error_of(small_problem(0.3, 16), o).rfind("formulation.multipliers", 0), 0u);
  o = {};
  EXPECT_EQ(error_of(small_problem(0.3, 16), o).rfind("formulation.offset", 0), 0u);
  o.variant = fictus::Variant::nonsmooth;
  o.normal_derivative = fictus::NormalDerivative::shifted;
  auto p = small_problem(0.2, 32);
  p.g = [](double, double, double) { return std::nan(""); };
  EXPECT_EQ(error_of(p, o).rfind("data.g: not finite", 0), 0u);
  p.g = [](double, double, double) { return 1e200; };
  EXPECT_EQ(error_of(p, o).rfind("data.g: 1e+200 is beyond", 0), 0u);
  p.g = [](double, double, double) { return 0.0; };  // (g is checked before the load)
  p.f = [](double, double, double) { return 1e300; };
  EXPECT_EQ(error_of(p, o).rfind("data.f: u0 = A^-1 f reaches", 0), 0u);
  EXPECT_THROW(fictus::Ellipsoid({0, 0, 0}, {1, -1, 1}), std::invalid_argument);
}

/// c = 0 on a periodic box: A is singular, the Newton system is bordered by the constants. With
/// −Δu = f in ω, ∫_γ ∂u/∂n = −∫_ω f must be ≥ 0: f = −1.
fictus::SurfaceProblem periodic_without_reaction(double radius, int N) {
  fictus::SurfaceProblem p = small_problem(radius, N);
  p.boundary = fictus::Boundary::periodic;
  p.c = 0;
  p.f = [](double, double, double) { return -1.0; };
  return p;
}

TEST(SurfaceSolver, PeriodicBoxWithoutReactionSolves) {
  const fictus::SurfaceProblem p = periodic_without_reaction(0.2, 32);
  fictus::SolverOptions o;
  o.variant = fictus::Variant::nonsmooth;
  o.normal_derivative = fictus::NormalDerivative::shifted;
  const fictus::SurfaceSolution s = fictus::solve(p, o);
  ASSERT_TRUE(s.newton.converged);
  EXPECT_GT(s.signorini.min_gap, -1e-12);
  EXPECT_GT(s.signorini.min_normal_derivative, -1e-10);
  EXPECT_LT(s.signorini.max_complementarity, 1e-12);
}

TEST(SurfaceSolver, PeriodicBoxWithoutReactionWithTheFarFieldInterpolated) {
  // The bordered system (λ, α) through the interpolated S̃ and the exact S: the same answer as the
  // exact assembly.
  const fictus::SurfaceProblem p = periodic_without_reaction(0.3, 48);
  fictus::SolverOptions o;
  o.variant = fictus::Variant::nonsmooth;
  o.threads = 2;
  o.far_field = false;
  const fictus::SurfaceSolution exact = fictus::solve(p, o);
  o.far_field = true;
  const fictus::SurfaceSolution far = fictus::solve(p, o);
  ASSERT_TRUE(exact.newton.converged && far.newton.converged);
  ASSERT_TRUE(far.far_field.has_value());
  EXPECT_EQ(far.newton.active, exact.newton.active);
  double largest = 0, difference = 0;
  for (std::size_t i = 0; i < far.lambda.size(); ++i) {
    largest = std::max(largest, std::abs(exact.lambda[i]));
    difference = std::max(difference, std::abs(far.lambda[i] - exact.lambda[i]));
  }
  EXPECT_LT(difference, 1e-10 * largest);
  EXPECT_NEAR(far.alpha, exact.alpha, 1e-10 * std::abs(exact.alpha) + 1e-12);
  EXPECT_LT(far.signorini.max_complementarity, 1e-12);
}

}  // namespace

namespace {

TEST(ImplicitSurface, SphereAndTorusFromTheirLevelFunctions) {
  // A sphere: the area from the marching-tetrahedra triangulation, no fold for outward offsets, the
  // points of the patches on γ with unit outward normals.
  const Point3 c{0.5, 0.5, 0.5};
  const fictus::ImplicitSurface sphere(
      [c](double x, double y, double z) {
        return (x - c.x) * (x - c.x) + (y - c.y) * (y - c.y) + (z - c.z) * (z - c.z) - 0.09;
      },
      fictus::Box3{{0.1, 0.1, 0.1}, {0.9, 0.9, 0.9}});
  EXPECT_NEAR(sphere.area(), 4 * std::numbers::pi * 0.09, 2e-3 * 4 * std::numbers::pi * 0.09);
  EXPECT_TRUE(std::isinf(sphere.reach()));
  EXPECT_NEAR(sphere.bounds().lower.x, 0.2, 1e-3);
  EXPECT_NEAR(sphere.bounds().upper.z, 0.8, 1e-3);
  const fictus::PatchedSurface patches = sphere.patches(50, 1.0 / 64);
  ASSERT_EQ(patches.m, 50);
  double total = 0;
  for (int p = 0; p < patches.m; ++p) {
    EXPECT_NEAR(norm(patches.point[p] - c), 0.3, 1e-12);
    EXPECT_NEAR(dot(patches.normal[p], (1 / 0.3) * (patches.point[p] - c)), 1.0, 1e-9);
    total += patches.area[p];
  }
  EXPECT_NEAR(total, 4 * std::numbers::pi * 0.09, 2e-3);
  // A torus: its offsets fold at the axis, R − r from the inner equator (the concave side's largest
  // principal curvature 1/(R − r)), and the implicit torus solves the built-in torus's problem alike.
  const double R = 0.25, r = 0.1;
  const fictus::ImplicitSurface torus(
      [c, R, r](double x, double y, double z) {
        const double planar = std::hypot(x - c.x, y - c.y) - R;
        return planar * planar + (z - c.z) * (z - c.z) - r * r;
      },
      fictus::Box3{{0.05, 0.05, 0.3}, {0.95, 0.95, 0.7}});
  EXPECT_NEAR(torus.reach(), R - r, 0.02 * (R - r));
  EXPECT_NEAR(torus.area(), 4 * std::numbers::pi * std::numbers::pi * R * r, 3e-3);
}

TEST(ImplicitSurface, NamesWhatIsWrongWithTheLevelFunction) {
  const fictus::Box3 box{{0.1, 0.1, 0.1}, {0.9, 0.9, 0.9}};
  const auto message = [&](fictus::ScalarField3 level, fictus::Box3 b) {
    try {
      fictus::ImplicitSurface s(std::move(level), b);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const auto ball = [](double x, double y, double z) {
    return (x - .5) * (x - .5) + (y - .5) * (y - .5) + (z - .5) * (z - .5) - 0.09;
  };
  EXPECT_NE(message(ball, {{0.25, 0.1, 0.1}, {0.9, 0.9, 0.9}}).find("geometry.bounds: the surface reaches"),
            std::string::npos);
  EXPECT_NE(message(ball, {{0.9, 0.1, 0.1}, {0.1, 0.9, 0.9}}).find("geometry.bounds: expected"), std::string::npos);
  EXPECT_NE(message(ball, {{-1e308, 0.1, 0.1}, {1e308, 0.9, 0.9}}).find("geometry.bounds: expected"),
            std::string::npos);
  EXPECT_NE(message([&](double x, double y, double z) { return std::pow(ball(x, y, z), 3); }, box)
                .find("geometry.level: the gradient vanishes"),
            std::string::npos);
  EXPECT_NE(message([&](double x, double y, double z) { return ball(x, y, z) + 0.1; }, box)
                .find("geometry.level: no surface"),
            std::string::npos);
  EXPECT_NE(
      message([&](double x, double y, double z) { return std::abs(x - 0.5) < 0.02 ? std::nan("") : ball(x, y, z); },
              box)
          .find("geometry.level: not finite"),
      std::string::npos);
}

}  // namespace

namespace {

/// max |a − b| / max |b| over the multipliers.
double lambda_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double largest = 0, difference = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    largest = std::max(largest, std::abs(b[i]));
    difference = std::max(difference, std::abs(a[i] - b[i]));
  }
  return difference / largest;
}

TEST(SurfaceSolver, HierarchicalSchurGivesTheDenseAnswer) {
  // Both variants on a sphere with partial contact: Newton on the compressed S̃ (GMRES, block LUs), then
  // refined on the exact S, against the dense path (LU on S̃, then GMRES on the exact S).
  const fictus::SurfaceProblem p = small_problem(0.3, 48);
  for (const fictus::Variant v : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    fictus::SolverOptions o;
    o.variant = v;
    o.threads = 2;
    o.error_estimate = false;
    o.schur_storage = fictus::SchurStorageKind::dense;
    const fictus::SurfaceSolution dense = fictus::solve(p, o);
    o.schur_storage = fictus::SchurStorageKind::hierarchical;
    const fictus::SurfaceSolution h = fictus::solve(p, o);
    const char* variant = fictus::to_string(v);
    ASSERT_TRUE(dense.newton.converged && h.newton.converged) << variant;
    ASSERT_TRUE(dense.schur_storage && h.schur_storage) << variant;
    EXPECT_EQ(dense.schur_storage->kind, "dense");
    EXPECT_EQ(h.schur_storage->kind, "hierarchical");
    EXPECT_LE(h.schur_storage->bytes, h.schur_storage->dense_bytes * 1.1) << variant;  // no gain at m ≈ 500
    EXPECT_EQ(h.newton.active, dense.newton.active) << variant;
    EXPECT_LT(lambda_difference(h.lambda, dense.lambda), 1e-9) << variant;
    EXPECT_LT(h.signorini.max_complementarity, 1e-12) << variant;
    EXPECT_GT(h.inner_iterations, 0) << variant;
  }
}

TEST(SurfaceSolver, EstimatesFollowTheSchurStorage) {
  // bench/sphere_contact.toml at N = 512, non-smooth (m = 12 868), measured on 2 threads
  // (bench/results/2026-11-28-compressed-schur-assembly.md): peak 8.16 GiB dense, 5.07 GiB compressed.
  fictus::SurfaceProblem p = small_problem(0.25, 512);
  fictus::SolverOptions o;
  o.variant = fictus::Variant::nonsmooth;
  o.threads = 2;
  const double GiB = double(1 << 30);
  o.schur_storage = fictus::SchurStorageKind::dense;
  o.condition_number = false;  // as in the measured runs (below)
  const double dense = double(fictus::estimated_peak_bytes(p, o)) / GiB;
  const double dense_seconds = fictus::estimated_seconds(p, o);
  o.schur_storage = fictus::SchurStorageKind::automatic;  // compressed from m = 5000 on in 3-D
  const double automatic = double(fictus::estimated_peak_bytes(p, o)) / GiB;
  EXPECT_NEAR(dense, 8.16, 0.15 * 8.16);
  EXPECT_NEAR(automatic, 5.07, 0.15 * 5.07);
  EXPECT_LT(fictus::estimated_seconds(p, o), dense_seconds);
  {  // cond₂ of the Newton matrix costs the dense path about 1.2e-7·m² s and one LU of 1.5e-11·m³ s
     // (m = 12 868: 20 s and 32 s), the compressed one nothing (it has no LU of S_𝒜, and no value)
    fictus::SolverOptions with = o;
    with.condition_number = true;
    EXPECT_EQ(fictus::estimated_seconds(p, with), fictus::estimated_seconds(p, o));
    with.schur_storage = fictus::SchurStorageKind::dense;
    const double m = 12868;
    EXPECT_NEAR(fictus::estimated_seconds(p, with) - dense_seconds, 1.2e-7 * m * m + 1.5e-11 * m * m * m, 1.0);
  }
  // The times of the same solves (bench/results/2026-11-28-pruned-products.md): 143 s dense, 93 s
  // compressed, to within the machine's own variation between runs and sessions.
  EXPECT_NEAR(dense_seconds, 143, 0.3 * 143);
  EXPECT_NEAR(fictus::estimated_seconds(p, o), 93, 0.3 * 93);
  // A singular A keeps the dense blocks, and so does the estimate.
  p.boundary = fictus::Boundary::periodic;
  p.c = 0;
  const double singular = double(fictus::estimated_peak_bytes(p, o)) / GiB;
  p.c = 1;
  EXPECT_GT(singular, double(fictus::estimated_peak_bytes(p, o)) / GiB + 2.0);
}

TEST(SurfaceSolver, HierarchicalSchurKeepsASingularBoxDense) {
  // The bordering (constants in A's null space) is dense only: a warning, and the dense answer.
  const fictus::SurfaceProblem p = periodic_without_reaction(0.2, 32);
  fictus::SolverOptions o;
  o.variant = fictus::Variant::nonsmooth;
  o.schur_storage = fictus::SchurStorageKind::hierarchical;
  const fictus::SurfaceSolution s = fictus::solve(p, o);
  ASSERT_TRUE(s.newton.converged);
  ASSERT_TRUE(s.schur_storage.has_value());
  EXPECT_EQ(s.schur_storage->kind, "dense");
  bool warned = false;
  for (const std::string& w : s.warnings) warned = warned || w.find("solver.schur_storage") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
