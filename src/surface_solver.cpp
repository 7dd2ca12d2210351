#include "fictus/surface_solver.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "fictus/fast_solver.hpp"
#include "fictus/green_table.hpp"
#include "fictus/q1_element.hpp"
#include "fictus/quadrature.hpp"
#include "fictus/schur_complement.hpp"
#include "fictus/spacing_rule.hpp"
#include "fictus/surface_kink.hpp"
#include "fictus/trace_operators.hpp"
#include "solve_steps.hpp"

namespace fictus {

// ---------------------------------------------------------------------------------------------
// Surfaces

Matrix3 Surface::level_hessian(const Point3& p) const {
  const Box3 box = bounds();
  const double step = 1e-5 * std::max({box.width(0), box.width(1), box.width(2)});
  Matrix3 H;
  for (int d = 0; d < 3; ++d) {
    Point3 plus = p, minus = p;
    plus[d] += step;
    minus[d] -= step;
    const Point3 column = (0.5 / step) * (level_gradient(plus) - level_gradient(minus));
    for (int e = 0; e < 3; ++e) H[e][d] = column[e];
  }
  for (int d = 0; d < 3; ++d)  // symmetric
    for (int e = 0; e < d; ++e) H[d][e] = H[e][d] = 0.5 * (H[d][e] + H[e][d]);
  return H;
}

Ellipsoid::Ellipsoid(Point3 center, Point3 semi_axes) : center_(center), semi_axes_(semi_axes) {
  for (int d = 0; d < 3; ++d) {
    if (!std::isfinite(center[d])) throw std::invalid_argument("geometry.center: must be finite");
    if (!(semi_axes[d] > 0) || !std::isfinite(semi_axes[d]))
      throw std::invalid_argument("geometry.semi_axes: must be positive and finite");
  }
}

double Ellipsoid::level(const Point3& p) const {
  double sum = -1.0;
  for (int d = 0; d < 3; ++d) {
    const double t = (p[d] - center_[d]) / semi_axes_[d];
    sum += t * t;
  }
  return sum;
}

Point3 Ellipsoid::level_gradient(const Point3& p) const {
  Point3 g;
  for (int d = 0; d < 3; ++d) g[d] = 2 * (p[d] - center_[d]) / (semi_axes_[d] * semi_axes_[d]);
  return g;
}

Matrix3 Ellipsoid::level_hessian(const Point3&) const {
  Matrix3 H{};
  for (int d = 0; d < 3; ++d) H[d][d] = 2 / (semi_axes_[d] * semi_axes_[d]);
  return H;
}

PatchedSurface Ellipsoid::patches(int m, double edge) const { return ellipsoid_patches(center_, semi_axes_, m, edge); }

double Ellipsoid::area() const {
  // Knud Thomsen's formula (within 1.1 %; exact for a sphere): enough for the default m.
  const double a = semi_axes_.x, b = semi_axes_.y, c = semi_axes_.z, p = 1.6075;
  return 4 * std::numbers::pi * std::pow((std::pow(a * b, p) + std::pow(a * c, p) + std::pow(b * c, p)) / 3, 1 / p);
}

Box3 Ellipsoid::bounds() const {
  Box3 box;
  box.lower = center_ - semi_axes_;
  box.upper = center_ + semi_axes_;
  return box;
}

Torus::Torus(Point3 center, double R, double r) : center_(center), R_(R), r_(r) {
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(center[d])) throw std::invalid_argument("geometry.center: must be finite");
  if (!(r > 0 && R > r && std::isfinite(R))) throw std::invalid_argument("geometry.radii: need 0 < r < R, finite");
}

double Torus::level(const Point3& p) const {
  const Point3 d = p - center_;
  const double planar = std::hypot(d.x, d.y) - R_;
  return (planar * planar + d.z * d.z - r_ * r_) / (2 * r_);  // ≈ the signed distance near γ
}

Point3 Torus::level_gradient(const Point3& p) const {
  const Point3 d = p - center_;
  const double rho = std::hypot(d.x, d.y);
  const double scale = rho > 0 ? (rho - R_) / rho : 0.0;  // the z-axis, far inside the hole: no radial part
  return (1.0 / r_) * Point3{scale * d.x, scale * d.y, d.z};
}

Matrix3 Torus::level_hessian(const Point3& p) const {
  const Point3 d = p - center_;
  const double rho = std::hypot(d.x, d.y);
  Matrix3 H{};
  H[2][2] = 1 / r_;
  if (rho == 0) return H;  // the axis, far inside the hole
  const double radial = (1 - R_ / rho) / r_, bend = R_ / (rho * rho * rho * r_);
  H[0][0] = radial + bend * d.x * d.x;
  H[1][1] = radial + bend * d.y * d.y;
  H[0][1] = H[1][0] = bend * d.x * d.y;
  return H;
}

PatchedSurface Torus::patches(int m, double edge) const { return torus_patches(center_, R_, r_, m, edge); }

double Torus::area() const { return 4 * std::numbers::pi * std::numbers::pi * R_ * r_; }

Box3 Torus::bounds() const {
  Box3 box;
  box.lower = center_ - Point3{R_ + r_, R_ + r_, r_};
  box.upper = center_ + Point3{R_ + r_, R_ + r_, r_};
  return box;
}

int default_patches(double area, double h, Variant variant) {
  const double s = (variant == Variant::smooth ? default_patch_cells_smooth_3d : default_patch_cells_nonsmooth_3d) * h;
  return std::max(minimum_multipliers, int(std::lround(area / (s * s))));
}

// ---------------------------------------------------------------------------------------------
// Quadrature over ω

