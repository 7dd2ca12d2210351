#include "fictus/fictitious_domain_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <thread>

#include "fictus/curve_discretization.hpp"
#include "fictus/execution.hpp"
#include "fictus/fast_solver.hpp"
#include "fictus/green_table.hpp"
#include "fictus/load_vector.hpp"
#include "fictus/options.hpp"
#include "fictus/schur_complement.hpp"
#include "solve_steps.hpp"

namespace fictus {

using detail::PhaseClock;
using detail::row_sums;
using detail::to_eigen;

double Timings::operator[](const std::string& name) const {
  for (const auto& [phase, seconds] : phases)
    if (phase == name) return seconds;
  return 0.0;
}

namespace {

/// The options that shape steps 1–3: a change in any of them rebuilds the curve's rows and blocks.
bool same_curve_options(const SolverOptions& a, const SolverOptions& b) {
  return a.variant == b.variant && a.multipliers == b.multipliers && a.offset == b.offset &&
         a.normal_derivative == b.normal_derivative && a.normal_shift == b.normal_shift && a.inner == b.inner &&
         a.krylov_tolerance == b.krylov_tolerance && a.krylov_max_iterations == b.krylov_max_iterations;
}

using detail::largest_scale;

bool same_box(const Box2& a, const Box2& b) {
  return a.lower.x == b.lower.x && a.lower.y == b.lower.y && a.upper.x == b.upper.x && a.upper.y == b.upper.y;
}

template <class Vector>
bool all_finite(const Vector& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

template <class Vector>
double max_abs(const Vector& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

std::string format_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", v);
  return buffer;
}

std::string format_point(Point2 p) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "(%.6g, %.6g)", p.x, p.y);
  return buffer;
}

}  // namespace

/// Steps 1–3 for one curve: kept while the curve and its options stay.
struct CurveSetup {
  std::shared_ptr<const Curve> gamma;
  SolverOptions options;  // as asked (m = 0 stays 0), so the next request compares equal
  std::unique_ptr<CurveDiscretization> boundary;
  std::unique_ptr<SchurComplement> schur;
  Eigen::VectorXd b0, c0;            // B_γu₀, C_γu₀
  std::optional<ConstantMode> mode;  // singular A only
  int load_version = 0;              // the u₀ that b0, c0 and mode came from
};

struct FictitiousDomainSolver::State {
  Grid2 grid;
  double c;
  Execution execution;
  int load_quadrature;
  ScalarField f;
  VectorizedField f_vectorized;
  std::unique_ptr<FastSolver<2>> fast;
  std::unique_ptr<GreenTable<2>> green;
  GridVector u0;
  bool have_u0 = false;
  double load_total = 0;
  int load_version = 0;  // counts the loads given (replace_load)
  std::unique_ptr<CurveSetup> setup;
};

FictitiousDomainSolver::FictitiousDomainSolver(const Problem& problem, const SolverOptions& options) {
  validate_options(problem, options);
  if (!problem.f && !problem.f_vectorized) throw std::invalid_argument("data.f: not given");
  const Grid2 grid(problem.box, problem.N, problem.boundary);
  const Execution execution(options.threads);
  state_ = std::make_unique<State>(State{grid,
                                         problem.c,
                                         execution,
                                         options.load_quadrature,
                                         problem.f,
                                         problem.f_vectorized,
                                         make_fast_solver(grid, problem.c, execution),
                                         nullptr,
                                         {},
                                         false,
                                         0.0,
                                         0,
                                         nullptr});
}

FictitiousDomainSolver::~FictitiousDomainSolver() = default;

const Grid2& FictitiousDomainSolver::grid() const { return state_->grid; }

void FictitiousDomainSolver::set_interrupt_check(std::function<bool()> check) {
  state_->execution.set_interrupt_check(std::move(check));
}

