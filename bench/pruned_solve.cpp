// The fast solve of the Schur complement's exact products against the full solve, one run: a load on
// the grid lines that meet a sphere of radius 0.25 in the unit box, read on the same lines
// (DstSolver::solve_in_place_at), and the same solve on every line; best of three each, 3-D.
//   build/bench/fictus_bench_pruned_solve [--N 512] [--threads 2]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "fictus/grid/dst_solver.hpp"
#include "report.hpp"

namespace {

using Clock = std::chrono::steady_clock;

template <class F>
double best_of_three(F&& f) {
  double best = 1e300;
  for (int r = 0; r < 3; ++r) {
    const auto t = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  int N = 512, threads = 2;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string a = argv[k];
    if (a == "--N")
      N = std::stoi(argv[k + 1]);
    else if (a == "--threads")
      threads = std::stoi(argv[k + 1]);
    else {
      std::fprintf(stderr, "fictus_bench_pruned_solve: unknown option %s (options: --N, --threads)\n", a.c_str());
      return 2;
    }
  }
  if (N < 8 || N > 2048 || threads < 1) {
    std::fprintf(stderr, "fictus_bench_pruned_solve: needs 8 <= N <= 2048 and threads >= 1\n");
    return 2;
  }
  const fictus::Grid3 grid(fictus::Box3{{0, 0, 0}, {1, 1, 1}}, N);
  const fictus::DstSolver<3> solver(grid, 1.0, fictus::Execution(threads));
  fictus::GridVector v(grid.n_unknowns(), 0.0);
  const std::size_t columns = grid.n_unknowns() / std::size_t(N - 1);
  fictus::Footprint every{std::vector<char>(columns, 1)}, none{std::vector<char>(columns, 0)}, sphere = none;
  for (int j = 1; j < N; ++j)
    for (int i = 1; i < N; ++i) {
      const double x = grid.x(i) - 0.5, y = grid.y(j) - 0.5;
      if (x * x + y * y < 0.26 * 0.26) sphere.columns[std::size_t(j - 1) * std::size_t(N - 1) + std::size_t(i - 1)] = 1;
    }
  const double full = best_of_three([&] { solver.solve_in_place(v); });
  const double lines_every = best_of_three([&] { solver.solve_in_place_at(v, every, every); });
  const double lines_sphere = best_of_three([&] { solver.solve_in_place_at(v, sphere, sphere); });
  const double lines_none = best_of_three([&] { solver.solve_in_place_at(v, none, none); });
  const double share = double(std::count(sphere.columns.begin(), sphere.columns.end(), 1)) / double(columns);
  std::printf("machine: %s; threads %d; commit %s\n\n", bench::machine().c_str(), threads,
              bench::command_output("git rev-parse --short HEAD 2>/dev/null").c_str());
  std::printf(
      "| N | full solve [s] | by lines, every line [s] | by lines, sphere r = 0.25 (%.0f %% of the columns) [s] "
      "| by lines, fastest axis only [s] |\n|---|---|---|---|---|\n",
      100 * share);
  std::printf("| %d | %.3f | %.3f | %.3f | %.3f |\n", N, full, lines_every, lines_sphere, lines_none);
}
