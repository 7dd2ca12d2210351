#include "results_io.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <limits>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "fictus/boundary/mesh_surface.hpp"
#include "fictus/solve/options.hpp"

namespace fictus::cli {

using nlohmann::json;

template <int dim>
json options_to_json(const BasicProblem<dim>& problem, const SolverOptions& options) {
  json j = json::object();
  const DomainSettings domain = domain_of(problem);
  for (const OptionSpec& spec : option_specs())
    if (spec.applies_to(dim)) std::visit([&](const auto& v) { j[spec.key] = v; }, spec.get(domain, options));
  return j;
}

template json options_to_json(const BasicProblem<2>&, const SolverOptions&);
template json options_to_json(const BasicProblem<3>&, const SolverOptions&);

json options_schema_json() {
  static const char* const types[] = {"boolean", "integer", "number", "choice", "numbers"};
  json list = json::array();
  for (const OptionSpec& spec : option_specs()) {
    json j{{"section", spec.section}, {"key", spec.key},         {"type", types[int(spec.type)]},
           {"rule", spec.rule},       {"meaning", spec.meaning}, {"aliases", spec.aliases},
           {"dims", spec.dims}};
    std::visit([&](const auto& v) { j["default"] = v; }, spec.default_value(spec.applies_to(2) ? 2 : 3));
    if (spec.applies_to(2) && spec.applies_to(3))
      std::visit([&](const auto& v) { j["default_3d"] = v; }, spec.default_value(3));
    if (spec.type == OptionType::choice) j["choices"] = spec.choices;
    list.push_back(j);
  }
  return list;
}

namespace {

json newton_json(const NewtonResult& n) {
  json history = json::array();
  for (const NewtonStep& step : n.history)
    history.push_back({{"n_active", step.n_active},
                       {"inner_iterations", step.inner_iterations},
                       {"residual", step.residual},
                       {"n_changed", step.n_changed}});
  json j = {{"iterations", n.iterations},
            {"converged", n.converged},
            {"n_active", std::count(n.active.begin(), n.active.end(), 1)},
            {"residual", n.residual},
            {"history", history}};
  j["failure"] = n.converged ? json(nullptr) : json(n.failure);
  return j;
}

json timings_json(const Timings& t) {
  json timings;
  for (const auto& [phase, seconds] : t.phases) timings[phase] = seconds;
  timings["total"] = t.total;
  return timings;
}

json signorini_json(const SignoriniCheck& s) {
  return {{"min_gap", s.min_gap},
          {"min_normal_derivative", s.min_normal_derivative},
          {"max_complementarity", s.max_complementarity}};
}

json errors_json(const ErrorNorms& e, const std::optional<PointErrors>& point_errors) {
  json j = {{"l2_omega", e.l2_omega},
            {"h1_omega", e.h1_omega},
            {"h1semi_omega", e.h1semi_omega},
            {"l2_gamma", e.l2_gamma},
            {"rel_l2_omega", e.rel_l2_omega},
            {"rel_h1_omega", e.rel_h1_omega},
            {"rel_h1semi_omega", e.rel_h1semi_omega},
            {"rel_l2_gamma", e.rel_l2_gamma},
            {"integral_u", e.integral_u},
            {"force", e.force},
            {"energy", e.energy}};
  if (point_errors) {
    j["max_trace_at_points"] = point_errors->max_trace;
    j["max_normal_derivative_at_points"] = point_errors->max_normal_derivative;
  }
  return j;
}

}  // namespace

namespace {

template <int dim>
json grid_json(const Grid<dim>& g) {
  json j = {{"N", g.nx()}, {"Ny", g.ny()}, {"h", g.h()}, {"n_nodes", g.n_nodes()}, {"n_unknowns", g.n_unknowns()}};
  if constexpr (dim == 3) j["Nz"] = g.nz();
  return j;
}

/// The boundary: its measure (length or area), the points' spacing, δ; 3-D: the triangles and a mesh's report.
template <int dim>
json boundary_json(const BasicProblem<dim>& problem, const BasicSolution<dim>& s) {
  double measure = 0;
  for (double w : s.weights()) measure += w;
  json j = {{"measure", measure}, {"spacing", s.spacing()}, {"delta", s.delta}};
  if constexpr (dim == 3) {
    j["triangles"] = s.gamma.triangles.size();
    if (const auto* mesh = dynamic_cast<const MeshSurface*>(problem.gamma.get()))
      j["mesh"] = {{"vertices", mesh->mesh_vertices()},
                   {"faces", mesh->mesh_faces()},
                   {"resolution", mesh->resolution()},
                   {"spacing", mesh->spacing()}};
  }
  return j;
}

template <int dim>
json inner_json(const BasicSolution<dim>& s) {
  json j = {{"solver", to_string(s.options.inner)},
            {"fast_solves", s.fast_solves},
            {"krylov_iterations", s.inner_iterations},
            {"factorizations", s.factorizations},
            {"far_field", nullptr},  // null where no pair was interpolated, as every optional block
            {"schur_storage", nullptr}};
  if (s.far_field) {
    const FarFieldReport& a = s.far_field->assembly;
    j["far_field"] = {{"far_fraction", a.far_pairs / (a.far_pairs + a.near_pairs)},
                      {"far_blocks", a.far_blocks},
                      {"near_blocks", a.near_blocks},
                      {"exact_steps", s.far_field->exact_steps}};
  }
  if (s.schur_storage) {
    const SchurStorage& t = *s.schur_storage;
    j["schur_storage"] = {{"kind", t.kind},
                          {"bytes", t.bytes},
                          {"dense_bytes", t.dense_bytes},
                          {"compression", t.dense_bytes > 0 ? t.bytes / t.dense_bytes : 1.0},
                          {"low_rank_blocks", t.low_rank_blocks},
                          {"full_blocks", t.full_blocks},
                          {"largest_rank", t.largest_rank},
                          {"preconditioner_bytes", t.preconditioner_bytes},
                          {"far_fraction", t.far_fraction},
                          {"seconds", t.seconds_assembly}};
  }
  return j;
}

json domain_json(const DomainQuantities& d) {
  return {{"volume", d.volume},           {"integral_u", d.integral_u},
          {"integral_u2", d.integral_u2}, {"integral_grad2", d.integral_grad2},
          {"integral_f", d.integral_f},   {"integral_fu", d.integral_fu},
          {"energy", d.energy},           {"flux", d.flux}};
}

json estimate_json(const ErrorEstimate& e) {
  if (!e.skipped.empty()) return json{{"skipped", e.skipped}, {"seconds", e.seconds}};
  json j{{"N", e.N},
         {"l2_omega", e.l2_omega},
         {"rel_l2_omega", e.rel_l2_omega},
         {"force", e.force},
         {"measure", e.measure},
         {"energy", e.energy},
         {"integral_u", e.integral_u},
         {"seconds", e.seconds}};
  if (!e.caveat.empty()) j["caveat"] = e.caveat;
  return j;
}

json nested_start_json(const NestedStart& n) {
  return n.skipped.empty() ? json{{"N", n.N},
                                  {"multipliers", n.multipliers},
                                  {"newton_steps", n.newton_steps},
                                  {"active", n.active},
                                  {"seconds", n.seconds}}
                           : json{{"skipped", n.skipped}, {"seconds", n.seconds}};
}

}  // namespace

template <int dim>
json solution_to_json(const BasicProblem<dim>& problem, const BasicSolution<dim>& s, const json& input,
                      const std::vector<std::string>& input_warnings) {
  json j;
  j["version"] = FICTUS_VERSION;
  j["commit"] = FICTUS_GIT_COMMIT;
  j["dim"] = dim;
  j["problem"] = input;
  j["problem"]["name"] = problem.name;
  j["options"] = options_to_json(problem, s.options);
  j["box"] = domain_of(problem).box;
  j["grid"] = grid_json(s.grid);
  j["multipliers"] = s.n_points();
  j["boundary"] = boundary_json(problem, s);
  j["alpha"] = s.alpha;
  j["newton"] = newton_json(s.newton);
  j["newton"]["nested_start"] = s.nested_start ? nested_start_json(*s.nested_start) : json(nullptr);
  j["inner"] = inner_json(s);
  j["timings"] = timings_json(s.timings);
  j["condition_number"] = s.condition_number ? json(*s.condition_number) : json(nullptr);
  j["signorini"] = signorini_json(s.signorini);
  j["signorini"]["check"] = nullptr;
  if (s.check)
    j["signorini"]["check"] = {{"rule", s.check->rule},
                               {"min_normal_derivative", s.check->min_normal_derivative},
                               {"max_complementarity", s.check->max_complementarity},
                               {"max_difference", s.check->max_difference},
                               {"rms_difference", s.check->rms_difference},
                               {"relative_difference", s.check->relative_difference}};
  const ContactSummary contact = contact_summary(s);
  j["contact"] = {{"points", contact.points},
                  {"measure", contact.measure},
                  {"measure_points", contact.measure_points},
                  {"force", contact.force},
                  {"force_patches", contact.force_patches},
                  {"force_rule", contact.force_from_domain ? "domain" : "patches"},
                  {"lambda_integral", contact.lambda},
                  {"min_gap", contact.min_gap},
                  {"max_gap", contact.max_gap}};
  j["contact"]["boundary"] = json::array();
  for (const Point<dim>& x : s.contact_boundary) {
    json p = json::array();
    for (int d = 0; d < dim; ++d) p.push_back(x[d]);
    j["contact"]["boundary"].push_back(p);
  }
  const auto part_json = [](const PartSummary& p) {
    return json{{"points", p.points}, {"measure", p.measure}, {"flux", p.flux}};
  };
  j["conditions"] = {{"signorini", part_json(contact.signorini)},
                     {"dirichlet", part_json(contact.dirichlet)},
                     {"neumann", part_json(contact.neumann)},
                     {"junctions", json::array()}};  // where the parts meet, located between the points
  for (const PartJunction<dim>& junction : s.junctions) {
    json p = json::array();
    for (int d = 0; d < dim; ++d) p.push_back(junction.at[d]);
    j["conditions"]["junctions"].push_back(p);
  }
  j["contact"]["boundary_lines"] = json::array();  // 3-D: consecutive points of contact.boundary
  for (const auto& line : s.contact_boundary_lines) j["contact"]["boundary_lines"].push_back({line[0], line[1]});
  j["contact"]["fit"] = nullptr;  // solver.fit_contact: the solves that placed the points to the contact boundary
  if (s.contact_fit)
    j["contact"]["fit"] = {{"passes", s.contact_fit->passes},
                           {"moved", s.contact_fit->moved},
                           {"newton_steps", s.contact_fit->newton_steps},
                           {"seconds", s.contact_fit->seconds}};
  j["domain"] = s.domain ? domain_json(*s.domain) : json(nullptr);
  j["estimate"] = s.estimate ? estimate_json(*s.estimate) : json(nullptr);
  j["flux_balance"] = s.flux_balance ? json{{"scatter", s.flux_balance->scatter},
                                            {"mean", s.flux_balance->mean},
                                            {"data_shift", s.flux_balance->data_shift}}
                                     : json(nullptr);
  if (s.errors) j["errors"] = errors_json(*s.errors, s.point_errors);
  std::vector<std::string> warnings = input_warnings;
  warnings.insert(warnings.end(), s.warnings.begin(), s.warnings.end());
  j["warnings"] = warnings;
  j["peak_memory_bytes"] = s.peak_memory_bytes;
  if (!s.rank_peak_memory_bytes.empty()) {  // a run on several MPI ranks
    std::size_t total = 0;
    for (std::size_t b : s.rank_peak_memory_bytes) total += b;
    j["ranks"] = json{{"count", s.rank_peak_memory_bytes.size()},
                      {"peak_memory_bytes", s.rank_peak_memory_bytes},
                      {"total_peak_memory_bytes", total}};
  }
  return j;
}

template json solution_to_json(const BasicProblem<2>&, const BasicSolution<2>&, const json&,
                               const std::vector<std::string>&);
template json solution_to_json(const BasicProblem<3>&, const BasicSolution<3>&, const json&,
                               const std::vector<std::string>&);

LevelResult level_result(const Solution& s) {
  LevelResult r;
  r.N = s.grid.nx();
  r.n_nodes = s.grid.n_nodes();
  r.m = s.collocation.m;
  r.it0 = s.newton.iterations;
  r.it1 = s.fast_solves;
  r.time = s.timings.total;
  if (s.errors) {
    r.l2_omega = s.errors->rel_l2_omega;
    r.h1_omega = s.errors->rel_h1_omega;
    r.l2_gamma = s.errors->rel_l2_gamma;
  }
  return r;
}

namespace {

namespace fs = std::filesystem;

/// The nearest existing folder at or above `dir` ("." for a relative path with none).
fs::path existing_ancestor(const fs::path& dir) {
  fs::path p = dir;
  std::error_code error;
  while (!p.empty() && !fs::exists(p, error)) p = p.parent_path();
  return p.empty() ? fs::path(".") : p;
}

std::string reason(const std::error_code& error) { return error ? error.message() : std::string("unknown error"); }

}  // namespace

void on_rank_0(const Distribution& distribution, const std::function<void()>& work) {
  if (!distribution.distributed()) return work();
  std::exception_ptr failure;
  if (distribution.rank() == 0) try {
      work();
    } catch (...) {
      failure = std::current_exception();
    }
  if (distribution.all(!failure)) return;
  if (failure) std::rethrow_exception(failure);
  throw std::runtime_error("rank 0 stopped the run (its error line says why)");
}

void agree_on_threads(const Distribution& distribution, SolverOptions& options) {
  if (!distribution.distributed()) return;
  options.threads = int(-distribution.max(-double(Execution(options.threads).threads())));
}

void check_output_folder(const fs::path& dir, const std::vector<std::string>& names) {
  for (std::size_t k = 0; k < names.size(); ++k)
    if (std::find(names.begin(), names.begin() + k, names[k]) != names.begin() + k)
      throw std::invalid_argument("output.files: " + names[k].substr(0, 60) + " is named twice");
  std::error_code error;
  const std::string shown = dir.string().substr(0, 120);
  if (fs::exists(dir, error) && !fs::is_directory(dir, error))
    throw OutputError("output.dir: " + shown + " exists and is not a folder");
  const fs::path base = existing_ancestor(dir);
  if (!fs::is_directory(base, error))
    throw OutputError("output.dir: " + base.string().substr(0, 120) + " is not a folder");
  // Writable in fact, not only by its mode bits (a read-only mount, /proc): a folder made and removed.
  const fs::path probe = base / (".fictus-probe-" + std::to_string(::getpid()));
  if (::mkdir(probe.c_str(), 0700) != 0)
    throw OutputError("output.dir: cannot write in " + base.string().substr(0, 120) + " (" + std::strerror(errno) +
                      ")");
  ::rmdir(probe.c_str());
  for (const std::string& name : names)
    if (fs::is_directory(dir / name, error))
      throw OutputError("output.dir: " + (dir / name).string().substr(0, 120) + " is a folder, not a file");
}

bool written_by_fictus(const fs::path& file, const std::string& key) {
  std::error_code error;
  if (!fs::is_regular_file(file, error)) return false;
  std::ifstream in(file, std::ios::binary);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);  // no exception: discarded when bad
  return j.is_object() && j.contains(key);
}

