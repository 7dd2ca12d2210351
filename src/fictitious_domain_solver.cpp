#include "fictus/fictitious_domain_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "fictus/curve_grid_intersection.hpp"
#include "fictus/dst_solver.hpp"
#include "fictus/green_table.hpp"
#include "fictus/load_vector.hpp"
#include "fictus/trace_operators.hpp"

namespace fictus {

const char* to_string(Variant v) { return v == Variant::smooth ? "smooth" : "nonsmooth"; }
const char* to_string(InnerSolver s) { return s == InnerSolver::green ? "green" : "krylov"; }

Variant parse_variant(const std::string& text) {
  if (text == "smooth") return Variant::smooth;
  if (text == "nonsmooth" || text == "non-smooth") return Variant::nonsmooth;
  throw std::invalid_argument("formulation.variant: expected \"smooth\" or \"nonsmooth\", got \"" + text + "\"");
}

InnerSolver parse_inner_solver(const std::string& text) {
  if (text == "green") return InnerSolver::green;
  if (text == "krylov") return InnerSolver::krylov;
  throw std::invalid_argument("solver.schur: expected \"green\" or \"krylov\", got \"" + text + "\"");
}

void SolverOptions::validate() const {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw std::invalid_argument(message);
  };
  require(multipliers >= 0, "formulation.multipliers: must be >= 0 (0 = default rule)");
  require(std::isfinite(offset) && offset > 0, "formulation.offset: must be > 0");
  require(std::isfinite(rho) && rho > 0, "formulation.rho: must be > 0");
  require(std::isfinite(normal_shift) && normal_shift >= 0, "formulation.normal_shift: must be >= 0");
  require(krylov_tolerance > 0 && krylov_tolerance < 1, "solver.krylov_tolerance: must be in (0, 1)");
  require(krylov_max_iterations >= 1, "solver.krylov_max_iterations: must be >= 1");
  require(newton_tolerance > 0 && newton_tolerance < 1, "solver.newton_tolerance: must be in (0, 1)");
  require(max_newton >= 1, "solver.max_newton: must be >= 1");
  require(load_quadrature >= 1 && load_quadrature <= 8, "solver.load_quadrature: must be in 1..8");
  require(error_quadrature >= 1 && error_quadrature <= 12, "solver.error_quadrature: must be in 1..12");
  require(threads >= 1, "solver.threads: must be >= 1");
}

double Timings::operator[](const std::string& name) const {
  for (const auto& [phase, seconds] : phases)
    if (phase == name) return seconds;
  return 0.0;
}

std::size_t peak_memory_bytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::size_t(std::stoull(line.substr(6))) * 1024;
  return 0;
}

namespace {

class PhaseClock {
 public:
  explicit PhaseClock(Timings& timings) : timings_(timings), start_(now()), last_(start_) {}
  void mark(const std::string& phase) {
    const auto t = now();
    timings_.phases.emplace_back(phase, seconds(last_, t));
    timings_.total = seconds(start_, t);
    last_ = t;
  }

 private:
  using Clock = std::chrono::steady_clock;
  static Clock::time_point now() { return Clock::now(); }
  static double seconds(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  }
  Timings& timings_;
  Clock::time_point start_, last_;
};

Eigen::VectorXd to_eigen(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), Eigen::Index(v.size()));
}

}  // namespace

