#include "fictus/solve/curve_discretization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>

#include "fictus/boundary/shapes.hpp"
#include "fictus/grid/distribution.hpp"
#include "solve_steps.hpp"

namespace fictus {

CurveDiscretization::CurveDiscretization(std::shared_ptr<const Curve> gamma, const Grid2& grid,
                                         const SolverOptions& options, double c, const Execution& execution,
                                         const PartConditions<2>& parts)
    : execution_(execution), gamma_(std::move(gamma)) {
  if (!gamma_) throw std::invalid_argument("geometry: no curve given");
  SolverOptions resolved = options;
  resolved.variant = resolved_variant(options.variant, gamma_->smooth());
  make_shape(grid, resolved);
  place_points(resolved, parts, nullptr);
  make_trace_rows(grid, resolved, c, nullptr);
}

CurveDiscretization::CurveDiscretization(const CurveDiscretization& base, const SolverOptions& options, double c,
                                         const PartConditions<2>& parts)
    : execution_(base.execution_),
      gamma_(base.gamma_),
      Gamma_(base.Gamma_),
      delta_(base.delta_),
      spacing_(base.spacing_),
      samples_(parts.placed() ? base.layout_samples() : base.samples_),
      arc_length_(base.arc_length_),
      placement_(base.placement_),
      gamma_geometry_(base.gamma_geometry_),
      Gamma_geometry_(base.Gamma_geometry_) {
  SolverOptions resolved = options;
  resolved.variant = resolved_variant(options.variant, gamma_->smooth());
  if ((resolved.variant == Variant::smooth) != bool(placement_))
    throw std::logic_error("CurveDiscretization::placed_for: the variant differs from the shape's");
  place_points(resolved, parts, &base.collocation_);
  make_trace_rows(gamma_geometry_->grid(), resolved, c, &base);
}

std::unique_ptr<BoundaryDiscretization<2>> CurveDiscretization::placed_for(const PartConditions<2>& parts,
                                                                           const SolverOptions& options, double c,
                                                                           const MarkPhase&) const {
  return std::unique_ptr<BoundaryDiscretization<2>>(new CurveDiscretization(*this, options, c, parts));
}

namespace {

/// The room of Γ = γ + δn (spacing_rule.hpp) at grid spacing h: on every side of the box, from
/// the samples of γ whose normal points towards it, δ <= (distance − 2h)/(n toward the side); and
/// the δ beyond which Γ stops being simple, found once by bisection when Γ at the box's limit folds.
OffsetRoom curve_offset_room(std::shared_ptr<const Curve> gamma, const Box2& box) {
  struct Sample {
    double distance, toward;  // to one side of the box, and n's component toward it
  };
  auto samples = std::make_shared<std::vector<Sample>>();
  constexpr int count = 4096;  // as check_inside_box and check_simple
  std::vector<double> t = gamma->corners();
  for (int k = 0; k < count; ++k) t.push_back(2 * std::numbers::pi * k / count);
  for (double s : t) {
    const Point2 p = gamma->position(s), n = gamma->outward_normal(s);
    const Sample sides[4] = {
        {p.x - box.lower.x, -n.x}, {box.upper.x - p.x, n.x}, {p.y - box.lower.y, -n.y}, {box.upper.y - p.y, n.y}};
    for (const Sample& side : sides)
      if (side.toward > 0) samples->push_back(side);
  }
  const auto box_room = [samples](double h) {
    double room = std::numeric_limits<double>::infinity();
    for (const Sample& s : *samples) room = std::min(room, (s.distance - 2 * h) / s.toward);
    return room;
  };
  auto fold = std::make_shared<std::optional<double>>();  // the δ where Γ stops being simple (+∞: never)
  return [gamma, box_room, fold](double h) {
    const double room = box_room(h);
    if (!fold->has_value()) {
      const auto simple = [&gamma](double delta) {
        try {
          check_simple(OffsetCurve(gamma, delta), "formulation.offset");
          return true;
        } catch (const std::invalid_argument&) {
          return false;
        }
      };
      const double widest = box_room(0);
      if (!(widest > 0) || simple(widest)) {
        *fold = std::numeric_limits<double>::infinity();
      } else {
        double low = 0, high = widest;
        for (int k = 0; k < 40 && high - low > 1e-9 * widest; ++k)
          ((simple((low + high) / 2)) ? low : high) = (low + high) / 2;
        *fold = low;
      }
    }
    return std::min(room, **fold);
  };
}

}  // namespace

std::vector<int> CurveDiscretization::part_layout(const PartConditions<2>& parts) const {
  if (!parts.placed()) return {};
  const std::vector<Point2>& samples = *layout_samples();
  std::vector<int> layout(samples.size());
  for (std::size_t k = 0; k < layout.size(); ++k) layout[k] = parts.label(samples[k]);
  return layout;
}

const std::shared_ptr<const std::vector<Point2>>& CurveDiscretization::layout_samples() const {
  if (!samples_) {
    const int samples = std::max(4096, 16 * spacing_.m);
    auto at = std::make_shared<std::vector<Point2>>(std::size_t(samples));
    for (int k = 0; k < samples; ++k)
      (*at)[std::size_t(k)] = gamma_->position(2 * std::numbers::pi * (k + 0.5) / samples);
    samples_ = std::move(at);
  }
  return samples_;
}

bool CurveDiscretization::same_parts(const PartConditions<2>& parts) const {
  const std::vector<int> layout = part_layout(parts);
  if (layout != part_layout_) return false;
  const std::vector<std::pair<double, int>> now = junctions(parts, layout);
  if (now.size() != junctions_.size()) return false;
  for (std::size_t k = 0; k < now.size(); ++k)
    if (now[k].second != junctions_[k].second || std::abs(now[k].first - junctions_[k].first) > 1e-12) return false;
  return true;
}

std::vector<std::pair<double, int>> CurveDiscretization::junctions(const PartConditions<2>& parts,
                                                                   const std::vector<int>& layout) const {
  std::vector<std::pair<double, int>> out;
  const int samples = int(layout.size());
  if (samples == 0) return out;
  const double step = 2 * std::numbers::pi / samples;
  for (int k = 0; k < samples; ++k) {
    const int before = layout[std::size_t(k)], after = layout[std::size_t(k + 1) % std::size_t(samples)];
    if (before == after) continue;
    double lo = (k + 0.5) * step, hi = lo + step;
    for (int i = 0; i < 60; ++i) {
      const double t = 0.5 * (lo + hi);
      (parts.label(gamma_->position(std::fmod(t, 2 * std::numbers::pi))) == before ? lo : hi) = t;
    }
    out.emplace_back(std::fmod(0.5 * (lo + hi), 2 * std::numbers::pi), after);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void CurveDiscretization::make_shape(const Grid2& grid, const SolverOptions& options) {
  const Curve& gamma = *gamma_;
  const double h = grid.h(), width = grid.box().width(0);
  check_simple(gamma, "geometry");
  check_regular(gamma, "geometry");
  if (signed_area(gamma) <= 0)
    throw std::invalid_argument("geometry: the curve must be counter-clockwise (ω on its left)");
  if (const BoxClearance c = box_clearance(gamma, grid.box(), "geometry"); c.distance < 2 * h) {
    char text[240];
    if (c.distance > 0)
      std::snprintf(text, sizeof text,
                    "geometry: the curve comes within %.3g of the box at (%.6g, %.6g); the grid needs 2h = %.3g "
                    "there: N >= %.0f (or a larger box)",
                    c.distance, c.at.x, c.at.y, 2 * h, std::ceil(2 * width / c.distance - 1e-9));
    else
      std::snprintf(
          text, sizeof text,
          "geometry: the curve comes within %.3g of the box boundary (or leaves it) at (%.6g, %.6g): a larger box",
          c.distance, c.at.x, c.at.y);
    throw std::invalid_argument(text);
  }
  gamma_geometry_ = std::make_shared<const CurveGridIntersection>(gamma, grid, "geometry");
  arc_length_ = std::make_shared<const ArcLengthTable>(gamma);
  const double L = arc_length_->length();
  if (options.variant == Variant::smooth && !gamma.smooth())
    throw std::invalid_argument(
        "formulation.variant: the smooth variant needs a curve with a continuous normal "
        "(use \"nonsmooth\" for polygons)");
  const double spacing_cells =
      options.variant == Variant::smooth ? default_spacing_cells_smooth : default_spacing_cells_nonsmooth;
  SpacingInput input{2,
                     L,
                     h,
                     width,
                     [L, spacing_cells](double k) { return default_multipliers(L, k, spacing_cells); },
                     options.variant == Variant::smooth ? curve_offset_room(gamma_, grid.box()) : OffsetRoom()};
  spacing_ = plan_spacing(input, options);
  if (options.variant == Variant::nonsmooth) {
    Gamma_ = gamma_;
    return;
  }
  delta_ = spacing_.delta;
  // Points placed so that the arcs of Γ behind them are equal where γ is convex (there Γ's arcs are
  // stretched by 1 + δκ): the longest arc of Γ, which sets the ripple of the controls, is as short as m
  // allows (docs/math.md, "Placement of the points").
  placement_ = std::make_shared<const ArcLengthTable>(offset_placement(gamma, delta_));
  Gamma_ = std::make_shared<OffsetCurve>(gamma_, delta_);
  check_simple(*Gamma_, "formulation.offset");  // the plan's room says so; checked again on Γ itself
  check_inside_box(*Gamma_, grid.box(), 2 * h, "formulation.offset");
  Gamma_geometry_ = std::make_shared<const CurveGridIntersection>(*Gamma_, grid, "formulation.offset");
}

void CurveDiscretization::place_points(const SolverOptions& options, const PartConditions<2>& parts,
                                       const Collocation* reuse) {
  const Curve& gamma = *gamma_;
  const ArcLengthTable& arc_length = *arc_length_;
  const double L = arc_length.length();
  const int m = spacing_.m;
  // Mixed conditions: the arcs end where the parts meet (and at the corners, which the phase would
  // otherwise keep the points away from), so that each point's arc lies in one part.
  part_layout_ = part_layout(parts);
  junctions_ = junctions(parts, part_layout_);
  const std::vector<std::pair<double, int>>& joins = junctions_;
  // A junction of the contact fit (the Signorini part on both sides) within a quarter spacing of another
  // break is left out: no sliver of an arc between them.
  std::vector<double> breaks;
  std::vector<Snap> fitted, snaps;  // the contact fit's, and those kept
  for (std::size_t k = 0; k < joins.size(); ++k) {
    const int before = joins[(k + joins.size() - 1) % joins.size()].second, after = joins[k].second;
    if (PartConditions<2>::condition_of(before) != PartConditions<2>::condition_of(after))
      breaks.push_back(joins[k].first);
    else
      fitted.push_back({joins[k].first, after == PartConditions<2>::contact_label ? 1 : -1});
  }
  for (const Snap& snap : fitted) {
    bool near = false;
    const auto close = [&](double b) {
      const double d = std::abs(arc_length.s_of_t(snap.t) - arc_length.s_of_t(b));
      return std::min(d, L - d) < 0.25 * L / m;
    };
    for (double b : breaks) near = near || close(b);
    for (const Snap& kept : snaps) near = near || close(kept.t);
    if (!near) snaps.push_back(snap);
  }
  std::sort(breaks.begin(), breaks.end());
  // The corners too (non-smooth), where they are few: one within a quarter spacing of a junction is
  // left to the junction (no sliver of an arc between them).
  if (const std::vector<double> corners = gamma.corners();
      !(breaks.empty() && snaps.empty()) && options.variant == Variant::nonsmooth && int(corners.size()) <= m / 4)
    for (double t : corners) {
      bool near = false;
      for (const auto& [junction, part] : joins) {
        const double d = std::abs(arc_length.s_of_t(t) - arc_length.s_of_t(junction));
        near = near || std::min(d, L - d) < 0.25 * L / m;
      }
      if (!near) breaks.push_back(t);
    }
  const auto set_point_parts = [&]() {
    if (part_layout_.empty()) return;
    point_parts_.assign(std::size_t(m), PartConditions<2>::condition_of(part_layout_[0]));
    if (joins.empty()) return;
    for (int i = 0; i < m; ++i) {  // the part after the last junction before t_i (cyclically)
      const double t = collocation_.t[std::size_t(i)];
      auto it = std::upper_bound(joins.begin(), joins.end(), t, [](double v, const auto& j) { return v < j.first; });
      point_parts_[std::size_t(i)] =
          PartConditions<2>::condition_of((it == joins.begin() ? joins.back() : *std::prev(it)).second);
    }
  };
  if (options.variant == Variant::nonsmooth)
    collocation_ =
        make_collocation(gamma, arc_length, m, phase_off_corners(gamma, arc_length, m), nullptr, breaks, snaps, reuse);
  else
    collocation_ = make_collocation(gamma, arc_length, m, 0.5, placement_.get(), breaks, snaps, reuse);
  set_point_parts();
}

void CurveDiscretization::make_trace_rows(const Grid2& grid, const SolverOptions& options, double c,
                                          const CurveDiscretization* base) {
  const Collocation& points = collocation_;
  B_gamma_ = point_value_rows(grid, points.point);
  const CurveGridIntersection& Gamma = Gamma_geometry_ ? *Gamma_geometry_ : *gamma_geometry_;
  if (base && !points.reused.empty()) {  // the arcs placed as the base's keep its rows (the same numbers)
    std::vector<double> begin, end;
    for (int i = 0; i < points.m; ++i)
      if (points.reused[std::size_t(i)] < 0)
        begin.push_back(points.arc_begin[std::size_t(i)]), end.push_back(points.arc_end[std::size_t(i)]);
    B_Gamma_ = merge_rows(base->B_Gamma_, points.reused, arc_integral_rows(Gamma, begin, end));
  } else {
    B_Gamma_ = arc_integral_rows(Gamma, points.arc_begin, points.arc_end);
  }
  loads_ = B_Gamma_;
  if (options.normal_derivative == NormalDerivative::shifted) {
    C_gamma_ = normal_derivative_rows(grid, points.point, points.normal, options.normal_shift * grid.h());
    return;
  }
  C_gamma_ = normal_derivative_rows_centered(grid, points.point, points.normal, 2);
  if (options.variant == Variant::nonsmooth) {
    kink_ = std::make_unique<KinkCorrection>(*gamma_geometry_, collocation_, c, execution_);
    loads_ = add_rows(B_Gamma_, kink_->galerkin());
    direct_.trace = kink_->direct(B_gamma_);
    direct_.normal_derivative = kink_->direct(C_gamma_);
  }
}

void CurveDiscretization::finish_field(const std::vector<double>& lambda, GridVector& u) const {
  if (kink_) kink_->add_kinks(lambda, u, execution_.distribution().slab(gamma_geometry_->grid()));
}

std::optional<std::vector<double>> CurveDiscretization::independent_normal_derivative(const GridVector& u,
                                                                                      std::string& rule) const {
  std::vector<double> d;
  const Grid2& grid = gamma_geometry_->grid();
  const Distribution& distribution = execution_.distribution();
  if (kink_) {
    rule = "bicubic interpolant of the kink-corrected field";
    read_rows(normal_derivative_rows_centered(grid, points(), normals(), 3), grid, u, distribution, d);
    return d;
  }
  rule = check_fit_rule;
  std::optional<SparseRows> rows;
  try {  // the same on every rank: the rows are made from γ alone
    rows.emplace(one_sided_rows(*gamma_geometry_, points(), normals(), OneSidedTrace::normal_derivative,
                                check_fit_degree, check_fit_radius));
  } catch (const std::runtime_error&) {  // ω too thin for the fit: no check, not a failed solve
    return std::nullopt;
  }
  read_rows(*rows, grid, u, distribution, d);
  return d;
}

std::vector<double> CurveDiscretization::obstacle(const Data& data) const {
  const int m = n_points();
  const std::vector<Point2>& p = points();
  std::vector<double> g(m);
  if (data.g_vectorized && !data.g_along_curve) {
    std::vector<double> x(m), y(m);
    for (int i = 0; i < m; ++i) x[i] = p[i].x, y[i] = p[i].y;
    data.g_vectorized(m, x.data(), y.data(), g.data());
  }
  for (int i = 0; i < m; ++i) {
    if (data.g_along_curve)
      g[i] = data.g_along_curve(p[i].x, p[i].y, arc_positions()[i]);
    else if (!data.g_vectorized)
      g[i] = data.g(p[i].x, p[i].y);
  }
  detail::check_obstacle(g, p);
  return g;
}

void CurveDiscretization::for_each_omega_sample(const GridVector& u, int quadrature,
                                                const OmegaSampleVisitor<2>& visit) const {
  fictus::for_each_omega_sample(u, *gamma_geometry_, quadrature, execution_, visit);
}

ErrorNorms CurveDiscretization::errors(const GridVector& u, const std::vector<double>&, const Data& data,
                                       int quadrature) const {
  if (data.exact_vectorized)
    return compute_errors(u, *gamma_geometry_, data.exact_vectorized, {}, quadrature, execution_);
  return compute_errors(u, *gamma_geometry_, data.exact, data.exact_gradient, quadrature, execution_);
}

PointErrors CurveDiscretization::point_errors(const std::vector<double>& trace,
                                              const std::vector<double>& normal_derivative, const Data& data) const {
  const VectorizedField exact = data.exact_vectorized ? data.exact_vectorized : vectorize(data.exact);
  const std::vector<Point2>& p = points();
  const std::vector<Point2>& n = normals();
  const std::size_t m = p.size();
  std::vector<double> x(m), y(m), values(m);
  for (std::size_t i = 0; i < m; ++i) x[i] = p[i].x, y[i] = p[i].y;
  exact(m, x.data(), y.data(), values.data());
  const Grid2& grid = gamma_geometry_->grid();
  const double step = 1e-5 * (grid.box().upper.x - grid.box().lower.x);
  std::vector<double> xs(2 * m), ys(2 * m), inner(2 * m);
  for (std::size_t i = 0; i < m; ++i)
    for (int k = 0; k < 2; ++k) {
      const Point2 q = p[i] - (k + 1) * step * n[i];
      xs[2 * i + k] = q.x, ys[2 * i + k] = q.y;
    }
  if (!data.exact_gradient) exact(2 * m, xs.data(), ys.data(), inner.data());
  std::vector<double> dudn(m);
  for (std::size_t i = 0; i < m; ++i)
    dudn[i] = data.exact_gradient ? dot(n[i], data.exact_gradient(x[i], y[i]))
                                  : (3 * values[i] - 4 * inner[2 * i] + inner[2 * i + 1]) / (2 * step);
  return detail::point_errors_at(p, trace, normal_derivative, values, dudn);
}

void CurveDiscretization::describe(SolutionBoundary<2>& out) const {
  out.collocation = collocation_;
  out.Gamma = Gamma_;
}

}  // namespace fictus
