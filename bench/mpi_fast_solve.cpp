// The fast solve on FFTW-MPI slabs against the serial one: one Dirichlet (or periodic) solve of the unit
// box's grid, timed, with each rank's memory. Run it under mpirun for the slab solver:
//   mpirun -np P build/bench/fictus_bench_mpi_solve --dim 3 --N 256 [--threads T] [--repeat 5] [--periodic]
//   build/bench/fictus_bench_mpi_solve --dim 3 --N 256 --path serial --threads 2   (DstSolver, one process)
//   … --at sphere: the Schur complement's product instead (solve_in_place_at, Dirichlet box), its load
//   and readings on the nodes within 2h of the sphere r = 1/4 about the box's centre (a circle in 2-D)
// It prints one Markdown row: the path, ranks, threads, unknowns, the mean and best of `repeat` solves
// after one more, this rank's grid part (its vector's storage (make_vector: on a Dirichlet box the
// solver transforms in it) and the solver's workspace, where it made one), the largest peak
// resident memory of a rank and their sum; --header prints the machine, the libraries and the header.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "fictus/grid/dst_solver.hpp"
#include "fictus/io/process.hpp"
#include "fictus/mpi/slab_solver.hpp"
#include "report.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Arguments {
  int dim = 3, N = 128, threads = 1, repeat = 5;
  bool periodic = false, header = false, at_sphere = false;
  std::string path = "slab";
};

template <int dim>
int run(const Arguments& a, const fictus::mpi::Communicator& comm) {
  fictus::Box<dim> box;
  const fictus::Grid<dim> grid(box, a.N, a.periodic ? fictus::Boundary::periodic : fictus::Boundary::dirichlet);
  const fictus::Execution execution(a.threads);
  std::unique_ptr<fictus::FastSolver<dim>> solver;
  const fictus::mpi::SlabSolver<dim>* slab = nullptr;
  if (a.path == "serial") {
    solver = fictus::make_fast_solver(grid, 1.0, execution);
  } else {
    auto made = std::make_unique<fictus::mpi::SlabSolver<dim>>(grid, 1.0, comm, execution);
    slab = made.get();
    solver = std::move(made);
  }
  fictus::GridVector v = solver->make_vector();
  const std::size_t offset = std::size_t(solver->slab().first) * grid.layer_size();
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::sin(0.37 * double(offset + i));
  // The nodes within 2h of the sphere, as one row: the footprint of its load and of its readings.
  fictus::SparseRows shell;
  for (std::size_t k = 0; k < grid.n_unknowns() && a.at_sphere; ++k) {
    typename fictus::Grid<dim>::Index node{};
    double r2 = 0;
    for (int d = 0, rest = int(k); d < dim; ++d) {
      node[d] = 1 + rest % (grid.n(d) - 1), rest /= grid.n(d) - 1;
      r2 += std::pow(grid.coordinate(d, node[d]) - 0.5, 2);
    }
    if (std::abs(std::sqrt(r2) - 0.25) < 2 * grid.h())
      shell.entries.push_back({grid.index(node), node[0], node[1], dim == 3 ? node[dim - 1] : 0, 1.0});
  }
  shell.row_begin.push_back(shell.entries.size());
  const fictus::Footprint near = fictus::footprint(grid, {&shell});
  std::vector<double> seconds;
  for (int r = 0; r <= a.repeat; ++r) {
    if (a.at_sphere) {  // its load: zero but at the shell's nodes
      std::fill(v.begin(), v.end(), 0.0);
      shell.add_transposed(std::vector<double>{1.0}, v, offset);
    }
    comm.barrier();
    const auto t = Clock::now();
    if (a.at_sphere)
      solver->solve_in_place_at(v, near, near);
    else
      solver->solve_in_place(v);
    comm.barrier();
    if (r > 0) seconds.push_back(std::chrono::duration<double>(Clock::now() - t).count());
  }
  double mean = 0;
  for (double s : seconds) mean += s / double(seconds.size());
  const double best = *std::min_element(seconds.begin(), seconds.end());
  const std::size_t workspace = slab != nullptr ? slab->workspace_bytes() : 0;
  const double grid_part = double(v.capacity() * sizeof(double) + workspace) / (1 << 20);
  const double peak = double(fictus::peak_memory_bytes()) / (1 << 20);
  double total = peak;
  comm.sum(&total, 1);
  const double largest = comm.max(peak), largest_grid_part = comm.max(grid_part);
  if (comm.rank() == 0)
    std::printf("| %s%s | %s | %d | %d | %d | %d | %zu | %.3f | %.3f | %.0f | %.0f | %.0f |\n", a.path.c_str(),
                a.at_sphere ? ", at the sphere" : "", a.periodic ? "periodic" : "Dirichlet", comm.size(), a.threads,
                dim, a.N, grid.n_unknowns(), mean, best, largest_grid_part, largest, total);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const fictus::mpi::Environment environment(argc, argv);
  const fictus::mpi::Communicator comm;
  Arguments a;
  for (int k = 1; k < argc; ++k) {
    const std::string s = argv[k];
    const bool value = k + 1 < argc;
    if (s == "--dim" && value)
      a.dim = std::stoi(argv[++k]);
    else if (s == "--N" && value)
      a.N = std::stoi(argv[++k]);
    else if (s == "--threads" && value)
      a.threads = std::stoi(argv[++k]);
    else if (s == "--repeat" && value)
      a.repeat = std::stoi(argv[++k]);
    else if (s == "--path" && value)
      a.path = argv[++k];
    else if (s == "--periodic")
      a.periodic = true;
    else if (s == "--at" && value && std::string(argv[k + 1]) == "sphere")
      a.at_sphere = true, ++k;
    else if (s == "--header")
      a.header = true;
    else {
      if (comm.rank() == 0)
        std::fprintf(stderr,
                     "fictus_bench_mpi_solve: unknown option %s (--dim, --N, --threads, --repeat, --path "
                     "slab|serial, --periodic, --at sphere, --header)\n",
                     s.c_str());
      return 2;
    }
  }
  if ((a.dim != 2 && a.dim != 3) || a.N < 8 || a.threads < 1 || a.repeat < 1 ||
      (a.path != "slab" && a.path != "serial") || (a.path == "serial" && comm.size() > 1) ||
      (a.at_sphere && a.periodic)) {
    if (comm.rank() == 0)
      std::fprintf(stderr,
                   "fictus_bench_mpi_solve: needs --dim 2 or 3, N >= 8, threads and repeat >= 1, and "
                   "--path serial on one rank only (--at sphere: a Dirichlet box)\n");
    return 2;
  }
  if (a.header && comm.rank() == 0) {
    char mpi_version[MPI_MAX_LIBRARY_VERSION_STRING];
    int length = 0;
    MPI_Get_library_version(mpi_version, &length);
    std::string mpi_line = mpi_version;
    mpi_line = mpi_line.substr(0, mpi_line.find_first_of(",\n"));
    std::printf("machine: %s\ncompiler: g++ %s; %s; %s\ncommit: %s\n\n", bench::machine().c_str(), __VERSION__,
                bench::command_output("dpkg-query -W -f='FFTW ${Version}' libfftw3-dev").c_str(), mpi_line.c_str(),
                bench::command_output("git describe --always --dirty --abbrev=12").c_str());
    std::printf(
        "| path | box | ranks | threads per rank | dim | N | unknowns | solve mean [s] | best [s] | grid part "
        "per rank [MiB] | peak of a rank [MiB] | peaks summed [MiB] "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  }
  return a.dim == 2 ? run<2>(a, comm) : run<3>(a, comm);
}
