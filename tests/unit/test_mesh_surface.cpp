// Surfaces from meshes: the lattice spline (interpolation, derivatives, fourth order), the four file
// formats, the checks of bad meshes with their one-line errors, and the level set of a sphere's mesh
// against the sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <stdexcept>
#include <string>

#include "fictus/boundary/mesh_surface.hpp"

namespace {

using fictus::Point3;
using fictus::PolygonSoup;

double smooth(const Point3& p) { return std::sin(2 * p.x) * std::cos(3 * p.y) * std::exp(p.z); }

fictus::LatticeSpline spline_of(int n) {
  const double spacing = 1.0 / n;
  std::vector<double> values;
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) values.push_back(smooth({i * spacing, j * spacing, k * spacing}));
  return fictus::LatticeSpline({0, 0, 0}, spacing, n, values);
}

TEST(LatticeSpline, InterpolatesTheNodes) {
  const fictus::LatticeSpline s = spline_of(12);
  for (int k = 0; k <= 12; k += 3)
    for (int j = 0; j <= 12; j += 4)
      for (int i = 0; i <= 12; ++i) {
        const Point3 p{i / 12.0, j / 12.0, k / 12.0};
        EXPECT_NEAR(s.value(p), smooth(p), 1e-13) << i << " " << j << " " << k;
      }
}

TEST(LatticeSpline, DerivativesAreThoseOfTheValue) {
  const fictus::LatticeSpline s = spline_of(10);
  const double step = 1e-5;
  for (const Point3& p :
       {Point3{0.31, 0.52, 0.47}, Point3{0.05, 0.93, 0.11}, Point3{0.66, 0.23, 0.85}}) {  // off the knots
    const Point3 g = s.gradient(p);
    const fictus::Matrix3 H = s.hessian(p);
    for (int d = 0; d < 3; ++d) {
      Point3 plus = p, minus = p;
      plus[d] += step;
      minus[d] -= step;
      EXPECT_NEAR(g[d], (s.value(plus) - s.value(minus)) / (2 * step), 1e-7);
      const Point3 dg = (1 / (2 * step)) * (s.gradient(plus) - s.gradient(minus));
      for (int e = 0; e < 3; ++e) EXPECT_NEAR(H[d][e], dg[e], 1e-6);
    }
  }
}

TEST(LatticeSpline, ConvergesAtFourthOrderInside) {
  double previous = 0;
  for (int n : {8, 16, 32}) {
    const fictus::LatticeSpline s = spline_of(n);
    double error = 0;  // away from the ends, where the mirror condition costs order
    for (int k = 0; k < 7; ++k)
      for (int j = 0; j < 7; ++j)
        for (int i = 0; i < 7; ++i) {
          const Point3 p{0.35 + 0.041 * i, 0.33 + 0.047 * j, 0.36 + 0.043 * k};
          error = std::max(error, std::abs(s.value(p) - smooth(p)));
        }
    if (previous > 0) EXPECT_GT(previous / error, 12.0) << "n = " << n;  // 16 for fourth order
    previous = error;
  }
  EXPECT_LT(previous, 1e-6);
}

TEST(LatticeSpline, GrowsOutsideItsBox) {
  const fictus::LatticeSpline s = spline_of(8);
  EXPECT_NEAR(s.value({1.5, 0.5, 0.5}), s.value({1, 0.5, 0.5}) + 0.5, 1e-14);
  EXPECT_NEAR(s.gradient({1.5, 0.5, 0.5}).x, 1.0, 1e-14);
  EXPECT_THROW(fictus::LatticeSpline({0, 0, 0}, 0.1, 4, std::vector<double>(10)), std::invalid_argument);
}

class MeshFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("fictus_mesh_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }
  std::filesystem::path dir_;
};

/// The message of the std::invalid_argument that `f` throws ("" when none).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();  // one line
    return e.what();
  }
  return "";
}

