#include "fictus/solve/options.hpp"

#include <sched.h>

#include "fictus/grid/execution.hpp"
#include "fictus/grid/q1_symbol.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace fictus {

namespace {

/// The shortest text that reads back as v ("1e-10", "1e12", "0.75"), marked as a number ("1.0").
std::string format_number(double v) {
  char buffer[32];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
    if (std::strtod(buffer, nullptr) == v) break;
  }
  if (v == std::floor(v) && std::abs(v) < 1e6) std::snprintf(buffer, sizeof buffer, "%.0f", v);  // 100, not 1e+02
  std::string text = buffer;
  if (const auto e = text.find("e+"); e != std::string::npos) text.erase(e + 1, 1);
  if (text.find_first_of(".en") == std::string::npos) text += ".0";  // a number, not an integer
  return text;
}

std::string quoted_list(const std::vector<std::string>& names) {
  std::string text;
  for (std::size_t k = 0; k < names.size(); ++k)
    text += (k ? (k + 1 == names.size() ? " or " : ", ") : "") + ("\"" + names[k] + "\"");
  return text;
}

/// A member of SolverOptions or Problem, read and written through the value's alternative.
template <class T, class Owner>
OptionSpec member(std::string section, std::string key, OptionType type, T Owner::*field, std::string meaning) {
  OptionSpec spec;
  spec.section = std::move(section);
  spec.key = std::move(key);
  spec.type = type;
  spec.meaning = std::move(meaning);
  spec.get = [field](const DomainSettings& p, const SolverOptions& o) -> OptionValue {
    const Owner* owner;
    if constexpr (std::is_same_v<Owner, DomainSettings>)
      owner = &p, (void)o;
    else
      owner = &o, (void)p;
    if constexpr (std::is_same_v<T, int>)
      return std::int64_t(owner->*field);
    else
      return owner->*field;
  };
  spec.set = [field](DomainSettings& p, SolverOptions& o, const OptionValue& v) {
    Owner* owner;
    if constexpr (std::is_same_v<Owner, DomainSettings>)
      owner = &p, (void)o;
    else
      owner = &o, (void)p;
    if constexpr (std::is_same_v<T, int>)
      owner->*field = int(std::get<std::int64_t>(v));
    else
      owner->*field = std::get<T>(v);
  };
  return spec;
}

OptionSpec integer(std::string section, std::string key, int SolverOptions::*field, std::int64_t lo, std::int64_t hi,
                   std::string meaning) {
  OptionSpec s = member(std::move(section), std::move(key), OptionType::integer, field, std::move(meaning));
  s.rule = "in " + std::to_string(lo) + " … " + std::to_string(hi);
  s.violation = [lo, hi](const OptionValue& v, int) {
    const std::int64_t i = std::get<std::int64_t>(v);
    return i < lo || i > hi
               ? "must be in " + std::to_string(lo) + " … " + std::to_string(hi) + ", got " + std::to_string(i)
               : std::string();
  };
  return s;
}

/// A number in an interval; `open_low`/`open_high` exclude the end.
template <class Owner>
OptionSpec number(std::string section, std::string key, double Owner::*field, double lo, bool open_low, double hi,
                  bool open_high, std::string meaning) {
  OptionSpec s = member(std::move(section), std::move(key), OptionType::number, field, std::move(meaning));
  const std::string lo_text = format_number(lo), hi_text = std::isinf(hi) ? "∞" : format_number(hi);
  if (std::isinf(hi))
    s.rule = open_low ? "> " + lo_text : ">= " + lo_text;
  else
    s.rule = std::string("in ") + (open_low ? "(" : "[") + lo_text + ", " + hi_text + (open_high ? ")" : "]");
  const std::string rule = s.rule;
  s.violation = [=](const OptionValue& v, int) {
    const double x = std::get<double>(v);
    const bool ok = std::isfinite(x) && (open_low ? x > lo : x >= lo) && (open_high ? x < hi : x <= hi);
    return ok ? std::string() : "must be " + rule + ", got " + format_number(x);
  };
  return s;
}