bool near_surface(const Surface& gamma, const Point3& center, double radius) {
  const double value = gamma.level(center);
  const double slope = norm(gamma.level_gradient(center));
  return !(std::abs(value) > 2.0 * radius * slope);
}

namespace {

/// The cube [lower, lower + side]³ ∩ ω by lines along the axis where γ is steepest. The inside
/// length of a line is smooth across the cube while γ leaves through the four faces parallel to the
/// axis (every edge along the axis crosses γ); where γ meets the two faces across the axis it is
/// clamped (a kink the Gauss rule does not see), so such cubes are split in 8, down to `depth` 0.
template <class Visit>
void cut_cube(const Surface& gamma, const Point3& lower, double side, const GaussRule& rule, int depth, Visit&& visit) {
  Point3 center = lower;
  for (int d = 0; d < 3; ++d) center[d] += side / 2;
  const Point3 slope = gamma.level_gradient(center);
  int axis = 0;
  for (int d = 1; d < 3; ++d)
    if (std::abs(slope[d]) > std::abs(slope[axis])) axis = d;
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  if (depth > 0) {
    bool inside = false, outside = false, clean = true;
    for (int corner = 0; corner < 4; ++corner) {
      Point3 bottom = lower;
      bottom[u] += (corner & 1) * side;
      bottom[v] += (corner >> 1) * side;
      Point3 top = bottom;
      top[axis] += side;
      const double f0 = gamma.level(bottom), f1 = gamma.level(top);
      inside = inside || f0 < 0 || f1 < 0;
      outside = outside || f0 >= 0 || f1 >= 0;
      clean = clean && (f0 < 0) != (f1 < 0);
    }
    if (inside && outside && !clean) {
      for (int k = 0; k < 8; ++k)
        cut_cube(gamma, lower + (side / 2) * Point3{double(k & 1), double((k >> 1) & 1), double((k >> 2) & 1)},
                 side / 2, rule, depth - 1, visit);
      return;
    }
  }
  const int q = int(rule.nodes.size());
  for (int b = 0; b < q; ++b)
    for (int a = 0; a < q; ++a) {
      Point3 start = lower;
      start[u] += rule.nodes[a] * side;
      start[v] += rule.nodes[b] * side;
      const auto at = [&](double t) {
        Point3 x = start;
        x[axis] += t;
        return x;
      };
      const double f0 = gamma.level(at(0)), f1 = gamma.level(at(side));
      double t0 = 0, t1 = side;
      if (f0 >= 0 && f1 >= 0) continue;
      if ((f0 < 0) != (f1 < 0)) {  // one crossing: the root by bisection safeguarded regula falsi
        double lo = 0, hi = side, flo = f0, fhi = f1;
        for (int iteration = 0; iteration < 100 && hi - lo > 1e-15 * side; ++iteration) {
          double t = lo - flo * (hi - lo) / (fhi - flo);
          if (!(t > lo && t < hi) || iteration % 3 == 2) t = 0.5 * (lo + hi);
          const double ft = gamma.level(at(t));
          if ((ft < 0) == (flo < 0))
            lo = t, flo = ft;
          else
            hi = t, fhi = ft;
        }
        const double root = 0.5 * (lo + hi);
        if (f0 < 0)
          t1 = root;
        else
          t0 = root;
      }
      const double base = rule.weights[a] * rule.weights[b] * side * side * (t1 - t0);
      for (int c = 0; c < q; ++c) visit(at(t0 + rule.nodes[c] * (t1 - t0)), base * rule.weights[c]);
    }
}

/// The voxels of γ's bounding box, the only ones that can meet ω: first and last index per axis.
std::pair<std::array<int, 3>, std::array<int, 3>> bounding_voxels(const Grid3& grid, const Surface& gamma) {
  const Box3 bounds = gamma.bounds();
  std::array<int, 3> first, last;
  for (int d = 0; d < 3; ++d) {
    first[d] = grid.cell(d, bounds.lower[d]);
    last[d] = grid.cell(d, bounds.upper[d]);
  }
  return {first, last};
}

/// The rule's points in ω ∩ one voxel: q³ Gauss points when γ stays away from it, else its eight
/// half-voxels by cut_cube.
template <class Visit>
void omega_part(const Grid3& grid, const Surface& gamma, const Grid3::Index& cell, const GaussRule& rule, Visit&& visit,
                int cut_depth = 0) {  // deeper splits cost 8× per level, gain little on volumes
  const double h = grid.h();
  const int q = int(rule.nodes.size());
  const Point3 lower{grid.x(cell[0]), grid.y(cell[1]), grid.z(cell[2])};
  const Point3 center = lower + Point3{h / 2, h / 2, h / 2};
  if (!near_surface(gamma, center, 0.87 * h)) {
    if (gamma.level(center) > 0) return;
    for (int c = 0; c < q; ++c)
      for (int b = 0; b < q; ++b)
        for (int a = 0; a < q; ++a)
          visit(lower + h * Point3{rule.nodes[a], rule.nodes[b], rule.nodes[c]},
                rule.weights[a] * rule.weights[b] * rule.weights[c] * h * h * h);
    return;
  }
  for (int k = 0; k < 8; ++k) {  // eight half-voxels
    const Point3 sub = lower + (h / 2) * Point3{double(k & 1), double((k >> 1) & 1), double((k >> 2) & 1)};
    cut_cube(gamma, sub, h / 2, rule, cut_depth, visit);
  }
}

}  // namespace

