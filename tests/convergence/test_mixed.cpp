// Mixed conditions on γ (docs/math.md, "Mixed conditions"): a Dirichlet part (u = u_D), a Neumann part
// (∂u/∂n = q) and the Signorini conditions on the rest, in both dimensions and both variants.
//   - With no Signorini point the problem is linear: one Newton step, second order against a closed form.
//   - The manufactured Signorini solutions (tests/convergence/manufactured*.py) with a Dirichlet cap deep
//     in the contact set and a Neumann cap deep in the free set, their data from the exact solution: the
//     solution is the same smooth u, the junctions lie where u is smooth, contact ends stay on the
//     Signorini part. The L²(ω) rate is that of the pure Signorini problem.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "fictus/solve/convergence_table.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "manufactured_solutions.hpp"
#include "manufactured_solutions_3d.hpp"

namespace {

using fictus::BasicProblem;
using fictus::BasicSolution;
using fictus::Point;
using fictus::PointCondition;

template <int dim>
double value(const typename fictus::Fields<dim>::Scalar& f, const Point<dim>& x) {
  if constexpr (dim == 2)
    return f(x[0], x[1]);
  else
    return f(x[0], x[1], x[2]);
}

template <int dim>
double normal_derivative(const BasicProblem<dim>& p, const Point<dim>& x, const Point<dim>& n) {
  if constexpr (dim == 2)
    return fictus::dot(p.exact_gradient(x[0], x[1]), n);
  else
    return fictus::dot(p.exact_gradient(x[0], x[1], x[2]), n);
}

template <int dim>
fictus::SolverOptions options(fictus::Variant variant) {
  fictus::SolverOptions o;
  o.variant = variant;
  o.threads = 2;
  o.error_estimate = false;  // the rates of the solve itself
  o.condition_number = false;
  return o;
}

/// The exact data of `p` on the parts `dirichlet` and `neumann` (u there, and ∇u·n).
template <int dim>
void exact_parts(BasicProblem<dim>& p, std::function<double(const Point<dim>&)> dirichlet,
                 std::function<double(const Point<dim>&)> neumann) {
  const auto exact = p.exact;
  const BasicProblem<dim> copy = p;
  p.conditions.dirichlet = std::move(dirichlet);
  p.conditions.neumann = std::move(neumann);
  if (p.conditions.dirichlet) p.conditions.u = [exact](const Point<dim>& x) { return value<dim>(exact, x); };
  if (p.conditions.neumann)
    p.conditions.flux = [copy](const Point<dim>& x, const Point<dim>& n) { return normal_derivative<dim>(copy, x, n); };
}

/// Caps of γ about the centre c: the points within `angle` of the direction from c to the point where
/// the exact flux is largest (Dirichlet: deep in the contact set) and to the point of the widest gap
/// (Neumann: deep in the free set), found on a solve's points.
template <int dim>
void caps(BasicProblem<dim>& p, const BasicSolution<dim>& s, Point<dim> c, double angle) {
  int deepest = 0, widest = 0;
  double flux = -1, gap = -1;
  for (int i = 0; i < s.n_points(); ++i) {
    const Point<dim>& x = s.points()[std::size_t(i)];
    const double q = normal_derivative<dim>(p, x, s.normals()[std::size_t(i)]);
    const double r = value<dim>(p.exact, x) - value<dim>(p.g, x);
    if (q > flux) flux = q, deepest = i;
    if (r > gap) gap = r, widest = i;
  }
  const auto cap = [c, angle](Point<dim> axis) {
    axis = (1 / fictus::norm(axis - c)) * (axis - c);
    return [c, axis, cos_angle = std::cos(angle)](const Point<dim>& x) {
      return fictus::dot(x - c, axis) > cos_angle * fictus::norm(x - c) ? 1.0 : 0.0;
    };
  };
  exact_parts<dim>(p, cap(s.points()[std::size_t(deepest)]), cap(s.points()[std::size_t(widest)]));
}

template <int dim>
fictus::LevelResult level_of(const BasicSolution<dim>& s) {
  return {s.grid.nx(),     s.grid.n_nodes(),       s.n_points(),           s.newton.iterations,   s.fast_solves,
          s.timings.total, s.errors->rel_l2_omega, s.errors->rel_h1_omega, s.errors->rel_l2_gamma};
}

/// Solves `p` (parts already set) at each N; checks that every part is there, the Signorini part has
/// contact and free points, the conditions hold at their points; returns the rows.
template <int dim>
std::vector<fictus::LevelResult> levels(BasicProblem<dim> p, const std::vector<int>& sizes, fictus::Variant variant) {
  std::vector<fictus::LevelResult> rows;
  for (int N : sizes) {
    p.N = N;
    const BasicSolution<dim> s = fictus::solve(p, options<dim>(variant));
    EXPECT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
    const fictus::ContactSummary c = fictus::contact_summary(s);
    EXPECT_GT(c.dirichlet.points, 0);
    EXPECT_GT(c.neumann.points, 0);
    EXPECT_GT(c.points, 0);                   // contact on the Signorini part
    EXPECT_LT(c.points, c.signorini.points);  // and free points
    EXPECT_EQ(c.dirichlet.points + c.neumann.points + c.signorini.points, s.n_points());
    for (int i = 0; i < s.n_points(); ++i) {  // the equations of the fixed points hold (Newton's tolerance)
      if (s.condition(i) == PointCondition::dirichlet) EXPECT_NEAR(s.newton.trace(i), s.g[std::size_t(i)], 1e-8) << i;
      if (s.condition(i) == PointCondition::neumann)
        EXPECT_NEAR(s.newton.normal_derivative(i), s.conditions.flux(i), 1e-7) << i;
    }
    rows.push_back(level_of(s));
  }
  return rows;
}

// ---- linear problems: no Signorini point ----------------------------------------------------------

double u2(double x, double y) { return 1 + std::sin(2 * x + y); }
double f2(double x, double y) { return 5 * std::sin(2 * x + y) + u2(x, y); }  // c = 1
double u3(double x, double y, double z) { return 1 + std::sin(2 * x + y - z); }
double f3(double x, double y, double z) { return 6 * std::sin(2 * x + y - z) + u3(x, y, z); }

template <int dim>
BasicProblem<dim> linear_problem(int N, const std::string& kind) {
  BasicProblem<dim> p;
  p.N = N;
  p.c = 1.0;
  if constexpr (dim == 2) {
    p.gamma = std::make_shared<fictus::Ellipse>(fictus::Point2{0.5, 0.5}, 0.3, 0.22, 0.3);
    p.f = f2, p.exact = u2;
    p.exact_gradient = [](double x, double y) { return fictus::Point2{2 * std::cos(2 * x + y), std::cos(2 * x + y)}; };
    p.g = [](double, double) { return -10.0; };
  } else {
    p.gamma = std::make_shared<fictus::Ellipsoid>(fictus::Point3{0.5, 0.5, 0.5}, fictus::Point3{0.25, 0.21, 0.18});
    p.f = f3, p.exact = u3;
    p.exact_gradient = [](double x, double y, double z) {
      const double c = std::cos(2 * x + y - z);
      return fictus::Point3{2 * c, c, -c};
    };
    p.g = [](double, double, double) { return -10.0; };
  }
  const auto all = [](const Point<dim>&) { return 1.0; };
  const auto left = [](const Point<dim>& x) { return x[0] < 0.5 ? 1.0 : 0.0; };
  const auto right = [](const Point<dim>& x) { return x[0] < 0.5 ? 0.0 : 1.0; };
  if (kind == "dirichlet") exact_parts<dim>(p, all, nullptr);
  if (kind == "neumann") exact_parts<dim>(p, nullptr, all);
  if (kind == "both") exact_parts<dim>(p, left, right);
  return p;
}

/// The lowest least-squares L²(ω) order accepted for each kind, smooth and non-smooth (measured:
/// docs/math.md, "Mixed conditions"). The non-smooth variant's readings of a Neumann part carry the bias
/// of its mean flux (no flux balance in 2-D; the 3-D one leaves the mean flux right but not each reading).
struct LinearBands {
  double dirichlet[2], neumann[2], both[2];
};

template <int dim>
void linear_in_one_step(const std::vector<int>& sizes, double largest_error, const LinearBands& bands) {
  for (const std::string kind : {"dirichlet", "neumann", "both"})
    for (const auto variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
      std::vector<fictus::LevelResult> rows;
      for (int N : sizes) {
        const BasicSolution<dim> s = fictus::solve(linear_problem<dim>(N, kind), options<dim>(variant));
        ASSERT_TRUE(s.newton.converged) << kind << ", N = " << N << ": " << s.newton.failure;
        // one linear solve; in 3-D one on the interpolated far field and one on the exact S
        EXPECT_LE(s.newton.iterations, s.far_field ? 2 : 1) << kind;
        EXPECT_EQ(fictus::contact_summary(s).points, 0) << kind;
        rows.push_back(level_of(s));
      }
      const int v = variant == fictus::Variant::smooth ? 0 : 1;
      const double lowest = kind == "dirichlet" ? bands.dirichlet[v]
                            : kind == "neumann" ? bands.neumann[v]
                                                : bands.both[v];
      std::cout << fictus::format_convergence_table(std::to_string(dim) + "-D " + kind, rows, variant);
      EXPECT_LT(rows.back().l2_omega, largest_error) << kind << ", " << fictus::to_string(variant);
      EXPECT_GE(fictus::fitted_rates(rows)[0], lowest) << kind << ", " << fictus::to_string(variant);
    }
}

TEST(MixedConditions, LinearProblemsSolveInOneStep2d) {
  linear_in_one_step<2>({256, 512, 1024}, 5e-4, {{1.8, 1.8}, {1.8, 0.8}, {1.6, 0.8}});
}
TEST(MixedConditions, LinearProblemsSolveInOneStep3d) {
  // Measured over N = 64 … 128 (docs/math.md, "Mixed conditions"): smooth 2.29, 3.74, 3.27; non-smooth 2.80,
  // 2.57, 2.49 (still pre-asymptotic).
  linear_in_one_step<3>({64, 96, 128}, 3e-3, {{1.8, 1.8}, {1.8, 1.8}, {1.8, 1.8}});
}

/// The points are placed part by part: the parts' measures are those of γ's parts (the plane x = 0.5
/// through the centre halves the ellipse and the ellipsoid: central symmetry), to the arc-length table
/// in 2-D and to the triangles (edge h) the plane cuts in 3-D; the located junctions lie on the plane.
template <int dim>
void parts_follow_the_junctions(int N, double tolerance) {
  for (const auto variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    const BasicSolution<dim> s = fictus::solve(linear_problem<dim>(N, "both"), options<dim>(variant));
    const fictus::ContactSummary c = fictus::contact_summary(s);
    const double total = c.dirichlet.measure + c.neumann.measure;
    EXPECT_NEAR(c.dirichlet.measure / total, 0.5, tolerance) << fictus::to_string(variant);
    EXPECT_NEAR(c.neumann.measure / total, 0.5, tolerance) << fictus::to_string(variant);
    ASSERT_FALSE(s.junctions.empty());
    for (const auto& junction : s.junctions) EXPECT_NEAR(junction.at[0], 0.5, 0.25 * s.spacing());
  }
}

TEST(MixedConditions, PartsFollowTheJunctions2d) { parts_follow_the_junctions<2>(512, 1e-9); }
TEST(MixedConditions, PartsFollowTheJunctions3d) { parts_follow_the_junctions<3>(48, 1e-2); }  // 0.67 % measured

TEST(MixedConditions, AllNeumannWithoutReactionIsRefused) {
  BasicProblem<2> p = linear_problem<2>(64, "neumann");
  p.c = 0;
  p.f = [](double, double) { return 0.0; };
  try {
    fictus::solve(p, options<2>(fictus::Variant::smooth));
    FAIL() << "expected a refusal";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("conditions.neumann: covers all of gamma with c = 0"), std::string::npos)
        << e.what();
  }
}

