// The fast solvers on FFTW-MPI slabs against the serial ones, run by ctest under mpirun with 1, 2 and 3
// ranks (3 divides none of the grids' layers): every rank solves the whole grid serially and compares
// its own layers. The errors are reduced over the ranks before each check, so all ranks check the same.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "fictus/boundary/curve.hpp"
#include "fictus/boundary/curve_grid_intersection.hpp"
#include "fictus/boundary/omega_quadrature.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/boundary/surface_integrals.hpp"
#include "fictus/boundary/surface_kink.hpp"
#include "fictus/boundary/trace_operators.hpp"
#include "fictus/grid/green_table.hpp"
#include "fictus/grid/load_vector.hpp"
#include "fictus/mpi/distribution.hpp"
#include "fictus/mpi/next_layer.hpp"
#include "fictus/mpi/slab_solver.hpp"
#include "fictus/solve/error_norms.hpp"
#include "fictus/solve/hierarchical_schur.hpp"
#include "fictus/solve/schur_complement.hpp"
#include "fictus/solve/surface_discretization.hpp"
#include "scattered_rows.hpp"
#include "sphere_rows.hpp"

namespace {

using fictus::Boundary;
using fictus::GridVector;
using fictus::Slab;
using fictus::mpi::Communicator;

/// A fixed vector without structure: the same on every rank.
GridVector data_of(std::size_t n) {
  GridVector v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = std::sin(1.7 * double(i) + 0.3) + 0.25 * std::cos(0.11 * double(i) * double(i));
  return v;
}

/// max over this rank's layers of |local − whole|, over max |whole|, the largest over the ranks.
double relative_difference(const GridVector& local, const GridVector& whole, std::size_t offset,
                           const Communicator& comm) {
  double difference = 0, size = 0;
  for (std::size_t i = 0; i < whole.size(); ++i) size = std::max(size, std::abs(whole[i]));
  for (std::size_t i = 0; i < local.size(); ++i)
    difference = std::max(difference, std::abs(local[i] - whole[offset + i]));
  return comm.max(difference) / size;
}

/// The relative difference `value` (the same on every rank) below 1e-12, and printed by rank 0: the
/// agreement the distributed parts reach, for the record.
void expect_agreement(double value, const std::string& what, const Communicator& comm) {
  if (comm.rank() == 0) std::printf("    [%d ranks] %-48s %.1e\n", comm.size(), what.c_str(), value);
  EXPECT_LT(value, 1e-12) << what;
}

template <int dim>
void check(const fictus::Box<dim>& box, int n0, Boundary boundary, double c, int threads) {
  const Communicator comm;
  const fictus::Grid<dim> grid(box, n0, boundary);
  const fictus::Execution execution(threads);
  const fictus::mpi::SlabSolver<dim> slab_solver(grid, c, comm, execution);
  const std::unique_ptr<fictus::FastSolver<dim>> serial = fictus::make_fast_solver(grid, c, execution);

  const Slab slab = slab_solver.slab();
  double layers = slab.count;
  comm.sum(&layers, 1);
  EXPECT_EQ(int(layers), grid.layers());
  const std::size_t offset = std::size_t(slab.first) * grid.layer_size();
  EXPECT_EQ(slab_solver.local_size(), std::size_t(slab.count) * grid.layer_size());

  const GridVector r = data_of(grid.n_unknowns());
  GridVector whole = r,
             local(r.begin() + std::ptrdiff_t(offset), r.begin() + std::ptrdiff_t(offset + slab_solver.local_size()));
  serial->solve_in_place(whole);
  GridVector in_place = slab_solver.make_vector();  // transformed where it lies (Dirichlet)
  std::copy(local.begin(), local.end(), in_place.begin());
  slab_solver.solve_in_place(local);
  const std::string name = std::to_string(dim) + "-D " + fictus::to_string(boundary) +
                           ", c = " + std::to_string(c).substr(0, 3) + ", " + std::to_string(threads) + " thread(s): ";
  expect_agreement(relative_difference(local, whole, offset, comm), name + "solve", comm);
  const double* storage = in_place.data();
  slab_solver.solve_in_place(in_place);
  EXPECT_EQ(in_place.size(), local.size());
  EXPECT_EQ(in_place.data(), storage);  // no new storage
  expect_agreement(relative_difference(in_place, whole, offset, comm), name + "solve in place", comm);

  GridVector y_whole, y_local,
      x_local(r.begin() + std::ptrdiff_t(offset), r.begin() + std::ptrdiff_t(offset + slab_solver.local_size()));
  serial->apply(r, y_whole);
  slab_solver.apply(x_local, y_local);
  expect_agreement(relative_difference(y_local, y_whole, offset, comm), name + "apply", comm);
}

const fictus::Box<2> box2{{-1.0, -0.5}, {1.0, 1.25}};
const fictus::Box<3> box3{{-1.0, -0.5, 0.0}, {1.0, 1.0, 1.75}};

TEST(SlabSolver, DirichletMatchesTheSerialSolverIn2d) {
  // 40 × 35 cells: 34 layers of 39 unknowns.
  for (double c : {0.0, 2.5}) check<2>(box2, 40, Boundary::dirichlet, c, 1);
  check<2>(box2, 40, Boundary::dirichlet, 1.0, 2);
}

TEST(SlabSolver, PeriodicMatchesTheSerialSolverIn2d) {
  // 16 × 14 cells: 14 layers; c = 0 is the pseudo-inverse.
  for (double c : {0.0, 2.5}) check<2>(box2, 16, Boundary::periodic, c, 1);
  check<2>(box2, 16, Boundary::periodic, 1.0, 2);
}

TEST(SlabSolver, RanksWithoutLayersTakePart) {
  // Dirichlet 8 × 3 cells: 2 layers, so a third rank holds none; periodic 2 × 2 × 4 cells: the
  // transposed spectrum has 2 entries along its distributed axis (x: 2/2 + 1).
  const fictus::Box<2> wide{{0.0, 0.0}, {1.0, 0.375}};
  check<2>(wide, 8, Boundary::dirichlet, 1.0, 1);
  const fictus::Box<3> tall{{0.0, 0.0, 0.0}, {1.0, 1.0, 2.0}};
  check<3>(tall, 2, Boundary::periodic, 1.0, 1);
}

TEST(SlabSolver, DirichletMatchesTheSerialSolverIn3d) {
  // 16 × 12 × 14 cells: 13 layers of 15 × 11 unknowns.
  for (double c : {0.0, 2.5}) check<3>(box3, 16, Boundary::dirichlet, c, 1);
  check<3>(box3, 16, Boundary::dirichlet, 1.0, 2);
}

TEST(SlabSolver, PeriodicMatchesTheSerialSolverIn3d) {
  // 16 × 12 × 14 cells: 14 layers of 16 × 12 unknowns.
  for (double c : {0.0, 2.5}) check<3>(box3, 16, Boundary::periodic, c, 1);
  check<3>(box3, 16, Boundary::periodic, 1.0, 2);
}

/// solve_in_place_at (the Schur complement's products) against the serial full solve: a load on the
/// lines of 3 scattered rows, read by 9 others (their partial sums over the ranks' layers added), on a
/// vector transformed where it lies and on one through the workspace, twice (the second call on the
/// first's plans).
template <int dim>
void check_at(const fictus::Box<dim>& box, int n0, double c, int threads) {
  const Communicator comm;
  const fictus::Grid<dim> grid(box, n0, Boundary::dirichlet);
  const fictus::Execution execution(threads);
  const fictus::mpi::SlabSolver<dim> slab_solver(grid, c, comm, execution);
  const std::unique_ptr<fictus::FastSolver<dim>> serial = fictus::make_fast_solver(grid, c, execution);
  const fictus::SparseRows all = fictus::test_support::scattered_rows(grid, 12);
  const fictus::SparseRows loads = fictus::select_rows(all, {0, 1, 2}),
                           readings = fictus::select_rows(all, {3, 4, 5, 6, 7, 8, 9, 10, 11});
  const fictus::Footprint load = fictus::footprint(grid, {&loads}), wanted = fictus::footprint(grid, {&readings});
  GridVector whole(grid.n_unknowns(), 0.0);
  loads.add_transposed({0.7, -1.3, 0.4}, whole);
  const std::size_t offset = grid.slab_offset(slab_solver.slab()), local_size = slab_solver.local_size();
  const GridVector local(whole.begin() + std::ptrdiff_t(offset), whole.begin() + std::ptrdiff_t(offset + local_size));
  serial->solve_in_place(whole);
  std::vector<double> expected;
  readings.multiply(whole, expected);
  double size = 0;
  for (double v : expected) size = std::max(size, std::abs(v));
  ASSERT_GT(size, 0.0);
  const std::string name = std::to_string(dim) + "-D, c = " + std::to_string(c).substr(0, 3) + ", " +
                           std::to_string(threads) + " thread(s): solve at footprints";
  for (int repeat = 0; repeat < 2; ++repeat) {
    GridVector in_place = slab_solver.make_vector(), copied;
    std::copy(local.begin(), local.end(), in_place.begin());
    copied.reserve(local_size);  // no more: the solve takes it through the workspace
    copied.assign(local.begin(), local.end());
    const double* storage = in_place.data();
    for (GridVector* u : {&in_place, &copied}) {
      slab_solver.solve_in_place_at(*u, load, wanted);
      EXPECT_EQ(u->size(), local_size);
      std::vector<double> got;
      readings.multiply(*u, offset, got);
      comm.sum(got.data(), got.size());
      double difference = 0;
      for (std::size_t i = 0; i < got.size(); ++i) difference = std::max(difference, std::abs(got[i] - expected[i]));
      expect_agreement(difference / size, name + (u == &in_place ? " (in place)" : " (workspace)"), comm);
    }
    EXPECT_EQ(in_place.data(), storage);  // no new storage
  }
  // The copy went through the workspace where FFTW-MPI's local array is larger than the layers.
  if (slab_solver.local_size() < std::size_t(slab_solver.make_vector().capacity()))
    EXPECT_GT(slab_solver.workspace_bytes(), 0u);
  GridVector u = slab_solver.make_vector();
  EXPECT_THROW(slab_solver.solve_in_place_at(u, fictus::Footprint{}, wanted), std::invalid_argument);
}

TEST(SlabSolver, SolvesAtFootprintsMatchTheSerialSolver) {
  // Rows of 39, 15, 33, 199 and 7 unknowns (chunks of 16, 16 and 7; 15 alone; 16, 16 and 1; 7 alone),
  // and 34, 13, 16, 199 and 2 layers (a third rank holds none of the last two grids'); the 200 × 200
  // cells give each rank more rows and more spectral lines than a task's 64.
  for (int threads : {1, 2}) {
    check_at<2>(box2, 40, 2.5, threads);
    check_at<2>(fictus::Box<2>{{0.0, 0.0}, {1.0, 1.0}}, 200, 1.0, threads);
    check_at<3>(box3, 16, 0.0, threads);
    check_at<3>(fictus::Box<3>{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}}, 34, 1.0, threads);
  }
  check_at<2>(fictus::Box<2>{{0.0, 0.0}, {1.0, 0.375}}, 8, 1.0, 1);
  check_at<3>(fictus::Box<3>{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.375}}, 8, 1.0, 1);
}

