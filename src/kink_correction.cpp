#include "fictus/kink_correction.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include "fictus/quadrature.hpp"

namespace fictus {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

/// The point of the curve nearest to x (Newton on (p(t) − x)·p′(t) = 0 from t0, a few steps:
/// x is within a cell or two of the curve) and the kink function q(d)⁺ there.
struct Kink {
  double t = 0.0;      // parameter of the nearest point, in [0, 2π)
  double d = 0.0;      // signed distance, > 0 outside ω
  double kappa = 0.0;  // curvature there
  Point normal;        // outward unit normal there
  double q() const { return d - 0.5 * kappa * d * d; }                // ψ outside ω, extended smoothly inside
  double psi() const { return d > 0 ? q() : 0.0; }                    // q(d)⁺
  Point grad_q() const { return (1.0 - kappa * d) * normal; }          // ∇q (d small)
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

  Kink operator()(Point x, double t0) const {
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
    const Point V = curve_.position(tv);
    const Point mean = curve_.outward_normal(wrap(tv - e)) + curve_.outward_normal(wrap(tv + e));
    const double r = norm(x - V);
    Kink k;
    k.t = tv;
    k.d = dot(x - V, mean) >= 0 ? r : -r;
    k.normal = r > 0 ? (1.0 / k.d) * (x - V) : (1.0 / norm(mean)) * mean;
    k.kappa = 0.0;
    return k;
  }

