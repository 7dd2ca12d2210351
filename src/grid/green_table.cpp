#include "fictus/grid/green_table.hpp"

#include <algorithm>
#include <climits>
#include <stdexcept>

#include "fftw_plan.hpp"
#include "fictus/grid/distribution.hpp"
#include "fictus/grid/q1_symbol.hpp"

namespace fictus {

template <int dim>
GreenTable<dim>::GreenTable(const Grid<dim>& grid, double c, const Execution& execution)
    : grid_(grid), c_(c), periodic_(grid.periodic()) {
  const Q1Symbol<dim> symbol(grid, c);
  std::size_t entries = 1;
  for (int d = 0; d < dim; ++d) {
    period_[d] = periodic_ ? grid.n(d) : 2 * grid.n(d);
    size_[d] = std::size_t(period_[d] / 2 + 1);
    entries *= size_[d];
  }
  std::vector<int> shape;  // slowest axis first
  for (int d = dim - 1; d >= 0; --d) shape.push_back(int(size_[d]));
  // This rank's planes of the slowest axis (all of them serially), then a plane of zeros that every
  // plane held elsewhere reads.
  const Distribution& distribution = execution.distribution();
  partial_ = distribution.distributed();
  std::size_t local = entries;
  const Slab held = partial_ ? distribution.transform_planes(shape, local) : Slab{0, shape[0]};
  held_ = held;
  const std::size_t plane = entries / size_[dim - 1];
  plane_.resize(size_[dim - 1]);
  for (int z = 0; z < shape[0]; ++z)
    plane_[std::size_t(z)] = (held.holds(z) ? std::size_t(z - held.first) : std::size_t(held.count)) * plane;
  if (partial_) zeros_ = std::size_t(held.count) * plane;
  table_.assign(partial_ ? std::max(local, std::size_t(held.count + 1) * plane) : entries, 0.0);
  // Table entry p holds 1/λ of mode p. Dirichlet: p_d = 1..n_d−1 (spectrum index p_d − 1), zero at
  // p_d ∈ {0, n_d}; periodic: p_d = 0..n_d/2 (spectrum index p_d), the zero mode dropped when λ = 0.
  double denominator = periodic_ ? 1.0 : double(1 << dim);
  for (int d = 0; d < dim; ++d) denominator *= grid.n(d);
  const double scale = 1.0 / denominator;
  const int shift = periodic_ ? 0 : 1, row_length = int(size_[0]);
  const int rows_per_plane = int(plane / size_[0]), first_row = held.first * rows_per_plane,
            rows = held.count * rows_per_plane;
  const double* k0 = symbol.axis(0).stiffness.data();
  const double* m0 = symbol.axis(0).mass.data();
#pragma omp parallel for num_threads(execution.threads()) schedule(static)
  for (int r = 0; r < rows; ++r) {
    std::array<int, dim> slow{};
    bool inside = true;
    for (int d = 1, rest = first_row + r; d < dim; ++d) {
      slow[d] = rest % int(size_[d]) - shift, rest /= int(size_[d]);
      inside = inside && slow[d] >= 0 && slow[d] < symbol.axis(d).size();
    }
    if (!inside) continue;
    const typename Q1Symbol<dim>::Row factors = symbol.row(slow);
    double* row = table_.data() + std::size_t(r) * size_[0];
    for (int p = 0; p < row_length; ++p) {
      const int ip = p - shift;
      if (ip < 0 || ip >= symbol.axis(0).size()) continue;
      const double lambda = Q1Symbol<dim>::lambda(k0[ip], m0[ip], c, factors);
      row[p] = lambda > 0 ? scale / lambda : 0.0;
    }
  }
  if (partial_) {
    distribution.dct1(shape, table_.data(), execution.threads());
    const auto zeros = table_.begin() + std::ptrdiff_t(std::size_t(held.count) * plane);  // the transform's scratch
    std::fill(zeros, zeros + std::ptrdiff_t(plane), 0.0);
    return;
  }
  detail::R2rPlan plan(shape, detail::R2rKind::dct1, execution.threads());
  plan.execute(table_.data());
}

template <int dim>
GreenTable<dim>::GreenTable(const GreenTable& table, const std::vector<char>& wanted, const Distribution& distribution)
    : grid_(table.grid_), c_(table.c_), periodic_(table.periodic_), period_(table.period_), size_(table.size_) {
  if (wanted.size() != size_[dim - 1]) throw std::invalid_argument("GreenTable: one mark per plane");
  std::vector<int> list;
  for (std::size_t z = 0; z < wanted.size(); ++z)
    if (wanted[z]) list.push_back(int(z));
  const std::size_t entries = plane_size();
  held_ = Slab{0, int(size_[dim - 1])};
  // The planes, then one of zeros: the planes not copied read it, and the node sums refuse them.
  if (table.partial_) {
    table_ = distribution.planes(table.table_.data(), table.held_, entries, list, entries);
  } else {
    table_.assign((list.size() + 1) * entries, 0.0);
    for (std::size_t t = 0; t < list.size(); ++t) {
      const std::size_t from = table.plane_[std::size_t(list[t])];
      if (from == table.missing_) throw std::invalid_argument("GreenTable: a plane the copied table does not hold");
      std::copy_n(table.table_.begin() + std::ptrdiff_t(from), entries, table_.begin() + std::ptrdiff_t(t * entries));
    }
  }
  missing_ = list.size() * entries;
  plane_.assign(size_[dim - 1], missing_);
  for (std::size_t t = 0; t < list.size(); ++t) plane_[std::size_t(list[t])] = t * entries;
}

template <int dim>
void GreenTable<dim>::mark_planes(int a_lo, int a_hi, int b_lo, int b_hi, std::vector<char>& planes) const {
  const int period = period_[dim - 1];
  planes.resize(size_[dim - 1], 0);
  for (int s = a_lo - b_hi; s <= a_hi - b_lo; ++s) planes[std::size_t(fold(s, period))] = 1;
  if (!periodic_)
    for (int s = a_lo + b_lo; s <= a_hi + b_hi; ++s) planes[std::size_t(fold(s, period))] = 1;
}

namespace {

/// Σ over the reflections from the table rows at the folded (y, z) offsets (3-D: (−,−), (+,−), (−,+),
/// (+,+); 2-D: y = −, +) and the folded x offsets m = |a − b|, p = a + b: the order of the
/// node-by-node form's sums.
inline double reflections(const double* mm, const double* pm, const double* mp, const double* pp, std::size_t m,
                          std::size_t p) {
  return (mm[m] - mm[p] - pm[m] + pm[p]) - (mp[m] - mp[p] - pp[m] + pp[p]);
}
inline double reflections(const double* tm, const double* tp, std::size_t m, std::size_t p) {
  return tm[m] - tm[p] - tp[m] + tp[p];
}

/// Which of the two table rows (planes) of a reflection pair, at offsets `minus` and `plus`, this rank
/// holds: distributed, a row held elsewhere is the zero plane (`zeros`; serially none), and the sums
/// skip its terms. They are exact zeros, so the sums' bits are those with them (up to the sign of a zero).
enum Held { both, minus_only, plus_only, neither };
inline Held held(std::size_t minus, std::size_t plus, std::size_t zeros) {
  return minus != zeros ? (plus != zeros ? both : minus_only) : (plus != zeros ? plus_only : neither);
}

}  // namespace

template <int dim>
void GreenTable<dim>::G(const std::array<std::vector<int>, dim>& a, const std::array<std::vector<int>, dim>& b,
                        double* out, std::size_t ld) const {
  // Per axis and pair of coordinates (b's slowest): the table offsets of a − b and (Dirichlet) a + b.
  std::array<std::vector<std::size_t>, dim> minus, plus;
  std::size_t stride = 1;
  for (int d = 0; d < dim; ++d) {
    const auto &ad = a[std::size_t(d)], &bd = b[std::size_t(d)];
    for (int y : bd)
      for (int x : ad) {
        minus[std::size_t(d)].push_back(offset(d, near_fold(x - y, period_[d]), stride));
        if (!periodic_) plus[std::size_t(d)].push_back(offset(d, near_fold(x + y, period_[d]), stride));
      }
    stride *= size_[d];
  }
  const double* t = table_.data();
  const std::size_t na0 = a[0].size(), nb0 = b[0].size(), na1 = a[1].size(), nb1 = b[1].size();
  if constexpr (dim == 2) {
    for (std::size_t q1 = 0; q1 < nb1; ++q1)
      for (std::size_t q0 = 0; q0 < nb0; ++q0) {
        double* column = out + ld * (q1 * nb0 + q0);
        const std::size_t* sm = minus[0].data() + q0 * na0;
        const std::size_t* sp = plus[0].data() + q0 * na0;  // empty in a periodic box
        for (std::size_t p1 = 0; p1 < na1; ++p1) {
          const std::size_t ym = minus[1][q1 * na1 + p1], yp = periodic_ ? zeros_ : plus[1][q1 * na1 + p1];
          const double *tm = t + ym, *tp = periodic_ ? t : t + yp;
          double* o = column + p1 * na0;
          switch (held(ym, yp, zeros_)) {  // the terms of the rows held elsewhere are zeros: skipped (the same bits)
            case both:
              for (std::size_t p0 = 0; p0 < na0; ++p0) o[p0] = reflections(tm, tp, sm[p0], sp[p0]);
              break;
            case minus_only:
              if (periodic_)
                for (std::size_t p0 = 0; p0 < na0; ++p0) o[p0] = tm[sm[p0]];
              else
                for (std::size_t p0 = 0; p0 < na0; ++p0) o[p0] = tm[sm[p0]] - tm[sp[p0]];
              break;
            case plus_only:
              for (std::size_t p0 = 0; p0 < na0; ++p0) o[p0] = -tp[sm[p0]] + tp[sp[p0]];
              break;
            case neither:
              std::fill(o, o + na0, 0.0);
          }
        }
      }
  } else {
    const std::size_t na2 = a[2].size(), nb2 = b[2].size();
    for (std::size_t q2 = 0; q2 < nb2; ++q2)
      for (std::size_t q1 = 0; q1 < nb1; ++q1)
        for (std::size_t q0 = 0; q0 < nb0; ++q0) {
          double* column = out + ld * ((q2 * nb1 + q1) * nb0 + q0);
          const std::size_t* xm = minus[0].data() + q0 * na0;
          const std::size_t* xp = plus[0].data() + q0 * na0;  // empty in a periodic box
          for (std::size_t p2 = 0; p2 < na2; ++p2) {
            const std::size_t zm = minus[2][q2 * na2 + p2], zp = periodic_ ? zeros_ : plus[2][q2 * na2 + p2];
            double* block = column + p2 * na1 * na0;  // rows p1 of plane p2, na0 each
            // The terms of the planes held elsewhere are zeros: skipped (the same bits).
            const Held z = held(zm, zp, zeros_);
            if (z == neither) {
              std::fill(block, block + na1 * na0, 0.0);
              continue;
            }
            const auto rows = [&](const auto& row) {
              for (std::size_t p1 = 0; p1 < na1; ++p1) row(block + p1 * na0, minus[1][q1 * na1 + p1], q1 * na1 + p1);
            };
            if (periodic_)
              rows([&](double* o, std::size_t ym, std::size_t) {
                for (std::size_t p0 = 0; p0 < na0; ++p0) o[p0] = t[zm + ym + xm[p0]];
              });
            else if (z == both)
              rows([&](double* o, std::size_t ym, std::size_t at) {
                const std::size_t yp = plus[1][at];
                const double *mm = t + ym + zm, *pm = t + yp + zm, *mp = t + ym + zp, *pp = t + yp + zp;
                for (std::size_t p0 = 0; p0 < na0; ++p0) o[p0] = reflections(mm, pm, mp, pp, xm[p0], xp[p0]);
              });
            else if (z == minus_only)
              rows([&](double* o, std::size_t ym, std::size_t at) {
                const double *mm = t + ym + zm, *pm = t + plus[1][at] + zm;
                for (std::size_t p0 = 0; p0 < na0; ++p0) o[p0] = reflections(mm, pm, xm[p0], xp[p0]);
              });
            else
              rows([&](double* o, std::size_t ym, std::size_t at) {
                const double *mp = t + ym + zp, *pp = t + plus[1][at] + zp;
                for (std::size_t p0 = 0; p0 < na0; ++p0) o[p0] = -reflections(mp, pp, xm[p0], xp[p0]);
              });
          }
        }
  }
}

template <int dim>
void GreenTable<dim>::G(const Index* a, std::size_t n_a, const Index* b, const double* w, std::size_t n_b,
                        double* out) const {
  std::fill(out, out + n_a, 0.0);
  if (n_b == 0) return;
  // b's coordinates from their least along each axis; then, for each a, the folded offsets of a_d − b_d
  // and (Dirichlet) a_d + b_d times the axis's stride over that range, so the sums only look them up.
  thread_local std::vector<int> from_low;
  thread_local std::vector<std::size_t> offsets;
  std::array<int, dim> low, width;
  std::array<std::size_t, dim> stride, minus_at, plus_at;
  low.fill(INT_MAX);
  width.fill(0);
  for (std::size_t k = 0; k < n_b; ++k)
    for (int d = 0; d < dim; ++d) low[d] = std::min(low[d], b[k][d]);
  from_low.resize(n_b * dim);
  for (std::size_t k = 0; k < n_b; ++k)
    for (int d = 0; d < dim; ++d) {
      from_low[k * dim + std::size_t(d)] = b[k][d] - low[d];
      width[d] = std::max(width[d], b[k][d] - low[d] + 1);
    }
  std::size_t total = 0;
  for (int d = 0; d < dim; ++d) {
    stride[d] = d == 0 ? 1 : stride[d - 1] * size_[d - 1];
    minus_at[d] = total, total += std::size_t(width[d]);
    plus_at[d] = total, total += std::size_t(width[d]);
  }
  offsets.resize(total);
  const double* t = table_.data();
  const int* c = from_low.data();
  for (std::size_t u = 0; u < n_a; ++u) {
    for (int d = 0; d < dim; ++d)
      for (int j = 0; j < width[d]; ++j) {
        const int y = low[d] + j;
        offsets[minus_at[d] + std::size_t(j)] = offset(d, near_fold(a[u][d] - y, period_[d]), stride[d]);
        if (!periodic_) offsets[plus_at[d] + std::size_t(j)] = offset(d, near_fold(a[u][d] + y, period_[d]), stride[d]);
        if (d == dim - 1 && missing_ != SIZE_MAX &&
            (offsets[minus_at[d] + std::size_t(j)] == missing_ ||
             (!periodic_ && offsets[plus_at[d] + std::size_t(j)] == missing_)))
          throw std::logic_error("GreenTable: the sums read a plane that was not copied");
      }
    const std::size_t *xm = offsets.data() + minus_at[0], *xp = offsets.data() + plus_at[0];
    const std::size_t *ym = offsets.data() + minus_at[1], *yp = offsets.data() + plus_at[1];
    double sum = 0.0;
    if constexpr (dim == 2) {
      if (periodic_) {
        for (std::size_t k = 0; k < n_b; ++k)
          if (!partial_ || ym[c[2 * k + 1]] != zeros_) sum += t[ym[c[2 * k + 1]] + xm[c[2 * k]]] * w[k];
      } else if (!partial_) {
        for (std::size_t k = 0; k < n_b; ++k) {
          const int cx = c[2 * k], cy = c[2 * k + 1];
          sum += reflections(t + ym[cy], t + yp[cy], xm[cx], xp[cx]) * w[k];
        }
      } else {
        for (std::size_t k = 0; k < n_b; ++k) {
          const int cx = c[2 * k], cy = c[2 * k + 1];
          const double *tm = t + ym[cy], *tp = t + yp[cy];
          switch (held(ym[cy], yp[cy], zeros_)) {  // rows held elsewhere: zeros, skipped (the same bits)
            case both:
              sum += reflections(tm, tp, xm[cx], xp[cx]) * w[k];
              break;
            case minus_only:
              sum += (tm[xm[cx]] - tm[xp[cx]]) * w[k];
              break;
            case plus_only:
              sum += (-tp[xm[cx]] + tp[xp[cx]]) * w[k];
              break;
            case neither:
              break;
          }
        }
      }
    } else {
      const std::size_t *zm = offsets.data() + minus_at[2], *zp = offsets.data() + plus_at[2];
      if (periodic_) {
        for (std::size_t k = 0; k < n_b; ++k)
          if (!partial_ || zm[c[3 * k + 2]] != zeros_)
            sum += t[zm[c[3 * k + 2]] + ym[c[3 * k + 1]] + xm[c[3 * k]]] * w[k];
      } else if (!partial_) {
        for (std::size_t k = 0; k < n_b; ++k) {
          const int cx = c[3 * k], cy = c[3 * k + 1], cz = c[3 * k + 2];
          sum += reflections(t + ym[cy] + zm[cz], t + yp[cy] + zm[cz], t + ym[cy] + zp[cz], t + yp[cy] + zp[cz], xm[cx],
                             xp[cx]) *
                 w[k];
        }
      } else {
        for (std::size_t k = 0; k < n_b; ++k) {
          const int cx = c[3 * k], cy = c[3 * k + 1], cz = c[3 * k + 2];
          const double *mm = t + ym[cy] + zm[cz], *pm = t + yp[cy] + zm[cz], *mp = t + ym[cy] + zp[cz],
                       *pp = t + yp[cy] + zp[cz];
          switch (held(zm[cz], zp[cz], zeros_)) {  // planes held elsewhere: zeros, skipped (the same bits)
            case both:
              sum += reflections(mm, pm, mp, pp, xm[cx], xp[cx]) * w[k];
              break;
            case minus_only:
              sum += reflections(mm, pm, xm[cx], xp[cx]) * w[k];
              break;
            case plus_only:
              sum += -reflections(mp, pp, xm[cx], xp[cx]) * w[k];
              break;
            case neither:
              break;
          }
        }
      }
    }
    out[u] = sum;
  }
}

template class GreenTable<2>;
template class GreenTable<3>;

}  // namespace fictus
