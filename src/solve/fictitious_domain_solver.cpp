#include "fictus/solve/fictitious_domain_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include "fictus/grid/distribution.hpp"
#include "fictus/grid/execution.hpp"
#include "fictus/grid/fast_solver.hpp"
#include "fictus/grid/green_table.hpp"
#include "fictus/grid/load_vector.hpp"
#include "fictus/solve/boundary_discretization.hpp"
#include "fictus/solve/curve_discretization.hpp"
#include "fictus/solve/hierarchical_schur.hpp"
#include "fictus/solve/options.hpp"
#include "fictus/solve/schur_complement.hpp"
#include "fictus/solve/surface_discretization.hpp"
#include "solve_steps.hpp"

namespace fictus {

using detail::PhaseClock;
using detail::row_sums;
using detail::to_eigen;

namespace {

using detail::largest_scale;

/// The options that shape the boundary's rows and Schur blocks: a change in any of them rebuilds them.
bool same_boundary_options(const SolverOptions& a, const SolverOptions& b) {
  return a.variant == b.variant && a.multipliers == b.multipliers && a.offset == b.offset &&
         a.normal_derivative == b.normal_derivative && a.normal_shift == b.normal_shift && a.inner == b.inner &&
         a.krylov_tolerance == b.krylov_tolerance && a.krylov_max_iterations == b.krylov_max_iterations &&
         a.flux_balance == b.flux_balance && a.far_field == b.far_field && a.schur_storage == b.schur_storage;
}

template <int dim>
bool same_box(const Box<dim>& a, const Box<dim>& b) {
  for (int d = 0; d < dim; ++d)
    if (a.lower[d] != b.lower[d] || a.upper[d] != b.upper[d]) return false;
  return true;
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

/// Does γ have a continuous normal (the smooth variant's Γ needs one)? Every surface does.
bool smooth_boundary(const Curve& gamma) { return gamma.smooth(); }
bool smooth_boundary(const Surface&) { return true; }

}  // namespace

/// Steps 1–3 for one boundary: kept while the boundary and its options stay.
template <int dim>
struct BoundarySetup {
  std::shared_ptr<const typename BoundaryShape<dim>::type> gamma;
  SolverOptions options;  // as asked (m = 0 stays 0), so the next request compares equal
  std::unique_ptr<BoundaryDiscretization<dim>> boundary;
  std::unique_ptr<SchurComplement> schur;
  std::unique_ptr<ImplicitSchur> exact;  // the exact S behind an interpolated far field
  std::optional<FarFieldReport> far_field;
  std::optional<SchurStorage> storage;  // green
  std::string storage_warning;          // why hierarchical storage was asked for and not used
  std::size_t fast_solves = 0;          // made by the setup (2b), counted in the solve that made it
  Eigen::VectorXd b0, c0;               // B_γu₀, C_γu₀ (+ the reading shift)
  double shift = 0;                     // what the data's readings moved by (the flux balance)
  std::optional<ConstantMode> mode;     // singular A only
  int load_version = -1;                // the u₀ that b0, c0, shift and mode came from
};

template <int dim>
struct FictitiousDomainSolver<dim>::State {
  Grid<dim> grid;
  double c;
  Execution execution;
  int load_quadrature;
  typename Fields<dim>::Scalar f;
  typename Fields<dim>::Vectorized f_vectorized;
  std::unique_ptr<FastSolver<dim>> fast;
  std::unique_ptr<GreenTable<dim>> green;
  GridVector u0;
  bool have_u0 = false;
  double load_total = 0;
  int load_version = 0;  // counts the loads given (replace_load)
  std::unique_ptr<BoundarySetup<dim>> setup;
};

template <int dim>
FictitiousDomainSolver<dim>::FictitiousDomainSolver(const BasicProblem<dim>& problem, const SolverOptions& options) {
  validate_options(problem, options);
  if (!problem.f && !problem.f_vectorized) throw std::invalid_argument("data.f: not given");
  if (!(problem.c >= 0) || !std::isfinite(problem.c)) throw std::invalid_argument("data.c: must be finite and >= 0");
  const Grid<dim> grid(problem.box, problem.N, problem.boundary);
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

template <int dim>
FictitiousDomainSolver<dim>::~FictitiousDomainSolver() = default;

template <int dim>
const Grid<dim>& FictitiousDomainSolver<dim>::grid() const {
  return state_->grid;
}

template <int dim>
void FictitiousDomainSolver<dim>::set_interrupt_check(std::function<bool()> check) {
  state_->execution.set_interrupt_check(std::move(check));
}

template <int dim>
void FictitiousDomainSolver<dim>::replace_load(const BasicProblem<dim>& problem) {
  State& st = *state_;
  if (!problem.f && !problem.f_vectorized) throw std::invalid_argument("data.f: not given");
  if (problem.N != st.grid.nx() || problem.c != st.c || problem.boundary != st.grid.boundary() ||
      !same_box<dim>(problem.box, st.grid.box()))
    throw std::invalid_argument(
        "data.f: replace_load keeps the grid, c and the boundary conditions; make a new solver to change them");
  st.f = problem.f;
  st.f_vectorized = problem.f_vectorized;
  st.have_u0 = false;
  ++st.load_version;
}

template <int dim>
void FictitiousDomainSolver<dim>::set_progress(std::function<void(const std::string&, double)> progress) {
  state_->execution.set_progress(std::move(progress));
}

namespace {

template <int dim>
using State = typename FictitiousDomainSolver<dim>::State;

/// Checks the per-solve options against the solver's and resolves the variant (`chosen`: it was automatic).
template <int dim>
SolverOptions solve_options(const State<dim>& st, const BasicContactData<dim>& data, SolverOptions options,
                            bool& chosen) {
  options.validate();
  check_options_apply(dim, options);  // an option of the other dimension is refused, never ignored
  if (Execution(options.threads).threads() != st.execution.threads() || options.load_quadrature != st.load_quadrature)
    throw std::invalid_argument("solver.threads: threads and load_quadrature are the solver's (" +
                                std::to_string(st.execution.threads()) + ", " + std::to_string(st.load_quadrature) +
                                "); make a new FictitiousDomainSolver to change them");
  if (!data.gamma) throw std::invalid_argument(dim == 2 ? "geometry: no curve given" : "geometry: no surface given");
  bool has_g = data.g || data.g_vectorized;
  if constexpr (dim == 2) has_g = has_g || data.g_along_curve;
  if (!has_g) throw std::invalid_argument("data.g: not given");
  chosen = options.variant == Variant::automatic;
  options.variant = resolved_variant(options.variant, smooth_boundary(*data.gamma));
  // Measured (docs/math.md, "Fitting the points to the contact set"): two passes make the 2-D smooth
  // variant's errors second order where the ends fall anywhere between the points; on surfaces and in the
  // non-smooth variant they were no better.
  if (options.fit_contact < 0) options.fit_contact = dim == 2 && options.variant == Variant::smooth ? 2 : 0;
  options.threads = st.execution.threads();
  return options;
}

template <int dim>
std::unique_ptr<BoundarySetup<dim>> new_boundary_setup(const State<dim>& st, const BasicContactData<dim>& data,
                                                       const SolverOptions& options, PhaseClock& clock);

/// Steps 1–2 for data.gamma, or the previous ones when the boundary and its options are unchanged.
template <int dim>
BoundarySetup<dim>& boundary_setup(State<dim>& st, const BasicContactData<dim>& data, const SolverOptions& options,
                                   PhaseClock& clock, bool& reused) {
  reused = st.setup && st.setup->schur && st.setup->gamma == data.gamma &&
           same_boundary_options(st.setup->options, options) && st.setup->boundary->same_parts(data.conditions);
  if (reused) return *st.setup;
  st.setup.reset();
  st.setup = new_boundary_setup<dim>(st, data, options, clock);
  return *st.setup;
}

/// Steps 1–2 for data.gamma, made afresh (and not kept by the solver).
template <int dim>
std::unique_ptr<BoundarySetup<dim>> new_boundary_setup(const State<dim>& st, const BasicContactData<dim>& data,
                                                       const SolverOptions& options, PhaseClock& clock) {
  auto setup = std::make_unique<BoundarySetup<dim>>();
  setup->gamma = data.gamma;
  setup->options = options;
  const MarkPhase mark = [&clock](const std::string& phase) { clock.mark(phase); };
  if constexpr (dim == 2) {
    setup->boundary =
        std::make_unique<CurveDiscretization>(data.gamma, st.grid, options, st.c, st.execution, data.conditions);
    clock.mark("geometry");
  } else {
    setup->boundary = std::make_unique<SurfaceDiscretization>(data.gamma, st.grid, options, st.c, st.execution, mark,
                                                              data.conditions);
  }
  return setup;
}

/// Steps 1–2 for the points placed for data.conditions, on the shape of `base` (the contact fit: made for
/// this solve only).
template <int dim>
std::unique_ptr<BoundarySetup<dim>> placed_setup(const BoundarySetup<dim>& base, const BasicContactData<dim>& data,
                                                 const SolverOptions& options, double c, PhaseClock& clock) {
  auto setup = std::make_unique<BoundarySetup<dim>>();
  setup->gamma = data.gamma;
  setup->options = options;
  const MarkPhase mark = [&clock](const std::string& phase) { clock.mark(phase); };
  setup->boundary = base.boundary->placed_for(data.conditions, options, c, mark);
  if constexpr (dim == 2) clock.mark("geometry");
  return setup;
}

/// Step 0: the load vector and u₀ = A⁻¹f (A⁺f for a singular A), once per load.
template <int dim>
void load_and_u0(State<dim>& st, PhaseClock& clock, std::size_t& fast_solves) {
  if (st.have_u0) return;
  const Distribution& distribution = st.execution.distribution();
  if (!distribution.distributed()) {
    st.u0 = st.f_vectorized ? assemble_load(st.grid, st.f_vectorized, st.load_quadrature, st.execution)
                            : assemble_load(st.grid, st.f, st.load_quadrature, st.execution);
  } else {  // this rank's layers, into the vector the slab solver transforms in place
    const GridVector load = assemble_load(st.grid, st.f_vectorized ? st.f_vectorized : vectorize(st.f),
                                          st.load_quadrature, st.execution, st.fast->slab());
    st.u0 = st.fast->make_vector();
    std::copy(load.begin(), load.end(), st.u0.begin());
  }
  st.load_total = 0;
  bool finite = true;
  for (double v : st.u0) finite = finite && std::isfinite(v), st.load_total += v;
  if (!distribution.all(finite)) throw std::invalid_argument("data.f: not finite somewhere in the box");
  st.load_total = distribution.sum(st.load_total);
  clock.mark("load");
  st.execution.throw_if_interrupted();
  const double largest_load = distribution.max(max_abs(st.u0));
  st.fast->solve_in_place(st.u0);
  ++fast_solves;
  const double largest_u0 = distribution.max(max_abs(st.u0));
  if (!distribution.all(all_finite(st.u0)) || largest_u0 > largest_scale)
    throw std::invalid_argument("data.f: u0 = A^-1 f reaches " + format_number(largest_u0) + " (load entries up to " +
                                format_number(largest_load) + "), beyond " + format_number(largest_scale) +
                                ": rescale the problem (u, f and g by one factor)");
  st.have_u0 = true;
  clock.mark("u0");
}

/// The points whose rows (B_γ, C_γ, loads) differ between two boundaries with as many points, when the
/// blocks of `before` can be updated for them: dense blocks with exact entries and no direct terms, and
/// at most half the points changed; else nullopt.
template <int dim>
std::optional<std::vector<int>> changed_points(const BoundarySetup<dim>* before, const BoundaryDiscretization<dim>& b,
                                               const SolverOptions& options) {
  if (!before || !before->schur || before->exact || !dynamic_cast<const ExplicitSchur*>(before->schur.get()) ||
      options.inner != InnerSolver::green || b.far_field(options).order != 0 || !b.direct().empty())
    return std::nullopt;
  const BoundaryDiscretization<dim>& a = *before->boundary;
  const int m = b.n_points();
  if (a.n_points() != m || !a.direct().empty()) return std::nullopt;
  std::vector<int> changed;
  for (int i = 0; i < m; ++i)
    if (!same_row(a.B_gamma(), b.B_gamma(), i) || !same_row(a.C_gamma(), b.C_gamma(), i) ||
        !same_row(a.loads(), b.loads(), i))
      changed.push_back(i);
  if (2 * changed.size() > std::size_t(m)) return std::nullopt;
  return changed;
}

/// Steps 2b–3: the boundary's grid-level setup and the Schur blocks, explicit from the Green's table
/// (its far field interpolated where the boundary allows it) or implicit. With `keep` false the
/// Green's table is freed once the blocks are made. With `before` (the contact fit's previous solve),
/// dense blocks are those of `before` with the entries of the moved points made again; `before`'s blocks
/// are freed (or moved into the new ones) first unless `keep_before`.
template <int dim>
void schur_blocks(State<dim>& st, BoundarySetup<dim>& setup, const SolverOptions& options, PhaseClock& clock, bool keep,
                  BoundarySetup<dim>* before = nullptr, bool keep_before = true) {
  if (setup.schur) return;
  BoundaryDiscretization<dim>& b = *setup.boundary;
  const MarkPhase mark = [&clock](const std::string& phase) { clock.mark(phase); };
  setup.fast_solves += b.finish_setup(*st.fast, mark);
  const std::optional<std::vector<int>> changed = changed_points<dim>(before, b, options);
  Eigen::MatrixXd before_B, before_C;  // the blocks to update
  if (changed) {
    auto& blocks = static_cast<ExplicitSchur&>(*before->schur);
    if (keep_before)
      before_B = blocks.S_B(), before_C = blocks.S_C();
    else
      blocks.release(before_B, before_C);
  }
  if (before && !keep_before) before->schur.reset(), before->exact.reset();  // (with its LU)
  const GmresOptions gmres = detail::gmres_options(options, b.n_points(), st.execution);
  const Distribution& distribution = st.execution.distribution();
  if (options.inner == InnerSolver::krylov) {
    setup.schur = std::make_unique<ImplicitSchur>(*st.fast, b.B_gamma(), b.C_gamma(), b.loads(), gmres, b.direct(),
                                                  &distribution);
    return;
  }
  if (!st.green) {
    st.green = std::make_unique<GreenTable<dim>>(st.grid, st.c, st.execution);
    clock.mark("green_table");
  }
  const int m = b.n_points();
  // Distributed, each rank makes its part of every entry from its planes of the table and the parts are
  // summed: the dense blocks' (every rank then takes rank 0's), or the compressed blocks' near entries
  // and far cores before each block's one owner compresses it (green_blocks.cpp). Newton then runs the
  // same on every rank.
  const bool hierarchical = compressed_schur(options.schur_storage, dim, m, st.fast->singular());
  if (options.schur_storage == SchurStorageKind::hierarchical && !hierarchical)
    setup.storage_warning =
        "solver.schur_storage: a periodic box with c = 0 (A singular) keeps the Schur complement dense";
  if (hierarchical) {
    GmresOptions inner = gmres;
    inner.relative_tolerance = hierarchical_gmres_tolerance;
    SolverOptions interpolated = options;  // the far field is what makes the blocks small
    interpolated.far_field = true;
    HierarchicalOptions h_options;
    h_options.far_field = b.far_field(interpolated);
    if (h_options.far_field.order == 0) h_options.far_field = default_far_field_3d;  // 2-D: the same rule
    auto h = std::make_unique<HierarchicalSchur>(*st.green, b.B_gamma(), b.C_gamma(), b.loads(), st.execution,
                                                 b.direct(), h_options, inner);
    setup.storage = h->storage();
    setup.schur = std::move(h);
  } else if (changed) {
    auto dense_blocks = std::make_unique<ExplicitSchur>(std::move(before_B), std::move(before_C), *changed, *st.green,
                                                        b.B_gamma(), b.C_gamma(), b.loads(), st.execution);
    dense_blocks->share(distribution);
    setup.schur = std::move(dense_blocks);
    setup.storage = before->storage;
  } else {
    FarFieldReport report;
    auto dense_blocks = std::make_unique<ExplicitSchur>(*st.green, b.B_gamma(), b.C_gamma(), b.loads(), st.execution,
                                                        b.direct(), b.far_field(options), &report);
    dense_blocks->share(distribution);
    setup.schur = std::move(dense_blocks);
    SchurStorage dense;
    dense.bytes = dense.dense_bytes = 2.0 * 8.0 * double(m) * double(m);
    setup.storage = dense;
    if (report.far_pairs > 0) setup.far_field = report;
  }
  if (!keep) st.green.reset();
  if (hierarchical || setup.far_field)  // Newton finishes on the exact S
    setup.exact = std::make_unique<ImplicitSchur>(*st.fast, b.B_gamma(), b.C_gamma(), b.loads(), gmres, b.direct(),
                                                  &distribution);
  clock.mark("schur");
  st.execution.throw_if_interrupted();
}

/// What a boundary's setup takes from u₀: B_γu₀, C_γu₀ (+ the reading shift) and (singular A) the
/// load's total; again for each new load.
template <int dim>
void load_terms(const State<dim>& st, BoundarySetup<dim>& setup) {
  if (setup.load_version == st.load_version) return;
  const BoundaryDiscretization<dim>& boundary = *setup.boundary;
  std::vector<double> b0, c0;
  read_rows(boundary.B_gamma(), st.grid, st.u0, st.execution.distribution(), b0);
  read_rows(boundary.C_gamma(), st.grid, st.u0, st.execution.distribution(), c0);
  setup.shift = boundary.reading_shift(st.u0, st.f_vectorized ? st.f_vectorized : vectorize(st.f), st.load_quadrature);
  if (setup.shift != 0.0)  // the data's readings: their area-weighted sum is c∫_ω u₀ − ∫_ω f
    for (double& v : c0) v += setup.shift;
  setup.b0 = to_eigen(b0);
  setup.c0 = to_eigen(c0);
  if (st.fast->singular())
    setup.mode = ConstantMode{row_sums(boundary.B_gamma()), row_sums(boundary.C_gamma()), row_sums(boundary.B_Gamma()),
                              st.load_total};
  setup.load_version = st.load_version;
}

/// Each of `points` takes the flag of the nearest of `from`.
template <int dim>
ActiveSet nearest_flags(const std::vector<Point<dim>>& from, const ActiveSet& flags,
                        const std::vector<Point<dim>>& points, const Execution& execution) {
  ActiveSet out(points.size());
  const std::ptrdiff_t n = std::ptrdiff_t(points.size());
#pragma omp parallel for num_threads(execution.threads()) schedule(static)
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t nearest = 0;
    for (std::size_t q = 0; q < from.size(); ++q) {
      const Point<dim> d = from[q] - points[std::size_t(p)];
      double d2 = 0;
      for (int k = 0; k < dim; ++k) d2 += d[k] * d[k];
      if (d2 < best) best = d2, nearest = q;
    }
    out[std::size_t(p)] = flags[nearest];
  }
  return out;
}

}  // namespace

namespace {

/// The same problem on the grid of N/2 as a user would solve it there (the options as given: m/2^(dim−1)
/// points when m is given, δ by the offset rule of that grid; no error integrals and no estimate of its
/// own; an offset given that does not fit there is replaced by that grid's rule), for the nested start
/// and the error estimate: with δ ∝ h on both grids the two solves lie on the method's path of
/// convergence, as Richardson's estimate needs. Or nothing, with `skipped` saying why: the coarse grid
/// checks the box's margin (2h), the boundary's reach and δ ≥ 4h with its own h, and may refuse what
/// this grid takes. Its steps are reported as "N/2 <step>"; an interrupt asked there ends this solve too.
template <int dim>
std::optional<BasicSolution<dim>> coarse_solve(const State<dim>& st, const BasicContactData<dim>& data,
                                               const SolverOptions& options, bool field, std::string& skipped) {
  const int N = st.grid.nx();
  if (N % 2 != 0) {
    skipped = "N is odd";
    return std::nullopt;
  }
  if (N / 2 < minimum_nested_grid) {
    skipped = "N/2 is below " + std::to_string(minimum_nested_grid);
    return std::nullopt;
  }
  BasicProblem<dim> coarse;
  static_cast<BasicContactData<dim>&>(coarse) = data;
  coarse.exact = {};
  coarse.exact_vectorized = {};
  coarse.exact_gradient = {};
  coarse.box = st.grid.box(), coarse.boundary = st.grid.boundary(), coarse.N = N / 2, coarse.c = st.c;
  coarse.f = st.f, coarse.f_vectorized = st.f_vectorized;
  SolverOptions coarse_options = options;
  coarse_options.error_estimate = false;
  coarse_options.condition_number = false;
  if (options.multipliers > 0)
    coarse_options.multipliers =
        std::max(minimum_multipliers, int(std::lround(options.multipliers / (dim == 2 ? 2.0 : 4.0))));
  const Execution& execution = st.execution;
  const auto progress = [&execution](const std::string& phase, double seconds) {
    execution.report("N/2 " + phase, seconds);
  };
  bool stop_asked = false;  // a data callback may turn an interrupt into invalid_argument (Python's Ctrl-C)
  const auto check = [&execution, &stop_asked] { return stop_asked = stop_asked || execution.interrupt_requested(); };
  try {
    const auto solve_coarse = [&] {  // the field only where the estimate wants it
      FictitiousDomainSolver<dim> solver(coarse, coarse_options);
      solver.set_progress(progress);
      solver.set_interrupt_check(check);
      return solver.solve(coarse, coarse_options, field, false);
    };
    std::optional<BasicSolution<dim>> made;
    try {
      made.emplace(solve_coarse());
    } catch (const std::invalid_argument& e) {  // an offset given for this grid may not fit on that one:
      if (coarse_options.offset == 0 || std::string(e.what()).rfind("formulation.offset", 0) != 0 || stop_asked) throw;
      coarse_options.offset = 0;  // then δ by that grid's own rule
      made.emplace(solve_coarse());
    }
    BasicSolution<dim>& s = *made;
    if (s.newton.converged) return std::move(s);
    skipped = "the solve on the grid of N/2 did not converge: " + s.newton.failure;
  } catch (const Interrupted&) {
    throw;
  } catch (const std::runtime_error& e) {  // e.g. an empty patch
    if (stop_asked) throw Interrupted();
    // Distributed, a failure here may be one rank's alone while the others wait in the coarse solve's
    // collectives: it ends the run (the CLI stops every rank) rather than leave them waiting.
    if (st.execution.distribution().distributed()) throw;
    skipped = std::string("the solve on the grid of N/2 failed: ") + e.what();
  } catch (const std::invalid_argument& e) {  // a grid too coarse for the boundary or the box
    if (stop_asked) throw Interrupted();
    skipped = std::string("the grid of N/2 does not take the problem: ") + e.what();
  }
  return std::nullopt;
}

/// The nested start from the coarse solve: its active set carried to this grid's points (each takes
/// the flag of the nearest coarse point), or nothing when there is no coarse solve.
template <int dim>
ActiveSet nested_start(const State<dim>& st, const std::optional<BasicSolution<dim>>& coarse,
                       const std::string& skipped, const BoundaryDiscretization<dim>& fine, NestedStart& report) {
  if (!coarse) {
    report.skipped = skipped;
    return {};
  }
  report.N = coarse->grid.nx();
  report.multipliers = coarse->options.multipliers;
  report.newton_steps = coarse->newton.iterations;
  report.active = int(std::count(coarse->newton.active.begin(), coarse->newton.active.end(), 1));
  return nearest_flags<dim>(coarse->points(), coarse->newton.active, fine.points(), st.execution);
}

/// The value of a condition at a point: finite and within the solver's scale, else an error naming `key`.
template <int dim>
double condition_value(double value, const char* key, const Point<dim>& x) {
  if (!std::isfinite(value))
    throw std::invalid_argument(std::string(key) + ": not finite at the point " + detail::format_point(x));
  if (std::abs(value) > largest_scale)
    throw std::invalid_argument(std::string(key) + ": " + format_number(value) + " at the point " +
                                detail::format_point(x) + " is beyond " + format_number(largest_scale) +
                                ": rescale the problem (u, f and g by one factor)");
  return value;
}

/// Step 4: g at the points and, with mixed conditions, each point's condition (docs/math.md, "Mixed
/// conditions"): u_D takes g's place at the Dirichlet points (the value of their B rows), q is kept for
/// the Neumann ones. Throws naming the key where a part holds at no point, two parts claim one point, a
/// value is not finite, or the Neumann part is all of γ with c = 0 (u then fixed up to a constant).
template <int dim>
void obstacle_and_conditions(const BoundaryDiscretization<dim>& boundary, const BasicContactData<dim>& data, double c,
                             BasicSolution<dim>& sol) {
  sol.g = boundary.obstacle(data);
  sol.conditions = {};
  const PartConditions<dim>& parts = data.conditions;
  if (!parts.mixed()) return;
  if (parts.dirichlet && !parts.u)
    throw std::invalid_argument("conditions.u: not given (the Dirichlet part needs u there)");
  const int m = boundary.n_points();
  const std::vector<Point<dim>>&x = boundary.points(), &n = boundary.normals();
  PointConditions pc;
  pc.kind.assign(std::size_t(m), PointCondition::signorini);
  pc.flux = Eigen::VectorXd::Zero(m);
  int dirichlet = 0, neumann = 0;
  const std::vector<PointCondition>& placed = boundary.point_parts();  // the part each point was placed in
  for (int i = 0; i < m; ++i) {
    const Point<dim>& p = x[std::size_t(i)];
    bool in_d = parts.dirichlet && condition_value(parts.dirichlet(p), "conditions.dirichlet", p) != 0;
    bool in_n = parts.neumann && condition_value(parts.neumann(p), "conditions.neumann", p) != 0;
    if (in_d && in_n)
      throw std::invalid_argument("conditions.neumann: overlaps conditions.dirichlet at the point " +
                                  detail::format_point(p) + " of gamma (a point takes one condition)");
    if (!placed.empty())
      in_d = placed[std::size_t(i)] == PointCondition::dirichlet,
      in_n = placed[std::size_t(i)] == PointCondition::neumann;
    if (in_d) {
      sol.g[std::size_t(i)] = condition_value(parts.u(p), "conditions.u", p);
      pc.kind[std::size_t(i)] = PointCondition::dirichlet;
      ++dirichlet;
    } else if (in_n) {
      pc.flux(i) = parts.flux ? condition_value(parts.flux(p, n[std::size_t(i)]), "conditions.flux", p) : 0.0;
      pc.kind[std::size_t(i)] = PointCondition::neumann;
      ++neumann;
    }
  }
  const std::string points = " of the " + std::to_string(m) + " points of gamma (m = formulation.multipliers)";
  if (parts.dirichlet && dirichlet == 0) throw std::invalid_argument("conditions.dirichlet: holds at none" + points);
  if (parts.neumann && neumann == 0) throw std::invalid_argument("conditions.neumann: holds at none" + points);
  if (neumann == m && c == 0)
    throw std::invalid_argument(
        "conditions.neumann: covers all of gamma with c = 0, which fixes u only up to a constant (give c > 0, or a "
        "Dirichlet or Signorini part)");
  sol.conditions = std::move(pc);
}

/// With mixed conditions: each pair of neighbouring points under different conditions, with the junction
/// between them located by bisection along the chord from x_i to x_j on the parts' expressions (docs/math.md,
/// "Mixed conditions"). The chord is within O(d²) of γ, which places the junction to second order.
template <int dim>
void locate_junctions(const BasicContactData<dim>& data, BasicSolution<dim>& sol) {
  sol.junctions.clear();
  if (sol.conditions.kind.empty()) return;
  const PartConditions<dim>& parts = data.conditions;
  for (NeighbourPair& pair : neighbour_pairs<dim>(sol)) {
    const PointCondition own = sol.condition(pair.i);
    if (own == sol.condition(pair.j)) continue;
    const Point<dim>&xi = sol.points()[std::size_t(pair.i)], &xj = sol.points()[std::size_t(pair.j)];
    double lo = 0, hi = 1;
    for (int k = 0; k < 40; ++k) {
      const double t = 0.5 * (lo + hi);
      (parts.at(xi + t * (xj - xi)) == own ? lo : hi) = t;
    }
    const double theta = 0.5 * (lo + hi);
    sol.junctions.push_back({std::move(pair), theta, xi + theta * (xj - xi)});
  }
}

/// With mixed conditions: where the Dirichlet part meets the Signorini part with the obstacle above
/// u_D (u ≥ g on one side, u = u_D on the other), u jumps: its energy is infinite and the quantities do
/// not converge with N. Judged at each Dirichlet–Signorini junction from g − u_D at both points: their
/// mean (the mismatch at the junction) beyond their difference (what one spacing explains). A warning
/// names the first such junction.
template <int dim>
void junction_warning(const BoundaryDiscretization<dim>& boundary, const BasicContactData<dim>& data,
                      BasicSolution<dim>& sol) {
  if (!data.conditions.dirichlet || sol.conditions.kind.empty()) return;
  const std::vector<double> g = boundary.obstacle(data);  // the obstacle at the Dirichlet points too
  double scale = 0;
  for (double v : sol.g) scale = std::max(scale, std::abs(v));
  for (const PartJunction<dim>& junction : sol.junctions) {
    const NeighbourPair& pair = junction.pair;
    const PointCondition a = sol.condition(pair.i), b = sol.condition(pair.j);
    if (!((a == PointCondition::dirichlet && b == PointCondition::signorini) ||
          (a == PointCondition::signorini && b == PointCondition::dirichlet)))
      continue;
    const Point<dim>&xi = sol.points()[std::size_t(pair.i)], &xj = sol.points()[std::size_t(pair.j)];
    const double di = g[std::size_t(pair.i)] - data.conditions.u(xi),
                 dj = g[std::size_t(pair.j)] - data.conditions.u(xj);
    const double mismatch = 0.5 * (di + dj);
    if (!(mismatch > std::abs(di - dj) + 1e-9 * scale)) continue;
    sol.warnings.push_back("conditions.u: where the Dirichlet part meets the Signorini part near " +
                           detail::format_point<dim>(junction.at) + ", the obstacle g lies " + format_number(mismatch) +
                           " above u there: u jumps (its energy is infinite) and the quantities do not converge "
                           "with N");
    return;
  }
}

/// Step 5: semismooth Newton on λ with the Schur blocks; where the far field was interpolated, on S̃
/// until the active set has nearly settled (dense S̃) or settled (compressed S̃), then on the exact S,
/// solved through S̃ (GMRES preconditioned by its LU, or refinement) from there.
template <int dim>
void newton(const State<dim>& st, BoundarySetup<dim>& setup, const SolverOptions& options, const ActiveSet& start,
            BasicSolution<dim>& sol) {
  const NewtonOptions newton_options = detail::newton_options(options, st.execution);
  NewtonOptions first = newton_options;
  const int m = setup.boundary->n_points();
  // Hand on to the exact S: from the dense S̃ when few points still change (each step there is an LU or
  // an update of one); from the compressed S̃ only once its active set has settled (its steps cost no
  // fast solve, the exact S's several).
  const auto* compressed = dynamic_cast<const HierarchicalSchur*>(setup.schur.get());
  if (setup.exact) first.hand_on_at_changes = compressed ? 0 : std::max(1, int(far_field_hand_on * m));
  if (setup.exact && compressed)  // a set that never settles on S̃ leaves the exact S two steps at least
    first.max_iterations = std::max(1, newton_options.max_iterations - 2);
  if (!start.empty()) first.start_active = &start;
  if (!sol.conditions.kind.empty()) first.conditions = &sol.conditions;
  const ConstantMode* mode = setup.mode ? &*setup.mode : nullptr;
  const Eigen::VectorXd g = to_eigen(sol.g);
  const std::size_t before = setup.schur->fast_solves(), exact_before = setup.exact ? setup.exact->fast_solves() : 0;
  // On the compressed S̃ the first run seeks the active set only: its solves need not go below S̃'s own
  // accuracy (the exact run refines λ from there).
  std::optional<SettlingSchur> settling;
  if (setup.exact && compressed) settling.emplace(*compressed, settling_tolerance);
  sol.newton = solve_semismooth_newton(settling ? static_cast<const SchurComplement&>(*settling) : *setup.schur,
                                       setup.b0, setup.c0, g, first, mode);
  if (setup.exact) {
    GmresOptions polish = detail::gmres_options(options, m, st.execution);
    polish.relative_tolerance = far_field_gmres_tolerance;
    const auto* dense = dynamic_cast<const ExplicitSchur*>(setup.schur.get());
    std::unique_ptr<SchurComplement> exact;  // the exact S, solved through the approximate one
    if (dense)
      exact = std::make_unique<PreconditionedSchur>(*dense, *setup.exact, polish);
    else
      exact = std::make_unique<RefinedSchur>(*compressed, *setup.exact, far_field_gmres_tolerance);
    NewtonOptions from_there = newton_options;  // solver.max_newton caps the runs together
    from_there.conditions = first.conditions;
    from_there.start = &sol.newton;
    from_there.max_iterations = std::max(1, newton_options.max_iterations - sol.newton.iterations);
    NewtonResult search;
    if (!dense && from_there.max_iterations > 1) {
      // Compressed: each exact step costs a fast solve per GMRES step, so the steps that still change
      // the active set stop at exact_search_tolerance; a last run solves to the full tolerance from
      // there and confirms the set (or goes on where it changes).
      auto& refined = static_cast<RefinedSchur&>(*exact);
      refined.set_tolerance(exact_search_tolerance);
      NewtonOptions searching = from_there;
      searching.max_iterations = from_there.max_iterations - 1;
      search = solve_semismooth_newton(*exact, setup.b0, setup.c0, g, searching, mode);
      refined.set_tolerance(far_field_gmres_tolerance);
      from_there.start = &search;
      from_there.max_iterations = std::max(1, from_there.max_iterations - search.iterations);
      sol.newton.iterations += search.iterations;
      sol.newton.history.insert(sol.newton.history.end(), search.history.begin(), search.history.end());
      sol.newton.inner_failed = sol.newton.inner_failed || search.inner_failed;
    }
    NewtonResult second = solve_semismooth_newton(*exact, setup.b0, setup.c0, g, from_there, mode);
    if (setup.far_field) sol.far_field = FarFieldUse{*setup.far_field, second.iterations};
    second.iterations += sol.newton.iterations;
    if (!second.converged && second.failure.rfind("no convergence in ", 0) == 0)  // the runs' steps together
      second.failure = "no convergence in " + std::to_string(second.iterations) + " Newton steps";
    second.history.insert(second.history.begin(), sol.newton.history.begin(), sol.newton.history.end());
    second.inner_failed = second.inner_failed || sol.newton.inner_failed;
    sol.newton = std::move(second);
    sol.fast_solves += setup.exact->fast_solves() - exact_before;
  }
  sol.fast_solves += setup.schur->fast_solves() - before;
  if (const auto* dense = dynamic_cast<const ExplicitSchur*>(setup.schur.get()))
    sol.factorizations = dense->factorizations();
  else if (const auto* h = dynamic_cast<const HierarchicalSchur*>(setup.schur.get()))
    sol.factorizations = h->factorizations();
  sol.schur_storage = setup.storage;
  if (!setup.storage_warning.empty()) sol.warnings.push_back(setup.storage_warning);
  for (const NewtonStep& step : sol.newton.history) sol.inner_iterations += step.inner_iterations;
  // Distributed: every rank ran the same steps on the same numbers; rank 0's λ, α, active set and outcome
  // are the answer, so that no later decision can differ between ranks.
  const Distribution& distribution = st.execution.distribution();
  if (distribution.distributed()) {
    distribution.broadcast(sol.newton.lambda.data(), std::size_t(sol.newton.lambda.size()));
    std::vector<double> outcome{sol.newton.alpha, double(sol.newton.converged), double(sol.newton.iterations)};
    outcome.insert(outcome.end(), sol.newton.active.begin(), sol.newton.active.end());
    distribution.broadcast(outcome.data(), outcome.size());
    sol.newton.alpha = outcome[0], sol.newton.converged = outcome[1] != 0, sol.newton.iterations = int(outcome[2]);
    for (std::size_t i = 0; i < sol.newton.active.size(); ++i) sol.newton.active[i] = outcome[3 + i] != 0;
  }
  sol.lambda.assign(sol.newton.lambda.data(), sol.newton.lambda.data() + sol.newton.lambda.size());
  sol.lambda_total = row_sums(setup.boundary->B_Gamma()).dot(sol.newton.lambda);
  sol.alpha = sol.newton.alpha;
  if (!all_finite(sol.lambda) || !std::isfinite(sol.alpha) || max_abs(sol.lambda) > largest_scale)
    throw std::invalid_argument("data.g: the multipliers reach " + format_number(max_abs(sol.lambda)) + " (|g| up to " +
                                format_number(max_abs(sol.g)) + "), beyond " + format_number(largest_scale) +
                                ": rescale the problem (u, f and g by one factor)");
}

/// Step 6: û = u₀ + A⁻¹ loadsᵀλ + α, finished by the boundary (the kink-corrected field I_h w in the
/// non-smooth variant, whose traces and readings are those of the Newton system); its traces at the points.
template <int dim>
void field(const State<dim>& st, const BoundarySetup<dim>& setup, BasicSolution<dim>& sol) {
  const BoundaryDiscretization<dim>& boundary = *setup.boundary;
  const Distribution& distribution = st.execution.distribution();
  GridVector u = st.fast->make_vector();  // this rank's layers (all of them serially)
  add_rows(boundary.loads(), st.grid, sol.lambda, u, distribution);
  st.fast->solve_in_place(u);
  ++sol.fast_solves;
  for (std::size_t k = 0; k < u.size(); ++k) u[k] += st.u0[k] + sol.alpha;
  boundary.finish_field(sol.lambda, u);
  if (!distribution.all(all_finite(u)))
    throw std::invalid_argument("data: the field u is not finite: the data are too large for double precision");
  sol.u = std::move(u);
  read_rows(boundary.B_gamma(), st.grid, sol.u, distribution, sol.trace);
  read_rows(boundary.C_gamma(), st.grid, sol.u, distribution, sol.normal_derivative);
  boundary.finish_readings(sol.lambda, sol.normal_derivative);
  if (setup.shift != 0.0)
    for (double& v : sol.normal_derivative) v += setup.shift;
}

/// The range of the trace B_γû over the points divided by the diagonal of their bounding box: a slope
/// of the field along γ (0 for a single point or a constant trace).
template <int dim>
double trace_slope(const BasicSolution<dim>& sol) {
  if (sol.n_points() < 2) return 0.0;
  const auto [low, high] = std::minmax_element(sol.trace.begin(), sol.trace.end());
  Point<dim> lo = sol.points()[0], hi = lo;
  for (const Point<dim>& x : sol.points())
    for (int d = 0; d < dim; ++d) lo[d] = std::min(lo[d], x[d]), hi[d] = std::max(hi[d], x[d]);
  const double extent = norm(hi - lo);
  return extent > 0 ? (*high - *low) / extent : 0.0;
}

/// Step 7: the Signorini conditions at the points, and again with an independent ∂u/∂n.
template <int dim>
void signorini_checks(const BoundaryDiscretization<dim>& boundary, bool with_field, BasicSolution<dim>& sol) {
  const int m = boundary.n_points();
  sol.signorini = detail::signorini_check(sol.trace, sol.normal_derivative, sol.g, sol.conditions.kind);
  if (!with_field) return;  // (not sol.u.empty(): a rank of a distributed run may hold no layer)
  IndependentCheck check;
  std::optional<std::vector<double>> d = boundary.independent_normal_derivative(sol.u, check.rule);
  if (!d) return;
  check.min_normal_derivative = std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    const double gap = sol.trace[i] - sol.g[i], difference = (*d)[i] - sol.normal_derivative[i];
    check.max_difference = std::max(check.max_difference, std::abs(difference));
    sum += difference * difference;
    if (sol.condition(i) != PointCondition::signorini) continue;
    check.min_normal_derivative = std::min(check.min_normal_derivative, (*d)[i]);
    check.max_complementarity = std::max(check.max_complementarity, std::abs(gap * (*d)[i]));
  }
  if (!std::isfinite(check.min_normal_derivative)) check.min_normal_derivative = 0;
  check.rms_difference = std::sqrt(sum / m);
  // The largest |C_γû|; where the readings carry no flux (no contact, no Dirichlet part, no flux
  // given: they are round-off), the trace's range over γ per unit of γ's extent instead.
  const double flux_scale = max_abs(sol.normal_derivative), field_scale = trace_slope(sol);
  const bool by_flux = flux_scale > 1e-8 * field_scale;
  const double scale = by_flux ? flux_scale : field_scale;
  check.relative_difference = scale > 0 ? check.rms_difference / scale : 0.0;
  check.normal_derivative = std::move(*d);
  if (check.relative_difference > check_warning) {
    char line[640];
    std::snprintf(line, sizeof line,
                  "signorini.check: the enforced du/dn and the du/dn of the field near gamma (%s) differ by %.3g %% "
                  "of %s (root mean square; at most %.3g %%), more than %g %%: one of them is not resolved at N = "
                  "%d; refine the grid (docs/math.md, \"Checks\")",
                  check.rule.c_str(), 100 * check.relative_difference,
                  by_flux ? "the largest |du/dn|" : "the trace's range over gamma per unit length",
                  100 * check.max_difference / scale, 100 * check_warning, sol.grid.nx());
    sol.warnings.push_back(line);
  }
  sol.check = std::move(check);
}

/// Step 8: the errors against the exact solution, at the points and in ω and on γ.
template <int dim>
void errors(const State<dim>& st, const BoundaryDiscretization<dim>& boundary, const BasicContactData<dim>& data,
            const SolverOptions& options, BasicSolution<dim>& sol) {
  sol.point_errors = boundary.point_errors(sol.trace, sol.normal_derivative, data);
  sol.errors = boundary.errors(sol.u, sol.trace, data, options.error_quadrature);
  const ErrorNorms& e = *sol.errors;
  for (double v : {e.l2_omega, e.h1semi_omega, e.l2_gamma, e.rel_l2_omega, e.rel_h1_omega, e.rel_l2_gamma})
    if (!std::isfinite(v))
      throw std::invalid_argument("data.exact: not finite somewhere in omega or on gamma (or its gradient is not)");
  (void)st;
}

/// Step 9: the integrals over ω of û and f (docs/math.md, "Quantities"), and with a coarse solve
/// ‖û − û_{N/2}‖²_{L²(ω)} in the same pass (`difference2`; û_{N/2} interpolated at the points).
template <int dim>
DomainQuantities domain_quantities(const State<dim>& st, const BoundaryDiscretization<dim>& boundary,
                                   const GridVector& u, int quadrature, const BasicSolution<dim>* coarse,
                                   const GridVector& coarse_u, std::optional<Slab> coarse_held,
                                   const typename Fields<dim>::Vectorized& exact, double& difference2,
                                   std::array<double, 2>& exact_integrals) {
  const typename Fields<dim>::Vectorized f = st.f_vectorized ? st.f_vectorized : vectorize(st.f);
  constexpr int K = 9;  // |ω|, ∫û, ∫û², ∫|∇û|², ∫f, ∫fû, ∫(û − û_{N/2})², ∫u, ∫fu (u: the exact solution)
  std::vector<std::array<double, K>> sums(std::size_t(st.execution.threads()), std::array<double, K>{});
  std::vector<std::vector<double>> f_at(sums.size()), coarse_at(sums.size()), exact_at(sums.size());
  boundary.for_each_omega_sample(u, quadrature, [&](int thread, const OmegaSamples<dim>& row) {
    std::vector<double>& fv = f_at[std::size_t(thread)];
    std::vector<double>& cv = coarse_at[std::size_t(thread)];
    std::vector<double>& ev = exact_at[std::size_t(thread)];
    evaluate_at(f, row.x, fv);
    if (coarse) sample_q1_at<dim>(coarse->grid, coarse_u, row.x, cv, coarse_held);
    if (exact) evaluate_at(exact, row.x, ev);
    std::array<double, K> r{};  // per row, then per thread
    for (std::size_t k = 0; k < row.size(); ++k) {
      const double w = row.weight[k], v = row.value[k];
      double grad2 = 0;
      for (int d = 0; d < dim; ++d) grad2 += row.gradient[d][k] * row.gradient[d][k];
      r[0] += w, r[1] += w * v, r[2] += w * v * v, r[3] += w * grad2, r[4] += w * fv[k], r[5] += w * fv[k] * v;
      if (coarse) r[6] += w * (v - cv[k]) * (v - cv[k]);
      if (exact) r[7] += w * ev[k], r[8] += w * fv[k] * ev[k];
    }
    for (int c = 0; c < K; ++c) sums[std::size_t(thread)][std::size_t(c)] += r[std::size_t(c)];
  });
  std::array<double, K> t{};
  for (const auto& s : sums)
    for (int c = 0; c < K; ++c) t[std::size_t(c)] += s[std::size_t(c)];
  st.execution.distribution().sum(t.data(), t.size());  // the ranks' cells
  if (!std::isfinite(t[4]) || !std::isfinite(t[5])) throw std::invalid_argument("data.f: not finite somewhere in ω");
  DomainQuantities q;
  q.volume = t[0], q.integral_u = t[1], q.integral_u2 = t[2], q.integral_grad2 = t[3];
  q.integral_f = t[4], q.integral_fu = t[5];
  q.energy = 0.5 * q.integral_grad2 + 0.5 * st.c * q.integral_u2 - q.integral_fu;
  q.flux = st.c * q.integral_u - q.integral_f;
  difference2 = t[6];
  exact_integrals = {t[7], t[8]};
  return q;
}

/// Where the solve on the grid of N/2 left the path of this one's method, which Richardson's rule assumes:
/// patches or arcs of another size in cells (the default rule moved there, or m raised to its minimum),
/// Γ at another δ/s (an offset given that does not fit there), or fewer fitted solves (a fit failed
/// there). Empty when it kept to it. `fine_offset`: this solve's δ/s (its options are filled in later).
template <int dim>
std::string estimate_caveat(const BasicSolution<dim>& coarse, const BasicSolution<dim>& fine, double fine_offset) {
  constexpr double cells_tolerance = 0.1, offset_tolerance = 0.02;  // rounding of m moves s/h by far less
  std::string caveat;
  const auto add = [&caveat](const std::string& part) { caveat += (caveat.empty() ? "" : "; ") + part; };
  char text[160];
  const double fine_cells = fine.spacing() / fine.grid.h(), coarse_cells = coarse.spacing() / coarse.grid.h();
  if (std::abs(coarse_cells / fine_cells - 1) > cells_tolerance) {
    std::snprintf(text, sizeof text, "its spacing is %.3g h against %.3g h here", coarse_cells, fine_cells);
    add(text);
  }
  if (coarse.options.variant == Variant::smooth &&
      std::abs(coarse.options.offset / fine_offset - 1) > offset_tolerance) {
    std::snprintf(text, sizeof text, "its Γ lies at δ = %.3g s against %.3g s here", coarse.options.offset,
                  fine_offset);
    add(text);
  }
  const int fine_passes = fine.contact_fit ? fine.contact_fit->passes : 0;
  const int coarse_passes = coarse.contact_fit ? coarse.contact_fit->passes : 0;
  if (coarse_passes < fine_passes) add("its fit to the contact boundary made fewer passes");
  return caveat;
}

/// Step 10: the error estimate from the solve on the grid of N/2 (docs/math.md, "The error estimate"):
/// Richardson's |Q_N − Q_{N/2}|/(2^p − 1), p = 2 for û, the force and the energy, p = 1 for the contact
/// measure (whole points enter and leave the contact set).
template <int dim>
ErrorEstimate error_estimate(const BasicSolution<dim>& coarse, const BasicSolution<dim>& fine, double difference2,
                             double fine_offset) {
  constexpr double second_order = 3, first_order = 1;  // 2^p − 1
  ErrorEstimate e;
  e.N = coarse.grid.nx();
  e.l2_omega = std::sqrt(difference2) / second_order;
  const double norm = std::sqrt(fine.domain->integral_u2);
  e.rel_l2_omega = norm > 0 ? e.l2_omega / norm : e.l2_omega;
  e.force = std::abs(contact_summary(fine).force - contact_summary(coarse).force) / second_order;
  e.energy = std::abs(fine.domain->energy - coarse.domain->energy) / second_order;
  e.integral_u = std::abs(fine.domain->integral_u - coarse.domain->integral_u) / second_order;
  e.measure = std::abs(contact_summary(fine).measure - contact_summary(coarse).measure) / first_order;
  e.caveat = estimate_caveat(coarse, fine, fine_offset);
  return e;
}

/// The warning of the estimate (docs/math.md, "The error estimate").
template <int dim>
void estimate_warning_line(BasicSolution<dim>& sol) {
  if (!sol.estimate || !sol.estimate->skipped.empty() || !(sol.estimate->rel_l2_omega > estimate_warning)) return;
  char line[320];
  std::snprintf(line, sizeof line,
                "domain.N: the estimated error of u is %.2g %% of its L2(omega) norm (from the solve at N = %d): "
                "refine the grid for results to %g %%",
                100 * sol.estimate->rel_l2_omega, sol.estimate->N, 100 * estimate_warning);
  sol.warnings.push_back(line);
}

/// Before the load: the same problem on the grid of N/2 where the nested start (3-D, N at or above
/// solver.nested_start) or the error estimate (with the field) wants it; the nested start's active set
/// into `start`, the reports into `sol`.
template <int dim>
std::optional<BasicSolution<dim>> coarse_step(const State<dim>& st, const BasicContactData<dim>& data,
                                              const SolverOptions& options, bool compute_field,
                                              const BoundaryDiscretization<dim>& boundary, PhaseClock& clock,
                                              ActiveSet& start, BasicSolution<dim>& sol) {
  const bool nested = dim == 3 && options.nested_start > 0 && st.grid.nx() >= options.nested_start;
  const bool estimate = options.error_estimate && compute_field;
  if (!nested && !estimate) return std::nullopt;
  std::string skipped;
  std::optional<BasicSolution<dim>> coarse = coarse_solve<dim>(st, data, options, estimate, skipped);
  clock.mark(nested ? "nested_start" : "coarse_solve");
  const double seconds = sol.timings.phases.back().second;
  if (nested) {
    sol.nested_start.emplace();
    start = nested_start<dim>(st, coarse, skipped, boundary, *sol.nested_start);
    sol.nested_start->seconds = seconds;
  }
  if (estimate) {
    sol.estimate.emplace();
    sol.estimate->skipped = skipped;
    sol.estimate->seconds = seconds;
  }
  st.execution.throw_if_interrupted();
  return coarse;
}

/// Steps 9–10: the integrals over ω, the quantities' errors against an exact solution, the estimate
/// from the coarse solve and its warning.
template <int dim>
void quantities_step(const State<dim>& st, const BoundaryDiscretization<dim>& boundary,
                     const BasicContactData<dim>& data, const std::optional<BasicSolution<dim>>& coarse,
                     BasicSolution<dim>& sol) {
  double difference2 = 0;
  const BasicSolution<dim>* from = sol.estimate && coarse && coarse->domain ? &*coarse : nullptr;
  std::array<double, 2> exact{};  // ∫u, ∫fu of the exact solution
  typename Fields<dim>::Vectorized exact_u;
  if (sol.errors) exact_u = data.exact_vectorized ? data.exact_vectorized : vectorize(data.exact);
  // Distributed, each rank samples the coarse field at the points of its cells: it fetches the coarse
  // layers under its own.
  const Distribution& distribution = st.execution.distribution();
  std::optional<Slab> held;
  GridVector fetched;
  if (from && distribution.distributed()) {
    held = coarse_layers_under(st.grid, distribution.slab(st.grid), from->grid);
    fetched = distribution.layers(from->grid, from->u, *held);
  }
  const GridVector& coarse_u = held ? fetched : from ? from->u : fetched;
  sol.domain = domain_quantities<dim>(st, boundary, sol.u, quantity_quadrature, from, coarse_u, held, exact_u,
                                      difference2, exact);
  if (sol.errors) {
    ErrorNorms& e = *sol.errors;
    const double energy =
        0.5 * e.exact_h1semi_omega * e.exact_h1semi_omega + 0.5 * st.c * e.exact_l2_omega * e.exact_l2_omega - exact[1];
    e.integral_u = sol.domain->integral_u - exact[0];
    e.force = st.c * e.integral_u;
    e.energy = sol.domain->energy - energy;
  }
  if (from) {
    const double seconds = sol.estimate->seconds;
    sol.estimate = error_estimate<dim>(*from, sol, difference2, boundary.spacing().offset);
    sol.estimate->seconds = seconds;
  } else if (sol.estimate && sol.estimate->skipped.empty()) {
    sol.estimate->skipped = "the solve on the grid of N/2 made no field";
  }
  estimate_warning_line<dim>(sol);
}

/// The largest distance of a point of `found` from the nearest of `before` (0 when either is empty).
template <int dim>
double farthest_from(const std::vector<Point<dim>>& found, const std::vector<Point<dim>>& before) {
  double farthest = 0;
  for (const Point<dim>& e : found) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Point<dim>& p : before) nearest = std::min(nearest, norm(e - p));
    if (!before.empty()) farthest = std::max(farthest, nearest);
  }
  return farthest;
}