/// A choice stored as an enum: names[k] ↔ values[k] (later names are accepted spellings).
template <class Enum, class Owner>
OptionSpec choice(std::string section, std::string key, Enum Owner::*field, std::vector<std::string> names,
                  std::vector<Enum> values, std::string meaning) {
  OptionSpec s;
  s.section = std::move(section);
  s.key = std::move(key);
  s.type = OptionType::choice;
  s.meaning = std::move(meaning);
  s.choices = names;
  s.get = [=](const DomainSettings& p, const SolverOptions& o) -> OptionValue {
    Enum e;
    if constexpr (std::is_same_v<Owner, DomainSettings>)
      e = p.*field, (void)o;
    else
      e = o.*field, (void)p;
    for (std::size_t k = 0; k < values.size(); ++k)
      if (values[k] == e) return names[k];
    return std::string("?");
  };
  s.set = [=](DomainSettings& p, SolverOptions& o, const OptionValue& v) {
    const auto k = std::size_t(std::find(names.begin(), names.end(), std::get<std::string>(v)) - names.begin());
    if constexpr (std::is_same_v<Owner, DomainSettings>)
      p.*field = values[k], (void)o;
    else
      o.*field = values[k], (void)p;
  };
  s.violation = [](const OptionValue&, int) { return std::string(); };  // the names are checked by checked()
  std::vector<std::string> canonical;  // the first name of each value; later ones are other spellings
  for (std::size_t k = 0; k < names.size(); ++k)
    if (std::find(values.begin(), values.begin() + k, values[k]) == values.begin() + k) canonical.push_back(names[k]);
  s.rule = quoted_list(canonical);
  return s;
}

/// [domain]: the box, N and the boundary conditions.
void domain_specs(std::vector<OptionSpec>& specs) {
  {
    OptionSpec dim;
    dim.section = "domain", dim.key = "dim", dim.type = OptionType::integer;
    dim.meaning = "2: a curve in a rectangle; 3: a surface in a box (from the problem file: it sets the other keys)";
    dim.rule = "2 or 3";
    dim.get = [](const DomainSettings& d, const SolverOptions&) -> OptionValue { return std::int64_t(d.dim); };
    dim.set = [](DomainSettings& d, SolverOptions&, const OptionValue& v) { d.dim = int(std::get<std::int64_t>(v)); };
    dim.violation = [](const OptionValue& v, int) {
      const std::int64_t n = std::get<std::int64_t>(v);
      return n == 2 || n == 3 ? std::string() : "expected 2 or 3, got " + std::to_string(n);
    };
    specs.push_back(dim);
  }
  {
    OptionSpec box;
    box.section = "domain", box.key = "box", box.type = OptionType::numbers, box.count = 0;  // 2·dim
    box.meaning = "Ω = [x0, x1] × [y0, y1] (× [z0, z1]), in bounds order";
    box.rule = "[x0, x1, y0, y1] or [x0, x1, y0, y1, z0, z1]: finite, x0 < x1, y0 < y1, z0 < z1";
    box.get = [](const DomainSettings& d, const SolverOptions&) -> OptionValue { return d.box; };
    box.set = [](DomainSettings& d, SolverOptions&, const OptionValue& v) { d.box = std::get<std::vector<double>>(v); };
    box.violation = [](const OptionValue& v, int dim) {
      const auto& b = std::get<std::vector<double>>(v);
      for (double x : b)
        if (!std::isfinite(x) || std::abs(x) > 1e12) return std::string("must be finite numbers of magnitude <= 1e12");
      bool ordered = true;
      for (int d = 0; d < dim; ++d) ordered = ordered && b[2 * d] < b[2 * d + 1];
      if (ordered) return std::string();
      std::string given;
      for (double x : b) given += (given.empty() ? "" : ", ") + format_number(x);
      return std::string(dim == 2 ? "the box is [x0, x1, y0, y1]" : "the box is [x0, x1, y0, y1, z0, z1]") +
             " (bounds order, as VTK and matplotlib's extent) with x0 < x1" +
             (dim == 2 ? " and y0 < y1" : ", y0 < y1 and z0 < z1") + ", got [" + given + "]";
    };
    specs.push_back(box);
  }
  {
    OptionSpec N = member(std::string("domain"), std::string("N"), OptionType::integer, &DomainSettings::N,
                          "cells along x; h = (x1 − x0)/N, and the other sides must hold whole cells of h");
    N.rule = "8 … 1048576 in 2-D, 8 … 1024 in 3-D; even for a periodic box";
    N.violation = [](const OptionValue& v, int dim) {
      const std::int64_t n = std::get<std::int64_t>(v), most = dim == 2 ? 1048576 : 1024;
      return n < 8 || n > most ? "need 8 <= N <= " + std::to_string(most) + " in " + std::to_string(dim) + "-D, got " +
                                     std::to_string(n)
                               : std::string();
    };
    specs.push_back(N);
  }
  specs.push_back(choice(std::string("domain"), std::string("boundary"), &DomainSettings::boundary,
                         {to_string(Boundary::dirichlet), to_string(Boundary::periodic)},
                         {Boundary::dirichlet, Boundary::periodic},
                         "conditions on ∂Ω: u = 0, or periodic (even cell counts; c = 0 allowed)"));
}

