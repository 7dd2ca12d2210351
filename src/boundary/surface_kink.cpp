#include "fictus/boundary/surface_kink.hpp"

#include "fictus/boundary/omega_quadrature.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <omp.h>
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include "fictus/grid/q1_element.hpp"
#include "fictus/grid/quadrature.hpp"

namespace fictus {

namespace {

Point3 times(const Matrix3& A, const Point3& v) { return {dot(A[0], v), dot(A[1], v), dot(A[2], v)}; }

/// p moved onto γ along the level gradient (Newton on the level function).
Point3 drop_onto(const Surface& gamma, Point3 p, double tolerance) {
  for (int it = 0; it < 8; ++it) {
    const Point3 g = gamma.level_gradient(p);
    const double g2 = dot(g, g), f = gamma.level(p);
    if (!(g2 > 0)) break;
    p = p - (f / g2) * g;
    if (std::abs(f) <= tolerance * std::sqrt(g2)) break;
  }
  return p;
}

}  // namespace

Eigen::Matrix3d shape_operator(const Point3& gradient, const Matrix3& hessian) {
  const double slope = norm(gradient);
  Eigen::Matrix3d P = Eigen::Matrix3d::Identity(), H;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      P(a, b) -= gradient[a] * gradient[b] / (slope * slope);
      H(a, b) = hessian[a][b];
    }
  return P * H * P / slope;
}

SurfaceStart surface_start(const Surface& gamma, const Point3& start, double tolerance) {
  SurfaceStart s;
  s.point = drop_onto(gamma, start, tolerance);
  s.gradient = gamma.level_gradient(s.point);
  s.hessian = gamma.level_hessian(s.point);
  return s;
}

SurfaceFoot nearest_point(const Surface& gamma, const Point3& x, const Point3& start, double tolerance) {
  return nearest_point(gamma, x, surface_start(gamma, start, tolerance), tolerance);
}

SurfaceFoot nearest_point(const Surface& gamma, const Point3& x, const SurfaceStart& start, double tolerance) {
  // The start's gradient and Hessian stand for the first iteration's, and for the end's where no step
  // was taken: the same values as computed there (the Hessian at the start is needed either way).
  Point3 p = start.point;
  Point3 g = start.gradient;
  bool moved = false;
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 20; ++it) {
    const double slope = norm(g);
    if (!(slope > 0)) break;
    const Point3 n = (1.0 / slope) * g;
    const Point3 r = x - p;
    const double d = dot(r, n);
    const Point3 t = r - d * n;
    // Converged, or no longer converging (derivatives by differences stop it near their accuracy).
    if (norm(t) <= tolerance || (it >= 3 && norm(t) > 0.5 * previous)) break;
    previous = norm(t);
    // (I + d W) δ = t with W = P Hess P / |∇level| the shape operator (P the tangent projector): the
    // step that keeps x − p along the normal to first order; the normal direction is left as is.
    const Eigen::Matrix3d M =
        Eigen::Matrix3d::Identity() + d * shape_operator(g, it == 0 ? start.hessian : gamma.level_hessian(p));
    const Eigen::Vector3d step = M.partialPivLu().solve(Eigen::Vector3d(t.x, t.y, t.z));
    p = drop_onto(gamma, p + Point3{step[0], step[1], step[2]}, tolerance);
    moved = true;
    g = gamma.level_gradient(p);  // the next iteration's, or the end's
  }
  SurfaceFoot k;
  k.foot = p;
  const double slope = norm(g);
  k.normal = (1.0 / slope) * g;
  k.d = dot(x - p, k.normal);
  const Matrix3 hessian = moved ? gamma.level_hessian(p) : start.hessian;
  const double trace = hessian[0][0] + hessian[1][1] + hessian[2][2];
  k.H = (trace * slope * slope - dot(g, times(hessian, g))) / (slope * slope * slope);
  const Eigen::Matrix3d W = shape_operator(g, hessian);
  k.K2 = (W * W).trace();
  if (!std::isfinite(k.d) || !std::isfinite(k.H) || !std::isfinite(k.normal.x + k.normal.y + k.normal.z)) {
    char where[96];
    std::snprintf(where, sizeof where, "(%.4g, %.4g, %.4g)", x.x, x.y, x.z);
    throw std::invalid_argument(std::string("geometry: no nearest point of the surface to ") + where +
                                " (a vanishing or non-finite gradient of the level function there)");
  }
  return k;
}

SurfaceMap onto_surface(const Surface& gamma, double tolerance) {
  return [&gamma, tolerance](const Point3& x, const Point3& normal, double& factor) {
    const SurfaceFoot foot = nearest_point(gamma, x, x, tolerance);
    factor = std::abs(dot(normal, foot.normal)) / (1 + foot.H * foot.d);
    return foot.foot;
  };
}

