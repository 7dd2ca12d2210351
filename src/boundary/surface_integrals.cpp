#include "fictus/boundary/surface_integrals.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <map>
#include <numbers>
#include <queue>
#include <stdexcept>
#include <tuple>

namespace fictus {

namespace {

using Polygon = std::vector<Point3>;

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
                                         const std::vector<int>& patch_of, int n_patches, const SurfaceMap& onto,
                                         int threads, const Distribution& distribution) {
  if (patch_of.size() != triangles.size())
    throw std::invalid_argument("patch_integrals: one patch per triangle is needed");
  if (n_patches < 0) throw std::invalid_argument("patch_integrals: a negative number of patches");
  for (int patch : patch_of)
    if (patch < 0 || patch >= n_patches) throw std::invalid_argument("patch_integrals: patch out of range");
  // The triangles this rank integrates, in order: all of them, or (distributed) those of its run of
  // patches. A node's sum takes only its patch's triangles, so each rank's sums are the serial ones.
  std::vector<std::size_t> mine;
  if (!distribution.distributed()) {
    mine.resize(triangles.size());
    for (std::size_t t = 0; t < mine.size(); ++t) mine[t] = t;
  } else {
    std::vector<std::size_t> below(std::size_t(n_patches) + 1, 0);  // triangles of the patches before
    for (int patch : patch_of) ++below[std::size_t(patch) + 1];
    for (std::size_t p = 0; p < std::size_t(n_patches); ++p) below[p + 1] += below[p];
    const auto first_patch = [&](int rank) {  // the first patch whose triangles start at or after rank's share
      const std::size_t share = triangles.size() * std::size_t(rank) / std::size_t(distribution.size());
      return int(std::lower_bound(below.begin(), below.end() - 1, share) - below.begin());
    };
    const int first = first_patch(distribution.rank()), last = first_patch(distribution.rank() + 1);
    for (std::size_t t = 0; t < triangles.size(); ++t)
      if (patch_of[t] >= first && patch_of[t] < last) mine.push_back(t);
  }
  const double h = grid.h();
  const Box<3>& box = grid.box();
  // (patch, k, j, i) and value, for every piece's corner; sorted and merged at the end. Each thread
  // collects the items of one run of consecutive triangles, and the runs are joined in order: the
  // items, and so the sums, are those of one thread.
  struct Item {
    std::tuple<int, int, int, int> key;
    double value;
  };
  const auto add_triangle = [&](std::size_t t, auto& items) {
    const int patch = patch_of[t];
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
      std::array<double, 8> corner_sum{};                   // ∫_piece φ of the cell's 8 corners
      for (std::size_t f = 1; f + 1 < piece.size(); ++f) {  // the fan from the first vertex
        const Point3 &a = piece[0], &b = piece[f], &c = piece[f + 1];
        const Point3 normal_area = cross(b - a, c - a);
        const double jacobian = norm(normal_area);
        if (jacobian == 0.0) continue;
        for (const TrianglePoint& q : degree4_rule()) {
          Point3 x = q.l0 * a + q.l1 * b + q.l2 * c;
          double weight = 0.5 * q.w * jacobian;
          if (onto) {
            double factor = 1.0;
            x = onto(x, (1.0 / jacobian) * normal_area, factor);
            weight *= factor;
          }
          double xi[3];  // local coordinates in the cell, in [0, 1]
          for (int d = 0; d < 3; ++d) xi[d] = (x[d] - grid.coordinate(d, cell[d])) / h;
          for (int corner = 0; corner < 8; ++corner) {
            double phi = weight;
            for (int d = 0; d < 3; ++d) phi *= (corner >> d) & 1 ? xi[d] : 1 - xi[d];
            corner_sum[corner] += phi;
          }
        }
      }
      for (int corner = 0; corner < 8; ++corner) {
        Grid3::Index node = cell;
        for (int d = 0; d < 3; ++d) node[d] += (corner >> d) & 1;
        items.push_back({{patch, node[2], node[1], node[0]}, corner_sum[corner]});
      }
    }
  };
  const int teams = std::max(1, threads);
  std::vector<std::vector<Item>> items_of(static_cast<std::size_t>(teams));
  std::vector<std::exception_ptr> failure(static_cast<std::size_t>(teams));
#pragma omp parallel for num_threads(teams) schedule(static, 1)
  for (int team = 0; team < teams; ++team) try {
      std::vector<Item>& items = items_of[std::size_t(team)];
      const std::size_t first = mine.size() * std::size_t(team) / std::size_t(teams),
                        last = mine.size() * std::size_t(team + 1) / std::size_t(teams);
      for (std::size_t t = first; t < last; ++t) add_triangle(mine[t], items);
    } catch (...) {
      failure[std::size_t(team)] = std::current_exception();
    }
  std::exception_ptr first_failure;
  for (const std::exception_ptr& e : failure)
    if (e && !first_failure) first_failure = e;
  distribution.throw_first_failure(first_failure, false);  // on every rank: none goes on to the others' runs
  std::vector<Item> items;
  for (std::vector<Item>& run : items_of) items.insert(items.end(), run.begin(), run.end());
  // Sorted by patch, then by the node with i fastest; the sums over equal keys in a fixed order.
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.key < b.key; });
  std::vector<PatchWeight> out;
  for (std::size_t k = 0; k < items.size();) {
    double value = 0.0;
    std::size_t e = k;
    for (; e < items.size() && items[e].key == items[k].key; ++e) value += items[e].value;
    const auto& key = items[k].key;
    if (value != 0.0) out.push_back({std::get<0>(key), {std::get<3>(key), std::get<2>(key), std::get<1>(key)}, value});
    k = e;
  }
  return distribution.distributed() ? distribution.concatenate(out) : out;  // the runs in patch order
}

}  // namespace fictus

