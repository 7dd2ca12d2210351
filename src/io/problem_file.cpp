#include "fictus/io/problem_file.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <stdexcept>

#include "fictus/boundary/mesh_surface.hpp"
#include "fictus/boundary/shapes.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/io/expression.hpp"
#include "fictus/solve/options.hpp"

namespace fictus {

namespace {

[[noreturn]] void fail(const std::string& key, const std::string& reason) {
  throw std::invalid_argument(key + ": " + reason);
}

/// Reads the keys of one table, remembering which were used so that unknown keys are reported.
class TableReader {
 public:
  TableReader(const toml::table* table, std::string name) : table_(table), name_(std::move(name)) {}

  bool has(const std::string& key) const { return table_ && table_->contains(key); }
  /// Throws unless the table has `k`: "<table>.<k>: missing", or, when a key not read yet is a
  /// near spelling of it, "<table>.<that key>: unknown key (did you mean "<k>"?)".
  void require(const std::string& k) const {
    if (has(k)) return;
    if (table_)
      for (const auto& [name, value] : *table_) {
        const std::string given(name.str());
        if (used_.count(given)) continue;
        if (const std::string hint = did_you_mean(given, {k}); !hint.empty()) fail(key(given), "unknown key" + hint);
      }
    fail(key(k), "missing");
  }
  std::string key(const std::string& k) const { return name_ + "." + k; }

  double number(const std::string& k, double fallback) {
    const toml::node* n = node(k);
    if (!n) return fallback;
    std::optional<double> v =
        n->is_integer() ? std::optional<double>(double(*n->value<int64_t>())) : n->value<double>();
    if (!v || n->is_boolean()) fail(key(k), std::string("expected a number, got ") + type_name(*n));
    if (!std::isfinite(*v)) fail(key(k), "must be finite (NaN or Inf given)");
    return *v;
  }
  std::string string(const std::string& k, const std::string& fallback) {
    const toml::node* n = node(k);
    if (!n) return fallback;
    if (!n->is_string()) fail(key(k), std::string("expected a string, got ") + type_name(*n));
    return *n->value<std::string>();
  }
  std::string required_string(const std::string& k) {
    require(k);
    return string(k, "");
  }
  std::vector<double> numbers(const std::string& k, std::size_t size, std::vector<double> fallback) {
    const toml::node* n = node(k);
    if (!n) return fallback;
    const toml::array* a = n->as_array();
    if (!a || a->size() != size) fail(key(k), "expected an array of " + std::to_string(size) + " numbers");
    std::vector<double> out;
    for (const toml::node& e : *a) {
      std::optional<double> v = e.is_integer() ? std::optional<double>(double(*e.value<int64_t>())) : e.value<double>();
      if (!v || e.is_boolean()) fail(key(k), "expected an array of " + std::to_string(size) + " numbers");
      if (!std::isfinite(*v)) fail(key(k), "must be finite (NaN or Inf given)");
      out.push_back(*v);
    }
    return out;
  }
  std::vector<double> required_numbers(const std::string& k, std::size_t size) {
    require(k);
    return numbers(k, size, {});
  }
  const toml::array* array(const std::string& k) {
    const toml::node* n = node(k);
    if (!n) return nullptr;
    if (!n->is_array()) fail(key(k), std::string("expected an array, got ") + type_name(*n));
    return n->as_array();
  }
  /// The schema's options of this section that the table gives, set into (domain, options); an option
  /// of the other dimension is refused.
  void read_options(DomainSettings& domain, SolverOptions& options) {
    for (const OptionSpec& spec : option_specs())
      if (spec.section == name_)
        if (const toml::node* n = node(spec.key)) {
          check_applies(spec, domain.dim);
          set_option(spec, domain, options, value_of(spec, *n));
        }
  }
  /// Throws for the first key that was never read.
  void finish() const {
    if (!table_) return;
    for (const auto& [k, v] : *table_)
      if (!used_.count(std::string(k.str())))
        fail(key(std::string(k.str())),
             "unknown key" + did_you_mean(k.str(), std::vector<std::string>(used_.begin(), used_.end())));
  }

