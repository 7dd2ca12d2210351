#include "fictus/solve/solution.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <set>

namespace fictus {

double Timings::operator[](const std::string& name) const {
  for (const auto& [phase, seconds] : phases)
    if (phase == name) return seconds;
  return 0.0;
}

template <int dim>
ContactSummary contact_summary(const BasicSolution<dim>& s) {
  ContactSummary c;
  c.min_gap = std::numeric_limits<double>::infinity();
  c.max_gap = -c.min_gap;
  const std::vector<double>& part = s.weights();
  for (int i = 0; i < s.n_points(); ++i) {
    const PointCondition kind = s.condition(i);
    PartSummary& in = kind == PointCondition::dirichlet ? c.dirichlet
                      : kind == PointCondition::neumann ? c.neumann
                                                        : c.signorini;
    ++in.points;
    in.measure += part[i];
    in.flux += s.normal_derivative[i] * part[i];
    if (kind != PointCondition::signorini) continue;
    const double gap = s.trace[i] - s.g[i];
    c.min_gap = std::min(c.min_gap, gap);
    c.max_gap = std::max(c.max_gap, gap);
    if (s.in_contact(i)) {
      ++c.points;
      c.force_patches += s.normal_derivative[i] * part[i];
      c.measure_points += part[i];
    }
  }
  if (c.signorini.points == 0) c.min_gap = c.max_gap = 0;
  c.measure = s.contact_measure;
  c.force_from_domain = s.domain.has_value() && c.dirichlet.points == 0 && c.neumann.points == 0;
  c.force = c.force_from_domain ? s.domain->flux : c.force_patches;
  c.lambda = s.lambda_total;
  return c;
}

namespace {

/// Cubes of side `size` holding indices, for the searches near a point.
template <int dim>
class Buckets {
 public:
  explicit Buckets(double size) : size_(size) {}
  std::array<long, dim> cell(const Point<dim>& x) const {
    std::array<long, dim> c;
    for (int d = 0; d < dim; ++d) c[std::size_t(d)] = long(std::floor(x[d] / size_));
    return c;
  }
  void add(const std::array<long, dim>& c, int index) { cells_[c].push_back(index); }
  const std::vector<int>* at(const std::array<long, dim>& c) const {
    const auto it = cells_.find(c);
    return it == cells_.end() ? nullptr : &it->second;
  }
  /// Calls visit(c) for the cells within `rings` cells of c (in every coordinate).
  template <typename Visit>
  static void around(const std::array<long, dim>& c, long rings, Visit&& visit) {
    std::array<long, dim> k = c;
    for (int d = 0; d < dim; ++d) k[std::size_t(d)] = c[std::size_t(d)] - rings;
    while (true) {
      visit(k);
      int d = 0;
      while (d < dim && ++k[std::size_t(d)] > c[std::size_t(d)] + rings)
        k[std::size_t(d)] = c[std::size_t(d)] - rings, ++d;
      if (d == dim) return;
    }
  }
  double size() const { return size_; }

