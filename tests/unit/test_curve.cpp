// Curves: arc length, normals, offset curves, collocation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fictus/boundary/collocation.hpp"
#include "fictus/boundary/curve.hpp"
#include "fictus/boundary/shapes.hpp"
#include "fictus/solve/paper_problem.hpp"

namespace {

constexpr double pi = std::numbers::pi;

double ellipse_perimeter(double a, double b) {  // 4a E(e), e² = 1 − b²/a²
  return 4.0 * a * std::comp_ellint_2(std::sqrt(1.0 - b * b / (a * a)));
}

TEST(Curve, EllipsePerimeterMatchesEllipticIntegral) {
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2, 0.3);
  const fictus::ArcLengthTable table(e);
  EXPECT_NEAR(table.length(), ellipse_perimeter(0.4, 0.2), 1e-12);
}

TEST(Curve, ArcLengthInverse) {
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2);
  const fictus::ArcLengthTable table(e);
  for (double t : {0.0, 0.1, 1.0, 2.5, 4.0, 6.2}) EXPECT_NEAR(table.t_of_s(table.s_of_t(t)), t, 1e-12);
}

TEST(Curve, OutwardNormalAndCurvature) {
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2);
  const fictus::Point2 n0 = e.outward_normal(0.0), n1 = e.outward_normal(pi / 2);
  EXPECT_NEAR(n0.x, 1.0, 1e-15);
  EXPECT_NEAR(n1.y, 1.0, 1e-15);
  EXPECT_NEAR(e.curvature(0.0), 0.4 / (0.2 * 0.2), 1e-12);  // a/b² at the end of the major axis
}

TEST(Curve, OffsetCurveLengthGrowsByTwoPiDelta) {
  auto e = std::make_shared<fictus::Ellipse>(fictus::Point2{0.5, 0.5}, 0.4, 0.2);
  const double delta = 0.03;
  const fictus::OffsetCurve gamma(e, delta);
  EXPECT_NEAR(fictus::ArcLengthTable(gamma).length(), ellipse_perimeter(0.4, 0.2) + 2 * pi * delta, 1e-11);
  const fictus::Point2 p = gamma.position(1.0), q = e->position(1.0), n = e->outward_normal(1.0);
  EXPECT_NEAR(fictus::dot(p - q, n), delta, 1e-15);
}

TEST(Collocation, EquallySpacedInArcLength) {
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2);
  const fictus::ArcLengthTable table(e);
  const fictus::Collocation c = fictus::make_collocation(e, table, 34);
  for (int i = 0; i < c.m; ++i) {
    EXPECT_NEAR(table.s_of_t(c.t[i]), (i + 0.5) * c.spacing, 1e-12);
    EXPECT_NEAR(table.s_of_t(c.arc_end[i]) - table.s_of_t(c.arc_begin[i]), c.spacing, 1e-12);
  }
}