void FictitiousDomainSolver::replace_load(const Problem& problem) {
  State& st = *state_;
  if (!problem.f && !problem.f_vectorized) throw std::invalid_argument("data.f: not given");
  if (problem.N != st.grid.nx() || problem.c != st.c || problem.boundary != st.grid.boundary() ||
      !same_box(problem.box, st.grid.box()))
    throw std::invalid_argument(
        "data.f: replace_load keeps the grid, c and the boundary conditions; make a new solver to change them");
  st.f = problem.f;
  st.f_vectorized = problem.f_vectorized;
  st.have_u0 = false;
  ++st.load_version;
}

void FictitiousDomainSolver::set_progress(std::function<void(const std::string&, double)> progress) {
  state_->execution.set_progress(std::move(progress));
}

namespace {

using State = FictitiousDomainSolver::State;

/// Step 0: the load vector and u₀ = A⁻¹f (A⁺f for a singular A), once per solver.
void load_and_u0(State& st, PhaseClock& clock, std::size_t& fast_solves) {
  if (st.have_u0) return;
  st.u0 = st.f_vectorized ? assemble_load(st.grid, st.f_vectorized, st.load_quadrature, st.execution)
                          : assemble_load(st.grid, st.f, st.load_quadrature, st.execution);
  st.load_total = 0;
  for (double v : st.u0) {
    if (!std::isfinite(v)) throw std::invalid_argument("data.f: not finite somewhere in the box");
    st.load_total += v;
  }
  clock.mark("load");
  st.execution.throw_if_interrupted();
  const double largest_load = max_abs(st.u0);
  st.fast->solve_in_place(st.u0);
  ++fast_solves;
  if (!all_finite(st.u0) || max_abs(st.u0) > largest_scale)
    throw std::invalid_argument("data.f: u0 = A^-1 f reaches " + format_number(max_abs(st.u0)) +
                                " (load entries up to " + format_number(largest_load) + "), beyond " +
                                format_number(largest_scale) + ": rescale the problem (u, f and g by one factor)");
  st.have_u0 = true;
  clock.mark("u0");
}

/// Step 3: the Schur blocks of the curve's rows, explicit from the Green's table or implicit.
std::unique_ptr<SchurComplement> schur_blocks(State& st, const BoundaryDiscretization& boundary,
                                              const SolverOptions& options, PhaseClock& clock) {
  if (options.inner == InnerSolver::krylov) {
    return std::make_unique<ImplicitSchur>(*st.fast, boundary.B_gamma(), boundary.C_gamma(), boundary.loads(),
                                           detail::gmres_options(options, boundary.n_points(), st.execution),
                                           boundary.direct());
  }
  if (!st.green) {
    st.green = std::make_unique<GreenTable<2>>(st.grid, st.c, st.execution);
    clock.mark("green_table");
  }
  auto schur = std::make_unique<ExplicitSchur>(*st.green, boundary.B_gamma(), boundary.C_gamma(), boundary.loads(),
                                               st.execution, boundary.direct());
  clock.mark("schur");
  return schur;
}

/// The parts of a curve's setup that come from u₀: B_γu₀, C_γu₀ and (singular A) the load's total.
void load_terms(const State& st, CurveSetup& setup) {
  const BoundaryDiscretization& boundary = *setup.boundary;
  std::vector<double> b0, c0;
  boundary.B_gamma().multiply(st.u0, b0);
  boundary.C_gamma().multiply(st.u0, c0);
  setup.b0 = to_eigen(b0);
  setup.c0 = to_eigen(c0);
  if (st.fast->singular())
    setup.mode = ConstantMode{row_sums(boundary.B_gamma()), row_sums(boundary.C_gamma()), row_sums(boundary.B_Gamma()),
                              st.load_total};
  setup.load_version = st.load_version;
}

/// Steps 1–3 for data.gamma, or the previous ones when the curve and its options are unchanged
/// (B_γu₀ and C_γu₀ come after step 0: load_terms).
CurveSetup& curve_setup(State& st, const ContactData& data, const SolverOptions& options, PhaseClock& clock,
                        bool& reused) {
  reused = st.setup && st.setup->gamma == data.gamma && same_curve_options(st.setup->options, options);
  if (reused) return *st.setup;
  st.setup.reset();
  auto setup = std::make_unique<CurveSetup>();
  setup->gamma = data.gamma;
  setup->options = options;
  setup->boundary = std::make_unique<CurveDiscretization>(data.gamma, st.grid, options, st.c, st.execution);
  setup->load_version = -1;  // B_γu₀ and C_γu₀ once u₀ is there (load_terms)
  clock.mark("geometry");
  setup->schur = schur_blocks(st, *setup->boundary, options, clock);
  st.setup = std::move(setup);
  return *st.setup;
}

/// Step 4: g at the collocation points (a batch callable, g(x, y, s) along γ, or g(x, y)).
std::vector<double> obstacle(const ContactData& data, const BoundaryDiscretization& boundary) {
  const int m = boundary.n_points();
  const std::vector<Point2>& p = boundary.points();
  std::vector<double> g(m);
  if (data.g_vectorized && !data.g_along_curve) {
    std::vector<double> x(m), y(m);
    for (int i = 0; i < m; ++i) x[i] = p[i].x, y[i] = p[i].y;
    data.g_vectorized(m, x.data(), y.data(), g.data());
  }
  for (int i = 0; i < m; ++i) {
    if (data.g_along_curve)
      g[i] = data.g_along_curve(p[i].x, p[i].y, boundary.arc_positions()[i]);
    else if (!data.g_vectorized)
      g[i] = data.g(p[i].x, p[i].y);
    if (!std::isfinite(g[i]))
      throw std::invalid_argument("data.g: not finite at the collocation point " + format_point(p[i]));
    if (std::abs(g[i]) > largest_scale)
      throw std::invalid_argument("data.g: " + format_number(g[i]) + " at " + format_point(p[i]) + " is beyond " +
                                  format_number(largest_scale) + ": rescale the problem (u, f and g by one factor)");
  }
  return g;
}

/// Step 5: semismooth Newton on λ with the Schur blocks.
void newton(const CurveSetup& setup, const SolverOptions& options, const Execution& execution, Solution& sol,
            std::size_t& fast_solves) {
  const NewtonOptions newton_options = detail::newton_options(options, execution);
  const std::size_t before = setup.schur->fast_solves();
  sol.newton = solve_semismooth_newton(*setup.schur, setup.b0, setup.c0, to_eigen(sol.g), newton_options,
                                       setup.mode ? &*setup.mode : nullptr);
  fast_solves += setup.schur->fast_solves() - before;
  for (const NewtonStep& step : sol.newton.history) sol.inner_iterations += step.inner_iterations;
  if (options.condition_number) sol.condition_number = setup.schur->condition_number(sol.newton.active);
  sol.lambda.assign(sol.newton.lambda.data(), sol.newton.lambda.data() + sol.newton.lambda.size());
  sol.lambda_total = row_sums(setup.boundary->B_Gamma()).dot(sol.newton.lambda);
  sol.alpha = sol.newton.alpha;
  if (!all_finite(sol.lambda) || !std::isfinite(sol.alpha) || max_abs(sol.lambda) > largest_scale)
    throw std::invalid_argument("data.g: the multipliers reach " + format_number(max_abs(sol.lambda)) + " (|g| up to " +
                                format_number(max_abs(sol.g)) + "), beyond " + format_number(largest_scale) +
                                ": rescale the problem (u, f and g by one factor)");
}

/// Step 6: û = u₀ + A⁻¹ loadsᵀλ + α, finished by the boundary (the kink-corrected field I_h w in the
/// non-smooth variant, whose traces are those of the Newton system); its traces at the points.
void field(const State& st, const BoundaryDiscretization& boundary, Solution& sol, std::size_t& fast_solves) {
  GridVector u(st.grid.n_unknowns(), 0.0);
  boundary.loads().add_transposed(sol.lambda, u);
  st.fast->solve_in_place(u);
  ++fast_solves;
  for (std::size_t k = 0; k < u.size(); ++k) u[k] += st.u0[k] + sol.alpha;
  boundary.finish_field(sol.lambda, u);
  if (!all_finite(u))
    throw std::invalid_argument("data: the field u is not finite: the data are too large for double precision");
  sol.u = std::move(u);
  boundary.B_gamma().multiply(sol.u, sol.trace);
  boundary.C_gamma().multiply(sol.u, sol.normal_derivative);
}

/// Step 7: the Signorini conditions at the points, and again with an independent ∂u/∂n.
void signorini_checks(const BoundaryDiscretization& boundary, Solution& sol) {
  const int m = boundary.n_points();
  sol.signorini = detail::signorini_check(sol.trace, sol.normal_derivative, sol.g);
  if (sol.u.empty()) return;
  IndependentCheck check;
  const std::optional<std::vector<double>> d = boundary.independent_normal_derivative(sol.u, check.rule);
  if (!d) return;
  check.min_normal_derivative = std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    const double gap = sol.trace[i] - sol.g[i], difference = (*d)[i] - sol.normal_derivative[i];
    check.min_normal_derivative = std::min(check.min_normal_derivative, (*d)[i]);
    check.max_complementarity = std::max(check.max_complementarity, std::abs(gap * (*d)[i]));
    check.max_difference = std::max(check.max_difference, std::abs(difference));
    sum += difference * difference;
  }
  check.rms_difference = std::sqrt(sum / m);
  check.normal_derivative = std::move(*d);
  sol.check = std::move(check);
}

