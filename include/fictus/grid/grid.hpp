#pragma once
// Uniform Q1 grid on a box Ω ⊂ R^dim with cubic cells of side h.
//
// Nodes are multi-indices i = (i_0, …, i_{dim−1}), 0 ≤ i_d ≤ n_d, at lower + i·h. Unknowns, stored
// with the first coordinate fastest:
//   Dirichlet box (u = 0 on ∂Ω): the interior nodes, index(i) = Σ_d (i_d − 1)·Π_{e<d}(n_e − 1);
//   periodic box: nodes (i_d mod n_d),                 index(i) = Σ_d (i_d mod n_d)·Π_{e<d} n_e.
// Cell c, 0 ≤ c_d < n_d, is Π_d [lower_d + c_d·h, lower_d + (c_d + 1)·h].
// In 2-D, (i, j) = (i_0, i_1), nx = n_0, ny = n_1, x(i), y(j); in 3-D also k, nz, z(k).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "fictus/grid/aligned_vector.hpp"
#include "fictus/grid/point.hpp"

namespace fictus {

enum class Boundary { dirichlet, periodic };
const char* to_string(Boundary b);

/// The unknowns one process holds: the layers first ≤ l < first + count along the grid's slowest axis
/// (Grid::layers), stored as the entries first·layer_size ≤ k < (first + count)·layer_size of the whole
/// grid's vector (Grid::slab_offset). A serial run holds every layer (Grid::every_layer); a run under
/// mpirun holds FFTW-MPI's block of them (mpi/slab_solver.hpp).
struct Slab {
  int first = 0, count = 0;
  bool operator==(const Slab&) const = default;
  bool holds(int layer) const { return layer >= first && layer < first + count; }
};

template <int dim>
class Grid {
 public:
  using Index = std::array<int, dim>;

  /// n0 cells along the first axis; the cell side is h = width(0)/n0 and every other width must be
  /// a whole number of cells (to 1e-9); throws std::invalid_argument naming the field otherwise.
  /// n_d ≥ 2; a periodic box needs even n_d (the Green's table uses the half period).
  Grid(const Box<dim>& box, int n0, Boundary boundary = Boundary::dirichlet) : box_(box), boundary_(boundary) {
    for (int d = 0; d < dim; ++d)
      if (!(box.upper[d] > box.lower[d]))
        throw std::invalid_argument("domain.box: need lower < upper along every axis");
    if (n0 < 2) throw std::invalid_argument("domain.N: need at least 2 cells, got " + std::to_string(n0));
    h_ = box.width(0) / n0;
    n_[0] = n0;
    for (int d = 1; d < dim; ++d) {
      const double cells = box.width(d) / h_;
      n_[d] = cells < 1e9 ? int(std::lround(cells)) : 0;
      if (std::abs(cells - n_[d]) > 1e-9 * std::max(1.0, cells) || n_[d] < 2)
        throw std::invalid_argument("domain.box: every side must be a whole number of cells of side h = (x1 - x0)/N");
    }
    for (int d = 0; d < dim; ++d)
      if (periodic() && n_[d] % 2 != 0)
        throw std::invalid_argument("domain.N: a periodic box needs an even number of cells along every axis");
  }

  const Box<dim>& box() const { return box_; }
  Boundary boundary() const { return boundary_; }
  bool periodic() const { return boundary_ == Boundary::periodic; }
  /// Cells along axis d.
  int n(int d) const { return n_[d]; }
  double h() const { return h_; }
  double coordinate(int d, int i) const { return box_.lower[d] + i * h_; }

