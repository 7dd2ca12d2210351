// 3-D patch integrals of the trilinear basis (surface_integrals.hpp): exact for every trilinear
// function (Σ_k f(x_k) ∫φ_k dS = ∫ f dS, the Q1 interpolant of a trilinear f being f itself), on
// triangles crossing many voxels, on voxel faces and edges, and summed over patches.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "fictus/boundary/surface_integrals.hpp"

namespace {

using fictus::Point3;
using fictus::Triangle3;

/// ∫_T f dS by the 7-point degree-5 rule on n² sub-triangles: exact for a cubic f.
double reference_integral(const Triangle3& t, const std::function<double(Point3)>& f, int n = 16) {
  const Point3 u = (1.0 / n) * (t.b - t.a), v = (1.0 / n) * (t.c - t.a);
  const double a0 = 0.333333333333333, w0 = 0.225, a1 = 0.059715871789770, b1 = 0.470142064105115,
               w1 = 0.132394152788506, a2 = 0.797426985353087, b2 = 0.101286507323456, w2 = 0.125939180544827;
  const std::vector<std::array<double, 4>> rule = {{a0, a0, a0, w0}, {a1, b1, b1, w1}, {b1, a1, b1, w1},
                                                   {b1, b1, a1, w1}, {a2, b2, b2, w2}, {b2, a2, b2, w2},
                                                   {b2, b2, a2, w2}};
  double sum = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j)
      for (int upper = 0; upper < 2; ++upper) {
        if (upper && i + j + 1 >= n) continue;
        const Point3 p = t.a + double(i) * u + double(j) * v;
        const Triangle3 s = upper ? Triangle3{p + u, p + u + v, p + v} : Triangle3{p, p + u, p + v};
        for (const auto& q : rule) sum += q[3] * fictus::area(s) * f(q[0] * s.a + q[1] * s.b + q[2] * s.c);
      }
  return sum;
}

double apply(const fictus::Grid3& grid, const std::vector<fictus::PatchWeight>& weights, int patch,
             const std::function<double(Point3)>& f) {
  double sum = 0;
  for (const fictus::PatchWeight& w : weights)
    if (w.patch == patch)
      sum += w.value * f({grid.coordinate(0, w.node[0]), grid.coordinate(1, w.node[1]), grid.coordinate(2, w.node[2])});
  return sum;
}

TEST(PatchIntegrals, ExactForTrilinearFunctionsOnTrianglesAcrossManyVoxels) {
  const fictus::Grid3 grid(fictus::Box<3>{{0, 0, 0}, {1, 1, 1}}, 16, fictus::Boundary::dirichlet);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(0.05, 0.95);
  std::vector<Triangle3> triangles;
  for (int t = 0; t < 20; ++t) {
    auto p = [&] { return Point3{coordinate(random), coordinate(random), coordinate(random)}; };
    triangles.push_back({p(), p(), p()});
  }
  // On grid planes, edges and nodes: a triangle in the plane x = 0.5, one along a voxel edge.
  triangles.push_back({{0.5, 0.1, 0.2}, {0.5, 0.8, 0.3}, {0.5, 0.4, 0.9}});
  triangles.push_back({{0.25, 0.25, 0.1}, {0.25, 0.25, 0.9}, {0.75, 0.6, 0.5}});
  std::vector<int> patch_of(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) patch_of[t] = int(t);
  const auto weights = fictus::patch_integrals(grid, triangles, patch_of, int(triangles.size()));

  const std::vector<std::function<double(Point3)>> functions = {
      [](Point3) { return 1.0; }, [](Point3 p) { return p.x - 2 * p.y + 0.5 * p.z; },
      [](Point3 p) { return p.x * p.y + p.y * p.z - p.x * p.z; },
      [](Point3 p) { return 3 * p.x * p.y * p.z - p.x + 1; }};
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::size_t k = 0; k < functions.size(); ++k) {
      const double exact = reference_integral(triangles[t], functions[k]);
      EXPECT_NEAR(apply(grid, weights, int(t), functions[k]), exact, 1e-13 * (1 + std::abs(exact)))
          << "triangle " << t << ", function " << k;
    }
  EXPECT_NEAR(apply(grid, weights, 20, functions[0]), fictus::area(triangles[20]), 1e-15);
}

TEST(PatchIntegrals, EqualTheIntegralOfTheInterpolantOfAnyFunction) {
  // Σ_k f(x_k) ∫φ_k dS = ∫ I_h f dS with I_h f the piecewise-trilinear interpolant, kinked on the voxel
  // faces: this sees the clipping (a trilinear f would not: its interpolant is f in every cell).
  const fictus::Grid3 grid(fictus::Box<3>{{0, 0, 0}, {1, 1, 1}}, 8, fictus::Boundary::dirichlet);
  const auto f = [](Point3 p) { return std::sin(7 * p.x) * std::cos(5 * p.y) + p.z * p.z * 4; };
  const auto interpolant = [&](Point3 p) {
    const double h = grid.h();
    int c[3];
    double xi[3];
    for (int d = 0; d < 3; ++d) {
      c[d] = std::min(int(p[d] / h), grid.n(d) - 1);
      xi[d] = p[d] / h - c[d];
    }
    double sum = 0;
    for (int corner = 0; corner < 8; ++corner) {
      double weight = 1;
      Point3 node;
      for (int d = 0; d < 3; ++d) {
        const int up = (corner >> d) & 1;
        weight *= up ? xi[d] : 1 - xi[d];
        node[d] = (c[d] + up) * h;
      }
      sum += weight * f(node);
    }
    return sum;
  };
  const std::vector<Triangle3> triangles = {{{0.07, 0.11, 0.13}, {0.91, 0.23, 0.37}, {0.42, 0.87, 0.71}},
                                            {{0.3, 0.3, 0.8}, {0.6, 0.35, 0.2}, {0.33, 0.9, 0.5}}};
  const auto weights = fictus::patch_integrals(grid, triangles, {0, 1}, 2);
  for (int t = 0; t < 2; ++t) {
    const double reference = reference_integral(triangles[t], interpolant, 256);
    EXPECT_NEAR(apply(grid, weights, t, f), reference, 2e-6 * std::abs(reference)) << "triangle " << t;
  }
}