namespace {

/// The patch of a point of γ: the triangle holding its projection onto the triangle's plane (the one
/// nearest to the point when several or none do). Triangles are found in buckets of the triangle
/// centroids; `near` collects those around a point once, for every point of one voxel.
class PatchLocator {
 public:
  PatchLocator(const PatchedSurface& surface, double reach) : surface_(surface) {
    double longest = 0;
    for (const Triangle3& t : surface.triangles)
      longest = std::max({longest, norm(t.b - t.a), norm(t.c - t.b), norm(t.a - t.c)});
    side_ = longest + reach;
    for (const Triangle3& t : surface.triangles) {
      Frame f;
      f.a = t.a, f.e1 = t.b - t.a, f.e2 = t.c - t.a;
      f.a11 = dot(f.e1, f.e1), f.a12 = dot(f.e1, f.e2), f.a22 = dot(f.e2, f.e2);
      const Point3 n = cross(f.e1, f.e2);
      f.inverse_det = 1 / dot(n, n);  // a11·a22 − a12², without its cancellation on slivers
      f.longest = std::sqrt(std::max(f.a11, f.a22));
      f.normal = (1 / norm(n)) * n;
      const Point3 middle = centroid(t);
      f.corner = std::max({norm(t.a - middle), norm(t.b - middle), norm(t.c - middle)});
      frames_.push_back(f);
    }
    buckets_.reserve(surface.triangles.size());
    for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
      centroids_.push_back(centroid(surface.triangles[t]));
      buckets_.emplace_back(key(bucket(centroids_.back())), int(t));
    }
    std::sort(buckets_.begin(), buckets_.end());
  }
  /// The triangles that may hold a point of the surface within `reach` of p (their centroids lie
  /// within the longest edge + reach of p).
  void near(const Point3& p, std::vector<int>& out) const {
    out.clear();
    const std::array<std::int64_t, 3> b = bucket(p);
    for (std::int64_t dz = -1; dz <= 1; ++dz)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          const std::int64_t k = key({b[0] + dx, b[1] + dy, b[2] + dz});
          auto it = std::lower_bound(buckets_.begin(), buckets_.end(), std::make_pair(k, -1));
          for (; it != buckets_.end() && it->first == k; ++it)
            if (norm(centroids_[std::size_t(it->second)] - p) <= side_) out.push_back(it->second);
        }
  }
  /// Those of `candidates` that may hold a point of the surface within `reach` of p: their centroids
  /// lie within reach + (the triangle's farthest corner from its centroid) of p. (Only those of
  /// `candidates`: near() keeps the triangles within its own reach of the point.)
  void within(const Point3& p, double reach, const std::vector<int>& candidates, std::vector<int>& out) const {
    out.clear();
    for (int t : candidates)
      if (norm(centroids_[std::size_t(t)] - p) <= reach + frames_[std::size_t(t)].corner) out.push_back(t);
  }
  /// The patch of p among the triangles `candidates`.
  int patch(const Point3& p, const std::vector<int>& candidates) const {
    int best = -1;
    double best_score = 1e300;
    for (int t : candidates) {
      const Frame& f = frames_[std::size_t(t)];
      const Point3 r = p - f.a;
      const double b1 = dot(r, f.e1), b2 = dot(r, f.e2);
      const double u = (f.a22 * b1 - f.a12 * b2) * f.inverse_det, v = (f.a11 * b2 - f.a12 * b1) * f.inverse_det;
      // Outside the triangle: the distance past its edges counts; inside: the distance to its plane.
      const double outside = std::max({0.0, -u, -v, u + v - 1}) * f.longest;
      const double score = outside + std::abs(dot(r, f.normal)) * 1e-3;
      if (score < best_score) best_score = score, best = t;
    }
    return best < 0 ? -1 : surface_.patch_of[std::size_t(best)];
  }
  int patch(const Point3& p) const {
    std::vector<int> candidates;
    near(p, candidates);
    return patch(p, candidates);
  }

 private:
  static Point3 centroid(const Triangle3& t) { return (1.0 / 3.0) * (t.a + t.b + t.c); }
  std::array<std::int64_t, 3> bucket(const Point3& p) const {
    return {std::int64_t(std::floor(p.x / side_)), std::int64_t(std::floor(p.y / side_)),
            std::int64_t(std::floor(p.z / side_))};
  }
  static std::int64_t key(const std::array<std::int64_t, 3>& b) {
    return ((b[2] + 4096) * 8192 + (b[1] + 4096)) * 8192 + b[0] + 4096;
  }
  /// A triangle's corner a, edges e1 = b − a and e2 = c − a, their Gram matrix and unit normal.
  struct Frame {
    Point3 a, e1, e2, normal;
    double a11, a12, a22, inverse_det, longest, corner;  // corner: the farthest corner from the centroid
  };
  const PatchedSurface& surface_;
  std::vector<Frame> frames_;
  double side_ = 1;
  std::vector<Point3> centroids_;
  std::vector<std::pair<std::int64_t, int>> buckets_;  // (bucket, triangle), sorted
};

/// A node of the band: its key (i + (n0+1)(j + (n1+1)k)), patch and ψ.
struct BandNode {
  std::size_t key;
  Grid3::Index node;
  int patch;
  double psi;
};

struct RowEntry {
  int patch;
  Grid3::Index node;
  double value;
};

}  // namespace

struct SurfaceKink::State {
  explicit State(const Grid3& g) : grid(g) {}
  struct Build;
  const Grid3& grid;
  int m = 0;
  std::vector<BandNode> band;  // sorted by key
  SparseRows galerkin;
  std::size_t cut_voxels = 0;