 private:
  double newton(Point x, double t, double lo, double hi) const {
    for (int it = 0; it < 12; ++it) {
      const double tw = wrap(t);
      const Point p = curve_.position(tw), d1 = curve_.derivative(tw), d2 = curve_.second_derivative(tw);
      const Point r = p - x;
      const double f = dot(r, d1), df = dot(d1, d1) + dot(r, d2);
      const double step = df > 0 ? f / df : f / dot(d1, d1);
      const double next = std::clamp(t - step, lo, hi);
      if (std::abs(next - t) < 1e-14 * two_pi) return next;
      t = next;
    }
    return t;
  }
  Kink at(Point x, double t) const {
    Kink k;
    k.t = t;
    k.normal = curve_.outward_normal(t);
    k.d = dot(x - curve_.position(t), k.normal);
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

/// Kink values at grid nodes, computed once per node.
class NodeKinks {
 public:
  NodeKinks(const Curve& curve, const Grid& grid) : project_(curve), grid_(grid) {}
  std::size_t key(int i, int j) const { return std::size_t(j + 2) * std::size_t(grid_.nx() + 5) + std::size_t(i + 2); }
  /// Registers node (i, j) with a starting parameter; returns true if it is new.
  bool add(int i, int j, double t0) { return start_.emplace(key(i, j), t0).second; }
  void compute(int threads) {
    std::vector<std::pair<std::size_t, double>> todo(start_.begin(), start_.end());
    std::vector<Kink> values(todo.size());
    const std::size_t width = std::size_t(grid_.nx() + 5);
#pragma omp parallel for num_threads(threads < 1 ? 1 : threads) schedule(static)
    for (std::size_t n = 0; n < todo.size(); ++n) {
      const int i = int(todo[n].first % width) - 2, j = int(todo[n].first / width) - 2;
      values[n] = project_({grid_.x(i), grid_.y(j)}, todo[n].second);
    }
    for (std::size_t n = 0; n < todo.size(); ++n) kinks_[todo[n].first] = values[n];
  }
  const Kink& at(int i, int j, double t0) {
    auto it = kinks_.find(key(i, j));
    if (it == kinks_.end()) it = kinks_.emplace(key(i, j), project_({grid_.x(i), grid_.y(j)}, t0)).first;
    return it->second;
  }
  const Kink& at(int i, int j) const { return kinks_.at(key(i, j)); }
  /// f(i, j, kink) for every node registered before compute() (not those met later by at()).
  template <class F>
  void for_each(F&& f) const {
    const std::size_t width = std::size_t(grid_.nx() + 5);
    for (const auto& [key, t0] : start_) f(int(key % width) - 2, int(key / width) - 2, kinks_.at(key));
  }

 private:
  Projector project_;
  const Grid& grid_;
  std::unordered_map<std::size_t, double> start_;
  std::unordered_map<std::size_t, Kink> kinks_;
};

/// Q1 on a square cell, local nodes (0,0), (1,0), (0,1), (1,1): value and gradient at (ξ, η).
struct Q1Basis {
  double value[4];
  Point gradient[4];
  Q1Basis(double xi, double eta, double h) {
    for (int k = 0; k < 4; ++k) {
      const int a = k & 1, b = k >> 1;
      const double fx = a ? xi : 1 - xi, fy = b ? eta : 1 - eta;
      value[k] = fx * fy;
      gradient[k] = {(a ? 1.0 : -1.0) * fy / h, (b ? 1.0 : -1.0) * fx / h};
    }
  }
};

struct RowEntry {
  int arc, i, j;
  double value;
};

}  // namespace

SparseRows add_rows(const SparseRows& a, const SparseRows& b) {
  SparseRows out;
  for (int r = 0; r < a.n_rows(); ++r) {
    std::vector<SparseRows::Entry> row(a.entries.begin() + std::ptrdiff_t(a.row_begin[r]),
                                       a.entries.begin() + std::ptrdiff_t(a.row_begin[r + 1]));
    for (std::size_t k = b.row_begin[r]; k < b.row_begin[r + 1]; ++k) {
      const auto& e = b.entries[k];
      auto same = std::find_if(row.begin(), row.end(), [&](const SparseRows::Entry& x) { return x.index == e.index; });
      if (same != row.end()) same->value += e.value;
      else row.push_back(e);
    }
    out.entries.insert(out.entries.end(), row.begin(), row.end());
    out.row_begin.push_back(out.entries.size());
  }
  return out;
}

struct KinkCorrection::State {
  State(const CurveGridIntersection& g, const Collocation& a) : gamma(g), arcs(a), arc_of(a), nodes(g.curve(), g.grid()) {}
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

KinkCorrection::KinkCorrection(const CurveGridIntersection& gamma, const Collocation& arcs, double c, int threads)
    : state_(std::make_unique<State>(gamma, arcs)) {
  const Grid& grid = gamma.grid();
  const Projector project(gamma.curve());
  const double h = grid.h();
  const int m = arcs.m;
  const ArcIndex& arc_of = state_->arc_of;
  NodeKinks& nodes = state_->nodes;
  const auto& cells = gamma.cut_cells();
  auto cell_parameter = [&](const CutCell& cell) {
    const CurvePiece& piece = gamma.pieces()[cell.pieces.front()];
    return 0.5 * (piece.t0 + piece.t1);
  };

  // 1. Kink values at the nodes of the cut cells and of the two rings of cells around them (the band
  //    that trace stencils reach).
  for (const CutCell& cell : cells)
    for (int j = cell.iy - 2; j <= cell.iy + 3; ++j)
      for (int i = cell.ix - 2; i <= cell.ix + 3; ++i)
        if (i >= 0 && j >= 0 && i <= grid.nx() && j <= grid.ny()) nodes.add(i, j, cell_parameter(cell));
  nodes.compute(threads);
  // 2. r_j,k = a(ψ_j − I_hψ_j, φ_k) on every cut cell: the part outside ω is the whole cell minus
  //    its part in ω (ψ_j's smooth extension q(d) on both), and I_hψ_j takes the element matrix.
  //    Each quadrature point goes to the arc its nearest curve point lies on.
  const GaussRule& rule = gauss_legendre(4);
  constexpr int cut_q = 3;
  // Element matrix of −Δ + c on a square Q1 cell (local nodes as in Q1Basis).
  const double K[4][4] = {{4, -1, -1, -2}, {-1, 4, -2, -1}, {-1, -2, 4, -1}, {-2, -1, -1, 4}};
  const double M[4][4] = {{4, 2, 2, 1}, {2, 4, 1, 2}, {2, 1, 4, 2}, {1, 2, 2, 4}};
  std::vector<std::vector<RowEntry>> by_cell(cells.size());  // summed in cell order: the same for any thread count
#pragma omp parallel num_threads(threads < 1 ? 1 : threads)
  {
    std::vector<QuadraturePoint> inside;
#pragma omp for schedule(dynamic, 16)
    for (std::size_t n = 0; n < cells.size(); ++n) {
      const CutCell& cell = cells[n];
      std::vector<RowEntry>& local = by_cell[n];
      const double t0 = cell_parameter(cell), x0 = grid.x(cell.ix), y0 = grid.y(cell.iy);
      auto add_point = [&](double x, double y, double w) {
        const Kink kink = project({x, y}, t0);
        const Q1Basis basis((x - x0) / h, (y - y0) / h, h);
        const int arc = arc_of(kink.t);
        const double q = kink.q();
        const Point grad = kink.grad_q();
        for (int k = 0; k < 4; ++k)
          local.push_back({arc, cell.ix + (k & 1), cell.iy + (k >> 1),
                           w * (dot(grad, basis.gradient[k]) + c * q * basis.value[k])});
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
        const int arc = arc_of(kink.t);
        for (int k = 0; k < 4; ++k)
          local.push_back({arc, cell.ix + (k & 1), cell.iy + (k >> 1), -psi * (K[l][k] / 6.0 + c * h * h * M[l][k] / 36.0)});
      }
    }
  }

  // Rows r_j: entries merged per (arc, node), boundary nodes of the box dropped.
  std::vector<RowEntry> entries;
  for (const auto& cell_entries : by_cell) entries.insert(entries.end(), cell_entries.begin(), cell_entries.end());
  std::stable_sort(entries.begin(), entries.end(), [&](const RowEntry& a, const RowEntry& b) {
    return std::tie(a.arc, a.j, a.i) < std::tie(b.arc, b.j, b.i);
  });
  SparseRows& rows = state_->galerkin;
  std::size_t e = 0;
  for (int arc = 0; arc < m; ++arc) {
    for (; e < entries.size() && entries[e].arc == arc;) {
      const RowEntry first = entries[e];
      double value = 0.0;
      for (; e < entries.size() && entries[e].arc == arc && entries[e].i == first.i && entries[e].j == first.j; ++e)
        value += entries[e].value;
      if (grid.has_unknown(first.i, first.j)) rows.entries.push_back({grid.index(first.i, first.j), first.i, first.j, value});
    }
    rows.row_begin.push_back(rows.entries.size());
  }
}

void KinkCorrection::add_kinks(const std::vector<double>& lambda, GridVector& u) const {
  const Grid& grid = state_->gamma.grid();
  state_->nodes.for_each([&](int i, int j, const Kink& kink) {
    const double psi = kink.psi();
    if (psi != 0.0 && grid.has_unknown(i, j)) u[grid.index(i, j)] += lambda[state_->arc_of(kink.t)] * psi;
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