void for_each_omega_point_in_voxel(const Grid3& grid, const Surface& gamma, const Grid3::Index& cell, int q,
                                   const std::function<void(const Point3&, double)>& visit, int depth) {
  omega_part(grid, gamma, cell, gauss_legendre(q), visit, depth);
}

void for_each_omega_row(const Grid3& grid, const Surface& gamma, int q, const Execution& execution,
                        const OmegaRowVisitor& visit) {
  const GaussRule& rule = gauss_legendre(q);
  const auto [first, last] = bounding_voxels(grid, gamma);
  std::atomic<bool> stop = false;
#pragma omp parallel num_threads(execution.threads())
  {
    std::vector<OmegaPoint> row;
#pragma omp for schedule(dynamic, 1)
    for (int iz = first[2]; iz <= last[2]; ++iz) {
      const int thread = omp_get_thread_num();
      if (thread == 0 && execution.interrupt_requested()) stop = true;
      if (stop) continue;
      for (int iy = first[1]; iy <= last[1]; ++iy) {
        row.clear();
        for (int ix = first[0]; ix <= last[0]; ++ix) {
          const Grid3::Index cell{ix, iy, iz};
          omega_part(grid, gamma, cell, rule, [&](const Point3& x, double w) { row.push_back({cell, x, w}); });
        }
        if (!row.empty()) visit(thread, row);
      }
    }
  }
  if (stop) throw Interrupted();
}

void for_each_omega_point(const Grid3& grid, const Surface& gamma, int q, const Execution& execution,
                          const OmegaVisitor& visit) {
  for_each_omega_row(grid, gamma, q, execution, [&](int thread, const std::vector<OmegaPoint>& row) {
    for (const OmegaPoint& p : row) visit(thread, p.cell, p.x, p.weight);
  });
}

GridVector omega_load(const Grid3& grid, const Surface& gamma, int q, const Execution& execution) {
  const double h = grid.h();
  const GaussRule& rule = gauss_legendre(q);
  const auto [first, last] = bounding_voxels(grid, gamma);
  GridVector load(grid.n_unknowns(), 0.0);
  // A voxel adds to the node planes z = k and k + 1 only, so the layers of one parity run in parallel.
  std::atomic<bool> stop = false;
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel for num_threads(execution.threads()) schedule(dynamic, 1)
    for (int iz = first[2] + parity; iz <= last[2]; iz += 2) {
      if (omp_get_thread_num() == 0 && execution.interrupt_requested()) stop = true;
      if (stop) continue;
      for (int iy = first[1]; iy <= last[1]; ++iy)
        for (int ix = first[0]; ix <= last[0]; ++ix) {
          const Grid3::Index cell{ix, iy, iz};
          const Point3 lower{grid.x(ix), grid.y(iy), grid.z(iz)};
          std::array<double, 8> sums{};
          const Point3 center = lower + Point3{h / 2, h / 2, h / 2};
          if (!near_surface(gamma, center, 0.87 * h)) {  // wholly inside or outside: ∫φ_k = h³/8
            if (gamma.level(center) > 0) continue;
            sums.fill(h * h * h / 8);
          } else {
            omega_part(grid, gamma, cell, rule, [&](const Point3& x, double w) {
              const Q1Element<3> basis((1 / h) * (x - lower), h);
              for (int l = 0; l < 8; ++l) sums[std::size_t(l)] += w * basis.value[l];
            });
          }
          for (int l = 0; l < 8; ++l) {
            const Grid3::Index node{ix + Q1Element<3>::offset(l, 0), iy + Q1Element<3>::offset(l, 1),
                                    iz + Q1Element<3>::offset(l, 2)};
            if (grid.has_unknown(node)) load[grid.index(node)] += sums[std::size_t(l)];
          }
        }
    }
  }
  if (stop) throw Interrupted();
  return load;
}

double omega_integral(const Grid3& grid, const Surface& gamma, const VectorizedField3& f, int q,
                      const Execution& execution) {
  // One sum per voxel row, added in row order afterwards: the same total on any number of threads.
  const std::size_t rows_per_layer = std::size_t(grid.ny() + 1);
  std::vector<double> per_row(rows_per_layer * std::size_t(grid.nz() + 1), 0.0);
  std::vector<std::array<std::vector<double>, 4>> buffers(std::size_t(execution.threads()));
  for_each_omega_row(grid, gamma, q, execution, [&](int thread, const std::vector<OmegaPoint>& row) {
    auto& [x, y, z, value] = buffers[std::size_t(thread)];
    x.resize(row.size()), y.resize(row.size()), z.resize(row.size()), value.resize(row.size());
    for (std::size_t p = 0; p < row.size(); ++p) x[p] = row[p].x.x, y[p] = row[p].x.y, z[p] = row[p].x.z;
    f(row.size(), x.data(), y.data(), z.data(), value.data());
    double sum = 0;
    for (std::size_t p = 0; p < row.size(); ++p) sum += row[p].weight * value[p];
    per_row[std::size_t(row[0].cell[2]) * rows_per_layer + std::size_t(row[0].cell[1])] = sum;
  });
  double total = 0;
  for (double s : per_row) total += s;
  return total;
}

double omega_volume(const Grid3& grid, const Surface& gamma, int q, const Execution& execution) {
  std::vector<double> sums(execution.threads(), 0.0);
  for_each_omega_point(grid, gamma, q, execution,
                       [&](int thread, const Grid3::Index&, const Point3&, double w) { sums[thread] += w; });
  double total = 0;
  for (double s : sums) total += s;
  return total;
}