/// [formulation]: the variant, m, δ, ρ and the traces.
void formulation_specs(std::vector<OptionSpec>& specs) {
  specs.push_back(
      choice(std::string("formulation"), std::string("variant"), &SolverOptions::variant,
             {to_string(Variant::automatic), to_string(Variant::smooth), to_string(Variant::nonsmooth), "non-smooth"},
             {Variant::automatic, Variant::smooth, Variant::nonsmooth, Variant::nonsmooth},
             "smooth: controls λ on the offset curve Γ outside ω; nonsmooth: multipliers on γ; "
             "automatic: smooth where γ has a continuous normal, nonsmooth where it has corners"));
  {
    OptionSpec m = integer("formulation", "multipliers", &SolverOptions::multipliers, 0, 1000000,
                           "m, the points (2-D) or patches (3-D) on γ; 0 = the default rule: spacing s = c·h, m = "
                           "max(8, round(L/s)) on a curve of length L, c = 8 (smooth) or 12 (non-smooth), "
                           "max(8, round(A/s²)) on a surface of area A, c = 5 (smooth) or 4 (non-smooth); a given m "
                           "needs 8 <= m and s >= 2h");
    m.aliases = {"m"};
    specs.push_back(m);
  }
  specs.push_back(
      number("formulation", "offset", &SolverOptions::offset, 0.0, false, 100.0, false,
             "smooth variant: δ/s, the distance of Γ from γ in units of the point spacing s; 0 = the "
             "default rule δ = 2·s on a curve, 1.5·s on a surface, made to fit (with a warning) where the box or γ "
             "leave Γ less room; Γ needs δ >= 4h"));
  specs.push_back(number("formulation", "rho", &SolverOptions::rho, 0.0, true, 1e12, false,
                         "ρ of the projection max{0, ∂u/∂n − ρ(u − g)}"));
  specs.push_back(choice(std::string("formulation"), std::string("normal_derivative"),
                         &SolverOptions::normal_derivative,
                         {to_string(NormalDerivative::reconstructed), to_string(NormalDerivative::shifted)},
                         {NormalDerivative::reconstructed, NormalDerivative::shifted},
                         "traces B_γ, C_γ: reconstructed (consistent at x_i) or shifted (the cell gradient "
                         "normal_shift cells inside ω; first order at best)"));
  specs.push_back(number("formulation", "normal_shift", &SolverOptions::normal_shift, 0.0, false, 8.0, false,
                         "shifted rule only: C_γ is taken this many cells h inside ω"));
  {
    OptionSpec b = member(std::string("formulation"), std::string("flux_balance"), OptionType::boolean,
                          &SolverOptions::flux_balance,
                          "non-smooth, reconstructed traces (not a periodic box with c = 0): correct the "
                          "readings ∂u/∂n so that each patch's multiplier and the data move their area-weighted "
                          "sum over γ by the discrete field's flux c∫_ω u − ∫_ω f");
    b.rule = "true or false";
    b.violation = [](const OptionValue&, int) { return std::string(); };
    b.dims = {3};
    specs.push_back(b);
  }
}