  std::size_t key(const Grid3::Index& i) const {
    return (std::size_t(i[2]) * std::size_t(grid.n(1) + 1) + std::size_t(i[1])) * std::size_t(grid.n(0) + 1) +
           std::size_t(i[0]);
  }
  const BandNode* find(const Grid3::Index& i) const {
    for (int d = 0; d < 3; ++d)
      if (i[d] < 0 || i[d] > grid.n(d)) return nullptr;
    const std::size_t k = key(i);
    const auto it =
        std::lower_bound(band.begin(), band.end(), k, [](const BandNode& b, std::size_t v) { return b.key < v; });
    return it != band.end() && it->key == k ? &*it : nullptr;
  }
};

SurfaceKink::~SurfaceKink() = default;
SurfaceKink::SurfaceKink(SurfaceKink&&) noexcept = default;
SurfaceKink& SurfaceKink::operator=(SurfaceKink&&) noexcept = default;

const SparseRows& SurfaceKink::galerkin() const { return state_->galerkin; }
std::size_t SurfaceKink::cut_voxels() const { return state_->cut_voxels; }

/// The construction of the kink model, step by step, with what the steps share.
struct SurfaceKink::State::Build {
  Build(State& s, const Grid3& g, const Surface& surface, const PatchedSurface& p, double coefficient,
        const Execution& e)
      : st(s), grid(g), gamma(surface), patches(p), c(coefficient), execution(e) {}
  State& st;
  const Grid3& grid;
  const Surface& gamma;
  const PatchedSurface& patches;
  double c;
  const Execution& execution;
  // Distributed, each rank makes every P-th piece of the work (layers, voxels), and all take the parts.
  const Distribution& distribution = execution.distribution();
  bool mine(std::size_t piece) const {
    return piece % std::size_t(distribution.size()) == std::size_t(distribution.rank());
  }
  double h = grid.h();
  double band_width = 6 * h;  // the nodes of the two rings of voxels around the cut ones (≤ 5.2h)
  double tolerance = 1e-13 * h;
  // The feet of a voxel's points lie within 0.9h of its centre's (a point farther is sought among
  // all the triangles near the centre's); the triangles (edges about h) lie within 0.25h of γ, their
  // sag, which is O(κh²).
  double spread = 0.9 * h, margin = 0.25 * h;
  PatchLocator locate{patches, h};
  std::array<int, 3> first{}, last{};
  std::exception_ptr failure;      // nearest_point throws on a vanishing gradient: kept, thrown after each loop
  std::atomic<bool> stop = false;  // an interruption seen by thread 0 (the caller's) ends every thread's work
  const GaussRule& rule = gauss_legendre(3);  // q(d) is smooth on the voxel: degree-5 exactness suffices
  static constexpr int cut_q = 3;
  double K[8][8] = {}, M[8][8] = {};  // the element matrices of a voxel

  void keep() {
#pragma omp critical(fictus_surface_kink_failure)
    if (!failure) failure = std::current_exception();
  }
  /// After each loop: a failure or an interruption, thrown on every rank (they then take each other's
  /// parts: none may go on alone).
  void rethrow() const { distribution.throw_first_failure(failure, stop || execution.interrupt_requested()); }
  void bounds();
  void band();
  void element_matrices();
  std::vector<Grid3::Index> cut_voxels();
  void add_rings(std::vector<Grid3::Index>& voxels);
  std::vector<std::vector<RowEntry>> residuals(const std::vector<Grid3::Index>& voxels);
  void voxel_residual(const Grid3::Index& cell, std::vector<int>& near, std::vector<int>& local,
                      std::vector<std::pair<int, std::array<double, 8>>>& sums,
                      std::vector<std::pair<Point3, double>>& inside, std::vector<RowEntry>& out);
  void rows(std::vector<std::vector<RowEntry>> by_voxel);
};

/// The range of nodes within the band's reach of γ's box.
void SurfaceKink::State::Build::bounds() {
  const Box3 box = gamma.bounds();
  for (int d = 0; d < 3; ++d) {
    first[d] = std::max(0, grid.cell(d, box.lower[d] - band_width) - 1);
    last[d] = std::min(grid.n(d), grid.cell(d, box.upper[d] + band_width) + 2);
  }
}

/// Step 1. The band: the nodes outside ω within 6h of γ, with ψ and the patch of their nearest point.
/// Distributed, each rank makes every P-th layer, and all take every rank's nodes.
void SurfaceKink::State::Build::band() {
  std::vector<std::vector<BandNode>> band_by_z(std::size_t(last[2] - first[2] + 1));
#pragma omp parallel for num_threads(execution.threads()) schedule(dynamic, 1)
  for (int k = first[2]; k <= last[2]; ++k) {
    if (omp_get_thread_num() == 0 && execution.interrupt_requested()) stop = true;
    if (stop || !mine(std::size_t(k))) continue;
    try {
      for (int j = first[1]; j <= last[1]; ++j)
        for (int i = first[0]; i <= last[0]; ++i) {
          const Point3 x{grid.x(i), grid.y(j), grid.z(k)};
          const double level = gamma.level(x);
          if (!(level > 0) || level > 2 * band_width * norm(gamma.level_gradient(x))) continue;
          const SurfaceFoot foot = nearest_point(gamma, x, x, tolerance);
          if (!(foot.d > 0 && foot.d <= band_width)) continue;
          const Grid3::Index node{i, j, k};
          band_by_z[std::size_t(k - first[2])].push_back({st.key(node), node, locate.patch(foot.foot), foot.psi()});
        }
    } catch (...) {
      keep();
    }
  }
  rethrow();
  for (auto& layer : band_by_z) st.band.insert(st.band.end(), layer.begin(), layer.end());
  st.band = distribution.concatenate(st.band);
  std::sort(st.band.begin(), st.band.end(), [](const BandNode& a, const BandNode& b) { return a.key < b.key; });
}