// ---- manufactured Signorini solutions with Dirichlet and Neumann caps -----------------------------

struct Case2d {
  std::string name;
  fictus::Variant variant;
  double lowest_rate;
};

class Mixed2d : public ::testing::TestWithParam<Case2d> {};

TEST_P(Mixed2d, ConvergesLikeThePureSignoriniProblem) {
  const Case2d& c = GetParam();
  fictus::Problem p;
  for (const auto& m : manufactured::all(256))
    if (m.name == c.name) p = m.problem;
  const fictus::Solution pure = fictus::solve(p, options<2>(c.variant));
  const fictus::Problem signorini = p;
  caps<2>(p, pure, p.gamma->center(), 0.35);
  const std::vector<fictus::LevelResult> rows = levels<2>(p, {256, 512, 1024}, c.variant);
  std::cout << fictus::format_convergence_table("mixed " + c.name, rows, c.variant);
  // About the errors of the Signorini problem on all of γ: the caps move the points (placed part by part),
  // which moves the non-smooth variant's errors by up to about half (measured: 0.80–1.51 at N = 256 …
  // 1024) and the smooth one's by less than a fifth.
  const double spread = c.variant == fictus::Variant::smooth ? 0.25 : 0.6;
  for (const fictus::LevelResult& r : rows) {
    fictus::Problem q = signorini;
    q.N = r.N;
    const double e = fictus::solve(q, options<2>(c.variant)).errors->rel_l2_omega;
    EXPECT_NEAR(r.l2_omega / e, 1.0, spread) << "N = " << r.N << ": " << r.l2_omega << " against " << e;
  }
  const auto fit = fictus::fitted_rates(rows);
  EXPECT_GE(fit[0], c.lowest_rate);
  EXPECT_LT(rows.back().l2_omega, 3e-4);
}

