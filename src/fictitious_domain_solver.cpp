#include "fictus/fictitious_domain_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "fictus/curve_grid_intersection.hpp"
#include "fictus/fast_solver.hpp"
#include "fictus/schur_complement.hpp"
#include "fictus/shapes.hpp"
#include "fictus/green_table.hpp"
#include "fictus/kink_correction.hpp"
#include "fictus/load_vector.hpp"
#include "fictus/options.hpp"
#include "fictus/trace_operators.hpp"

namespace fictus {


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

namespace {

/// R·1: the sum of each row's entries.
Eigen::VectorXd row_sums(const SparseRows& rows) {
  Eigen::VectorXd sums = Eigen::VectorXd::Zero(rows.n_rows());
  for (int r = 0; r < rows.n_rows(); ++r)
    for (std::size_t k = rows.row_begin[r]; k < rows.row_begin[r + 1]; ++k) sums(r) += rows.entries[k].value;
  return sums;
}

}  // namespace

/// Everything that depends on the curve and the options that shape the trace rows.
struct CurveSetup {
  std::shared_ptr<const Curve> gamma, Gamma;
  SolverOptions options;  // the options it was built with
  Collocation collocation;
  double delta = 0;
  std::unique_ptr<CurveGridIntersection> gamma_geometry, offset_geometry;
  SparseRows B_gamma, C_gamma, B_Gamma;
  SparseRows loads;      // rows carrying λ in the Schur complement: B_Γ, or B_Γ + R (kink correction)
  DirectTerms direct;    // D_B, D_C of the kink correction (non-smooth variant, reconstructed traces)
  std::unique_ptr<KinkCorrection> kink;
  std::unique_ptr<SchurComplement> schur;
  Eigen::VectorXd b0, c0;
  std::optional<ConstantMode> mode;

  const CurveGridIntersection& Gamma_geometry() const { return offset_geometry ? *offset_geometry : *gamma_geometry; }
  bool matches(const Problem& problem, const SolverOptions& o) const {
    const SolverOptions& s = options;
    return problem.gamma == gamma && o.variant == s.variant && o.multipliers == s.multipliers &&
           o.offset == s.offset && o.normal_derivative == s.normal_derivative && o.normal_shift == s.normal_shift &&
           o.inner == s.inner &&
           o.krylov_tolerance == s.krylov_tolerance && o.krylov_max_iterations == s.krylov_max_iterations;
  }
};

struct FictitiousDomainSolver::State {
  Problem problem;  // grid-level data only: box, N, boundary, c, f
  Grid grid;
  int threads;
  int load_quadrature;
  std::unique_ptr<FastSolver> fast;
  std::unique_ptr<GreenTable> green;
  GridVector u0;
  bool have_u0 = false;
  double load_total = 0;
  std::unique_ptr<CurveSetup> setup;
};

namespace {

/// The Signorini conditions with a normal derivative D_γ from another stencil than C_γ:
///   smooth variant (or shifted C_γ): the one-sided quadratic least-squares fit through the nodes of ω;
///   non-smooth variant, reconstructed traces: the bicubic interpolant of the kink-corrected field.
std::optional<IndependentCheck> independent_check(const CurveSetup& setup, const Solution& sol) {
  const Collocation& points = setup.collocation;
  const int m = points.m;
  IndependentCheck check;
  std::vector<double> d;
  if (setup.kink) {
    check.rule = "bicubic interpolant of the kink-corrected field";
    normal_derivative_rows_centered(sol.grid, points.point, points.normal, 3).multiply(sol.u, d);
  } else {
    check.rule = "one-sided quadratic least-squares fit through the nodes of omega";
    try {
      one_sided_rows(*setup.gamma_geometry, points.point, points.normal, OneSidedTrace::normal_derivative, 2, 2.5)
          .multiply(sol.u, d);
    } catch (const std::runtime_error&) {  // ω too thin for the fit: no check, not a failed solve
      return std::nullopt;
    }
  }
  check.min_normal_derivative = 1e300;
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    const double gap = sol.trace[i] - sol.g[i], difference = d[i] - sol.normal_derivative[i];
    check.min_normal_derivative = std::min(check.min_normal_derivative, d[i]);
    check.max_complementarity = std::max(check.max_complementarity, std::abs(gap * d[i]));
    check.max_difference = std::max(check.max_difference, std::abs(difference));
    sum += difference * difference;
  }
  check.rms_difference = std::sqrt(sum / m);
  return check;
}

}  // namespace