/// The element matrices of a voxel (exact by 2 Gauss points per axis).
void SurfaceKink::State::Build::element_matrices() {
  const GaussRule& two = gauss_legendre(2);
  for (int c3 = 0; c3 < 2; ++c3)
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) {
        const Q1Element<3> e({two.nodes[a], two.nodes[b], two.nodes[c3]}, h);
        const double w = two.weights[a] * two.weights[b] * two.weights[c3] * h * h * h;
        for (int l = 0; l < 8; ++l)
          for (int k = 0; k < 8; ++k) {
            K[l][k] += w * dot(e.gradient(l), e.gradient(k));
            M[l][k] += w * e.value[l] * e.value[k];
          }
      }
}

/// Step 2a. The cut voxels: those near γ with corners on both sides of γ or a part in ω neither empty nor whole.
std::vector<Grid3::Index> SurfaceKink::State::Build::cut_voxels() {
  std::vector<Grid3::Index> near_voxels;
  for (int k = first[2]; k < last[2]; ++k)
    for (int j = first[1]; j < last[1]; ++j)
      for (int i = first[0]; i < last[0]; ++i) {
        const Point3 center{grid.x(i) + h / 2, grid.y(j) + h / 2, grid.z(k) + h / 2};
        if (near_surface(gamma, center, 0.87 * h)) near_voxels.push_back({i, j, k});
      }
  std::vector<double> is_cut(near_voxels.size(), 0.0);  // 1: cut (distributed, each rank decides every P-th)
#pragma omp parallel for num_threads(execution.threads()) schedule(dynamic, 64)
  for (std::size_t n = 0; n < near_voxels.size(); ++n) {
    if (omp_get_thread_num() == 0 && n % 256 == 0 && execution.interrupt_requested()) stop = true;
    if (stop || !mine(n)) continue;
    // Cut: corners on both sides of γ, or a part in ω that the cut-voxel rule sees as neither empty
    // nor whole (γ through a face between the corners). The rule alone misses a corner just outside
    // γ: that voxel's ψ at the corner and its residual would be lost (docs/math.md, "Three dimensions":
    // the error then follows the grid's position against γ).
    try {
      const Grid3::Index& cell = near_voxels[n];
      bool inside = false, outside = false;
      for (int corner = 0; corner < 8; ++corner) {
        const double level = gamma.level({grid.x(cell[0] + (corner & 1)), grid.y(cell[1] + ((corner >> 1) & 1)),
                                          grid.z(cell[2] + ((corner >> 2) & 1))});
        (level > 0 ? outside : inside) = true;
      }
      if (inside && outside) {
        is_cut[n] = 1;
        continue;
      }
      double volume = 0;
      for_each_omega_point_in_voxel(grid, gamma, cell, cut_q, [&](const Point3&, double w) { volume += w; });
      is_cut[n] = volume > 1e-12 * h * h * h && volume < (1 - 1e-12) * h * h * h ? 1 : 0;
    } catch (...) {
      keep();
    }
  }
  rethrow();
  distribution.sum(is_cut);
  std::vector<Grid3::Index> voxels;
  for (std::size_t n = 0; n < near_voxels.size(); ++n)
    if (is_cut[n]) voxels.push_back(near_voxels[n]);
  return voxels;
}

/// Step 2b. Two rings of outside voxels around the cut ones. Σ_j λ_j ψ_j jumps by (λ_j − λ_k)·q(d) across the normal
/// planes through the patches' borders, so its residual a(ψ − I_hψ, φ) is not small in the voxels
/// beside the cut ones either (measured on the manufactured sphere, L²(ω) at N = 64: cut voxels only
/// 4.0e-3, one ring 1.3e-3, two 8.2e-4, three 8.3e-4).
void SurfaceKink::State::Build::add_rings(std::vector<Grid3::Index>& voxels) {
  constexpr int rings = 2;
  std::vector<std::size_t> have;
  for (const Grid3::Index& cell : voxels) have.push_back(st.key(cell));
  std::sort(have.begin(), have.end());
  const std::size_t n0 = std::size_t(grid.n(0) + 1), n1 = std::size_t(grid.n(1) + 1);
  std::size_t begin = 0;
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<std::size_t> next;
    const std::size_t end_of_layer = voxels.size();
    for (std::size_t v = begin; v < end_of_layer; ++v)
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const Grid3::Index cell{voxels[v][0] + dx, voxels[v][1] + dy, voxels[v][2] + dz};
            if (cell[0] >= 0 && cell[1] >= 0 && cell[2] >= 0 && cell[0] < grid.n(0) && cell[1] < grid.n(1) &&
                cell[2] < grid.n(2))
              next.push_back(st.key(cell));
          }
    std::sort(next.begin(), next.end());
    next.erase(std::unique(next.begin(), next.end()), next.end());
    std::vector<std::size_t> added;
    for (std::size_t key : next) {
      if (std::binary_search(have.begin(), have.end(), key)) continue;
      const Grid3::Index cell{int(key % n0), int(key / n0 % n1), int(key / (n0 * n1))};
      const Point3 center{grid.x(cell[0]) + h / 2, grid.y(cell[1]) + h / 2, grid.z(cell[2]) + h / 2};
      if (gamma.level(center) > 0) voxels.push_back(cell), added.push_back(key);  // wholly outside ω
    }
    have.insert(have.end(), added.begin(), added.end());
    std::sort(have.begin(), have.end());
    begin = end_of_layer;
  }
}

