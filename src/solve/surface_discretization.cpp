#include "fictus/solve/surface_discretization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "fictus/boundary/omega_quadrature.hpp"
#include "fictus/boundary/surface_kink.hpp"
#include "fictus/grid/distribution.hpp"
#include "solve_steps.hpp"

namespace fictus {

int default_patches(double area, double h, Variant variant) {
  const double s = (variant == Variant::smooth ? default_patch_cells_smooth_3d : default_patch_cells_nonsmooth_3d) * h;
  return std::max(minimum_multipliers, int(std::lround(area / (s * s))));
}

namespace {

using detail::row_sums;
using detail::to_eigen;

std::string format(const char* pattern, double a, double b = 0, double c = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, pattern, a, b, c);
  return buffer;
}

/// γ (or Γ) with its bounds grown by `grow` must keep 2h from the box's sides.
void check_inside_box(const Surface& gamma, const Grid3& grid, double grow, const std::string& field) {
  const Box3 bounds = gamma.bounds();
  const double margin = 2 * grid.h();
  for (int d = 0; d < 3; ++d) {
    const double room =
        std::min(bounds.lower[d] - grow - grid.box().lower[d], grid.box().upper[d] - bounds.upper[d] - grow);
    if (room >= margin) continue;
    std::string text = field + ": " + (grow > 0 ? "the offset surface" : "the surface") +
                       format(" comes within %.3g of the box along axis %.0f; the grid needs 2h = %.3g there", room,
                              double(d), margin);
    if (room > 0 && grow == 0)
      text += format(": N >= %.0f (or a larger box)", std::ceil(2 * grid.box().width(0) / room - 1e-9));
    throw std::invalid_argument(text);
  }
}

/// The triangles of `surface` moved by δ along the surface's unit normal at each vertex.
std::vector<Triangle3> offset_triangles(const std::vector<Triangle3>& triangles, const Surface& gamma, double delta) {
  const auto move = [&](const Point3& p) {
    const Point3 n = gamma.level_gradient(p);
    return p + (delta / norm(n)) * n;
  };
  std::vector<Triangle3> out;
  out.reserve(triangles.size());
  for (const Triangle3& t : triangles) out.push_back({move(t.a), move(t.b), move(t.c)});
  return out;
}

/// Whether x, projected onto the plane of t, falls inside t (edges included) and lies no farther from that
/// plane than t's longest edge.
bool lies_over(const Triangle3& t, const Point3& x) {
  const Point3 u = t.b - t.a, v = t.c - t.a, q = x - t.a, n = cross(u, v);
  const double nn = dot(n, n);
  if (!(nn > 1e-24 * dot(u, u) * dot(v, v))) return false;  // degenerate, or not finite
  const double along_u = dot(cross(q, v), n) / nn, along_v = dot(cross(u, q), n) / nn;
  constexpr double slack = 1e-12;
  if (!(along_u >= -slack && along_v >= -slack && along_u + along_v <= 1 + slack)) return false;
  const double longest = std::max({dot(u, u), dot(v, v), dot(t.c - t.b, t.c - t.b)});
  return dot(q, n) * dot(q, n) <= longest * nn;
}

}  // namespace

/// The kink correction, and the flux balance once finish_setup has made it.
struct SurfaceDiscretization::Kink {
  SurfaceKink model;
  Eigen::SparseMatrix<double> balance;  // X (empty without the flux balance)
  Eigen::VectorXd area;                 // the patch areas of the flux balance
  double scatter = 0, mean = 0;
  bool balanced = false;
};

SurfaceDiscretization::SurfaceDiscretization(std::shared_ptr<const Surface> gamma, const Grid3& grid,
                                             const SolverOptions& options, double c, const Execution& execution,
                                             const MarkPhase& mark, const PartConditions<3>& parts)
    : grid_(grid), gamma_(std::move(gamma)), execution_(execution), c_(c), balance_wanted_(options.flux_balance) {
  if (!gamma_) throw std::invalid_argument("geometry: no surface given");
  make_shape(options);
  place_points(options, parts, true);
  make_trace_rows(options, mark);
}