Solution solve(const Problem& problem, SolverOptions options) {
  options.validate();
  if (!problem.gamma) throw std::invalid_argument("geometry: no curve given");
  if (!problem.f) throw std::invalid_argument("data.f: not given");
  if (!problem.g) throw std::invalid_argument("data.g: not given");
  if (problem.N < 8) throw std::invalid_argument("domain.N: need N >= 8, got " + std::to_string(problem.N));
  if (!(problem.c >= 0) || !std::isfinite(problem.c)) throw std::invalid_argument("data.c: must be finite and >= 0");

  Solution sol(Grid(problem.box, problem.N));
  const Grid& grid = sol.grid;
  const double h = grid.h();
  PhaseClock clock(sol.timings);

  // Curves, collocation points, trace rows.
  const Curve& gamma = *problem.gamma;
  const CurveGridIntersection gamma_geometry(gamma, grid, "geometry");
  const ArcLengthTable arc_length(gamma);
  const double L = arc_length.length();
  if (options.multipliers == 0) options.multipliers = default_multipliers(L, grid.box().x1 - grid.box().x0, h);
  const int m = options.multipliers;
  const double spacing = L / m;
  if (spacing < 2 * h)
    throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(m) + " is too large for the grid (spacing L/m = " +
                                std::to_string(spacing) + " < 2h; use m <= " + std::to_string(int(L / (2 * h))) + ")");
  sol.collocation = make_collocation(gamma, arc_length, m);
  const Collocation& points = sol.collocation;

  if (options.variant == Variant::smooth) {
    sol.delta = options.offset * spacing;
    sol.Gamma = std::make_shared<OffsetCurve>(problem.gamma, sol.delta);
  } else {
    sol.delta = 0.0;
    sol.Gamma = problem.gamma;
  }
  std::optional<CurveGridIntersection> offset_geometry;
  if (options.variant == Variant::smooth) offset_geometry.emplace(*sol.Gamma, grid, "formulation.offset");
  const CurveGridIntersection& Gamma_geometry = offset_geometry ? *offset_geometry : gamma_geometry;

  const SparseRows B_gamma = point_value_rows(grid, points.point);
  const SparseRows C_gamma = normal_derivative_rows(grid, points.point, points.normal, options.normal_shift * h);
  const SparseRows B_Gamma = arc_integral_rows(Gamma_geometry, points.arc_begin, points.arc_end);
  sol.g.resize(m);
  for (int i = 0; i < m; ++i) {
    sol.g[i] = problem.g(points.point[i].x, points.point[i].y);
    if (!std::isfinite(sol.g[i]))
      throw std::invalid_argument("data.g: not finite at the collocation point (" + std::to_string(points.point[i].x) +
                                  ", " + std::to_string(points.point[i].y) + ")");
  }
  clock.mark("geometry");

  // Load and u₀ = A⁻¹ f.
  GridVector load = assemble_load(grid, problem.f, options.load_quadrature, options.threads);
  for (double v : load)
    if (!std::isfinite(v)) throw std::invalid_argument("data.f: not finite somewhere in the box");
  clock.mark("load");
  const DstSolver fast_solver(grid, problem.c, options.threads);
  GridVector u0 = load;
  fast_solver.solve_in_place(u0);
  std::vector<double> b0, c0;
  B_gamma.multiply(u0, b0);
  C_gamma.multiply(u0, c0);
  u0 = GridVector();  // only its traces are needed from here on
  clock.mark("u0");

  // Schur complement.
  std::unique_ptr<SchurComplement> schur;
  if (options.inner == InnerSolver::green) {
    const GreenTable green(grid, problem.c, options.threads);
    clock.mark("green_table");
    schur = std::make_unique<ExplicitSchur>(green, B_gamma, C_gamma, B_Gamma, options.threads);
    clock.mark("schur");
  } else {
    GmresOptions gmres_options;
    gmres_options.relative_tolerance = options.krylov_tolerance;
    gmres_options.max_iterations = options.krylov_max_iterations;
    gmres_options.restart = m;
    schur = std::make_unique<ImplicitSchur>(fast_solver, B_gamma, C_gamma, B_Gamma, gmres_options);
  }

  // Semismooth Newton.
  NewtonOptions newton_options;
  newton_options.rho = options.rho;
  newton_options.max_iterations = options.max_newton;
  newton_options.start_all_active = options.start_all_active;
  newton_options.tolerance = options.newton_tolerance;
  sol.newton = solve_semismooth_newton(*schur, to_eigen(b0), to_eigen(c0), to_eigen(sol.g), newton_options);
  for (const NewtonStep& step : sol.newton.history) sol.inner_iterations += step.inner_iterations;
  if (options.condition_number) sol.condition_number = schur->condition_number(sol.newton.active);
  clock.mark("newton");

  // û = A⁻¹ (f + B_Γᵀ λ).
  sol.lambda.assign(sol.newton.lambda.data(), sol.newton.lambda.data() + m);
  B_Gamma.add_transposed(sol.lambda, load);
  fast_solver.solve_in_place(load);
  sol.u = std::move(load);
  sol.fast_solves = 2 + schur->fast_solves();
  clock.mark("final_solve");

  // Signorini conditions at the collocation points.
  B_gamma.multiply(sol.u, sol.trace);
  C_gamma.multiply(sol.u, sol.normal_derivative);
  sol.signorini.min_gap = 1e300;
  sol.signorini.min_normal_derivative = 1e300;
  for (int i = 0; i < m; ++i) {
    const double gap = sol.trace[i] - sol.g[i], dn = sol.normal_derivative[i];
    sol.signorini.min_gap = std::min(sol.signorini.min_gap, gap);
    sol.signorini.min_normal_derivative = std::min(sol.signorini.min_normal_derivative, dn);
    sol.signorini.max_complementarity = std::max(sol.signorini.max_complementarity, std::abs(gap * dn));
  }

  if (problem.exact) {
    const GradientField gradient = problem.exact_gradient ? problem.exact_gradient
                                                          : numerical_gradient(problem.exact, grid.box().x1 - grid.box().x0);
    sol.errors = compute_errors(sol.u, gamma_geometry, problem.exact, gradient, options.error_quadrature, options.threads);
    clock.mark("errors");
  }
  sol.options = options;
  sol.peak_memory_bytes = peak_memory_bytes();
  return sol;
}

}  // namespace fictus
