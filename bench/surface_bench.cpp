// fictus 3-D benchmark: the manufactured sphere (tests/convergence/manufactured3d.py), both variants,
// end to end per phase with peak memory at N = 64 … --max-N (non-smooth up to 256), the exact and the
// far-field assembly of S compared in the same run at N = 128, Newton's two starts at N = 256, and the green and krylov
// inner solvers at N = 64. Writes a Markdown report (machine, compiler, threads, commit beside the figures). Not part
// of the test suite: `make bench`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fictus/io/process.hpp"
#include "manufactured_solutions_3d.hpp"
#include "report.hpp"

namespace {

using bench::command_output;
using bench::format;

bool peak_per_run = true;  // the peak memory of each run alone (else the process's so far)

fictus::SurfaceSolution run(int N, fictus::SolverOptions o) {
  const fictus::SurfaceProblem p = manufactured3d::all(N).front().problem;  // the sphere
  o.condition_number = false;  // dense only: it would weigh on one storage's time and not the other's
  peak_per_run = peak_per_run && fictus::reset_peak_memory();
  fictus::SurfaceSolution s = fictus::solve(p, o);
  s.peak_memory_bytes = fictus::peak_memory_bytes();
  if (!s.newton.converged) std::fprintf(stderr, "N = %d: Newton did not converge: %s\n", N, s.newton.failure.c_str());
  return s;
}

double far_fraction(const fictus::SurfaceSolution& s) {
  if (!s.far_field) return 0;
  const fictus::FarFieldReport& a = s.far_field->assembly;
  return a.far_pairs / (a.far_pairs + a.near_pairs);
}

/// max |a − b| / max |b|
double max_relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double largest = 0, difference = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    largest = std::max(largest, std::abs(b[i]));
    difference = std::max(difference, std::abs(a[i] - b[i]));
  }
  return difference / largest;
}

const char* phases[] = {"nested_start", "load",  "u0",     "geometry",    "kink_correction", "flux_balance",
                        "green_table",  "schur", "newton", "final_solve", "errors"};

}  // namespace