INSTANTIATE_TEST_SUITE_P(
    Manufactured, Mixed2d,
    ::testing::Values(Case2d{"circle", fictus::Variant::smooth, 1.8}, Case2d{"circle", fictus::Variant::nonsmooth, 1.5},
                      Case2d{"ellipse", fictus::Variant::smooth, 1.8},
                      Case2d{"ellipse", fictus::Variant::nonsmooth, 1.5}, Case2d{"star", fictus::Variant::smooth, 1.8},
                      Case2d{"star", fictus::Variant::nonsmooth, 1.5}),
    [](const auto& info) {
      return info.param.name + (info.param.variant == fictus::Variant::smooth ? "_smooth" : "_nonsmooth");
    });

/// 3-D: the sphere and the torus, caps chosen at the coarsest N. The caps' data are those of the
/// Signorini solution on all of γ, so the errors should stay near that problem's at every N: the caps
/// only change where the points go (placed part by part). `spread` bounds the ratio's distance from 1.
void mixed_3d(const std::string& name, const std::vector<int>& sizes, fictus::Variant variant, double lowest_rate,
              double spread) {
  fictus::SurfaceProblem p;
  for (const auto& m : manufactured3d::all(sizes.front()))
    if (m.name == name) p = m.problem;
  const fictus::SurfaceProblem signorini = p;
  const fictus::SurfaceSolution pure = fictus::solve(p, options<3>(variant));
  caps<3>(p, pure, fictus::Point3{0.5, 0.5, 0.5}, 0.45);
  const std::vector<fictus::LevelResult> rows = levels<3>(p, sizes, variant);
  std::cout << fictus::format_convergence_table("mixed " + name + ", 3-D", rows, variant);
  for (const fictus::LevelResult& r : rows) {
    fictus::SurfaceProblem q = signorini;
    q.N = r.N;
    const double e =
        r.N == pure.grid.nx() ? pure.errors->rel_l2_omega : fictus::solve(q, options<3>(variant)).errors->rel_l2_omega;
    std::cout << "N = " << r.N << ": " << r.l2_omega << " with the caps, " << e << " without (ratio " << r.l2_omega / e
              << ")\n";
    EXPECT_NEAR(r.l2_omega / e, 1.0, spread) << "N = " << r.N << ": " << r.l2_omega << " against " << e;
  }
  EXPECT_GE(fictus::fitted_rates(rows)[0], lowest_rate);
}