/// [data] c and the first half of [solver]: the Schur complement, GMRES, Newton, threads.
void data_and_solver_specs(std::vector<OptionSpec>& specs) {
  // [data]
  specs.push_back(number("data", "c", &DomainSettings::c, 0.0, false, largest_reaction, false,
                         "reaction coefficient of −Δu + c·u = f"));
  // [solver]
  specs.push_back(
      choice(std::string("solver"), std::string("schur"), &SolverOptions::inner,
             {to_string(InnerSolver::green), to_string(InnerSolver::krylov)}, {InnerSolver::green, InnerSolver::krylov},
             "green: explicit Schur complement, dense LU; krylov: GMRES on the implicit one (the paper's)"));
  specs.push_back(
      choice(std::string("solver"), std::string("schur_storage"), &SolverOptions::schur_storage,
             {to_string(SchurStorageKind::automatic), to_string(SchurStorageKind::dense),
              to_string(SchurStorageKind::hierarchical)},
             {SchurStorageKind::automatic, SchurStorageKind::dense, SchurStorageKind::hierarchical},
             "green: S_B and S_C dense (LU), or hierarchical (far pairs of low rank, no m × m "
             "array; GMRES with block LUs, then flexible GMRES on the exact S); auto: hierarchical from m = " +
                 std::to_string(hierarchical_from_points_3d) + " on in 3-D, " +
                 std::to_string(hierarchical_from_points_2d) + " in 2-D"));
  {
    OptionSpec s = number("solver", "krylov_tolerance", &SolverOptions::krylov_tolerance, 0.0, true, 1.0, true,
                          "relative GMRES residual");
    s.aliases = {"krylov-tol"};
    specs.push_back(s);
  }
  specs.push_back(integer("solver", "krylov_max_iterations", &SolverOptions::krylov_max_iterations, 1, 1000000,
                          "GMRES operator applications per solve"));
  {
    OptionSpec s = number("solver", "newton_tolerance", &SolverOptions::newton_tolerance, 0.0, true, 1.0, true,
                          "relative Newton residual ‖F‖∞");
    s.aliases = {"newton-tol"};
    specs.push_back(s);
  }
  specs.push_back(integer("solver", "max_newton", &SolverOptions::max_newton, 1, 10000,
                          "Newton steps; when exceeded the run fails with the iteration history"));
  {
    OptionSpec start;
    start.section = "solver", start.key = "start", start.type = OptionType::choice, start.choices = {"all", "zero"};
    start.meaning = "Newton start: all (every point active) or zero (λ = 0)";
    start.get = [](const DomainSettings&, const SolverOptions& o) -> OptionValue {
      return std::string(o.start_all_active ? "all" : "zero");
    };
    start.set = [](DomainSettings&, SolverOptions& o, const OptionValue& v) {
      o.start_all_active = std::get<std::string>(v) == "all";
    };
    start.violation = [](const OptionValue&, int) { return std::string(); };
    specs.push_back(start);
  }
  {
    OptionSpec t = member(std::string("solver"), std::string("threads"), OptionType::integer, &SolverOptions::threads,
                          "threads for the transforms, loops and dense algebra; 0 = the machine's "
                          "(OMP_NUM_THREADS when set, else the CPUs the process may run on)");
    t.rule = "in 0 … 4 × the hardware threads";
    t.violation = [](const OptionValue& v, int) {
      const std::int64_t n = std::get<std::int64_t>(v);
      return n < 0 || n > max_threads() ? "must be in 0 … " + std::to_string(max_threads()) +
                                              " (4 × the hardware threads), got " + std::to_string(n)
                                        : std::string();
    };
    specs.push_back(t);
  }
}