/// The grid steps of a solve on the ranks' slabs against one process: u₀ = A⁻¹F from the load F, its
/// readings R u₀ (partial sums added over the ranks), and û = u₀ + A⁻¹Rᵀλ with its readings.
template <int dim>
void check_steps(const fictus::Box<dim>& box, int n0, Boundary boundary, double c) {
  const Communicator comm;
  const fictus::Grid<dim> grid(box, n0, boundary);
  const fictus::mpi::SlabSolver<dim> slab_solver(grid, c, comm);
  const std::unique_ptr<fictus::FastSolver<dim>> serial = fictus::make_fast_solver(grid, c);
  const Slab slab = slab_solver.slab();
  const std::size_t offset = grid.slab_offset(slab);
  const fictus::SparseRows R = fictus::test_support::scattered_rows(grid, 23);
  std::vector<double> lambda(23);
  for (std::size_t r = 0; r < lambda.size(); ++r) lambda[r] = std::cos(double(r));

  auto f3 = [](std::size_t n, const double* x, const double* y, const double* z, double* out) {
    for (std::size_t k = 0; k < n; ++k) out[k] = 1.0 + x[k] * y[k] - (z ? std::sin(3 * z[k]) : 0.0);
  };
  auto f2 = [&](std::size_t n, const double* x, const double* y, double* out) { f3(n, x, y, nullptr, out); };
  auto load = [&](std::optional<Slab> s) {
    if constexpr (dim == 2)
      return fictus::assemble_load(grid, fictus::VectorizedField(f2), 2, fictus::Execution{}, s);
    else
      return fictus::assemble_load(grid, fictus::VectorizedField3(f3), 2, fictus::Execution{}, s);
  };
  // One process.
  GridVector u0 = load(std::nullopt), u_hat;
  serial->solve_in_place(u0);
  std::vector<double> readings0, readings1;
  R.multiply(u0, readings0);
  GridVector correction(grid.n_unknowns(), 0.0);
  R.add_transposed(lambda, correction);
  serial->solve_in_place(correction);
  u_hat = u0;
  for (std::size_t i = 0; i < u_hat.size(); ++i) u_hat[i] += correction[i];
  R.multiply(u_hat, readings1);
  // The ranks.
  GridVector v0 = load(slab);
  slab_solver.solve_in_place(v0);
  std::vector<double> parts0, parts1;
  R.multiply(v0, offset, parts0);
  comm.sum(parts0.data(), parts0.size());
  GridVector v_hat(v0.size(), 0.0);
  R.add_transposed(lambda, v_hat, offset);
  slab_solver.solve_in_place(v_hat);
  for (std::size_t i = 0; i < v_hat.size(); ++i) v_hat[i] += v0[i];
  R.multiply(v_hat, offset, parts1);
  comm.sum(parts1.data(), parts1.size());

  const std::string name =
      std::to_string(dim) + "-D " + fictus::to_string(boundary) + ", c = " + std::to_string(c).substr(0, 3) + ": ";
  expect_agreement(relative_difference(v0, u0, offset, comm), name + "u0", comm);
  expect_agreement(relative_difference(v_hat, u_hat, offset, comm), name + "u-hat", comm);
  double scale = 0, difference = 0;
  for (std::size_t r = 0; r < readings0.size(); ++r) {
    scale = std::max({scale, std::abs(readings0[r]), std::abs(readings1[r])});
    difference = std::max({difference, std::abs(parts0[r] - readings0[r]), std::abs(parts1[r] - readings1[r])});
  }
  expect_agreement(difference / scale, name + "readings of u0 and u-hat", comm);
}

