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
#include "fictus/solve/options.hpp"

namespace fictus::cli {

class OptionFlags {
 public:
  /// Adds a flag for every option that `include` accepts. `note` is appended to the help of the keys
  /// it names (e.g. the defaults that differ without a problem file).
  void add(CLI::App& command, const std::function<bool(const OptionSpec&)>& include,
           const std::map<std::string, std::string>& note = {});
  /// Sets every option given on the command line into (domain, options); throws naming the key, and
  /// refuses an option of the other dimension.
  void apply(DomainSettings& domain, SolverOptions& options) const;
  template <int dim>
  void apply(BasicProblem<dim>& problem, SolverOptions& options) const {
    DomainSettings domain = domain_of(problem);
    apply(domain, options);
    apply_domain(domain, problem);
  }
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

/// The problem a command works on, with the flags applied and checked: the problem file's text (read
/// once: a sweep's members, a file that may change or be a pipe), its [parameters] replaced by
/// `parameters`, or without a file (2-D only) the paper's problem with its m and δ unless the flags
/// give them. `shape` as in parse_problem.
template <int dim>
BasicProblemSpec<dim> problem_from_text(const std::string& text, const std::string& path, const OptionFlags& flags,
                                        const ParameterValues& parameters = {},
                                        std::shared_ptr<const typename BoundaryShape<dim>::type> shape = nullptr);

/// Markdown text as plain text for the terminal (without the backticks of `fictus options --markdown`).
std::string plain(std::string text);

}  // namespace fictus::cli
