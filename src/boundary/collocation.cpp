#include "fictus/boundary/collocation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>
#include <stdexcept>
#include <string>

namespace fictus {

bool PlacedArc::same(const PlacedArc& o) const {
  const auto equal = [](double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); };
  return centre == o.centre && begin == o.begin && end == o.end && equal(t_begin, o.t_begin) && equal(t_end, o.t_end);
}

namespace {

/// Arcs over which a snap's shift fades (make_collocation's snaps): measured on the 2-D references, 2 gave
/// the lowest errors of 1, 2, 3, 4 and 6 (bench/results/2026-11-29-contact-snap.md).
constexpr int snap_reach = 2;

/// How far into the contact side of a located end its arc border goes, in spacings (make_collocation's
/// snaps with a side). With an arc border exactly at a contact end the discrete problem acts as if its
/// contact reached further: with the contact set fixed to the fitted-mesh references' own, the error is
/// least with each end moved 0.05–0.1 s into the contact (1.4–6.5× below the error at the exact ends, at every
/// N). Of 0, 0.03, 0.05, 0.075 and 0.1 in the fitted solves, 0.05 gave the lowest errors with the fewest bad
/// runs (bench/results/2026-12-06-contact-inset.md).
constexpr double snap_inset = 0.05;

/// The arcs in the placement measure: m equal ones from (phase − ½)·W/m on; or, with breaks, each piece
/// between consecutive breaks cut into equal arcs, the pieces given their counts one at a time to the
/// piece whose arcs are longest (at least one each). Each arc as [begin, end) in the measure, and the
/// parameter at a break exactly where an arc starts or ends there (NaN elsewhere).
std::vector<PlacedArc> placed_arcs(const ArcLengthTable& measure, int m, double phase,
                                   const std::vector<double>& breaks) {
  const double total = measure.length(), none = std::numeric_limits<double>::quiet_NaN();
  std::vector<PlacedArc> arcs;
  if (breaks.empty()) {
    const double step = total / m;
    for (int i = 0; i < m; ++i) {
      const double w = (i + phase) * step;
      arcs.push_back({w, w - 0.5 * step, w + 0.5 * step, none, none});
    }
    return arcs;
  }
  std::vector<std::pair<double, double>> at;  // (measure, parameter) of each break
  for (double t : breaks) at.emplace_back(t <= 0 ? 0.0 : measure.s_of_t(t), t);
  std::sort(at.begin(), at.end());
  at.erase(std::unique(at.begin(), at.end(),  // a junction at a corner breaks γ once
                       [total](const auto& a, const auto& b) { return b.first - a.first < 1e-12 * total; }),
           at.end());
  if (at.size() > 1 && at[0].first + total - at.back().first < 1e-12 * total) at.pop_back();
  const int pieces = int(at.size());
  if (m < pieces)
    throw std::invalid_argument(
        "formulation.multipliers: m = " + std::to_string(m) + " is fewer than the " + std::to_string(pieces) +
        " pieces of gamma between the junctions of the conditions' parts (and its corners): raise m or N");
  std::vector<double> length(static_cast<std::size_t>(pieces));
  for (int k = 0; k < pieces; ++k)
    length[std::size_t(k)] =
        (k + 1 < pieces ? at[std::size_t(k) + 1].first : at[0].first + total) - at[std::size_t(k)].first;
  std::vector<int> count(static_cast<std::size_t>(pieces), 1);
  std::priority_queue<std::pair<double, int>> longest;  // (arc length in the piece, piece)
  for (int k = 0; k < pieces; ++k) longest.emplace(length[std::size_t(k)], k);
  for (int given = pieces; given < m; ++given) {
    const int k = longest.top().second;
    longest.pop();
    ++count[std::size_t(k)];
    longest.emplace(length[std::size_t(k)] / count[std::size_t(k)], k);
  }
  const auto end_at = [](double t) { return t <= 0 ? 2 * std::numbers::pi : t; };  // an arc ending at t = 0
  for (int k = 0; k < pieces; ++k) {
    const double from = at[std::size_t(k)].first, step = length[std::size_t(k)] / count[std::size_t(k)];
    const int n = count[std::size_t(k)];
    for (int i = 0; i < n; ++i)
      arcs.push_back({from + (i + 0.5) * step, from + i * step, from + (i + 1) * step,
                      i == 0 ? at[std::size_t(k)].second : none,
                      i + 1 == n ? end_at(at[std::size_t(k + 1) % std::size_t(pieces)].second) : none});
  }
  return arcs;
}

/// Moves the arcs' borders so that one ends at each snap (a parameter of γ), each snap taking the
/// nearest free border (at most s/2 away unless another snap or a break holds it; at most 3s/4); the
/// shift d fades linearly over snap_reach arcs on either side (the breaks and the other snaps hold their
/// borders), so the arcs stay as they were away from the snaps and, near a snap with no other within
/// 2·snap_reach arcs, change by |d|/snap_reach from one to the next. False (the arcs untouched) where a
/// snap finds no border of its own or an arc would shrink below a quarter of the spacing (snaps out of
/// their order along γ make an arc negative).
bool snap_borders(const ArcLengthTable& measure, std::vector<PlacedArc>& arcs, const std::vector<double>& snaps) {
  const double total = measure.length();
  const int m = int(arcs.size());
  const double mean = total / m;
  std::vector<double> border(static_cast<std::size_t>(m)), shift(static_cast<std::size_t>(m), 0.0),
      t_at(static_cast<std::size_t>(m), std::numeric_limits<double>::quiet_NaN());
  std::vector<char> anchor(static_cast<std::size_t>(m), 0);
  for (int i = 0; i < m; ++i) {
    border[std::size_t(i)] = arcs[std::size_t(i)].begin;
    if (!std::isnan(arcs[std::size_t(i)].t_begin))
      anchor[std::size_t(i)] = 1, t_at[std::size_t(i)] = arcs[std::size_t(i)].t_begin;
  }
  const auto cyclic = [total](double d) { return d - total * std::round(d / total); };
  std::vector<double> from_first(static_cast<std::size_t>(m));  // the borders from border 0 on: increasing
  for (int i = 0; i < m; ++i) from_first[std::size_t(i)] = border[std::size_t(i)] - border[0];
  for (double t : snaps) {
    const double w = t <= 0 ? 0.0 : measure.s_of_t(t);
    double offset = std::fmod(w - border[0], total);
    if (offset < 0) offset += total;
    const int j = int(std::upper_bound(from_first.begin(), from_first.end(), offset) - from_first.begin()) - 1;
    int best = -1;  // the nearest free one of the borders j − 1 … j + 2 (j, j + 1 enclose the snap)
    for (int k = -1; k <= 2; ++k) {
      const int i = ((j + k) % m + m) % m;
      if (!anchor[std::size_t(i)] &&
          (best < 0 || std::abs(cyclic(w - border[std::size_t(i)])) < std::abs(cyclic(w - border[std::size_t(best)]))))
        best = i;
    }
    if (best < 0 || std::abs(cyclic(w - border[std::size_t(best)])) > 0.75 * mean) return false;
    anchor[std::size_t(best)] = 1, shift[std::size_t(best)] = cyclic(w - border[std::size_t(best)]);
    t_at[std::size_t(best)] = t;
  }
  std::vector<int> anchors;
  for (int i = 0; i < m; ++i)
    if (anchor[std::size_t(i)]) anchors.push_back(i);
  for (std::size_t a = 0; a < anchors.size(); ++a) {  // between consecutive anchors (cyclically)
    const int from = anchors[a], gap = (a + 1 < anchors.size() ? anchors[a + 1] : anchors[0] + m) - from;
    const double d0 = shift[std::size_t(from)], d1 = shift[std::size_t((from + gap) % m)];
    for (int k = 1; k < gap; ++k)
      shift[std::size_t((from + k) % m)] = gap <= 2 * snap_reach
                                               ? d0 + (d1 - d0) * k / gap
                                               : d0 * std::max(0.0, 1.0 - double(k) / snap_reach) +
                                                     d1 * std::max(0.0, 1.0 - double(gap - k) / snap_reach);
  }
  std::vector<PlacedArc> moved(arcs);  // an arc whose borders stay is kept bit for bit (its rows too)
  for (int i = 0; i < m; ++i) {
    const int next = (i + 1) % m;
    if (shift[std::size_t(i)] == 0 && shift[std::size_t(next)] == 0) continue;
    const double begin = border[std::size_t(i)] + shift[std::size_t(i)],
                 end = border[std::size_t(next)] + (next == 0 ? total : 0.0) + shift[std::size_t(next)];
    if (end - begin < 0.25 * mean) return false;
    moved[std::size_t(i)] = {0.5 * (begin + end), begin, end, t_at[std::size_t(i)],
                             std::isnan(t_at[std::size_t(next)]) || t_at[std::size_t(next)] > 0
                                 ? t_at[std::size_t(next)]
                                 : 2 * std::numbers::pi};  // an arc ending at t = 0
  }
  arcs = std::move(moved);
  return true;
}

/// Where an arc is to end for `snap`: snap_inset spacings (of the measure) into its contact side; at the
/// snap itself where the side is unknown.
double snap_target(const ArcLengthTable& measure, int m, const Snap& snap) {
  if (snap.contact_side == 0) return snap.t;
  const double total = measure.length();
  const double w = std::fmod(
      (snap.t <= 0 ? 0.0 : measure.s_of_t(snap.t)) + snap.contact_side * snap_inset * total / m + total, total);
  return w <= 0 ? 0.0 : measure.t_of_s(w);
}

}  // namespace

