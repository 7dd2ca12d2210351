#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "fictus/boundary/surface.hpp"
#include "fictus/boundary/surface_kink.hpp"

namespace fictus {

namespace {

std::string at(const Point3& p) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "(%.4g, %.4g, %.4g)", p.x, p.y, p.z);
  return buffer;
}

double largest_side(const Box3& box) { return std::max({box.width(0), box.width(1), box.width(2)}); }

/// The six tetrahedra of a cube that share its diagonal from corner 0 to corner 7 (corner k at the
/// offsets of bits 0, 1, 2): neighbouring cubes split their common faces the same way.
constexpr int tetrahedra[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7}, {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};

}  // namespace

ImplicitSurface::ImplicitSurface(ScalarField3 level, Box3 bounds, GradientField3 gradient, HessianField3 hessian)
    : level_(std::move(level)), gradient_(std::move(gradient)), hessian_(std::move(hessian)), bounds_(bounds) {
  if (!level_) throw std::invalid_argument("geometry.level: not given");
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(bounds.lower[d]) || !std::isfinite(bounds.upper[d]) || !(bounds.upper[d] > bounds.lower[d]) ||
        !std::isfinite(bounds.width(d)))
      throw std::invalid_argument(
          "geometry.bounds: expected [x0, y0, z0, x1, y1, z1], finite, x0 < x1, y0 < y1, z0 < z1");
  // γ must stay inside the bounds: level > 0 on their faces (sampled on a 33 × 33 lattice each).
  constexpr int n = 32;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side)
      for (int b = 0; b <= n; ++b)
        for (int a = 0; a <= n; ++a) {
          Point3 p;
          p[axis] = side ? bounds.upper[axis] : bounds.lower[axis];
          const int u = (axis + 1) % 3, v = (axis + 2) % 3;
          p[u] = bounds.lower[u] + bounds.width(u) * a / n;
          p[v] = bounds.lower[v] + bounds.width(v) * b / n;
          const double value = level_(p.x, p.y, p.z);
          if (!std::isfinite(value)) throw std::invalid_argument("geometry.level: not finite at " + at(p));
          if (!(value > 0))
            throw std::invalid_argument("geometry.bounds: the surface reaches the bounding box (level <= 0 at " +
                                        at(p) + "): larger bounds");
        }
  // The tight box, the area, the checks of the gradient and the curvature from one triangulation.
  const double edge = largest_side(bounds) / 96;
  const std::vector<Triangle3> triangles = triangulate(bounds, edge);
  if (triangles.empty())
    throw std::invalid_argument("geometry.level: no surface inside geometry.bounds (level > 0 at every sample)");
  tight_.lower = tight_.upper = triangles.front().a;
  for (const Triangle3& t : triangles)
    for (const Point3& v : {t.a, t.b, t.c})
      for (int d = 0; d < 3; ++d)
        tight_.lower[d] = std::min(tight_.lower[d], v[d]), tight_.upper[d] = std::max(tight_.upper[d], v[d]);
  for (int d = 0; d < 3; ++d) {  // the vertices lie on γ; between them it bulges by about edge²κ/8
    tight_.lower[d] = std::max(bounds.lower[d], tight_.lower[d] - 0.05 * edge);
    tight_.upper[d] = std::min(bounds.upper[d], tight_.upper[d] + 0.05 * edge);
  }
  scale_ = largest_side(tight_);  // the steps of the derivatives scale with γ, not with the given box
  double typical_slope = 0;       // |level| at the box's corners over its size: the scale of the level function
  for (int c = 0; c < 8; ++c) {
    const Point3 corner{c & 1 ? bounds.upper.x : bounds.lower.x, c & 2 ? bounds.upper.y : bounds.lower.y,
                        c & 4 ? bounds.upper.z : bounds.lower.z};
    typical_slope = std::max(typical_slope, std::abs(level_(corner.x, corner.y, corner.z)) / largest_side(bounds));
  }
  double largest_concave = 0;
  for (const Triangle3& t : triangles) {
    area_ += fictus::area(t);
    const Point3 g = level_gradient(t.a);
    const double slope = norm(g);
    if (!(slope > 1e-6 * typical_slope))
      throw std::invalid_argument("geometry.level: the gradient vanishes on the surface near " + at(t.a) +
                                  " (a singular point): a level function with a nonzero gradient on its zero set");
    // Principal curvatures: the eigenvalues of P∇²φP/|∇φ| on the tangent plane.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> shape(shape_operator(g, level_hessian(t.a)));
    const Eigen::Vector3d normal(g.x / slope, g.y / slope, g.z / slope);
    int along_normal = 0;  // its eigenvalue is 0: not a curvature
    for (int k = 1; k < 3; ++k)
      if (std::abs(shape.eigenvectors().col(k).dot(normal)) >
          std::abs(shape.eigenvectors().col(along_normal).dot(normal)))
        along_normal = k;
    for (int k = 0; k < 3; ++k)
      if (k != along_normal) largest_concave = std::max(largest_concave, -shape.eigenvalues()[k]);
  }
  reach_ = largest_concave > 0 ? 1 / largest_concave : std::numeric_limits<double>::infinity();
}

