#pragma once
// Every setting of a solve, described once: its section and key (the problem-file key, the CLI flag
// `--key`, the key in results.json's `options` and the Python keyword), its type, its default (the
// member initializer of Problem or SolverOptions, read back from a default-constructed object), its
// meaning and the rule its values must obey. The problem-file reader, the CLI, results.json, the
// bindings, `fictus options` and the table in docs/problem_files.md all come from this list.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "fictus/problem.hpp"

namespace fictus {

/// A value as given: bool, integer, number, text (choices) or a fixed-length list of numbers.
using OptionValue = std::variant<bool, std::int64_t, double, std::string, std::vector<double>>;

enum class OptionType { boolean, integer, number, choice, numbers };

struct OptionSpec {
  std::string section;  // "domain", "formulation", "data" or "solver"
  std::string key;      // e.g. "newton_tolerance"
  OptionType type = OptionType::number;
  std::string meaning;               // one line: unit and meaning (help text, docs)
  std::string rule;                  // the allowed values in words, e.g. "in (0, 1)"
  std::vector<std::string> choices;  // choice: the accepted names (first spelling is canonical)
  std::size_t count = 0;             // numbers: the list's length
  std::vector<std::string> aliases;  // older CLI flag names, accepted and hidden
  /// The value in (problem, options); the default is get(Problem{}, SolverOptions{}).
  std::function<OptionValue(const Problem&, const SolverOptions&)> get;
  /// Stores a value that passed check().
  std::function<void(Problem&, SolverOptions&, const OptionValue&)> set;
  /// Empty when the value obeys the rule, else the reason ("must be > 0").
  std::function<std::string(const OptionValue&)> violation;

  std::string name() const { return section + "." + key; }
  OptionValue default_value() const;
};

/// All options, in the order of the docs.
const std::vector<OptionSpec>& option_specs();
/// The option with this key (or "section.key"); nullptr if there is none.
const OptionSpec* find_option(std::string_view key);

/// Throws std::invalid_argument "section.key: <reason>" when `value` has the wrong type or breaks the
/// rule; converts an integer given for a number.
OptionValue checked(const OptionSpec& spec, OptionValue value);
/// Reads a value from text (a command-line argument): "true"/"false", integers, numbers, choice
/// names, comma-separated numbers; then checked().
OptionValue parse_option_text(const OptionSpec& spec, const std::string& text);
/// checked() then set().
void set_option(const OptionSpec& spec, Problem& problem, SolverOptions& options, OptionValue value);
/// The value as text: what `fictus options`, the help and the docs print ("1e-09", "\"smooth\"").
std::string option_text(const OptionSpec& spec, const OptionValue& value);
/// Checks every option of (problem, options) against its rule, and that the box and N make a grid
/// (whole cells, even counts on a periodic box); throws naming the first one broken.
void validate_options(const Problem& problem, const SolverOptions& options);
/// The largest `threads` accepted: 4 × the hardware threads (at least 4).
int max_threads();

/// " (did you mean \"radius\"?)" for the candidate nearest to `name` (edit distance with
/// transpositions, letter case ignored) when it is at most max(1, |name|/3) edits away and fewer
/// than the shorter name's letters (so "g" never suggests "f"); else "".
/// Every message about an unknown name (key, section, flag, choice, variable) ends with it.
std::string did_you_mean(std::string_view name, const std::vector<std::string>& candidates);

/// The options table in Markdown (section, key, default, rule, meaning), as in docs/problem_files.md.
std::string options_markdown();

}  // namespace fictus