/// Step 2c. r_j,k = a(ψ_j − I_hψ_j, φ_k) on every cut voxel (the part outside ω is the whole voxel minus
/// its part in ω, ψ_j's smooth extension q(d) on both) and on the rings of outside voxels around them;
/// I_hψ_j takes the element matrix. Each quadrature point goes to the patch its nearest point of γ lies on.
std::vector<std::vector<RowEntry>> SurfaceKink::State::Build::residuals(const std::vector<Grid3::Index>& voxels) {
  std::vector<std::vector<RowEntry>> by_voxel(voxels.size());  // summed in voxel order: any thread count
#pragma omp parallel num_threads(execution.threads())
  {
    std::vector<int> near, local;
    std::vector<std::pair<int, std::array<double, 8>>> sums;  // per patch met in a voxel, for its eight nodes
    std::vector<std::pair<Point3, double>> inside;
#pragma omp for schedule(dynamic, 16)
    for (std::size_t n = 0; n < voxels.size(); ++n) try {
        if (omp_get_thread_num() == 0 && n % 64 == 0 && execution.interrupt_requested()) stop = true;
        if (stop || !mine(n)) continue;
        voxel_residual(voxels[n], near, local, sums, inside, by_voxel[n]);
      } catch (...) {
        keep();
      }
  }
  rethrow();
  if (!distribution.distributed()) return by_voxel;
  // Every rank's voxels (every P-th, from its rank on) back in voxel order: their entry counts and
  // entries in the order each rank made them.
  std::vector<std::uint64_t> counts;
  std::vector<RowEntry> made;
  for (std::size_t n = std::size_t(distribution.rank()); n < voxels.size(); n += std::size_t(distribution.size())) {
    counts.push_back(by_voxel[n].size());
    made.insert(made.end(), by_voxel[n].begin(), by_voxel[n].end());
  }
  counts = distribution.concatenate(counts);
  made = distribution.concatenate(made);
  std::size_t count = 0, entry = 0;
  for (int r = 0; r < distribution.size(); ++r)
    for (std::size_t n = std::size_t(r); n < voxels.size(); n += std::size_t(distribution.size()), ++count) {
      const auto from = made.begin() + std::ptrdiff_t(entry);
      by_voxel[n].assign(from, from + std::ptrdiff_t(counts[count]));
      entry += counts[count];
    }
  return by_voxel;
}