double ImplicitSurface::level(const Point3& p) const { return level_(p.x, p.y, p.z); }

Point3 ImplicitSurface::level_gradient(const Point3& p) const {
  if (gradient_) return gradient_(p.x, p.y, p.z);
  const double step = 1e-5 * scale_;
  Point3 g;
  for (int d = 0; d < 3; ++d) {
    Point3 plus = p, minus = p;
    plus[d] += step;
    minus[d] -= step;
    g[d] = (level(plus) - level(minus)) / (2 * step);
  }
  return g;
}

Matrix3 ImplicitSurface::level_hessian(const Point3& p) const {
  if (hessian_) return hessian_(p);
  const double step = 1e-4 * scale_;
  const auto shifted = [&](int d, double a, int e, double b) {
    Point3 q = p;
    q[d] += a * step;
    q[e] += b * step;
    return level(q);
  };
  Matrix3 H;
  const double center = level(p);
  for (int d = 0; d < 3; ++d) {
    H[d][d] = (shifted(d, 1, d, 0) - 2 * center + shifted(d, -1, d, 0)) / (step * step);
    for (int e = 0; e < d; ++e)
      H[d][e] = H[e][d] = (shifted(d, 1, e, 1) - shifted(d, 1, e, -1) - shifted(d, -1, e, 1) + shifted(d, -1, e, -1)) /
                          (4 * step * step);
  }
  return H;
}

