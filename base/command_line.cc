#include "base/command_line.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>

#include "base/number_list.h"
#include "orbed_build_commit.h"  // generated at build time: ORBED_BUILD_COMMIT, ORBED_BUILD_MODIFIED

namespace orbed {

namespace {

/// A bound as people write it: 60, 0.1, 1e+06.
std::string BoundText(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

/// A validator of a number passing `ok`; `expected` completes "expected a number ...".
CLI::Validator NumberCheck(std::function<bool(double)> ok, const std::string& expected,
                           const std::string& name) {
  return CLI::Validator(
      [ok, expected](std::string& value) {
        double number = 0;
        if (CLI::detail::lexical_cast(value, number) && std::isfinite(number) && ok(number)) {
          return std::string();
        }
        return "expected a finite number" + expected + ", got '" + value + "'";
      },
      name);
}

/// "orbed-foo": the app's name, else argv[0], without its folder.
std::string ProgramName(const CLI::App& app, int argc, const char* const* argv) {
  std::string name = app.get_name();
  if (name.empty() && argc > 0 && argv[0] != nullptr) name = argv[0];
  const size_t slash = name.rfind('/');
  return slash == std::string::npos ? name : name.substr(slash + 1);
}

/// CLI11's message on one line.
std::string OneLine(std::string text) {
  while (!text.empty() && text.back() == '\n') text.pop_back();
  for (char& c : text) {
    if (c == '\n') c = ' ';
  }
  return text;
}

}  // namespace

std::string VersionText() {
  std::string text = std::string("orbed ") + ORBED_VERSION + " (commit " + ORBED_BUILD_COMMIT;
  if (ORBED_BUILD_MODIFIED) text += ", modified";
  return text + ")";
}

void AddVersionFlag(CLI::App* app) {
  app->set_version_flag("--version", VersionText(), "Print the version and the git commit it was built from");
}

CLI::Validator FiniteNumber() {
  return NumberCheck([](double) { return true; }, "", "FINITE");
}

CLI::Validator PositiveNumber() {
  return NumberCheck([](double x) { return x > 0; }, " > 0", "POSITIVE");
}

CLI::Validator NonNegativeNumber() {
  return NumberCheck([](double x) { return x >= 0; }, " >= 0", "NONNEGATIVE");
}

CLI::Validator NumberIn(double lo, double hi) {
  const std::string range = "[" + BoundText(lo) + ", " + BoundText(hi) + "]";
  return NumberCheck([lo, hi](double x) { return x >= lo && x <= hi; }, " in " + range, "in " + range);
}

CLI::Option* AddNumberListOption(CLI::App* app, const std::string& name, std::vector<double>* values,
                                 size_t count, const std::string& help) {
  const std::string shape =
      count == 0 ? "a,b,..." : "a comma-separated list of " + std::to_string(count) + " numbers";
  CLI::Option* option = app->add_option_function<std::string>(
      name, [name, values](const std::string& text) { *values = ParseNumberList(text, name); }, help);
  option->type_name(count == 0 ? "LIST" : "LIST" + std::to_string(count));
  option->check(CLI::Validator(
      [name, count, shape](std::string& text) {
        try {
          const size_t n = ParseNumberList(text, name).size();
          if (count != 0 && n != count) {
            return "expected " + shape + ", got " + std::to_string(n) + " in '" + text + "'";
          }
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
        return std::string();
      },
      ""));
  return option;
}

std::optional<int> ParseArguments(CLI::App* app, int argc, const char* const* argv, std::ostream& out,
                                  std::ostream& err) {
  try {
    app->parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app->exit(e, out, err);  // --help, --version: printed on out
    err << ProgramName(*app, argc, argv) << ": " << OneLine(e.what()) << " (see --help)\n";
    return kExitUsage;
  }
  return std::nullopt;
}

}  // namespace orbed