/// The entries of r in one voxel.
void SurfaceKink::State::Build::voxel_residual(const Grid3::Index& cell_index, std::vector<int>& near,
                                               std::vector<int>& local,
                                               std::vector<std::pair<int, std::array<double, 8>>>& sums,
                                               std::vector<std::pair<Point3, double>>& inside,
                                               std::vector<RowEntry>& out) {
  const Grid3::Index cell = cell_index;
  const Point3 lower{grid.x(cell[0]), grid.y(cell[1]), grid.z(cell[2])};
  const Point3 center = lower + Point3{h / 2, h / 2, h / 2};
  const SurfaceFoot centre = nearest_point(gamma, center, center, tolerance);
  const SurfaceStart from_centre = surface_start(gamma, centre.foot, tolerance);  // every point's start
  locate.near(centre.foot, near);
  // The triangles that can hold the feet within `spread` of the centre's (the margin covers the
  // triangles' distance from γ): each point's patch is sought among those alone.
  locate.within(centre.foot, spread + margin, near, local);
  bool one_patch = !local.empty();
  for (int t : local)
    one_patch = one_patch && patches.patch_of[std::size_t(t)] == patches.patch_of[std::size_t(local[0])];
  sums.clear();
  auto sums_of = [&](int patch) -> std::array<double, 8>& {
    for (auto& [p, v] : sums)
      if (p == patch) return v;
    return sums.emplace_back(patch, std::array<double, 8>{}).second;
  };
  auto add_point = [&](const Point3& x, double w) {
    const SurfaceFoot foot = nearest_point(gamma, x, from_centre, tolerance);
    const bool close = norm(foot.foot - centre.foot) <= spread && !local.empty();
    const std::vector<int>& pool = close ? local : near;
    const int patch = close && one_patch ? patches.patch_of[std::size_t(local[0])]
                      : pool.empty()     ? locate.patch(foot.foot)
                                         : locate.patch(foot.foot, pool);
    Point3 xi;
    for (int d = 0; d < 3; ++d) xi[d] = (x[d] - lower[d]) / h;
    const Q1Element<3> basis(xi, h);
    const double q = foot.q();
    const Point3 grad = foot.grad_q();
    std::array<double, 8>& v = sums_of(patch);
    for (int l = 0; l < 8; ++l) v[l] += w * (dot(grad, basis.gradient(l)) + c * q * basis.value[l]);
  };
  for (std::size_t c3 = 0; c3 < rule.nodes.size(); ++c3)
    for (std::size_t b = 0; b < rule.nodes.size(); ++b)
      for (std::size_t a = 0; a < rule.nodes.size(); ++a)
        add_point(lower + h * Point3{rule.nodes[a], rule.nodes[b], rule.nodes[c3]},
                  rule.weights[a] * rule.weights[b] * rule.weights[c3] * h * h * h);
  inside.clear();
  for_each_omega_point_in_voxel(grid, gamma, cell, cut_q,
                                [&](const Point3& x, double w) { inside.emplace_back(x, w); });
  for (const auto& [x, w] : inside) add_point(x, -w);
  for (int l = 0; l < 8; ++l) {
    const Grid3::Index node{cell[0] + Q1Element<3>::offset(l, 0), cell[1] + Q1Element<3>::offset(l, 1),
                            cell[2] + Q1Element<3>::offset(l, 2)};
    const BandNode* b = st.find(node);
    if (!b || b->patch < 0) continue;
    std::array<double, 8>& v = sums_of(b->patch);
    for (int k = 0; k < 8; ++k) v[k] -= b->psi * (K[l][k] + c * M[l][k]);
  }
  out.reserve(8 * sums.size());
  for (const auto& [patch, v] : sums)
    for (int k = 0; k < 8; ++k) {
      const Grid3::Index node{cell[0] + Q1Element<3>::offset(k, 0), cell[1] + Q1Element<3>::offset(k, 1),
                              cell[2] + Q1Element<3>::offset(k, 2)};
      if (patch >= 0) out.push_back({patch, node, v[k]});
    }
}

/// Step 3. The rows: entries merged per (patch, node) in voxel order, nodes without an unknown dropped.
void SurfaceKink::State::Build::rows(std::vector<std::vector<RowEntry>> by_voxel) {
  std::vector<RowEntry> entries;
  for (const auto& voxel : by_voxel) entries.insert(entries.end(), voxel.begin(), voxel.end());
  by_voxel = {};
  std::stable_sort(entries.begin(), entries.end(), [](const RowEntry& a, const RowEntry& b) {
    return std::tie(a.patch, a.node[2], a.node[1], a.node[0]) < std::tie(b.patch, b.node[2], b.node[1], b.node[0]);
  });
  SparseRows& rows = st.galerkin;
  std::size_t e = 0;
  for (int patch = 0; patch < st.m; ++patch) {
    while (e < entries.size() && entries[e].patch == patch) {
      const RowEntry first_entry = entries[e];
      double value = 0.0;
      for (; e < entries.size() && entries[e].patch == patch && entries[e].node == first_entry.node; ++e)
        value += entries[e].value;
      const Grid3::Index& node = first_entry.node;
      if (grid.has_unknown(node)) rows.entries.push_back({grid.index(node), node[0], node[1], node[2], value});
    }
    rows.row_begin.push_back(rows.entries.size());
  }
}

SurfaceKink::SurfaceKink(const Grid3& grid, const Surface& gamma, const PatchedSurface& patches, double c,
                         const Execution& execution)
    : state_(std::make_unique<State>(grid)) {
  state_->m = patches.m;
  State::Build build(*state_, grid, gamma, patches, c, execution);
  build.bounds();
  build.band();  // 1.
  build.element_matrices();
  std::vector<Grid3::Index> voxels = build.cut_voxels();  // 2.
  state_->cut_voxels = voxels.size();
  build.add_rings(voxels);
  build.rows(build.residuals(voxels));  // 3.
}

Eigen::SparseMatrix<double> SurfaceKink::direct(const SparseRows& rows) const {
  const State& st = *state_;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int r = 0; r < rows.n_rows(); ++r)
    for (std::size_t k = rows.row_begin[r]; k < rows.row_begin[r + 1]; ++k) {
      const auto& entry = rows.entries[k];
      const BandNode* b = st.find({entry.i, entry.j, entry.k});
      if (b && b->patch >= 0 && b->psi != 0.0) triplets.emplace_back(r, b->patch, entry.value * b->psi);
    }
  Eigen::SparseMatrix<double> D(rows.n_rows(), st.m);
  D.setFromTriplets(triplets.begin(), triplets.end());
  return D;
}

void SurfaceKink::add_kinks(const std::vector<double>& lambda, GridVector& u, std::optional<Slab> slab) const {
  const State& st = *state_;
  const Slab s = slab.value_or(st.grid.every_layer());
  const std::size_t offset = st.grid.slab_offset(s);
  for (const BandNode& b : st.band)
    if (b.patch >= 0 && st.grid.has_unknown(b.node) && s.holds(st.grid.layer(b.node[2])))
      u[st.grid.index(b.node) - offset] += lambda[std::size_t(b.patch)] * b.psi;
}