namespace {

/// û at the eight nodes of `cell` (local node k as in Q1Element; 0 where a node has no unknown).
std::array<double, 8> nodal_values(const Grid3& grid, const GridVector& u, const Grid3::Index& cell) {
  std::array<double, 8> v;
  for (int k = 0; k < 8; ++k) {
    const Grid3::Index node{cell[0] + Q1Element<3>::offset(k, 0), cell[1] + Q1Element<3>::offset(k, 1),
                            cell[2] + Q1Element<3>::offset(k, 2)};
    v[std::size_t(k)] = grid.has_unknown(node) ? u[grid.index(node)] : 0.0;
  }
  return v;
}

/// ∇u at the points: the given gradient, or central differences of u with step e (six batches).
void gradient_at(const VectorizedField3& u, const GradientField3& gradient, double e,
                 const std::array<std::vector<double>, 3>& x, std::array<std::vector<double>, 3>& du) {
  const std::size_t n = x[0].size();
  for (auto& d : du) d.resize(n);
  if (gradient) {
    for (std::size_t k = 0; k < n; ++k) {
      const Point3 g = gradient(x[0][k], x[1][k], x[2][k]);
      for (int d = 0; d < 3; ++d) du[d][k] = g[d];
    }
    return;
  }
  std::vector<double> shifted(n), plus(n), minus(n);
  for (int axis = 0; axis < 3; ++axis) {
    const auto at = [&](std::vector<double>& out) {
      const double* c[3] = {x[0].data(), x[1].data(), x[2].data()};
      c[axis] = shifted.data();
      u(n, c[0], c[1], c[2], out.data());
    };
    for (std::size_t k = 0; k < n; ++k) shifted[k] = x[axis][k] + e;
    at(plus);
    for (std::size_t k = 0; k < n; ++k) shifted[k] = x[axis][k] - e;
    at(minus);
    for (std::size_t k = 0; k < n; ++k) du[axis][k] = (plus[k] - minus[k]) / (2 * e);
  }
}

/// The coordinates of `points` as three arrays.
std::array<std::vector<double>, 3> coordinates(const std::vector<Point3>& points) {
  std::array<std::vector<double>, 3> x;
  for (auto& c : x) c.reserve(points.size());
  for (const Point3& p : points)
    for (int d = 0; d < 3; ++d) x[d].push_back(p[d]);
  return x;
}

}  // namespace

ErrorNorms compute_errors(const GridVector& u_h, const Grid3& grid, const Surface& gamma, const PatchedSurface& patches,
                          const std::vector<double>& trace, const ScalarField3& exact,
                          const GradientField3& exact_gradient, int q, const Execution& execution) {
  return compute_errors(u_h, grid, gamma, patches, trace, vectorize(exact), exact_gradient, q, execution);
}

ErrorNorms compute_errors(const GridVector& u_h, const Grid3& grid, const Surface& gamma, const PatchedSurface& patches,
                          const std::vector<double>& trace, const VectorizedField3& exact,
                          const GradientField3& exact_gradient, int q, const Execution& execution) {
  const double e = 1e-6 * grid.box().width(0);
  struct Sums {
    double e2 = 0, de2 = 0, u2 = 0, du2 = 0;
  };
  struct Buffers {
    std::array<std::vector<double>, 3> x, du;
    std::vector<double> u;
  };
  std::vector<Sums> sums(execution.threads());
  std::vector<Buffers> buffers(execution.threads());
  for_each_omega_row(grid, gamma, q, execution, [&](int thread, const std::vector<OmegaPoint>& row) {
    Buffers& b = buffers[thread];
    const std::size_t n = row.size();
    for (int d = 0; d < 3; ++d) {
      b.x[d].resize(n);
      for (std::size_t k = 0; k < n; ++k) b.x[d][k] = row[k].x[d];
    }
    b.u.resize(n);
    exact(n, b.x[0].data(), b.x[1].data(), b.x[2].data(), b.u.data());
    gradient_at(exact, exact_gradient, e, b.x, b.du);
    Sums& s = sums[thread];
    std::array<double, 8> nodal{};
    for (std::size_t k = 0; k < n; ++k) {
      if (k == 0 || row[k].cell != row[k - 1].cell) nodal = nodal_values(grid, u_h, row[k].cell);
      Point3 xi;
      for (int d = 0; d < 3; ++d) xi[d] = (row[k].x[d] - grid.coordinate(d, row[k].cell[d])) / grid.h();
      const auto [value, slope] = Q1Element<3>::interpolate(nodal, xi, grid.h());
      const double u = b.u[k];
      const Point3 du{b.du[0][k], b.du[1][k], b.du[2][k]};
      const Point3 de = slope - du;
      const double w = row[k].weight;
      s.e2 += w * (value - u) * (value - u);
      s.de2 += w * dot(de, de);
      s.u2 += w * u * u;
      s.du2 += w * dot(du, du);
    }
  });
  Sums total;
  for (const Sums& s : sums) total.e2 += s.e2, total.de2 += s.de2, total.u2 += s.u2, total.du2 += s.du2;
  const std::array<std::vector<double>, 3> x = coordinates(patches.point);
  std::vector<double> u(x[0].size());
  exact(u.size(), x[0].data(), x[1].data(), x[2].data(), u.data());
  double g2 = 0, gu2 = 0;
  for (int p = 0; p < patches.m; ++p) {
    g2 += patches.area[p] * (trace[p] - u[p]) * (trace[p] - u[p]);
    gu2 += patches.area[p] * u[p] * u[p];
  }
  ErrorNorms out;
  out.l2_omega = std::sqrt(total.e2);
  out.h1semi_omega = std::sqrt(total.de2);
  out.h1_omega = std::sqrt(total.e2 + total.de2);
  out.l2_gamma = std::sqrt(g2);
  const auto relative = [](double error, double norm) { return norm > 0 ? error / norm : error; };
  out.rel_l2_omega = relative(out.l2_omega, std::sqrt(total.u2));
  out.rel_h1semi_omega = relative(out.h1semi_omega, std::sqrt(total.du2));
  out.rel_h1_omega = relative(out.h1_omega, std::sqrt(total.u2 + total.du2));
  out.rel_l2_gamma = relative(out.l2_gamma, std::sqrt(gu2));
  return out;
}

