#pragma once
// 3-D: a closed surface given as a triangle mesh (a file in OFF, STL, OBJ or PLY, or vertex and face
// arrays). The mesh is checked (closed, manifold, free of self-intersections, oriented outward) with
// CGAL, and turned into a smooth level function: its signed distance sampled on a lattice of
// `resolution` cells across the mesh's largest side, interpolated by a C² tricubic B-spline. γ is the
// zero set of that spline: it follows the mesh to O(ℓ⁴) where the mesh is smooth on the lattice's
// scale ℓ and rounds edges sharper than that (docs/math.md, "Surfaces from meshes"). The solver then
// treats it as an implicit surface (marching tetrahedra, patches, curvature from the spline).
#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "fictus/boundary/surface.hpp"
#include "fictus/grid/point.hpp"

namespace fictus {

/// A C² tricubic B-spline interpolating values on the nodes of a uniform lattice: lower + ℓ·(i, j, k),
/// 0 ≤ i, j, k ≤ n (mirror-symmetric beyond the ends). Outside the lattice's box the value is the
/// spline at the nearest point of the box plus the distance to it (continuous, growing outward).
class LatticeSpline {
 public:
  /// `values[(k·(n+1) + j)·(n+1) + i]` at node (i, j, k); n ≥ 2, ℓ > 0.
  LatticeSpline(Point3 lower, double spacing, int n, std::vector<double> values);
  double value(const Point3& p) const;
  Point3 gradient(const Point3& p) const;
  Matrix3 hessian(const Point3& p) const;
  Box3 box() const;
  double spacing() const { return spacing_; }
  int cells() const { return n_; }

 private:
  /// Value, gradient and Hessian at p (the derivatives only when asked).
  double evaluate(const Point3& p, Point3* gradient, Matrix3* hessian) const;
  Point3 lower_;
  double spacing_;
  int n_;
  std::vector<double> coefficients_;
};

/// Lattice cells across the mesh's largest side (geometry.resolution). 0 chooses: the largest side
/// over twice the median edge length, within [16, 128]: a lattice as fine as the edges sees the
/// facets as ripples of the curvature (measured in docs/notes/meshes.md, "The level function").
inline constexpr int automatic_mesh_resolution = 0;
inline constexpr int default_mesh_resolution = 128;
inline constexpr int min_mesh_resolution = 16;
inline constexpr int max_mesh_resolution = 256;  // (272 + 1)³ lattice nodes: about 0.5 GB while it is built

/// Throws std::invalid_argument naming geometry.resolution unless it is 0 or a whole number in [16, 256].
void check_mesh_resolution(double resolution);

/// A polygon soup as read from a file: vertices and faces (three or more vertex indices each).
struct PolygonSoup {
  std::vector<Point3> vertices;
  std::vector<std::vector<std::size_t>> faces;
};

/// Reads OFF, STL (ASCII or binary), OBJ or PLY, chosen by the file's extension. Throws
/// std::invalid_argument naming `field` when the file cannot be read, has another extension, or holds
/// no faces or a coordinate that is not finite.
PolygonSoup read_polygon_soup(const std::string& path, const std::string& field = "geometry.file");

/// Writes `soup` as an OFF file (for tests and examples).
void write_off(const std::string& path, const PolygonSoup& soup);

/// A sphere as a mesh: the icosahedron's faces split in four `levels` times, the vertices moved onto
/// the sphere; 20·4^levels triangles, oriented outward.
PolygonSoup icosphere(Point3 center, double radius, int levels);

class MeshSurface final : public Surface {
 public:
  /// Checks the mesh and builds the level function. Throws std::invalid_argument naming `field` for a
  /// mesh that is empty, not finite, has a face index out of range, is not closed, not manifold,
  /// intersects itself, or encloses no volume; and naming geometry.resolution for a resolution out
  /// of [16, 256] (0: automatic). An inward-oriented mesh is reoriented (see warnings()).
  MeshSurface(const PolygonSoup& soup, int resolution = automatic_mesh_resolution,
              const std::string& field = "geometry.file");
  ~MeshSurface() override;

  double level(const Point3& p) const override { return spline_->value(p); }
  Point3 level_gradient(const Point3& p) const override { return spline_->gradient(p); }
  Matrix3 level_hessian(const Point3& p) const override { return spline_->hessian(p); }
  PatchedSurface patches(int m, double edge) const override { return implicit_->patches(m, edge); }
  double area() const override { return implicit_->area(); }
  Box3 bounds() const override { return implicit_->bounds(); }
  double reach() const override { return implicit_->reach(); }

  /// The distance from p to the mesh itself (not to the spline's zero set).
  double distance_to_mesh(const Point3& p) const;
  /// What the checks changed: "the mesh was oriented inward: reversed" and the like.
  const std::vector<std::string>& warnings() const { return warnings_; }
  std::size_t mesh_vertices() const { return vertices_; }
  std::size_t mesh_faces() const { return faces_; }
  /// The lattice spacing ℓ, and the cells across the mesh's largest side.
  double spacing() const { return spline_->spacing(); }
  int resolution() const { return resolution_; }

 private:
  struct Mesh;
  std::unique_ptr<const Mesh> mesh_;
  std::shared_ptr<const LatticeSpline> spline_;
  std::unique_ptr<ImplicitSurface> implicit_;
  std::vector<std::string> warnings_;
  std::size_t vertices_ = 0, faces_ = 0;
  int resolution_ = 0;
};

}  // namespace fictus