 private:
  const toml::node* node(const std::string& k) {
    used_.insert(k);
    return table_ ? table_->get(k) : nullptr;
  }
  static OptionValue value_of(const OptionSpec& spec, const toml::node& n) {
    if (n.is_boolean()) return *n.value<bool>();
    if (n.is_integer()) return std::int64_t(*n.value<int64_t>());
    if (n.is_floating_point()) return *n.value<double>();
    if (n.is_string()) return *n.value<std::string>();
    if (const toml::array* a = n.as_array()) {
      std::vector<double> list;
      for (const toml::node& e : *a) {
        if (!e.is_number())
          fail(spec.name(), std::string("expected an array of numbers, got ") + type_name(e) + " in it");
        list.push_back(*e.value<double>());
      }
      return list;
    }
    fail(spec.name(), std::string("unsupported value: ") + type_name(n));
  }
  static const char* type_name(const toml::node& n) {
    switch (n.type()) {
      case toml::node_type::string:
        return "a string";
      case toml::node_type::integer:
        return "an integer";
      case toml::node_type::floating_point:
        return "a number";
      case toml::node_type::boolean:
        return "a boolean";
      case toml::node_type::array:
        return "an array";
      case toml::node_type::table:
        return "a table";
      default:
        return "a date or time";
    }
  }
  const toml::table* table_;
  std::string name_;
  std::set<std::string> used_;
};

const toml::table* subtable(const toml::table& root, const std::string& name) {
  const toml::node* n = root.get(name);
  if (!n) return nullptr;
  if (!n->is_table()) fail(name, "expected a table [" + name + "]");
  return n->as_table();
}

using Constants = std::vector<std::pair<std::string, double>>;

/// The expressions of a problem file, made with its [parameters] and remembering which name which.
struct ExpressionMaker {
  Constants constants;
  std::map<std::string, std::vector<std::string>>* uses;
  Expression operator()(const std::string& text, std::vector<std::string> variables, const std::string& key) const {
    Expression e(text, std::move(variables), key, constants);
    for (const auto& [name, value] : constants)
      if (e.mentions(name)) (*uses)[name].push_back(key);
    return e;
  }
};

/// [parameters]: named numbers for the expressions, the file's values replaced by `overrides`.
std::map<std::string, double> read_parameters(const toml::table* table, const ParameterValues& overrides) {
  static const std::set<std::string> variables = {"x", "y", "z", "t", "phi", "s"};
  std::map<std::string, double> values;
  if (table)
    for (const auto& [k, node] : *table) {
      const std::string name(k.str()), key = "parameters." + name;
      const bool identifier =
          !name.empty() && name.size() <= 40 && (std::isalpha(static_cast<unsigned char>(name[0]))) &&
          std::all_of(name.begin(), name.end(),
                      [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; });
      if (!identifier)
        fail(key.substr(0, 60), "a parameter name is a letter followed by letters, digits or _ (at most 40)");
      if (variables.count(name) || is_builtin_name(name))
        fail(key, "the name is a variable or function of the expressions; choose another");
      const std::optional<double> v =
          node.is_integer() ? std::optional<double>(double(*node.value<int64_t>())) : node.value<double>();
      if (!v || node.is_boolean()) fail(key, "expected a number");
      if (!std::isfinite(*v)) fail(key, "must be finite (NaN or Inf given)");
      values[name] = *v;
    }
  for (const auto& [name, value] : overrides) {
    if (!values.count(name)) {
      std::string known;
      for (const auto& [n, v] : values) known += (known.empty() ? "" : ", ") + n;
      fail("parameters." + name.substr(0, 40),
           "not a parameter of the problem file (its [parameters]: " + (known.empty() ? "none" : known) + ")");
    }
    if (!std::isfinite(value)) fail("parameters." + name, "must be finite");
    values[name] = value;
  }
  return values;
}

std::shared_ptr<const Curve> read_geometry(TableReader& g, const ExpressionMaker& expression,
                                           std::vector<std::string>& warnings) {
  const std::string shape = g.required_string("shape");
  std::shared_ptr<const Curve> curve;
  if (shape == "ellipse") {
    const auto c = g.required_numbers("center", 2), ab = g.required_numbers("semi_axes", 2);
    if (!(ab[0] > 0 && ab[1] > 0)) fail("geometry.semi_axes", "must be positive");
    curve = std::make_shared<Ellipse>(Point2{c[0], c[1]}, ab[0], ab[1], g.number("angle", 0.0));
  } else if (shape == "circle") {
    const auto c = g.required_numbers("center", 2);
    g.require("radius");
    const double r = g.number("radius", 0.0);
    if (!(r > 0)) fail("geometry.radius", "must be positive");
    curve = std::make_shared<Ellipse>(Point2{c[0], c[1]}, r, r, 0.0);
  } else if (shape == "polygon") {
    const toml::array* list = g.array("vertices");
    if (!list) g.require("vertices");
    std::vector<Point2> vertices;
    for (const toml::node& v : *list) {
      const toml::array* xy = v.as_array();
      if (!xy || xy->size() != 2 || !(*xy)[0].is_number() || !(*xy)[1].is_number())
        fail("geometry.vertices", "expected an array of [x, y] number pairs");
      const double x = (*xy)[0].value<double>().value(), y = (*xy)[1].value<double>().value();
      if (!std::isfinite(x) || !std::isfinite(y)) fail("geometry.vertices", "must be finite (NaN or Inf given)");
      vertices.push_back({x, y});
    }
    auto polygon = std::make_shared<PolygonCurve>(vertices);
    check_simple(*polygon, "geometry.vertices");
    if (signed_area(*polygon) < 0) {
      std::reverse(vertices.begin(), vertices.end());
      polygon = std::make_shared<PolygonCurve>(vertices);
      warnings.push_back("geometry.vertices: the polygon is clockwise; reoriented counter-clockwise");
    }
    curve = polygon;
  } else if (shape == "parametric") {
    const Expression x = expression(g.required_string("x"), {"t"}, "geometry.x"),
                     y = expression(g.required_string("y"), {"t"}, "geometry.y");
    curve = std::make_shared<ParametricCurve>([x](double t) { return x({t}); }, [y](double t) { return y({t}); });
  } else if (shape == "star") {
    const auto c = g.required_numbers("center", 2);
    const Expression r = expression(g.required_string("r"), {"t"}, "geometry.r");
    curve = std::make_shared<StarCurve>(Point2{c[0], c[1]}, [r](double t) { return r({t}); });
  } else {
    fail("geometry.shape", "unknown shape \"" + shape + "\" (ellipse, circle, polygon, parametric, star)");
  }
  if (shape != "polygon") {
    check_simple(*curve, "geometry");
    if (signed_area(*curve) < 0) {
      curve = std::make_shared<ReversedCurve>(curve);
      warnings.push_back("geometry: the curve is clockwise; reoriented counter-clockwise");
    }
  }
  return curve;
}

}  // namespace

namespace {

toml::table parse_toml(const std::string& text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << source << ":" << e.source().begin.line << ": TOML syntax error: " << e.description();
    throw std::invalid_argument(msg.str());
  }
}

}  // namespace