namespace fictus {

namespace {

/// The 12 vertices and 20 faces of the icosahedron on the unit sphere.
void icosahedron(std::vector<Point3>& vertices, std::vector<std::array<int, 3>>& faces) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  vertices = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
              {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (Point3& v : vertices) v = (1.0 / norm(v)) * v;
  faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
           {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
           {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
}

}  // namespace

std::vector<Point3> split_into_patches(PatchedSurface& s, int m, const std::vector<int>& labels,
                                       std::vector<int>* patch_labels) {
  const std::size_t count = s.triangles.size();
  if (m < 1 || std::size_t(m) > count / 4)
    throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(m) + " needs 1 <= m <= " +
                                std::to_string(count / 4) + " for this triangulation (a smaller edge allows more)");
  std::vector<Point3> centroid(count);
  std::vector<double> weight(count);
  for (std::size_t t = 0; t < count; ++t) {
    centroid[t] = (1.0 / 3) * (s.triangles[t].a + s.triangles[t].b + s.triangles[t].c);
    weight[t] = area(s.triangles[t]);
  }
  // Lloyd's iteration from m triangles spread over the list (with labels: over each label's triangles,
  // the counts given one at a time to the label whose patches are largest).
  std::vector<Point3> seeds(m);
  std::vector<int> seed_label(std::size_t(m), 0);
  if (labels.empty()) {
    for (int p = 0; p < m; ++p) seeds[p] = centroid[std::size_t(p) * count / std::size_t(m)];
  } else {
    if (labels.size() != count) throw std::invalid_argument("split_into_patches: one label per triangle");
    std::map<int, std::vector<std::size_t>> members;
    std::map<int, double> label_area;
    for (std::size_t t = 0; t < count; ++t) members[labels[t]].push_back(t), label_area[labels[t]] += weight[t];
    if (int(members.size()) > m)
      throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(m) + " is fewer than the " +
                                  std::to_string(members.size()) + " parts of the surface: raise m or N");
    std::map<int, int> given;
    std::priority_queue<std::pair<double, int>> largest;  // (patch area in the label, label)
    for (const auto& [label, a] : label_area) {
      given[label] = 1;
      if (members[label].size() > 1) largest.emplace(a, label);
    }
    for (int n = int(members.size()); n < m; ++n) {  // a label takes at most as many patches as triangles
      if (largest.empty())
        throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(m) +
                                    " is more than the parts' triangles allow (a smaller edge allows more)");
      const int label = largest.top().second;
      largest.pop();
      if (++given[label] < int(members[label].size())) largest.emplace(label_area[label] / given[label], label);
    }
    int p = 0;
    for (const auto& [label, list] : members)
      for (int k = 0; k < given[label]; ++k, ++p) {
        seeds[p] = centroid[list[std::size_t(k) * list.size() / std::size_t(given[label])]];
        seed_label[std::size_t(p)] = label;
      }
  }
  const auto may_take = [&](std::size_t t, int p) { return labels.empty() || labels[t] == seed_label[std::size_t(p)]; };
  s.patch_of.assign(count, 0);
  // The nearest seed by buckets of side 2·(patch spacing): when the nearest one in the 27 buckets
  // around a centroid is within one bucket side, no seed outside them is nearer; else all are searched.
  double total_area = 0;
  for (double w : weight) total_area += w;
  const double bucket = 2 * std::sqrt(total_area / m);
  Point3 low = centroid[0], high = centroid[0];
  for (const Point3& c : centroid)
    for (int d = 0; d < 3; ++d) low[d] = std::min(low[d], c[d]), high[d] = std::max(high[d], c[d]);
  std::array<int, 3> size;  // buckets along each axis, over the centroids' box
  for (int d = 0; d < 3; ++d) size[d] = int(std::floor((high[d] - low[d]) / bucket)) + 1;
  const auto bucket_of = [&](const Point3& p, int d) {  // may lie outside [0, size) for a seed
    return int(std::floor((p[d] - low[d]) / bucket));
  };
  std::vector<std::vector<int>> buckets(static_cast<std::size_t>(size[0]) * size[1] * size[2]);
  for (int iteration = 0; iteration < 30; ++iteration) {
    for (auto& b : buckets) b.clear();
    std::vector<int> outside;  // seeds beyond the centroids' box (searched for every triangle)
    for (int p = 0; p < m; ++p) {
      int b[3];
      for (int d = 0; d < 3; ++d) b[d] = bucket_of(seeds[p], d);
      if (b[0] < 0 || b[1] < 0 || b[2] < 0 || b[0] >= size[0] || b[1] >= size[1] || b[2] >= size[2])
        outside.push_back(p);
      else
        buckets[(std::size_t(b[2]) * size[1] + b[1]) * size[0] + b[0]].push_back(p);
    }
    for (std::size_t t = 0; t < count; ++t) {
      double best = 1e300;
      const auto nearest = [&](int p) {
        if (!may_take(t, p)) return;
        const Point3 d = centroid[t] - seeds[p];
        const double distance = dot(d, d);
        if (distance < best || (distance == best && p < s.patch_of[t])) best = distance, s.patch_of[t] = p;
      };
      int b[3];
      for (int d = 0; d < 3; ++d) b[d] = bucket_of(centroid[t], d);
      for (int z = std::max(b[2] - 1, 0); z <= std::min(b[2] + 1, size[2] - 1); ++z)
        for (int y = std::max(b[1] - 1, 0); y <= std::min(b[1] + 1, size[1] - 1); ++y)
          for (int x = std::max(b[0] - 1, 0); x <= std::min(b[0] + 1, size[0] - 1); ++x)
            for (int p : buckets[(std::size_t(z) * size[1] + y) * size[0] + x]) nearest(p);
      for (int p : outside) nearest(p);
      if (best > bucket * bucket)
        for (int p = 0; p < m; ++p) nearest(p);
    }
    std::vector<Point3> sum(m);
    std::vector<double> total(m, 0.0);
    for (std::size_t t = 0; t < count; ++t) {
      sum[s.patch_of[t]] = sum[s.patch_of[t]] + weight[t] * centroid[t];
      total[s.patch_of[t]] += weight[t];
    }
    for (int p = 0; p < m; ++p)
      if (total[p] > 0) seeds[p] = (1.0 / total[p]) * sum[p];
  }
  s.m = m;
  s.point.resize(m);
  s.normal.resize(m);
  s.area.assign(m, 0.0);
  for (std::size_t t = 0; t < count; ++t) s.area[s.patch_of[t]] += weight[t];
  for (int p = 0; p < m; ++p)
    if (s.area[p] == 0.0) throw std::runtime_error("surface patches: an empty patch (use a smaller edge)");
  if (patch_labels) *patch_labels = seed_label;
  return seeds;
}