  /// Unknowns (Π(n_d − 1) Dirichlet, Π n_d periodic) and all nodes Π(n_d + 1) (the paper's n).
  std::size_t n_unknowns() const {
    std::size_t count = 1;
    for (int d = 0; d < dim; ++d) count *= std::size_t(periodic() ? n_[d] : n_[d] - 1);
    return count;
  }
  /// The unknowns' layers along the slowest axis (dim − 1), and the unknowns in one layer: a process of
  /// a distributed run holds whole layers (Slab, fast_solver.hpp).
  int layers() const { return periodic() ? n_[dim - 1] : n_[dim - 1] - 1; }
  std::size_t layer_size() const { return n_unknowns() / std::size_t(layers()); }
  Slab every_layer() const { return Slab{0, layers()}; }
  /// Where a slab's entries begin in the whole vector, and how many there are.
  std::size_t slab_offset(const Slab& s) const { return std::size_t(s.first) * layer_size(); }
  std::size_t slab_size(const Slab& s) const { return std::size_t(s.count) * layer_size(); }
  /// The layer of a node's unknown (its slowest coordinate, wrapped on a periodic box); precondition
  /// has_unknown(i).
  int layer(int slowest) const { return periodic() ? wrap(slowest, n_[dim - 1]) : slowest - 1; }
  /// The layer that cell layer c (the cells between node layers c and c + 1 of the slowest axis) belongs
  /// to: its lower nodes' (layer 0 for the Dirichlet box's first cells, whose lower nodes carry no
  /// unknown). A rank of a distributed run visits the cells of its layers, which read its layers and the
  /// next one.
  int cell_layer(int c) const { return periodic() ? c : std::max(c - 1, 0); }
  /// Where node i's unknown is in a vector that holds slab s's layers and then the next layer (the next
  /// after a periodic box's last layer is layer 0): the whole vector's index for every_layer();
  /// precondition has_unknown(i) and i's layer held there.
  std::size_t slab_index(const Index& i, const Slab& s) const {
    const int l = layer(i[dim - 1]);
    return index(i) - std::size_t(s.first) * layer_size() + (l < s.first ? n_unknowns() : 0);
  }
  std::size_t n_nodes() const {
    std::size_t count = 1;
    for (int d = 0; d < dim; ++d) count *= std::size_t(n_[d] + 1);
    return count;
  }

  /// Does node i, 0 ≤ i_d ≤ n_d, carry an unknown?
  bool has_unknown(const Index& i) const {
    if (periodic()) return true;
    bool inside = true;
    for (int d = 0; d < dim; ++d) inside = inside && i[d] > 0 && i[d] < n_[d];
    return inside;
  }
  /// Storage index of node i; precondition has_unknown(i).
  std::size_t index(const Index& i) const {
    std::size_t k = 0;
    if (periodic()) {
      for (int d = dim - 1; d >= 0; --d) k = k * std::size_t(n_[d]) + std::size_t(wrap(i[d], n_[d]));
    } else {
      for (int d = dim - 1; d >= 0; --d) k = k * std::size_t(n_[d] - 1) + std::size_t(i[d] - 1);
    }
    return k;
  }
  /// The cell along axis d containing coordinate x, clamped to the grid (NaN: 0); cells are half-open.
  int cell(int d, double x) const {
    const double c = std::floor((x - box_.lower[d]) / h_);
    if (!(c > 0)) return 0;
    return c >= n_[d] - 1 ? n_[d] - 1 : int(c);
  }

  // The axes by name.
  int nx() const { return n_[0]; }
  int ny() const requires(dim >= 2) { return n_[1]; }
  int nz() const requires(dim >= 3) { return n_[2]; }
  double x(int i) const { return coordinate(0, i); }
  double y(int j) const requires(dim >= 2) { return coordinate(1, j); }
  double z(int k) const requires(dim >= 3) { return coordinate(2, k); }
  int cell_x(double x) const { return cell(0, x); }
  int cell_y(double y) const requires(dim >= 2) { return cell(1, y); }
  int cell_z(double z) const requires(dim >= 3) { return cell(2, z); }
  // The same as has_unknown(Index)/index(Index), written out for the innermost 2-D loops.
  bool has_unknown(int i, int j) const requires(dim == 2) {
    return periodic() || (i > 0 && i < n_[0] && j > 0 && j < n_[1]);
  }
  std::size_t index(int i, int j) const requires(dim == 2) {
    if (periodic()) return std::size_t(wrap(j, n_[1])) * std::size_t(n_[0]) + std::size_t(wrap(i, n_[0]));
    return std::size_t(j - 1) * std::size_t(n_[0] - 1) + std::size_t(i - 1);
  }
  bool has_unknown(int i, int j, int k) const requires(dim == 3) { return has_unknown(Index{i, j, k}); }
  std::size_t index(int i, int j, int k) const requires(dim == 3) { return index(Index{i, j, k}); }

 private:
  static int wrap(int i, int n) { return ((i % n) + n) % n; }
  Box<dim> box_;
  Boundary boundary_;
  std::array<int, dim> n_{};
  double h_ = 0;
};

using Grid2 = Grid<2>;
using Grid3 = Grid<3>;

/// Nodal values at the unknowns, in Grid::index order, aligned for the fast transforms.
using GridVector = AlignedVector<double>;

/// Value at p of the Q1 function with nodal values u at the unknowns (zero on a Dirichlet ∂Ω).
double evaluate_q1(const Grid2& grid, const GridVector& u, Point2 p);

}  // namespace fictus