Collocation make_collocation(const Curve& curve, const ArcLengthTable& arc_length, int m, double phase,
                             const ArcLengthTable* placement, const std::vector<double>& breaks,
                             const std::vector<Snap>& snaps, const Collocation* reuse) {
  if (m < 1) throw std::invalid_argument("make_collocation: need m >= 1, got " + std::to_string(m));
  Collocation c;
  c.m = m;
  c.length = arc_length.length();
  c.spacing = c.length / m;
  c.phase = phase;
  c.s.resize(m);
  c.arc.resize(m);
  c.t.resize(m);
  c.arc_begin.resize(m);
  c.arc_end.resize(m);
  c.point.resize(m);
  c.normal.resize(m);
  const double two_pi = 2.0 * std::numbers::pi;
  const ArcLengthTable& measure = placement ? *placement : arc_length;
  const double total = measure.length();
  auto wrap = [total](double w) {
    w = std::fmod(w, total);
    return w < 0 ? w + total : w;
  };
  auto t_at = [&](double w) {  // parameter at measure w (mod the total); exact ends at 0 and the total
    w = wrap(w);
    return w <= 0 ? 0.0 : measure.t_of_s(w);
  };
  std::vector<PlacedArc> arcs = placed_arcs(measure, m, phase, breaks);
  std::vector<double> targets;  // where the arcs are to end for the snaps
  for (const Snap& snap : snaps) targets.push_back(snap_target(measure, m, snap));
  if (!targets.empty() && !snap_borders(measure, arcs, targets)) {  // then arcs end at them as at breaks
    std::vector<double> all = breaks;
    all.insert(all.end(), targets.begin(), targets.end());
    arcs = placed_arcs(measure, m, phase, all);
  }
  // Point 0 is the first from t = 0 on (an arc may wrap past 0).
  std::stable_sort(arcs.begin(), arcs.end(),
                   [&wrap](const PlacedArc& a, const PlacedArc& b) { return wrap(a.centre) < wrap(b.centre); });
  const bool equal = !placement && breaks.empty() && snaps.empty();
  c.equal_arcs = equal;
  if (reuse && (reuse->m != m || reuse->placed.size() != std::size_t(m))) reuse = nullptr;
  std::size_t from = 0;  // where the search of `reuse`'s arcs (in the same order) goes on
  for (int i = 0; i < m; ++i) {
    const PlacedArc& a = arcs[std::size_t(i)];
    const double w = a.centre;
    std::size_t k = from;  // the same arc in `reuse`, if there is one
    if (reuse) {
      while (k < std::size_t(m) && wrap(reuse->placed[k].centre) < wrap(w)) ++k;
      if (k < std::size_t(m) && !reuse->placed[k].same(a)) from = k, k = std::size_t(m);  // (later arcs lie on)
    }
    if (reuse) c.reused.push_back(k < std::size_t(m) ? int(k) : -1);
    if (reuse && k < std::size_t(m)) {
      from = k + 1;
      c.t[i] = reuse->t[k], c.arc_begin[i] = reuse->arc_begin[k], c.arc_end[i] = reuse->arc_end[k];
      c.point[i] = reuse->point[k], c.normal[i] = reuse->normal[k];
    } else {
      c.t[i] = t_at(w);
      c.arc_begin[i] = !std::isnan(a.t_begin) ? a.t_begin : std::abs(a.begin) < 1e-14 * total ? 0.0 : t_at(a.begin);
      c.arc_end[i] = !std::isnan(a.t_end) ? a.t_end : std::abs(a.end - total) < 1e-14 * total ? two_pi : t_at(a.end);
      c.point[i] = curve.position(c.t[i]);
      c.normal[i] = curve.outward_normal(c.t[i]);
      k = std::size_t(m);
    }
    if (equal) {
      c.s[i] = w;
      c.arc[i] = c.spacing;
    } else if (k < std::size_t(m) && !reuse->equal_arcs) {
      c.s[i] = reuse->s[k], c.arc[i] = reuse->arc[k];
    } else {
      c.s[i] = arc_length.s_of_t(c.t[i]);
      const double begin = arc_length.s_of_t(c.arc_begin[i]), end = arc_length.s_of_t(c.arc_end[i]);
      c.arc[i] = end >= begin ? end - begin : end + c.length - begin;
    }
  }
  c.placed = std::move(arcs);
  return c;
}

ArcLengthTable offset_placement(const Curve& curve, double delta) {
  return ArcLengthTable(
      [&curve, delta](double t) { return curve.speed(t) * std::max(1.0, 1.0 + delta * curve.curvature(t)); });
}

double phase_off_corners(const Curve& curve, const ArcLengthTable& arc_length, int m) {
  const std::vector<double> corners = curve.corners();
  if (corners.empty()) return 0.5;
  const double spacing = arc_length.length() / m;
  double best_phase = 0.5, best_distance = -1.0;
  for (int k = 0; k < 32; ++k) {
    const double phase = std::fmod(0.5 + k / 32.0, 1.0);
    double distance = 1e300;
    for (double t : corners) {
      const double u = arc_length.s_of_t(t) / spacing - phase;  // in units of the spacing
      distance = std::min(distance, std::abs(u - std::round(u)));
    }
    if (distance > best_distance + 1e-12) best_distance = distance, best_phase = phase;
  }
  return best_phase;
}

int default_multipliers(double curve_length, double h, double spacing_cells) {
  return std::max(minimum_multipliers, int(std::lround(curve_length / (spacing_cells * h))));
}

}  // namespace fictus