/// The soup as text in each format (STL repeats the vertices of every triangle).
std::string as_off(const PolygonSoup& s) {
  std::string t = "OFF\n" + std::to_string(s.vertices.size()) + " " + std::to_string(s.faces.size()) + " 0\n";
  for (const Point3& v : s.vertices)
    t += std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z) + "\n";
  for (const auto& f : s.faces)
    t += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
  return t;
}
std::string as_obj(const PolygonSoup& s) {
  std::string t;
  for (const Point3& v : s.vertices)
    t += "v " + std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z) + "\n";
  for (const auto& f : s.faces)
    t += "f " + std::to_string(f[0] + 1) + " " + std::to_string(f[1] + 1) + " " + std::to_string(f[2] + 1) + "\n";
  return t;
}
std::string as_stl(const PolygonSoup& s) {
  std::string t = "solid mesh\n";
  for (const auto& f : s.faces) {
    t += "facet normal 0 0 0\nouter loop\n";
    for (std::size_t k : f) {
      const Point3& v = s.vertices[k];
      t += "vertex " + std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z) + "\n";
    }
    t += "endloop\nendfacet\n";
  }
  return t + "endsolid mesh\n";
}
std::string as_ply(const PolygonSoup& s) {
  std::string t = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(s.vertices.size()) +
                  "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
                  std::to_string(s.faces.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Point3& v : s.vertices)
    t += std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z) + "\n";
  for (const auto& f : s.faces)
    t += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
  return t;
}

TEST_F(MeshFiles, TheFourFormatsGiveTheSameSurface) {
  const PolygonSoup sphere = fictus::icosphere({0.5, 0.5, 0.5}, 0.3, 2);
  const std::vector<std::pair<std::string, std::string>> files = {
      {"s.off", as_off(sphere)}, {"s.obj", as_obj(sphere)}, {"s.STL", as_stl(sphere)}, {"s.ply", as_ply(sphere)}};
  double first_level = 0;
  for (const auto& [name, text] : files) {
    const fictus::MeshSurface m(fictus::read_polygon_soup(write(name, text)), 32);
    EXPECT_EQ(m.mesh_vertices(), 162u) << name;  // the STL's repeated vertices are merged
    EXPECT_EQ(m.mesh_faces(), 320u) << name;
    EXPECT_TRUE(m.warnings().empty()) << name;
    const double level = m.level({0.5, 0.5, 0.5});
    if (name == "s.off") first_level = level;
    EXPECT_NEAR(level, first_level, 1e-9) << name;
  }
  EXPECT_NEAR(first_level, -0.3, 0.01);
}

TEST_F(MeshFiles, BadFilesGiveOneLineErrors) {
  EXPECT_NE(error_of([&] { fictus::read_polygon_soup(path("none.off")); }).find("geometry.file: '"), std::string::npos);
  EXPECT_NE(
      error_of([&] { fictus::read_polygon_soup(write("a.txt", "OFF\n")); }).find("expected a .off, .stl, .obj or .ply"),
      std::string::npos);
  EXPECT_NE(
      error_of([&] { fictus::read_polygon_soup(write("g.off", "not a mesh at all\n1 2 3\n")); }).find("geometry.file"),
      std::string::npos);
  EXPECT_NE(error_of([&] { fictus::read_polygon_soup(write("e.obj", "v 0 0 0\nv 1 0 0\n")); }).find("geometry.file"),
            std::string::npos);
  // CGAL's PLY reader would write out of bounds for a property before any element: checked first.
  EXPECT_NE(error_of([&] {
              fictus::read_polygon_soup(write("p.ply",
                                              "ply\nformat ascii 1.0\nproperty double x\nelement face 1\n"
                                              "property list uchar int vertex_indices\nend_header\n3 0 1 2\n"));
            }).find("a property before any element"),
            std::string::npos);
  // Counts beyond what the file holds are refused before the reader sizes its arrays by them.
  EXPECT_NE(error_of([&] {
              fictus::read_polygon_soup(write("big.off", "OFF\n2000000000 2000000000 0\n0 0 0\n"));
            }).find("counts are more than the file holds"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              fictus::read_polygon_soup(write("big.ply",
                                              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                              "element face 1\nproperty list uint int vertex_indices\n"
                                              "end_header\n0\n0\n0\n3 0 1 2\n"));
            }).find("wider than 16 bits"),
            std::string::npos);
  std::string binary(84, '\0');
  binary[80] = char(0xff), binary[81] = char(0xff), binary[82] = char(0xff), binary[83] = char(0x7f);
  EXPECT_NE(error_of([&] { fictus::read_polygon_soup(write("big.stl", binary)); }).find("triangle count"),
            std::string::npos);
  std::filesystem::create_directories(path("folder.off"));
  EXPECT_NE(error_of([&] { fictus::read_polygon_soup(path("folder.off")); }).find("no such file"), std::string::npos);
}