SurfaceDiscretization::SurfaceDiscretization(const SurfaceDiscretization& base, const SolverOptions& options,
                                             const MarkPhase& mark, const PartConditions<3>& parts)
    : grid_(base.grid_),
      gamma_(base.gamma_),
      execution_(base.execution_),
      c_(base.c_),
      balance_wanted_(base.balance_wanted_),
      plan_(base.plan_),
      delta_(base.delta_),
      unsplit_(base.unsplit_),
      gamma_patches_(base.unsplit_ ? *base.unsplit_
                     : base.split_ ? base.gamma_->patches(plan_.m, grid_.h())  // (a fitted copy as the base)
                                   : base.gamma_patches_) {
  place_points(options, parts, false);
  make_trace_rows(options, mark);
}

std::unique_ptr<BoundaryDiscretization<3>> SurfaceDiscretization::placed_for(const PartConditions<3>& parts,
                                                                             const SolverOptions& options, double,
                                                                             const MarkPhase& mark) const {
  return std::unique_ptr<BoundaryDiscretization<3>>(new SurfaceDiscretization(*this, options, mark, parts));
}

SurfaceDiscretization::~SurfaceDiscretization() = default;

std::vector<int> SurfaceDiscretization::part_layout(const PartConditions<3>& parts) const {
  if (!parts.placed()) return {};
  std::vector<int> layout;
  layout.reserve(gamma_patches_.triangles.size());
  for (const Triangle3& t : gamma_patches_.triangles) layout.push_back(parts.label((1.0 / 3) * (t.a + t.b + t.c)));
  return layout;
}

void SurfaceDiscretization::make_shape(const SolverOptions& options) {
  const Surface& gamma = *gamma_;
  const double h = grid_.h();
  check_inside_box(gamma, grid_, 0, "geometry");  // before any work
  const double area = gamma.area();
  const Box3 bounds = gamma.bounds(), box = grid_.box();
  const OffsetRoom room = [&gamma, bounds, box](double k) {  // Γ keeps 2h from the box and does not fold
    double room = gamma.reach() - 2 * k;
    for (int d = 0; d < 3; ++d)
      room = std::min({room, bounds.lower[d] - box.lower[d] - 2 * k, box.upper[d] - bounds.upper[d] - 2 * k});
    return room;
  };
  const Variant variant = options.variant;
  plan_ = plan_spacing(
      {3, area, h, box.width(0), [area, variant](double k) { return default_patches(area, k, variant); }, room},
      options);
  execution_.throw_if_interrupted();
  gamma_patches_ = gamma.patches(plan_.m, h);
  execution_.throw_if_interrupted();
  if (options.variant == Variant::smooth) {
    delta_ = plan_.delta;
    check_inside_box(gamma, grid_, delta_, "formulation.offset");
  }
}

