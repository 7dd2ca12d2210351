// The option descriptions (options.hpp): names unique, every rule enforced with a message naming
// the key, text and typed values read alike, defaults those of the structs.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <string>

#include "fictus/solve/options.hpp"

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
  fictus::SolverOptions o;
  EXPECT_NO_THROW(fictus::validate_options(fictus::Problem{}, o));
  EXPECT_NO_THROW(fictus::validate_options(fictus::SurfaceProblem{}, o));
  for (int dim : {2, 3})
    for (const fictus::OptionSpec& s : fictus::option_specs())
      if (s.applies_to(dim)) EXPECT_NO_THROW(fictus::checked(s, s.default_value(dim), dim)) << s.key << " " << dim;
}

TEST(Options, OneSchemaKnowsTheDimension) {
  const fictus::OptionSpec& N = *fictus::find_option("N");
  const fictus::OptionSpec& box = *fictus::find_option("box");
  EXPECT_EQ(std::get<std::int64_t>(N.default_value(2)), 256);
  EXPECT_EQ(std::get<std::int64_t>(N.default_value(3)), 64);
  EXPECT_EQ(std::get<std::vector<double>>(box.default_value(3)), (std::vector<double>{0, 1, 0, 1, 0, 1}));
  EXPECT_EQ(fictus::default_text(N), "`256` (2-D), `64` (3-D)");
  // One box order in both dimensions, and one message for N's range.
  auto text_error = [](const char* key, const char* text, int dim) {
    return error_of([&] { fictus::parse_option_text(*fictus::find_option(key), text, dim); });
  };
  EXPECT_EQ(text_error("box", "0,1,0,1,0,1", 3), "");
  EXPECT_NE(text_error("box", "0,0,0,1,1,1", 3).find("domain.box: the box is [x0, x1, y0, y1, z0, z1] (bounds order"),
            std::string::npos);
  EXPECT_NE(text_error("box", "0,1,0,1", 3).find("domain.box: expected an array of 6 numbers in 3-D"),
            std::string::npos);
  EXPECT_NE(text_error("N", "2048", 3).find("domain.N: need 8 <= N <= 1024 in 3-D, got 2048"), std::string::npos);
  EXPECT_NE(text_error("N", "4", 2).find("domain.N: need 8 <= N <= 1048576 in 2-D, got 4"), std::string::npos);
  // An option of the other dimension is refused, never ignored: by name, and when set in a problem.
  EXPECT_EQ(error_of([] { fictus::check_applies(*fictus::find_option("condition_number"), 3); }), "");
  EXPECT_EQ(error_of([] { fictus::check_applies(*fictus::find_option("flux_balance"), 2); }),
            "formulation.flux_balance: applies to 3-D problems only (this one is 2-D)");
  fictus::SolverOptions o;
  o.flux_balance = false;
  EXPECT_EQ(error_of([&] { fictus::validate_options(fictus::Problem{}, o); }),
            "formulation.flux_balance: applies to 3-D problems only (this one is 2-D)");
  EXPECT_EQ(error_of([&] { fictus::validate_options(fictus::SurfaceProblem{}, o); }), "");
  o = {};
  o.nested_start = 0;
  EXPECT_EQ(error_of([&] { fictus::validate_options(fictus::Problem{}, o); }),
            "solver.nested_start: applies to 3-D problems only (this one is 2-D)");
  // The domain of a problem and back, in bounds order.
  fictus::SurfaceProblem q;
  q.box = fictus::Box3{{-1, -2, -3}, {1, 2, 3}};
  q.N = 48;
  const fictus::DomainSettings d = fictus::domain_of(q);
  EXPECT_EQ(d.dim, 3);
  EXPECT_EQ(d.box, (std::vector<double>{-1, 1, -2, 2, -3, 3}));
  fictus::SurfaceProblem back;
  fictus::apply_domain(d, back);
  EXPECT_EQ(back.box.lower.z, -3.0);
  EXPECT_EQ(back.N, 48);
  fictus::Problem flat;
  EXPECT_NE(error_of([&] { fictus::apply_domain(d, flat); }).find("domain.dim"), std::string::npos);
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
  EXPECT_EQ(std::get<std::string>(fictus::find_option("variant")->get(fictus::domain_of(p), o)),
            "nonsmooth");  // the canonical name
  fictus::set_option(*fictus::find_option("box"), p, o,
                     fictus::parse_option_text(*fictus::find_option("box"), "-1,2,0,3"));
  EXPECT_EQ(p.box.lower.x, -1.0);
  EXPECT_EQ(p.box.upper.y, 3.0);
  EXPECT_EQ(fictus::option_text(*fictus::find_option("newton_tolerance"), 1e-9), "1e-09");
}

}  // namespace
