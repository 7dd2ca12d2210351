// fictus benchmark: the paper's problem at h = 1/512 … 1/4096 with both inner solvers, the green
// path on larger grids, the time of one DST-I of each grid measured in the same run, 1 vs 2
// threads per phase, parameter sweeps, and the trace rules and m rule compared in one run. Writes a Markdown report
// (machine, compiler, threads, commit beside every figure). Not part of the test suite: `make bench`.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fictus/grid/dst_solver.hpp"
#include "fictus/io/process.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/paper_problem.hpp"
#include "report.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

using bench::command_output;
using bench::format;

/// Best of `repeats` in-place 2-D DST-I (RODFT00) of the grid's unknowns.
double dst1_seconds(int N, int threads, int repeats = 3) {
  const fictus::Grid2 grid(fictus::Box2{}, N);
  const fictus::DstSolver<2> solver(grid, 1.0, fictus::Execution(threads));
  fictus::GridVector v(grid.n_unknowns(), 1.0);
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto t = Clock::now();
    solver.transform(v);
    best = std::min(best, since(t));
  }
  return best;
}

struct Run {
  int N;
  fictus::Variant variant;
  fictus::InnerSolver inner;
  int threads;
  std::unique_ptr<fictus::Solution> solution;
};

Run run(int N, fictus::Variant variant, fictus::InnerSolver inner, int threads,
        fictus::NormalDerivative traces = fictus::NormalDerivative::reconstructed, bool default_m = false) {
  // The paper's m and δ = L/m, or fictus's defaults (s = 8h smooth, 12h non-smooth; δ = 2·s).
  fictus::SolverOptions o = fictus::paper_options(N, variant);
  if (default_m) o.multipliers = 0, o.offset = fictus::SolverOptions{}.offset;
  o.normal_derivative = traces;
  o.inner = inner;
  o.threads = threads;
  o.condition_number = false;
  o.error_estimate = false;    // the paper's method, as the tables time it
  o.krylov_tolerance = 1e-12;  // so that both paths give λ to ~1e-9 (cond S up to 1e4)
  std::fprintf(stderr, "  N = %d, %s, %s, %d thread(s)...\n", N, fictus::to_string(variant), fictus::to_string(inner),
               threads);
  auto s = std::make_unique<fictus::Solution>(fictus::solve(fictus::paper_problem(N), o));
  s->peak_memory_bytes = fictus::peak_memory_bytes();
  return {N, variant, inner, threads, std::move(s)};
}

const char* phase_names[] = {"load",   "u0",          "geometry", "green_table", "schur",
                             "newton", "final_solve", "check",    "errors"};