void SurfaceDiscretization::place_points(const SolverOptions& options, const PartConditions<3>& parts,
                                         bool keep_unsplit) {
  const Surface& gamma = *gamma_;
  part_layout_ = part_layout(parts);
  if (!part_layout_.empty() &&
      std::any_of(part_layout_.begin(), part_layout_.end(), [&](int c) { return c != part_layout_[0]; })) {
    split_ = true;
    if (keep_unsplit && !unsplit_) unsplit_ = std::make_shared<const PatchedSurface>(gamma_patches_);
    // The patches again, each in one part. A patch's point: the foot on γ of its centroid where the
    // centroid lies over one of the patch's own triangles and the foot is in the patch's part; else (e.g.
    // a patch bent round a junction) the foot of the centroid of its triangle nearest to its centroid,
    // which stays inside the patch. (Every point at such a triangle's centroid, up to half an edge from
    // the patch's centroid, cost the patch-area rule Σ a_i g(x_i) of the flux balance its second order.)
    std::vector<int> patch_labels;
    const std::vector<Point3> seeds = split_into_patches(gamma_patches_, plan_.m, part_layout_, &patch_labels);
    const std::vector<Triangle3>& triangles = gamma_patches_.triangles;
    std::vector<Point3> nearest(std::size_t(plan_.m));
    std::vector<double> best(std::size_t(plan_.m), 1e300);
    std::vector<char> over_own(std::size_t(plan_.m), 0);
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const std::size_t p = std::size_t(gamma_patches_.patch_of[t]);
      const Point3 centroid = (1.0 / 3) * (triangles[t].a + triangles[t].b + triangles[t].c);
      if (const double d = norm(centroid - seeds[p]); d < best[p]) best[p] = d, nearest[p] = centroid;
      if (!over_own[p] && lies_over(triangles[t], seeds[p])) over_own[p] = 1;
    }
    const Box3 bounds = gamma.bounds();
    const double tolerance = 1e-13 * std::max({bounds.width(0), bounds.width(1), bounds.width(2)});
    for (std::size_t p = 0; p < nearest.size(); ++p) {
      SurfaceFoot foot;
      if (over_own[p]) foot = nearest_point(gamma, seeds[p], seeds[p], tolerance);
      if (!over_own[p] || parts.label(foot.foot) != patch_labels[p])
        foot = nearest_point(gamma, nearest[p], nearest[p], tolerance);
      gamma_patches_.point[p] = foot.foot;
      gamma_patches_.normal[p] = foot.normal;
    }
    point_parts_.assign(patch_labels.size(), PointCondition::signorini);
    for (std::size_t p = 0; p < patch_labels.size(); ++p)
      point_parts_[p] = PartConditions<3>::condition_of(patch_labels[p]);
    execution_.throw_if_interrupted();
  } else if (!part_layout_.empty()) {
    point_parts_.assign(std::size_t(plan_.m), PartConditions<3>::condition_of(part_layout_[0]));
  }
  Gamma_patches_ = gamma_patches_;
  if (options.variant == Variant::smooth) {
    Gamma_patches_.triangles = offset_triangles(gamma_patches_.triangles, gamma, delta_);
    for (int p = 0; p < plan_.m; ++p)
      Gamma_patches_.point[p] = gamma_patches_.point[p] + delta_ * gamma_patches_.normal[p];
  }
  Gamma_patches_.area.assign(plan_.m, 0.0);
  for (std::size_t t = 0; t < Gamma_patches_.triangles.size(); ++t)
    Gamma_patches_.area[Gamma_patches_.patch_of[t]] += fictus::area(Gamma_patches_.triangles[t]);
}

void SurfaceDiscretization::make_trace_rows(const SolverOptions& options, const MarkPhase& mark) {
  const double h = grid_.h();
  const int m = plan_.m;
  const PatchedSurface& patches = gamma_patches_;
  B_gamma_ = point_value_rows(grid_, patches.point);
  const bool reconstructed = options.normal_derivative == NormalDerivative::reconstructed;
  C_gamma_ = reconstructed ? normal_derivative_rows_centered(grid_, patches.point, patches.normal)
                           : normal_derivative_rows(grid_, patches.point, patches.normal, options.normal_shift * h);
  // Non-smooth: λ lives on γ itself, where the kink of û must sit to O(h³) for C_γ (which reaches across
  // γ): the triangles' points are mapped onto γ (their O(h²) sag would be a double layer, an O(h) error).
  execution_.throw_if_interrupted();
  B_Gamma_ = patch_integral_rows(
      grid_,
      patch_integrals(grid_, Gamma_patches_.triangles, Gamma_patches_.patch_of, m,
                      options.variant == Variant::nonsmooth ? onto_surface(*gamma_, 1e-13 * h) : SurfaceMap{},
                      execution_.threads(), execution_.distribution()),
      m);
  mark("geometry");
  execution_.throw_if_interrupted();
  loads_ = B_Gamma_;
  if (options.variant != Variant::nonsmooth || !reconstructed) return;
  if (!(gamma_->reach() > 6 * h))  // the kink band reaches 6h outside γ: its nearest points must be unique
    throw std::invalid_argument(
        format("formulation.variant: the surface folds within %.3g of itself outside, "
               "inside the non-smooth variant's band of 6h = %.3g: a larger N",
               gamma_->reach(), 6 * h));
  kink_ = std::make_unique<Kink>(Kink{SurfaceKink(grid_, *gamma_, patches, c_, execution_), {}, {}, 0, 0, false});
  direct_.trace = kink_->model.direct(B_gamma_);
  direct_.normal_derivative = kink_->model.direct(C_gamma_);
  loads_ = add_rows(B_Gamma_, kink_->model.galerkin());
  mark("kink_correction");
  execution_.throw_if_interrupted();
}