std::vector<double> SurfaceKink::band_sums(const GridVector& weights, std::optional<Slab> slab) const {
  const State& st = *state_;
  const Slab s = slab.value_or(st.grid.every_layer());
  const std::size_t offset = st.grid.slab_offset(s);
  std::vector<double> sums(std::size_t(st.m), 0.0);
  for (const BandNode& b : st.band)
    if (b.patch >= 0 && st.grid.has_unknown(b.node) && s.holds(st.grid.layer(b.node[2])))
      sums[std::size_t(b.patch)] += b.psi * weights[st.grid.index(b.node) - offset];
  return sums;
}

namespace {

/// The patches' neighbours: W_ij = Σ_k (B_Γ)_ik (B_Γ)_jk over the nodes their rows share (symmetric).
Eigen::SparseMatrix<double> row_overlaps(const SparseRows& rows) {
  struct NodeValue {
    std::size_t node;
    int row;
    double value;
  };
  std::vector<NodeValue> by_node;
  by_node.reserve(rows.entries.size());
  for (int r = 0; r < rows.n_rows(); ++r)
    for (std::size_t e = rows.row_begin[std::size_t(r)]; e < rows.row_begin[std::size_t(r) + 1]; ++e)
      by_node.push_back({rows.entries[e].index, r, rows.entries[e].value});
  std::sort(by_node.begin(), by_node.end(),
            [](const NodeValue& a, const NodeValue& b) { return std::tie(a.node, a.row) < std::tie(b.node, b.row); });
  std::vector<Eigen::Triplet<double>> overlap;
  for (std::size_t first = 0; first < by_node.size();) {
    std::size_t last = first;
    while (last < by_node.size() && by_node[last].node == by_node[first].node) ++last;
    for (std::size_t p = first; p < last; ++p)
      for (std::size_t q = p + 1; q < last; ++q)
        if (by_node[p].row != by_node[q].row) {
          const double w = by_node[p].value * by_node[q].value;
          if (!(w > 0)) continue;  // a touch at one corner with no weight is no neighbour
          overlap.emplace_back(by_node[p].row, by_node[q].row, w);
          overlap.emplace_back(by_node[q].row, by_node[p].row, w);
        }
    first = last;
  }
  Eigen::SparseMatrix<double> W(rows.n_rows(), rows.n_rows());
  W.setFromTriplets(overlap.begin(), overlap.end());
  return W;
}

/// The connected parts of the graph W: a label per vertex, and the number of parts.
std::pair<std::vector<int>, int> connected_parts(const Eigen::SparseMatrix<double>& W) {
  const int n = int(W.rows());
  std::vector<int> part(std::size_t(n), -1);
  int parts = 0;
  for (int start = 0; start < n; ++start) {
    if (part[std::size_t(start)] >= 0) continue;
    std::vector<int> stack{start};
    part[std::size_t(start)] = parts;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      for (Eigen::SparseMatrix<double>::InnerIterator it(W, i); it; ++it)
        if (part[std::size_t(it.row())] < 0) part[std::size_t(it.row())] = parts, stack.push_back(int(it.row()));
    }
    ++parts;
  }
  return {part, parts};
}

}  // namespace

