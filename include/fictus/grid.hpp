#pragma once
// Uniform Q1 grid on the box Ω = [x0,x1]×[y0,y1] with square cells of side h.
//
// Nodes are (i, j), i = 0..nx, j = 0..ny, at (x0 + i·h, y0 + j·h). Unknowns, stored x-fastest:
//   Dirichlet box (u = 0 on ∂Ω): the interior nodes, index(i, j) = (j − 1)·(nx − 1) + (i − 1);
//   periodic box: nodes (i mod nx, j mod ny),     index(i, j) = (j mod ny)·nx + (i mod nx).
// Cell (ix, iy), ix = 0..nx−1, iy = 0..ny−1, is [x0 + ix·h, x0 + (ix+1)·h] × [y0 + iy·h, …].
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fictus/aligned_vector.hpp"

namespace fictus {

struct Point {
  double x = 0.0;
  double y = 0.0;
};

inline Point operator+(Point a, Point b) { return {a.x + b.x, a.y + b.y}; }
inline Point operator-(Point a, Point b) { return {a.x - b.x, a.y - b.y}; }
inline Point operator*(double s, Point a) { return {s * a.x, s * a.y}; }
inline double dot(Point a, Point b) { return a.x * b.x + a.y * b.y; }
inline double norm(Point a) { return std::hypot(a.x, a.y); }

struct Box {
  double x0 = 0.0, x1 = 1.0, y0 = 0.0, y1 = 1.0;
};

enum class Boundary { dirichlet, periodic };
const char* to_string(Boundary b);

class Grid {
 public:
  /// nx cells along x; the cell side is h = (x1 − x0)/nx and (y1 − y0)/h must be an integer
  /// (to 1e-9); throws std::invalid_argument naming the field otherwise. nx ≥ 2 and ny ≥ 2.
  /// A periodic box needs even nx and ny (the Green's table uses the half period).
  Grid(const Box& box, int nx, Boundary boundary = Boundary::dirichlet);

  const Box& box() const { return box_; }
  Boundary boundary() const { return boundary_; }
  bool periodic() const { return boundary_ == Boundary::periodic; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  double h() const { return h_; }
  double x(int i) const { return box_.x0 + i * h_; }
  double y(int j) const { return box_.y0 + j * h_; }

  /// Unknowns ((nx − 1)(ny − 1) Dirichlet, nx·ny periodic) and all nodes (nx + 1)(ny + 1) (the
  /// paper's n).
  std::size_t n_unknowns() const {
    return periodic() ? std::size_t(nx_) * std::size_t(ny_) : std::size_t(nx_ - 1) * std::size_t(ny_ - 1);
  }
  std::size_t n_nodes() const { return std::size_t(nx_ + 1) * std::size_t(ny_ + 1); }

  /// Does node (i, j), 0 ≤ i ≤ nx, 0 ≤ j ≤ ny, carry an unknown?
  bool has_unknown(int i, int j) const { return periodic() || (i > 0 && i < nx_ && j > 0 && j < ny_); }
  /// Storage index of node (i, j); precondition has_unknown(i, j).
  std::size_t index(int i, int j) const {
    if (periodic()) return std::size_t(wrap(j, ny_)) * std::size_t(nx_) + std::size_t(wrap(i, nx_));
    return std::size_t(j - 1) * std::size_t(nx_ - 1) + std::size_t(i - 1);
  }

  /// Cell containing (x, y), clamped to the grid: cells are half-open [x_i, x_{i+1}).
  int cell_x(double x) const;
  int cell_y(double y) const;

 private:
  static int wrap(int i, int n) { return ((i % n) + n) % n; }
  Box box_;
  Boundary boundary_;
  int nx_, ny_;
  double h_;
};

/// Nodal values at the interior nodes, in Grid::index order, aligned for FFTW.
using GridVector = AlignedVector<double>;

/// Value at (x, y) of the Q1 function with interior nodal values u (zero on ∂Ω).
double evaluate_q1(const Grid& grid, const GridVector& u, Point p);

}  // namespace fictus