TEST(Collocation, OffsetPlacementMakesTheArcsOfGammaEqualWhereGammaIsConvex) {
  // Convex ellipse: every arc of Γ (the normal offsets of γ's arcs at δ) has the length |Γ|/m; γ's arcs
  // are shorter at the ends of the major axis (curvature a/b² = 10) and cover γ once.
  auto e = std::make_shared<fictus::Ellipse>(fictus::Point2{0.5, 0.5}, 0.4, 0.2);
  const fictus::ArcLengthTable table(*e);
  const double delta = 0.057;
  const fictus::ArcLengthTable placement = fictus::offset_placement(*e, delta);
  const fictus::Collocation c = fictus::make_collocation(*e, table, 34, 0.5, &placement);
  const fictus::OffsetCurve Gamma(e, delta);
  const fictus::ArcLengthTable on_Gamma(Gamma);
  EXPECT_NEAR(placement.length(), on_Gamma.length(), 1e-12);
  double total = 0, shortest = 1e300, longest = 0;
  for (int i = 0; i < c.m; ++i) {
    const double from = on_Gamma.s_of_t(c.arc_begin[i]), to = on_Gamma.s_of_t(c.arc_end[i]);
    EXPECT_NEAR(to >= from ? to - from : to + on_Gamma.length() - from, on_Gamma.length() / c.m, 1e-11);
    EXPECT_NEAR(c.s[i], table.s_of_t(c.t[i]), 1e-14);
    total += c.arc[i];
    shortest = std::min(shortest, c.arc[i]);
    longest = std::max(longest, c.arc[i]);
  }
  EXPECT_NEAR(total, table.length(), 1e-12);
  EXPECT_LT(shortest, 0.8 * c.spacing);  // at the ends of the major axis: about |Γ|/m / (1 + δ·10) = 0.76 s
  EXPECT_GT(longest, c.spacing);

  // A star with concave parts: there the weight is 1 (γ's own arc length), so no arc of γ is longer
  // than W/m, W = ∫ max(1, 1 + δκ) ds, and none of Γ's longer than that either.
  const fictus::StarCurve star({0.5, 0.5}, [](double t) { return 0.3 + 0.08 * std::cos(5 * t); });
  const fictus::ArcLengthTable star_table(star);
  const fictus::ArcLengthTable star_placement = fictus::offset_placement(star, 0.03);
  const fictus::Collocation d = fictus::make_collocation(star, star_table, 60, 0.5, &star_placement);
  for (int i = 0; i < d.m; ++i) EXPECT_LE(d.arc[i], star_placement.length() / d.m * (1 + 1e-9));
  EXPECT_GT(star_placement.length(), star_table.length());
}

TEST(Collocation, ArcsEndAtTheBreaks) {
  // Three breaks (one past t = 0 on the wrap): every break is an arc's end and the next arc's start, the
  // arcs are equal within each piece, the m arcs cover γ once, and the longest is as short as m allows.
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2, 0.3);
  const fictus::ArcLengthTable table(e);
  const std::vector<double> breaks = {0.4, 2.5, 6.1};
  const int m = 37;
  const fictus::Collocation c = fictus::make_collocation(e, table, m, 0.5, nullptr, breaks);
  ASSERT_EQ(c.m, m);
  double total = 0, longest = 0;
  for (int i = 0; i < m; ++i) {
    total += c.arc[i];
    longest = std::max(longest, c.arc[i]);
    EXPECT_NEAR(c.arc_end[i], c.arc_begin[(i + 1) % m], 1e-12) << i;  // consecutive, in order from t = 0
    if (i > 0) EXPECT_GT(c.s[i], c.s[i - 1]);
  }
  EXPECT_NEAR(total, table.length(), 1e-12);
  for (double t : breaks) {
    int ends = 0;
    for (int i = 0; i < m; ++i) ends += std::abs(c.arc_end[i] - t) < 1e-14;
    EXPECT_EQ(ends, 1) << "break " << t;
  }
  // Optimal counts: taking an arc from any piece would make its arcs longer than the longest now.
  const double L = table.length();
  std::vector<double> at;
  for (double t : breaks) at.push_back(table.s_of_t(t));
  for (int k = 0; k < 3; ++k) {
    const double from = at[std::size_t(k)], length = k < 2 ? at[std::size_t(k) + 1] - from : at[0] + L - from;
    std::vector<int> in_piece;
    for (int i = 0; i < m; ++i)
      if (std::fmod(c.s[i] - from + L, L) < length) in_piece.push_back(i);
    const int count = int(in_piece.size());
    ASSERT_GE(count, 1);
    for (int i : in_piece) EXPECT_NEAR(c.arc[i], length / count, 1e-12) << "piece " << k;  // equal within it
    if (count > 1) EXPECT_GE(length / (count - 1), longest * (1 - 1e-12)) << "piece " << k;
  }
  EXPECT_LT(longest, 1.1 * L / m);
  EXPECT_THROW(fictus::make_collocation(e, table, 2, 0.5, nullptr, breaks), std::invalid_argument);
}

