#pragma once
// Quadrature over ω ⊂ Ω in 3-D, where γ = ∂ω is a Surface: whole voxels by Gauss points, voxels cut
// by γ by a rule that follows γ (docs/math.md, "Quadrature"). The load of 1_ω, ∫_ω f and the error
// integrals use it.
#include <functional>
#include <optional>
#include <vector>

#include "fictus/boundary/surface.hpp"
#include "fictus/grid/execution.hpp"
#include "fictus/grid/grid.hpp"
#include "fictus/grid/load_vector.hpp"

namespace fictus {

/// ∫_ω w over the part of each voxel inside γ: full voxels by q³ Gauss points, voxels near γ split
/// in 8 and each cut half-voxel by a rule along the axis where γ is steepest (the segment of each
/// Gauss line inside ω found by root finding on the level set, then q Gauss points on it), exact up
/// to the quadrature's degree for integrands smooth in the voxel. `visit(thread, cell, x, weight)` is
/// called from `execution.threads()` threads at once, `thread` in [0, threads): keep sums per thread.
using OmegaVisitor = std::function<void(int thread, const Grid3::Index& cell, const Point3& x, double weight)>;
void for_each_omega_point(const Grid3& grid, const Surface& gamma, int q, const Execution& execution,
                          const OmegaVisitor& visit);
/// The same points one voxel row (fixed y and z) at a time, for integrands evaluated in batches.
struct OmegaPoint {
  Grid3::Index cell;
  Point3 x;
  double weight;
};
using OmegaRowVisitor = std::function<void(int thread, const std::vector<OmegaPoint>& row)>;
void for_each_omega_row(const Grid3& grid, const Surface& gamma, int q, const Execution& execution,
                        const OmegaRowVisitor& visit);
/// The same for the voxel layers that belong to the slab's layers only (Grid::cell_layer).
void for_each_omega_row(const Grid3& grid, const Surface& gamma, int q, const Execution& execution, const Slab& slab,
                        const OmegaRowVisitor& visit);

/// May γ come within `radius` of `center`? (|level| ≤ 2·radius·|∇level| there: the distance is about
/// |level|/|∇level| near γ, with a factor 2 to spare.)
bool near_surface(const Surface& gamma, const Point3& center, double radius);

/// The points of that rule in one voxel (none for a voxel outside ω), on the calling thread.
/// `depth` > 0 splits the half-voxels where γ meets the faces across the line direction up to that many times more.
void for_each_omega_point_in_voxel(const Grid3& grid, const Surface& gamma, const Grid3::Index& cell, int q,
                                   const std::function<void(const Point3& x, double weight)>& visit, int depth = 0);

/// ∫_ω φ_k for every node with an unknown: h³/8 per corner of a voxel wholly inside γ, the rule above
/// on the voxels near γ (the load of f = 1_ω). γ must stay a cell away from the walls (solve checks
/// 2h), so that no two of the parallel voxel layers write one node plane of a periodic grid. With
/// `slab`: only that slab's layers (a rank's; the voxels that touch them visited).
GridVector omega_load(const Grid3& grid, const Surface& gamma, int q = 3, const Execution& execution = Execution{},
                      std::optional<Slab> slab = std::nullopt);

/// ∫_ω f by that rule, f evaluated one voxel row at a time and the rows summed in order (the same
/// result on any number of threads). Distributed (`execution`'s distribution), each rank evaluates its
/// slab's voxel layers and every rank gets the serial total (collective).
double omega_integral(const Grid3& grid, const Surface& gamma, const VectorizedField3& f, int q = 3,
                      const Execution& execution = Execution{});

/// The volume of ω by that rule (a test of it).
double omega_volume(const Grid3& grid, const Surface& gamma, int q = 3, const Execution& execution = Execution{});

}  // namespace fictus