std::string phase_cells(const fictus::Solution& s) {
  std::string out;
  for (const char* p : phase_names) out += format(" %.3f |", s.timings[p]);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_dir = "bench/results";
  int max_level = 14, krylov_max_level = 12, threads = 2;
  std::string sections = "all";
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    auto next = [&]() -> std::string {
      if (k + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++k];
    };
    if (a == "--out")
      out_dir = next();
    else if (a == "--max-level")
      max_level = std::stoi(next());
    else if (a == "--krylov-max-level")
      krylov_max_level = std::stoi(next());
    else if (a == "--threads")
      threads = std::stoi(next());
    else if (a == "--sections")
      sections = next();
    else {
      std::fprintf(stderr,
                   "usage: fictus_bench [--out DIR] [--max-level 14] [--krylov-max-level 12] [--threads 2] "
                   "[--sections all|traces]\n");
      return 1;
    }
  }
  const std::string machine = bench::machine();
  const std::string commit = command_output("git rev-parse --short HEAD 2>/dev/null");
  const std::string compiler = std::string("g++ ") + __VERSION__ + " -O3 (Release)";
  char date[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d", std::gmtime(&now));
  std::ostringstream md;
  md << "# fictus benchmark, " << date << "\n\n"
     << "- machine: " << machine << "\n- compiler: " << compiler << ", FFTW 3.3 (ESTIMATE plans)\n"
     << "- commit: " << commit << "\n- threads: " << threads << " unless a table says otherwise\n"
     << "- problem: the paper's (docs/reproduction.md), m as in the paper (default rule above 1/4096); "
        "Krylov tolerance 1e-12; times in seconds, one run each\n\n";

  // 0. Trace rules and m rule in one run: the paper's shifted C_γ against the reconstructed traces
  //    (same m), and the default m (s = 8h or 12h, δ = 2s) against the paper's m; median of 3.
  md << "## Trace rules and m rule (same run, median of 3, " << threads << " threads)\n\n"
     << "| h | variant | traces | m | total |";
  for (const char* p : phase_names) md << ' ' << p << " |";
  md << " rel L2(w) |\n|---|---|---|---|---|";
  for (std::size_t k = 0; k < std::size(phase_names); ++k) md << "---|";
  md << "---|\n";
  for (int N : {1024, 2048, 4096}) {
    if (N > (1 << max_level)) break;
    for (fictus::Variant v : {fictus::Variant::nonsmooth, fictus::Variant::smooth})
      for (int config = 0; config < 3; ++config) {
        const auto traces = config == 0 ? fictus::NormalDerivative::shifted : fictus::NormalDerivative::reconstructed;
        std::vector<Run> repeats;
        for (int r = 0; r < 3; ++r)
          repeats.push_back(run(N, v, fictus::InnerSolver::green, threads, traces, config == 2));
        std::sort(repeats.begin(), repeats.end(),
                  [](const Run& a, const Run& b) { return a.solution->timings.total < b.solution->timings.total; });
        const fictus::Solution& s = *repeats[1].solution;
        md << format("| 1/%d | %s | %s | %d%s | %.3f |", N, fictus::to_string(v), fictus::to_string(traces),
                     s.collocation.m, config == 2 ? " (default)" : " (paper)", s.timings.total)
           << phase_cells(s) << format(" %.3e |\n", s.errors->rel_l2_omega);
      }
  }
  md << "\n";
  if (sections == "traces") {
    std::printf("%s", md.str().c_str());
    return 0;
  }

  // 1. Both variants, both inner solvers, with the DST-I reference of each grid.
  md << "## End to end, both inner solvers\n\n"
     << "| h | variant | inner | it0/it1 | total | DST-I | total / DST-I |";
  for (const char* p : phase_names) md << ' ' << p << " |";
  md << " rel L2(w) | peak MiB |\n|---|---|---|---|---|---|---|";
  for (std::size_t k = 0; k < std::size(phase_names); ++k) md << "---|";
  md << "---|---|\n";
  std::map<std::pair<int, int>, std::pair<const fictus::Solution*, const fictus::Solution*>> pairs;
  std::vector<Run> runs;
  std::map<int, double> dst_time;
  for (int level = 9; level <= max_level; ++level) {
    const int N = 1 << level;
    dst_time[N] = dst1_seconds(N, threads);
    for (fictus::Variant v : {fictus::Variant::nonsmooth, fictus::Variant::smooth}) {
      for (fictus::InnerSolver inner : {fictus::InnerSolver::green, fictus::InnerSolver::krylov}) {
        if (inner == fictus::InnerSolver::krylov && level > krylov_max_level) continue;
        runs.push_back(run(N, v, inner, threads));
        const fictus::Solution& s = *runs.back().solution;
        md << format("| 1/%d | %s | %s | %d/%zu | %.3f | %.3f | %.1f |", N, fictus::to_string(v),
                     fictus::to_string(inner), s.newton.iterations, s.fast_solves, s.timings.total, dst_time[N],
                     s.timings.total / dst_time[N])
           << phase_cells(s) << format(" %.3e | %.0f |\n", s.errors->rel_l2_omega, s.peak_memory_bytes / 1048576.0);
        md.flush();
      }
    }
  }
  // 2. Green against Krylov: speed and agreement.
  md << "\n## green vs krylov (same run)\n\n| h | variant | time green | time krylov | speed-up | max rel diff of λ | "
        "active sets |\n|---|---|---|---|---|---|---|\n";
  for (const Run& a : runs) {
    if (a.inner != fictus::InnerSolver::green) continue;
    for (const Run& b : runs) {
      if (b.inner != fictus::InnerSolver::krylov || b.N != a.N || b.variant != a.variant) continue;
      const auto& la = a.solution->lambda;
      const auto& lb = b.solution->lambda;
      double diff = 0, scale = 0;
      for (std::size_t i = 0; i < la.size(); ++i) {
        diff = std::max(diff, std::abs(la[i] - lb[i]));
        scale = std::max(scale, std::abs(la[i]));
      }
      md << format("| 1/%d | %s | %.3f | %.3f | %.0fx | %.1e | %s |\n", a.N, fictus::to_string(a.variant),
                   a.solution->timings.total, b.solution->timings.total,
                   b.solution->timings.total / a.solution->timings.total, diff / scale,
                   a.solution->newton.active == b.solution->newton.active ? "identical" : "DIFFERENT");
    }
  }
  // 3. Threads: 1 vs 2 per phase at h = 1/4096 (only when --max-level reaches it).
  if (max_level >= 12) {
    md << "\n## 1 vs 2 threads per phase, h = 1/4096, smooth, green\n\n| threads | total |";
    for (const char* p : phase_names) md << ' ' << p << " |";
    md << "\n|---|---|";
    for (std::size_t k = 0; k < std::size(phase_names); ++k) md << "---|";
    md << "\n";
    Run one = run(4096, fictus::Variant::smooth, fictus::InnerSolver::green, 1);
    Run two = run(4096, fictus::Variant::smooth, fictus::InnerSolver::green, 2);
    for (const Run* r : {&one, &two})
      md << format("| %d | %.3f |", r->threads, r->solution->timings.total) << phase_cells(*r->solution) << "\n";
    md << "| speed-up | " << format("%.2f", one.solution->timings.total / two.solution->timings.total) << " |";
    for (const char* p : phase_names) {
      const double a = one.solution->timings[p], b = two.solution->timings[p];
      md << (b > 0 ? format(" %.2f |", a / b) : std::string(" – |"));
    }
    md << "\n";
  }
  // 4. Sweeps at h = 1/1024 on one solver: 100 obstacles (boundary quantities only), 20 rotations.
  md << "\n## Sweeps on one grid, h = 1/1024, smooth, green, boundary quantities only\n\n| sweep | problems | first "
        "[s] | per problem after the first [s] | problems per second |\n|---|---|---|---|---|\n";
  for (const std::string kind : {"100 obstacles g·s, s ∈ [0.5, 1.5]", "20 rotations of γ, [0, 0.5] rad"}) {
    const bool obstacles = kind[0] == '1';
    const int count = obstacles ? 100 : 20;
    const fictus::Problem base = fictus::paper_problem(1024);
    fictus::SolverOptions o = fictus::paper_options(1024, fictus::Variant::smooth);  // as `fictus sweep`
    o.threads = threads;
    o.condition_number = false;
    fictus::FictitiousDomainSolver solver(base, o);
    double first = 0, rest = 0;
    for (int k = 0; k < count; ++k) {
      fictus::Problem p = base;
      const double v = obstacles ? 0.5 + k / 99.0 : 0.5 * k / 19.0;
      if (obstacles)
        p.g = [g = base.g, v](double x, double y) { return v * g(x, y); };
      else
        p.gamma = std::make_shared<fictus::TransformedCurve>(base.gamma, v, fictus::Point2{0, 0});
      const auto t = Clock::now();
      const fictus::Solution s = solver.solve(p, o, false);
      (k == 0 ? first : rest) += since(t);
      if (!s.newton.converged) std::fprintf(stderr, "sweep: not converged at %g\n", v);
    }
    md << format("| %s | %d | %.3f | %.4f | %.1f |\n", kind.c_str(), count, first, rest / (count - 1),
                 (count - 1) / rest);
  }
  std::filesystem::create_directories(out_dir);
  // A report already there (committed, of the same day and host) is kept: the new one gets -2, -3, …
  const std::string stem = out_dir + "/" + date + "-" + command_output("hostname");
  std::string path = stem + ".md";
  for (int k = 2; std::filesystem::exists(path); ++k) path = stem + "-" + std::to_string(k) + ".md";
  std::ofstream(path) << md.str();
  std::printf("%s\nwrote %s\n", md.str().c_str(), path.c_str());
  return 0;
}