PatchedSurface ellipsoid_patches(Point3 center, Point3 semi_axes, int m, double edge) {
  for (int d = 0; d < 3; ++d)
    if (!(semi_axes[d] > 0) || !std::isfinite(semi_axes[d]))
      throw std::invalid_argument("geometry.semi_axes: must be positive and finite");
  if (!(edge > 0)) throw std::invalid_argument("ellipsoid_patches: the edge length must be positive");
  std::vector<Point3> vertices;
  std::vector<std::array<int, 3>> faces;
  icosahedron(vertices, faces);
  const double largest = std::max({semi_axes.x, semi_axes.y, semi_axes.z});
  const int n = std::max(1, int(std::ceil(1.1 * largest / edge)));  // icosahedron edge 1.05 on the unit sphere
  const auto on_ellipsoid = [&](Point3 p) {
    p = (1.0 / norm(p)) * p;
    return Point3{center.x + semi_axes.x * p.x, center.y + semi_axes.y * p.y, center.z + semi_axes.z * p.z};
  };
  PatchedSurface s;
  for (const auto& f : faces) {
    const Point3 &a = vertices[f[0]], &b = vertices[f[1]], &c = vertices[f[2]];
    auto at = [&](int i, int j) { return on_ellipsoid(a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a)); };
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j) {
        s.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
        if (i + j + 1 < n) s.triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  }
  const std::vector<Point3> seeds = split_into_patches(s, m);
  for (int p = 0; p < m; ++p) {
    const Point3 q = on_ellipsoid(Point3{(seeds[p].x - center.x) / semi_axes.x, (seeds[p].y - center.y) / semi_axes.y,
                                         (seeds[p].z - center.z) / semi_axes.z});
    const Point3 gradient{(q.x - center.x) / (semi_axes.x * semi_axes.x),
                          (q.y - center.y) / (semi_axes.y * semi_axes.y),
                          (q.z - center.z) / (semi_axes.z * semi_axes.z)};
    s.point[p] = q;
    s.normal[p] = (1.0 / norm(gradient)) * gradient;
  }
  return s;
}