/// The phases from `first` on, but those a solve makes once (the coarse solve, the load, u₀ and the Green's
/// table), become
/// the one phase `name` (added to an earlier one of that name); returns their seconds.
double merge_phases(Timings& timings, std::size_t first, const std::string& name) {
  std::vector<std::pair<std::string, double>>& phases = timings.phases;
  double seconds = 0;
  for (std::size_t k = first; k < phases.size();) {
    const std::string& phase = phases[k].first;
    if (phase == "coarse_solve" || phase == "nested_start" || phase == "load" || phase == "u0" ||
        phase == "green_table") {
      ++k;
      continue;
    }
    seconds += phases[k].second;
    phases.erase(phases.begin() + std::ptrdiff_t(k));
  }
  const auto earlier = std::find_if(phases.begin(), phases.end(), [&name](const auto& p) { return p.first == name; });
  if (earlier == phases.end())
    phases.emplace_back(name, seconds);
  else
    earlier->second += seconds;
  return seconds;
}

}  // namespace

template <int dim>
BasicSolution<dim> FictitiousDomainSolver<dim>::solve(const BasicContactData<dim>& data, SolverOptions options,
                                                      bool compute_field, bool keep) {
  State& st = *state_;
  bool chosen = false;
  options = solve_options<dim>(st, data, options, chosen);
  Eigen::setNbThreads(st.execution.threads());  // the dense LU of the Newton steps follows the threads option
  BasicSolution<dim> sol(st.grid);
  PhaseClock clock(sol.timings, st.execution);
  ActiveSet start;
  std::optional<BasicSolution<dim>> coarse;
  // solver.fit_contact: each solve after the first places its points to the contact boundary the one
  // before located (docs/math.md, "Fitting the points to the contact set").
  BasicContactData<dim> fitted;
  const BasicContactData<dim>* current = &data;
  std::vector<Point<dim>> placed_for;  // the located ends the points were placed for
  // The first solve's setup is the solver's (a new obstacle or load reuses it); the fitted ones are made
  // for this solve only. The solve before a fitted one, and its setup, are kept to fall back to.
  std::unique_ptr<BoundarySetup<dim>> fitted_setup, before_setup;
  std::optional<BasicSolution<dim>> before;
  const auto solve_pass = [&](int pass, bool last) -> BoundarySetup<dim>& {
    sol.far_field.reset();
    if (pass > 0) fitted_setup = placed_setup<dim>(*st.setup, fitted, options, st.c, clock);
    BoundarySetup<dim>& setup =
        pass > 0 ? *fitted_setup : boundary_setup<dim>(st, data, options, clock, sol.reused_curve);  // 1–2
    obstacle_and_conditions<dim>(*setup.boundary, *current, st.c, sol);                              // 4
    st.execution.throw_if_interrupted();
    if (pass > 0) {  // Newton starts from the contact side at the new points
      const std::vector<Point<dim>>& x = setup.boundary->points();
      start.assign(x.size(), 0);
      for (std::size_t i = 0; i < x.size(); ++i) start[i] = char(fitted.conditions.contact_side(x[i]) != 0);
    }
    if (pass == 0) coarse = coarse_step<dim>(st, data, options, compute_field, *setup.boundary, clock, start, sol);
    load_and_u0<dim>(st, clock, sol.fast_solves);  // 0
    st.execution.throw_if_interrupted();
    const bool made = !setup.schur;
    // The solve before's blocks (a fitted solve updates them where the points moved), then freed.
    BoundarySetup<dim>* previous = pass == 0 ? nullptr : pass == 1 ? st.setup.get() : before_setup.get();
    schur_blocks<dim>(st, setup, options, clock, keep || !last, previous, keep);  // 2b–3
    if (made) sol.fast_solves += setup.fast_solves;
    load_terms<dim>(st, setup);
    const BoundaryDiscretization<dim>& boundary = *setup.boundary;
    boundary.describe(sol);
    locate_junctions<dim>(*current, sol);
    junction_warning<dim>(boundary, *current, sol);
    sol.delta = boundary.delta();
    sol.flux_balance = boundary.flux_balance(setup.shift);
    newton<dim>(st, setup, options, start, sol);  // 5
    clock.mark("newton");
    st.execution.throw_if_interrupted();
    return setup;
  };
  sol.options.fit_contact = options.fit_contact;  // resolve_contact's rule for the ends depends on it
  for (int pass = 0;; ++pass) {
    const std::size_t pass_begins = sol.timings.phases.size();
    const bool last = pass >= options.fit_contact;
    std::string failure;  // a fitted solve that failed: the one before stands
    BoundarySetup<dim>* made = nullptr;
    if (pass == 0) {
      made = &solve_pass(pass, last);
    } else {
      try {
        made = &solve_pass(pass, last);
        if (!sol.newton.converged) failure = "Newton did not converge";
      } catch (const std::invalid_argument& e) {
        failure = e.what();
      }
    }
    if (!failure.empty()) {
      Timings timings = sol.timings;
      sol = std::move(*before);
      sol.timings = std::move(timings);
      sol.warnings.push_back("solver.fit_contact: the solve fitted to the contact boundary (pass " +
                             std::to_string(pass) + ") failed (" + failure +
                             "); the results are those of the solve before");
      --sol.contact_fit->passes;  // the fitted solves whose results stand
      fitted_setup = std::move(before_setup);
      current = &data;
      if (!keep)  // (the failed solve may have stopped before it freed the blocks before it)
        for (BoundarySetup<dim>* s : {st.setup.get(), fitted_setup.get()})
          if (s) s->schur.reset(), s->exact.reset();
      break;
    }
    BoundarySetup<dim>& setup = *made;
    const bool fit_next = !last && sol.newton.converged;
    if (pass > 0 || fit_next) {  // the located ends, from Newton's readings (the field's, to round-off)
      sol.trace.assign(sol.newton.trace.data(), sol.newton.trace.data() + sol.newton.trace.size());
      sol.normal_derivative.assign(sol.newton.normal_derivative.data(),
                                   sol.newton.normal_derivative.data() + sol.newton.normal_derivative.size());
      // Distributed: rank 0's readings, so that every rank places the next points alike.
      const Distribution& distribution = st.execution.distribution();
      distribution.broadcast(sol.trace.data(), sol.trace.size());
      distribution.broadcast(sol.normal_derivative.data(), sol.normal_derivative.size());
      resolve_contact<dim>(sol);
    }
    if (pass > 0) {
      sol.contact_fit->moved.push_back(farthest_from(sol.contact_boundary, placed_for) / sol.spacing());
      sol.contact_fit->newton_steps.push_back(sol.newton.iterations);
    }
    if (std::function<double(const Point<dim>&)> side = fit_next ? contact_side<dim>(sol) : nullptr) {
      if (!sol.contact_fit) sol.contact_fit.emplace(), sol.contact_fit->newton_steps.push_back(sol.newton.iterations);
      ++sol.contact_fit->passes;
      sol.contact_fit->seconds += merge_phases(sol.timings, pass_begins, "fit_contact");
      before = sol;
      before_setup = std::move(fitted_setup);  // (none after the first solve: the solver's own)
      placed_for = sol.contact_boundary;
      fitted = data;
      fitted.conditions.contact_side = std::move(side);
      current = &fitted;
      continue;
    }
    if (options.condition_number && setup.schur) {  // of the final Newton matrix: the solve whose results stand
      sol.condition_number = setup.schur->condition_number(sol.newton.active, setup.mode ? &*setup.mode : nullptr);
      if (const auto* dense = dynamic_cast<const ExplicitSchur*>(setup.schur.get())) {
        sol.factorizations = dense->factorizations();  // its LU, where it factored S_𝒜 anew
        if (!sol.condition_number)
          sol.warnings.push_back(
              "solver.condition_number: the final Newton matrix is singular to working precision (its LU solves "
              "are not finite); no condition number");
      }
      clock.mark("condition");
    }
    if (!keep) setup.schur.reset(), setup.exact.reset();  // S_B, S_C and the kept LU: freed before the field
    break;
  }
  if (!keep) st.green.reset();  // (kept for a fitted solve that did not come)
  before.reset();
  BoundarySetup<dim>& setup = fitted_setup ? *fitted_setup : *st.setup;
  const BoundaryDiscretization<dim>& boundary = *setup.boundary;
  if (compute_field) {  // 6
    field<dim>(st, setup, sol);
    if (!keep) st.u0 = GridVector(), st.have_u0 = false;
    clock.mark("final_solve");
    st.execution.throw_if_interrupted();
  } else {
    sol.trace.assign(sol.newton.trace.data(), sol.newton.trace.data() + sol.newton.trace.size());
    sol.normal_derivative.assign(sol.newton.normal_derivative.data(),
                                 sol.newton.normal_derivative.data() + sol.newton.normal_derivative.size());
  }
  signorini_checks<dim>(boundary, compute_field, sol);  // 7
  resolve_contact<dim>(sol);
  if (compute_field) clock.mark("check");
  if ((data.exact || data.exact_vectorized) && compute_field) {  // 8
    errors<dim>(st, boundary, *current, options, sol);
    clock.mark("errors");
  }
  if (compute_field) {  // 9–10
    quantities_step<dim>(st, boundary, *current, coarse, sol);
    clock.mark("quantities");
  }
  sol.options = options;
  sol.options.multipliers = boundary.spacing().m;
  sol.options.offset = boundary.spacing().offset;
  if (chosen && options.variant == Variant::nonsmooth)
    sol.warnings.push_back(
        "formulation.variant: γ has corners: solved with the non-smooth variant (the smooth one needs a continuous "
        "normal)");
  if (!boundary.spacing().warning.empty()) sol.warnings.push_back(boundary.spacing().warning);
  // Each line once (the fitted solves say again what the first said).
  std::vector<std::string> lines;
  for (std::string& w : sol.warnings)
    if (std::find(lines.begin(), lines.end(), w) == lines.end()) lines.push_back(std::move(w));
  sol.warnings = std::move(lines);
  if (!keep) st.setup.reset();
  return sol;
}