int problem_dimension(const std::string& text, const std::string& source) {
  const toml::table root = parse_toml(text, source);
  const toml::table* domain = subtable(root, "domain");
  const toml::node* dim = domain ? domain->get("dim") : nullptr;
  if (!dim) return 2;
  const std::optional<int64_t> value = dim->value<int64_t>();
  if (!dim->is_integer() || !value || (*value != 2 && *value != 3)) fail("domain.dim", "expected 2 or 3");
  return int(*value);
}

const std::vector<std::string>& output_file_names(int dim) {
  static const std::vector<std::string> curves = {"results.json", "points.csv", "solution.vti", "curves.vtp"};
  static const std::vector<std::string> surfaces = {"results.json", "points.csv", "solution.vti", "surface.vtp"};
  return dim == 3 ? surfaces : curves;
}

namespace {

/// A mesh file named relative to the problem file's folder when `source` names a file.
std::filesystem::path mesh_path(const std::string& file, const std::string& source) {
  std::filesystem::path path = file;
  std::error_code error;
  if (path.is_relative() && std::filesystem::is_regular_file(source, error))
    path = std::filesystem::path(source).parent_path() / path;
  return path;
}

/// [geometry] of a 3-D problem: a sphere, an ellipsoid, a torus, an implicit surface, or a mesh (built
/// by `build_mesh`, which the caller runs once every other key has been read: it can take seconds).
std::shared_ptr<const Surface> read_surface(TableReader& geometry, const ExpressionMaker& expression,
                                            const std::string& source,
                                            std::function<std::shared_ptr<const Surface>()>& build_mesh,
                                            std::vector<std::string>& warnings) {
  const std::string shape = geometry.required_string("shape");
  if (shape == "implicit") {
    const Expression level = expression(geometry.required_string("level"), {"x", "y", "z"}, "geometry.level");
    const auto b = geometry.required_numbers("bounds", 6);  // bounds order, as domain.box
    if (!(b[0] < b[1] && b[2] < b[3] && b[4] < b[5]))
      throw std::invalid_argument(
          "geometry.bounds: the bounds are [x0, x1, y0, y1, z0, z1] (bounds order, as domain.box) with x0 < x1, "
          "y0 < y1 and z0 < z1");
    return std::make_shared<ImplicitSurface>(
        [level](double x, double y, double z) {
          return level({x, y, z});
        },
        Box3{{b[0], b[2], b[4]}, {b[1], b[3], b[5]}});
  }
  if (shape == "mesh") {
    const double resolution = geometry.number("resolution", automatic_mesh_resolution);
    check_mesh_resolution(resolution);
    geometry.require("file");
    const std::filesystem::path file = mesh_path(geometry.string("file", ""), source);
    build_mesh = [file, resolution, &warnings] {
      const auto surface = std::make_shared<MeshSurface>(read_polygon_soup(file.string(), "geometry.file"),
                                                         int(resolution), "geometry.file");
      for (const std::string& w : surface->warnings()) warnings.push_back("geometry.file: " + w);
      return surface;
    };
    return nullptr;
  }
  if (shape != "sphere" && shape != "ellipsoid" && shape != "torus")
    fail("geometry.shape", "unknown 3-D shape \"" + shape.substr(0, 40) +
                               "\" (sphere, ellipsoid, torus, implicit, mesh)" +
                               did_you_mean(shape, {"sphere", "ellipsoid", "torus", "implicit", "mesh"}));
  const auto c = geometry.required_numbers("center", 3);
  const Point3 center{c[0], c[1], c[2]};
  if (shape == "torus") {
    geometry.require("major_radius");
    geometry.require("minor_radius");
    const double R = geometry.number("major_radius", 0.0), r = geometry.number("minor_radius", 0.0);
    if (!(r > 0 && R > r)) fail("geometry.minor_radius", "need 0 < minor_radius < major_radius");
    return std::make_shared<Torus>(center, R, r);
  }
  if (shape == "sphere") {
    geometry.require("radius");
    const double r = geometry.number("radius", 0.0);
    if (!(r > 0)) fail("geometry.radius", "must be positive");
    return std::make_shared<Ellipsoid>(center, Point3{r, r, r});
  }
  const auto a = geometry.required_numbers("semi_axes", 3);
  return std::make_shared<Ellipsoid>(center, Point3{a[0], a[1], a[2]});
}

/// The batch form of an expression in (x, y) or (x, y, z): one parser lookup per batch.
template <int dim>
typename Fields<dim>::Vectorized vectorized(const Expression& e) {
  if constexpr (dim == 2)
    return [e](std::size_t n, const double* x, const double* y, double* out) { e.evaluate(n, {x, y}, out); };
  else
    return [e](std::size_t n, const double* x, const double* y, const double* z, double* out) {
      e.evaluate(n, {x, y, z}, out);
    };
}

/// [data]: c (through the schema), f, g and the exact solution as expressions in x, y (, z); in 2-D g
/// may also name phi (the polar angle about γ's center) and s (the arc length along γ).
template <int dim>
void read_data(TableReader& data, const ExpressionMaker& expression, DomainSettings& domain,
               BasicProblemSpec<dim>& spec) {
  BasicProblem<dim>& p = spec.problem;
  data.read_options(domain, spec.options);
  if constexpr (dim == 2) {
    const Expression f = expression(data.required_string("f"), {"x", "y"}, "data.f");
    p.f = [f](double x, double y) { return f({x, y}); };
    p.f_vectorized = vectorized<2>(f);
    const Expression g = expression(data.required_string("g"), {"x", "y", "phi", "s"}, "data.g");
    spec.g_about = [g](Point2 center) -> std::function<double(double, double, double)> {
      return [g, center](double x, double y, double s) { return g({x, y, std::atan2(y - center.y, x - center.x), s}); };
    };
    p.g_along_curve = spec.g_about(p.gamma->center());
    if (data.has("exact")) {
      const Expression exact = expression(data.string("exact", ""), {"x", "y"}, "data.exact");
      p.exact = [exact](double x, double y) { return exact({x, y}); };
      p.exact_vectorized = vectorized<2>(exact);
    }
  } else {
    const Expression f = expression(data.required_string("f"), {"x", "y", "z"}, "data.f");
    p.f = [f](double x, double y, double z) { return f({x, y, z}); };
    p.f_vectorized = vectorized<3>(f);
    const Expression g = expression(data.required_string("g"), {"x", "y", "z"}, "data.g");
    p.g = [g](double x, double y, double z) { return g({x, y, z}); };
    p.g_vectorized = vectorized<3>(g);
    if (data.has("exact")) {
      const Expression exact = expression(data.string("exact", ""), {"x", "y", "z"}, "data.exact");
      p.exact = [exact](double x, double y, double z) { return exact({x, y, z}); };
      p.exact_vectorized = vectorized<3>(exact);
    }
  }
  data.finish();
}

/// [conditions]: the Dirichlet and Neumann parts of γ and their values (docs/problem_files.md, "Mixed
/// conditions"); the rest of γ is Signorini. Parts in x, y (, z); the flux may name the outward normal.
template <int dim>
void read_conditions(TableReader& table, const ExpressionMaker& expression, BasicProblem<dim>& p) {
  const std::vector<std::string> at =
      dim == 2 ? std::vector<std::string>{"x", "y"} : std::vector<std::string>{"x", "y", "z"};
  std::vector<std::string> with_normal = at;
  for (const std::string& axis : at) with_normal.push_back("n" + axis);
  const auto field = [&](const char* key) -> std::function<double(const Point<dim>&)> {
    const Expression e = expression(table.string(key, ""), at, std::string("conditions.") + key);
    return [e](const Point<dim>& x) {
      if constexpr (dim == 2)
        return e({x[0], x[1]});
      else
        return e({x[0], x[1], x[2]});
    };
  };
  for (const char* key : {"dirichlet", "u", "neumann", "flux"}) table.string(key, "");  // the keys known here
  table.finish();  // a misspelt key first: "neuman" beside a flux is answered as a misspelling
  PartConditions<dim>& c = p.conditions;
  if (table.has("dirichlet")) c.dirichlet = field("dirichlet");
  if (table.has("neumann")) c.neumann = field("neumann");
  if (table.has("u")) {
    if (!c.dirichlet) fail("conditions.u", "given without conditions.dirichlet (the part where u takes it)");
    c.u = field("u");
  } else if (c.dirichlet) {
    fail("conditions.u", "missing: the Dirichlet part needs the value of u there");
  }
  if (table.has("flux")) {
    if (!c.neumann) fail("conditions.flux", "given without conditions.neumann (the part where the flux is given)");
    const Expression e = expression(table.string("flux", ""), with_normal, "conditions.flux");
    c.flux = [e](const Point<dim>& x, const Point<dim>& n) {
      if constexpr (dim == 2)
        return e({x[0], x[1], n[0], n[1]});
      else
        return e({x[0], x[1], x[2], n[0], n[1], n[2]});
    };
  }
}

/// [output]: the folder and the files (the names of the dimension).
OutputOptions read_output(TableReader& output, int dim) {
  OutputOptions out;
  out.dir = output.string("dir", out.dir);
  const std::vector<std::string>& names = output_file_names(dim);
  out.files = names;
  if (const toml::array* files = output.array("files")) {
    out.files.clear();
    for (const toml::node& f : *files) {
      const auto name = f.value<std::string>();
      if (!name || std::find(names.begin(), names.end(), *name) == names.end())
        fail("output.files", "expected names from " + names[0] + ", " + names[1] + ", " + names[2] + ", " + names[3]);
      out.files.push_back(*name);
    }
  }
  output.finish();
  return out;
}

/// results.json's echo of the file: [geometry] (a mesh file as an absolute path), [data], [parameters].
std::string echo_json(const toml::table& root, const toml::table& geometry_table, const std::string& source,
                      const std::map<std::string, double>& parameters) {
  toml::table echo;
  toml::table geometry = geometry_table;
  if (const auto* file = geometry.get_as<std::string>("file"))
    geometry.insert_or_assign("file",
                              std::filesystem::absolute(mesh_path(file->get(), source)).lexically_normal().string());
  echo.insert("geometry", geometry);
  if (const toml::table* d = subtable(root, "data")) echo.insert("data", *d);
  if (const toml::table* c = subtable(root, "conditions")) echo.insert("conditions", *c);
  if (!parameters.empty()) {
    toml::table in_effect;
    for (const auto& [name, value] : parameters) in_effect.insert(name, value);
    echo.insert("parameters", in_effect);
  }
  std::ostringstream json;
  json << toml::json_formatter{echo};
  return json.str();
}

const std::vector<std::string> sections = {"domain",     "geometry", "formulation", "data",
                                           "conditions", "solver",   "output",      "parameters"};

}  // namespace

