// The dense blocks R A⁻¹ Qᵀ from the Green's table: exact against fast solves, and with the far
// field interpolated (FarField) against the exact assembly.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <ostream>

#include "fictus/boundary/curve.hpp"
#include "fictus/boundary/omega_quadrature.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/boundary/surface_integrals.hpp"
#include "fictus/boundary/trace_operators.hpp"
#include "fictus/grid/fast_solver.hpp"
#include "fictus/solve/curve_discretization.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/hierarchical_schur.hpp"
#include "fictus/solve/schur_complement.hpp"
#include "fictus/solve/surface_discretization.hpp"
#include "sphere_rows.hpp"

namespace {

struct Case {
  fictus::Boundary boundary;
  double c;
  double radius;  // of the sphere about the box's center: 0.45 comes within 2.4h of the walls at N = 48
};

std::string name(const ::testing::TestParamInfo<struct Case>& info);
void PrintTo(const Case& k, std::ostream* out) {
  *out << (k.boundary == fictus::Boundary::periodic ? "periodic" : "dirichlet") << ", c = " << k.c
       << ", r = " << k.radius;
}

/// The rows of the case's sphere.
struct SphereRows : fictus::test_support::SphereRows {
  SphereRows(const Case& k, int N, double patch_cells, double delta_cells)
      : fictus::test_support::SphereRows(k.boundary, k.radius, N, patch_cells, delta_cells) {}
};

double relative_max_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

class GreenBlocksTest : public ::testing::TestWithParam<Case> {};

TEST_P(GreenBlocksTest, ExactAssemblyMatchesFastSolves) {
  const SphereRows rows(GetParam(), 32, 3.0, 0.0);
  const fictus::GreenTable<3> green(rows.grid, GetParam().c);
  const std::vector<Eigen::MatrixXd> S = fictus::green_blocks(green, {&rows.B, &rows.C}, rows.Q);
  const auto solver = fictus::make_fast_solver(rows.grid, GetParam().c);
  for (int col : {0, rows.Q.n_rows() / 3, rows.Q.n_rows() - 1}) {
    std::vector<double> unit(std::size_t(rows.Q.n_rows()), 0.0);
    unit[std::size_t(col)] = 1.0;
    fictus::GridVector w(rows.grid.n_unknowns(), 0.0);
    rows.Q.add_transposed(unit, w);
    solver->solve_in_place(w);  // A⁺ for the singular periodic c = 0, as the table
    std::vector<double> b, c;
    rows.B.multiply(w, b);
    rows.C.multiply(w, c);
    for (int r = 0; r < rows.B.n_rows(); ++r) {
      EXPECT_NEAR(S[0](r, col), b[std::size_t(r)], 1e-11 * S[0].cwiseAbs().maxCoeff());
      EXPECT_NEAR(S[1](r, col), c[std::size_t(r)], 1e-11 * S[1].cwiseAbs().maxCoeff());
    }
  }
}

TEST_P(GreenBlocksTest, InterpolatedFarFieldConvergesWithTheOrder) {
  // Patches of 4h at N = 48, Γ at 2h: a few hundred rows, most pairs far. The error of an interpolated pair
  // falls like (radius/distance)^order; the exact pairs and the rows' structure are untouched.
  const SphereRows rows(GetParam(), 48, 4.0, 2.0);
  const fictus::GreenTable<3> green(rows.grid, GetParam().c);
  const std::vector<Eigen::MatrixXd> exact = fictus::green_blocks(green, {&rows.B, &rows.C}, rows.Q);
  double previous = 1;
  for (const int order : {3, 5, 7}) {
    fictus::FarFieldReport report;
    const std::vector<Eigen::MatrixXd> S =
        fictus::green_blocks(green, {&rows.B, &rows.C}, rows.Q, fictus::Execution{2}, {order, 1.0, 2}, &report);
    const double error = std::max(relative_max_difference(S[0], exact[0]), relative_max_difference(S[1], exact[1]));
    EXPECT_GT(report.far_pairs, 0.3 * (report.far_pairs + report.near_pairs)) << "order " << order;
    EXPECT_LT(error, previous / 8) << "order " << order;
    previous = error;
  }
  EXPECT_LT(previous, 1e-4);
  // The solver's setting: a preconditioner's accuracy.
  const std::vector<Eigen::MatrixXd> S =
      fictus::green_blocks(green, {&rows.B, &rows.C}, rows.Q, fictus::Execution{2}, fictus::default_far_field_3d);
  EXPECT_LT(std::max(relative_max_difference(S[0], exact[0]), relative_max_difference(S[1], exact[1])), 2e-2);
}

TEST_P(GreenBlocksTest, CompressedBlocksAndTheirSolves) {
  // Patches of 3h at N = 40, Γ at 1.5h: a few hundred rows. The compressed blocks (the hierarchical
  // solver's partition, far pairs interpolated and recompressed) against the exact dense assembly.
  const SphereRows rows(GetParam(), 40, 3.0, 1.5);
  const fictus::GreenTable<3> green(rows.grid, GetParam().c);
  const std::vector<Eigen::MatrixXd> exact = fictus::green_blocks(green, {&rows.B, &rows.C}, rows.Q);
  const int m = rows.B.n_rows();
  const fictus::FarField far = fictus::default_far_field_3d;
  fictus::FarField storage = fictus::hierarchical_far_field;
  storage.leaf = 8;  // small leaves: far pairs at this m
  fictus::FarFieldReport report;
  const fictus::CompressedBlocks c =
      fictus::compressed_green_blocks(green, {&rows.B, &rows.C}, rows.Q, fictus::Execution{2}, far, storage, &report);
  EXPECT_GT(report.far_pairs, 0.2 * (report.far_pairs + report.near_pairs));
  EXPECT_LE(c.bytes(), 2 * 8.0 * m * m);  // never more than dense
  // The entries are those of the dense assembly with the same far field (its interpolation error, up to
  // where a coarser pair of the dense partition was interpolated whole); the recompression adds 1e-8.
  fictus::FarFieldReport dense_report;
  const std::vector<Eigen::MatrixXd> interpolated =
      fictus::green_blocks(green, {&rows.B, &rows.C}, rows.Q, fictus::Execution{2}, far, &dense_report);
  // The near blocks' entries interpolated as often as the dense assembly's (its cost, not the storage's
  // coarser partition, decides which pieces are summed exactly).
  const auto fraction = [](const fictus::FarFieldReport& r) { return r.far_pairs / (r.far_pairs + r.near_pairs); };
  EXPECT_GE(fraction(report), fraction(dense_report) - 0.02);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(m, -1.0, 2.0).array().sin();
  std::vector<Eigen::VectorXd> y;
  c.multiply(x, y, 2);
  std::array<double, 2> entry_error{};
  for (int s = 0; s < 2; ++s) {
    const Eigen::MatrixXd& S = exact[std::size_t(s)];
    const Eigen::VectorXd want = S * x;
    const double dense_error = (interpolated[std::size_t(s)] * x - want).norm();
    EXPECT_LT((y[std::size_t(s)] - want).norm(), 1.5 * dense_error + 1e-8 * want.norm()) << "set " << s;
    EXPECT_LT(dense_error, 1e-2 * want.norm()) << "set " << s;
    entry_error[std::size_t(s)] = (interpolated[std::size_t(s)] - S).cwiseAbs().maxCoeff();
  }
  // The Newton matrix's rows only: set 0 on the points above the sphere's equator, set 1 below, the same
  // numbers as the full product where wanted.
  std::vector<char> set_of_row(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i)
    set_of_row[std::size_t(i)] = rows.B.entries[rows.B.row_begin[std::size_t(i)]].k > rows.grid.nz() / 2 ? 0 : 1;
  std::vector<Eigen::VectorXd> selected;
  c.multiply(x, selected, 2, &set_of_row);
  for (int i = 0; i < m; ++i) {
    const int s = set_of_row[std::size_t(i)];
    EXPECT_NEAR(selected[std::size_t(s)](i), y[std::size_t(s)](i), 1e-13 * y[std::size_t(s)].norm()) << "row " << i;
  }
  // Diagonal blocks of the groups: every point in one group, entries as in the product.
  int covered = 0;
  for (const int g : c.groups(64)) {
    const auto& cl = c.row_clusters[std::size_t(g)];
    ASSERT_LE(cl.end - cl.begin, 64);
    covered += cl.end - cl.begin;
    for (int s = 0; s < 2; ++s) {
      const Eigen::MatrixXd M = c.diagonal_block(s, g);
      for (int a = cl.begin; a < cl.end; ++a)
        for (int b = cl.begin; b < cl.end; ++b)
          ASSERT_NEAR(M(a - cl.begin, b - cl.begin),
                      exact[std::size_t(s)](c.row_item[std::size_t(a)], c.row_item[std::size_t(b)]),
                      1.5 * entry_error[std::size_t(s)] + 1e-12);  // the interpolation's error
    }
  }
  EXPECT_EQ(covered, m);
  if (GetParam().boundary == fictus::Boundary::periodic && GetParam().c == 0) return;  // bordered: dense only

  // Newton matrices: GMRES with the block LUs, then refined on the exact S, against the exact dense LU.
  fictus::GmresOptions gmres;
  gmres.relative_tolerance = 1e-12;
  fictus::HierarchicalOptions options;
  options.far_field = far;
  options.storage = storage;
  options.group = 64;
  const fictus::HierarchicalSchur H(green, rows.B, rows.C, rows.Q, fictus::Execution{2}, {}, options, gmres);
  EXPECT_EQ(H.storage().kind, "hierarchical");
  EXPECT_NEAR(H.storage().bytes, c.bytes(), 1e-9 * c.bytes());
  fictus::ActiveSet active(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) active[std::size_t(i)] = char(i % 3 != 0);
  Eigen::MatrixXd S(m, m);
  for (int i = 0; i < m; ++i) S.row(i) = active[std::size_t(i)] ? exact[0].row(i) : exact[1].row(i);
  const Eigen::VectorXd d = Eigen::VectorXd::LinSpaced(m, 0.0, 3.0).array().cos();
  const Eigen::VectorXd want = S.partialPivLu().solve(d);
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
  double alpha = 0;
  const fictus::LinearSolveReport report_h = H.solve(active, d, nullptr, lambda, alpha);
  EXPECT_TRUE(report_h.converged);
  EXPECT_LT(report_h.relative_residual, 1e-11);
  EXPECT_LT((lambda - want).norm(), 1e-3 * want.norm());  // S̃'s answer
  EXPECT_LT(report_h.inner_iterations, 150);
  const auto fast = fictus::make_fast_solver(rows.grid, GetParam().c);
  const fictus::ImplicitSchur implicit(*fast, rows.B, rows.C, rows.Q, gmres);
  const fictus::RefinedSchur refined(H, implicit, 1e-13);
  lambda.setZero();
  const fictus::LinearSolveReport r = refined.solve(active, d, nullptr, lambda, alpha);
  EXPECT_TRUE(r.converged) << r.relative_residual;
  EXPECT_LE(r.inner_iterations, 8);  // fast solves
  EXPECT_LT((lambda - want).norm(), 1e-10 * want.norm());
  // Newton's residual at the answer reuses the last exact product; another λ makes a fast solve.
  const std::size_t solves = implicit.fast_solves();
  Eigen::VectorXd sb, sc;
  refined.apply(lambda, sb, sc);
  EXPECT_EQ(implicit.fast_solves(), solves);
  Eigen::VectorXd sb_exact, sc_exact;
  implicit.apply(lambda, sb_exact, sc_exact);
  EXPECT_LE((sb - sb_exact).norm(), 1e-14 * sb_exact.norm());
  EXPECT_LE((sc - sc_exact).norm(), 1e-14 * sc_exact.norm());
  refined.apply(2 * lambda, sb, sc);
  EXPECT_EQ(implicit.fast_solves(), solves + 2);
  // A second solve with the same set makes no new block LU; one changed row makes one.
  const int made = H.factorizations();
  EXPECT_GE(made, int(c.groups(64).size()));
  H.solve(active, d, nullptr, lambda, alpha);
  EXPECT_EQ(H.factorizations(), made);
  active[0] = 1;
  H.solve(active, d, nullptr, lambda, alpha);
  EXPECT_EQ(H.factorizations(), made + 1);
}

INSTANTIATE_TEST_SUITE_P(Boxes, GreenBlocksTest,
                         ::testing::Values(Case{fictus::Boundary::dirichlet, 1.0, 0.3},
                                           Case{fictus::Boundary::dirichlet, 100.0, 0.3},
                                           Case{fictus::Boundary::dirichlet, 1.0, 0.45},
                                           Case{fictus::Boundary::periodic, 0.0, 0.45},
                                           Case{fictus::Boundary::periodic, 1.0, 0.3}),
                         name);

std::string name(const ::testing::TestParamInfo<Case>& info) {
  const Case& k = info.param;
  return std::string(k.boundary == fictus::Boundary::periodic ? "periodic" : "dirichlet") + "_c" +
         std::to_string(int(k.c)) + "_r" + std::to_string(int(100 * k.radius));
}

TEST(GreenBlocks, InterpolationNodesAreDistinctAndInsideTheirBox) {
  // Every width and order: high orders on narrow boxes round two Chebyshev points to one node, and a
  // node pushed past the box would interpolate outside it (past a periodic box's last node, read
  // outside the Green's table).
  for (int order = 1; order <= 16; ++order)
    for (int width = 1; width <= 64; ++width) {
      const int lo = 7, hi = lo + width - 1;
      const std::vector<int> x = fictus::interpolation_nodes(lo, hi, order);
      ASSERT_EQ(int(x.size()), std::min(order, width)) << "order " << order << ", width " << width;
      EXPECT_GE(x.front(), lo) << "order " << order << ", width " << width;
      EXPECT_LE(x.back(), hi) << "order " << order << ", width " << width;
      for (std::size_t k = 1; k < x.size(); ++k) EXPECT_LT(x[k - 1], x[k]) << "order " << order << ", width " << width;
    }
  EXPECT_EQ(fictus::interpolation_nodes(0, 10, 3), (std::vector<int>{1, 5, 9}));  // Chebyshev: 5 ∓ 5·cos(π/6)
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, 16);
  const fictus::GreenTable<3> green(grid, 1.0);
  const fictus::SparseRows one = fictus::point_value_rows(grid, {fictus::Point3{0.5, 0.5, 0.5}});
  EXPECT_THROW(fictus::green_block(green, one, one, fictus::Execution{}, {6, 0.0, 2}), std::invalid_argument);
  EXPECT_THROW(fictus::green_block(green, one, one, fictus::Execution{}, {6, 2.0, 0}), std::invalid_argument);
}