FictitiousDomainSolver::FictitiousDomainSolver(const Problem& problem, int threads, int load_quadrature) {
  validate_options(problem, SolverOptions{});
  if (!problem.f && !problem.f_vectorized) throw std::invalid_argument("data.f: not given");
  if (threads < 1) throw std::invalid_argument("solver.threads: must be >= 1");
  Grid grid(problem.box, problem.N, problem.boundary);
  state_ = std::make_unique<State>(State{problem, grid, threads, load_quadrature, make_fast_solver(grid, problem.c, threads),
                                         nullptr, {}, false, 0.0, nullptr});
}

FictitiousDomainSolver::~FictitiousDomainSolver() = default;

const Grid& FictitiousDomainSolver::grid() const { return state_->grid; }

Solution FictitiousDomainSolver::solve(const Problem& problem, SolverOptions options, bool compute_field) {
  options.validate();
  if (!problem.gamma) throw std::invalid_argument("geometry: no curve given");
  Eigen::setNbThreads(options.threads);  // the dense LU of the Newton steps follows the threads option
  if (!problem.g && !problem.g_along_curve && !problem.g_vectorized) throw std::invalid_argument("data.g: not given");
  State& st = *state_;
  const Grid& grid = st.grid;
  const double h = grid.h();
  Solution sol(grid);
  PhaseClock clock(sol.timings);
  std::size_t fast_solves = 0;

  // Load and u₀ = A⁻¹f (A⁺f for a singular A), once per solver.
  if (!st.have_u0) {
    st.u0 = st.problem.f_vectorized ? assemble_load(grid, st.problem.f_vectorized, st.load_quadrature, st.threads)
                                    : assemble_load(grid, st.problem.f, st.load_quadrature, st.threads);
    st.load_total = 0;
    for (double v : st.u0) {
      if (!std::isfinite(v)) throw std::invalid_argument("data.f: not finite somewhere in the box");
      st.load_total += v;
    }
    clock.mark("load");
    st.fast->solve_in_place(st.u0);
    ++fast_solves;
    st.have_u0 = true;
    clock.mark("u0");
  }

  // Curve, collocation, trace rows, Schur complement: reused while the curve and its options stay.
  if (st.setup && st.setup->matches(problem, options)) {
    options.multipliers = st.setup->collocation.m;
    sol.reused_curve = true;
  } else {
    st.setup.reset();
    auto setup = std::make_unique<CurveSetup>();
    setup->gamma = problem.gamma;
    const Curve& gamma = *problem.gamma;
    // A curve must be simple, counter-clockwise and a few cells inside the box.
    if (signed_area(gamma) <= 0)
      throw std::invalid_argument("geometry: the curve must be counter-clockwise (ω on its left)");
    check_simple(gamma, "geometry");
    check_inside_box(gamma, grid.box(), 2 * h, "geometry");
    setup->gamma_geometry = std::make_unique<CurveGridIntersection>(gamma, grid, "geometry");
    const ArcLengthTable arc_length(gamma);
    const double L = arc_length.length();
    const SolverOptions requested = options;
    const double spacing_cells =
        options.variant == Variant::smooth ? default_spacing_cells_smooth : default_spacing_cells_nonsmooth;
    if (options.multipliers == 0) options.multipliers = default_multipliers(L, h, spacing_cells);
    const int m = options.multipliers;
    const double spacing = L / m;
    if (spacing < 2 * h)
      throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(m) +
                                  " is too large for the grid (spacing L/m = " + std::to_string(spacing) +
                                  " < 2h; use m <= " + std::to_string(int(L / (2 * h))) + ")");
    if (m < 8) throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(m) + " is too small (need m >= 8)");
    setup->collocation = make_collocation(gamma, arc_length, m, phase_off_corners(gamma, arc_length, m));
    if (options.variant == Variant::smooth) {
      if (!gamma.smooth())
        throw std::invalid_argument("formulation.variant: the smooth variant needs a curve with a continuous normal "
                                    "(use \"nonsmooth\" for polygons)");
      setup->delta = options.offset * spacing;
      // The biquadratic stencil of C_γ reaches 1.5·√2·h ≈ 2.1h from x_i; its nodes must stay out of
      // the cells cut by Γ (which reach 1.4h from Γ), where the kink of û pollutes the nodal values.
      if (options.normal_derivative == NormalDerivative::reconstructed && setup->delta < 4 * h)
        throw std::invalid_argument("formulation.offset: Γ at δ = offset·L/m = " + std::to_string(setup->delta / h) +
                                    " h is within reach of the C_γ stencil (need δ >= 4h: a larger offset or a smaller m)");
      setup->Gamma = std::make_shared<OffsetCurve>(problem.gamma, setup->delta);
      check_simple(*setup->Gamma, "formulation.offset");
      check_inside_box(*setup->Gamma, grid.box(), 2 * h, "formulation.offset");
      setup->offset_geometry = std::make_unique<CurveGridIntersection>(*setup->Gamma, grid, "formulation.offset");
    } else {
      setup->Gamma = problem.gamma;
    }
    const Collocation& points = setup->collocation;
    setup->B_gamma = point_value_rows(grid, points.point);
    setup->B_Gamma = arc_integral_rows(setup->Gamma_geometry(), points.arc_begin, points.arc_end);
    if (options.normal_derivative == NormalDerivative::shifted) {
      setup->C_gamma = normal_derivative_rows(grid, points.point, points.normal, options.normal_shift * h);
      setup->loads = setup->B_Gamma;
    } else {
      setup->C_gamma = normal_derivative_rows_centered(grid, points.point, points.normal, 2);
      if (options.variant == Variant::nonsmooth) {
        setup->kink = std::make_unique<KinkCorrection>(*setup->gamma_geometry, setup->collocation, st.problem.c,
                                                       st.threads);
        setup->loads = add_rows(setup->B_Gamma, setup->kink->galerkin());
        setup->direct.trace = setup->kink->direct(setup->B_gamma);
        setup->direct.normal_derivative = setup->kink->direct(setup->C_gamma);
      } else {
        setup->loads = setup->B_Gamma;
      }
    }
    std::vector<double> b0, c0;
    setup->B_gamma.multiply(st.u0, b0);
    setup->C_gamma.multiply(st.u0, c0);
    setup->b0 = to_eigen(b0);
    setup->c0 = to_eigen(c0);
    if (st.fast->singular())
      setup->mode = ConstantMode{row_sums(setup->B_gamma), row_sums(setup->C_gamma), row_sums(setup->B_Gamma),
                                 st.load_total};
    clock.mark("geometry");

    if (options.inner == InnerSolver::green) {
      if (!st.green) {
        st.green = std::make_unique<GreenTable>(grid, st.problem.c, st.threads);
        clock.mark("green_table");
      }
      setup->schur = std::make_unique<ExplicitSchur>(*st.green, setup->B_gamma, setup->C_gamma, setup->loads, st.threads,
                                                     setup->direct);
      clock.mark("schur");
    } else {
      GmresOptions gmres_options;
      gmres_options.relative_tolerance = options.krylov_tolerance;
      gmres_options.max_iterations = options.krylov_max_iterations;
      gmres_options.restart = m + 1;
      setup->schur = std::make_unique<ImplicitSchur>(*st.fast, setup->B_gamma, setup->C_gamma, setup->loads, gmres_options,
                                                     setup->direct);
    }
    setup->options = requested;  // as asked (m = 0 stays 0), so the next request compares equal
    st.setup = std::move(setup);
  }
  const CurveSetup& setup = *st.setup;
  const int m = setup.collocation.m;
  sol.collocation = setup.collocation;
  sol.Gamma = setup.Gamma;
  sol.delta = setup.delta;

  // Obstacle at the collocation points, then semismooth Newton.
  sol.g.resize(m);
  if (problem.g_vectorized && !problem.g_along_curve) {
    std::vector<double> x(m), y(m);
    for (int i = 0; i < m; ++i) x[i] = setup.collocation.point[i].x, y[i] = setup.collocation.point[i].y;
    problem.g_vectorized(m, x.data(), y.data(), sol.g.data());
  }
  for (int i = 0; i < m; ++i) {
    const Point p = setup.collocation.point[i];
    if (problem.g_along_curve) sol.g[i] = problem.g_along_curve(p.x, p.y, setup.collocation.s[i]);
    else if (!problem.g_vectorized) sol.g[i] = problem.g(p.x, p.y);
    if (!std::isfinite(sol.g[i]))
      throw std::invalid_argument("data.g: not finite at the collocation point (" + std::to_string(p.x) + ", " +
                                  std::to_string(p.y) + ")");
  }
  NewtonOptions newton_options;
  newton_options.rho = options.rho;
  newton_options.max_iterations = options.max_newton;
  newton_options.start_all_active = options.start_all_active;
  newton_options.tolerance = options.newton_tolerance;
  const std::size_t schur_solves_before = setup.schur->fast_solves();
  sol.newton = solve_semismooth_newton(*setup.schur, setup.b0, setup.c0, to_eigen(sol.g), newton_options,
                                       setup.mode ? &*setup.mode : nullptr);
  fast_solves += setup.schur->fast_solves() - schur_solves_before;
  for (const NewtonStep& step : sol.newton.history) sol.inner_iterations += step.inner_iterations;
  if (options.condition_number) sol.condition_number = setup.schur->condition_number(sol.newton.active);
  sol.lambda.assign(sol.newton.lambda.data(), sol.newton.lambda.data() + m);
  sol.alpha = sol.newton.alpha;
  clock.mark("newton");

  if (compute_field) {
    // û = u₀ + A⁻¹B_Γᵀλ (+ α for a singular A); with the kink correction the field is
    // I_h w = u₀ + A⁻¹(B_Γ + R)ᵀλ + Σ_j λ_j ψ_j, whose traces are those of the Newton system.
    GridVector u(grid.n_unknowns(), 0.0);
    setup.loads.add_transposed(sol.lambda, u);
    st.fast->solve_in_place(u);
    ++fast_solves;
    for (std::size_t k = 0; k < u.size(); ++k) u[k] += st.u0[k] + sol.alpha;
    if (setup.kink) setup.kink->add_kinks(sol.lambda, u);
    sol.u = std::move(u);
    setup.B_gamma.multiply(sol.u, sol.trace);
    setup.C_gamma.multiply(sol.u, sol.normal_derivative);
    clock.mark("final_solve");
  } else {
    sol.trace.assign(sol.newton.trace.data(), sol.newton.trace.data() + m);
    sol.normal_derivative.assign(sol.newton.normal_derivative.data(), sol.newton.normal_derivative.data() + m);
  }
  sol.fast_solves = fast_solves;

  // Signorini conditions at the collocation points.
  sol.signorini.min_gap = 1e300;
  sol.signorini.min_normal_derivative = 1e300;
  for (int i = 0; i < m; ++i) {
    const double gap = sol.trace[i] - sol.g[i], dn = sol.normal_derivative[i];
    sol.signorini.min_gap = std::min(sol.signorini.min_gap, gap);
    sol.signorini.min_normal_derivative = std::min(sol.signorini.min_normal_derivative, dn);
    sol.signorini.max_complementarity = std::max(sol.signorini.max_complementarity, std::abs(gap * dn));
  }

  if (compute_field) {
    sol.check = independent_check(setup, sol);
    clock.mark("check");
  }

  if ((problem.exact || problem.exact_vectorized) && compute_field) {
    const VectorizedField exact = problem.exact_vectorized ? problem.exact_vectorized : vectorize(problem.exact);
    std::vector<double> x(m), y(m), values(m);
    for (int i = 0; i < m; ++i) x[i] = setup.collocation.point[i].x, y[i] = setup.collocation.point[i].y;
    exact(m, x.data(), y.data(), values.data());
    for (int i = 0; i < m; ++i)
      if (!std::isfinite(values[i]))
        throw std::invalid_argument("data.exact: not finite at (" + std::to_string(x[i]) + ", " + std::to_string(y[i]) + ")");
    // ∂u/∂n at the points: the given gradient, else a one-sided second-order difference into ω
    // (u may be defined in ω only): (3u(x) − 4u(x − εn) + u(x − 2εn))/(2ε), ε = 1e-5·box width.
    const double step = 1e-5 * (grid.box().x1 - grid.box().x0);
    std::vector<double> xs(2 * std::size_t(m)), ys(2 * std::size_t(m)), inner(2 * std::size_t(m));
    for (int i = 0; i < m; ++i)
      for (int k = 0; k < 2; ++k) {
        const Point p = setup.collocation.point[i] - (k + 1) * step * setup.collocation.normal[i];
        xs[2 * i + k] = p.x, ys[2 * i + k] = p.y;
      }
    if (!problem.exact_gradient) exact(2 * std::size_t(m), xs.data(), ys.data(), inner.data());
    PointErrors pe;
    for (int i = 0; i < m; ++i) {
      const double dudn = problem.exact_gradient
                              ? dot(setup.collocation.normal[i], problem.exact_gradient(x[i], y[i]))
                              : (3 * values[i] - 4 * inner[2 * i] + inner[2 * i + 1]) / (2 * step);
      if (!std::isfinite(dudn))
        throw std::invalid_argument("data.exact: its normal derivative is not finite near (" + std::to_string(x[i]) +
                                    ", " + std::to_string(y[i]) + ")");
      pe.max_trace = std::max(pe.max_trace, std::abs(sol.trace[i] - values[i]));
      pe.max_normal_derivative = std::max(pe.max_normal_derivative, std::abs(sol.normal_derivative[i] - dudn));
    }
    sol.point_errors = pe;
    if (problem.exact_vectorized)
      sol.errors = compute_errors(sol.u, *setup.gamma_geometry, problem.exact_vectorized, {}, options.error_quadrature, st.threads);
    else
      sol.errors = compute_errors(sol.u, *setup.gamma_geometry, problem.exact, problem.exact_gradient,
                                  options.error_quadrature, st.threads);
    clock.mark("errors");
  }
  sol.options = options;
  sol.peak_memory_bytes = peak_memory_bytes();
  return sol;
}

std::string describe_newton_failure(const Solution& s) {
  std::string line = "solver.max_newton: Newton did not converge: " + s.newton.failure + "; history (active points, residual):";
  for (const NewtonStep& step : s.newton.history) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, " (%d, %.2e)", step.n_active, step.residual);
    line += buffer;
  }
  return line;
}

Solution solve(const Problem& problem, SolverOptions options) {
  options.validate();
  FictitiousDomainSolver solver(problem, options.threads, options.load_quadrature);
  return solver.solve(problem, options);
}

}  // namespace fictus