TEST(MeshSurface, BadMeshesAreRefusedByName) {
  const PolygonSoup sphere = fictus::icosphere({0.5, 0.5, 0.5}, 0.3, 1);
  PolygonSoup open = sphere;
  open.faces.pop_back();
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(open); }).find("not closed"), std::string::npos);

  PolygonSoup two = sphere;  // a second sphere overlapping the first
  const PolygonSoup other = fictus::icosphere({0.6, 0.5, 0.5}, 0.3, 1);
  for (const auto& f : other.faces)
    two.faces.push_back({f[0] + sphere.vertices.size(), f[1] + sphere.vertices.size(), f[2] + sphere.vertices.size()});
  two.vertices.insert(two.vertices.end(), other.vertices.begin(), other.vertices.end());
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(two); }).find("intersects itself"), std::string::npos);

  // Two tetrahedra sharing an edge: four faces on it.
  PolygonSoup pinched;
  pinched.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0.2}, {0.5, 0.3, 1}, {0.5, -1, 0.2}, {0.5, -0.3, -1}};
  pinched.faces = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}, {0, 1, 4}, {0, 5, 1}, {1, 5, 4}, {0, 4, 5}};
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(pinched); }).find("not a manifold"), std::string::npos);

  PolygonSoup bad = sphere;
  bad.vertices[3].y = std::nan("");
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(bad); }).find("not finite"), std::string::npos);
  bad = sphere;
  bad.vertices[3].y = 1e200;
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(bad); }).find("beyond 1e100"), std::string::npos);
  bad = sphere;
  bad.faces[0][1] = 100000;
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(bad); }).find("refers to vertex 100000"), std::string::npos);
  bad.faces = {};
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(bad); }).find("no faces"), std::string::npos);
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(sphere, 8); }).find("geometry.resolution"), std::string::npos);
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(sphere, 4096); }).find("geometry.resolution"), std::string::npos);
  EXPECT_NE(error_of([&] { fictus::MeshSurface m(open, 32, "geometry.vertices"); }).find("geometry.vertices: "),
            std::string::npos);
}

TEST(MeshSurface, AnInwardMeshIsReorientedWithAWarning) {
  const PolygonSoup sphere = fictus::icosphere({0.5, 0.5, 0.5}, 0.3, 2);
  PolygonSoup inward = sphere;
  for (auto& f : inward.faces) std::swap(f[1], f[2]);
  const fictus::MeshSurface a(sphere, 32), b(inward, 32);
  EXPECT_TRUE(a.warnings().empty());
  ASSERT_EQ(b.warnings().size(), 1u);
  EXPECT_NE(b.warnings()[0].find("reoriented"), std::string::npos);
  for (const Point3& p : {Point3{0.5, 0.5, 0.5}, Point3{0.81, 0.5, 0.5}, Point3{0.2, 0.3, 0.9}})
    EXPECT_NEAR(a.level(p), b.level(p), 1e-12);
}

