#include "fictus/surface_integrals.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

namespace fictus {

namespace {

using Polygon = std::vector<Point3>;

Point3 cross(const Point3& u, const Point3& v) {
  return {u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
}

/// The part of a convex polygon where sign·(p[axis] − plane) ≥ 0 (Sutherland–Hodgman, one plane).
Polygon clip(const Polygon& polygon, int axis, double plane, double sign) {
  Polygon out;
  const std::size_t n = polygon.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Point3& p = polygon[k];
    const Point3& q = polygon[(k + 1) % n];
    const double dp = sign * (p[axis] - plane), dq = sign * (q[axis] - plane);
    if (dp >= 0) out.push_back(p);
    if ((dp > 0 && dq < 0) || (dp < 0 && dq > 0)) {
      const double s = dp / (dp - dq);
      Point3 x = p + s * (q - p);
      x[axis] = plane;  // exactly on the plane
      out.push_back(x);
    }
  }
  return out;
}

/// Splits each polygon into its parts in the slabs [lower + k·h, lower + (k+1)·h] of one axis.
std::vector<Polygon> split(const std::vector<Polygon>& polygons, int axis, double lower, double h, int cells) {
  std::vector<Polygon> out;
  for (const Polygon& polygon : polygons) {
    double low = polygon[0][axis], high = low;
    for (const Point3& p : polygon) low = std::min(low, p[axis]), high = std::max(high, p[axis]);
    const int first = std::clamp(int(std::floor((low - lower) / h)), 0, cells - 1);
    const int last = std::clamp(int(std::floor((high - lower) / h)), 0, cells - 1);
    if (first == last) {
      out.push_back(polygon);
      continue;
    }
    for (int k = first; k <= last; ++k) {
      Polygon piece = clip(polygon, axis, lower + k * h, 1.0);
      if (piece.size() >= 3) piece = clip(piece, axis, lower + (k + 1) * h, -1.0);
      if (piece.size() >= 3) out.push_back(std::move(piece));
    }
  }
  return out;
}

/// The symmetric 6-point rule of degree 4 on a triangle (barycentric points, weights summing to 1).
struct TrianglePoint {
  double l0, l1, l2, w;
};
const std::vector<TrianglePoint>& degree4_rule() {
  static const std::vector<TrianglePoint> rule = [] {
    const double a1 = 0.445948490915965, w1 = 0.223381589678011;
    const double a2 = 0.091576213509771, w2 = 0.109951743655322;
    std::vector<TrianglePoint> r;
    for (auto [a, w] : {std::pair{a1, w1}, std::pair{a2, w2}}) {
      const double b = 1 - 2 * a;
      r.push_back({b, a, a, w});
      r.push_back({a, b, a, w});
      r.push_back({a, a, b, w});
    }
    return r;
  }();
  return rule;
}

}  // namespace

double area(const Triangle3& t) { return 0.5 * norm(cross(t.b - t.a, t.c - t.a)); }

std::vector<PatchWeight> patch_integrals(const Grid3& grid, const std::vector<Triangle3>& triangles,
                                         const std::vector<int>& patch_of, int n_patches) {
  if (patch_of.size() != triangles.size())
    throw std::invalid_argument("patch_integrals: one patch per triangle is needed");
  const double h = grid.h();
  const Box<3>& box = grid.box();
  // (patch, k, j, i) → value: sorted by patch, then by the node with i fastest.
  std::map<std::tuple<int, int, int, int>, double> sums;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const int patch = patch_of[t];
    if (patch < 0 || patch >= n_patches) throw std::invalid_argument("patch_integrals: patch out of range");
    const Triangle3& tri = triangles[t];
    for (const Point3& p : {tri.a, tri.b, tri.c})
      for (int d = 0; d < 3; ++d)
        if (!std::isfinite(p[d]) || p[d] < box.lower[d] || p[d] > box.upper[d])
          throw std::invalid_argument("surface: a triangle is not finite or leaves the box");
    std::vector<Polygon> pieces{{tri.a, tri.b, tri.c}};
    for (int d = 0; d < 3; ++d) pieces = split(pieces, d, box.lower[d], h, grid.n(d));
    for (const Polygon& piece : pieces) {
      Point3 centroid;
      for (const Point3& p : piece) centroid = centroid + p;
      centroid = (1.0 / piece.size()) * centroid;
      Grid3::Index cell;
      for (int d = 0; d < 3; ++d)
        cell[d] = std::clamp(int(std::floor((centroid[d] - box.lower[d]) / h)), 0, grid.n(d) - 1);
      for (std::size_t f = 1; f + 1 < piece.size(); ++f) {  // the fan from the first vertex
        const Point3 &a = piece[0], &b = piece[f], &c = piece[f + 1];
        const double jacobian = 2.0 * area({a, b, c});
        if (jacobian == 0.0) continue;
        for (const TrianglePoint& q : degree4_rule()) {
          const Point3 x = q.l0 * a + q.l1 * b + q.l2 * c;
          const double weight = 0.5 * q.w * jacobian;
          double xi[3];  // local coordinates in the cell, in [0, 1]
          for (int d = 0; d < 3; ++d) xi[d] = (x[d] - grid.coordinate(d, cell[d])) / h;
          for (int corner = 0; corner < 8; ++corner) {
            double phi = weight;
            Grid3::Index node = cell;
            for (int d = 0; d < 3; ++d) {
              const int up = (corner >> d) & 1;
              phi *= up ? xi[d] : 1 - xi[d];
              node[d] += up;
            }
            sums[{patch, node[2], node[1], node[0]}] += phi;
          }
        }
      }
    }
  }
  std::vector<PatchWeight> out;
  out.reserve(sums.size());
  for (const auto& [key, value] : sums)
    if (value != 0.0) out.push_back({std::get<0>(key), {std::get<3>(key), std::get<2>(key), std::get<1>(key)}, value});
  return out;
}

}  // namespace fictus
