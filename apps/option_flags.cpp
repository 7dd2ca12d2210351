#include "option_flags.hpp"

#include <algorithm>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "fictus/solve/paper_problem.hpp"

namespace fictus::cli {

std::string plain(std::string text) {
  text.erase(std::remove(text.begin(), text.end(), '`'), text.end());
  return text;
}

void OptionFlags::add(CLI::App& command, const std::function<bool(const OptionSpec&)>& include,
                      const std::map<std::string, std::string>& note) {
  for (const OptionSpec& spec : option_specs()) {
    if (!include(spec) || spec.key == "dim") continue;  // the dimension is the problem file's
    std::string& text = text_[spec.key];
    const std::string dims = spec.applies_to(2) && spec.applies_to(3) ? ""
                             : spec.applies_to(2)                     ? "2-D only; "
                                                                      : "3-D only; ";
    std::string help = spec.meaning + " [" + dims + spec.rule + "; default " + plain(default_text(spec));
    if (const auto it = note.find(spec.key); it != note.end()) help += "; " + it->second;
    help += "]";
    static const char* const type_names[] = {"BOOL", "INT", "FLOAT", "CHOICE", "LIST"};
    Flag flag{&spec, {command.add_option("--" + spec.key, text, help)->type_name(type_names[int(spec.type)])}};
    std::vector<std::string> aliases = spec.aliases;
    std::string dashed = spec.key;
    std::replace(dashed.begin(), dashed.end(), '_', '-');
    if (dashed != spec.key) aliases.push_back(dashed);
    for (const std::string& alias : aliases)
      flag.options.push_back(command.add_option("--" + alias, text, "alias of --" + spec.key)->group(""));
    flags_.push_back(flag);
    if (spec.key == "condition_number") {
      no_condition_flag_ =
          command.add_flag("--no-condition", no_condition_, "same as --condition_number false")->group("");
    }
  }
}

bool OptionFlags::given(const std::string& key) const {
  for (const Flag& f : flags_)
    if (f.spec->key == key)
      return std::any_of(f.options.begin(), f.options.end(), [](const CLI::Option* o) { return o->count() > 0; });
  return false;
}

void OptionFlags::apply(DomainSettings& domain, SolverOptions& options) const {
  for (const Flag& f : flags_)
    if (given(f.spec->key)) {
      check_applies(*f.spec, domain.dim);
      set_option(*f.spec, domain, options, parse_option_text(*f.spec, text_.at(f.spec->key), domain.dim));
    }
  if (no_condition_flag_ && no_condition_flag_->count() > 0) {
    check_applies(*find_option("condition_number"), domain.dim);
    options.condition_number = false;
  }
}

namespace {

/// The paper's problem, with its m and δ unless the flags say otherwise.
ProblemSpec paper_spec(const OptionFlags& flags, const ParameterValues& parameters) {
  if (!parameters.empty()) throw std::invalid_argument("--parameter: only a problem file has [parameters]");
  Problem given;
  SolverOptions options;
  flags.apply(given, options);
  if (given.N % 2)
    throw std::invalid_argument(
        "domain.N: the paper's problem needs an even N (its data have kinks on x = 1/2 and "
        "y = 1/2, which must be grid lines), got " +
        std::to_string(given.N));
  ProblemSpec spec;
  spec.problem = paper_problem(given.N, given.c, given.boundary);
  spec.options = paper_options(given.N, options.variant);
  spec.input_json = nlohmann::json{{"geometry", "the paper's ellipse (built in)"},
                                   {"data", "the paper's f, g and exact solution (built in; f follows c)"}}
                        .dump();
  return spec;
}

}  // namespace

template <int dim>
BasicProblemSpec<dim> problem_from_text(const std::string& text, const std::string& path, const OptionFlags& flags,
                                        const ParameterValues& parameters,
                                        std::shared_ptr<const typename BoundaryShape<dim>::type> shape) {
  BasicProblemSpec<dim> spec;
  if (!path.empty()) {
    spec = parse_problem<dim>(text, path, parameters, std::move(shape));
    const std::string name = path.substr(path.find_last_of('/') + 1);
    spec.problem.name = name.substr(0, name.rfind(".toml"));
  } else if constexpr (dim == 2) {
    spec = paper_spec(flags, parameters);
  } else {
    throw std::invalid_argument("arguments: a 3-D problem needs a problem file");
  }
  flags.apply(spec.problem, spec.options);
  validate_options(spec.problem, spec.options);
  return spec;
}

template ProblemSpec problem_from_text(const std::string&, const std::string&, const OptionFlags&,
                                       const ParameterValues&, std::shared_ptr<const Curve>);
template SurfaceProblemSpec problem_from_text(const std::string&, const std::string&, const OptionFlags&,
                                              const ParameterValues&, std::shared_ptr<const Surface>);

}  // namespace fictus::cli
