#pragma once
// The options of options.hpp as command-line flags: `--key VALUE` for every key (the problem file's
// name), with `--key-with-dashes` and older names as hidden aliases. Values are kept as text and
// applied through the same checks as the problem file's.
#include <CLI/CLI.hpp>

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "fictus/io/problem_file.hpp"
#include "fictus/options.hpp"

namespace fictus::cli {

class OptionFlags {
 public:
  /// Adds a flag for every option that `include` accepts. `note` is appended to the help of the keys
  /// it names (e.g. the defaults that differ without a problem file).
  void add(CLI::App& command, const std::function<bool(const OptionSpec&)>& include,
           const std::map<std::string, std::string>& note = {});
  /// Sets every option given on the command line into (problem, options); throws naming the key.
  void apply(Problem& problem, SolverOptions& options) const;
  bool given(const std::string& key) const;

 private:
  struct Flag {
    const OptionSpec* spec;
    std::vector<CLI::Option*> options;  // the flag and its aliases
  };
  std::vector<Flag> flags_;
  std::map<std::string, std::string> text_;  // key → value as typed
  bool no_condition_ = false;
  CLI::Option* no_condition_flag_ = nullptr;
};

/// The problem a command works on, with the flags applied and checked: the problem file at `path`
/// (its [parameters] replaced by `parameters`), or without one the paper's problem with its m and δ
/// unless the flags give them. `input` is set to what results.json echoes under "problem".
ProblemSpec problem_from(const std::string& path, const OptionFlags& flags, const ParameterValues& parameters = {});
/// The same from the file's text, read once (a sweep's members: the file may change or be a pipe).
/// `curve` as in parse_problem_text.
ProblemSpec problem_from_text(const std::string& text, const std::string& path, const OptionFlags& flags,
                              const ParameterValues& parameters = {}, std::shared_ptr<const Curve> curve = nullptr);

}  // namespace fictus::cli