TEST(SlabSteps, LoadSolveAndReadingsMatchOneProcess) {
  for (double c : {0.0, 1.0}) {
    check_steps<2>(box2, 40, Boundary::dirichlet, c);
    check_steps<2>(box2, 16, Boundary::periodic, c);
    check_steps<3>(box3, 16, Boundary::dirichlet, c);
    check_steps<3>(box3, 16, Boundary::periodic, c);
  }
}

/// Σ w, Σ w·û², Σ w·|∇û|² over ω's samples, with the sampler given (whole grid or a slab).
template <int dim, class Sampler>
std::array<double, 3> omega_sums(int threads, const Sampler& for_each_sample) {
  std::vector<std::array<double, 3>> per_thread(std::size_t(threads), std::array<double, 3>{});
  for_each_sample([&](int thread, const fictus::OmegaSamples<dim>& row) {
    std::array<double, 3>& s = per_thread[std::size_t(thread)];
    for (std::size_t k = 0; k < row.size(); ++k) {
      double g2 = 0;
      for (int d = 0; d < dim; ++d) g2 += row.gradient[d][k] * row.gradient[d][k];
      s[0] += row.weight[k], s[1] += row.weight[k] * row.value[k] * row.value[k], s[2] += row.weight[k] * g2;
    }
  });
  std::array<double, 3> total{};
  for (const auto& s : per_thread)
    for (int c = 0; c < 3; ++c) total[std::size_t(c)] += s[std::size_t(c)];
  return total;
}

/// The integrals over ω of a grid field on the ranks' slabs (each with the next layer from its
/// neighbour) against one process.
template <int dim, class Sample>
void check_omega(const fictus::Grid<dim>& grid, const Sample& sample) {
  const Communicator comm;
  const Slab slab = fictus::mpi::default_slab(grid.layers(), comm.rank(), comm.size());
  GridVector u(grid.n_unknowns());
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = std::sin(0.37 * double(i)) + 0.5;
  const std::array<double, 3> whole = omega_sums<dim>(2, [&](const auto& visit) { sample(u, visit, std::nullopt); });
  const std::size_t offset = grid.slab_offset(slab);
  const GridVector local(u.begin() + std::ptrdiff_t(offset), u.begin() + std::ptrdiff_t(offset + grid.slab_size(slab)));
  const GridVector extended = fictus::mpi::with_next_layer(grid, slab, local, comm);
  std::array<double, 3> parts = omega_sums<dim>(2, [&](const auto& visit) { sample(extended, visit, slab); });
  comm.sum(parts.data(), 3);
  double difference = 0;
  for (int c = 0; c < 3; ++c)
    difference = std::max(difference, std::abs(parts[std::size_t(c)] - whole[std::size_t(c)]) / whole[std::size_t(c)]);
  expect_agreement(difference, std::to_string(dim) + "-D " + fictus::to_string(grid.boundary()) + ": sums over omega",
                   comm);
  EXPECT_GT(whole[1], 0.0);
}