TEST(MeshSurface, TheLevelSetOfASphereMeshIsTheSphereToTheMeshesSag) {
  const double R = 0.3;
  const Point3 c{0.5, 0.5, 0.5};
  const PolygonSoup soup = fictus::icosphere(c, R, 4);  // 5120 triangles, edges about 0.019
  const fictus::MeshSurface m(soup);
  EXPECT_EQ(m.mesh_faces(), 5120u);
  EXPECT_GE(m.resolution(), 16);
  EXPECT_LE(m.resolution(), 128);
  // The facets sag up to edge²/(8R) ≈ 1.5e-4 inside the sphere; the level set follows them.
  const fictus::PatchedSurface p = m.patches(200, 0.01);
  double deviation = 0, polyhedron_area = 0;
  for (const auto& t : p.triangles)
    for (const Point3& v : {t.a, t.b, t.c}) deviation = std::max(deviation, std::abs(norm(v - c) - R));
  EXPECT_LT(deviation, 4e-4);
  for (const auto& f : soup.faces)
    polyhedron_area += fictus::area(fictus::Triangle3{soup.vertices[f[0]], soup.vertices[f[1]], soup.vertices[f[2]]});
  EXPECT_NEAR(m.area() / polyhedron_area, 1.0, 2e-3);
  EXPECT_GT(m.reach(), 0.1);           // a convex mesh: no fold within a third of the radius
  for (int q = 0; q < p.m; q += 17) {  // points and normals of the patches: on the mesh, radial
    EXPECT_LT(m.distance_to_mesh(p.point[q]), 2e-4);
    EXPECT_GT(dot(p.normal[q], (1 / norm(p.point[q] - c)) * (p.point[q] - c)), 0.999);
  }
  // Inside negative, outside positive, about the signed distance near γ.
  EXPECT_LT(m.level(c), 0);
  EXPECT_NEAR(m.level({0.5, 0.5, 0.85}), 0.05, 3e-4);
  EXPECT_NEAR(m.level({0.5, 0.5, 0.75}), -0.05, 3e-4);
}

TEST(MeshSurface, AHollowShellWithItsInnerFacesOutwardIsReorientedWithAWarning) {
  PolygonSoup hollow = fictus::icosphere({0.5, 0.5, 0.5}, 0.35, 2);
  const PolygonSoup inner = fictus::icosphere({0.5, 0.5, 0.5}, 0.2, 2);  // pointing outward: wrong for a cavity
  const std::size_t offset = hollow.vertices.size();
  hollow.vertices.insert(hollow.vertices.end(), inner.vertices.begin(), inner.vertices.end());
  for (const auto& f : inner.faces) hollow.faces.push_back({f[0] + offset, f[1] + offset, f[2] + offset});
  const fictus::MeshSurface m(hollow, 48);
  ASSERT_EQ(m.warnings().size(), 1u);
  EXPECT_NE(m.warnings()[0].find("reoriented to bound a volume"), std::string::npos);
  EXPECT_GT(m.level({0.5, 0.5, 0.5}), 0.1);  // the cavity is outside ω
  EXPECT_LT(m.level({0.5, 0.5, 0.78}), 0);   // between the shells is inside
}

TEST(MeshSurface, TheLevelFunctionIsTheSignedDistanceAwayFromTheSurfaceToo) {
  // Exact distances within 6ℓ of the mesh; farther nodes take the nearest points swept from there
  // (measured: 0.3–0.6 % off at 6–10ℓ).
  const Point3 c{0.5, 0.5, 0.5};
  const fictus::MeshSurface m(fictus::icosphere(c, 0.3, 3), 32);  // ℓ = 0.01875
  for (const Point3& p : {Point3{0.5, 0.5, 0.5}, Point3{0.6, 0.45, 0.52}, Point3{0.5, 0.5, 0.92},
                          Point3{0.15, 0.2, 0.5}, Point3{0.36, 0.5, 0.5}, Point3{0.5, 0.5, 0.88}}) {
    const double d = m.distance_to_mesh(p);
    EXPECT_NEAR(std::abs(m.level(p)), d, (d < 6 * m.spacing() ? 2e-3 : 1e-2) * std::max(d, 0.05))
        << p.x << " " << p.y << " " << p.z;
  }
  // Beyond the lattice's box (8 cells past the mesh): the value at the box plus the distance to it.
  const Point3 far{0.5, 0.5, 2.0};
  EXPECT_NEAR(m.level(far), m.distance_to_mesh(far), 0.01);
  EXPECT_NEAR(m.level_gradient(far).z, 1.0, 1e-12);
  EXPECT_TRUE(std::isnan(m.level({std::nan(""), 0.5, 0.5})));
}

}  // namespace