std::string with_mesh_overrides(const std::string& text, const std::string& source, const std::string& file,
                                std::optional<double> resolution) {
  toml::table root = parse_toml(text, source);
  toml::node* node = root.get("geometry");
  if (!node || !node->is_table()) fail("geometry", "missing section [geometry]");
  toml::table& geometry = *node->as_table();
  const auto* shape = geometry.get_as<std::string>("shape");
  if (!shape || shape->get() != "mesh")
    fail(file.empty() ? "--resolution" : "--file", "--file and --resolution need geometry.shape = \"mesh\"");
  if (!file.empty()) geometry.insert_or_assign("file", std::filesystem::absolute(file).lexically_normal().string());
  if (resolution) {
    check_mesh_resolution(*resolution);
    geometry.insert_or_assign("resolution", std::int64_t(*resolution));
  }
  std::ostringstream out;
  out << root;
  return out.str();
}

template <int dim>
BasicProblemSpec<dim> parse_problem(const std::string& text, const std::string& source,
                                    const ParameterValues& parameters,
                                    std::shared_ptr<const typename BoundaryShape<dim>::type> shape) {
  const toml::table root = parse_toml(text, source);
  for (const auto& [k, v] : root)
    if (std::find(sections.begin(), sections.end(), std::string(k.str())) == sections.end())
      fail(std::string(k.str()),
           "unknown section (domain, geometry, formulation, data, conditions, solver, output, parameters)" +
               did_you_mean(k.str(), sections));
  if (problem_dimension(text, source) != dim)
    fail("domain.dim", "a " + std::to_string(problem_dimension(text, source)) + "-D problem read as a " +
                           std::to_string(dim) + "-D one");
  BasicProblemSpec<dim> spec;
  spec.parameters = read_parameters(subtable(root, "parameters"), parameters);
  ExpressionMaker expression{{spec.parameters.begin(), spec.parameters.end()}, &spec.parameter_uses};
  BasicProblem<dim>& p = spec.problem;
  DomainSettings domain(dim);
  TableReader domain_table(subtable(root, "domain"), "domain");
  domain_table.read_options(domain, spec.options);
  domain_table.finish();

  const toml::table* geometry_table = subtable(root, "geometry");
  if (!geometry_table) fail("geometry", "missing section [geometry]");
  TableReader geometry(geometry_table, "geometry");
  std::function<std::shared_ptr<const Surface>()> build_mesh;
  if (shape) {  // the caller's boundary (a sweep member whose parameter is not in [geometry]): not read again
    p.gamma = shape;
  } else {
    if constexpr (dim == 2)
      p.gamma = read_geometry(geometry, expression, spec.warnings);
    else
      p.gamma = read_surface(geometry, expression, source, build_mesh, spec.warnings);
    geometry.finish();
  }

  TableReader formulation(subtable(root, "formulation"), "formulation");
  formulation.read_options(domain, spec.options);
  formulation.finish();
  TableReader data(subtable(root, "data"), "data");
  read_data<dim>(data, expression, domain, spec);
  TableReader conditions(subtable(root, "conditions"), "conditions");
  read_conditions<dim>(conditions, expression, p);
  TableReader solver(subtable(root, "solver"), "solver");
  solver.read_options(domain, spec.options);
  solver.finish();
  validate_options(domain, spec.options);
  apply_domain(domain, p);
  TableReader output(subtable(root, "output"), "output");
  spec.output = read_output(output, dim);
  p.name = source;
  spec.input_json = echo_json(root, *geometry_table, source, spec.parameters);
  if constexpr (dim == 3)
    if (build_mesh) p.gamma = build_mesh();
  return spec;
}