FarField SurfaceDiscretization::far_field(const SolverOptions& options) const {
  if (!options.far_field) return {};
  return options.variant == Variant::nonsmooth ? default_far_field_3d_nonsmooth : default_far_field_3d;
}

std::size_t SurfaceDiscretization::finish_setup(const FastSolver<3>& fast, const MarkPhase& mark) {
  // The flux balance (flux_balance in surface_kink.hpp): X joins D_C.
  if (!kink_ || !balance_wanted_ || fast.singular()) return 0;
  constexpr int load_points = 3;  // per Gauss line of the cut-voxel rule, as the error integrals'
  const Distribution& distribution = execution_.distribution();
  load_of_omega_ =
      c_ != 0.0 ? omega_load(grid_, *gamma_, load_points, execution_, distribution.slab(grid_)) : GridVector();
  FluxBalance b = fictus::flux_balance(kink_->model, B_Gamma_, C_gamma_, loads_, direct_.normal_derivative,
                                       load_of_omega_, fast, distribution);
  direct_.normal_derivative += b.correction;
  kink_->balance = std::move(b.correction);
  kink_->area = std::move(b.area);
  kink_->scatter = b.scatter;
  kink_->mean = b.mean;
  kink_->balanced = true;
  mark("flux_balance");
  execution_.throw_if_interrupted();
  return std::size_t(b.fast_solves);
}

double SurfaceDiscretization::reading_shift(const GridVector& u0, const VectorizedField3& f,
                                            int load_quadrature) const {
  if (!kink_ || !kink_->balanced) return 0;
  constexpr int load_points = 3;  // as finish_setup's ℓ
  double u0_integral = 0;         // ∫_ω u₀ (distributed: over this rank's layers, then added)
  const Distribution& distribution = execution_.distribution();
  if (c_ != 0.0) {
    const GridVector load_of_omega = load_of_omega_.empty()
                                         ? omega_load(grid_, *gamma_, load_points, execution_, distribution.slab(grid_))
                                         : std::move(load_of_omega_);
    load_of_omega_ = GridVector();
    for (std::size_t k = 0; k < load_of_omega.size(); ++k) u0_integral += load_of_omega[k] * u0[k];
    u0_integral = distribution.sum(u0_integral);
  }
  std::vector<double> c_u0;
  read_rows(C_gamma_, grid_, u0, distribution, c_u0);
  const double readings = kink_->area.dot(to_eigen(c_u0)), area_total = kink_->area.sum();
  const double f_integral = omega_integral(grid_, *gamma_, f, load_quadrature, execution_);
  if (!std::isfinite(f_integral)) throw std::invalid_argument("data.f: not finite somewhere in ω");
  return (c_ * u0_integral - f_integral - readings) / area_total;
}

