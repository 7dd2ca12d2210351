// Surfaces from triangle meshes: reading, checks and the signed distance by CGAL, then the lattice
// spline (lattice_spline.cpp). The only translation unit that includes CGAL: it is compiled with
// CGAL's flags (-frounding-math) apart from the numerics.
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <omp.h>
#include <boost/iterator/function_output_iterator.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "fictus/boundary/mesh_surface.hpp"

namespace fictus {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalPoint = Kernel::Point_3;
using TriangleMeshCgal = CGAL::Surface_mesh<CgalPoint>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<TriangleMeshCgal>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;
using Side = CGAL::Side_of_triangle_mesh<TriangleMeshCgal, Kernel>;
namespace PMP = CGAL::Polygon_mesh_processing;

/// Coordinates beyond this are refused: squared distances must stay finite.
constexpr double largest_coordinate = 1e100;

std::string at(const CgalPoint& p) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "(%.4g, %.4g, %.4g)", p.x(), p.y(), p.z());
  return buffer;
}

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw std::invalid_argument(field + ": " + what);
}

std::string extension_of(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

/// CGAL's PLY reader trusts the header: a `property` before any `element` is written out of bounds.
/// So the header is checked first: `ply`, a format line, every property after an element, vertex and
/// face elements, and `end_header`, within 64 KiB. Returns what is wrong, or "" when it is sound.
/// Also, since the reader sizes its arrays by the header's counts before reading them: the counts
/// must fit in the file (at least 2 bytes a value), and list counts must be 8 or 16 bits wide.
std::string ply_header_problem(const std::string& path, std::uintmax_t file_size) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) return "it does not start with 'ply'";
  bool format = false, element = false, vertex = false, face = false;
  double values = 0, count = 0;  // the least number of values the elements need, the current element's count
  std::size_t read = line.size();
  while (std::getline(in, line)) {
    read += line.size() + 1;
    if (read > (64u << 10)) return "its header is longer than 64 KiB";
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string word, name;
    words >> word;
    if (word == "format") {
      std::string kind;
      words >> kind;
      if (kind != "ascii" && kind != "binary_little_endian" && kind != "binary_big_endian")
        return "an unknown format in its header";
      format = true;
    } else if (word == "element") {
      words >> name >> count;
      if (!words || !(count >= 0)) return "an element without a count in its header";
      element = true;
      vertex = vertex || name == "vertex";
      face = face || name == "face";
    } else if (word == "property") {
      if (!element) return "a property before any element in its header";
      std::string type, count_type;
      words >> type;
      if (type == "list") {
        words >> count_type;
        if (count_type != "uchar" && count_type != "uint8" && count_type != "char" && count_type != "int8" &&
            count_type != "ushort" && count_type != "uint16" && count_type != "short" && count_type != "int16")
          return "a list whose count is wider than 16 bits in its header";
      }
      values += count;
      if (2 * values > double(file_size)) return "its header counts more values than the file holds";
    } else if (word == "end_header") {
      if (!format) return "no format line in its header";
      if (!vertex || !face) return "no vertex or no face element in its header";
      return "";
    } else if (word != "comment" && word != "obj_info" && !word.empty()) {
      return "an unknown line in its header";
    }
  }
  return "no end_header";
}

/// The same for OFF (vertex and face counts on the first line after the keyword) and binary STL (a
/// triangle count at byte 80, 50 bytes a triangle).
std::string count_problem(const std::string& path, const std::string& extension, std::uintmax_t file_size) {
  std::ifstream in(path, std::ios::binary);
  if (extension == ".stl") {
    char head[84] = {};
    in.read(head, 84);
    if (in.gcount() < 84 || std::string(head, 5) == "solid") return "";  // ASCII: no counts
    std::uint32_t triangles = 0;
    std::memcpy(&triangles, head + 80, 4);
    return 84 + 50 * std::uintmax_t(triangles) > file_size ? "its triangle count is more than the file holds" : "";
  }
  if (extension != ".off") return "";
  std::string word;
  in >> word;  // OFF, COFF, NOFF, …
  if (word.find("OFF") == std::string::npos) return "";
  double vertices = 0, faces = 0;
  while (in >> std::ws && in.peek() == '#') std::getline(in, word);
  if (!(in >> vertices >> faces)) return "";
  if (!(vertices >= 0 && faces >= 0) || 6 * vertices + 8 * faces > double(file_size))
    return "its vertex and face counts are more than the file holds";
  return "";
}