/// Step 8a: the errors of the traces at the points. ∂u/∂n of the exact solution: its gradient when
/// given, else a one-sided second-order difference into ω (u may be defined in ω only):
/// (3u(x) − 4u(x − εn) + u(x − 2εn))/(2ε), ε = 1e-5·box width.
PointErrors point_errors(const ContactData& data, const BoundaryDiscretization& boundary, const Grid2& grid,
                         const Solution& sol) {
  const VectorizedField exact = data.exact_vectorized ? data.exact_vectorized : vectorize(data.exact);
  const std::vector<Point2>& p = boundary.points();
  const std::vector<Point2>& n = boundary.normals();
  const std::size_t m = p.size();
  std::vector<double> x(m), y(m), values(m);
  for (std::size_t i = 0; i < m; ++i) x[i] = p[i].x, y[i] = p[i].y;
  exact(m, x.data(), y.data(), values.data());
  const double step = 1e-5 * (grid.box().upper.x - grid.box().lower.x);
  std::vector<double> xs(2 * m), ys(2 * m), inner(2 * m);
  for (std::size_t i = 0; i < m; ++i)
    for (int k = 0; k < 2; ++k) {
      const Point2 q = p[i] - (k + 1) * step * n[i];
      xs[2 * i + k] = q.x, ys[2 * i + k] = q.y;
    }
  if (!data.exact_gradient) exact(2 * m, xs.data(), ys.data(), inner.data());
  PointErrors pe;
  for (std::size_t i = 0; i < m; ++i) {
    if (!std::isfinite(values[i])) throw std::invalid_argument("data.exact: not finite at " + format_point(p[i]));
    const double dudn = data.exact_gradient ? dot(n[i], data.exact_gradient(x[i], y[i]))
                                            : (3 * values[i] - 4 * inner[2 * i] + inner[2 * i + 1]) / (2 * step);
    if (!std::isfinite(dudn))
      throw std::invalid_argument("data.exact: its normal derivative is not finite near " + format_point(p[i]));
    pe.max_trace = std::max(pe.max_trace, std::abs(sol.trace[i] - values[i]));
    pe.max_normal_derivative = std::max(pe.max_normal_derivative, std::abs(sol.normal_derivative[i] - dudn));
  }
  return pe;
}

}  // namespace