// ---------------------------------------------------------------------------------------------
// The solve

namespace {

using detail::row_sums;
using detail::to_eigen;

std::string format(const char* pattern, double a, double b = 0, double c = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, pattern, a, b, c);
  return buffer;
}

/// γ (or Γ) with its bounds grown by `grow` must keep 2h from the box's sides.
void check_inside_box(const Surface& gamma, const Grid3& grid, double grow, const std::string& field) {
  const Box3 bounds = gamma.bounds();
  const double margin = 2 * grid.h();
  for (int d = 0; d < 3; ++d) {
    const double room =
        std::min(bounds.lower[d] - grow - grid.box().lower[d], grid.box().upper[d] - bounds.upper[d] - grow);
    if (room >= margin) continue;
    std::string text = field + ": " + (grow > 0 ? "the offset surface" : "the surface") +
                       format(" comes within %.3g of the box along axis %.0f; the grid needs 2h = %.3g there", room,
                              double(d), margin);
    if (room > 0 && grow == 0)
      text += format(": N >= %.0f (or a larger box)", std::ceil(2 * grid.box().width(0) / room - 1e-9));
    throw std::invalid_argument(text);
  }
}

/// The triangles of `surface` moved by δ along the surface's unit normal at each vertex.
std::vector<Triangle3> offset_triangles(const std::vector<Triangle3>& triangles, const Surface& gamma, double delta) {
  const auto move = [&](const Point3& p) {
    const Point3 n = gamma.level_gradient(p);
    return p + (delta / norm(n)) * n;
  };
  std::vector<Triangle3> out;
  out.reserve(triangles.size());
  for (const Triangle3& t : triangles) out.push_back({move(t.a), move(t.b), move(t.c)});
  return out;
}

/// The nested start's coarse solve: `problem` on the grid of N/2 (m/4 points when m is given; Γ at the
/// same distance δ from γ, `offset` being this grid's δ/s; no error integrals), its points and active set in `points`
/// and `active`, or `skipped` set to why not: the coarse grid checks the box's margin (2h), the surface's reach and δ ≥
/// 4h with its own h, and may refuse what this grid takes. Its steps are reported through `execution` as "N/2 <step>";
/// an interrupt asked there ends this solve too.
void solve_coarse(const SurfaceProblem& problem, const SolverOptions& options, double offset,
                  const Execution& execution, const std::function<bool()>& interrupt,
                  SurfaceSolution::NestedStart& report, std::vector<Point3>& points, ActiveSet& active) {
  if (problem.N % 2 != 0) {
    report.skipped = "N is odd";
    return;
  }
  if (problem.N / 2 < minimum_nested_grid) {
    report.skipped = "N/2 is below " + std::to_string(minimum_nested_grid);
    return;
  }
  SurfaceProblem coarse = problem;
  coarse.N = problem.N / 2;
  coarse.exact = {};
  coarse.exact_vectorized = {};
  coarse.exact_gradient = {};
  SolverOptions coarse_options = options;
  if (options.multipliers > 0)
    coarse_options.multipliers = std::max(minimum_multipliers, int(std::lround(options.multipliers / 4.0)));
  coarse_options.offset = offset / 2;  // δ = offset·s, and s doubles
  bool stop_asked = false;             // a data callback may turn an interrupt into invalid_argument (Python's Ctrl-C)
  const auto check = [&interrupt, &stop_asked] { return stop_asked = stop_asked || (interrupt && interrupt()); };
  try {
    const auto progress = [&execution](const std::string& phase, double seconds) {
      execution.report("N/2 " + phase, seconds);
    };
    const SurfaceSolution s = solve(coarse, coarse_options, progress, check);
    if (!s.newton.converged) {
      report.skipped = "the solve on the grid of N/2 did not converge: " + s.newton.failure;
      return;
    }
    report.N = coarse.N;
    report.multipliers = s.options.multipliers;
    report.newton_steps = s.newton.iterations;
    report.active = int(std::count(s.newton.active.begin(), s.newton.active.end(), 1));
    points = s.gamma.point;
    active = s.newton.active;
  } catch (const Interrupted&) {
    throw;
  } catch (const std::runtime_error& e) {  // e.g. an empty patch
    if (stop_asked) throw Interrupted();
    report.skipped = std::string("the solve on the grid of N/2 failed: ") + e.what();
  } catch (const std::invalid_argument& e) {  // a grid too coarse for the surface or the box
    if (stop_asked) throw Interrupted();
    report.skipped = std::string("the grid of N/2 does not take the problem: ") + e.what();
  }
}

/// Each of `points` takes the flag of the nearest of `from`.
ActiveSet nearest_flags(const std::vector<Point3>& from, const ActiveSet& flags, const std::vector<Point3>& points,
                        const Execution& execution) {
  ActiveSet out(points.size());
  const std::ptrdiff_t n = std::ptrdiff_t(points.size());
#pragma omp parallel for num_threads(execution.threads()) schedule(static)
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t nearest = 0;
    for (std::size_t q = 0; q < from.size(); ++q) {
      const Point3 d = from[q] - points[std::size_t(p)];
      const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
      if (d2 < best) best = d2, nearest = q;
    }
    out[std::size_t(p)] = flags[nearest];
  }
  return out;
}

}  // namespace

