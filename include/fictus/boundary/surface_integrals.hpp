#pragma once
// 3-D: integrals of the trilinear (Q1) basis over the patches of a triangulated surface, the entries of
// B_Γ when λ is piecewise constant on patches. Each triangle is clipped against the voxel planes into
// convex pieces inside one voxel; on a piece the trilinear basis is a cubic polynomial of the plane, so
// a degree-4 triangle rule on a fan of the piece integrates it exactly (to round-off).
#include <cstddef>
#include <functional>
#include <vector>

#include "fictus/grid/distribution.hpp"
#include "fictus/grid/grid.hpp"
#include "fictus/grid/point.hpp"

namespace fictus {

struct Triangle3 {
  Point3 a, b, c;
};

/// ∫_{patch} φ_node dS for one patch and one grid node (all nodes 0 ≤ i_d ≤ n_d: the caller drops those
/// that carry no unknown).
struct PatchWeight {
  int patch;
  Grid3::Index node;
  double value;
};

/// The nonzero ∫_{patch p} φ_k dS, sorted by patch, then by node in the grid's storage order (i fastest). `patch_of[t]`
/// is the patch of triangle t, in 0 … n_patches − 1. Throws std::invalid_argument for a triangle that is not finite or
/// leaves the box.
/// With `onto`, the integrals are over the curved surface the triangles approximate: `onto(x, n, factor)`
/// maps a point x of a triangle with unit normal n to the surface and sets factor = dS_surface/dS_triangle
/// there (the quadrature stays the pieces' rule: exact no longer, but free of the triangles' O(h²) offset).
/// `threads` share the triangles (and may call `onto` at once); the answer does not depend on their number.
/// Distributed, each rank integrates the triangles of one run of patches (of about equal triangle counts)
/// and every rank takes all runs (collective): the answer is the serial one, bit for bit, on every rank.
/// The triangles and `patch_of` must then be the same on every rank.
using SurfaceMap = std::function<Point3(const Point3& x, const Point3& normal, double& factor)>;
std::vector<PatchWeight> patch_integrals(const Grid3& grid, const std::vector<Triangle3>& triangles,
                                         const std::vector<int>& patch_of, int n_patches, const SurfaceMap& onto = {},
                                         int threads = 1, const Distribution& distribution = Distribution{});

/// The area of a triangle.
double area(const Triangle3& t);

}  // namespace fictus

namespace fictus {

/// A closed triangulated surface split into m patches (γ in a 3-D box): the triangles, the patch of
/// each, and per patch a collocation point on the surface, its outward unit normal and its area.
struct PatchedSurface {
  std::vector<Triangle3> triangles;
  std::vector<int> patch_of;
  int m = 0;
  std::vector<Point3> point, normal;
  std::vector<double> area;
};

/// An axis-aligned ellipsoid triangulated by a subdivided icosahedron mapped onto it (triangle edges
/// at most about `edge`), split into m patches of nearly equal area by Lloyd's iteration (k-means of the
/// triangle centroids, weighted by area). A patch's point is its area-weighted centroid moved onto the
/// ellipsoid along the ray from the center.
PatchedSurface ellipsoid_patches(Point3 center, Point3 semi_axes, int m, double edge);

/// Splits the triangles of `s` into m patches of nearly equal area (Lloyd's iteration on the area-weighted
/// triangle centroids): sets patch_of, m and area, sizes point and normal, and returns each patch's
/// centroid for the caller to move onto the surface. With `labels` (one per triangle), a patch takes
/// triangles of one label only: each label gets patches as many as keep the largest patch area smallest
/// (at least one), and `patch_labels` (if given) receives each patch's label.
std::vector<Point3> split_into_patches(PatchedSurface& s, int m, const std::vector<int>& labels = {},
                                       std::vector<int>* patch_labels = nullptr);

/// A torus about the z-axis through `center`: core radius R, tube radius r (0 < r < R), triangulated
/// by its angle chart with edges about `edge`, split into m patches (the nearest points of the torus to
/// the patch centroids, with the outward normals).
PatchedSurface torus_patches(Point3 center, double R, double r, int m, double edge);

}  // namespace fictus
