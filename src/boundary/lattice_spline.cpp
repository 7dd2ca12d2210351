#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

#include "fictus/boundary/mesh_surface.hpp"

namespace fictus {

namespace {

/// Cubic B-spline interpolation coefficients of one line of samples s_0 … s_n in place, with
/// mirror-symmetric ends (s_{-k} = s_k, s_{n+k} = s_{n-k}): the causal and anti-causal recursions of
/// the filter 6/(z + 4 + 1/z), pole z = √3 − 2, the causal start summed over the whole mirrored line.
void interpolate_line(double* s, std::ptrdiff_t stride, int n) {
  const double z = std::sqrt(3.0) - 2;
  const auto at = [&](int k) -> double& { return s[std::ptrdiff_t(k) * stride]; };
  // c⁺_0 = (s_0 + z^n s_n + Σ_{0<k<n} (z^k + z^{2n−k}) s_k) / (1 − z^{2n}); |z|^k < 1e-23 beyond k = 40.
  constexpr int horizon = 40;
  const double zn = std::pow(z, n), z2n = zn * zn;
  double start = at(0) + zn * at(n);
  for (int k = 1; k < std::min(n, horizon); ++k) start += std::pow(z, k) * at(k);
  for (int k = std::max(1, n - horizon); k < n; ++k) start += std::pow(z, 2 * n - k) * at(k);
  at(0) = start / (1 - z2n);
  for (int k = 1; k <= n; ++k) at(k) += z * at(k - 1);
  at(n) = z / (z * z - 1) * (at(n) + z * at(n - 1));
  for (int k = n - 1; k >= 0; --k) at(k) = z * (at(k + 1) - at(k));
  for (int k = 0; k <= n; ++k) at(k) *= 6;
}

/// The four cubic B-spline weights of the nodes i−1 … i+2 at u = t − i ∈ [0, 1], and their first and
/// second derivatives in t.
void weights(double u, double w[4], double d1[4], double d2[4]) {
  const double v = 1 - u, u2 = u * u, u3 = u2 * u;
  w[0] = v * v * v / 6;
  w[1] = (3 * u3 - 6 * u2 + 4) / 6;
  w[2] = (-3 * u3 + 3 * u2 + 3 * u + 1) / 6;
  w[3] = u3 / 6;
  d1[0] = -v * v / 2;
  d1[1] = (3 * u2 - 4 * u) / 2;
  d1[2] = (-3 * u2 + 2 * u + 1) / 2;
  d1[3] = u2 / 2;
  d2[0] = v;
  d2[1] = 3 * u - 2;
  d2[2] = 1 - 3 * u;
  d2[3] = u;
}

}  // namespace

LatticeSpline::LatticeSpline(Point3 lower, double spacing, int n, std::vector<double> values)
    : lower_(lower), spacing_(spacing), n_(n), coefficients_(std::move(values)) {
  if (!(n >= 2) || !(spacing > 0) || !std::isfinite(spacing))
    throw std::invalid_argument("LatticeSpline: need n >= 2 and a positive spacing");
  const std::size_t side = std::size_t(n) + 1;
  if (coefficients_.size() != side * side * side) throw std::invalid_argument("LatticeSpline: expected (n+1)^3 values");
  const std::ptrdiff_t sx = 1, sy = std::ptrdiff_t(side), sz = sy * sy;
  for (std::size_t a = 0; a < side; ++a)  // along x, then y, then z: the tensor product of three filters
    for (std::size_t b = 0; b < side; ++b) interpolate_line(&coefficients_[(a * side + b) * side], sx, n);
  for (std::size_t a = 0; a < side; ++a)
    for (std::size_t b = 0; b < side; ++b) interpolate_line(&coefficients_[a * side * side + b], sy, n);
  for (std::size_t a = 0; a < side; ++a)
    for (std::size_t b = 0; b < side; ++b) interpolate_line(&coefficients_[a * side + b], sz, n);
}

Box3 LatticeSpline::box() const {
  Box3 b;
  b.lower = lower_;
  for (int d = 0; d < 3; ++d) b.upper[d] = lower_[d] + spacing_ * n_;
  return b;
}

double LatticeSpline::evaluate(const Point3& p, Point3* gradient, Matrix3* hessian) const {
  // Outside the box: the value at the nearest point of the box plus the distance to it; the
  // derivatives are those of the spline there, with the outward unit vector added to the gradient.
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (gradient) *gradient = {nan, nan, nan};
    if (hessian) *hessian = {Point3{nan, nan, nan}, Point3{nan, nan, nan}, Point3{nan, nan, nan}};
    return nan;
  }
  Point3 outside{0, 0, 0};
  int cell[3];
  double w[3][4], d1[3][4], d2[3][4];
  for (int d = 0; d < 3; ++d) {
    const double r = (p[d] - lower_[d]) / spacing_;
    const double clamped = std::clamp(r, 0.0, double(n_));
    outside[d] = (r - clamped) * spacing_;
    cell[d] = std::min(int(std::floor(clamped)), n_ - 1);
    weights(clamped - cell[d], w[d], d1[d], d2[d]);
  }
  const std::size_t side = std::size_t(n_) + 1;
  const auto index = [&](int i) { return std::size_t(i < 0 ? -i : i > n_ ? 2 * n_ - i : i); };  // mirror
  std::size_t xs[4];
  for (int a = 0; a < 4; ++a) xs[a] = index(cell[0] - 1 + a);
  // Contract along x for each of the 4 × 4 lines (y, z): the coefficient sums s0, and with the
  // derivatives asked for, their x-derivatives s1 and s2.
  double s0[4][4], s1[4][4], s2[4][4];
  for (int c = 0; c < 4; ++c) {
    const std::size_t k = index(cell[2] - 1 + c);
    for (int b = 0; b < 4; ++b) {
      const double* row = &coefficients_[(k * side + index(cell[1] - 1 + b)) * side];
      const double c0 = row[xs[0]], c1 = row[xs[1]], c2 = row[xs[2]], c3 = row[xs[3]];
      s0[c][b] = w[0][0] * c0 + w[0][1] * c1 + w[0][2] * c2 + w[0][3] * c3;
      if (!gradient) continue;
      s1[c][b] = d1[0][0] * c0 + d1[0][1] * c1 + d1[0][2] * c2 + d1[0][3] * c3;
      if (hessian) s2[c][b] = d2[0][0] * c0 + d2[0][1] * c1 + d2[0][2] * c2 + d2[0][3] * c3;
    }
  }
  double value = 0;
  Point3 g{0, 0, 0};
  Matrix3 H{};
  for (int c = 0; c < 4; ++c)
    for (int b = 0; b < 4; ++b) {
      const double wyz = w[1][b] * w[2][c];
      value += wyz * s0[c][b];
      if (!gradient) continue;
      g.x += wyz * s1[c][b];
      g.y += d1[1][b] * w[2][c] * s0[c][b];
      g.z += w[1][b] * d1[2][c] * s0[c][b];
      if (!hessian) continue;
      H[0][0] += wyz * s2[c][b];
      H[1][1] += d2[1][b] * w[2][c] * s0[c][b];
      H[2][2] += w[1][b] * d2[2][c] * s0[c][b];
      H[0][1] += d1[1][b] * w[2][c] * s1[c][b];
      H[0][2] += w[1][b] * d1[2][c] * s1[c][b];
      H[1][2] += d1[1][b] * d1[2][c] * s0[c][b];
    }
  const double distance = outside.x == 0 && outside.y == 0 && outside.z == 0 ? 0.0 : norm(outside);
  if (gradient) {
    *gradient = (1 / spacing_) * g;
    for (int d = 0; d < 3; ++d)
      if (outside[d] != 0) (*gradient)[d] = outside[d] / distance;  // across the box's face: outward
  }
  if (hessian) {
    const double scale = 1 / (spacing_ * spacing_);
    H[1][0] = H[0][1], H[2][0] = H[0][2], H[2][1] = H[1][2];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) H[a][b] = outside[a] != 0 || outside[b] != 0 ? 0 : H[a][b] * scale;
    *hessian = H;
  }
  return value + distance;
}

