#pragma once
// Closed surfaces γ = ∂ω in a 3-D box, given by a level-set function (level < 0 in ω, > 0 outside)
// with a triangulation split into patches on demand: ellipsoids (spheres), tori, any implicit surface
// and (mesh_surface.hpp) triangle meshes.
#include <array>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "fictus/boundary/surface_integrals.hpp"
#include "fictus/grid/load_vector.hpp"
#include "fictus/grid/point.hpp"

namespace fictus {

/// A symmetric 3 × 3 matrix by rows.
using Matrix3 = std::array<Point3, 3>;

/// A closed surface γ = ∂ω given by a level-set function: level(x) < 0 in ω, > 0 outside, with a
/// triangulation split into patches on demand.
class Surface {
 public:
  virtual ~Surface() = default;
  virtual double level(const Point3& p) const = 0;
  virtual Point3 level_gradient(const Point3& p) const = 0;
  /// The Hessian of the level function (default: central differences of level_gradient).
  virtual Matrix3 level_hessian(const Point3& p) const;
  /// γ triangulated with edges of about `edge` or less, split into m patches of nearly equal area,
  /// with a point on γ and its outward normal per patch.
  virtual PatchedSurface patches(int m, double edge) const = 0;
  /// The area of γ (for the default m).
  virtual double area() const = 0;
  /// A box holding γ.
  virtual Box3 bounds() const = 0;
  /// The largest outward offset whose surface does not touch itself (infinite for a convex γ).
  virtual double reach() const { return std::numeric_limits<double>::infinity(); }
};

/// (x − c)ᵀ diag(a)⁻² (x − c) < 1, axis-aligned; a sphere when the semi-axes are equal.
class Ellipsoid final : public Surface {
 public:
  /// Throws std::invalid_argument naming geometry.center or geometry.semi_axes.
  Ellipsoid(Point3 center, Point3 semi_axes);
  double level(const Point3& p) const override;
  Point3 level_gradient(const Point3& p) const override;
  Matrix3 level_hessian(const Point3& p) const override;
  PatchedSurface patches(int m, double edge) const override;
  double area() const override;
  Box3 bounds() const override;
  Point3 center() const { return center_; }
  Point3 semi_axes() const { return semi_axes_; }

 private:
  Point3 center_, semi_axes_;
};

/// ((x − c)_xy distance from the z-axis through c − R)² + (z − c_z)² < r², 0 < r < R: a torus
/// about the z-axis (genus one).
class Torus final : public Surface {
 public:
  /// Throws std::invalid_argument naming geometry.center or geometry.radii.
  Torus(Point3 center, double R, double r);
  double level(const Point3& p) const override;
  Point3 level_gradient(const Point3& p) const override;
  Matrix3 level_hessian(const Point3& p) const override;
  PatchedSurface patches(int m, double edge) const override;
  double area() const override;
  Box3 bounds() const override;
  double reach() const override { return R_ - r_; }

 private:
  Point3 center_;
  double R_, r_;
};

using HessianField3 = std::function<Matrix3(const Point3& p)>;

/// level(x) < 0 in ω, any smooth function with a nonzero gradient on its zero set, inside a box that
/// holds γ: triangulated by marching tetrahedra on a lattice of cubes of side `edge` (the crossings on the
/// tetrahedra's edges by root finding), split into patches as the built-in shapes are. Derivatives from
/// `gradient` and `hessian` when given, else by central differences (steps 1e-5 and 1e-4 of the
/// largest side of γ's box).
class ImplicitSurface final : public Surface {
 public:
  /// Throws std::invalid_argument naming geometry.bounds (not a box, or γ reaches its faces) or
  /// geometry.level (not finite, no surface inside the box, or a vanishing gradient on γ).
  ImplicitSurface(ScalarField3 level, Box3 bounds, GradientField3 gradient = {}, HessianField3 hessian = {});
  double level(const Point3& p) const override;
  Point3 level_gradient(const Point3& p) const override;
  Matrix3 level_hessian(const Point3& p) const override;
  PatchedSurface patches(int m, double edge) const override;
  /// From a triangulation with cubes of 1/96 of the box's largest side (relative error O((edge·κ)²)).
  double area() const override { return area_; }
  /// The box of that triangulation's vertices grown by 1/20 of its cube side, within the given box.
  Box3 bounds() const override { return tight_; }
  /// 1/(the largest principal curvature of the concave side) on that triangulation's vertices: where
  /// outward offsets first fold. A neck between two distant parts of γ is not seen.
  double reach() const override { return reach_; }

 private:
  std::vector<Triangle3> triangulate(const Box3& box, double edge) const;
  ScalarField3 level_;
  GradientField3 gradient_;
  HessianField3 hessian_;
  Box3 bounds_, tight_;
  double scale_ = 1, area_ = 0, reach_ = 0;
};

/// γ rotated by `angle` about the axis `axis` (0: x, 1: y, 2: z) through the centre of its bounds,
/// then moved by `shift` (a sweep's members): level(x) = level₀(c + Rᵀ(x − shift − c)).
class TransformedSurface final : public Surface {
 public:
  TransformedSurface(std::shared_ptr<const Surface> base, int axis, double angle, Point3 shift);
  double level(const Point3& p) const override { return base_->level(back(p)); }
  Point3 level_gradient(const Point3& p) const override { return rotate(base_->level_gradient(back(p))); }
  Matrix3 level_hessian(const Point3& p) const override;
  /// The base's patches, rotated and moved.
  PatchedSurface patches(int m, double edge) const override;
  double area() const override { return base_->area(); }
  /// The box of the base's bounds' corners, rotated and moved.
  Box3 bounds() const override;
  double reach() const override { return base_->reach(); }

 private:
  Point3 rotate(const Point3& v) const;    // R v
  Point3 unrotate(const Point3& v) const;  // Rᵀ v
  Point3 back(const Point3& p) const { return center_ + unrotate(p - shift_ - center_); }
  Point3 forward(const Point3& p) const { return center_ + rotate(p - center_) + shift_; }
  std::shared_ptr<const Surface> base_;
  int axis_;
  double cos_, sin_;
  Point3 center_, shift_;
};

}  // namespace fictus
