#pragma once
// Every setting of a solve, described once, for both dimensions: its section and key (the problem-file
// key, the CLI flag `--key`, the key in results.json's `options` and the Python keyword), its type, the
// dimensions it applies to, its default (read back from a default-constructed DomainSettings(dim) or
// SolverOptions), its meaning and the rule its values must obey. The problem-file reader, the CLI,
// results.json, the bindings, `fictus options` and the table in docs/problem_files.md all come from
// this list. An option given for a dimension it does not apply to is refused (check_applies).
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "fictus/solve/problem.hpp"

namespace fictus {

/// A value as given: bool, integer, number, text (choices) or a fixed-length list of numbers.
using OptionValue = std::variant<bool, std::int64_t, double, std::string, std::vector<double>>;

enum class OptionType { boolean, integer, number, choice, numbers };

/// The grid-level settings of a problem in either dimension: the [domain] section and data.c.
struct DomainSettings {
  /// The defaults of dimension `dim`: the unit box, N = 256 (2-D) or 64 (3-D), Dirichlet, c = 1.
  explicit DomainSettings(int dim = 2);
  int dim;
  std::vector<double> box;  // bounds order: [x0, x1, y0, y1] or [x0, x1, y0, y1, z0, z1]
  int N;                    // cells along x
  Boundary boundary = Boundary::dirichlet;
  double c = 1.0;
};
template <int dim>
DomainSettings domain_of(const BasicProblem<dim>& problem);
/// Sets the problem's box, N, boundary and c (throws naming domain.dim for another dimension).
template <int dim>
void apply_domain(const DomainSettings& domain, BasicProblem<dim>& problem);

struct OptionSpec {
  std::string section;  // "domain", "formulation", "data" or "solver"
  std::string key;      // e.g. "newton_tolerance"
  OptionType type = OptionType::number;
  std::string meaning;               // one line: unit and meaning (help text, docs)
  std::string rule;                  // the allowed values in words, e.g. "in (0, 1)"
  std::vector<std::string> choices;  // choice: the accepted names (first spelling is canonical)
  std::size_t count = 0;             // numbers: the list's length (0: 2·dim, the box)
  std::vector<std::string> aliases;  // older CLI flag names, accepted and hidden
  std::vector<int> dims = {2, 3};    // the dimensions it applies to
  /// The value in (domain, options); the default is get(DomainSettings(dim), SolverOptions{}).
  std::function<OptionValue(const DomainSettings&, const SolverOptions&)> get;
  /// Stores a value that passed check().
  std::function<void(DomainSettings&, SolverOptions&, const OptionValue&)> set;
  /// Empty when the value obeys the rule in dimension dim, else the reason ("must be > 0").
  std::function<std::string(const OptionValue&, int dim)> violation;

  std::string name() const { return section + "." + key; }
  bool applies_to(int dim) const;
  OptionValue default_value(int dim = 2) const;
};

/// All options, in the order of the docs.
const std::vector<OptionSpec>& option_specs();
/// The option with this key (or "section.key"); nullptr if there is none.
const OptionSpec* find_option(std::string_view key);

/// Throws std::invalid_argument "section.key: <reason>" when `value` has the wrong type or breaks the
/// rule in dimension dim; converts an integer given for a number.
OptionValue checked(const OptionSpec& spec, OptionValue value, int dim = 2);
/// Reads a value from text (a command-line argument): "true"/"false", integers, numbers, choice
/// names, comma-separated numbers; then checked().
OptionValue parse_option_text(const OptionSpec& spec, const std::string& text, int dim = 2);
/// Throws std::invalid_argument "section.key: applies to 3-D problems only (this one is 2-D)" when the
/// option does not apply to dimension dim (given in a file, a flag or Python: refused, never ignored).
void check_applies(const OptionSpec& spec, int dim);
/// Refuses (check_applies) an option that does not apply to dimension dim and is set away from its default.
void check_options_apply(int dim, const SolverOptions& options);
/// check_applies(), checked(), then set().
void set_option(const OptionSpec& spec, DomainSettings& domain, SolverOptions& options, OptionValue value);
template <int dim>
void set_option(const OptionSpec& spec, BasicProblem<dim>& problem, SolverOptions& options, OptionValue value);
/// The value as text: what `fictus options`, the help and the docs print ("1e-09", "\"smooth\"").
std::string option_text(const OptionSpec& spec, const OptionValue& value);
/// Checks every option that applies to the dimension against its rule, refuses one set away from its
/// default where it does not apply (check_applies), and checks that the box and N make a grid (whole
/// cells, even counts on a periodic box); throws naming the first one broken.
void validate_options(const DomainSettings& domain, const SolverOptions& options);
template <int dim>
void validate_options(const BasicProblem<dim>& problem, const SolverOptions& options);
/// The largest `threads` accepted: 4 × the hardware threads (at least 4).
int max_threads();

/// " (did you mean \"radius\"?)" for the candidate nearest to `name` (edit distance with
/// transpositions, letter case ignored) when it is at most max(1, |name|/3) edits away and fewer
/// than the shorter name's letters (so "g" never suggests "f"); else "".
/// Every message about an unknown name (key, section, flag, choice, variable) ends with it.
std::string did_you_mean(std::string_view name, const std::vector<std::string>& candidates);

/// The default as `fictus options` prints it: one value, or the 2-D and the 3-D one.
std::string default_text(const OptionSpec& spec);
/// The options table in Markdown (section, key, dimensions, default, rule, meaning), as in
/// docs/problem_files.md.
std::string options_markdown();

}  // namespace fictus