/// CGAL's ASCII OFF scanner reads a face's size and indices as doubles and converts them to unsigned
/// integers unchecked (undefined for −1 or 1e20): the face lines are checked first. Vertices are one a
/// line (the usual layout; extra columns such as colours are allowed), then each face line holds its
/// size k ≥ 3 and k whole indices below the vertex count.
std::string off_faces_problem(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::vector<std::string> header;  // the keyword and the three counts, wherever the lines break
  const auto next_line = [&](std::vector<std::string>& words) {
    while (std::getline(in, line)) {
      if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
      std::istringstream split(line);
      words.clear();
      for (std::string w; split >> w;) words.push_back(w);
      if (!words.empty()) return true;
    }
    return false;
  };
  std::vector<std::string> words;
  while (header.size() < 4 && next_line(words)) header.insert(header.end(), words.begin(), words.end());
  if (header.empty() || header[0].find("OFF") == std::string::npos) return "";  // the reader decides
  if (header[0].find("BINARY") != std::string::npos || (header.size() > 1 && header[1] == "BINARY")) return "";
  if (header.size() < 4) return "no vertex, face and edge counts";
  const auto whole = [](const std::string& w, double& value) {
    std::istringstream number(w);
    return number >> value && number.eof() && value == std::floor(value);
  };
  double vertices = 0, faces = 0;
  if (!whole(header[1], vertices) || !whole(header[2], faces) || vertices < 0 || faces < 0)
    return "its vertex and face counts are not whole numbers";
  for (double v = 0; v < vertices; ++v)
    if (!next_line(words)) return "fewer vertices than its count";
  for (double f = 0; f < faces; ++f) {
    if (!next_line(words)) return "fewer faces than its count";
    double size = 0;
    if (!whole(words[0], size) || size < 3 || size + 1 > double(words.size()))
      return "face " + std::to_string(std::size_t(f)) +
             " does not start with its size (3 or more) and that many indices";
    for (std::size_t k = 1; k <= std::size_t(size); ++k) {
      double index = 0;
      if (!whole(words[k], index) || index < 0 || index >= vertices)
        return "face " + std::to_string(std::size_t(f)) + " has an index that is not a vertex number";
    }
  }
  return "";
}

}  // namespace

struct MeshSurface::Mesh {
  TriangleMeshCgal mesh;
  Tree tree;
};

PolygonSoup read_polygon_soup(const std::string& path, const std::string& field) {
  const std::string e = extension_of(path);
  if (e != ".off" && e != ".stl" && e != ".obj" && e != ".ply")
    fail(field, "'" + path + "': expected a .off, .stl, .obj or .ply file");
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) fail(field, "'" + path + "': no such file");
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) fail(field, "'" + path + "': cannot read its size");
  std::string problem = e == ".ply" ? ply_header_problem(path, size) : count_problem(path, e, size);
  if (problem.empty() && e == ".off") problem = off_faces_problem(path);
  if (!problem.empty())
    fail(field, "'" + path + "': not a readable " + e.substr(1) + " surface mesh (" + problem + ")");
  std::vector<CgalPoint> points;
  std::vector<std::vector<std::size_t>> faces;
  bool read = false;
  try {
    read = CGAL::IO::read_polygon_soup(path, points, faces, CGAL::parameters::verbose(false));
  } catch (const std::exception&) {
    read = false;
  }
  if (!read) fail(field, "'" + path + "': not a readable " + e.substr(1) + " surface mesh");
  if (faces.empty()) fail(field, "'" + path + "': no faces");
  PolygonSoup soup;
  soup.vertices.reserve(points.size());
  for (const CgalPoint& p : points) soup.vertices.push_back({p.x(), p.y(), p.z()});
  soup.faces = std::move(faces);
  return soup;
}

void write_off(const std::string& path, const PolygonSoup& soup) {
  std::vector<CgalPoint> points;
  for (const Point3& v : soup.vertices) points.emplace_back(v.x, v.y, v.z);
  if (!CGAL::IO::write_OFF(path, points, soup.faces, CGAL::parameters::stream_precision(17)))
    throw std::runtime_error("cannot write " + path);
}

void check_mesh_resolution(double resolution) {
  if (resolution != std::floor(resolution) ||
      (resolution != automatic_mesh_resolution &&
       !(resolution >= min_mesh_resolution && resolution <= max_mesh_resolution)))
    fail("geometry.resolution", "expected 0 (automatic) or a whole number of lattice cells across the mesh, " +
                                    std::to_string(min_mesh_resolution) +
                                    " <= resolution <= " + std::to_string(max_mesh_resolution));
}

MeshSurface::~MeshSurface() = default;

