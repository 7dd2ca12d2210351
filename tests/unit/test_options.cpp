// The option descriptions (options.hpp): names unique, every rule enforced with a message naming
// the key, text and typed values read alike, defaults those of the structs.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <string>

#include "fictus/options.hpp"

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Options, KeysAndAliasesAreUniqueAndFlagSafe) {
  std::set<std::string> names;
  for (const fictus::OptionSpec& s : fictus::option_specs()) {
    EXPECT_TRUE(names.insert(s.key).second) << s.key;
    for (const std::string& alias : s.aliases) EXPECT_TRUE(names.insert(alias).second) << alias;
    EXPECT_EQ(s.key.find_first_not_of("abcdefghijklmnopqrstuvwxyzN_"), std::string::npos) << s.key;
    EXPECT_FALSE(s.meaning.empty()) << s.key;
    EXPECT_FALSE(s.rule.empty()) << s.key;
    EXPECT_EQ(fictus::find_option(s.key), &s);
    EXPECT_EQ(fictus::find_option(s.name()), &s);
  }
  EXPECT_EQ(fictus::find_option("tolerance"), nullptr);
}

TEST(Options, DefaultsObeyTheirRules) {
  fictus::Problem p;
  fictus::SolverOptions o;
  EXPECT_NO_THROW(fictus::validate_options(p, o));
  for (const fictus::OptionSpec& s : fictus::option_specs())
    EXPECT_NO_THROW(fictus::checked(s, s.default_value())) << s.key;
}

TEST(Options, BadValuesAreRejectedNamingTheKey) {
  auto text_error = [](const char* key, const char* text) {
    return error_of([&] { fictus::parse_option_text(*fictus::find_option(key), text); });
  };
  EXPECT_EQ(text_error("start", "bogus"), "solver.start: expected \"all\" or \"zero\", got \"bogus\"");
  EXPECT_NE(text_error("newton_tolerance", "2").find("solver.newton_tolerance: must be in (0.0, 1.0)"),
            std::string::npos);
  EXPECT_NE(text_error("N", "4").find("domain.N: need 8 <= N"), std::string::npos);
  EXPECT_NE(text_error("N", "12x").find("domain.N: expected an integer"), std::string::npos);
  EXPECT_NE(text_error("threads", "1000000").find("solver.threads: must be in 0"), std::string::npos);
  EXPECT_NE(text_error("normal_shift", "1e300").find("formulation.normal_shift: must be in [0.0, 8.0]"),
            std::string::npos);
  EXPECT_NE(text_error("rho", "nan").find("formulation.rho"), std::string::npos);
  EXPECT_NE(text_error("c", "-1").find("data.c"), std::string::npos);
  // The expected order is said, and what was given.
  EXPECT_NE(text_error("box", "0,1,1,0").find("domain.box: the box is [x0, x1, y0, y1] (bounds order"),
            std::string::npos);
  EXPECT_NE(text_error("box", "0,0,1,1").find("with x0 < x1 and y0 < y1, got [0.0, 0.0, 1.0, 1.0]"), std::string::npos);
  // Unknown choices and names are answered with the nearest known one.
  EXPECT_EQ(text_error("variant", "smoth"),
            "formulation.variant: expected \"automatic\", \"smooth\" or \"nonsmooth\", got \"smoth\" (did you mean "
            "\"smooth\"?)");
  EXPECT_EQ(fictus::did_you_mean("raduis", {"center", "radius"}), " (did you mean \"radius\"?)");
  EXPECT_EQ(fictus::did_you_mean("--n", {"--N", "--m", "--out"}), " (did you mean \"--N\"?)");
  EXPECT_EQ(fictus::did_you_mean("pi", {"x", "y", "_pi", "_e"}), " (did you mean \"_pi\"?)");
  EXPECT_EQ(fictus::did_you_mean("threds", {"threads", "rho"}), " (did you mean \"threads\"?)");
  EXPECT_EQ(fictus::did_you_mean("banana", {"threads", "rho"}), "");
  EXPECT_EQ(fictus::did_you_mean("g", {"f", "c"}), "");  // one letter for another is no spelling
  EXPECT_NE(text_error("box", "0,1,0").find("domain.box: expected an array of 4 numbers"), std::string::npos);
  EXPECT_NE(text_error("condition_number", "maybe").find("solver.condition_number"), std::string::npos);
  // A periodic box needs an even N: a rule across two options.
  fictus::Problem p;
  p.boundary = fictus::Boundary::periodic;
  p.N = 129;
  EXPECT_NE(error_of([&] {
              fictus::validate_options(p, fictus::SolverOptions{});
            }).find("domain.N: a periodic box needs an even"),
            std::string::npos);
}

TEST(Options, TextAndTypedValuesSetTheSameOption) {
  fictus::Problem p;
  fictus::SolverOptions o;
  fictus::set_option(*fictus::find_option("offset"), p, o, std::int64_t(2));  // an integer for a number
  EXPECT_EQ(o.offset, 2.0);
  fictus::set_option(*fictus::find_option("variant"), p, o,
                     fictus::parse_option_text(*fictus::find_option("variant"), "non-smooth"));
  EXPECT_EQ(o.variant, fictus::Variant::nonsmooth);
  EXPECT_EQ(std::get<std::string>(fictus::find_option("variant")->get(p, o)), "nonsmooth");  // the canonical name
  fictus::set_option(*fictus::find_option("box"), p, o,
                     fictus::parse_option_text(*fictus::find_option("box"), "-1,2,0,3"));
  EXPECT_EQ(p.box.lower.x, -1.0);
  EXPECT_EQ(p.box.upper.y, 3.0);
  EXPECT_EQ(fictus::option_text(*fictus::find_option("newton_tolerance"), 1e-9), "1e-09");
}

}  // namespace