/// The rest of [solver]: memory, quadrature, the far field, the nested start, the error estimate, the
/// condition number.
void more_solver_specs(std::vector<OptionSpec>& specs) {
  specs.push_back(number("solver", "max_memory", &SolverOptions::max_memory, 0.0, false, 1e6, false,
                         "GiB a solve may use (checked against an estimate before any grid array is made); "
                         "0 = the memory available when the solve starts"));
  specs.push_back(integer("solver", "load_quadrature", &SolverOptions::load_quadrature, 1, 8,
                          "Gauss points per direction per cell for the load"));
  specs.push_back(integer("solver", "error_quadrature", &SolverOptions::error_quadrature, 1, 12,
                          "Gauss points per direction for the error integrals"));
  {
    OptionSpec f =
        member(std::string("solver"), std::string("far_field"), OptionType::boolean, &SolverOptions::far_field,
               "green: interpolate the far pairs of the Schur complement and finish Newton on the exact "
               "one (false: assemble every pair exactly)");
    f.rule = "true or false";
    f.violation = [](const OptionValue&, int) { return std::string(); };
    f.dims = {3};
    specs.push_back(f);
  }
  {
    OptionSpec n = integer("solver", "nested_start", &SolverOptions::nested_start, 0, 1048576,
                           "from this N on, Newton starts from the active set of the same problem solved on the "
                           "grid of N/2 (0: never)");
    n.dims = {3};
    specs.push_back(n);
  }
  specs.push_back(integer("solver", "fit_contact", &SolverOptions::fit_contact, -1, 8,
                          "solves more, each with the points placed so that their arcs (2-D) or patches (3-D) end "
                          "at the contact boundary the solve before located (0: one solve; -1: 2 with the smooth "
                          "variant in 2-D, else 0)"));
  {
    OptionSpec e = member(std::string("solver"), std::string("error_estimate"), OptionType::boolean,
                          &SolverOptions::error_estimate,
                          "estimate the errors of u, the force, the contact measure and the energy from the same "
                          "problem solved on the grid of N/2 (the nested start's solve where there is one)");
    e.rule = "true or false";
    e.violation = [](const OptionValue&, int) { return std::string(); };
    specs.push_back(e);
  }
  {
    OptionSpec c = member(std::string("solver"), std::string("condition_number"), OptionType::boolean,
                          &SolverOptions::condition_number,
                          "compute cond₂(S) of the final Newton matrix (dense Schur complement only)");
    c.rule = "true or false";
    c.violation = [](const OptionValue&, int) { return std::string(); };
    specs.push_back(c);
  }
}

std::vector<OptionSpec> make_specs() {
  std::vector<OptionSpec> specs;
  domain_specs(specs);
  formulation_specs(specs);
  data_and_solver_specs(specs);
  more_solver_specs(specs);
  for (OptionSpec& s : specs)
    if (s.type == OptionType::choice && s.rule.empty()) s.rule = quoted_list(s.choices);
  return specs;
}

[[noreturn]] void fail(const OptionSpec& spec, const std::string& reason) {
  throw std::invalid_argument(spec.name() + ": " + reason);
}

const char* type_words(OptionType t) {
  switch (t) {
    case OptionType::boolean:
      return "true or false";
    case OptionType::integer:
      return "an integer";
    case OptionType::number:
      return "a number";
    case OptionType::choice:
      return "a string";
    case OptionType::numbers:
      return "an array of numbers";
  }
  return "";
}

}  // namespace

const char* to_string(Variant v) {
  return v == Variant::smooth ? "smooth" : v == Variant::nonsmooth ? "nonsmooth" : "automatic";
}
const char* to_string(SchurStorageKind k) {
  return k == SchurStorageKind::automatic ? "auto" : k == SchurStorageKind::dense ? "dense" : "hierarchical";
}
const char* to_string(InnerSolver s) { return s == InnerSolver::green ? "green" : "krylov"; }
const char* to_string(NormalDerivative d) { return d == NormalDerivative::shifted ? "shifted" : "reconstructed"; }