TEST(SlabSteps, IntegralsOverOmegaMatchOneProcess) {
  const fictus::Execution execution(2);
  for (auto boundary : {Boundary::dirichlet, Boundary::periodic}) {
    // 70 layers (periodic) or 69; ω reaches the last cells (h = 1/32 from the top), where a periodic
    // box's last rank reads layer 0 from the first.
    const fictus::Grid<2> grid2(box2, 16 * 4, boundary);
    const fictus::Ellipse circle({0.1, 0.64}, 0.6, 0.6);
    const fictus::CurveGridIntersection curve(circle, grid2);
    check_omega<2>(grid2, [&](const GridVector& v, const fictus::OmegaSampleVisitor<2>& visit, std::optional<Slab> s) {
      fictus::for_each_omega_sample(v, curve, 3, execution, visit, s);
    });
    const fictus::Grid<3> grid3(box3, 16, boundary);
    const fictus::Ellipsoid ellipsoid({0.05, 0.2, 1.14}, {0.5, 0.4, 0.6});  // to z = 1.74 (h = 1/8)
    check_omega<3>(grid3, [&](const GridVector& v, const fictus::OmegaSampleVisitor<3>& visit, std::optional<Slab> s) {
      fictus::for_each_omega_sample(v, grid3, ellipsoid, 3, execution, visit, s);
    });
    // ∫_ω f with each rank's voxel layers: the serial total, bit for bit, on every rank.
    const fictus::VectorizedField3 f = [](std::size_t n, const double* x, const double* y, const double* z,
                                          double* out) {
      for (std::size_t p = 0; p < n; ++p) out[p] = std::exp(x[p] - 0.3 * y[p]) * std::cos(2 * z[p]);
    };
    const double whole = fictus::omega_integral(grid3, ellipsoid, f, 3, execution);
    fictus::set_process_distribution(std::make_shared<fictus::mpi::SlabDistribution>(Communicator()));
    const double parts = fictus::omega_integral(grid3, ellipsoid, f, 3, fictus::Execution(1));
    fictus::set_process_distribution(nullptr);
    EXPECT_NE(whole, 0.0);
    EXPECT_EQ(Communicator().max(parts == whole ? 0.0 : 1.0), 0.0)
        << "integral of f over omega: " << parts << " on this rank, " << whole << " serially";
  }
}

/// The Green's table on the ranks' planes: each rank's G (0 wherever the planes are another rank's),
/// summed over the ranks, against the whole table of one process, at node pairs all over the grid, by
/// the scalar and the batch lookups.
template <int dim>
void check_green_table(const fictus::Box<dim>& box, int n0, Boundary boundary, double c) {
  const Communicator comm;
  const fictus::Grid<dim> grid(box, n0, boundary);
  const fictus::GreenTable<dim> whole(grid, c, fictus::Execution(2));
  fictus::set_process_distribution(std::make_shared<fictus::mpi::SlabDistribution>(comm));
  const fictus::GreenTable<dim> part(grid, c, fictus::Execution(1));
  fictus::set_process_distribution(nullptr);
  EXPECT_EQ(part.partial(), comm.size() > 1);
  using Index = typename fictus::Grid<dim>::Index;
  std::vector<Index> a, b;
  std::vector<double> weights;
  for (int k = 0; k < 40; ++k) {
    Index p, q;
    for (int d = 0; d < dim; ++d) {
      const int lo = boundary == Boundary::dirichlet ? 1 : 0,
                span = grid.n(d) - (boundary == Boundary::dirichlet ? 1 : 0);
      p[d] = lo + (k * 7 + 3 * d) % (span - lo), q[d] = lo + (k * 13 + 5 * d + 2) % (span - lo);
    }
    a.push_back(p), b.push_back(q), weights.push_back(1.0 + 0.1 * k);
  }
  std::vector<double> scalar(a.size()), batch(a.size()), exact(a.size()), exact_batch(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) scalar[k] = part.G(a[k], b[k]), exact[k] = whole.G(a[k], b[k]);
  part.G(a.data(), a.size(), b.data(), weights.data(), b.size(), batch.data());
  whole.G(a.data(), a.size(), b.data(), weights.data(), b.size(), exact_batch.data());
  comm.sum(scalar.data(), scalar.size());
  comm.sum(batch.data(), batch.size());
  double difference = 0, size = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    difference = std::max({difference, std::abs(scalar[k] - exact[k]), std::abs(batch[k] - exact_batch[k])});
    size = std::max({size, std::abs(exact[k]), std::abs(exact_batch[k])});
  }
  const std::string name = std::to_string(dim) + "-D " + fictus::to_string(boundary) +
                           ", c = " + std::to_string(c).substr(0, 3) + ": the Green's table on planes, summed";
  expect_agreement(comm.max(difference) / size, name, comm);
}

TEST(SlabGreenTable, PartsAddUpToTheWholeTable) {
  check_green_table<2>(fictus::Box<2>{{0.0, 0.0}, {1.0, 1.0}}, 32, Boundary::dirichlet, 1.0);
  check_green_table<2>(fictus::Box<2>{{0.0, 0.0}, {1.0, 1.25}}, 32, Boundary::periodic, 0.0);
  check_green_table<3>(fictus::Box<3>{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}}, 16, Boundary::dirichlet, 1.0);
  check_green_table<3>(fictus::Box<3>{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.25}}, 16, Boundary::periodic, 1.0);
}