template <int dim>
BasicSolution<dim> solve(const BasicProblem<dim>& problem, SolverOptions options,
                         std::function<void(const std::string& phase, double seconds)> progress,
                         std::function<bool()> interrupt) {
  FictitiousDomainSolver<dim> solver(problem, options);
  solver.set_progress(std::move(progress));
  solver.set_interrupt_check(std::move(interrupt));
  return solver.solve(problem, options, true, false);
}

namespace {

/// Grid nodes and the m a solve will use (the default rule, with γ's length or area), before any
/// array is made.
template <int dim>
std::pair<double, double> nodes_and_multipliers(const BasicProblem<dim>& problem, const SolverOptions& options) {
  const double h = problem.box.width(0) / problem.N;
  double nodes = double(problem.N) + 1;
  for (int d = 1; d < dim; ++d) nodes *= std::floor(problem.box.width(d) / h + 0.5) + 1;
  double m = options.multipliers;
  if constexpr (dim == 2) {
    const double L = problem.gamma ? ArcLengthTable(*problem.gamma, 256).length()
                                   : 2 * (problem.box.width(0) + problem.box.width(1));
    const Variant variant = resolved_variant(options.variant, !problem.gamma || problem.gamma->smooth());
    const double cells = variant == Variant::smooth ? default_spacing_cells_smooth : default_spacing_cells_nonsmooth;
    if (m == 0)
      m = std::max(double(minimum_multipliers), L / (cells * h));
    else if (problem.gamma)
      m = std::min(m, L / (2 * h));  // the most a solve accepts
  } else {
    const double area = problem.gamma ? problem.gamma->area() : 0.0;
    const Variant variant = resolved_variant(options.variant, true);
    if (m == 0)
      m = default_patches(area, h, variant);
    else if (problem.gamma)
      m = std::min(m, area / (4 * h * h));
  }
  return {nodes, m};
}

/// Whether a green solve of `problem` would keep its Schur blocks compressed.
template <int dim>
bool compressed(const BasicProblem<dim>& problem, const SolverOptions& options, double m) {
  return options.inner == InnerSolver::green &&
         compressed_schur(options.schur_storage, dim, m, problem.boundary == Boundary::periodic && problem.c == 0);
}

}  // namespace

