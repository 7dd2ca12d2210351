#include "fictus/boundary/kink_correction.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include "fictus/grid/q1_element.hpp"
#include "fictus/grid/quadrature.hpp"

namespace fictus {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

/// The point of the curve nearest to x (Newton on (p(t) − x)·p′(t) = 0 from t0, a few steps:
/// x is within a cell or two of the curve) and the kink function q(d)⁺ there.
struct Kink {
  double t = 0.0;      // parameter of the nearest point, in [0, 2π)
  double d = 0.0;      // signed distance, > 0 outside ω
  double kappa = 0.0;  // curvature there
  Point2 normal;       // outward unit normal there
  Point2 foot;         // the nearest point itself
  /// ψ outside ω, extended smoothly inside: q(d) = d − κd²/2 + κ²d³/3, with Δq = O(d²) (math.md).
  double q() const { return d * (1.0 + d * (-0.5 * kappa + d * kappa * kappa / 3.0)); }
  double psi() const { return d > 0 ? q() : 0.0; }                                     // q(d)⁺
  Point2 grad_q() const { return (1.0 + d * (-kappa + d * kappa * kappa)) * normal; }  // q′(d)·n, κ constant
};

double wrap(double t) {
  t = std::fmod(t, two_pi);
  return t < 0 ? t + two_pi : t;
}

/// The point of the curve nearest to x, and the kink function there. Smooth curves: Newton on
/// (p(t) − x)·p′(t) = 0 from t0 (x is within a cell or two of the curve). Curves with corners: the
/// same on the smooth piece holding t0 and its two neighbours, each clamped to its piece, the
/// nearest kept; when that is a corner V, d = ±|x − V| along (x − V) and κ = 0.
class Projector {
 public:
  explicit Projector(const Curve& curve) : curve_(curve), corners_(curve.corners()) {
    std::sort(corners_.begin(), corners_.end());
  }

  /// The nearest point of a point y near x (within a few cells) from x's nearest point: on a curve
  /// without corners by its osculating circle there (d, n, t to O(κ′|y − x|³)), otherwise exactly.
  Kink near(const Kink& at_x, Point2 y, double speed) const {
    if (!corners_.empty()) return (*this)(y, at_x.t);
    Kink k = at_x;
    const Point2 p = at_x.foot;
    if (std::abs(at_x.kappa) * norm(y - p) < 1e-12) {
      const Point2 tangent{-at_x.normal.y, at_x.normal.x};
      k.d = dot(y - p, at_x.normal);
      k.t = wrap(at_x.t + dot(y - p, tangent) / speed);
      return k;
    }
    const double rho = 1.0 / at_x.kappa;
    const Point2 centre = p - rho * at_x.normal, v = y - centre, u = p - centre;
    const double r = norm(v);
    k.d = rho > 0 ? r - rho : -rho - r;
    k.normal = (rho > 0 ? 1.0 / r : -1.0 / r) * v;
    const double angle = std::atan2(u.x * v.y - u.y * v.x, dot(u, v));
    k.t = wrap(at_x.t + rho * angle / speed);
    k.foot = centre + (std::abs(rho) / r) * v;
    return k;
  }

  Kink operator()(Point2 x, double t0) const {
    if (corners_.empty()) return at(x, wrap(newton(x, t0, -1e300, 1e300)));
    const int n = int(corners_.size());
    // The piece [corner k, corner k+1) holding t0; -1: before the first corner (the last piece).
    const int piece = int(std::upper_bound(corners_.begin(), corners_.end(), wrap(t0)) - corners_.begin()) - 1;
    double best_t = 0.0, best_distance = 1e300;
    bool at_corner = false;
    for (int k = piece - 1; k <= piece + 1; ++k) {
      const int i = ((k % n) + n) % n;
      const double a = corners_[i], b = i + 1 < n ? corners_[i + 1] : corners_[0] + two_pi;
      const double start = std::clamp(wrap(t0) < a ? wrap(t0) + two_pi : wrap(t0), a, b);
      const double t = newton(x, start, a, b);
      const double distance = norm(curve_.position(wrap(t)) - x);
      if (distance < best_distance) best_distance = distance, best_t = t, at_corner = t <= a || t >= b;
    }
    if (!at_corner) return at(x, wrap(best_t));
    // Nearest at the corner V: the side from the mean of the two edge normals there.
    const double tv = wrap(best_t), e = 1e-9;
    const Point2 V = curve_.position(tv);
    const Point2 mean = curve_.outward_normal(wrap(tv - e)) + curve_.outward_normal(wrap(tv + e));
    const double r = norm(x - V);
    Kink k;
    k.t = tv;
    k.foot = V;
    k.d = dot(x - V, mean) >= 0 ? r : -r;
    k.normal = r > 0 ? (1.0 / k.d) * (x - V) : (1.0 / norm(mean)) * mean;
    k.kappa = 0.0;
    return k;
  }