std::string did_you_mean(std::string_view name, const std::vector<std::string>& candidates) {
  const auto lower = [](std::string_view text) {
    std::string out(text);
    for (char& ch : out) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return out;
  };
  const std::string a = lower(name);
  // Optimal string alignment distance: insertions, deletions, substitutions, adjacent transpositions.
  const auto distance = [&a](const std::string& b) {
    const std::size_t n = a.size(), m = b.size();
    std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
    for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= n; ++i)
      for (std::size_t j = 1; j <= m; ++j) {
        d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
        if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
          d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    return d[n][m];
  };
  if (a.empty() || a.size() > 64) return "";
  const std::size_t allowed = std::max<std::size_t>(1, a.size() / 3);
  std::size_t best = allowed + 1;
  std::string nearest;
  for (const std::string& candidate : candidates) {
    if (candidate.empty() || candidate.size() > a.size() + allowed + 1 || candidate == name) continue;
    const std::size_t d = distance(lower(candidate));
    // Not one that changes every letter ("g" for "f"): a near spelling keeps some of the name. A
    // one-letter key is kept by a name that only repeats it ("NN" for "N"; not "xy" for "x").
    const std::string c = lower(candidate);
    const bool keeps =
        d < std::min(a.size(), c.size()) || (c.size() == 1 && a.find_first_not_of(c) == std::string::npos);
    if (d < best && keeps) best = d, nearest = candidate;
  }
  return nearest.empty() ? "" : " (did you mean \"" + nearest + "\"?)";
}

int default_threads() {
  if (const char* text = std::getenv("OMP_NUM_THREADS")) {
    char* end = nullptr;
    const long n = std::strtol(text, &end, 10);  // "4" or "4,2" (nested levels): the first entry
    if (end != text && n > 0 && n <= max_threads()) return int(n);
  }
  cpu_set_t allowed;  // the CPUs this process may run on: fewer than the machine's under a launcher's binding
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0 && CPU_COUNT(&allowed) > 0) return CPU_COUNT(&allowed);
  return std::max(1, int(std::thread::hardware_concurrency()));
}

int max_threads() {
  static const int n = std::max(4, 4 * int(std::thread::hardware_concurrency()));
  return n;
}

const std::vector<OptionSpec>& option_specs() {
  static const std::vector<OptionSpec> specs = make_specs();
  return specs;
}

const OptionSpec* find_option(std::string_view key) {
  for (const OptionSpec& s : option_specs())
    if (s.key == key || s.name() == key) return &s;
  return nullptr;
}

bool OptionSpec::applies_to(int dim) const { return std::find(dims.begin(), dims.end(), dim) != dims.end(); }

OptionValue OptionSpec::default_value(int dim) const {
  if (key == "dim") return std::int64_t(2);  // a problem without domain.dim is 2-D
  return get(DomainSettings(dim), SolverOptions{});
}

DomainSettings::DomainSettings(int d) : dim(d), N(d == 3 ? 64 : 256) {
  for (int k = 0; k < d; ++k) box.push_back(0.0), box.push_back(1.0);
}

template <int dim>
DomainSettings domain_of(const BasicProblem<dim>& p) {
  DomainSettings d(dim);
  for (int k = 0; k < dim; ++k)
    d.box[std::size_t(2 * k)] = p.box.lower[k], d.box[std::size_t(2 * k + 1)] = p.box.upper[k];
  d.N = p.N;
  d.boundary = p.boundary;
  d.c = p.c;
  return d;
}

template <int dim>
void apply_domain(const DomainSettings& d, BasicProblem<dim>& p) {
  if (d.dim != dim || d.box.size() != std::size_t(2 * dim))
    throw std::invalid_argument("domain.dim: a " + std::to_string(d.dim) + "-D domain for a " + std::to_string(dim) +
                                "-D problem");
  for (int k = 0; k < dim; ++k)
    p.box.lower[k] = d.box[std::size_t(2 * k)], p.box.upper[k] = d.box[std::size_t(2 * k + 1)];
  p.N = d.N;
  p.boundary = d.boundary;
  p.c = d.c;
}

