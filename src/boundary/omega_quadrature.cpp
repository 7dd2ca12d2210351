#include "fictus/boundary/omega_quadrature.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <vector>

#include "fictus/grid/distribution.hpp"
#include "fictus/grid/q1_element.hpp"
#include "fictus/grid/quadrature.hpp"

namespace fictus {

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
  for_each_omega_row(grid, gamma, q, execution, grid.every_layer(), visit);
}

void for_each_omega_row(const Grid3& grid, const Surface& gamma, int q, const Execution& execution, const Slab& slab,
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
      if (stop || !slab.holds(grid.cell_layer(iz))) continue;
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

GridVector omega_load(const Grid3& grid, const Surface& gamma, int q, const Execution& execution,
                      std::optional<Slab> slab) {
  const double h = grid.h();
  const GaussRule& rule = gauss_legendre(q);
  const auto [first, last] = bounding_voxels(grid, gamma);
  const Slab s = slab.value_or(grid.every_layer());
  const std::size_t offset = grid.slab_offset(s);
  const auto held = [&](int z) { return (grid.periodic() || (z > 0 && z < grid.n(2))) && s.holds(grid.layer(z)); };
  GridVector load(grid.slab_size(s), 0.0);
  // A voxel adds to the node planes z = k and k + 1 only, so the layers of one parity run in parallel.
  std::atomic<bool> stop = false;
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel for num_threads(execution.threads()) schedule(dynamic, 1)
    for (int iz = first[2] + parity; iz <= last[2]; iz += 2) {
      if (omp_get_thread_num() == 0 && execution.interrupt_requested()) stop = true;
      if (stop || (!held(iz) && !held(iz + 1))) continue;
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
            if (grid.has_unknown(node) && s.holds(grid.layer(node[2])))
              load[grid.index(node) - offset] += sums[std::size_t(l)];
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
  // Distributed, each rank sums the rows of its slab's voxel layers and the ranks' rows are added (each
  // row one rank's, the others' zeros): the same total on every rank, and the serial one.
  const Distribution& distribution = execution.distribution();
  const std::size_t rows_per_layer = std::size_t(grid.ny() + 1);
  std::vector<double> per_row(rows_per_layer * std::size_t(grid.nz() + 1), 0.0);
  std::vector<std::array<std::vector<double>, 4>> buffers(std::size_t(execution.threads()));
  const OmegaRowVisitor sum_row = [&](int thread, const std::vector<OmegaPoint>& row) {
    auto& [x, y, z, value] = buffers[std::size_t(thread)];
    x.resize(row.size()), y.resize(row.size()), z.resize(row.size()), value.resize(row.size());
    for (std::size_t p = 0; p < row.size(); ++p) x[p] = row[p].x.x, y[p] = row[p].x.y, z[p] = row[p].x.z;
    f(row.size(), x.data(), y.data(), z.data(), value.data());
    double sum = 0;
    for (std::size_t p = 0; p < row.size(); ++p) sum += row[p].weight * value[p];
    per_row[std::size_t(row[0].cell[2]) * rows_per_layer + std::size_t(row[0].cell[1])] = sum;
  };
  std::exception_ptr failure;  // (an interruption on one rank is thrown on every rank, before the sum)
  try {
    for_each_omega_row(grid, gamma, q, execution, distribution.slab(grid), sum_row);
  } catch (...) {
    failure = std::current_exception();
  }
  distribution.throw_first_failure(failure, false);
  distribution.sum(per_row);
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

}  // namespace fictus
