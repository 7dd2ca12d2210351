#pragma once
// The smooth variant's rows on a sphere about the box's center, for the tests of the Schur blocks
// (unit and mpirun).
#include "fictus/boundary/surface.hpp"
#include "fictus/boundary/surface_integrals.hpp"
#include "fictus/boundary/trace_operators.hpp"
#include "fictus/grid/grid.hpp"
#include "fictus/grid/sparse_rows.hpp"

namespace fictus::test_support {

/// B_γ and C_γ at the points, patch integrals Q on Γ at δ = delta_cells·h, patches of about
/// patch_cells·h, on the unit box with N cells per axis.
struct SphereRows {
  Grid3 grid;
  SparseRows B, C, Q;
  SphereRows(Boundary boundary, double radius, int N, double patch_cells, double delta_cells)
      : grid(Box3{{0, 0, 0}, {1, 1, 1}}, N, boundary) {
    const double h = grid.h();
    const Ellipsoid sphere({0.5, 0.5, 0.5}, {radius, radius, radius});
    const int m = int(sphere.area() / (patch_cells * h * patch_cells * h));
    const PatchedSurface s = sphere.patches(m, h);
    std::vector<Triangle3> Gamma = s.triangles;
    for (Triangle3& t : Gamma)
      for (Point3* p : {&t.a, &t.b, &t.c}) {
        const Point3 d = *p - Point3{0.5, 0.5, 0.5};
        *p = *p + (delta_cells * h / norm(d)) * d;
      }
    B = point_value_rows(grid, s.point);
    C = normal_derivative_rows_centered(grid, s.point, s.normal);
    Q = patch_integral_rows(grid, patch_integrals(grid, Gamma, s.patch_of, m), m);
  }
};

}  // namespace fictus::test_support