/// The near pairs of a distributed assembly: either each near block was one rank's (every rank fetched
/// whole planes; the shares add up to every near pair, about evenly), or, where that does not pay (on
/// 3 ranks of this small grid the planes fetched would be more than twice a rank's), every rank made its
/// part of every one. Returns whether they were shared.
bool check_near_shares(const fictus::FarFieldReport& report, const std::string& name, const Communicator& comm) {
  const bool shared = comm.max(report.whole_planes_bytes > 0 ? 1.0 : 0.0) > 0;
  EXPECT_EQ(comm.max(report.whole_planes_bytes > 0 ? 0.0 : 1.0), shared ? 0.0 : 1.0) << name << ": ranks disagree";
  double shares[2] = {report.near_pairs_here, report.near_pairs_here};
  comm.sum(shares, 1);
  shares[1] = comm.max(shares[1]);
  if (shared) {
    EXPECT_EQ(shares[0], report.near_pairs) << name;
    EXPECT_LT(shares[1], 1.3 * report.near_pairs / comm.size()) << name << ": the near pairs unevenly shared";
  } else {
    EXPECT_EQ(shares[1], report.near_pairs) << name;
    EXPECT_EQ(comm.max(report.near_pairs - report.near_pairs_here), 0.0) << name;
  }
  if (comm.rank() == 0 && comm.size() > 1)
    std::printf("    %s: near blocks %s\n", name.c_str(), shared ? "shared out" : "every rank's");
  return shared;
}

/// The compressed Schur blocks (the hierarchical solver's partition with leaves of 8: low-rank pairs at
/// this m) from the ranks' planes of the table, each far pair's core (or core times V_yᵀ) summed over
/// the ranks before its compression, each near block made by one rank, each block kept by one rank,
/// against the blocks of the whole table: the products (each
/// rank's blocks', summed) agree to round-off, and every rank gets the same bits (its Newton steps must
/// be the others').
TEST(SlabGreenTable, CompressedBlocksFromThePartsAreThoseOfTheWholeTable) {
  const Communicator comm;
  for (const auto& [boundary, c] : {std::pair{Boundary::dirichlet, 1.0}, std::pair{Boundary::periodic, 1.0}}) {
    const fictus::test_support::SphereRows rows(boundary, 0.3, 48, 2.0, 1.5);
    fictus::FarField storage = fictus::hierarchical_far_field;
    storage.leaf = 8;
    const fictus::GreenTable<3> whole(rows.grid, c, fictus::Execution(1));
    const fictus::CompressedBlocks serial = fictus::compressed_green_blocks(
        whole, {&rows.B, &rows.C}, rows.Q, fictus::Execution(2), fictus::default_far_field_3d, storage);
    const auto distribution = std::make_shared<fictus::mpi::SlabDistribution>(comm);
    fictus::set_process_distribution(distribution);
    const fictus::Execution execution(2);
    const fictus::GreenTable<3> part(rows.grid, c, execution);
    fictus::FarFieldReport report;
    const fictus::CompressedBlocks parts = fictus::compressed_green_blocks(
        part, {&rows.B, &rows.C}, rows.Q, execution, fictus::default_far_field_3d, storage, &report);
    fictus::set_process_distribution(nullptr);
    const std::string name = std::string("3-D ") + fictus::to_string(boundary) + ": compressed blocks from planes";
    const bool shared = check_near_shares(report, name, comm);
    if (comm.size() == 2) EXPECT_TRUE(shared) << name << ": the near blocks not shared on 2 ranks";
    ASSERT_EQ(parts.blocks.size(), serial.blocks.size()) << name;
    // Each block is one rank's; together the ranks hold what the serial blocks take.
    double counts[3] = {0, 0, parts.bytes()};  // held blocks, of them of low rank, bytes
    for (const fictus::CompressedBlocks::Block& b : parts.blocks)
      if (b.held) counts[0] += 1, counts[1] += b.dense.empty() ? 1 : 0;
    comm.sum(counts, 3);
    EXPECT_EQ(counts[0], double(parts.blocks.size())) << name;
    EXPECT_NEAR(counts[2], serial.bytes(), 0.02 * serial.bytes()) << name;
    if (comm.size() > 1) EXPECT_LT(parts.bytes(), 0.9 * serial.bytes()) << name;
    const int low_rank = int(counts[1]);
    if (boundary == Boundary::dirichlet)  // periodic: the images keep the far pairs dense at this m
      EXPECT_GT(low_rank, 10) << name;
    if (comm.rank() == 0)
      std::printf("    %d of %zu blocks of low rank, m = %d\n", low_rank, parts.blocks.size(), rows.B.n_rows());
    const int m = rows.B.n_rows();
    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(m, -1.0, 2.0).array().sin();
    std::vector<Eigen::VectorXd> want, got;
    serial.multiply(x, want, 2);
    parts.multiply(x, got, 2);
    double difference = 0;
    for (std::size_t s = 0; s < 2; ++s) difference = std::max(difference, (got[s] - want[s]).norm() / want[s].norm());
    expect_agreement(comm.max(difference), name + ", products", comm);
    std::vector<double> mine(got[0].data(), got[0].data() + m), first;
    mine.insert(mine.end(), got[1].data(), got[1].data() + m);
    first = mine;
    distribution->broadcast(first.data(), first.size());
    EXPECT_EQ(comm.max(mine == first ? 0.0 : 1.0), 0.0) << name << ": the ranks' products differ";
  }
}