int main(int argc, char** argv) {
  std::string out_dir = "bench/results";
  int max_N = 256, threads = 2;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--out" && k + 1 < argc)
      out_dir = argv[++k];
    else if (a == "--max-N" && k + 1 < argc)
      max_N = std::stoi(argv[++k]);
    else if (a == "--threads" && k + 1 < argc)
      threads = std::stoi(argv[++k]);
    else {
      std::fprintf(stderr, "usage: fictus_bench_3d [--out DIR] [--max-N 256] [--threads 2]\n");
      return 1;
    }
  }
  const std::string machine = bench::machine();
  char date[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d", std::gmtime(&now));
  std::ostringstream md;
  md << "# fictus 3-D benchmark, " << date << "\n\n"
     << "- machine: " << machine << "\n- compiler: g++ " << __VERSION__ << " -O3 (Release), FFTW 3.3\n"
     << "- commit: " << command_output("git rev-parse --short HEAD 2>/dev/null") << "\n- threads: " << threads
     << "\n- problem: the manufactured sphere (r = 0.3, contact boundary a plane section in general position, "
        "∂²u/∂n² ≠ 0 on the free part), default m (patches of 5h smooth, 4h non-smooth) and δ = 1.5 s; one run per "
        "row; peak memory: see the end of the report\n\n";

  // The non-smooth variant stops at N = 256: with patches of 4h its m is 18 530 at N = 512, where the
  // dense Newton matrices (2.7 GB each) and their LUs (about 160 s each) make a 20-minute run
  // (docs/notes/3d-far-field-and-newton.md, "End to end").
  for (const fictus::Variant variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    const bool smooth = variant == fictus::Variant::smooth;
    md << (smooth ? "## End to end, smooth variant, green inner solver\n\n"
                  : "\n## End to end, non-smooth variant (kink correction, patches of 4h), green inner solver\n\n")
       << "| N | unknowns | m | Newton | exact steps | LUs | fast solves | far pairs | total [s]";
    for (const char* p : phases) md << " | " << p;
    md << " | rel L2(ω) | rel L2(γ) | peak MiB |\n|---|---|---|---|---|---|---|---|---";
    for (std::size_t k = 0; k < std::size(phases) + 3; ++k) md << "|---";
    md << "|\n";
    for (int N = 64; N <= (smooth ? max_N : std::min(max_N, 256)); N *= 2) {
      fictus::SolverOptions o;
      o.threads = threads;
      o.variant = variant;
      const fictus::SurfaceSolution s = run(N, o);
      md << format("| %d | %zu | %d | %d | %d | %d | %zu | %.1f %% | %.2f", N, s.grid.n_unknowns(),
                   s.options.multipliers, s.newton.iterations, s.far_field ? s.far_field->exact_steps : 0,
                   s.factorizations, s.fast_solves, 100 * far_fraction(s), s.timings.total);
      for (const char* p : phases) md << format(" | %.2f", s.timings[p]);
      md << format(" | %.3e | %.3e | %.0f |\n", s.errors->rel_l2_omega, s.errors->rel_l2_gamma,
                   s.peak_memory_bytes / 1048576.0);
      std::fflush(stdout);
    }
  }

  // The two assemblies of S in one run: every pair exact, or the far pairs interpolated (then Newton
  // finishes on the exact S).
  md << "\n## Explicit Schur complement: exact assembly vs interpolated far field (same run, N = 128)\n\n"
     << "| variant | far_field | m | Newton | exact steps | fast solves | schur [s] | newton [s] | total [s] | rel "
        "L2(ω) |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const fictus::Variant variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    fictus::SolverOptions o;
    o.threads = threads;
    o.variant = variant;
    o.far_field = false;
    const fictus::SurfaceSolution exact = run(128, o);
    o.far_field = true;
    const fictus::SurfaceSolution far = run(128, o);
    for (const fictus::SurfaceSolution* s : {&exact, &far})
      md << format("| %s | %s | %d | %d | %d | %zu | %.2f | %.2f | %.2f | %.3e |\n", fictus::to_string(variant),
                   s->options.far_field ? "true" : "false", s->options.multipliers, s->newton.iterations,
                   s->far_field ? s->far_field->exact_steps : 0, s->fast_solves, s->timings["schur"],
                   s->timings["newton"], s->timings.total, s->errors->rel_l2_omega);
    md << format("\n%s: max |λ_far − λ_exact| / max |λ| = %.2e; active sets %s; schur %.1f× faster, total %.1f×\n\n",
                 fictus::to_string(variant), max_relative_difference(far.lambda, exact.lambda),
                 far.newton.active == exact.newton.active ? "identical" : "DIFFERENT",
                 exact.timings["schur"] / far.timings["schur"], exact.timings.total / far.timings.total);
  }
  // Newton's start: from every point active, or from the N/2 solve's active set (solver.nested_start,
  // the default from N = 160 on).
  if (max_N >= 256) {
    md << "\n## Newton's start: all active vs nested (same run, N = 256, non-smooth variant)\n\n"
       << "| start | Newton | exact steps | LUs | fast solves | nested_start [s] | newton [s] | total [s] | rel L2(ω) "
          "|\n|---|---|---|---|---|---|---|---|---|\n";
    fictus::SolverOptions o;
    o.threads = threads;
    o.variant = fictus::Variant::nonsmooth;
    o.nested_start = 0;
    const fictus::SurfaceSolution plain = run(256, o);
    o.nested_start = fictus::SolverOptions{}.nested_start;
    const fictus::SurfaceSolution nested = run(256, o);
    for (const fictus::SurfaceSolution* s : {&plain, &nested})
      md << format(
          "| %s | %d | %d | %d | %zu | %.2f | %.2f | %.2f | %.3e |\n",
          !s->nested_start                   ? "all"
          : s->nested_start->skipped.empty() ? "nested"
                                             : ("all (no nested start: " + s->nested_start->skipped + ")").c_str(),
          s->newton.iterations, s->far_field ? s->far_field->exact_steps : 0, s->factorizations, s->fast_solves,
          s->timings["nested_start"], s->timings["newton"], s->timings.total, s->errors->rel_l2_omega);
    md << format("\nmax |λ_nested − λ_all| / max |λ| = %.2e; active sets %s; the N/2 solve took %d Newton steps\n",
                 max_relative_difference(nested.lambda, plain.lambda),
                 nested.newton.active == plain.newton.active ? "identical" : "DIFFERENT",
                 nested.nested_start ? nested.nested_start->newton_steps : 0);
  }
  md << "\n## green vs krylov (same run, N = 64, m = 129, Krylov tolerance 1e-12)\n\n"
     << "| inner | Newton | fast solves | Krylov iterations | schur [s] | newton [s] | total [s] |\n"
     << "|---|---|---|---|---|---|---|\n";
  fictus::SolverOptions o;
  o.threads = threads;
  o.multipliers = 129;
  const fictus::SurfaceSolution green = run(64, o);
  o.inner = fictus::InnerSolver::krylov;
  o.krylov_tolerance = 1e-12;
  const fictus::SurfaceSolution krylov = run(64, o);
  for (const fictus::SurfaceSolution* s : {&green, &krylov})
    md << format("| %s | %d | %zu | %d | %.2f | %.2f | %.2f |\n", fictus::to_string(s->options.inner),
                 s->newton.iterations, s->fast_solves, s->inner_iterations, s->timings["schur"], s->timings["newton"],
                 s->timings.total);
  md << format("\nmax |λ_green − λ_krylov| / max |λ| = %.2e; active sets %s; speed-up of green %.1f×\n",
               max_relative_difference(green.lambda, krylov.lambda),
               green.newton.active == krylov.newton.active ? "identical" : "DIFFERENT",
               krylov.timings.total / green.timings.total);

  md << (peak_per_run ? "\npeak MiB: the resident peak of each run alone (VmHWM reset before it).\n"
                      : "\npeak MiB: the resident peak of the process so far (this system did not let the bench "
                        "reset it between runs).\n");
  std::filesystem::create_directories(out_dir);
  const std::string stem = out_dir + "/" + date + "-3d-" + command_output("hostname");
  std::string path = stem + ".md";
  for (int k = 2; std::filesystem::exists(path); ++k) path = stem + "-" + std::to_string(k) + ".md";
  std::ofstream(path) << md.str();
  std::printf("%s\nwrote %s\n", md.str().c_str(), path.c_str());
  return 0;
}