SurfaceSolution solve(const SurfaceProblem& problem, SolverOptions options,
                      std::function<void(const std::string&, double)> progress, std::function<bool()> interrupt) {
  options.validate();
  options.variant = resolved_variant(options.variant, true);  // surfaces have a continuous normal
  Execution execution(options.threads);
  execution.set_progress(std::move(progress));
  execution.set_interrupt_check(interrupt);  // a copy: the nested start's coarse solve asks it too
  if (!problem.gamma) throw std::invalid_argument("geometry: no surface given");
  if (!problem.f && !problem.f_vectorized) throw std::invalid_argument("data.f: not given");
  if (!problem.g && !problem.g_vectorized) throw std::invalid_argument("data.g: not given");
  if (!(problem.c >= 0) || !std::isfinite(problem.c)) throw std::invalid_argument("data.c: must be finite and >= 0");
  const Grid3 grid(problem.box, problem.N, problem.boundary);
  const Surface& gamma = *problem.gamma;
  const double h = grid.h();
  SurfaceSolution sol(grid);
  detail::PhaseClock clock(sol.timings, execution);
  Eigen::setNbThreads(execution.threads());

  check_inside_box(gamma, grid, 0, "geometry");  // before any work
  const double area = gamma.area();
  const Box3 bounds = gamma.bounds();
  const Box3& box = grid.box();
  const OffsetRoom room = [&gamma, bounds, box](double k) {  // Γ keeps 2h from the box and does not fold
    double room = gamma.reach() - 2 * k;
    for (int d = 0; d < 3; ++d)
      room = std::min({room, bounds.lower[d] - box.lower[d] - 2 * k, box.upper[d] - bounds.upper[d] - 2 * k});
    return room;
  };
  const SpacingPlan plan =
      plan_spacing({3, area, h, box.width(0),
                    [area, &options](double k) { return default_patches(area, k, options.variant); }, room},
                   options);
  const int m = plan.m;
  if (!plan.warning.empty()) sol.warnings.push_back(plan.warning);
  execution.throw_if_interrupted();

  // Nested start: the same problem on the grid of N/2 first (before this grid's arrays exist).
  std::vector<Point3> coarse_points;
  ActiveSet coarse_active;
  if (options.nested_start > 0 && problem.N >= options.nested_start) {
    sol.nested_start.emplace();
    solve_coarse(problem, options, plan.offset, execution, interrupt, *sol.nested_start, coarse_points, coarse_active);
    clock.mark("nested_start");
    sol.nested_start->seconds = sol.timings.phases.back().second;
    execution.throw_if_interrupted();
  }

  // 0. The load and u₀.
  std::unique_ptr<FastSolver<3>> fast = make_fast_solver(grid, problem.c, execution);
  GridVector u0 = problem.f_vectorized ? assemble_load(grid, problem.f_vectorized, options.load_quadrature, execution)
                                       : assemble_load(grid, problem.f, options.load_quadrature, execution);
  double load_total = 0;
  for (double v : u0) {
    if (!std::isfinite(v)) throw std::invalid_argument("data.f: not finite somewhere in the box");
    load_total += v;
  }
  clock.mark("load");
  execution.throw_if_interrupted();
  fast->solve_in_place(u0);
  ++sol.fast_solves;
  for (double v : u0)
    if (!(std::abs(v) <= detail::largest_scale))
      throw std::invalid_argument(
          format("data.f: u0 = A^-1 f reaches %.3g, beyond %.0e: rescale the problem (u, f and g "
                 "by one factor)",
                 v, detail::largest_scale));
  clock.mark("u0");
  execution.throw_if_interrupted();

  // 1. Geometry: the patches of γ, δ and Γ (m and δ planned above).
  sol.gamma = gamma.patches(m, h);
  execution.throw_if_interrupted();
  sol.Gamma = sol.gamma;
  if (options.variant == Variant::smooth) {
    sol.delta = plan.delta;
    check_inside_box(gamma, grid, sol.delta, "formulation.offset");
    sol.Gamma.triangles = offset_triangles(sol.gamma.triangles, gamma, sol.delta);
    for (int p = 0; p < m; ++p) sol.Gamma.point[p] = sol.gamma.point[p] + sol.delta * sol.gamma.normal[p];
  }
  sol.Gamma.area.assign(m, 0.0);
  for (std::size_t t = 0; t < sol.Gamma.triangles.size(); ++t)
    sol.Gamma.area[sol.Gamma.patch_of[t]] += fictus::area(sol.Gamma.triangles[t]);

  // 2. Trace rows: B_γ trilinear, C_γ triquadratic (reconstructed) or the shifted voxel gradient, B_Γ
  //    the patch integrals; in the non-smooth variant with reconstructed traces, the kink correction
  //    (its rows r_j join B_Γ as the loads, and D_B, D_C act on λ directly).
  const SparseRows B_gamma = point_value_rows(grid, sol.gamma.point);
  const bool reconstructed = options.normal_derivative == NormalDerivative::reconstructed;
  const SparseRows C_gamma =
      reconstructed ? normal_derivative_rows_centered(grid, sol.gamma.point, sol.gamma.normal)
                    : normal_derivative_rows(grid, sol.gamma.point, sol.gamma.normal, options.normal_shift * h);
  // Non-smooth: λ lives on γ itself, where the kink of û must sit to O(h³) for C_γ (which reaches across
  // γ): the triangles' points are mapped onto γ (their O(h²) sag would be a double layer, an O(h) error).
  execution.throw_if_interrupted();
  const SparseRows B_Gamma = patch_integral_rows(
      grid,
      patch_integrals(grid, sol.Gamma.triangles, sol.Gamma.patch_of, m,
                      options.variant == Variant::nonsmooth ? onto_surface(gamma, 1e-13 * h) : SurfaceMap{}),
      m);
  clock.mark("geometry");
  execution.throw_if_interrupted();
  std::unique_ptr<SurfaceKink> kink;
  DirectTerms direct;
  if (options.variant == Variant::nonsmooth && reconstructed) {
    if (!(gamma.reach() > 6 * h))  // the kink band reaches 6h outside γ: its nearest points must be unique
      throw std::invalid_argument(
          format("formulation.variant: the surface folds within %.3g of itself outside, "
                 "inside the non-smooth variant's band of 6h = %.3g: a larger N",
                 gamma.reach(), 6 * h));
    kink = std::make_unique<SurfaceKink>(grid, gamma, sol.gamma, problem.c, execution);
    direct.trace = kink->direct(B_gamma);
    direct.normal_derivative = kink->direct(C_gamma);
    clock.mark("kink_correction");
    execution.throw_if_interrupted();
  }
  const SparseRows loads = kink ? add_rows(B_Gamma, kink->galerkin()) : B_Gamma;
  // The flux balance (flux_balance in surface_kink.hpp): X joins D_C, and the data's readings move
  // by one constant so that their area-weighted sum is c∫_ω u₀ − ∫_ω f, the discrete field's flux.
  Eigen::SparseMatrix<double> balance;
  double data_shift = 0;
  if (kink && options.flux_balance && !fast->singular()) {
    constexpr int load_points = 3;  // per Gauss line of the cut-voxel rule, as the error integrals'
    GridVector load_of_omega = problem.c != 0.0 ? omega_load(grid, gamma, load_points, execution) : GridVector();
    double u0_integral = 0;  // ∫_ω u₀
    for (std::size_t k = 0; k < load_of_omega.size(); ++k) u0_integral += load_of_omega[k] * u0[k];
    FluxBalance b =
        flux_balance(*kink, B_Gamma, C_gamma, loads, direct.normal_derivative, std::move(load_of_omega), *fast);
    direct.normal_derivative += b.correction;
    balance = std::move(b.correction);
    std::vector<double> c_u0;
    C_gamma.multiply(u0, c_u0);
    const double readings = b.area.dot(to_eigen(c_u0)), area_total = b.area.sum();
    const double f_integral =
        omega_integral(grid, gamma, problem.f_vectorized ? problem.f_vectorized : vectorize(problem.f),
                       options.load_quadrature, execution);
    if (!std::isfinite(f_integral)) throw std::invalid_argument("data.f: not finite somewhere in ω");
    data_shift = (problem.c * u0_integral - f_integral - readings) / area_total;
    sol.flux_balance = SurfaceSolution::FluxBalanceUse{b.scatter, b.mean, data_shift};
    sol.fast_solves += b.fast_solves;
    clock.mark("flux_balance");
    execution.throw_if_interrupted();
  }

  // 3. Schur blocks.
  std::unique_ptr<GreenTable<3>> green;
  std::unique_ptr<SchurComplement> schur;
  std::unique_ptr<ImplicitSchur> exact;  // the exact S behind an interpolated far field
  if (options.inner == InnerSolver::krylov) {
    schur = std::make_unique<ImplicitSchur>(*fast, B_gamma, C_gamma, loads,
                                            detail::gmres_options(options, m, execution), direct);
  } else {
    green = std::make_unique<GreenTable<3>>(grid, problem.c, execution);
    clock.mark("green_table");
    FarFieldReport report;
    schur = std::make_unique<ExplicitSchur>(*green, B_gamma, C_gamma, loads, execution, direct,
                                            !options.far_field                      ? FarField{}
                                            : options.variant == Variant::nonsmooth ? default_far_field_3d_nonsmooth
                                                                                    : default_far_field_3d,
                                            &report);
    green.reset();
    if (report.far_pairs > 0) {
      sol.far_field = SurfaceSolution::FarFieldUse{report, 0};
      exact = std::make_unique<ImplicitSchur>(*fast, B_gamma, C_gamma, loads,
                                              detail::gmres_options(options, m, execution), direct);
    }
    clock.mark("schur");
    execution.throw_if_interrupted();
  }

  // 4. g at the points.
  sol.g.resize(m);
  {
    const std::array<std::vector<double>, 3> x = coordinates(sol.gamma.point);
    (problem.g_vectorized ? problem.g_vectorized : vectorize(problem.g))(std::size_t(m), x[0].data(), x[1].data(),
                                                                         x[2].data(), sol.g.data());
  }
  for (int p = 0; p < m; ++p) {
    const Point3 x = sol.gamma.point[p];
    if (!std::isfinite(sol.g[p]))
      throw std::invalid_argument(format("data.g: not finite at the point (%.6g, %.6g, %.6g)", x.x, x.y, x.z));
    if (std::abs(sol.g[p]) > detail::largest_scale)
      throw std::invalid_argument(format("data.g: %.3g is beyond %.0e: rescale the problem (u, f and g by one factor)",
                                         sol.g[p], detail::largest_scale));
  }

  // 5. Newton.
  std::vector<double> b0, c0;
  B_gamma.multiply(u0, b0);
  C_gamma.multiply(u0, c0);
  if (sol.flux_balance)  // the data's readings: their area-weighted sum is c∫_ω u₀ − ∫_ω f
    for (double& v : c0) v += data_shift;
  std::optional<ConstantMode> mode;
  if (fast->singular()) mode = ConstantMode{row_sums(B_gamma), row_sums(C_gamma), row_sums(B_Gamma), load_total};
  const NewtonOptions newton_options = detail::newton_options(options, execution);
  NewtonOptions first = newton_options;
  if (exact) first.hand_on_at_changes = std::max(1, int(far_field_hand_on * m));
  ActiveSet start;
  if (!coarse_points.empty()) {
    start = nearest_flags(coarse_points, coarse_active, sol.gamma.point, execution);
    first.start_active = &start;
  }
  sol.newton =
      solve_semismooth_newton(*schur, to_eigen(b0), to_eigen(c0), to_eigen(sol.g), first, mode ? &*mode : nullptr);
  if (exact) {  // on with the exact S from where S̃ left the active set nearly settled
    GmresOptions polish = detail::gmres_options(options, m, execution);
    polish.relative_tolerance = far_field_gmres_tolerance;
    const PreconditionedSchur preconditioned(static_cast<const ExplicitSchur&>(*schur), *exact, polish);
    NewtonOptions from_there = newton_options;  // solver.max_newton caps both runs together
    from_there.start = &sol.newton;
    from_there.max_iterations = std::max(1, newton_options.max_iterations - sol.newton.iterations);
    NewtonResult second = solve_semismooth_newton(preconditioned, to_eigen(b0), to_eigen(c0), to_eigen(sol.g),
                                                  from_there, mode ? &*mode : nullptr);
    sol.far_field->exact_steps = second.iterations;
    second.iterations += sol.newton.iterations;
    second.history.insert(second.history.begin(), sol.newton.history.begin(), sol.newton.history.end());
    second.inner_failed = second.inner_failed || sol.newton.inner_failed;
    sol.newton = std::move(second);
    sol.fast_solves += exact->fast_solves();
  }
  sol.fast_solves += schur->fast_solves();
  if (const auto* dense = dynamic_cast<const ExplicitSchur*>(schur.get())) sol.factorizations = dense->factorizations();
  schur.reset();  // S_B, S_C and the kept LU (3m² doubles): freed before the field and the errors
  exact.reset();
  for (const NewtonStep& step : sol.newton.history) sol.inner_iterations += step.inner_iterations;
  sol.lambda.assign(sol.newton.lambda.data(), sol.newton.lambda.data() + m);
  sol.lambda_total = row_sums(B_Gamma).dot(sol.newton.lambda);
  sol.alpha = sol.newton.alpha;
  for (double v : sol.lambda)
    if (!(std::abs(v) <= detail::largest_scale) || !std::isfinite(sol.alpha))
      throw std::invalid_argument(
          format("data.g: the multipliers reach %.3g, beyond %.0e: rescale the problem (u, f "
                 "and g by one factor)",
                 v, detail::largest_scale));
  clock.mark("newton");
  execution.throw_if_interrupted();

  // 6. The field.
  GridVector u(grid.n_unknowns(), 0.0);
  loads.add_transposed(sol.lambda, u);
  fast->solve_in_place(u);
  ++sol.fast_solves;
  for (std::size_t k = 0; k < u.size(); ++k) u[k] += u0[k] + sol.alpha;
  if (kink) kink->add_kinks(sol.lambda, u);  // the kink-corrected field I_h w
  u0 = GridVector();
  sol.u = std::move(u);
  B_gamma.multiply(sol.u, sol.trace);
  C_gamma.multiply(sol.u, sol.normal_derivative);
  if (sol.flux_balance) {  // the readings of the Newton system: C_γ I_h w + Xλ + the data's shift
    Eigen::Map<Eigen::VectorXd>(sol.normal_derivative.data(), m) +=
        balance * Eigen::Map<const Eigen::VectorXd>(sol.lambda.data(), m);
    for (double& v : sol.normal_derivative) v += data_shift;
  }
  clock.mark("final_solve");
  execution.throw_if_interrupted();

  sol.signorini = detail::signorini_check(sol.trace, sol.normal_derivative, sol.g);  // 7

  // 8. Errors.
  if (problem.exact || problem.exact_vectorized) {
    const VectorizedField3 exact = problem.exact_vectorized ? problem.exact_vectorized : vectorize(problem.exact);
    const GradientField3& exact_gradient = problem.exact_gradient;
    const std::array<std::vector<double>, 3> x = coordinates(sol.gamma.point);
    std::array<std::vector<double>, 3> du;
    std::vector<double> u(sol.gamma.point.size());
    exact(u.size(), x[0].data(), x[1].data(), x[2].data(), u.data());
    gradient_at(exact, exact_gradient, 1e-6 * grid.box().width(0), x, du);
    PointErrors pe;
    for (int p = 0; p < m; ++p) {
      const Point3 n = sol.gamma.normal[p];
      pe.max_trace = std::max(pe.max_trace, std::abs(sol.trace[p] - u[p]));
      pe.max_normal_derivative =
          std::max(pe.max_normal_derivative,
                   std::abs(sol.normal_derivative[p] - (n.x * du[0][p] + n.y * du[1][p] + n.z * du[2][p])));
    }
    sol.point_errors = pe;
    sol.errors = compute_errors(sol.u, grid, gamma, sol.gamma, sol.trace, exact, exact_gradient,
                                options.error_quadrature, execution);
    clock.mark("errors");
  }
  sol.options = options;
  sol.options.threads = execution.threads();
  sol.options.multipliers = m;
  sol.options.offset = plan.offset;
  return sol;
}

}  // namespace fictus