Solution FictitiousDomainSolver::solve(const ContactData& data, SolverOptions options, bool compute_field) {
  State& st = *state_;
  options.validate();
  if (Execution(options.threads).threads() != st.execution.threads() || options.load_quadrature != st.load_quadrature)
    throw std::invalid_argument("solver.threads: threads and load_quadrature are the solver's (" +
                                std::to_string(st.execution.threads()) + ", " + std::to_string(st.load_quadrature) +
                                "); make a new FictitiousDomainSolver to change them");
  if (!data.gamma) throw std::invalid_argument("geometry: no curve given");
  if (!data.g && !data.g_along_curve && !data.g_vectorized) throw std::invalid_argument("data.g: not given");
  const bool chosen = options.variant == Variant::automatic;
  options.variant = resolved_variant(options.variant, data.gamma->smooth());
  Eigen::setNbThreads(st.execution.threads());  // the dense LU of the Newton steps follows the threads option
  Solution sol(st.grid);
  const Execution& execution = st.execution;
  PhaseClock clock(sol.timings, execution);
  std::size_t fast_solves = 0;

  // 1–3 before 0: the curve and the options that shape it are checked before any grid-sized work.
  CurveSetup& setup = curve_setup(st, data, options, clock, sol.reused_curve);  // 1–3
  execution.throw_if_interrupted();
  load_and_u0(st, clock, fast_solves);  // 0
  if (setup.load_version != st.load_version) load_terms(st, setup);
  execution.throw_if_interrupted();
  const CurveDiscretization& boundary = *setup.boundary;
  sol.collocation = boundary.collocation();
  sol.Gamma = boundary.Gamma();
  sol.delta = boundary.delta();
  sol.g = obstacle(data, boundary);                     // 4
  newton(setup, options, execution, sol, fast_solves);  // 5
  clock.mark("newton");
  execution.throw_if_interrupted();
  if (compute_field) {  // 6
    field(st, boundary, sol, fast_solves);
    clock.mark("final_solve");
    execution.throw_if_interrupted();
  } else {
    sol.trace.assign(sol.newton.trace.data(), sol.newton.trace.data() + sol.newton.trace.size());
    sol.normal_derivative.assign(sol.newton.normal_derivative.data(),
                                 sol.newton.normal_derivative.data() + sol.newton.normal_derivative.size());
  }
  sol.fast_solves = fast_solves;
  signorini_checks(boundary, sol);  // 7
  if (compute_field) clock.mark("check");
  if ((data.exact || data.exact_vectorized) && compute_field) {  // 8
    sol.point_errors = point_errors(data, boundary, st.grid, sol);
    sol.errors = boundary.errors(sol.u, data, options.error_quadrature, st.execution);
    const ErrorNorms& e = *sol.errors;
    for (double v : {e.l2_omega, e.h1semi_omega, e.l2_gamma, e.rel_l2_omega, e.rel_h1_omega, e.rel_l2_gamma})
      if (!std::isfinite(v))
        throw std::invalid_argument("data.exact: not finite somewhere in omega or on gamma (or its gradient is not)");
    clock.mark("errors");
  }
  sol.options = options;
  sol.options.threads = st.execution.threads();
  sol.options.multipliers = boundary.spacing().m;
  sol.options.offset = boundary.spacing().offset;
  if (chosen && options.variant == Variant::nonsmooth)
    sol.warnings.push_back(
        "formulation.variant: γ has corners: solved with the non-smooth variant (the smooth one needs a continuous "
        "normal)");
  if (!boundary.spacing().warning.empty()) sol.warnings.push_back(boundary.spacing().warning);
  return sol;
}