/// The dense Schur blocks with the far field interpolated, from the ranks' planes of the table: each near
/// block made by one rank from the whole planes it fetched, each far block's part by every rank. The
/// ranks' blocks, summed, are those of the whole table to round-off, and the near pairs are shared out.
TEST(SlabGreenTable, DenseBlocksFromThePartsAreThoseOfTheWholeTable) {
  const Communicator comm;
  for (const auto& [boundary, c] : {std::pair{Boundary::dirichlet, 1.0}, std::pair{Boundary::periodic, 0.0}}) {
    const fictus::test_support::SphereRows rows(boundary, 0.3, 48, 2.0, 1.5);
    const fictus::GreenTable<3> whole(rows.grid, c, fictus::Execution(1));
    const std::vector<Eigen::MatrixXd> serial =
        fictus::green_blocks(whole, {&rows.B, &rows.C}, rows.Q, fictus::Execution(2), fictus::default_far_field_3d);
    fictus::set_process_distribution(std::make_shared<fictus::mpi::SlabDistribution>(comm));
    const fictus::Execution execution(2);
    const fictus::GreenTable<3> part(rows.grid, c, execution);
    fictus::FarFieldReport report;
    std::vector<Eigen::MatrixXd> parts =
        fictus::green_blocks(part, {&rows.B, &rows.C}, rows.Q, execution, fictus::default_far_field_3d, &report);
    fictus::set_process_distribution(nullptr);
    const std::string name = std::string("3-D ") + fictus::to_string(boundary) + ": dense blocks from planes";
    double difference = 0;
    for (std::size_t s = 0; s < 2; ++s) {
      comm.sum(parts[s].data(), std::size_t(parts[s].size()));
      difference = std::max(difference, (parts[s] - serial[s]).norm() / serial[s].norm());
    }
    expect_agreement(comm.max(difference), name, comm);
    const bool shared = check_near_shares(report, name, comm);
    if (comm.size() == 2) EXPECT_TRUE(shared) << name << ": the near blocks not shared on 2 ranks";
  }
}

/// The compressed Schur complement's Newton solves from the ranks' planes of the table: the blocks and
/// the preconditioner's groups shared out (each group's LU on one rank, the ranks' parts of each
/// preconditioned vector summed), against the solver of the whole table. The answers agree to round-off,
/// every rank gets the same bits, and the ranks together make the serial solver's LUs.
TEST(SlabGreenTable, CompressedNewtonSolvesWithTheGroupsSharedOut) {
  const Communicator comm;
  const fictus::test_support::SphereRows rows(Boundary::dirichlet, 0.3, 48, 2.0, 1.5);
  const int m = rows.B.n_rows();
  fictus::GmresOptions gmres;
  gmres.relative_tolerance = 1e-12;
  fictus::HierarchicalOptions options;
  options.far_field = fictus::default_far_field_3d;
  options.storage.leaf = 8;
  options.group = 32;
  const fictus::GreenTable<3> whole(rows.grid, 1.0, fictus::Execution(1));
  const fictus::HierarchicalSchur serial(whole, rows.B, rows.C, rows.Q, fictus::Execution(2), {}, options, gmres);
  const auto distribution = std::make_shared<fictus::mpi::SlabDistribution>(comm);
  fictus::set_process_distribution(distribution);
  const fictus::Execution execution(2);
  const fictus::GreenTable<3> part(rows.grid, 1.0, execution);
  const fictus::HierarchicalSchur parts(part, rows.B, rows.C, rows.Q, execution, {}, options, gmres);
  fictus::set_process_distribution(nullptr);
  EXPECT_NEAR(parts.storage().preconditioner_bytes, serial.storage().preconditioner_bytes, 0.5);
  if (comm.size() > 1)  // each rank holds its share of the groups only
    EXPECT_LT(parts.storage().preconditioner_bytes_here, 0.75 * serial.storage().preconditioner_bytes);
  fictus::ActiveSet active(static_cast<std::size_t>(m));
  const Eigen::VectorXd d = Eigen::VectorXd::LinSpaced(m, 0.0, 3.0).array().cos();
  for (int turn = 0; turn < 2; ++turn) {  // the second: one point's status changed
    for (int i = 0; i < m; ++i) active[std::size_t(i)] = char(i % 3 != 0);
    if (turn == 1) active[0] = 1;
    Eigen::VectorXd want = Eigen::VectorXd::Zero(m), got = Eigen::VectorXd::Zero(m);
    const fictus::LinearSolveReport a = serial.solve(active, d, want, 1e-12);
    const fictus::LinearSolveReport b = parts.solve(active, d, got, 1e-12);
    const std::string name = "compressed Newton solve " + std::to_string(turn);
    ASSERT_TRUE(a.converged && b.converged) << name;
    EXPECT_EQ(a.inner_iterations, b.inner_iterations) << name;
    expect_agreement((got - want).norm() / want.norm(), name, comm);
    std::vector<double> mine(got.data(), got.data() + m), first = mine;
    distribution->broadcast(first.data(), first.size());
    EXPECT_EQ(comm.max(mine == first ? 0.0 : 1.0), 0.0) << name << ": the ranks' answers differ";
    EXPECT_EQ(parts.factorizations(), serial.factorizations()) << name;
  }
  EXPECT_GT(serial.factorizations(), 2);
}

/// Distribution::concatenate: every rank's items (of differing counts, none on rank 1) in rank order, on
/// every rank.
TEST(SlabConcatenate, EveryRankGetsEveryRanksItemsInRankOrder) {
  const Communicator comm;
  const fictus::mpi::SlabDistribution distribution(comm);
  struct Item {
    int rank, k;
    double value;
  };
  auto items_of = [](int rank) {
    std::vector<Item> items;
    for (int k = 0; k < (rank == 1 ? 0 : 3 + 2 * rank); ++k) items.push_back({rank, k, 0.5 * k - rank});
    return items;
  };
  const std::vector<Item> all = distribution.concatenate(items_of(comm.rank()));
  std::size_t at = 0;
  for (int r = 0; r < comm.size(); ++r)
    for (const Item& want : items_of(r)) {
      ASSERT_LT(at, all.size());
      EXPECT_TRUE(all[at].rank == want.rank && all[at].k == want.k && all[at].value == want.value) << "item " << at;
      ++at;
    }
  EXPECT_EQ(at, all.size());
}