template DomainSettings domain_of(const BasicProblem<2>&);
template DomainSettings domain_of(const BasicProblem<3>&);
template void apply_domain(const DomainSettings&, BasicProblem<2>&);
template void apply_domain(const DomainSettings&, BasicProblem<3>&);

void check_applies(const OptionSpec& spec, int dim) {
  if (!spec.applies_to(dim))
    fail(spec, "applies to " + std::to_string(spec.dims.front()) + "-D problems only (this one is " +
                   std::to_string(dim) + "-D)");
}

OptionValue checked(const OptionSpec& spec, OptionValue value, int dim) {
  if (spec.type == OptionType::number && std::holds_alternative<std::int64_t>(value))
    value = double(std::get<std::int64_t>(value));
  const bool right_type = (spec.type == OptionType::boolean && std::holds_alternative<bool>(value)) ||
                          (spec.type == OptionType::integer && std::holds_alternative<std::int64_t>(value)) ||
                          (spec.type == OptionType::number && std::holds_alternative<double>(value)) ||
                          (spec.type == OptionType::choice && std::holds_alternative<std::string>(value)) ||
                          (spec.type == OptionType::numbers && std::holds_alternative<std::vector<double>>(value));
  if (!right_type) fail(spec, std::string("expected ") + type_words(spec.type));
  if (spec.type == OptionType::number && !std::isfinite(std::get<double>(value)))
    fail(spec, "must be finite (NaN or Inf given)");
  if (spec.type == OptionType::choice) {
    const std::string& text = std::get<std::string>(value);
    if (std::find(spec.choices.begin(), spec.choices.end(), text) == spec.choices.end())
      fail(spec, "expected " + spec.rule + ", got \"" + text.substr(0, 40) + (text.size() > 40 ? "…" : "") + "\"" +
                     did_you_mean(text, spec.choices));
  }
  if (spec.type == OptionType::numbers) {
    const auto& list = std::get<std::vector<double>>(value);
    const std::size_t count = spec.count > 0 ? spec.count : std::size_t(2 * dim);
    if (list.size() != count)
      fail(spec, "expected an array of " + std::to_string(count) + " numbers" +
                     (spec.count > 0 ? std::string() : " in " + std::to_string(dim) + "-D"));
    for (double x : list)
      if (!std::isfinite(x)) fail(spec, "must be finite (NaN or Inf given)");
  }
  if (const std::string reason = spec.violation(value, dim); !reason.empty()) fail(spec, reason);
  return value;
}

OptionValue parse_option_text(const OptionSpec& spec, const std::string& text, int dim) {
  auto as_number = [&](const std::string& t) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(t, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != t.size()) fail(spec, "expected a number, got \"" + t.substr(0, 40) + "\"");
    return v;
  };
  switch (spec.type) {
    case OptionType::boolean:
      if (text == "true" || text == "1" || text == "yes") return checked(spec, true, dim);
      if (text == "false" || text == "0" || text == "no") return checked(spec, false, dim);
      fail(spec, "expected true or false, got \"" + text.substr(0, 40) + "\"");
    case OptionType::integer: {
      std::size_t used = 0;
      long long v = 0;
      try {
        v = std::stoll(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != text.size()) fail(spec, "expected an integer, got \"" + text.substr(0, 40) + "\"");
      return checked(spec, std::int64_t(v), dim);
    }
    case OptionType::number:
      return checked(spec, as_number(text), dim);
    case OptionType::choice:
      return checked(spec, text, dim);
    case OptionType::numbers: {
      std::vector<double> list;
      std::stringstream in(text);
      for (std::string part; std::getline(in, part, ',');) list.push_back(as_number(part));
      return checked(spec, list, dim);
    }
  }
  fail(spec, "unknown type");
}

void set_option(const OptionSpec& spec, DomainSettings& domain, SolverOptions& options, OptionValue value) {
  check_applies(spec, domain.dim);
  spec.set(domain, options, checked(spec, std::move(value), domain.dim));
}