double LatticeSpline::value(const Point3& p) const { return evaluate(p, nullptr, nullptr); }

Point3 LatticeSpline::gradient(const Point3& p) const {
  Point3 g;
  evaluate(p, &g, nullptr);
  return g;
}

Matrix3 LatticeSpline::hessian(const Point3& p) const {
  Point3 g;
  Matrix3 H;
  evaluate(p, &g, &H);
  return H;
}

PolygonSoup icosphere(Point3 center, double radius, int levels) {
  if (levels < 0 || levels > 8 || !(radius > 0)) throw std::invalid_argument("icosphere: 0 <= levels <= 8, radius > 0");
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Point3> unit = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (Point3& v : unit) v = (1 / norm(v)) * v;
  std::vector<std::array<std::size_t, 3>> faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                                   {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                   {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                                   {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::size_t, std::size_t>, std::size_t> middle;
    const auto split = [&](std::size_t a, std::size_t b) {
      const auto key = std::minmax(a, b);
      const auto [it, added] = middle.try_emplace(key, unit.size());
      if (added) {
        const Point3 m = unit[a] + unit[b];
        unit.push_back((1 / norm(m)) * m);
      }
      return it->second;
    };
    std::vector<std::array<std::size_t, 3>> finer;
    for (const auto& [a, b, c] : faces) {
      const std::size_t ab = split(a, b), bc = split(b, c), ca = split(c, a);
      finer.push_back({a, ab, ca});
      finer.push_back({b, bc, ab});
      finer.push_back({c, ca, bc});
      finer.push_back({ab, bc, ca});
    }
    faces = std::move(finer);
  }
  PolygonSoup soup;
  for (const Point3& v : unit) soup.vertices.push_back(center + radius * v);
  for (const auto& [a, b, c] : faces) soup.faces.push_back({a, b, c});
  return soup;
}

}  // namespace fictus