 private:
  double newton(Point2 x, double t, double lo, double hi) const {
    for (int it = 0; it < 12; ++it) {
      const double tw = wrap(t);
      const Point2 p = curve_.position(tw), d1 = curve_.derivative(tw), d2 = curve_.second_derivative(tw);
      const Point2 r = p - x;
      const double f = dot(r, d1), df = dot(d1, d1) + dot(r, d2);
      const double step = df > 0 ? f / df : f / dot(d1, d1);
      const double next = std::clamp(t - step, lo, hi);
      if (std::abs(next - t) < 1e-14 * two_pi) return next;
      t = next;
    }
    return t;
  }
  Kink at(Point2 x, double t) const {
    Kink k;
    k.t = t;
    k.normal = curve_.outward_normal(t);
    k.foot = curve_.position(t);
    k.d = dot(x - k.foot, k.normal);
    k.kappa = curve_.curvature(t);
    return k;
  }
  const Curve& curve_;
  std::vector<double> corners_;
};

/// Arc of a curve parameter: arc i covers [arc_begin[i], arc_end[i]) (the last one may wrap past 0).
class ArcIndex {
 public:
  explicit ArcIndex(const Collocation& arcs) {
    for (int i = 0; i < arcs.m; ++i) begins_.emplace_back(arcs.arc_begin[i], i);
    std::sort(begins_.begin(), begins_.end());
  }
  int operator()(double t) const {
    auto it = std::upper_bound(begins_.begin(), begins_.end(), std::make_pair(t, 1 << 30));
    return it == begins_.begin() ? begins_.back().second : std::prev(it)->second;
  }