 private:
  double size_;
  std::map<std::array<long, dim>, std::vector<int>> cells_;
};

}  // namespace

template <>
std::vector<NeighbourPair> neighbour_pairs(const SolutionBoundary<2>& b) {
  const Collocation& c = b.collocation;
  std::vector<NeighbourPair> pairs;
  for (int i = 0; i < c.m && c.m > 1; ++i) {
    const int j = (i + 1) % c.m;
    const double d = j > i ? c.s[std::size_t(j)] - c.s[std::size_t(i)] : c.length - c.s[std::size_t(i)] + c.s[0];
    pairs.push_back({i, j, d, 1.0, {}});
  }
  return pairs;
}

template <>
std::vector<NeighbourPair> neighbour_pairs(const SolutionBoundary<3>& b) {
  // A triangulation made face by face computes a shared vertex once per face, equal only to round-off:
  // copies within 1e-9 of the surface's extent are one vertex (looked up in cubes of that side, so that
  // copies on two sides of a cube's face still meet). Then each edge with its triangles' patches: an
  // edge between two patches is part of their border.
  const PatchedSurface& s = b.gamma;
  double extent = 0;
  for (const Triangle3& t : s.triangles)
    for (const Point3& p : {t.a, t.b, t.c}) extent = std::max({extent, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  const double unit = 1e-9 * std::max(extent, 1e-300);
  Buckets<3> cells(unit);
  std::vector<Point3> vertices;
  const auto id = [&](const Point3& p) {
    const std::array<long, 3> c = cells.cell(p);
    int found = -1;
    const auto look = [&](const std::array<long, 3>& k) {
      if (const std::vector<int>* in = found < 0 ? cells.at(k) : nullptr)
        for (int v : *in)
          if (norm(vertices[std::size_t(v)] - p) <= unit) found = v;
    };
    look(c);  // most copies fall in the first copy's cube
    if (found < 0) Buckets<3>::around(c, 1, look);
    if (found < 0) found = int(vertices.size()), vertices.push_back(p), cells.add(c, found);
    return found;
  };
  std::map<std::pair<int, int>, std::pair<int, double>> edge_patch;  // edge → (first patch, length)
  std::map<std::pair<int, int>, NeighbourPair> border;               // (patch i < j) → their pair
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const Point3 v[3] = {s.triangles[t].a, s.triangles[t].b, s.triangles[t].c};
    const int ids[3] = {id(v[0]), id(v[1]), id(v[2])};
    for (int e = 0; e < 3; ++e) {
      const int a = ids[e], c = ids[(e + 1) % 3];
      const std::pair<int, int> key{std::min(a, c), std::max(a, c)};
      const auto [it, first] = edge_patch.emplace(key, std::make_pair(s.patch_of[t], norm(v[e] - v[(e + 1) % 3])));
      if (!first && it->second.first != s.patch_of[t]) {
        const int p = it->second.first, q = s.patch_of[t];
        NeighbourPair& pair = border[{std::min(p, q), std::max(p, q)}];
        pair.border += it->second.second;
        pair.corners.insert(pair.corners.end(), {a, c});
      }
    }
  }
  std::vector<NeighbourPair> pairs;
  for (auto& [key, pair] : border) {
    pair.i = key.first, pair.j = key.second;
    pair.distance = norm(s.point[std::size_t(key.first)] - s.point[std::size_t(key.second)]);
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

double contact_end_fraction(double q, double r, double d) {
  if (!(q > 0)) return 0.0;
  if (!(r > 0) || !(d > 0)) return 1.0;
  const double rho = q * d / (1.5 * r);
  double lo = 0, hi = 1;  // √θ/(1 − θ)^{3/2} increases from 0 to ∞ on (0, 1)
  for (int k = 0; k < 60; ++k) {
    const double theta = 0.5 * (lo + hi);
    (std::sqrt(theta) / std::pow(1 - theta, 1.5) < rho ? lo : hi) = theta;
  }
  return 0.5 * (lo + hi);
}

double contact_end_fraction(double q, double r, double d, double beyond) {
  if (!(beyond < std::numeric_limits<double>::infinity())) return contact_end_fraction(q, r, d);
  if (!(q > 0)) return 0.0;
  if (!(r > 0) || !(d > 0) || !(beyond > 0)) return 1.0;  // beyond = 0: the band closes at the free point
  const double target = q / r;
  double lo = 0, hi = 1;  // the ratio increases from 0 to ∞ on (0, 1)
  for (int k = 0; k < 60; ++k) {
    const double theta = 0.5 * (lo + hi), alpha = theta * d, beta = (1 - theta) * d, e = beta + beyond;
    const double ratio = 3 * (alpha + 0.5 * e) * std::sqrt(alpha * (alpha + e)) / std::pow(beta * beyond, 1.5);
    (ratio < target ? lo : hi) = theta;
  }
  return 0.5 * (lo + hi);
}

namespace {

/// Whether a contact end lies between the pair's points: both Signorini, one active and one free.
template <int dim>
bool located_pair(const BasicSolution<dim>& s, const NeighbourPair& p) {
  return s.condition(p.i) == PointCondition::signorini && s.condition(p.j) == PointCondition::signorini &&
         s.in_contact(p.i) != s.in_contact(p.j);
}

/// The share of a triangle where the linear interpolant of ψ (its values at the corners) is negative.
double negative_share(const std::array<double, 3>& psi) {
  const int negative = int(psi[0] < 0) + int(psi[1] < 0) + int(psi[2] < 0);
  if (negative == 0 || negative == 3) return negative / 3.0;
  // The corner alone on its side cuts off a triangle with sides t1, t2 of its two edges.
  const bool alone_negative = negative == 1;
  int k = 0;
  while ((psi[std::size_t(k)] < 0) != alone_negative) ++k;
  const double p = psi[std::size_t(k)], t1 = p / (p - psi[std::size_t((k + 1) % 3)]),
               t2 = p / (p - psi[std::size_t((k + 2) % 3)]);
  return alone_negative ? t1 * t2 : 1 - t1 * t2;
}

/// Whether the polyline p–x–n turns at x by less than 60° (and none of its points coincide): where it
/// turns more, it does not follow a smooth curve at its spacing.
bool turns_gently(const Point3& p, const Point3& x, const Point3& n) {
  const Point3 before = x - p, after = n - x;
  const double lb = norm(before), la = norm(after);
  return lb > 0 && la > 0 && dot(before, after) > 0.5 * lb * la;
}

/// The area between the chord from a to b and the cubic through h, a, b, k (its parameter the distance
/// along the polyline h–a–b–k), positive where the cubic lies on the side opposite `across`. The cubic
/// less the chord is D(t) = t(t − ℓ)(α + βt), which vanishes at a (t = 0) and b (t = ℓ); its values at h
/// and k fix α and β, and ∫₀^ℓ D = −αℓ³/6 − βℓ⁴/12. Zero where a turn of the polyline at a or b is 60° or
/// more (no smooth curve at that spacing) or two of the points coincide.
double bulge(const Point3& h, const Point3& a, const Point3& b, const Point3& k, const Point3& across) {
  if (!(turns_gently(h, a, b) && turns_gently(a, b, k))) return 0.0;
  const Point3 chord = b - a;
  const double l = norm(chord), th = -norm(a - h), tk = l + norm(k - b);
  const Point3 dh = h - (a + (th / l) * chord), dk = k - (a + (tk / l) * chord);
  const double a11 = th * (th - l), a12 = th * a11, a21 = tk * (tk - l), a22 = tk * a21;
  const double det = a11 * a22 - a12 * a21;  // a11·a21·(tk − th) > 0
  const Point3 alpha = (1 / det) * (a22 * dh - a12 * dk), beta = (1 / det) * (a11 * dk - a21 * dh);
  return dot((l * l * l / 6) * alpha + (l * l * l * l / 12) * beta, across);
}

/// A piece of the located contact boundary: a segment between two consecutive ends (3-D), or one end
/// joined to no other (a = b; every end in 2-D), with the unit normal across it towards the contact side
/// (that of the active points of its ends). Where a patch's ends all sit at its point (a patch in contact
/// among free ones whose flux reading is ≤ 0, θ = 0 on every side; or a free one among patches in contact
/// whose gap is ≤ 0, θ = 1), the set it bounds has shrunk to that point: `around` is then −1 (free all
/// around) or +1 (in contact all around) and `across` is 0.
template <int dim>
struct Segment {
  Point<dim> a, b, across;
  double around = 0;
};

template <int dim>
Point<dim> unit(const Point<dim>& v) {
  return norm(v) > 0 ? (1 / norm(v)) * v : v;
}

/// The segments of s's located boundary (`pairs`: its neighbour pairs): its lines, then the ends on none.
template <int dim>
std::vector<Segment<dim>> located_segments(const BasicSolution<dim>& s, const std::vector<NeighbourPair>& pairs) {
  const std::vector<Point<dim>>& ends = s.contact_boundary;
  const auto towards = [&](std::size_t k) {  // from the free point to the active one: never 0
    const std::array<int, 2>& pair = s.contact_boundary_pairs[k];
    return unit<dim>(s.points()[std::size_t(pair[0])] - s.points()[std::size_t(pair[1])]);
  };
  // The patches whose every Signorini neighbour is across a located end that sits at the patch's point
  // (θ = 0 or 1 give the points themselves): the end's `around` is −1 at a patch in contact, +1 at a
  // free one, 0 elsewhere.
  std::vector<int> neighbours(std::size_t(s.n_points()), 0), collapsed(std::size_t(s.n_points()), 0);
  for (const NeighbourPair& p : pairs)
    if (s.condition(p.i) == PointCondition::signorini && s.condition(p.j) == PointCondition::signorini)
      ++neighbours[std::size_t(p.i)], ++neighbours[std::size_t(p.j)];
  for (std::size_t k = 0; k < ends.size(); ++k) {
    const std::array<int, 2>& pair = s.contact_boundary_pairs[k];
    const double d = norm(s.points()[std::size_t(pair[0])] - s.points()[std::size_t(pair[1])]);
    for (int i : pair)
      if (norm(ends[k] - s.points()[std::size_t(i)]) <= 1e-12 * d) ++collapsed[std::size_t(i)];
  }
  const auto around = [&](std::size_t k) {
    for (int i : s.contact_boundary_pairs[k])
      if (collapsed[std::size_t(i)] == neighbours[std::size_t(i)]) return s.in_contact(i) ? -1.0 : 1.0;
    return 0.0;
  };
  std::vector<Segment<dim>> segments;
  std::vector<bool> joined(ends.size(), false);
  for (const auto& [k1, k2] : s.contact_boundary_lines) {
    const std::size_t i = std::size_t(k1), j = std::size_t(k2);
    joined[i] = joined[j] = true;
    const Point<dim> along = ends[j] - ends[i], toward = towards(i) + towards(j);
    const double length2 = dot(along, along);
    if (around(i) != 0 && around(i) == around(j)) {
      segments.push_back({ends[i], ends[j], Point<dim>{}, around(i)});
      continue;
    }
    segments.push_back(
        {ends[i], ends[j], unit<dim>(length2 > 0 ? toward - (dot(toward, along) / length2) * along : toward)});
  }
  for (std::size_t k = 0; k < ends.size(); ++k)
    if (!joined[k])
      segments.push_back(around(k) != 0 ? Segment<dim>{ends[k], ends[k], Point<dim>{}, around(k)}
                                        : Segment<dim>{ends[k], ends[k], towards(k)});
  return segments;
}

/// x minus its nearest point of g.
template <int dim>
Point<dim> offset_from(const Point<dim>& x, const Segment<dim>& g) {
  const Point<dim> along = g.b - g.a;
  const double length2 = dot(along, along);
  return x - (g.a + (length2 > 0 ? std::clamp(dot(x - g.a, along) / length2, 0.0, 1.0) : 0.0) * along);
}

/// ψ at x: the distance to the nearest of the `candidates`, negative on its contact side; where several
/// are nearest (beyond a vertex of the polyline), the sum of their unit normals towards the contact side
/// decides, with a shrunken set's `around` (Segment) for its whole side. `outside` where none comes
/// within `reach`.
template <int dim>
double signed_distance(const Point<dim>& x, const std::vector<const Segment<dim>*>& candidates, double reach,
                       double outside) {
  double nearest = reach;
  for (const Segment<dim>* g : candidates) nearest = std::min(nearest, norm(offset_from(x, *g)));
  if (!(nearest < reach)) return outside;
  double side = 0;  // Σ over the nearest segments of offset·normal
  for (const Segment<dim>* g : candidates) {
    const Point<dim> offset = offset_from(x, *g);
    if (norm(offset) <= nearest + 1e-12 * reach) side += dot(offset, g->across) + g->around * norm(offset);
  }
  return side > 0 ? -nearest : nearest;
}

/// The area of γ's triangles on the contact side of the located boundary (located_segments). ψ at a
/// triangle's corner is signed_distance within 1.5·s; elsewhere a triangle counts by its patch (in
/// contact or not). Each triangle counts by the share where the linear interpolant of ψ is negative;
/// only the patches of the located pairs are looked at. The boundary is a smooth curve, not its
/// polyline: each segment adds the bulge of the cubic through its ends and, beyond each, the first end
/// along the polyline at least half its length away (the chords of a curve of geodesic curvature κ cut
/// off κℓ³/12 each); none where the line branches, ends or closes on itself before such an end.
double contact_area_inside(const BasicSolution<3>& s, const std::vector<NeighbourPair>& pairs) {
  const std::vector<Point3>& ends = s.contact_boundary;
  const std::vector<Segment<3>> segments = located_segments(s, pairs);
  std::vector<std::vector<std::size_t>> neighbours(ends.size());
  for (const auto& [k1, k2] : s.contact_boundary_lines) {
    neighbours[std::size_t(k1)].push_back(std::size_t(k2));
    neighbours[std::size_t(k2)].push_back(std::size_t(k1));
  }
  // The end beyond `from` (seen from `back`) that the cubic takes: the first along the polyline at least
  // half the segment's length from `from`, within three steps. A nearer one would set the cubic's slope
  // by a segment whose direction is mostly the ends' scatter. None (the line branches, ends or turns
  // back first): no bulge.
  constexpr std::size_t none = std::size_t(-1);
  const auto beyond = [&](std::size_t from, std::size_t back, double length) {
    std::size_t previous = from, current = back;
    for (int step = 0; step < 3; ++step) {
      if (neighbours[previous].size() != 2) return none;
      const std::size_t next = neighbours[previous][0] == current ? neighbours[previous][1] : neighbours[previous][0];
      if (next == from || next == back) return none;
      if (norm(ends[next] - ends[from]) >= 0.5 * length) return next;
      current = previous, previous = next;
    }
    return none;
  };
  double bulges = 0;
  for (std::size_t g = 0; g < s.contact_boundary_lines.size(); ++g) {
    const std::size_t i = std::size_t(s.contact_boundary_lines[g][0]), j = std::size_t(s.contact_boundary_lines[g][1]);
    const double length = norm(ends[j] - ends[i]);
    const std::size_t h = beyond(i, j, length), k = beyond(j, i, length);
    if (h != none && k != none && h != k) bulges += bulge(ends[h], ends[i], ends[j], ends[k], segments[g].across);
  }
  std::vector<bool> located(std::size_t(s.gamma.m), false);  // patches of a located pair
  for (const NeighbourPair& p : pairs)
    if (located_pair(s, p)) located[std::size_t(p.i)] = located[std::size_t(p.j)] = true;
  const double reach = 1.5 * s.spacing();
  // Each located patch looks only at the segments that can come within the reach of its triangles'
  // corners (the same answer as looking at all: its corners lie within `radius` of its point).
  std::vector<double> radius(std::size_t(s.gamma.m), 0.0);
  for (std::size_t t = 0; t < s.gamma.triangles.size(); ++t) {
    const std::size_t patch = std::size_t(s.gamma.patch_of[t]);
    const Triangle3& tri = s.gamma.triangles[t];
    for (const Point3& x : {tri.a, tri.b, tri.c})
      radius[patch] = std::max(radius[patch], norm(x - s.gamma.point[patch]));
  }
  std::vector<std::vector<const Segment<3>*>> near(std::size_t(s.gamma.m));
  for (std::size_t p = 0; p < near.size(); ++p)
    if (located[p])
      for (const Segment<3>& g : segments)
        if (norm(offset_from(s.gamma.point[p], g)) < radius[p] + reach) near[p].push_back(&g);
  const auto psi = [&](const Point3& x, int patch) {
    return signed_distance(x, near[std::size_t(patch)], reach, s.in_contact(patch) ? -reach : reach);
  };
  double area = 0;
  for (std::size_t t = 0; t < s.gamma.triangles.size(); ++t) {
    const int patch = s.gamma.patch_of[t];
    if (s.condition(patch) != PointCondition::signorini) continue;
    const Triangle3& tri = s.gamma.triangles[t];
    const double size = 0.5 * norm(cross(tri.b - tri.a, tri.c - tri.a));
    area += located[std::size_t(patch)]
                ? size * negative_share({psi(tri.a, patch), psi(tri.b, patch), psi(tri.c, patch)})
                : (s.in_contact(patch) ? size : 0.0);
  }
  return area + bulges;
}

/// For each located end of s: how far past its free point, along its pair's direction from the active
/// point, the located boundary lies again (infinity where it does not; resolve_contact ignores distances
/// from 4 pair distances on). On a curve: the next end along it that is not at its active point (a contact
/// set shrunk to a point does not close a band), before a point under another condition. On a surface:
/// where the ray from the free point along the pair (in its tangent plane) first crosses, at 30° or more,
/// the plane through a segment of the polyline and the normal (the end's own segments aside).
template <int dim>
std::vector<double> free_band_beyond(const BasicSolution<dim>& s) {
  const std::vector<Point<dim>>& ends = s.contact_boundary;
  std::vector<double> beyond(ends.size(), std::numeric_limits<double>::infinity());
  if constexpr (dim == 2) {
    const int m = s.n_points();
    if (m < 3) return beyond;
    std::map<std::array<int, 2>, std::size_t> end_of;  // (free, active) → the end between them
    for (std::size_t k = 0; k < ends.size(); ++k)
      end_of[{s.contact_boundary_pairs[k][1], s.contact_boundary_pairs[k][0]}] = k;
    for (std::size_t k = 0; k < ends.size(); ++k) {
      const int a = s.contact_boundary_pairs[k][0], b = s.contact_boundary_pairs[k][1];
      const int step = (a + 1) % m == b ? 1 : -1;
      const Point2& xb = s.points()[std::size_t(b)];
      const double far = 4 * norm(xb - s.points()[std::size_t(a)]);
      for (int p = b, q = (b + step + m) % m; q != a; p = q, q = (q + step + m) % m) {
        if (s.condition(q) != PointCondition::signorini) break;
        const auto it = s.in_contact(q) ? end_of.find({p, q}) : end_of.end();
        // An end at its active point (θ = 0: a contact set shrunk to the point) does not close the band.
        if (it != end_of.end() && norm(ends[it->second] - s.points()[std::size_t(q)]) > 0) {
          beyond[k] = norm(ends[it->second] - xb);  // the taper in resolve_contact takes it to ∞ from 4d
          break;
        }
        if (norm(s.points()[std::size_t(q)] - xb) > far) break;
      }
    }
  } else {
    for (std::size_t k = 0; k < ends.size(); ++k) {
      const int a = s.contact_boundary_pairs[k][0], b = s.contact_boundary_pairs[k][1];
      const Point3& xb = s.points()[std::size_t(b)];
      const Point3 n = s.normals()[std::size_t(b)], pair = xb - s.points()[std::size_t(a)];
      const double far = 4 * norm(pair);
      const Point3 along = unit<3>(pair - dot(pair, n) * n), side = cross(n, along);
      for (const auto& [i, j] : s.contact_boundary_lines) {
        if (std::size_t(i) == k || std::size_t(j) == k) continue;
        const Point3 p = ends[std::size_t(i)] - xb, q = ends[std::size_t(j)] - xb;
        if (std::min(norm(p), norm(q)) > far + norm(q - p)) continue;
        const double py = dot(p, side), qy = dot(q, side);
        if ((py > 0 && qy > 0) || (py < 0 && qy < 0) || py == qy) continue;
        // Only a segment that crosses the ray at 30° or more: one that runs along it (ends of another pair
        // beside the same free point, near it) does not close a band there.
        if (std::abs(py - qy) < 0.5 * norm(q - p)) continue;
        const double lambda = py / (py - qy);
        const Point3 x = p + lambda * (q - p);
        const double t = dot(x, along);  // the crossing's distance along the ray, if it lies near the plane
        if (t > 0 && t < beyond[k] && std::abs(dot(x, n)) < 0.5 * t) beyond[k] = t;
      }
    }
  }
  return beyond;
}

}  // namespace

template <int dim>
void resolve_contact(BasicSolution<dim>& s) {
  const std::vector<double>& part = s.weights();
  double measure = 0, total = 0;
  for (int i = 0; i < s.n_points(); ++i) {
    if (s.condition(i) == PointCondition::signorini) total += part[std::size_t(i)];
    if (s.in_contact(i)) measure += part[std::size_t(i)];
  }
  s.contact_boundary.clear();
  s.contact_boundary_lines.clear();
  s.contact_boundary_pairs.clear();
  std::map<int, std::vector<int>> at_corner;  // 3-D: a mesh vertex → the located ends whose border has it
  const std::vector<NeighbourPair> pairs = neighbour_pairs<dim>(s);
  std::vector<const NeighbourPair*> located;  // each end's pair
  for (const NeighbourPair& p : pairs) {
    if (!located_pair(s, p)) continue;
    const bool i_active = s.in_contact(p.i);
    const int a = i_active ? p.i : p.j, b = i_active ? p.j : p.i;
    for (int corner : p.corners) at_corner[corner].push_back(int(located.size()));
    located.push_back(&p);
    s.contact_boundary_pairs.push_back({a, b});
  }
  // End k's θ from its readings, the free side a band `beyond` past the free point (∞: none).
  const auto law = [&](std::size_t k, double beyond) {
    const std::size_t active = std::size_t(s.contact_boundary_pairs[k][0]),
                      free = std::size_t(s.contact_boundary_pairs[k][1]);
    return contact_end_fraction(s.normal_derivative[active], s.trace[free] - s.g[free], located[k]->distance, beyond);
  };
  std::vector<double> theta(located.size());
  for (std::size_t k = 0; k < located.size(); ++k) theta[k] = law(k, std::numeric_limits<double>::infinity());
  const auto place = [&] {
    s.contact_boundary.clear();
    for (std::size_t k = 0; k < located.size(); ++k) {
      const Point<dim>& xa = s.points()[std::size_t(s.contact_boundary_pairs[k][0])];
      const Point<dim>& xb = s.points()[std::size_t(s.contact_boundary_pairs[k][1])];
      s.contact_boundary.push_back(theta[k] == 1 ? xb : xa + theta[k] * (xb - xa));
    }
  };
  place();
  // Two ends whose borders meet at a vertex of the triangulation are consecutive along the contact
  // boundary: a segment joins them. Where more meet (a saddle: patches in contact and free alternate
  // around the vertex), the ends are grouped by the sector in contact they bound (patches in contact
  // that border each other at the vertex are one sector), so that the sectors stay apart; a group of two
  // is joined, a larger one (a patch that comes round twice) chained, and an end alone (its sector
  // bounded by a part under another condition) is not joined there.
  std::map<int, std::vector<std::array<int, 2>>> touching;  // a vertex → the pairs in contact whose border has it
  for (const NeighbourPair& p : pairs)
    if (s.in_contact(p.i) && s.in_contact(p.j))
      for (int corner : p.corners) touching[corner].push_back({p.i, p.j});
  std::set<std::array<int, 2>> lines;
  for (auto& [corner, ends] : at_corner) {
    std::sort(ends.begin(), ends.end());
    ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
    if (ends.size() == 2) lines.insert({ends[0], ends[1]});
    if (ends.size() <= 2) continue;
    std::map<int, int> sector;  // a patch in contact → the sector's first patch (a union-find)
    const std::function<int(int)> root = [&](int p) {
      const auto it = sector.emplace(p, p).first;
      return it->second == p ? p : it->second = root(it->second);
    };
    if (const auto it = touching.find(corner); it != touching.end())
      for (const auto& [p, q] : it->second) sector[root(p)] = root(q);
    std::map<int, std::vector<int>> by_sector;
    for (int k : ends) by_sector[root(s.contact_boundary_pairs[std::size_t(k)][0])].push_back(k);
    for (const auto& [first, own] : by_sector)
      for (std::size_t k = 0; k + 1 < own.size(); ++k) lines.insert({own[k], own[k + 1]});
  }
  s.contact_boundary_lines.assign(lines.begin(), lines.end());
  // Where the located boundary comes back within a few spacings past a free point, the free part there is
  // a band that the two ends close: each end's law takes the band's width (docs/math.md, "The contact
  // set"). The ends move each other, so sweeps until they settle (at most eight). Each takes the geometric
  // mean of the free side's length before and after it: the two ends of a band narrower than a spacing
  // share a free point whose gap fixes only the product of their distances from it, and undamped they
  // would swing from sweep to sweep. The distance to the next end is tapered from 0 to 4d (taken as
  // beyond/(1 − (beyond/4d)²), infinite from 4d on), so that the ends move continuously with the readings.
  // With the contact fit (solver.fit_contact > 0, the 2-D default) the lone end's law stays: there the
  // closed band moved the references' contact measure away at N = 256 … 384 (tips: +9.8e-5 → −3.5e-3 of
  // |γ|; bench/results/2026-12-08-free-band-and-peanut.md), though without the fit it brought it nearer.
  const bool close_bands = !(s.options.fit_contact > 0);
  for (int sweep = 0; close_bands && sweep < 8 && !located.empty(); ++sweep) {
    const std::vector<double> beyond = free_band_beyond(s);
    double moved = 0;
    for (std::size_t k = 0; k < located.size(); ++k) {
      const double d = located[k]->distance, far = 4 * d, band = beyond[k];
      if (!(band < far)) continue;  // no band: the lone end's θ, as placed
      const double next = law(k, band / (1 - (band / far) * (band / far)));
      const double damped = 1 - std::sqrt((1 - theta[k]) * (1 - next));
      moved = std::max(moved, std::abs(damped - theta[k]));
      theta[k] = damped;
    }
    place();
    if (moved < 1e-9) break;
  }
  if constexpr (dim == 2)  // each end moves the border between the arcs, each owning d in proportion
    for (std::size_t k = 0; k < located.size(); ++k) {
      const std::size_t a = std::size_t(s.contact_boundary_pairs[k][0]),
                        b = std::size_t(s.contact_boundary_pairs[k][1]);
      const double d = located[k]->distance, owned = d * part[a] / (part[a] + part[b]);
      measure += (theta[k] * d - owned) * located[k]->border;
    }
  // On a surface the measure is the area inside the located boundary (docs/math.md, "The contact set").
  if constexpr (dim == 3) measure = contact_area_inside(s, pairs);
  s.contact_measure = std::clamp(measure, 0.0, total);
}

template <int dim>
std::function<double(const Point<dim>&)> contact_side(const BasicSolution<dim>& s) {
  if (s.contact_boundary.empty()) return {};
  struct Side {
    std::vector<Segment<dim>> segments;
    std::vector<Point<dim>> points;
    std::vector<char> active;
    Buckets<dim> point_cells, segment_cells;
    double reach;
  };
  const double spacing = s.spacing();
  auto side = std::make_shared<Side>(Side{located_segments(s, neighbour_pairs<dim>(s)),
                                          s.points(),
                                          {},
                                          Buckets<dim>(spacing),
                                          Buckets<dim>(spacing),
                                          1.5 * spacing});
  for (int i = 0; i < s.n_points(); ++i) {  // the Signorini points (a located end lies between two)
    side->active.push_back(char(s.in_contact(i)));
    if (s.condition(i) == PointCondition::signorini)
      side->point_cells.add(side->point_cells.cell(s.points()[std::size_t(i)]), i);
  }
  // A segment goes into every cell its box, widened by the reach, touches.
  for (std::size_t k = 0; k < side->segments.size(); ++k) {
    const Segment<dim>& g = side->segments[k];
    Point<dim> low = g.a, high = g.a;
    for (int d = 0; d < dim; ++d)
      low[d] = std::min(g.a[d], g.b[d]) - side->reach, high[d] = std::max(g.a[d], g.b[d]) + side->reach;
    const std::array<long, dim> lo = side->segment_cells.cell(low), hi = side->segment_cells.cell(high);
    std::array<long, dim> mid = lo;
    long rings = 0;
    for (int d = 0; d < dim; ++d)
      mid[std::size_t(d)] = (lo[std::size_t(d)] + hi[std::size_t(d)]) / 2,
      rings =
          std::max(rings, std::max(mid[std::size_t(d)] - lo[std::size_t(d)], hi[std::size_t(d)] - mid[std::size_t(d)]));
    Buckets<dim>::around(mid, rings, [&](const std::array<long, dim>& c) {
      for (int d = 0; d < dim; ++d)
        if (c[std::size_t(d)] < lo[std::size_t(d)] || c[std::size_t(d)] > hi[std::size_t(d)]) return;
      side->segment_cells.add(c, int(k));
    });
  }
  return [side](const Point<dim>& x) {
    const std::array<long, dim> c = side->segment_cells.cell(x);
    std::vector<const Segment<dim>*> candidates;
    if (const std::vector<int>* in = side->segment_cells.at(c))
      for (int k : *in) candidates.push_back(&side->segments[std::size_t(k)]);
    const double psi = signed_distance(x, candidates, side->reach, 0.0);
    if (psi != 0) return psi < 0 ? 1.0 : 0.0;
    // Beyond the reach: the nearest point's status (the rings widen until one is found and no nearer
    // one can lie farther out).
    double best = std::numeric_limits<double>::infinity();
    int nearest = -1;
    for (long rings = 1; rings < (1L << 20); rings *= 2) {
      Buckets<dim>::around(side->point_cells.cell(x), rings, [&](const std::array<long, dim>& cell) {
        if (const std::vector<int>* in = side->point_cells.at(cell))
          for (int i : *in)
            if (const double d = norm(x - side->points[std::size_t(i)]); d < best) best = d, nearest = i;
      });
      if (nearest >= 0 && best <= double(rings) * side->point_cells.size()) break;
    }
    return nearest >= 0 && side->active[std::size_t(nearest)] ? 1.0 : 0.0;
  };
}

/// What to change when a GMRES stopped at its cap, by the solve that ran it: the implicit Schur
/// complement (schur = krylov), the compressed one's iterations, or the refinement on the exact S after
/// the interpolated far field (green, dense).
template <int dim>
std::string krylov_advice(const BasicSolution<dim>& s) {
  if (s.options.inner == InnerSolver::krylov) return "raise the cap, or use schur = green";
  if (s.schur_storage && s.schur_storage->kind == "hierarchical")
    return "raise the cap, or store S dense with schur_storage = dense where the memory allows";
  return "raise the cap, or assemble every pair of S exactly with far_field = false";
}

template <int dim>
std::string describe_newton_failure(const BasicSolution<dim>& s) {
  // Blame the setting at fault: a Krylov solve stopped short makes Newton wander, whatever its cap; a
  // set that repeats with the residual above the tolerance cannot gain from more steps.
  std::string line =
      s.newton.inner_failed
          ? "solver.krylov_max_iterations: GMRES stopped at its cap of " +
                std::to_string(s.options.krylov_max_iterations) + " iterations before solver.krylov_tolerance (" +
                krylov_advice(s) + "); then Newton: " + s.newton.failure + "; history (active points, residual):"
      : s.newton.stalled
          ? "solver.newton_tolerance: the active set repeats but the residual stays above the tolerance, so more "
            "steps cannot lower it (raise the tolerance where the residual is near round-off; lower formulation.rho "
            "where it is large): " +
                s.newton.failure + "; history (active points, residual):"
          : "solver.max_newton: Newton did not converge: " + s.newton.failure + "; history (active points, residual):";
  for (const NewtonStep& step : s.newton.history) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, " (%d, %.2e)", step.n_active, step.residual);
    line += buffer;
  }
  return line;
}

template ContactSummary contact_summary(const BasicSolution<2>&);
template ContactSummary contact_summary(const BasicSolution<3>&);
template std::string describe_newton_failure(const BasicSolution<2>&);
template void resolve_contact(BasicSolution<2>&);
template void resolve_contact(BasicSolution<3>&);
template std::function<double(const Point2&)> contact_side(const BasicSolution<2>&);
template std::function<double(const Point3&)> contact_side(const BasicSolution<3>&);
template std::string describe_newton_failure(const BasicSolution<3>&);

}  // namespace fictus