template BasicProblemSpec<2> parse_problem(const std::string&, const std::string&, const ParameterValues&,
                                           std::shared_ptr<const Curve>);
template BasicProblemSpec<3> parse_problem(const std::string&, const std::string&, const ParameterValues&,
                                           std::shared_ptr<const Surface>);

ProblemSpec parse_problem_text(const std::string& text, const std::string& source, const ParameterValues& parameters,
                               std::shared_ptr<const Curve> curve) {
  return parse_problem<2>(text, source, parameters, std::move(curve));
}

SurfaceProblemSpec parse_surface_problem_text(const std::string& text, const std::string& source,
                                              std::shared_ptr<const Surface> mesh, const ParameterValues& parameters) {
  return parse_problem<3>(text, source, parameters, std::move(mesh));
}

std::string read_problem_text(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw std::invalid_argument(path + ": is a folder, not a problem file");
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open the problem file");
  constexpr std::size_t limit = 64 << 20;  // a problem file is text; /dev/zero is not one
  std::string content;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    content.append(chunk, std::size_t(in.gcount()));
    if (content.size() > limit) throw std::invalid_argument(path + ": larger than 64 MiB, not a problem file");
  }
  if (in.bad()) throw std::invalid_argument(path + ": cannot read the problem file");
  return content;
}

ProblemSpec read_problem_file(const std::string& path, const ParameterValues& parameters) {
  ProblemSpec spec = parse_problem_text(read_problem_text(path), path, parameters);
  std::string name = path.substr(path.find_last_of('/') + 1);
  spec.problem.name = name.substr(0, name.rfind(".toml"));
  return spec;
}

}  // namespace fictus