namespace {

/// The soup's points and faces, checked (finite coordinates, faces of three or more existing vertices),
/// the duplicate points of STL-like files merged, degenerate and repeated faces dropped, the faces
/// oriented consistently (refused when some edge has more than two faces, or a vertex joins sheets
/// that meet only there).
void checked_soup(const PolygonSoup& soup, const std::string& field, std::vector<CgalPoint>& points,
                  std::vector<std::vector<std::size_t>>& polygons) {
  if (soup.faces.empty()) fail(field, "the mesh has no faces");
  points.reserve(soup.vertices.size());
  for (const Point3& v : soup.vertices) {
    for (int d = 0; d < 3; ++d)
      if (!(std::abs(v[d]) <= largest_coordinate))
        fail(field, "a vertex coordinate is not finite or beyond 1e100 in size");
    points.emplace_back(v.x, v.y, v.z);
  }
  polygons = soup.faces;
  for (const auto& face : polygons) {
    if (face.size() < 3) fail(field, "a face has fewer than three vertices");
    for (std::size_t index : face)
      if (index >= points.size())
        fail(field, "a face refers to vertex " + std::to_string(index) + " of " + std::to_string(points.size()));
  }
  PMP::repair_polygon_soup(points, polygons, CGAL::parameters::erase_all_duplicates(false));
  if (polygons.empty()) fail(field, "every face of the mesh is degenerate");
  if (!PMP::orient_polygon_soup(points, polygons))
    fail(field,
         "the mesh is not a manifold surface: an edge with more than two faces, a vertex where separate "
         "sheets meet, or faces that cannot be oriented consistently");
}

/// The triangle mesh of the checked soup: closed, free of self-intersections, oriented to bound a
/// positive volume (a warning when it was reoriented).
void closed_mesh(const std::vector<CgalPoint>& points, const std::vector<std::vector<std::size_t>>& polygons,
                 const std::string& field, TriangleMeshCgal& m, std::vector<std::string>& warnings) {
  PMP::polygon_soup_to_polygon_mesh(points, polygons, m);
  if (!CGAL::is_triangle_mesh(m) && !PMP::triangulate_faces(m)) fail(field, "a face could not be triangulated");
  for (auto h : halfedges(m))
    if (is_border(h, m))
      fail(field, "the mesh is not closed: it has a hole (an edge with one face) at " + at(m.point(source(h, m))));
  // The first crossing pair ends the search (a hostile mesh can have n² of them).
  struct Found {
    TriangleMeshCgal::Face_index face;
  };
  const auto first_crossing = boost::make_function_output_iterator(
      [](const std::pair<TriangleMeshCgal::Face_index, TriangleMeshCgal::Face_index>& pair) {
        throw Found{pair.first};
      });
  try {
    PMP::self_intersections(m, first_crossing);
  } catch (const Found& found) {
    fail(field, "the mesh intersects itself, near " + at(m.point(target(halfedge(found.face, m), m))));
  }
  const double before = PMP::volume(m);  // signed: positive for outward faces
  PMP::orient_to_bound_a_volume(m);
  const double volume = PMP::volume(m);
  if (!(volume > 0)) fail(field, "the mesh encloses no volume");
  if (std::abs(before - volume) > 1e-12 * volume)  // also a shell inside another that pointed outward
    warnings.push_back(before <= -volume * (1 - 1e-12)
                           ? "the mesh's faces pointed inward: reoriented outward"
                           : "some components of the mesh were oriented the wrong way: reoriented to bound a volume");
}

/// The automatic resolution: the largest side over twice the median edge length, within bounds.
int automatic_resolution(const TriangleMeshCgal& m, double largest) {
  std::vector<double> lengths;
  lengths.reserve(num_edges(m));
  for (auto e : edges(m)) lengths.push_back(PMP::edge_length(e, m));
  std::nth_element(lengths.begin(), lengths.begin() + std::ptrdiff_t(lengths.size() / 2), lengths.end());
  const double median = lengths[lengths.size() / 2];
  return int(
      std::clamp(std::round(largest / (2 * median)), double(min_mesh_resolution), double(default_mesh_resolution)));
}

/// The lattice of the level function: n cells of `spacing` per side from `lower`, around `center`.
struct Lattice {
  Point3 lower, center;
  double spacing = 0;
  int n = 0;
  std::size_t side() const { return std::size_t(n) + 1; }
  std::size_t nodes() const { return side() * side() * side(); }
  std::size_t index(std::size_t i, std::size_t j, std::size_t k) const { return (k * side() + j) * side() + i; }
  CgalPoint node(std::size_t i, std::size_t j, std::size_t k) const {
    return CgalPoint(lower.x + double(i) * spacing, lower.y + double(j) * spacing, lower.z + double(k) * spacing);
  }
};

/// The nodes within 6ℓ of some face (the nodes in each face's box grown by that band).
std::vector<std::uint8_t> band_of(const TriangleMeshCgal& m, const Lattice& L) {
  constexpr double band = 6;
  std::vector<std::uint8_t> in_band(L.nodes(), 0);
  for (auto f : faces(m)) {
    std::array<double, 3> lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::infinity()};
    std::array<double, 3> hi{-lo[0], -lo[1], -lo[2]};
    for (auto v : vertices_around_face(halfedge(f, m), m))
      for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], m.point(v)[d]), hi[d] = std::max(hi[d], m.point(v)[d]);
    std::array<std::size_t, 3> first, last;
    for (int d = 0; d < 3; ++d) {
      first[d] = std::size_t(std::max(0.0, std::ceil((lo[d] - band * L.spacing - L.lower[d]) / L.spacing)));
      last[d] = std::size_t(std::min(double(L.n), std::floor((hi[d] + band * L.spacing - L.lower[d]) / L.spacing)));
    }
    for (std::size_t k = first[2]; k <= last[2]; ++k)
      for (std::size_t j = first[1]; j <= last[1]; ++j)
        for (std::size_t i = first[0]; i <= last[0]; ++i) in_band[L.index(i, j, k)] = 1;
  }
  return in_band;
}

