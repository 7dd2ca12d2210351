#pragma once
// m collocation points on γ. Point i sits at the middle of arc i (in the measure that spaces them) and
// owns that arc; the arcs are
// equal in arc length (spacing s = L/m), or equal in a placement measure ∫ w(t)|p′(t)| dt: the
// smooth variant's, w = max(1, 1 + δκ), makes the arcs of Γ (their normal offsets at distance δ) equal
// wherever γ is convex (docs/math.md, "Placement of the points"). An arc may wrap past t = 0: then
// arc_begin > arc_end.
#include <vector>

#include "fictus/boundary/curve.hpp"

namespace fictus {

/// One arc in the placement measure: its centre and ends, and the parameter where it starts or ends at a
/// break or a snap exactly (NaN elsewhere).
struct PlacedArc {
  double centre, begin, end, t_begin, t_end;
  /// Bit for bit (NaN equal to NaN): the arcs a later placement can take over without evaluating γ again.
  bool same(const PlacedArc& o) const;
};

/// A contact end the arcs are to end at (make_collocation's snaps): γ's parameter there and the side the
/// contact lies on, +1 towards larger t, −1 towards smaller t, 0 unknown.
struct Snap {
  double t = 0.0;
  int contact_side = 0;
};

struct Collocation {
  int m = 0;
  double length = 0.0;   // L = |γ|
  double spacing = 0.0;  // s = L/m, the mean length of the arcs
  double phase = 0.5;
  std::vector<double> s;                   // arc length of point i
  std::vector<double> arc;                 // length of the arc of γ point i owns (L/m without placement)
  std::vector<double> t;                   // parameter of point i
  std::vector<double> arc_begin, arc_end;  // parameters bounding arc i (arc_begin[0] = 0 with phase ½, no breaks)
  std::vector<Point2> point, normal;       // x_i and the outward unit normal n_i
  std::vector<PlacedArc> placed;           // arc i in the placement measure (for `reuse`)
  std::vector<int> reused;                 // point i's index in make_collocation's `reuse`, or −1 (with one)
  bool equal_arcs = false;                 // s and arc from the equal arcs, not from γ's arc length

  int n_points() const { return m; }
};

/// The points of arcs equal in `placement` (nullptr: in arc length), point i at the placement
/// measure's (i + phase)·W/m. With `breaks` (parameters of γ, e.g. where the conditions' parts meet), an
/// arc ends at each break: the pieces between consecutive breaks get arcs equal within each piece, as
/// many as keep the longest arc shortest (at least one a piece; `phase` is then unused). Throws
/// std::invalid_argument naming formulation.multipliers when m is below the number of pieces. With `snaps`
/// (the contact fit's ends), the arcs so placed then move so that an arc ends at each snap, or, where its
/// contact side is known, a twentieth of the spacing (in `placement`) into its contact: the nearest border moves there
/// and the shift fades over a few arcs on either side, so the arcs stay nearly equal; where that cannot be done the
/// arcs end there as at breaks. `reuse`: a collocation made before with the same curve, tables and m (the contact fit's
/// unsnapped one); the arcs placed exactly as there take their parameters, points and normals from it instead of
/// inverting the measure again (the same numbers).
Collocation make_collocation(const Curve& curve, const ArcLengthTable& arc_length, int m, double phase = 0.5,
                             const ArcLengthTable* placement = nullptr, const std::vector<double>& breaks = {},
                             const std::vector<Snap>& snaps = {}, const Collocation* reuse = nullptr);

/// The smooth variant's placement measure for Γ at distance δ: speed |p′(t)|·max(1, 1 + δκ(t)), the
/// speed of the offset curve where γ is convex and of γ itself where it is concave.
ArcLengthTable offset_placement(const Curve& curve, double delta);

/// The phase (among 32 candidates, ½ first) that keeps the points farthest from the curve's corners.
double phase_off_corners(const Curve& curve, const ArcLengthTable& arc_length, int m);

/// Default spacing of the multipliers in cells, s = L/m ≈ c·h at every N (docs/math.md, "Rules for m
/// and δ": the contact ends are resolved to s, so s must shrink with h): 8 cells in
/// the smooth variant, 12 in the non-smooth one (measured on fitted-mesh references).
inline constexpr double default_spacing_cells_smooth = 8.0;
inline constexpr double default_spacing_cells_nonsmooth = 12.0;

/// The fewest multipliers a solve accepts (and the default rule gives).
inline constexpr int minimum_multipliers = 8;

/// Default number of multipliers: m = max(minimum_multipliers, round(L / (spacing_cells·h))).
int default_multipliers(double curve_length, double h, double spacing_cells = default_spacing_cells_smooth);

}  // namespace fictus