std::optional<FluxBalanceUse> SurfaceDiscretization::flux_balance(double data_shift) const {
  if (!kink_ || !kink_->balanced) return std::nullopt;
  return FluxBalanceUse{kink_->scatter, kink_->mean, data_shift};
}

std::vector<double> SurfaceDiscretization::obstacle(const Data& data) const {
  const int m = n_points();
  std::vector<double> g(m);
  const std::array<std::vector<double>, 3> x = coordinates(points());
  (data.g_vectorized ? data.g_vectorized : vectorize(data.g))(std::size_t(m), x[0].data(), x[1].data(), x[2].data(),
                                                              g.data());
  detail::check_obstacle(g, points());
  return g;
}

void SurfaceDiscretization::finish_field(const std::vector<double>& lambda, GridVector& u) const {
  if (kink_) kink_->model.add_kinks(lambda, u, execution_.distribution().slab(grid_));  // the kink-corrected I_h w
}

void SurfaceDiscretization::finish_readings(const std::vector<double>& lambda,
                                            std::vector<double>& normal_derivative) const {
  if (!kink_ || !kink_->balanced) return;  // the readings of the Newton system: C_γ I_h w + Xλ
  const int m = n_points();
  Eigen::Map<Eigen::VectorXd>(normal_derivative.data(), m) +=
      kink_->balance * Eigen::Map<const Eigen::VectorXd>(lambda.data(), m);
}

std::optional<std::vector<double>> SurfaceDiscretization::independent_normal_derivative(const GridVector& u,
                                                                                        std::string& rule) const {
  // Both variants: only nodes of ω enter, so the kink of the non-smooth field on γ does not.
  rule = check_fit_rule;
  std::optional<SparseRows> rows;
  try {  // the same on every rank: the rows are made from γ alone
    rows.emplace(one_sided_rows(grid_, *gamma_, points(), normals(), OneSidedTrace::normal_derivative, check_fit_degree,
                                check_fit_radius));
  } catch (const std::runtime_error&) {  // ω too thin for the fit: no check, not a failed solve
    return std::nullopt;
  }
  std::vector<double> d;
  read_rows(*rows, grid_, u, execution_.distribution(), d);
  return d;
}

void SurfaceDiscretization::for_each_omega_sample(const GridVector& u, int quadrature,
                                                  const OmegaSampleVisitor<3>& visit) const {
  fictus::for_each_omega_sample(u, grid_, *gamma_, quadrature, execution_, visit);
}

ErrorNorms SurfaceDiscretization::errors(const GridVector& u, const std::vector<double>& trace, const Data& data,
                                         int quadrature) const {
  const VectorizedField3 exact = data.exact_vectorized ? data.exact_vectorized : vectorize(data.exact);
  return compute_errors(u, grid_, *gamma_, gamma_patches_, trace, exact, data.exact_gradient, quadrature, execution_);
}

PointErrors SurfaceDiscretization::point_errors(const std::vector<double>& trace,
                                                const std::vector<double>& normal_derivative, const Data& data) const {
  const VectorizedField3 exact = data.exact_vectorized ? data.exact_vectorized : vectorize(data.exact);
  const std::array<std::vector<double>, 3> x = coordinates(points());
  std::array<std::vector<double>, 3> du;
  std::vector<double> u(points().size());
  exact(u.size(), x[0].data(), x[1].data(), x[2].data(), u.data());
  gradient_at(exact, data.exact_gradient, 1e-6 * grid_.box().width(0), x, du);
  std::vector<double> dudn(u.size());
  for (std::size_t p = 0; p < u.size(); ++p) {
    const Point3 n = normals()[p];
    dudn[p] = n.x * du[0][p] + n.y * du[1][p] + n.z * du[2][p];
  }
  return detail::point_errors_at(points(), trace, normal_derivative, u, dudn);
}

void SurfaceDiscretization::describe(SolutionBoundary<3>& out) const {
  out.gamma = gamma_patches_;
  out.Gamma = Gamma_patches_;
}

}  // namespace fictus