PatchedSurface torus_patches(Point3 center, double R, double r, int m, double edge) {
  if (!(r > 0) || !(R > r) || !std::isfinite(R)) throw std::invalid_argument("geometry.radii: need 0 < r < R, finite");
  if (!(edge > 0)) throw std::invalid_argument("torus_patches: the edge length must be positive");
  const int around = std::max(3, int(std::ceil(2 * std::numbers::pi * (R + r) / edge)));  // along the core circle
  const int across = std::max(3, int(std::ceil(2 * std::numbers::pi * r / edge)));        // around the tube
  const auto at = [&](int i, int j) {
    const double theta = 2 * std::numbers::pi * i / around, phi = 2 * std::numbers::pi * j / across;
    const double rho = R + r * std::cos(phi);
    return Point3{center.x + rho * std::cos(theta), center.y + rho * std::sin(theta), center.z + r * std::sin(phi)};
  };
  PatchedSurface s;
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < across; ++j) {  // outward: (θ, φ) is a right-handed chart for the outer normal
      s.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      s.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  const std::vector<Point3> seeds = split_into_patches(s, m);
  for (int p = 0; p < m; ++p) {  // the nearest point of the torus: through the nearest point of the core circle
    const Point3 d = seeds[p] - center;
    const double planar = std::hypot(d.x, d.y);
    const Point3 core = planar > 0 ? center + (R / planar) * Point3{d.x, d.y, 0.0} : center + Point3{R, 0.0, 0.0};
    Point3 n = seeds[p] - core;
    n = norm(n) > 0 ? (1.0 / norm(n)) * n : (1.0 / R) * (core - center);
    s.point[p] = core + r * n;
    s.normal[p] = n;
  }
  return s;
}

}  // namespace fictus