/// The non-smooth variant's kink rows with their work shared out over the ranks (the band's layers, the
/// cut voxels' test, the voxels' residuals): the serial rows, bit for bit, on every rank.
TEST(SlabKink, RanksMakeTheSerialKinkRows) {
  const Communicator comm;
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, 24);
  const fictus::Ellipsoid gamma({0.5, 0.48, 0.52}, {0.3, 0.25, 0.28});
  const fictus::PatchedSurface patches = gamma.patches(40, grid.h());
  const fictus::SurfaceKink serial(grid, gamma, patches, 1.0, fictus::Execution(2));
  fictus::set_process_distribution(std::make_shared<fictus::mpi::SlabDistribution>(comm));
  const fictus::SurfaceKink parts(grid, gamma, patches, 1.0, fictus::Execution(1));
  fictus::set_process_distribution(nullptr);
  const fictus::SparseRows &want = serial.galerkin(), &got = parts.galerkin();
  ASSERT_GT(want.entries.size(), 0u);
  EXPECT_EQ(parts.cut_voxels(), serial.cut_voxels());
  bool same = want.row_begin == got.row_begin && want.entries.size() == got.entries.size();
  for (std::size_t e = 0; same && e < want.entries.size(); ++e)
    same = want.entries[e].index == got.entries[e].index && want.entries[e].value == got.entries[e].value;
  EXPECT_EQ(comm.max(same ? 0.0 : 1.0), 0.0) << "the kink rows differ from the serial ones";
  // The band (ψ at the nodes outside ω) as the traces at the points see it.
  const fictus::SparseRows B = fictus::point_value_rows(grid, patches.point);
  const Eigen::SparseMatrix<double> difference = parts.direct(B) - serial.direct(B);
  EXPECT_GT(serial.direct(B).nonZeros(), 0);
  EXPECT_EQ(comm.max(difference.cwiseAbs().sum()), 0.0) << "the band differs from the serial one";
}

/// B_Γ's patch integrals with the patches shared out over the ranks (mapped onto γ, as in the non-smooth
/// variant): the serial weights, bit for bit, on every rank; a triangle outside the box is an error on
/// every rank, whichever rank integrates it.
TEST(SlabPatchIntegrals, RanksMakeTheSerialWeights) {
  const Communicator comm;
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, 24);
  const fictus::Ellipsoid gamma({0.5, 0.48, 0.52}, {0.3, 0.25, 0.28});
  const fictus::PatchedSurface patches = gamma.patches(40, grid.h());
  const fictus::SurfaceMap onto = fictus::onto_surface(gamma, 1e-15);
  const auto serial = fictus::patch_integrals(grid, patches.triangles, patches.patch_of, patches.m, onto, 2);
  const fictus::mpi::SlabDistribution slabs(comm);
  const auto parts = fictus::patch_integrals(grid, patches.triangles, patches.patch_of, patches.m, onto, 1, slabs);
  ASSERT_GT(serial.size(), std::size_t(patches.m));
  bool same = parts.size() == serial.size();
  for (std::size_t k = 0; same && k < serial.size(); ++k)
    same = parts[k].patch == serial[k].patch && parts[k].node == serial[k].node && parts[k].value == serial[k].value;
  EXPECT_EQ(comm.max(same ? 0.0 : 1.0), 0.0) << "the patch integrals differ from the serial ones";
  // Runs over patches without triangles (every other one, and the last three), and over fewer patches
  // than ranks (one: the other ranks' runs are empty).
  std::vector<int> spread = patches.patch_of, one(patches.patch_of.size(), 0);
  for (int& p : spread) p *= 2;
  for (const auto& [labels, count] : {std::pair{spread, 2 * patches.m + 2}, std::pair{one, 1}}) {
    const auto want = fictus::patch_integrals(grid, patches.triangles, labels, count, onto, 2);
    const auto got = fictus::patch_integrals(grid, patches.triangles, labels, count, onto, 1, slabs);
    bool equal = got.size() == want.size();
    for (std::size_t k = 0; equal && k < want.size(); ++k)
      equal = got[k].patch == want[k].patch && got[k].node == want[k].node && got[k].value == want[k].value;
    EXPECT_EQ(comm.max(equal ? 0.0 : 1.0), 0.0) << count << " patches: the weights differ from the serial ones";
  }
  // The last patch's first triangle moved out of the box: the last rank's run holds it.
  std::vector<fictus::Triangle3> broken = patches.triangles;
  const auto last = std::find(patches.patch_of.begin(), patches.patch_of.end(), patches.m - 1);
  ASSERT_NE(last, patches.patch_of.end());
  broken[std::size_t(last - patches.patch_of.begin())].a.x = 1.5;
  std::string message;
  try {
    fictus::patch_integrals(grid, broken, patches.patch_of, patches.m, onto, 1, slabs);
  } catch (const std::invalid_argument& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("leaves the box"), std::string::npos) << "rank " << comm.rank() << ": " << message;
}

/// A sphere whose level gradient vanishes near one layer of nodes (z = 13/24 on a grid of 24 cells): the
/// band's nearest points fail on the rank that makes the layer whose searches pass there only.
class BrokenNearALayer final : public fictus::Surface {
 public:
  double level(const fictus::Point3& p) const override { return e_.level(p); }
  fictus::Point3 level_gradient(const fictus::Point3& p) const override {
    return p.x > 0.75 && std::abs(p.z - 13.0 / 24) < 0.01 ? fictus::Point3{} : e_.level_gradient(p);
  }
  fictus::PatchedSurface patches(int m, double edge) const override { return e_.patches(m, edge); }
  double area() const override { return e_.area(); }
  fictus::Box3 bounds() const override { return e_.bounds(); }

