#include "fictus/grid/distribution.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <string>
#include <utility>

#include "fictus/grid/dst_solver.hpp"
#include "fictus/grid/execution.hpp"

namespace fictus {

namespace {

std::shared_ptr<const Distribution>& process_slot() {
  static std::shared_ptr<const Distribution> slot = std::make_shared<const Distribution>();
  return slot;
}

template <int dim>
std::unique_ptr<FastSolver<dim>> serial_fast_solver(const Grid<dim>& grid, double c, const Execution& execution) {
  if (grid.periodic()) return std::make_unique<PeriodicSolver<dim>>(grid, c, execution);
  return std::make_unique<DstSolver<dim>>(grid, c, execution);
}

[[noreturn]] void serial_only(const char* what) {
  throw std::logic_error(std::string("Distribution::") + what + ": asked of a serial run");
}

}  // namespace

std::shared_ptr<const Distribution> process_distribution() { return std::atomic_load(&process_slot()); }

void set_process_distribution(std::shared_ptr<const Distribution> distribution) {
  if (!distribution) distribution = std::make_shared<const Distribution>();
  std::atomic_store(&process_slot(), std::move(distribution));
}

std::unique_ptr<FastSolver<2>> Distribution::fast_solver(const Grid<2>& grid, double c,
                                                         const Execution& execution) const {
  return serial_fast_solver(grid, c, execution);
}
std::unique_ptr<FastSolver<3>> Distribution::fast_solver(const Grid<3>& grid, double c,
                                                         const Execution& execution) const {
  return serial_fast_solver(grid, c, execution);
}
GridVector Distribution::with_next_layer(const Grid<2>&, const GridVector&) const { serial_only("with_next_layer"); }
GridVector Distribution::with_next_layer(const Grid<3>&, const GridVector&) const { serial_only("with_next_layer"); }
Slab Distribution::transform_planes(const std::vector<int>& shape, std::size_t& local_size) const {
  local_size = 1;
  for (int n : shape) local_size *= std::size_t(n);
  return Slab{0, shape.empty() ? 0 : shape[0]};
}
void Distribution::throw_first_failure(const std::exception_ptr& failure, bool interrupted) const {
  if (!distributed()) {
    if (failure) std::rethrow_exception(failure);
    if (interrupted) throw Interrupted();
    return;
  }
  std::string mine;  // the kind ('a': invalid argument, 'r': another error, 'i': interrupted), the message
  if (failure) try {
      std::rethrow_exception(failure);
    } catch (const std::invalid_argument& e) {
      mine = std::string("a") + e.what();
    } catch (const std::exception& e) {
      mine = std::string("r") + e.what();
    } catch (...) {
      mine = "ran unknown error";
    }
  else if (interrupted)
    mine = "i";
  std::vector<char> bytes(mine.begin(), mine.end());
  bytes.push_back('\0');
  const std::vector<char> all = concatenate(bytes);
  for (std::size_t at = 0, r = 0; at < all.size(); ++r) {
    const std::string first(all.data() + at);
    at += first.size() + 1;
    if (first.empty()) continue;
    if (int(r) == rank() && failure) std::rethrow_exception(failure);
    if (first[0] == 'i') throw Interrupted();
    if (first[0] == 'a') throw std::invalid_argument(first.substr(1));
    throw std::runtime_error(first.substr(1));
  }
}

void Distribution::dct1(const std::vector<int>&, double*, int) const { serial_only("dct1"); }
GridVector Distribution::layers(const Grid<2>&, const GridVector&, Slab) const { serial_only("layers"); }
GridVector Distribution::layers(const Grid<3>&, const GridVector&, Slab) const { serial_only("layers"); }
AlignedVector<double> Distribution::planes(const double* local, Slab mine, std::size_t plane_size,
                                           const std::vector<int>& wanted, std::size_t zeros) const {
  AlignedVector<double> out(wanted.size() * plane_size + zeros, 0.0);
  for (std::size_t t = 0; t < wanted.size(); ++t) {
    if (!mine.holds(wanted[t])) throw std::invalid_argument("planes: a plane that is not held");
    std::copy_n(local + std::size_t(wanted[t] - mine.first) * plane_size, plane_size,
                out.begin() + std::ptrdiff_t(t * plane_size));
  }
  return out;
}
GridVector Distribution::gather(const Grid<2>&, const GridVector& local, bool) const { return local; }
GridVector Distribution::gather(const Grid<3>&, const GridVector& local, bool) const { return local; }

template <int dim>
void read_rows(const SparseRows& rows, const Grid<dim>& grid, const GridVector& u, const Distribution& distribution,
               std::vector<double>& out) {
  if (!distribution.distributed()) return rows.multiply(u, out);
  rows.multiply(u, grid.slab_offset(distribution.slab(grid)), out);
  distribution.sum(out);
}

template <int dim>
void add_rows(const SparseRows& rows, const Grid<dim>& grid, const std::vector<double>& lambda, GridVector& u,
              const Distribution& distribution) {
  if (!distribution.distributed()) return rows.add_transposed(lambda, u);
  rows.add_transposed(lambda, u, grid.slab_offset(distribution.slab(grid)));
}

template void read_rows(const SparseRows&, const Grid<2>&, const GridVector&, const Distribution&,
                        std::vector<double>&);
template void read_rows(const SparseRows&, const Grid<3>&, const GridVector&, const Distribution&,
                        std::vector<double>&);
template void add_rows(const SparseRows&, const Grid<2>&, const std::vector<double>&, GridVector&, const Distribution&);
template void add_rows(const SparseRows&, const Grid<3>&, const std::vector<double>&, GridVector&, const Distribution&);

}  // namespace fictus