TEST(GreenBlocks, RowsWithoutEntriesGiveZeros) {
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, 16);
  const fictus::GreenTable<3> green(grid, 1.0);
  fictus::SparseRows rows = fictus::point_value_rows(
      grid, {fictus::Point3{0.2, 0.2, 0.2}, fictus::Point3{0.8, 0.8, 0.8}, fictus::Point3{0.2, 0.8, 0.5}});
  rows.row_begin.push_back(rows.row_begin.back());  // a fourth row, empty
  rows.row_begin.push_back(rows.row_begin.back());  // and a fifth
  const Eigen::MatrixXd exact = fictus::green_block(green, rows, rows);
  const Eigen::MatrixXd far = fictus::green_block(green, rows, rows, fictus::Execution{}, {2, 4.0, 1});
  EXPECT_EQ(exact.bottomRows(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(far.bottomRows(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(far.rightCols(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT(relative_max_difference(far, exact), 1e-2);
}

TEST(GreenBlocks, EmptyRowsGiveEmptyBlocks) {
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, 8);
  const fictus::GreenTable<3> green(grid, 1.0);
  const fictus::SparseRows none;
  const fictus::SparseRows one = fictus::point_value_rows(grid, {fictus::Point3{0.5, 0.5, 0.5}});
  EXPECT_EQ(fictus::green_block(green, none, one, fictus::Execution{}, {6, 2.0, 2}).size(), 0);
  EXPECT_EQ(fictus::green_block(green, one, none, fictus::Execution{}, {6, 2.0, 2}).size(), 0);
}

TEST(GreenBlocks, ContactFitUpdatesTheMovedPointsOnly) {
  // The contact fit places the points again for a contact side: only the points near its ends move, and
  // the blocks updated in their rows and columns equal the blocks assembled afresh.
  const fictus::Grid2 grid(fictus::Box2{{0, 0}, {1, 1}}, 256);
  const fictus::Execution execution(2);
  fictus::SolverOptions options;
  options.variant = fictus::Variant::smooth;
  const auto gamma = std::make_shared<const fictus::Ellipse>(fictus::Point2{0.5, 0.5}, 0.35, 0.2, 0.4);
  const fictus::CurveDiscretization a(gamma, grid, options, 1.0, execution);
  fictus::PartConditions<2> parts;
  parts.contact_side = [](const fictus::Point2& x) { return x.x + 0.3 * x.y > 0.61 ? 1.0 : 0.0; };
  const std::unique_ptr<fictus::BoundaryDiscretization<2>> b = a.placed_for(parts, options, 1.0, {});
  ASSERT_EQ(b->n_points(), a.n_points());
  const int m = a.n_points();
  std::vector<int> changed;
  for (int i = 0; i < m; ++i)
    if (!fictus::same_row(a.B_gamma(), b->B_gamma(), i) || !fictus::same_row(a.C_gamma(), b->C_gamma(), i) ||
        !fictus::same_row(a.loads(), b->loads(), i))
      changed.push_back(i);
  EXPECT_GE(changed.size(), 2u);   // two ends, a border moved at each
  EXPECT_LE(changed.size(), 12u);  // and its shift fades over two arcs on either side
  const fictus::GreenTable<2> green(grid, 1.0, execution);
  const fictus::ExplicitSchur before(green, a.B_gamma(), a.C_gamma(), a.loads(), execution);
  const fictus::ExplicitSchur fresh(green, b->B_gamma(), b->C_gamma(), b->loads(), execution);
  const fictus::ExplicitSchur updated(before.S_B(), before.S_C(), changed, green, b->B_gamma(), b->C_gamma(),
                                      b->loads(), execution);
  EXPECT_LE(relative_max_difference(updated.S_B(), fresh.S_B()), 1e-15);
  EXPECT_LE(relative_max_difference(updated.S_C(), fresh.S_C()), 1e-15);
  EXPECT_GT(relative_max_difference(before.S_B(), fresh.S_B()), 1e-6);  // the points did move
}

TEST(GreenBlocks, ContactFitTakesOverTheUnmovedPointsBitForBit) {
  // A fitted placement takes the arcs placed as before (parameters, points, B_Γ rows) from the solve
  // before instead of making them again: the same numbers as a discretization made for the same parts from
  // scratch, in every row, for both variants.
  const fictus::Grid2 grid(fictus::Box2{{0, 0}, {1, 1}}, 256);
  const fictus::Execution execution(2);
  const auto gamma = std::make_shared<const fictus::Ellipse>(fictus::Point2{0.5, 0.5}, 0.35, 0.2, 0.4);
  fictus::PartConditions<2> parts;
  parts.contact_side = [](const fictus::Point2& x) { return x.x + 0.3 * x.y > 0.61 ? 1.0 : 0.0; };
  for (const fictus::Variant variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    fictus::SolverOptions options;
    options.variant = variant;
    const fictus::CurveDiscretization a(gamma, grid, options, 1.0, execution);
    const std::unique_ptr<fictus::BoundaryDiscretization<2>> placed = a.placed_for(parts, options, 1.0, {});
    const fictus::CurveDiscretization scratch(gamma, grid, options, 1.0, execution, parts);
    const int m = a.n_points();
    ASSERT_EQ(placed->n_points(), m);
    ASSERT_EQ(scratch.n_points(), m);
    int moved = 0;
    for (int i = 0; i < m; ++i) {
      EXPECT_EQ(placed->points()[std::size_t(i)].x, scratch.points()[std::size_t(i)].x) << i;
      EXPECT_EQ(placed->points()[std::size_t(i)].y, scratch.points()[std::size_t(i)].y) << i;
      EXPECT_TRUE(fictus::same_row(placed->B_gamma(), scratch.B_gamma(), i)) << i;
      EXPECT_TRUE(fictus::same_row(placed->C_gamma(), scratch.C_gamma(), i)) << i;
      EXPECT_TRUE(fictus::same_row(placed->loads(), scratch.loads(), i)) << i;
      if (!fictus::same_row(a.loads(), placed->loads(), i)) ++moved;
    }
    EXPECT_GE(moved, 2);      // the fit did move points
    EXPECT_LE(moved, m / 2);  // and took the others over
  }
}

TEST(GreenBlocks, ContactFitEndsTheArcsJustInsideTheContact) {
  // Each end of the contact side: the arc border nearest to it lies on the contact side (the side that
  // contact_side marks), a few hundredths of a spacing in (s/20 in the placement measure).
  const fictus::Grid2 grid(fictus::Box2{{0, 0}, {1, 1}}, 256);
  const fictus::Execution execution(2);
  const auto gamma = std::make_shared<const fictus::Ellipse>(fictus::Point2{0.5, 0.5}, 0.35, 0.2, 0.4);
  const fictus::ArcLengthTable table(*gamma);
  fictus::PartConditions<2> parts;
  const auto contact = [](const fictus::Point2& x) { return x.x + 0.3 * x.y > 0.61; };
  parts.contact_side = [&contact](const fictus::Point2& x) { return contact(x) ? 1.0 : 0.0; };
  std::vector<double> ends;  // where γ crosses into or out of the contact side
  constexpr int samples = 4096;
  const double two_pi = 2 * std::numbers::pi;
  for (int k = 0; k < samples; ++k) {
    double lo = two_pi * k / samples, hi = two_pi * (k + 1) / samples;
    const bool at_lo = contact(gamma->position(lo));
    if (at_lo == contact(gamma->position(hi))) continue;
    for (int it = 0; it < 60; ++it) (contact(gamma->position(0.5 * (lo + hi))) == at_lo ? lo : hi) = 0.5 * (lo + hi);
    ends.push_back(0.5 * (lo + hi));
  }
  ASSERT_EQ(ends.size(), 2u);
  for (const fictus::Variant variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    fictus::SolverOptions options;
    options.variant = variant;
    const fictus::CurveDiscretization a(gamma, grid, options, 1.0, execution);
    const std::unique_ptr<fictus::BoundaryDiscretization<2>> placed = a.placed_for(parts, options, 1.0, {});
    const auto* fitted = dynamic_cast<const fictus::CurveDiscretization*>(placed.get());
    ASSERT_NE(fitted, nullptr);
    const fictus::Collocation& c = fitted->collocation();
    const double L = table.length(), s = L / c.m;
    for (double t : ends) {
      double nearest = L, border = 0;
      for (int i = 0; i < c.m; ++i) {
        const double d = std::remainder(table.s_of_t(c.arc_end[std::size_t(i)]) - table.s_of_t(t), L);
        if (std::abs(d) < std::abs(nearest)) nearest = d, border = c.arc_end[std::size_t(i)];
      }
      EXPECT_TRUE(contact(gamma->position(border))) << fictus::to_string(variant) << ", end at t = " << t;
      EXPECT_GT(std::abs(nearest), 0.02 * s) << fictus::to_string(variant);
      EXPECT_LT(std::abs(nearest), 0.1 * s) << fictus::to_string(variant);
    }
  }
}

TEST(SparseRows, MergeTakesKeptAndMadeRowsInTurn) {
  fictus::SparseRows kept, made;
  kept.entries = {{1, 1, 0, 0, 1.0}, {2, 2, 0, 0, 2.0}, {3, 3, 0, 0, 3.0}};
  kept.row_begin = {0, 1, 3};
  made.entries = {{7, 7, 0, 0, 7.0}};
  made.row_begin = {0, 1, 1};
  const fictus::SparseRows out = fictus::merge_rows(kept, {1, -1, 0, -1}, made);
  ASSERT_EQ(out.n_rows(), 4);
  EXPECT_EQ(out.row_begin, (std::vector<std::size_t>{0, 2, 3, 4, 4}));
  EXPECT_EQ(out.entries[0].value, 2.0);
  EXPECT_EQ(out.entries[2].value, 7.0);
  EXPECT_EQ(out.entries[3].value, 1.0);
  EXPECT_THROW(fictus::merge_rows(kept, {1, -1}, made), std::logic_error);  // a made row left over
  EXPECT_THROW(fictus::merge_rows(kept, {-1, -1, -1}, made), std::logic_error);
}

}  // namespace