TEST(Collocation, ReuseTakesOverTheArcsPlacedAsBeforeBitForBit) {
  // The contact fit's placements take the arcs placed as in the solve before from it: the same numbers as a
  // placement made without it, in every field, with snaps on the wrap past t = 0 and beside a break, in
  // arc length (the non-smooth variant: s from the equal arcs before, from γ now) and in a placement measure.
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2, 0.3);
  const fictus::ArcLengthTable table(e);
  const fictus::ArcLengthTable placement = fictus::offset_placement(e, 0.05);
  const int m = 60;
  for (const fictus::ArcLengthTable* measure : {static_cast<const fictus::ArcLengthTable*>(nullptr), &placement})
    for (const std::vector<double>& breaks : {std::vector<double>{}, std::vector<double>{2.5}}) {
      const std::vector<fictus::Snap> snaps = {{0.93, 1}, {2.62, -1}, {6.27, 0}};
      const fictus::Collocation before = fictus::make_collocation(e, table, m, 0.5, measure, breaks);
      const fictus::Collocation scratch = fictus::make_collocation(e, table, m, 0.5, measure, breaks, snaps);
      const fictus::Collocation reused = fictus::make_collocation(e, table, m, 0.5, measure, breaks, snaps, &before);
      ASSERT_EQ(int(reused.reused.size()), m);
      EXPECT_TRUE(scratch.reused.empty());
      int taken = 0;
      for (int i = 0; i < m; ++i) {
        const std::size_t k = std::size_t(i);
        EXPECT_EQ(reused.t[k], scratch.t[k]) << i;
        EXPECT_EQ(reused.s[k], scratch.s[k]) << i;
        EXPECT_EQ(reused.arc[k], scratch.arc[k]) << i;
        EXPECT_EQ(reused.arc_begin[k], scratch.arc_begin[k]) << i;
        EXPECT_EQ(reused.arc_end[k], scratch.arc_end[k]) << i;
        EXPECT_EQ(reused.point[k].x, scratch.point[k].x) << i;
        EXPECT_EQ(reused.normal[k].y, scratch.normal[k].y) << i;
        if (const int j = reused.reused[k]; j >= 0) {
          ++taken;
          EXPECT_EQ(reused.t[k], before.t[std::size_t(j)]) << i;  // the arc it was taken from
        }
      }
      EXPECT_GE(taken, m / 2);  // the arcs far from the snaps were taken over
      EXPECT_LE(taken, m - 6);  // and the moved ones made again (at least two per snap)
    }
}

TEST(Collocation, SnapsMoveTheNearestBordersAndKeepTheOtherArcs) {
  // The contact fit's ends: an arc ends at each snap (one past t = 0 on the wrap, one beside a break), the
  // arcs more than a few away from every snap are those without snaps, and neighbouring arcs differ by at
  // most a quarter of the spacing here (each shift, at most s/2 where the nearest border is free, fades
  // over two arcs).
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2, 0.3);
  const fictus::ArcLengthTable table(e);
  const int m = 60;
  const std::vector<double> breaks = {2.5};
  const std::vector<fictus::Snap> snaps = {{0.93}, {2.62}, {6.2}};
  const fictus::Collocation plain = fictus::make_collocation(e, table, m, 0.5, nullptr, breaks);
  const fictus::Collocation c = fictus::make_collocation(e, table, m, 0.5, nullptr, breaks, snaps);
  ASSERT_EQ(c.m, m);
  const double L = table.length(), s = L / m;
  double total = 0;
  for (int i = 0; i < m; ++i) {
    total += c.arc[i];
    EXPECT_NEAR(c.arc_end[i], c.arc_begin[(i + 1) % m], 1e-12) << i;
    EXPECT_GT(c.arc[i], 0.5 * s) << i;
    EXPECT_LT(std::abs(c.arc[i] - c.arc[(i + 1) % m]), 0.25 * s + 1e-12) << i;
  }
  EXPECT_NEAR(total, L, 1e-12);
  for (double t : {breaks[0], snaps[0].t, snaps[1].t, snaps[2].t}) {
    int ends = 0;
    for (int i = 0; i < m; ++i) ends += std::abs(c.arc_end[i] - t) < 1e-14;
    EXPECT_EQ(ends, 1) << "end " << t;
  }
  int kept = 0;
  for (int i = 0; i < m; ++i) {
    double nearest = L;
    for (const fictus::Snap& snap : snaps) {
      const double d = std::abs(c.s[i] - table.s_of_t(snap.t));
      nearest = std::min(nearest, std::min(d, L - d));
    }
    if (nearest > 3.5 * s) {
      EXPECT_NEAR(c.arc[i], plain.arc[i], 1e-12) << i;
      ++kept;
    }
  }
  EXPECT_GT(kept, m / 2);
  // Two snaps closer than an arc: the arcs still end at both.
  const std::vector<fictus::Snap> close = {{1.0}, {1.0 + 0.3 * s / table.length() * 2 * pi}};
  const fictus::Collocation d = fictus::make_collocation(e, table, m, 0.5, nullptr, {}, close);
  for (const fictus::Snap& snap : close) {
    int ends = 0;
    for (int i = 0; i < m; ++i) ends += std::abs(d.arc_end[i] - snap.t) < 1e-14;
    EXPECT_EQ(ends, 1) << "close end " << snap.t;
  }
}

