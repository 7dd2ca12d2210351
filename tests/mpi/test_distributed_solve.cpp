// Whole solves on the ranks' slabs against the serial solve, run by ctest under mpirun with 1, 2 and 3
// ranks (3 divides none of the grids' layers). Every rank first solves the problem alone (the serial
// Distribution), then all solve it together (SlabDistribution), and each compares what it holds: the
// multipliers, the active set, the readings, the quantities over ω, the errors and its layers of û.
// The differences are reduced over the ranks before each check, so all ranks check the same. On one
// rank the slab path is not taken (a run on one rank is serial), so 1 rank checks that it stays so.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "fictus/io/problem_file.hpp"
#include "fictus/mpi/distribution.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"

namespace {

using fictus::mpi::Communicator;

std::string example(const std::string& name) {
  std::ifstream in(std::string(FICTUS_SOURCE_DIR) + "/examples/" + name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A problem without an exact solution: the reaction coefficient c and the box's conditions are free
/// (c = 0 on a periodic box included).
std::string plain_problem(int dim) {
  const std::string center = dim == 2 ? "[0.5, 0.5]" : "[0.5, 0.5, 0.5]";
  return std::string("[domain]\ndim = ") + std::to_string(dim) + "\n[geometry]\nshape = \"" +
         (dim == 2 ? "circle" : "sphere") + "\"\ncenter = " + center +
         "\nradius = 0.3\n[data]\nf = \"-6 * max(0, x - 0.5) + 0.5 * y\"\n"
         "g = \"max(0, x - 0.5)^3 - 0.1 * max(0, 0.5 - x)" +
         (dim == 3 ? " - 0.05 * z" : "") + "\"\n";
}

struct Case {
  std::string text;
  int N;
  fictus::Variant variant;
  fictus::Boundary boundary;
  double c = -1;  // < 0: the file's
  fictus::InnerSolver inner = fictus::InnerSolver::green;
  fictus::SchurStorageKind storage = fictus::SchurStorageKind::automatic;
};

std::string name_of(int dim, const Case& c) {
  return std::to_string(dim) + "-D N = " + std::to_string(c.N) + ", " + fictus::to_string(c.variant) + ", " +
         fictus::to_string(c.boundary) + (c.c >= 0 ? ", c = " + std::to_string(c.c).substr(0, 3) : "") +
         (c.inner == fictus::InnerSolver::krylov ? ", krylov" : "") +
         (c.storage == fictus::SchurStorageKind::hierarchical ? ", compressed Schur" : "");
}

template <class Vector>
double largest(const Vector& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

/// max |a − b| over max(|a|) (vectors replicated on every rank).
double difference(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return INFINITY;
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  const double scale = largest(a);
  return scale > 0 ? d / scale : d;
}

/// |a − b| over max(|a|, scale).
double relative(double a, double b, double scale = 0) {
  const double s = std::max(std::abs(a), scale);
  return s > 0 ? std::abs(a - b) / s : std::abs(a - b);
}

void expect_agreement(double value, double tolerance, const std::string& what, const Communicator& comm) {
  value = comm.max(value);
  if (comm.rank() == 0) std::printf("    [%d ranks] %-64s %.1e\n", comm.size(), what.c_str(), value);
  EXPECT_LE(value, tolerance) << what;
}

template <int dim>
void check(const Case& c) {
  const Communicator comm;
  fictus::BasicProblemSpec<dim> spec = fictus::parse_problem<dim>(c.text, "test");
  spec.problem.N = c.N;
  spec.problem.boundary = c.boundary;
  if (c.c >= 0) spec.problem.c = c.c;
  spec.options.variant = c.variant;
  spec.options.inner = c.inner;
  spec.options.schur_storage = c.storage;
  spec.options.threads = 1;
  spec.options.error_estimate = true;

  fictus::set_process_distribution(nullptr);  // serial: every rank alone
  const fictus::BasicSolution<dim> serial = fictus::solve(spec.problem, spec.options);
  fictus::set_process_distribution(std::make_shared<fictus::mpi::SlabDistribution>(comm));
  const fictus::BasicSolution<dim> slabs = fictus::solve(spec.problem, spec.options);
  fictus::set_process_distribution(nullptr);

  const std::string name = name_of(dim, c) + ": ";
  ASSERT_TRUE(serial.newton.converged) << name << serial.newton.failure;
  ASSERT_TRUE(slabs.newton.converged) << name << slabs.newton.failure;
  if (c.storage == fictus::SchurStorageKind::hierarchical) {  // kept compressed, the ranks' blocks the serial ones
    ASSERT_TRUE(serial.schur_storage && slabs.schur_storage) << name;
    const fictus::SchurStorage &a = *serial.schur_storage, &b = *slabs.schur_storage;
    EXPECT_EQ(b.kind, "hierarchical") << name;
    EXPECT_EQ(a.low_rank_blocks + a.full_blocks, b.low_rank_blocks + b.full_blocks) << name;
    EXPECT_NEAR(a.bytes, b.bytes, 0.02 * a.bytes) << name;
  }
  // The sums over the ranks run in another order than the serial ones, and the slab transforms are
  // FFTW-MPI's: the answers agree to round-off, amplified by the Newton matrix's condition (1e4 here).
  constexpr double tolerance = 1e-11;
  EXPECT_EQ(serial.newton.active, slabs.newton.active) << name << "active set";
  expect_agreement(difference(serial.lambda, slabs.lambda), tolerance, name + "lambda", comm);
  expect_agreement(difference(serial.trace, slabs.trace), tolerance, name + "B u at the points", comm);
  expect_agreement(difference(serial.normal_derivative, slabs.normal_derivative), tolerance, name + "C u at the points",
                   comm);
  ASSERT_EQ(serial.check.has_value(), slabs.check.has_value()) << name << "the independent check";
  if (serial.check)  // the cubic fit's weights over h amplify the field's round-off more than C_γ's: up to 1.7e-11
    expect_agreement(difference(serial.check->normal_derivative, slabs.check->normal_derivative), 10 * tolerance,
                     name + "the independent check's du/dn", comm);
  // û: this rank's layers against the same layers of the serial field.
  const fictus::Slab slab = fictus::mpi::SlabDistribution(comm).slab(serial.grid);
  const std::size_t offset = serial.grid.slab_offset(slab);
  double field = 0;
  ASSERT_EQ(slabs.u.size(), serial.grid.slab_size(slab));
  for (std::size_t k = 0; k < slabs.u.size(); ++k) field = std::max(field, std::abs(slabs.u[k] - serial.u[offset + k]));
  expect_agreement(field / largest(serial.u), tolerance, name + "u on the grid", comm);
  ASSERT_TRUE(serial.domain && slabs.domain);
  const fictus::DomainQuantities &a = *serial.domain, &b = *slabs.domain;
  double quantities = 0;
  for (const auto& [x, y] : {std::pair{a.integral_u, b.integral_u},
                             {a.integral_u2, b.integral_u2},
                             {a.integral_grad2, b.integral_grad2},
                             {a.energy, b.energy},
                             {a.volume, b.volume}})
    quantities = std::max(quantities, relative(x, y));
  // The flux c∫u − ∫f may nearly cancel: compared at the scale of its terms.
  quantities = std::max(quantities, relative(a.flux, b.flux, std::abs(a.integral_f)));
  quantities = std::max(quantities, relative(serial.contact_measure, slabs.contact_measure));
  expect_agreement(quantities, tolerance, name + "quantities over omega, contact measure", comm);
  if (serial.errors) {  // errors of û are 1e-5 of u: compared at the scale of u
    ASSERT_TRUE(slabs.errors);
    const fictus::ErrorNorms &e = *serial.errors, &f = *slabs.errors;
    double errors = 0;
    for (const auto& [x, y] : {std::pair{e.l2_omega, f.l2_omega}, {e.h1semi_omega, f.h1semi_omega}})
      errors = std::max(errors, std::abs(x - y) / e.exact_l2_omega);
    errors = std::max(errors, std::abs(e.l2_gamma - f.l2_gamma) / (e.l2_gamma / e.rel_l2_gamma));
    expect_agreement(errors, tolerance, name + "errors against the exact u (over its norm)", comm);
  }
  ASSERT_EQ(bool(serial.estimate), bool(slabs.estimate));
  if (serial.estimate && serial.estimate->skipped.empty()) {
    EXPECT_TRUE(slabs.estimate->skipped.empty()) << slabs.estimate->skipped;
    expect_agreement(std::abs(serial.estimate->l2_omega - slabs.estimate->l2_omega) / std::sqrt(a.integral_u2),
                     tolerance, name + "estimate of ||u - u_N/2|| (over the norm of u)", comm);
  }
}

TEST(DistributedSolve, TwoDimensionsAgreeWithTheSerialSolve) {
  const std::string circle = example("manufactured_circle.toml"), plain = plain_problem(2);
  using B = fictus::Boundary;
  using V = fictus::Variant;
  const auto compressed = fictus::SchurStorageKind::hierarchical;
  for (const Case& c : {Case{circle, 128, V::smooth, B::dirichlet}, Case{circle, 128, V::nonsmooth, B::dirichlet},
                        Case{circle, 128, V::smooth, B::periodic}, Case{circle, 128, V::nonsmooth, B::periodic},
                        Case{plain, 128, V::smooth, B::periodic, 0.0}, Case{plain, 128, V::nonsmooth, B::periodic, 0.0},
                        Case{circle, 128, V::smooth, B::dirichlet, -1, fictus::InnerSolver::krylov},
                        Case{circle, 128, V::nonsmooth, B::periodic, -1, fictus::InnerSolver::green, compressed}})
    check<2>(c);
}

TEST(DistributedSolve, ThreeDimensionsAgreeWithTheSerialSolve) {
  const std::string sphere = example("manufactured_sphere.toml"), plain = plain_problem(3);
  using B = fictus::Boundary;
  using V = fictus::Variant;
  const auto compressed = fictus::SchurStorageKind::hierarchical;
  for (const Case& c : {Case{sphere, 32, V::smooth, B::dirichlet}, Case{sphere, 32, V::nonsmooth, B::dirichlet},
                        Case{sphere, 32, V::nonsmooth, B::periodic}, Case{plain, 32, V::smooth, B::periodic, 0.0},
                        Case{plain, 32, V::nonsmooth, B::periodic, 0.0},
                        Case{sphere, 32, V::nonsmooth, B::dirichlet, -1, fictus::InnerSolver::krylov},
                        Case{sphere, 32, V::smooth, B::dirichlet, -1, fictus::InnerSolver::green, compressed}})
    check<3>(c);
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  const fictus::mpi::Environment environment(argc, argv);
  if (Communicator().rank() != 0) {  // one report, rank 0's
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