// Measured against the Signorini problem on all of γ (ratios at the three N): sphere smooth 0.97, 0.99,
// 0.99 with the smooth patches of 5h (1.22, 0.85, 0.99 with 8h), non-smooth 1.00, 0.96, 1.04; torus
// smooth 1.06, 1.00, 1.10, non-smooth 1.05, 0.94, 1.17. With every point at its nearest triangle's centroid the
// non-smooth sphere's were 1.04, 1.24, 1.67 (order 1.49) and the torus's 1.14, 2.08, 7.4 (its error grew with N, order
// −2.25). The smooth sphere's 1.22 with 8h was at N = 64, before its errors settled (order 3.8 over the three N; 2.02
// with 5h).
TEST(Mixed3d, SphereSmooth) { mixed_3d("sphere", {64, 96, 128}, fictus::Variant::smooth, 1.8, 0.3); }
// The non-smooth sphere over three grids (a minute) and the torus (several minutes) carry the label slow; the
// default suite keeps the non-smooth sphere's ratios at N = 64 and 96 (1.00, 0.96; 1.04, 1.24 with the points at
// the centroids) and its order from 64 to 96 (2.18).
TEST(Mixed3d, SphereNonSmoothOnTwoGrids) { mixed_3d("sphere", {64, 96}, fictus::Variant::nonsmooth, 1.8, 0.15); }
TEST(Mixed3dSlow, DISABLED_SphereNonSmooth) { mixed_3d("sphere", {64, 96, 128}, fictus::Variant::nonsmooth, 1.8, 0.3); }
TEST(Mixed3dSlow, DISABLED_TorusSmooth) { mixed_3d("torus", {128, 160, 192}, fictus::Variant::smooth, 1.8, 0.3); }
TEST(Mixed3dSlow, DISABLED_TorusNonSmooth) { mixed_3d("torus", {128, 160, 192}, fictus::Variant::nonsmooth, 1.8, 0.3); }

}  // namespace
