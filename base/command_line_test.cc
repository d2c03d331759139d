#include "base/command_line.h"

#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <CLI/CLI.hpp>

namespace orbed {
namespace {

/// Runs a one-option app (--x, a double checked by `check`) on `args`; returns the exit code (-1 to
/// go on) and what it printed.
struct Outcome {
  int code;
  double x;
  std::string out, err;
};

Outcome Parse(const CLI::Validator& check, std::vector<std::string> args) {
  CLI::App app{"test"};
  AddVersionFlag(&app);
  double x = -7;
  app.add_option("--x", x)->check(check);
  std::vector<const char*> argv{"prog"};
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const auto code = ParseArguments(&app, static_cast<int>(argv.size()), argv.data(), out, err);
  return {code ? *code : -1, x, out.str(), err.str()};
}

TEST(CommandLine, UsageErrorsExitTwoHelpAndVersionZero) {
  EXPECT_EQ(Parse(FiniteNumber(), {"--bogus"}).code, kExitUsage);
  EXPECT_EQ(Parse(FiniteNumber(), {"--x"}).code, kExitUsage);         // value missing
  EXPECT_EQ(Parse(FiniteNumber(), {"--x", "abc"}).code, kExitUsage);  // not a number
  EXPECT_EQ(Parse(FiniteNumber(), {"extra"}).code, kExitUsage);       // positional not taken
  const Outcome bogus = Parse(FiniteNumber(), {"--bogus"});
  EXPECT_EQ(bogus.err, "prog: The following argument was not expected: --bogus (see --help)\n");
  EXPECT_EQ(bogus.out, "");
  EXPECT_EQ(Parse(FiniteNumber(), {"--help"}).code, 0);
  const Outcome version = Parse(FiniteNumber(), {"--version"});
  EXPECT_EQ(version.code, 0);
  EXPECT_EQ(version.out, VersionText() + "\n");
  const Outcome ok = Parse(FiniteNumber(), {"--x", "2.5"});
  EXPECT_EQ(ok.code, -1);
  EXPECT_EQ(ok.x, 2.5);
}

TEST(CommandLine, VersionNamesTheProjectVersionAndACommit) {
  EXPECT_TRUE(std::regex_match(
      VersionText(),
      std::regex(R"(orbed [0-9]+\.[0-9]+\.[0-9]+ \(commit ([0-9a-f]{12}|unknown)(, modified)?\))")))
      << VersionText();
}

TEST(CommandLine, NumberChecksRefuseNanAndInfinities) {
  for (const char* bad : {"nan", "NaN", "inf", "-inf", "1e999"}) {
    EXPECT_EQ(Parse(FiniteNumber(), {"--x", bad}).code, kExitUsage) << bad;
    EXPECT_EQ(Parse(PositiveNumber(), {"--x", bad}).code, kExitUsage) << bad;
    EXPECT_EQ(Parse(NonNegativeNumber(), {"--x", bad}).code, kExitUsage) << bad;
    EXPECT_EQ(Parse(NumberIn(-1e300, 1e300), {"--x", bad}).code, kExitUsage) << bad;
  }
}

TEST(CommandLine, NumberChecksKeepTheirBoundsIncludingTheEnds) {
  EXPECT_EQ(Parse(PositiveNumber(), {"--x", "0"}).code, kExitUsage);
  EXPECT_EQ(Parse(PositiveNumber(), {"--x", "1e-9"}).code, -1);
  EXPECT_EQ(Parse(NonNegativeNumber(), {"--x", "0"}).code, -1);
  EXPECT_EQ(Parse(NonNegativeNumber(), {"--x", "-1e-9"}).code, kExitUsage);
  EXPECT_EQ(Parse(NumberIn(0.1, 60), {"--x", "0.1"}).code, -1);
  EXPECT_EQ(Parse(NumberIn(0.1, 60), {"--x", "60"}).code, -1);
  EXPECT_EQ(Parse(NumberIn(0.1, 60), {"--x", "60.001"}).code, kExitUsage);
  EXPECT_EQ(Parse(NumberIn(0.1, 60), {"--x", "0.09"}).code, kExitUsage);
}

TEST(CommandLine, BoundsArePrintedAsWritten) {
  const Outcome range = Parse(NumberIn(0.1, 60), {"--x", "nan"});
  EXPECT_NE(range.err.find("expected a finite number in [0.1, 60], got 'nan'"), std::string::npos)
      << range.err;
  const Outcome positive = Parse(PositiveNumber(), {"--x", "-1"});
  EXPECT_NE(positive.err.find("expected a finite number > 0, got '-1'"), std::string::npos) << positive.err;
  // No 309-digit double anywhere (CLI11's own PositiveNumber prints DBL_MAX in full).
  EXPECT_LT(positive.err.size(), 200u) << positive.err;
}

/// Runs an app with --p (a list of 3) on `args`; the exit code (-1 to go on), the values, err.
struct ListOutcome {
  int code;
  std::vector<double> values;
  std::string err;
};

ListOutcome ParseList(std::vector<std::string> args, size_t count = 3) {
  CLI::App app{"test"};
  std::vector<double> values;
  AddNumberListOption(&app, "--p", &values, count, "a point");
  std::vector<const char*> argv{"prog"};
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const auto code = ParseArguments(&app, static_cast<int>(argv.size()), argv.data(), out, err);
  return {code ? *code : -1, values, err.str()};
}

TEST(CommandLine, APointIsOneCommaSeparatedArgument) {
  EXPECT_EQ(ParseList({"--p", "1.5,-0.25, 2e-3"}).values, (std::vector<double>{1.5, -0.25, 0.002}));
  EXPECT_EQ(ParseList({"--p", "1,2,3"}).code, -1);
  EXPECT_EQ(ParseList({}).values, std::vector<double>{});  // not given: untouched
  const ListOutcome two = ParseList({"--p", "1,2"});
  EXPECT_EQ(two.code, kExitUsage);
  EXPECT_NE(two.err.find("expected a comma-separated list of 3 numbers, got 2 in '1,2'"), std::string::npos)
      << two.err;
  EXPECT_EQ(ParseList({"--p", "1", "2", "3"}).code, kExitUsage);  // the space-separated form is refused
  EXPECT_EQ(ParseList({"--p", "1 2 3"}).code, kExitUsage);
  EXPECT_EQ(ParseList({"--p", "1,nan,3"}).code, kExitUsage);
  EXPECT_EQ(ParseList({"--p", "1,2,3,"}).code, kExitUsage);
  EXPECT_EQ(ParseList({"--p", "0,20,0,-60,0,40,0"}, 0).values,
            (std::vector<double>{0, 20, 0, -60, 0, 40, 0}));
}

}  // namespace
}  // namespace orbed