std::function<bool(const std::string&)> earlier_solve_outputs(const fs::path& dir) {
  if (!written_by_fictus(dir / "results.json", "options")) return {};
  std::string pieces;  // the earlier solution.pvti, which names the ranks' parts of the field
  if (std::ifstream in(dir / "solution.pvti", std::ios::binary); in)
    pieces.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return [pieces](const std::string& name) {
    static const std::set<std::string> names = {
        "results.json", "points.csv",       "solution.vti",       "solution.pvti", "curves.vtp",
        "surface.vtp",  "offset_curve.vtp", "offset_surface.vtp", "solution.vtm",  "contact_boundary.vtp",
        "solution.png", "profiles.png",     "slices.png",         "surface.png"};
    static const std::regex piece(R"(solution_\d+\.vti)");
    return names.count(name) > 0 ||
           (std::regex_match(name, piece) && pieces.find('"' + name + '"') != std::string::npos);
  };
}

void write_output_set(const fs::path& dir, const std::vector<OutputFile>& files,
                      const std::function<bool(const std::string&)>& superseded) {
  std::vector<std::string> names;
  for (const OutputFile& f : files) names.push_back(f.name);
  check_output_folder(dir, names);
  std::error_code error;
  // The folders made here (from the nearest existing one down to `dir`), removed again on failure.
  std::vector<fs::path> made;
  for (fs::path p = dir; !p.empty() && !fs::exists(p, error); p = p.parent_path()) made.push_back(p);
  // The temporary folder lives inside `dir`, so that every move is a rename within one file system
  // (`dir` may be a mount point).
  const fs::path tmp = dir / (".fictus-tmp-" + std::to_string(::getpid()));
  std::vector<std::string> placed, kept;  // new files moved into `dir`; earlier ones set aside in tmp
  const auto undo = [&] {
    std::error_code ignored;
    for (const std::string& name : placed) fs::remove(dir / name, ignored);
    for (const std::string& name : kept) fs::rename(tmp / (name + ".earlier"), dir / name, ignored);
    fs::remove_all(tmp, ignored);
    for (const fs::path& p : made) fs::remove(p, ignored);  // innermost first; only if empty
  };
  try {
    fs::create_directories(dir, error);
    if (error) throw OutputError("output: cannot make " + dir.string().substr(0, 120) + ": " + reason(error));
    fs::remove_all(tmp, error);
    if (!fs::create_directory(tmp, error))
      throw OutputError("output: cannot make a temporary folder in " + dir.string().substr(0, 120) + ": " +
                        reason(error));
    for (const OutputFile& f : files) {  // 1. every file into the temporary folder
      std::ofstream out(tmp / f.name, std::ios::binary);
      if (out) f.write(out);
      if (out) out.flush();
      if (!out) throw OutputError("output: cannot write " + f.name + ": " + std::strerror(errno));
    }
    for (const OutputFile& f : files) {  // 2. all written: the earlier file aside, the new one in place
      if (fs::exists(dir / f.name, error)) {
        fs::rename(dir / f.name, tmp / (f.name + ".earlier"), error);
        if (error) throw OutputError("output: cannot replace " + f.name + ": " + reason(error));
        kept.push_back(f.name);
      }
      fs::rename(tmp / f.name, dir / f.name, error);
      if (error) throw OutputError("output: cannot move " + f.name + " into place: " + reason(error));
      placed.push_back(f.name);
    }
    if (superseded) {  // 3. an earlier run's files that this set does not replace by name: aside as well
      std::vector<std::string> stale;
      for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        if (superseded(name) && std::find(names.begin(), names.end(), name) == names.end() &&
            !fs::is_directory(entry.path(), error))
          stale.push_back(name);
      }
      for (const std::string& name : stale) {
        fs::rename(dir / name, tmp / (name + ".earlier"), error);
        if (error) throw OutputError("output: cannot remove the earlier " + name + ": " + reason(error));
        kept.push_back(name);
      }
    }
    fs::remove_all(tmp, error);
  } catch (const fs::filesystem_error& e) {
    undo();
    throw OutputError(std::string("output: ") + e.code().message());
  } catch (...) {
    undo();
    throw;
  }
}