template <int dim>
std::size_t estimated_peak_bytes(const BasicProblem<dim>& problem, const SolverOptions& options) {
  const auto [nodes, m] = nodes_and_multipliers(problem, options);
  // Dense: S_B, S_C and the LU's copy. Compressed: S_B and S_C as
  // measured on the sphere (16m²·0.44 at m = 3217, ·0.25 at m = 7238, ·0.16 at m = 12 868:
  // 2600·m^1.27 bytes) and the preconditioner's blocks of 256 points (three matrices), both shared out
  // over the ranks.
  const double P = process_distribution()->size(), arrays = dim == 2 ? 3 : 4;
  const double schur = compressed(problem, options, m)
                           ? (std::min(16 * m * m, 2600 * std::pow(m, 1.27)) + 3 * 8 * 256 * m) / P
                           : 3 * 8 * m * m;
  // On P ranks (one rank's peak, measured at 3-D N = 384 on 2 and 4 ranks, bench/results): 0.8 arrays on
  // every rank (the boundary setup) and 2.4 split, FFTW-MPI's transposes included.
  const double grid = P > 1 ? 8 * nodes * (0.8 + 2.4 / P) : arrays * 8 * nodes;
  const double bytes = grid + schur + 32.0 * (1 << 20);
  return bytes > 1.8e19 ? std::size_t(1.8e19) : std::size_t(bytes);
}