/// Sweeps in the eight diagonal orders, twice: each node away from the band tries the nearest points
/// (relative to the centre) of its three upwind neighbours.
void sweep_nearest_points(const Lattice& L, const std::vector<std::uint8_t>& in_band, std::vector<double>& distance,
                          std::vector<std::array<float, 3>>& nearest) {
  const std::size_t n = std::size_t(L.n);
  for (int round = 0; round < 2; ++round)
    for (int order = 0; order < 8; ++order) {
      const int step[3] = {order & 1 ? -1 : 1, order & 2 ? -1 : 1, order & 4 ? -1 : 1};
      for (std::size_t kk = 0; kk < L.side(); ++kk)
        for (std::size_t jj = 0; jj < L.side(); ++jj)
          for (std::size_t ii = 0; ii < L.side(); ++ii) {
            const std::size_t i = step[0] > 0 ? ii : n - ii, j = step[1] > 0 ? jj : n - jj,
                              k = step[2] > 0 ? kk : n - kk;
            const std::size_t q = L.index(i, j, k);
            if (in_band[q]) continue;
            const std::array<std::size_t, 3> here{i, j, k};
            const Point3 x = L.lower - L.center + L.spacing * Point3{double(i), double(j), double(k)};
            for (int d = 0; d < 3; ++d) {
              if ((step[d] > 0 && here[d] == 0) || (step[d] < 0 && here[d] == n)) continue;
              std::array<std::size_t, 3> from = here;
              from[d] = step[d] > 0 ? from[d] - 1 : from[d] + 1;
              const auto& c = nearest[L.index(from[0], from[1], from[2])];
              if (std::isnan(c[0])) continue;
              const double candidate = norm(x - Point3{double(c[0]), double(c[1]), double(c[2])});
              if (candidate < distance[q]) distance[q] = candidate, nearest[q] = c;
            }
          }
    }
}