 private:
  std::vector<std::pair<double, int>> begins_;
};

/// Kink values at the grid nodes of a band around γ, each from the osculating circle at the centre
/// of a cut cell next to it (computed once); nodes met later are projected exactly.
class NodeKinks {
 public:
  NodeKinks(const Curve& curve, const Grid2& grid) : project_(curve), grid_(grid) {}
  std::size_t key(int i, int j) const { return std::size_t(j + 2) * std::size_t(grid_.nx() + 5) + std::size_t(i + 2); }
  /// The band: every node of `nodes` with the index of a cut cell near it (the first one wins).
  void build(std::vector<std::pair<std::size_t, int>> nodes, const std::vector<Kink>& centres,
             const std::vector<double>& speeds, const Execution& execution) {
    std::stable_sort(nodes.begin(), nodes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    nodes.erase(
        std::unique(nodes.begin(), nodes.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
        nodes.end());
    keys_.resize(nodes.size());
    kinks_.resize(nodes.size());
    const std::size_t width = std::size_t(grid_.nx() + 5);
#pragma omp parallel for num_threads(execution.threads()) schedule(static)
    for (std::size_t n = 0; n < nodes.size(); ++n) {
      const auto [k, cell] = nodes[n];
      const int i = int(k % width) - 2, j = int(k / width) - 2;
      keys_[n] = k;
      kinks_[n] = project_.near(centres[cell], {grid_.x(i), grid_.y(j)}, speeds[cell]);
    }
  }
  /// A node of the band, or (projected from t0 and kept) another one.
  const Kink& at(int i, int j, double t0) {
    if (const Kink* k = find(i, j)) return *k;
    auto it = extra_.find(key(i, j));
    if (it == extra_.end()) it = extra_.emplace(key(i, j), project_({grid_.x(i), grid_.y(j)}, t0)).first;
    return it->second;
  }
  /// A node of the band (precondition: it is one).
  const Kink& at(int i, int j) const { return *find(i, j); }
  /// f(i, j, kink) for every node of the band.
  template <class F>
  void for_each(F&& f) const {
    const std::size_t width = std::size_t(grid_.nx() + 5);
    for (std::size_t n = 0; n < keys_.size(); ++n) f(int(keys_[n] % width) - 2, int(keys_[n] / width) - 2, kinks_[n]);
  }

 private:
  const Kink* find(int i, int j) const {
    const auto it = std::lower_bound(keys_.begin(), keys_.end(), key(i, j));
    return it != keys_.end() && *it == key(i, j) ? &kinks_[std::size_t(it - keys_.begin())] : nullptr;
  }
  Projector project_;
  const Grid2& grid_;
  std::vector<std::size_t> keys_;  // sorted
  std::vector<Kink> kinks_;
  std::unordered_map<std::size_t, Kink> extra_;
};

/// Q1 on a square cell, local nodes (0,0), (1,0), (0,1), (1,1): value and gradient at (ξ, η).
struct RowEntry {
  int arc, i, j;
  double value;
};

/// Rows r_j (one per arc) from the per-cell entries: merged per (arc, node) in cell order (the same
/// for any thread count), boundary nodes of the box dropped.
SparseRows merge_rows(const std::vector<std::vector<RowEntry>>& by_cell, int m, const Grid2& grid) {
  std::vector<RowEntry> entries;
  for (const auto& cell_entries : by_cell) entries.insert(entries.end(), cell_entries.begin(), cell_entries.end());
  std::stable_sort(entries.begin(), entries.end(), [&](const RowEntry& a, const RowEntry& b) {
    return std::tie(a.arc, a.j, a.i) < std::tie(b.arc, b.j, b.i);
  });
  SparseRows rows;
  std::size_t e = 0;
  for (int arc = 0; arc < m; ++arc) {
    for (; e < entries.size() && entries[e].arc == arc;) {
      const RowEntry first = entries[e];
      double value = 0.0;
      for (; e < entries.size() && entries[e].arc == arc && entries[e].i == first.i && entries[e].j == first.j; ++e)
        value += entries[e].value;
      if (grid.has_unknown(first.i, first.j))
        rows.entries.push_back({grid.index(first.i, first.j), first.i, first.j, 0, value});
    }
    rows.row_begin.push_back(rows.entries.size());
  }
  return rows;
}

}  // namespace

struct KinkCorrection::State {
  State(const CurveGridIntersection& g, const Collocation& a)
      : gamma(g), arcs(a), arc_of(a), nodes(g.curve(), g.grid()) {}
  const CurveGridIntersection& gamma;
  const Collocation& arcs;
  ArcIndex arc_of;
  mutable NodeKinks nodes;
  SparseRows galerkin;
};

KinkCorrection::~KinkCorrection() = default;
KinkCorrection::KinkCorrection(KinkCorrection&&) noexcept = default;
KinkCorrection& KinkCorrection::operator=(KinkCorrection&&) noexcept = default;

const SparseRows& KinkCorrection::galerkin() const { return state_->galerkin; }

namespace {

double cell_parameter(const CurveGridIntersection& gamma, const CutCell& cell) {
  const CurvePiece& piece = gamma.pieces()[cell.pieces.front()];
  return 0.5 * (piece.t0 + piece.t1);
}

/// Step 1 of the kink correction: the nearest point of every cut cell's centre (exact) and the curve's
/// speed there, then the kink values at the nodes of the cut cells and of the two rings of cells
/// around them (the band that trace stencils reach).
void nearest_points_and_band(const CurveGridIntersection& gamma, const Projector& project, NodeKinks& nodes,
                             std::vector<Kink>& centres, std::vector<double>& speeds, const Execution& execution) {
  const Grid2& grid = gamma.grid();
  const double h = grid.h();
  const auto& cells = gamma.cut_cells();
  centres.resize(cells.size());
  speeds.resize(cells.size());
#pragma omp parallel for num_threads(execution.threads()) schedule(static)
  for (std::size_t n = 0; n < cells.size(); ++n) {
    centres[n] =
        project({grid.x(cells[n].ix) + 0.5 * h, grid.y(cells[n].iy) + 0.5 * h}, cell_parameter(gamma, cells[n]));
    speeds[n] = gamma.curve().speed(centres[n].t);
  }
  std::vector<std::pair<std::size_t, int>> band;
  band.reserve(36 * cells.size());
  for (std::size_t n = 0; n < cells.size(); ++n)
    for (int j = cells[n].iy - 2; j <= cells[n].iy + 3; ++j)
      for (int i = cells[n].ix - 2; i <= cells[n].ix + 3; ++i)
        if (i >= 0 && j >= 0 && i <= grid.nx() && j <= grid.ny()) band.emplace_back(nodes.key(i, j), int(n));
  nodes.build(std::move(band), centres, speeds, execution);
}

}  // namespace

// Step 2 is one quadrature loop over the cut cells that shares step 1's band of kink values and
// nearest points.
KinkCorrection::KinkCorrection(const CurveGridIntersection& gamma, const Collocation& arcs, double c,
                               const Execution& execution)
    : state_(std::make_unique<State>(gamma, arcs)) {
  const Grid2& grid = gamma.grid();
  const Projector project(gamma.curve());
  const double h = grid.h();
  const int m = arcs.m;
  const ArcIndex& arc_of = state_->arc_of;
  NodeKinks& nodes = state_->nodes;
  const auto& cells = gamma.cut_cells();
  std::vector<Kink> centres;
  std::vector<double> speeds;
  nearest_points_and_band(gamma, project, nodes, centres, speeds, execution);  // 1.
  // 2. r_j,k = a(ψ_j − I_hψ_j, φ_k) on every cut cell: the part outside ω is the whole cell minus
  //    its part in ω (ψ_j's smooth extension q(d) on both), and I_hψ_j takes the element matrix.
  //    Each quadrature point goes to the arc its nearest curve point lies on.
  const GaussRule& rule = gauss_legendre(3);  // q(d) is smooth on the cell: degree-5 exactness suffices
  constexpr int cut_q = 3;
  // Element matrix of −Δ + c on a square Q1 cell (local nodes as in Q1Element).
  const double K[4][4] = {{4, -1, -1, -2}, {-1, 4, -2, -1}, {-1, -2, 4, -1}, {-2, -1, -1, 4}};
  const double M[4][4] = {{4, 2, 2, 1}, {2, 4, 1, 2}, {2, 1, 4, 2}, {1, 2, 2, 4}};
  std::vector<std::vector<RowEntry>> by_cell(cells.size());  // summed in cell order: the same for any thread count
#pragma omp parallel num_threads(execution.threads())
  {
    std::vector<QuadraturePoint> inside;
#pragma omp for schedule(dynamic, 16)
    for (std::size_t n = 0; n < cells.size(); ++n) {
      const CutCell& cell = cells[n];
      // Sums per arc met in this cell (rarely more than two) for the cell's four nodes.
      std::vector<std::pair<int, std::array<double, 4>>> sums;
      auto sums_of = [&](int arc) -> std::array<double, 4>& {
        for (auto& [a, v] : sums)
          if (a == arc) return v;
        return sums.emplace_back(arc, std::array<double, 4>{}).second;
      };
      // Nearest points of the quadrature points from the cell centre's (its osculating circle).
      const double x0 = grid.x(cell.ix), y0 = grid.y(cell.iy);
      auto add_point = [&](double x, double y, double w) {
        const Kink kink = project.near(centres[n], {x, y}, speeds[n]);
        const Q1Element<2> basis({(x - x0) / h, (y - y0) / h}, h);
        const double q = kink.q();
        const Point2 grad = kink.grad_q();
        std::array<double, 4>& v = sums_of(arc_of(kink.t));
        for (int k = 0; k < 4; ++k) v[k] += w * (dot(grad, basis.gradient(k)) + c * q * basis.value[k]);
      };
      for (std::size_t b = 0; b < rule.nodes.size(); ++b)
        for (std::size_t a = 0; a < rule.nodes.size(); ++a)
          add_point(x0 + rule.nodes[a] * h, y0 + rule.nodes[b] * h, rule.weights[a] * rule.weights[b] * h * h);
      inside.clear();
      gamma.cut_cell_rule(cell, cut_q, inside);
      for (const QuadraturePoint& p : inside) add_point(p.x, p.y, -p.weight);
      for (int l = 0; l < 4; ++l) {
        const Kink& kink = nodes.at(cell.ix + (l & 1), cell.iy + (l >> 1));
        const double psi = kink.psi();
        if (psi == 0.0) continue;
        std::array<double, 4>& v = sums_of(arc_of(kink.t));
        for (int k = 0; k < 4; ++k) v[k] -= psi * (K[l][k] / 6.0 + c * h * h * M[l][k] / 36.0);
      }
      for (const auto& [arc, v] : sums)
        for (int k = 0; k < 4; ++k) by_cell[n].push_back({arc, cell.ix + (k & 1), cell.iy + (k >> 1), v[k]});
    }
  }
  state_->galerkin = merge_rows(by_cell, m, grid);
}

void KinkCorrection::add_kinks(const std::vector<double>& lambda, GridVector& u, std::optional<Slab> slab) const {
  const Grid2& grid = state_->gamma.grid();
  const Slab s = slab.value_or(grid.every_layer());
  const std::size_t offset = grid.slab_offset(s);
  state_->nodes.for_each([&](int i, int j, const Kink& kink) {
    const double psi = kink.psi();
    if (psi != 0.0 && grid.has_unknown(i, j) && s.holds(grid.layer(j)))
      u[grid.index(i, j) - offset] += lambda[state_->arc_of(kink.t)] * psi;
  });
}

Eigen::SparseMatrix<double> KinkCorrection::direct(const SparseRows& rows) const {
  const State& st = *state_;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int r = 0; r < rows.n_rows(); ++r)
    for (std::size_t k = rows.row_begin[r]; k < rows.row_begin[r + 1]; ++k) {
      const auto& entry = rows.entries[k];
      const Kink& kink = st.nodes.at(entry.i, entry.j, st.arcs.t[r]);
      if (kink.psi() != 0.0) triplets.emplace_back(r, st.arc_of(kink.t), entry.value * kink.psi());
    }
  Eigen::SparseMatrix<double> D(rows.n_rows(), st.arcs.m);
  D.setFromTriplets(triplets.begin(), triplets.end());
  return D;
}

}  // namespace fictus