template <int dim>
double estimated_seconds(const BasicProblem<dim>& problem, const SolverOptions& options) {
  const auto [nodes, m] = nodes_and_multipliers(problem, options);
  const double n_log_n = nodes * std::log2(std::max(nodes, 2.0));
  // Calibrated on the benchmark's 2-core machine (bench/results): in 2-D the grid work (load, u₀,
  // Green's table, final solve, errors) costs about 9e-9 s per node·log2(nodes) on one thread, the
  // Schur blocks 2.3e-6 s per pair of points, each Newton step one dense LU of 1e-10·m³ s (8 steps
  // assumed); GMRES about 2.5 m iterations of 2.5 fast solves of 4.6e-10 s per node·log2(nodes).
  // Threads divide it, up to the cores there are. cond₂ of the final Newton matrix (dense storage only)
  // adds about 1.2e-7·m² s for Lanczos (products and LU solves; 3-D m = 906 … 4632 on 2 threads,
  // bench/results/2026-12-07-condition-number.md) and one more LU of S_𝒜, counted always: it is made
  // where Newton's last step went through an update, which the estimate cannot know.
  const double threads = std::clamp(double(Execution(options.threads).threads()), 1.0,
                                    double(std::max(1u, std::thread::hardware_concurrency())));
  double seconds = 0, lu = 0;  // one dense LU of m × m
  if constexpr (dim == 2) {
    lu = 0.5e-10 * m * m * m;
    const double grid = 4.5e-9 * n_log_n, pairs = 1.15e-6 * m * m;
    seconds = options.inner == InnerSolver::green ? grid + pairs + 8 * lu : grid + 2.5 * m * 2.5 * 2.3e-10 * n_log_n;
  } else {
    // 3-D, on 2 threads (the non-smooth sphere of bench/sphere_contact.toml, N = 128 … 768,
    // bench/results/2026-11-28-pruned-products.md): the grid work 5.9e-9 s per node·log2(nodes) and,
    // per point of γ, 3.2e-3 s (the kink correction, the cut voxels' rules, the nested start); the
    // blocks 1.2e-7 s per pair with the far field interpolated (2e-6 exact), compressed
    // 6.7e-5·m·log2(m); Newton one LU of 1.5e-11·m³ and about 18 fast solves (8e-9 per
    // node·log2(nodes)), compressed its fast solves and GMRES on S̃ in 4.5e-9.
    const bool kept_compressed = compressed(problem, options, m);
    lu = 1.5e-11 * m * m * m;
    const double grid = 5.9e-9 * n_log_n + 3.2e-3 * m;
    const double blocks =
        kept_compressed ? 6.7e-5 * m * std::log2(std::max(m, 2.0)) : (options.far_field ? 1.2e-7 : 2e-6) * m * m;
    const double newton = kept_compressed ? 4.5e-9 * n_log_n : lu + 8e-9 * n_log_n;
    seconds = options.inner == InnerSolver::green ? grid + blocks + newton : grid + 2.5 * m * 2.5 * 2.3e-10 * n_log_n;
  }
  if (options.condition_number && options.inner == InnerSolver::green && !compressed(problem, options, m))
    seconds += 1.2e-7 * m * m + lu;
  return seconds * 2 / threads;
}

template class FictitiousDomainSolver<2>;
template class FictitiousDomainSolver<3>;
template BasicSolution<2> solve(const BasicProblem<2>&, SolverOptions, std::function<void(const std::string&, double)>,
                                std::function<bool()>);
template BasicSolution<3> solve(const BasicProblem<3>&, SolverOptions, std::function<void(const std::string&, double)>,
                                std::function<bool()>);
template std::size_t estimated_peak_bytes(const BasicProblem<2>&, const SolverOptions&);
template std::size_t estimated_peak_bytes(const BasicProblem<3>&, const SolverOptions&);
template double estimated_seconds(const BasicProblem<2>&, const SolverOptions&);
template double estimated_seconds(const BasicProblem<3>&, const SolverOptions&);

}  // namespace fictus