TEST(PatchIntegrals, PatchesSumTheirTrianglesAndStayLocal) {
  const fictus::Grid3 grid(fictus::Box<3>{{0, 0, 0}, {1, 1, 1}}, 8, fictus::Boundary::dirichlet);
  const std::vector<Triangle3> triangles = {{{0.1, 0.1, 0.3}, {0.9, 0.2, 0.3}, {0.5, 0.9, 0.35}},
                                            {{0.1, 0.1, 0.3}, {0.5, 0.9, 0.35}, {0.2, 0.7, 0.6}}};
  const auto both = fictus::patch_integrals(grid, triangles, {0, 0}, 1);
  const auto apart = fictus::patch_integrals(grid, triangles, {0, 1}, 2);
  double total = 0, first = 0, second = 0;
  for (const auto& w : both) {
    total += w.value;
    for (int d = 0; d < 3; ++d) EXPECT_TRUE(w.node[d] >= 0 && w.node[d] <= 8);
  }
  for (const auto& w : apart) (w.patch == 0 ? first : second) += w.value;
  EXPECT_NEAR(total, fictus::area(triangles[0]) + fictus::area(triangles[1]), 1e-15);
  EXPECT_NEAR(first, fictus::area(triangles[0]), 1e-15);
  EXPECT_NEAR(second, fictus::area(triangles[1]), 1e-15);
  for (std::size_t k = 1; k < both.size(); ++k) EXPECT_LT(both[k - 1].node[2], both[k].node[2] + 1);  // sorted

  EXPECT_THROW(fictus::patch_integrals(grid, {{{0.1, 0.1, 0.1}, {1.2, 0.1, 0.1}, {0.1, 0.5, 0.1}}}, {0}, 1),
               std::invalid_argument);
  EXPECT_THROW(fictus::patch_integrals(grid, triangles, {0, 3}, 2), std::invalid_argument);
}

}  // namespace

namespace {

TEST(EllipsoidPatches, CoverTheSurfaceWithNearlyEqualPatchesAndPointsOnIt) {
  const double pi = 3.14159265358979323846;
  // A sphere: area 4πr² to the triangulation's O(edge²); an ellipsoid: points on it, normals outward.
  const fictus::PatchedSurface sphere = fictus::ellipsoid_patches({0.5, 0.5, 0.5}, {0.3, 0.3, 0.3}, 100, 0.01);
  double total = 0;
  for (double a : sphere.area) total += a;
  EXPECT_NEAR(total, 4 * pi * 0.09, 2e-3 * 4 * pi * 0.09);
  const double mean = total / sphere.m;
  for (double a : sphere.area) {
    EXPECT_GT(a, 0.7 * mean);
    EXPECT_LT(a, 1.3 * mean);
  }
  const fictus::PatchedSurface e = fictus::ellipsoid_patches({0.5, 0.4, 0.6}, {0.3, 0.2, 0.15}, 60, 0.01);
  ASSERT_EQ(int(e.point.size()), 60);
  for (int p = 0; p < e.m; ++p) {
    const Point3 q = e.point[p], n = e.normal[p];
    const double level =
        std::pow((q.x - 0.5) / 0.3, 2) + std::pow((q.y - 0.4) / 0.2, 2) + std::pow((q.z - 0.6) / 0.15, 2);
    EXPECT_NEAR(level, 1.0, 1e-13);
    EXPECT_NEAR(fictus::norm(n), 1.0, 1e-14);
    EXPECT_GT(fictus::dot(n, q - Point3{0.5, 0.4, 0.6}), 0);  // outward
  }
  for (int p : e.patch_of) EXPECT_TRUE(p >= 0 && p < e.m);
  // The patch integrals of the trilinear basis sum to the patch areas.
  const fictus::Grid3 grid(fictus::Box<3>{{0, 0, 0}, {1, 1, 1}}, 32, fictus::Boundary::dirichlet);
  const auto weights = fictus::patch_integrals(grid, e.triangles, e.patch_of, e.m);
  std::vector<double> sums(e.m, 0.0);
  for (const auto& w : weights) sums[w.patch] += w.value;
  for (int p = 0; p < e.m; ++p) EXPECT_NEAR(sums[p], e.area[p], 1e-14);
  EXPECT_THROW(fictus::ellipsoid_patches({0.5, 0.5, 0.5}, {0.3, -1, 0.3}, 10, 0.01), std::invalid_argument);
  EXPECT_THROW(fictus::ellipsoid_patches({0.5, 0.5, 0.5}, {0.3, 0.3, 0.3}, 100000, 0.05), std::invalid_argument);
}

}  // namespace