TEST(Collocation, SnapsWithASideEndAnArcJustInsideTheContact) {
  // A located end whose contact lies towards larger t (side +1) or smaller t (−1): an arc ends a twentieth
  // of the spacing (in the placement measure) into the contact, one with no side at the end itself; the
  // arcs stay within about a quarter spacing of equal. In arc length and in a placement measure, in the
  // middle of γ and on either side of t = 0 (the target wraps past it).
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2, 0.3);
  const fictus::ArcLengthTable table(e);
  const fictus::ArcLengthTable placement = fictus::offset_placement(e, 0.05);
  const int m = 60;
  for (const fictus::ArcLengthTable* measure : {&table, &placement}) {
    const double W = measure->length(), s = W / m;
    for (const double at : {17.1, 17.3, 17.5, 17.7, 17.9, 0.02, m - 0.02})  // in spacings of the measure
      for (const int side : {1, -1, 0}) {
        const double t = measure->t_of_s(at * s);
        const fictus::Collocation c =
            fictus::make_collocation(e, table, m, 0.5, measure == &table ? nullptr : measure, {}, {{t, side}});
        const double target = at + 0.05 * side;  // in spacings, taken cyclically
        int ends = 0;
        for (int i = 0; i < m; ++i) {
          const double w = measure->s_of_t(c.arc_end[std::size_t(i)]) / s;
          ends += std::abs(std::remainder(w - target, double(m))) < 1e-10;
          const double arc =
              (measure->s_of_t(c.arc_end[std::size_t(i)]) - measure->s_of_t(c.arc_begin[std::size_t(i)]));
          const double length = (arc < 0 ? arc + W : arc) / s;  // an arc may wrap past t = 0
          EXPECT_GT(length, 0.725 - 1e-9) << i;
          EXPECT_LT(length, 1.275 + 1e-9) << i;
        }
        EXPECT_EQ(ends, 1) << at << " " << side;
        if (side == 0) {
          int exact = 0;
          for (int i = 0; i < m; ++i) exact += c.arc_end[std::size_t(i)] == t;
          EXPECT_EQ(exact, 1) << at;
        }
      }
  }
}

TEST(Collocation, DefaultRuleKeepsTheSpacingInCells) {
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2);
  const double L = fictus::ArcLengthTable(e).length();
  for (int N = 128; N <= 4096; N *= 2) {
    EXPECT_NEAR(L / fictus::default_multipliers(L, 1.0 / N) * N, 8.0, 0.3)
        << "N = " << N;  // m rounded (m ≈ 20 at N = 128)
    EXPECT_NEAR(L / fictus::default_multipliers(L, 1.0 / N, fictus::default_spacing_cells_nonsmooth) * N, 12.0, 0.3)
        << "N = " << N;
  }
  EXPECT_EQ(fictus::default_multipliers(0.01, 1.0 / 64), 8);  // never fewer than 8
}

TEST(Collocation, PaperRuleBeyondItsTable) {
  EXPECT_EQ(fictus::paper_multipliers(1024), 198);
  EXPECT_NEAR(fictus::paper_multipliers(8192), 34.0 * std::pow(64.0, 0.85), 1.0);  // 1/8192: m ∝ N^0.85
}

