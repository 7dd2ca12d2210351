#include "option_flags.hpp"

#include <algorithm>

namespace fictus::cli {

void OptionFlags::add(CLI::App& command, const std::function<bool(const OptionSpec&)>& include,
                      const std::map<std::string, std::string>& note) {
  for (const OptionSpec& spec : option_specs()) {
    if (!include(spec)) continue;
    std::string& text = text_[spec.key];
    std::string help = spec.meaning + " [" + spec.rule + "; default " + option_text(spec, spec.default_value());
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

void OptionFlags::apply(Problem& problem, SolverOptions& options) const {
  for (const Flag& f : flags_)
    if (given(f.spec->key)) set_option(*f.spec, problem, options, parse_option_text(*f.spec, text_.at(f.spec->key)));
  if (no_condition_flag_ && no_condition_flag_->count() > 0) options.condition_number = false;
}

}  // namespace fictus::cli