 private:
  fictus::Ellipsoid e_{{0.5, 0.5, 0.5}, {0.3, 0.3, 0.3}};
};

/// A failure in one rank's share of the kink rows' work reaches every rank as an error, and none waits
/// for the others' parts (a hang here ends in ctest's timeout).
TEST(SlabKink, AFailureOnOneRankIsAnErrorOnEvery) {
  const Communicator comm;
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, 24);
  const BrokenNearALayer gamma;
  fictus::set_process_distribution(std::make_shared<fictus::mpi::SlabDistribution>(comm));
  std::string message;
  try {
    const fictus::SurfaceKink kink(grid, gamma, gamma.patches(40, grid.h()), 1.0, fictus::Execution(1));
  } catch (const std::invalid_argument& e) {
    message = e.what();
  } catch (const std::exception& e) {
    message = std::string("not the failing rank's kind of error: ") + e.what();
  }
  fictus::set_process_distribution(nullptr);
  // Every rank throws the failing rank's error, of its kind (a bad input), with its message.
  EXPECT_NE(message.find("geometry: no nearest point of the surface"), std::string::npos)
      << "rank " << comm.rank() << ": " << message;
}

/// Distribution::layers: each rank asks for its own run of layers (wrapping past the last one, or none)
/// and gets the whole vector's layers, in the asked order.
TEST(SlabLayers, EachRankGetsTheLayersItAsksFor) {
  const Communicator comm;
  const fictus::mpi::SlabDistribution distribution(comm);
  for (Boundary boundary : {Boundary::dirichlet, Boundary::periodic}) {
    const fictus::Grid<3> grid(fictus::Box<3>{{0, 0, 0}, {1, 1, 1}}, 8, boundary);
    const GridVector whole = data_of(grid.n_unknowns());
    const Slab mine = distribution.slab(grid);
    const GridVector local(whole.begin() + std::ptrdiff_t(grid.slab_offset(mine)),
                           whole.begin() + std::ptrdiff_t(grid.slab_offset(mine) + grid.slab_size(mine)));
    const int L = grid.layers();
    for (const Slab wanted :
         {Slab{(3 * comm.rank() + L - 2) % L, std::min(5, L)}, Slab{comm.rank() % L, 0}, Slab{0, L}}) {
      const GridVector got = distribution.layers(grid, local, wanted);
      ASSERT_EQ(got.size(), grid.slab_size(Slab{0, wanted.count}));
      double difference = 0;
      for (int t = 0; t < wanted.count; ++t)
        for (std::size_t k = 0; k < grid.layer_size(); ++k)
          difference =
              std::max(difference, std::abs(got[std::size_t(t) * grid.layer_size() + k] -
                                            whole[std::size_t((wanted.first + t) % L) * grid.layer_size() + k]));
      EXPECT_EQ(comm.max(difference), 0.0) << fictus::to_string(boundary) << ", layers from " << wanted.first;
    }
  }
}

/// Distribution::planes: each rank asks for planes of an array split in uneven planes over the ranks (in
/// any order, with repeats, or none) and gets them whole, in the asked order, followed by the zeros it
/// asked room for; a plane that no rank holds is an error on every rank.
TEST(SlabPlanes, EachRankGetsThePlanesItAsksFor) {
  const Communicator comm;
  const fictus::mpi::SlabDistribution distribution(comm);
  const int n_planes = 11;
  const std::size_t plane = 5;
  const Slab mine = fictus::mpi::default_slab(n_planes, comm.rank(), comm.size());
  const auto value = [&](int z, std::size_t k) { return 100.0 * z + double(k) + 0.5; };
  fictus::AlignedVector<double> local(std::size_t(mine.count) * plane);
  for (int z = mine.first; z < mine.first + mine.count; ++z)
    for (std::size_t k = 0; k < plane; ++k) local[std::size_t(z - mine.first) * plane + k] = value(z, k);
  const std::vector<std::vector<int>> wishes = {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10},
                                                {10, 3, comm.rank() % n_planes, 3, 0},
                                                {},
                                                {n_planes - 1 - comm.rank() % n_planes}};
  for (const std::vector<int>& wanted : wishes) {
    const fictus::AlignedVector<double> got = distribution.planes(local.data(), mine, plane, wanted, 3);
    ASSERT_EQ(got.size(), wanted.size() * plane + 3);
    double difference = 0;
    for (std::size_t t = 0; t < wanted.size(); ++t)
      for (std::size_t k = 0; k < plane; ++k)
        difference = std::max(difference, std::abs(got[t * plane + k] - value(wanted[t], k)));
    for (std::size_t k = 0; k < 3; ++k) difference = std::max(difference, std::abs(got[wanted.size() * plane + k]));
    EXPECT_EQ(comm.max(difference), 0.0) << wanted.size() << " planes asked for";
  }
  std::string message;
  try {
    distribution.planes(local.data(), mine, plane,
                        comm.rank() == 0 ? std::vector<int>{2, n_planes} : std::vector<int>{1});
  } catch (const std::invalid_argument& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("no rank holds"), std::string::npos) << "rank " << comm.rank() << ": " << message;
}

TEST(SlabSolver, DefaultSlabsCoverTheLayersInOrder) {
  for (int layers : {1, 2, 7, 34})
    for (int size : {1, 2, 3, 4, 8}) {
      int next = 0;
      for (int rank = 0; rank < size; ++rank) {
        const Slab s = fictus::mpi::default_slab(layers, rank, size);
        EXPECT_EQ(s.first, next);
        EXPECT_GE(s.count, 0);
        next += s.count;
      }
      EXPECT_EQ(next, layers);
    }
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  const fictus::mpi::Environment environment(argc, argv);
  const int rank = Communicator().rank();
  if (rank != 0) {  // one report, rank 0's: the errors are reduced over the ranks before every check
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