std::string levels_csv(const std::vector<LevelResult>& rows) {
  std::ostringstream out;
  out.precision(10);
  out << "N,h,n_nodes,m,it0,it1,time,rel_l2_omega,rel_h1_omega,rel_l2_gamma\n";
  for (const LevelResult& r : rows)
    out << r.N << ',' << 1.0 / r.N << ',' << r.n_nodes << ',' << r.m << ',' << r.it0 << ',' << r.it1 << ',' << r.time
        << ',' << r.l2_omega << ',' << r.h1_omega << ',' << r.l2_gamma << '\n';
  return out.str();
}

template <int dim>
std::string points_csv(const BasicSolution<dim>& s) {
  static const char* axis[] = {"x", "y", "z"};
  std::ostringstream out;
  out.precision(17);
  // s: the arc length (2-D); weight: the part of γ the point owns (an arc or a patch area); Gamma_*: the
  // point of Γ carrying λ; dudn_check: the independent check's ∂u/∂n (empty when there is none)
  out << "i" << (dim == 2 ? ",s" : "");
  for (int d = 0; d < dim; ++d) out << ',' << axis[d];
  for (int d = 0; d < dim; ++d) out << ",n" << axis[d];
  out << ",weight,g,u,dudn,lambda,contact,condition";
  for (int d = 0; d < dim; ++d) out << ",Gamma_" << axis[d];
  out << ",dudn_check\n";
  const bool check = s.check && int(s.check->normal_derivative.size()) == s.n_points();
  for (int i = 0; i < s.n_points(); ++i) {
    Point<dim> G;
    if constexpr (dim == 2)
      G = s.Gamma->position(s.collocation.t[i]);
    else
      G = s.Gamma.point[i];
    out << i;
    if constexpr (dim == 2) out << ',' << s.collocation.s[i];
    for (int d = 0; d < dim; ++d) out << ',' << s.points()[i][d];
    for (int d = 0; d < dim; ++d) out << ',' << s.normals()[i][d];
    out << ',' << s.weights()[i] << ',' << s.g[i] << ',' << s.trace[i] << ',' << s.normal_derivative[i] << ','
        << s.lambda[i] << ',' << int(s.in_contact(i)) << ',' << int(s.condition(i));
    for (int d = 0; d < dim; ++d) out << ',' << G[d];
    out << ',';
    if (check) out << s.check->normal_derivative[i];
    out << '\n';
  }
  return out.str();
}

template std::string points_csv(const BasicSolution<2>&);
template std::string points_csv(const BasicSolution<3>&);

}  // namespace fictus::cli