namespace {

/// Grid nodes and the m a solve will use (the default rule, with the curve's length), before any
/// array is made.
std::pair<double, double> nodes_and_multipliers(const Problem& problem, const SolverOptions& options) {
  const double h = problem.box.width(0) / problem.N;
  const double nodes = (double(problem.N) + 1) * (std::floor(problem.box.width(1) / h + 0.5) + 1);
  double m = options.multipliers;
  if (m == 0) {
    const double L = problem.gamma ? ArcLengthTable(*problem.gamma, 256).length()
                                   : 2 * (problem.box.width(0) + problem.box.width(1));
    const Variant variant = resolved_variant(options.variant, !problem.gamma || problem.gamma->smooth());
    const double cells = variant == Variant::smooth ? default_spacing_cells_smooth : default_spacing_cells_nonsmooth;
    m = std::max(double(minimum_multipliers), L / (cells * h));
  } else if (problem.gamma) {
    m = std::min(m, ArcLengthTable(*problem.gamma, 256).length() / (2 * h));  // the most a solve accepts
  }
  return {nodes, m};
}

}  // namespace

std::size_t estimated_peak_bytes(const Problem& problem, const SolverOptions& options) {
  const auto [nodes, m] = nodes_and_multipliers(problem, options);
  const double bytes = 3 * 8 * nodes + 4 * 8 * m * m + 32.0 * (1 << 20);
  return bytes > 1.8e19 ? std::size_t(1.8e19) : std::size_t(bytes);
}