std::vector<Triangle3> ImplicitSurface::triangulate(const Box3& box, double edge) const {
  std::array<int, 3> cells;
  for (int d = 0; d < 3; ++d) {
    const double n = std::ceil(box.width(d) / edge);
    if (!(n <= 4096))
      throw std::invalid_argument("geometry.level: the surface would need more than 4096 cubes along an axis");
    cells[d] = std::max(2, int(n));
  }
  const auto node = [&](int i, int j, int k) {
    return Point3{box.lower.x + box.width(0) * i / cells[0], box.lower.y + box.width(1) * j / cells[1],
                  box.lower.z + box.width(2) * k / cells[2]};
  };
  const std::size_t nx = std::size_t(cells[0] + 1), ny = std::size_t(cells[1] + 1);
  std::vector<double> values(nx * ny * std::size_t(cells[2] + 1));
  for (int k = 0; k <= cells[2]; ++k)
    for (int j = 0; j <= cells[1]; ++j)
      for (int i = 0; i <= cells[0]; ++i) {
        const Point3 p = node(i, j, k);
        const double value = level(p);
        if (!std::isfinite(value)) throw std::invalid_argument("geometry.level: not finite at " + at(p));
        const bool face = i == 0 || j == 0 || k == 0 || i == cells[0] || j == cells[1] || k == cells[2];
        if (face && !(value > 0))  // a closed triangulation needs ω inside the lattice
          throw std::invalid_argument("geometry.bounds: the surface reaches the bounding box (level <= 0 at " + at(p) +
                                      "): larger bounds");
        values[(std::size_t(k) * ny + std::size_t(j)) * nx + std::size_t(i)] = value;
      }
  // The crossing on the edge a–b (f(a) < 0 ≤ f(b)) by safeguarded regula falsi.
  const auto crossing = [&](Point3 a, double fa, Point3 b, double fb) {
    double lo = 0, hi = 1;
    for (int it = 0; it < 60 && hi - lo > 1e-13; ++it) {
      double t = lo - fa * (hi - lo) / (fb - fa);
      if (!(t > lo && t < hi) || it % 3 == 2) t = 0.5 * (lo + hi);
      const double ft = level(a + t * (b - a));
      if (ft < 0)
        lo = t, fa = ft;
      else
        hi = t, fb = ft;
    }
    return a + (0.5 * (lo + hi)) * (b - a);
  };
  std::vector<Triangle3> out;
  for (int k = 0; k < cells[2]; ++k)
    for (int j = 0; j < cells[1]; ++j)
      for (int i = 0; i < cells[0]; ++i) {
        std::array<Point3, 8> p;
        std::array<double, 8> f;
        bool inside = false, outside = false;
        for (int c = 0; c < 8; ++c) {
          const int a = i + (c & 1), b = j + ((c >> 1) & 1), e = k + ((c >> 2) & 1);
          p[c] = node(a, b, e);
          f[c] = values[(std::size_t(e) * ny + std::size_t(b)) * nx + std::size_t(a)];
          (f[c] < 0 ? inside : outside) = true;
        }
        if (!(inside && outside)) continue;
        for (const auto& tet : tetrahedra) {
          std::array<int, 4> in{}, out_{};
          int n_in = 0, n_out = 0;
          for (int v : tet) (f[v] < 0 ? in[n_in++] : out_[n_out++]) = v;
          if (n_in == 0 || n_out == 0) continue;
          const auto x = [&](int a, int b) { return crossing(p[a], f[a], p[b], f[b]); };
          if (n_in == 1) {
            out.push_back({x(in[0], out_[0]), x(in[0], out_[1]), x(in[0], out_[2])});
          } else if (n_in == 3) {
            out.push_back({x(in[0], out_[0]), x(in[1], out_[0]), x(in[2], out_[0])});
          } else {  // a quadrilateral: two triangles
            const Point3 a = x(in[0], out_[0]), b = x(in[0], out_[1]), c = x(in[1], out_[1]), d = x(in[1], out_[0]);
            out.push_back({a, b, c});
            out.push_back({a, c, d});
          }
        }
      }
  std::erase_if(out, [](const Triangle3& t) { return !(fictus::area(t) > 0); });
  return out;
}

PatchedSurface ImplicitSurface::patches(int m, double edge) const {
  if (!(edge > 0)) throw std::invalid_argument("ImplicitSurface::patches: the edge length must be positive");
  PatchedSurface s;
  Box3 region = tight_;  // a margin of two cubes, so that the lattice's faces stay outside γ
  for (int d = 0; d < 3; ++d) {
    region.lower[d] = std::max(bounds_.lower[d], region.lower[d] - 2 * edge);
    region.upper[d] = std::min(bounds_.upper[d], region.upper[d] + 2 * edge);
  }
  s.triangles = triangulate(region, edge);
  if (int(s.triangles.size()) < m)
    throw std::invalid_argument("formulation.multipliers: more patches than triangles of the surface");
  const std::vector<Point3> seeds = split_into_patches(s, m);
  const double tolerance = 1e-13 * scale_;
  for (int q = 0; q < m; ++q) {
    const SurfaceFoot foot = nearest_point(*this, seeds[q], seeds[q], tolerance);
    s.point[q] = foot.foot;
    s.normal[q] = foot.normal;
  }
  return s;
}

}  // namespace fictus