/// The signed distance to the mesh at every lattice node: exact by the AABB tree in the band around
/// the faces, from the sweeps elsewhere; negative inside (ray casting with exact predicates).
std::vector<double> signed_distances(const TriangleMeshCgal& m, const Tree& tree, const Lattice& L) {
  Side side(m);  // its own tree
  const std::vector<std::uint8_t> in_band = band_of(m, L);
  std::vector<std::size_t> band_nodes;
  for (std::size_t q = 0; q < L.nodes(); ++q)
    if (in_band[q]) band_nodes.push_back(q);
  std::vector<double> distance(L.nodes(), std::numeric_limits<double>::infinity());
  std::vector<std::array<float, 3>> nearest(L.nodes(), {NAN, NAN, NAN});
  const std::size_t side_nodes = L.side();
  const auto coordinates = [&](std::size_t q) {
    return std::array<std::size_t, 3>{q % side_nodes, (q / side_nodes) % side_nodes, q / (side_nodes * side_nodes)};
  };
  const Point3 center = L.center;
  const CgalPoint middle(center.x, center.y, center.z);  // inside the mesh's box: lazy set-ups happen here
  (void)tree.closest_point(middle);
  (void)side(middle);
#pragma omp parallel for schedule(dynamic, 256)
  for (std::size_t b = 0; b < band_nodes.size(); ++b) {
    const std::size_t q = band_nodes[b];
    const auto [i, j, k] = coordinates(q);
    const CgalPoint p = L.node(i, j, k);
    const CgalPoint c = tree.closest_point(p);
    distance[q] = std::sqrt(CGAL::squared_distance(p, c));
    nearest[q] = {float(c.x() - center.x), float(c.y() - center.y), float(c.z() - center.z)};  // from the centre
  }
  sweep_nearest_points(L, in_band, distance, nearest);
  std::vector<std::array<float, 3>>().swap(nearest);
  std::atomic<bool> unreached = false;
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t k = 0; k < side_nodes; ++k)
    for (std::size_t j = 0; j < side_nodes; ++j)
      for (std::size_t i = 0; i < side_nodes; ++i) {
        const std::size_t q = L.index(i, j, k);
        if (!std::isfinite(distance[q])) unreached = true;
        if (side(L.node(i, j, k)) == CGAL::ON_BOUNDED_SIDE) distance[q] = -distance[q];
      }
  if (unreached) throw std::logic_error("MeshSurface: a lattice node without a nearest point");
  return distance;
}

}  // namespace

MeshSurface::MeshSurface(const PolygonSoup& soup, int resolution, const std::string& field) {
  check_mesh_resolution(resolution);
  std::vector<CgalPoint> points;
  std::vector<std::vector<std::size_t>> polygons;
  checked_soup(soup, field, points, polygons);
  auto mesh = std::make_unique<Mesh>();
  TriangleMeshCgal& m = mesh->mesh;
  closed_mesh(points, polygons, field, m, warnings_);
  vertices_ = num_vertices(m);
  faces_ = num_faces(m);
  mesh->tree.insert(faces(m).first, faces(m).second, m);
  mesh->tree.build();
  mesh->tree.accelerate_distance_queries();

  // The lattice: `resolution` cells across the mesh's largest side, a margin of 8 cells around it.
  const CGAL::Bbox_3 box = PMP::bbox(m);
  const double largest = std::max({box.xmax() - box.xmin(), box.ymax() - box.ymin(), box.zmax() - box.zmin()});
  if (!(largest > 0)) fail(field, "the mesh is flat");
  if (resolution == automatic_mesh_resolution) resolution = automatic_resolution(m, largest);
  resolution_ = resolution;
  constexpr int margin = 8;
  Lattice L;
  L.spacing = largest / resolution;
  L.n = resolution + 2 * margin;
  L.center = {(box.xmin() + box.xmax()) / 2, (box.ymin() + box.ymax()) / 2, (box.zmin() + box.zmax()) / 2};
  L.lower = L.center - (0.5 * L.n * L.spacing) * Point3{1, 1, 1};
  spline_ = std::make_shared<const LatticeSpline>(L.lower, L.spacing, L.n, signed_distances(m, mesh->tree, L));
  mesh_ = std::move(mesh);
  const double spacing = L.spacing;

  const std::shared_ptr<const LatticeSpline> spline = spline_;
  try {
    implicit_ = std::make_unique<ImplicitSurface>(
        [spline](double x, double y, double z) {
          return spline->value({x, y, z});
        },
        spline->box(),
        [spline](double x, double y, double z) {
          return spline->gradient({x, y, z});
        },
        [spline](const Point3& p) { return spline->hessian(p); });
  } catch (const std::invalid_argument& e) {
    fail(field, std::string("the mesh's level set on the lattice of spacing ") + std::to_string(spacing) + " fails (" +
                    e.what() + "): parts thinner than the spacing are lost; a larger geometry.resolution");
  }
  // Parts thinner than ℓ vanish from the level set: its area then falls short of the mesh's.
  const double mesh_area = PMP::area(m), kept = implicit_->area() / mesh_area;
  if (std::abs(kept - 1) > 0.05)
    fail(field, "the mesh's level set on the lattice of spacing " + std::to_string(spacing) + " has " +
                    std::to_string(int(std::lround(100 * kept))) +
                    "% of the mesh's area: parts thinner than the spacing are lost; a larger geometry.resolution");
}

double MeshSurface::distance_to_mesh(const Point3& p) const {
  const CgalPoint q(p.x, p.y, p.z);
  return std::sqrt(CGAL::squared_distance(q, mesh_->tree.closest_point(q)));
}

}  // namespace fictus