namespace {

/// β_j: how far the readings' area-weighted column sums Σ_i a_i S_ij miss c∫_ω of the field of a unit
/// layer on patch j (one fast solve).
Eigen::VectorXd missed_fluxes(const SurfaceKink& kink, const SparseRows& C_gamma, const SparseRows& loads,
                              const Eigen::SparseMatrix<double>& D_C, const GridVector& load_of_omega,
                              const FastSolver<3>& fast, const Distribution& distribution, const Eigen::VectorXd& a,
                              int& fast_solves) {
  const int m = int(a.size());
  // Σ_i a_i S_ij = (B_Γ + R)_j·A⁻¹C_γᵀa + (D_Cᵀa)_j (an adjoint solve), less c∫_ω of the field of a
  // unit layer on patch j, I_h w_j = A⁻¹(B_Γ + R)ᵀe_j + I_hψ_j: c((B_Γ + R)_j·A⁻¹ℓ + Σ_k ψ_j(x_k)ℓ_k)
  // with ℓ_k = ∫_ω φ_k. A is symmetric: both solves are one, A⁻¹(C_γᵀa − cℓ).
  // Distributed: y and ℓ are this rank's layers, the readings and band sums added over the ranks.
  GridVector y = fast.make_vector();
  add_rows(C_gamma, fast.grid(), std::vector<double>(a.begin(), a.end()), y, distribution);
  std::vector<double> band(std::size_t(m), 0.0);
  if (fast.c() != 0.0) {
    band = kink.band_sums(load_of_omega, fast.slab());
    distribution.sum(band);
    for (std::size_t k = 0; k < y.size(); ++k) y[k] -= fast.c() * load_of_omega[k];
  }
  fast.solve_in_place(y);
  ++fast_solves;
  std::vector<double> share;
  read_rows(loads, fast.grid(), y, distribution, share);
  const Eigen::VectorXd from_direct = D_C.transpose() * a;
  Eigen::VectorXd beta(m);
  for (int j = 0; j < m; ++j) beta[j] = share[std::size_t(j)] + from_direct[j] - fast.c() * band[std::size_t(j)];
  return beta;
}

/// X from β and the patch areas a (docs/math.md, "The flux balance of the patches").
Eigen::SparseMatrix<double> balance_correction(const SparseRows& B_Gamma, const Eigen::VectorXd& beta,
                                               const Eigen::VectorXd& a) {
  const int m = int(a.size());
  // On each connected part of γ: μ = Σβ/Σa, and Lφ = (β − μa)/2 with φ = 0 at the part's first patch
  // (L is singular there; its right-hand side sums to zero over the part, so the pinned row holds too).
  const Eigen::SparseMatrix<double> W = row_overlaps(B_Gamma);
  const auto [part, parts] = connected_parts(W);
  std::vector<double> beta_sum(std::size_t(parts), 0.0), area_sum(std::size_t(parts), 0.0);
  std::vector<int> pinned(std::size_t(parts), -1);
  for (int j = 0; j < m; ++j) {
    const std::size_t p = std::size_t(part[std::size_t(j)]);
    beta_sum[p] += beta[j], area_sum[p] += a[j];
    if (pinned[p] < 0) pinned[p] = j;
  }
  std::vector<double> mu(std::size_t(parts), 0.0);
  for (int p = 0; p < parts; ++p) mu[std::size_t(p)] = beta_sum[std::size_t(p)] / area_sum[std::size_t(p)];
  const auto is_pinned = [&](int j) { return pinned[std::size_t(part[std::size_t(j)])] == j; };
  std::vector<Eigen::Triplet<double>> laplacian;
  Eigen::VectorXd rhs(m);
  for (int j = 0; j < m; ++j) {
    if (is_pinned(j)) {
      laplacian.emplace_back(j, j, 1.0);
      rhs[j] = 0;
      continue;
    }
    rhs[j] = 0.5 * (beta[j] - mu[std::size_t(part[std::size_t(j)])] * a[j]);
    double degree = 0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(W, j); it; ++it) {
      degree += it.value();
      if (!is_pinned(int(it.row()))) laplacian.emplace_back(j, int(it.row()), -it.value());
    }
    laplacian.emplace_back(j, j, degree);
  }
  Eigen::SparseMatrix<double> L(m, m);
  L.setFromTriplets(laplacian.begin(), laplacian.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor(L);
  if (factor.info() != Eigen::Success)
    throw std::runtime_error("flux balance: the patches' graph Laplacian could not be factorized");
  const Eigen::VectorXd phi = factor.solve(rhs);

  // X_ik = W_ik(φ_i − φ_k)/a_i beside each neighbour, X_ii = −Σ_k X_ik − μ.
  std::vector<Eigen::Triplet<double>> x;
  for (int i = 0; i < m; ++i) {
    double diagonal = -mu[std::size_t(part[std::size_t(i)])];
    for (Eigen::SparseMatrix<double>::InnerIterator it(W, i); it; ++it) {
      const double off_diagonal = it.value() * (phi[i] - phi[it.row()]) / a[i];
      x.emplace_back(i, int(it.row()), off_diagonal);
      diagonal -= off_diagonal;
    }
    x.emplace_back(i, i, diagonal);
  }
  Eigen::SparseMatrix<double> correction(m, m);
  correction.setFromTriplets(x.begin(), x.end());
  return correction;
}

}  // namespace

FluxBalance flux_balance(const SurfaceKink& kink, const SparseRows& B_Gamma, const SparseRows& C_gamma,
                         const SparseRows& loads, const Eigen::SparseMatrix<double>& D_C,
                         const GridVector& load_of_omega, const FastSolver<3>& fast, const Distribution& distribution) {
  const int m = B_Gamma.n_rows();
  if (fast.singular()) throw std::invalid_argument("flux_balance: A is singular (a periodic box with c = 0)");
  if (C_gamma.n_rows() != m || loads.n_rows() != m || D_C.rows() != m || D_C.cols() != m ||
      (fast.c() != 0.0 && load_of_omega.size() != fast.local_size()))
    throw std::invalid_argument("flux_balance: the rows, D_C and the load of ω do not match");
  FluxBalance result;
  const std::vector<double> areas = B_Gamma.row_sums();  // ∫_{P_j} 1 dS (no wall node lies near γ)
  result.area = Eigen::Map<const Eigen::VectorXd>(areas.data(), Eigen::Index(areas.size()));
  const Eigen::VectorXd& a = result.area;

  const Eigen::VectorXd beta =
      missed_fluxes(kink, C_gamma, loads, D_C, load_of_omega, fast, distribution, a, result.fast_solves);
  {
    double mean = 0, square = 0;
    for (int j = 0; j < m; ++j) mean += beta[j] / a[j] / m;
    for (int j = 0; j < m; ++j) square += std::pow(beta[j] / a[j] - mean, 2) / m;
    result.scatter = std::sqrt(square);
    result.mean = beta.sum() / a.sum();
  }

  result.correction = balance_correction(B_Gamma, beta, a);
  return result;
}

}  // namespace fictus
