#pragma once
// Q1 load vector f_k = ∫_Ω f φ_k at the interior nodes, by a q×q Gauss rule on every cell.
#include <functional>
#include <optional>

#include "fictus/grid/execution.hpp"
#include "fictus/grid/grid.hpp"

namespace fictus {

using ScalarField = std::function<double(double x, double y)>;
using GradientField = std::function<Point2(double x, double y)>;
/// A field evaluated on many points at once: out[k] = F(x[k], y[k]) for k < n (e.g. a numpy
/// callable). Called with one batch per cell row; must be thread-safe when threads > 1.
using VectorizedField = std::function<void(std::size_t n, const double* x, const double* y, double* out)>;

/// Pointwise field as a vectorized one.
VectorizedField vectorize(ScalarField f);

/// q = Gauss points per direction (q = 2 is O(h⁴) per cell, enough for the Q1 rates when f is
/// smooth inside cells). f must be thread-safe (it is called from `threads` threads).
GridVector assemble_load(const Grid2& grid, const ScalarField& f, int q = 2, const Execution& execution = Execution{});
/// With `slab`: only the slab's entries (a rank's layers, Slab; the cells that touch them evaluated).
GridVector assemble_load(const Grid2& grid, const VectorizedField& f, int q = 2,
                         const Execution& execution = Execution{}, std::optional<Slab> slab = std::nullopt);

/// 3-D: f_k = ∫_Ω f φ_k with the trilinear basis, q×q×q Gauss points per voxel (threaded over voxel
/// layers; f must be thread-safe).
using ScalarField3 = std::function<double(double x, double y, double z)>;
/// A 3-D field on many points at once: out[k] = F(x[k], y[k], z[k]) for k < n (e.g. a numpy callable).
/// Called with one batch per voxel row; must be thread-safe when threads > 1.
using VectorizedField3 =
    std::function<void(std::size_t n, const double* x, const double* y, const double* z, double* out)>;
using GradientField3 = std::function<Point3(double x, double y, double z)>;
VectorizedField3 vectorize(ScalarField3 f);
GridVector assemble_load(const Grid3& grid, const ScalarField3& f, int q = 2, const Execution& execution = Execution{});
GridVector assemble_load(const Grid3& grid, const VectorizedField3& f, int q = 2,
                         const Execution& execution = Execution{}, std::optional<Slab> slab = std::nullopt);

/// The field types of a dimension: a value, a value in batches and a gradient at a point.
template <int dim>
struct Fields;
template <>
struct Fields<2> {
  using Scalar = ScalarField;
  using Vectorized = VectorizedField;
  using Gradient = GradientField;
};
template <>
struct Fields<3> {
  using Scalar = ScalarField3;
  using Vectorized = VectorizedField3;
  using Gradient = GradientField3;
};

}  // namespace fictus