double estimated_seconds(const Problem& problem, const SolverOptions& options) {
  const auto [nodes, m] = nodes_and_multipliers(problem, options);
  const double n_log_n = nodes * std::log2(std::max(nodes, 2.0));
  // Calibrated on the benchmark's 2-core machine (bench/results, and 1-thread runs at h = 1/4096):
  // the grid work (load, u₀, Green's table, final solve, errors) costs about 9e-9 s per
  // node·log2(nodes) on one thread, the Schur blocks 2.3e-6 s per pair of points, each Newton step
  // one dense LU of 1e-10·m³ s (8 steps assumed; the cap allows more); GMRES about 2.5 m
  // iterations of 2.5 fast solves of 4.6e-10 s per node·log2(nodes). Threads divide it, up to the
  // cores there are.
  const double threads = std::clamp(double(Execution(options.threads).threads()), 1.0,
                                    double(std::max(1u, std::thread::hardware_concurrency())));
  const double grid = 4.5e-9 * n_log_n, pairs = 1.15e-6 * m * m, dense = 8 * 0.5e-10 * m * m * m;
  const double seconds =
      options.inner == InnerSolver::green ? grid + pairs + dense : grid + 2.5 * m * 2.5 * 2.3e-10 * n_log_n;
  return seconds * 2 / threads;
}

ContactSummary contact_summary(const Solution& s) {
  ContactSummary c;
  const Collocation& points = s.collocation;
  c.min_gap = std::numeric_limits<double>::infinity();
  c.max_gap = -c.min_gap;
  for (int i = 0; i < points.m; ++i) {
    const double gap = s.trace[i] - s.g[i];
    c.min_gap = std::min(c.min_gap, gap);
    c.max_gap = std::max(c.max_gap, gap);
    if (s.newton.active[i] == 1) {
      ++c.points;
      c.force += s.normal_derivative[i] * points.arc[i];
      c.measure += points.arc[i];
    }
  }
  c.lambda = s.lambda_total;
  return c;
}

std::string describe_newton_failure(const Solution& s) {
  // Blame the setting at fault: a Krylov solve stopped short makes Newton wander, whatever its cap.
  std::string line =
      s.newton.inner_failed
          ? "solver.krylov_max_iterations: GMRES stopped at its cap of " +
                std::to_string(s.options.krylov_max_iterations) +
                " iterations before solver.krylov_tolerance (raise the cap, or use schur = green); then Newton: " +
                s.newton.failure + "; history (active points, residual):"
          : "solver.max_newton: Newton did not converge: " + s.newton.failure + "; history (active points, residual):";
  for (const NewtonStep& step : s.newton.history) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, " (%d, %.2e)", step.n_active, step.residual);
    line += buffer;
  }
  return line;
}

Solution solve(const Problem& problem, SolverOptions options) {
  FictitiousDomainSolver solver(problem, options);
  return solver.solve(problem, options);
}

}  // namespace fictus