// The orientation sign is exact where rounding fails (Kettner et al.'s example): a = (0.5 + i u,
// 0.5 + j u) with u = 2⁻⁵³ against b = (12, 12), c = (24, 24), compared with the exact determinant
// in integers (all coordinates are whole multiples of u).
TEST(Predicates, OrientationIsExactWhereRoundingFails) {
  const double u = std::ldexp(1.0, -53);
  const __int128 unit = __int128(1) << 53;
  const __int128 bx = 12 * unit, cx = 24 * unit;
  int rounded_wrong = 0;
  for (int i = 0; i < 128; ++i)
    for (int j = 0; j < 128; ++j) {
      const fictus::Point2 a{0.5 + i * u, 0.5 + j * u}, b{12, 12}, c{24, 24};
      const __int128 ax = unit / 2 + i, ay = unit / 2 + j;
      const __int128 det = (bx - ax) * (cx - ay) - (bx - ay) * (cx - ax);
      const int exact = det > 0 ? 1 : det < 0 ? -1 : 0;
      ASSERT_EQ(fictus::orientation(a, b, c), exact) << i << ", " << j;
      const double rounded = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
      rounded_wrong += (rounded > 0 ? 1 : rounded < 0 ? -1 : 0) != exact;
    }
  EXPECT_GT(rounded_wrong, 1000) << "the example must be one where the rounded determinant errs";
  EXPECT_EQ(fictus::orientation({0, 0}, {1, 1}, {3, 3}), 0);
  EXPECT_EQ(fictus::orientation({0.1, 0.1}, {0.2, 0.2}, {0.3, 0.3}),
            -fictus::orientation({0.2, 0.2}, {0.1, 0.1}, {0.3, 0.3}));
}

// Segments that meet in every way, decided exactly; and ones that only come close.
TEST(Predicates, SegmentsMeetCatchesTouchesOverlapsAndShallowCrossings) {
  using fictus::Point2;
  using fictus::segments_meet;
  EXPECT_TRUE(segments_meet({0, 0}, {1, 1}, {0, 1}, {1, 0}, 0));             // crossing
  EXPECT_TRUE(segments_meet({0, 0}, {1, 0}, {0.5, 0}, {0.5, 1}, 0));         // an end on the other
  EXPECT_TRUE(segments_meet({0, 0}, {1, 0}, {0.5, 0}, {2, 0}, 0));           // collinear overlap
  EXPECT_TRUE(segments_meet({0, 0}, {1, 0}, {1, 0}, {2, 1}, 0));             // shared end
  EXPECT_FALSE(segments_meet({0, 0}, {1, 0}, {1.5, 0}, {2, 0}, 0));          // collinear, apart
  EXPECT_FALSE(segments_meet({0, 0}, {1, 0}, {0, 1e-300}, {1, 1e-300}, 0));  // parallel, apart
  // A shallow crossing (at x = 5e-4) of a short segment by a long one whose end lies 5e-10 off the
  // short one's line, beyond its end: orientation areas of 1e-11 … 5e-13. A test that calls areas
  // below 1e-12 collinear sees d "on the line but off the segment" and no crossing.
  EXPECT_TRUE(segments_meet({0, 0}, {1e-3, 0}, {-0.1995, 1e-8}, {0.0105, -5e-10}, 0));
  EXPECT_FALSE(segments_meet({0, 0}, {1e-3, 0}, {-0.1995, 1e-8}, {0.0105, 5e-10}, 1e-12));
  // Decimal input: (0.5, 0.3) is on the edge (0, 0)–(1, 0.6) in decimal, not in binary. Exactly
  // it does not touch; within the closeness it does.
  EXPECT_TRUE(segments_meet({0, 0}, {1, 0.6}, {0.5, 0.3}, {0.5, 1}, 1e-12));
  EXPECT_FALSE(segments_meet({0, 0}, {1, 0.6}, {0.5, 0.31}, {0.5, 1}, 1e-12));
}

}  // namespace