template <int dim>
void set_option(const OptionSpec& spec, BasicProblem<dim>& problem, SolverOptions& options, OptionValue value) {
  DomainSettings domain = domain_of(problem);
  set_option(spec, domain, options, std::move(value));
  apply_domain(domain, problem);
}

template void set_option(const OptionSpec&, BasicProblem<2>&, SolverOptions&, OptionValue);
template void set_option(const OptionSpec&, BasicProblem<3>&, SolverOptions&, OptionValue);

std::string option_text(const OptionSpec& spec, const OptionValue& value) {
  (void)spec;
  return std::visit(
      [](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>)
          return v ? "true" : "false";
        else if constexpr (std::is_same_v<T, std::int64_t>)
          return std::to_string(v);
        else if constexpr (std::is_same_v<T, double>)
          return format_number(v);
        else if constexpr (std::is_same_v<T, std::string>)
          return "\"" + v + "\"";
        else {
          std::string text = "[";
          for (std::size_t k = 0; k < v.size(); ++k) text += (k ? ", " : "") + format_number(v[k]);
          return text + "]";
        }
      },
      value);
}

void SolverOptions::validate() const {
  const DomainSettings defaults;  // the solver options do not read it
  for (const OptionSpec& spec : option_specs())
    if (spec.section == "formulation" || spec.section == "solver") checked(spec, spec.get(defaults, *this));
}

void check_options_apply(int dim, const SolverOptions& options) {
  const DomainSettings domain(dim);  // every [domain] key applies to both dimensions
  const SolverOptions defaults;
  for (const OptionSpec& spec : option_specs())
    if (!spec.applies_to(dim) && spec.get(domain, options) != spec.get(domain, defaults))
      check_applies(spec, dim);  // set away from its default where it means nothing: refused
}

void validate_options(const DomainSettings& domain, const SolverOptions& options) {
  if (domain.dim != 2 && domain.dim != 3) throw std::invalid_argument("domain.dim: expected 2 or 3");
  for (const OptionSpec& spec : option_specs())
    if (spec.applies_to(domain.dim)) checked(spec, spec.get(domain, options), domain.dim);
  check_options_apply(domain.dim, options);
  // The box must hold whole cells; periodic: even counts.
  if (domain.dim == 2) {
    BasicProblem<2> p;
    apply_domain(domain, p);
    (void)Grid2(p.box, p.N, p.boundary);
  } else {
    BasicProblem<3> p;
    apply_domain(domain, p);
    (void)Grid3(p.box, p.N, p.boundary);
  }
}

template <int dim>
void validate_options(const BasicProblem<dim>& problem, const SolverOptions& options) {
  validate_options(domain_of(problem), options);
}

template void validate_options(const BasicProblem<2>&, const SolverOptions&);
template void validate_options(const BasicProblem<3>&, const SolverOptions&);

std::string default_text(const OptionSpec& spec) {
  if (!spec.applies_to(2)) return "`" + option_text(spec, spec.default_value(3)) + "`";
  const std::string two = option_text(spec, spec.default_value(2));
  if (!spec.applies_to(3)) return "`" + two + "`";
  const std::string three = option_text(spec, spec.default_value(3));
  return two == three ? "`" + two + "`" : "`" + two + "` (2-D), `" + three + "` (3-D)";
}

std::string options_markdown() {
  std::string text;
  std::string section;
  for (const OptionSpec& s : option_specs()) {
    if (s.section != section) {
      section = s.section;
      text += (text.empty() ? "" : "\n") + std::string("[") + section +
              "]\n\n| key | dimensions | default | allowed | meaning |\n|---|---|---|---|---|\n";
    }
    const std::string dims = s.applies_to(2) && s.applies_to(3) ? "2, 3" : s.applies_to(2) ? "2" : "3";
    text += "| `" + s.key + "` | " + dims + " | " + default_text(s) + " | " + s.rule + " | " + s.meaning + " |\n";
  }
  return text;
}

}  // namespace fictus
