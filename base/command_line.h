#pragma once
/// @file
/// What every orbed command line shares, processes and tools alike, on CLI11:
///   - one exit code for a usage error (kExitUsage = 2: unknown flag, missing or bad value), 0 after
///     --help or --version;
///   - --version: "orbed <project version> (commit <12 hex>[, modified])", the commit the binary was
///     built from (read from git at build time; "unknown" outside a git checkout);
///   - number checks that refuse NaN and the infinities (which CLI::PositiveNumber and CLI::Range let
///     through: every comparison with NaN is false) and print their bounds as people write them
///     ("expected a finite number in [0.1, 60], got 'nan'"), not as 309-digit doubles;
///   - a usage error is one line on err: "orbed-foo: <what is wrong> (see --help)";
///   - one way to give a point or a joint vector: ONE argument of comma-separated numbers,
///     `--q-deg 0,20,0,-60,0,40,0`, `--camera-m 1.5,0.3,1.8` (AddNumberListOption).
/// Usage in a Run…(): add the options, `if (auto code = ParseArguments(&app, argc, argv, out, err))
/// return *code;`. Processes use ParseCommandLine (runtime/flags.h), which calls this.
/// Threading: pure functions.

#include <cstddef>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

// CLI11's types, declared only: a file that adds options includes <CLI/CLI.hpp> itself, so the
// ~30 k lines of CLI11 do not reach every process's translation units through process.h.
namespace CLI {
class App;
class Option;
class Validator;
}  // namespace CLI

namespace orbed {

/// Exit code of every usage error, in every orbed program (as Python's argparse and getopt tools).
inline constexpr int kExitUsage = 2;

/// "orbed 0.1.0 (commit 0123456789ab)", with ", modified" when the tree had uncommitted changes.
std::string VersionText();

/// Adds --version (prints VersionText(), exits 0).
void AddVersionFlag(CLI::App* app);

/// A finite number (refuses NaN, ±inf and text).
CLI::Validator FiniteNumber();
/// A finite number > 0.
CLI::Validator PositiveNumber();
/// A finite number >= 0.
CLI::Validator NonNegativeNumber();
/// A finite number in [lo, hi].
CLI::Validator NumberIn(double lo, double hi);

/// Adds `name` taking one argument "a,b,c" of finite numbers (base/number_list.h), `count` of them
/// (0: one or more), stored in `values`; anything else is a usage error naming the option.
CLI::Option* AddNumberListOption(CLI::App* app, const std::string& name, std::vector<double>* values,
                                 size_t count, const std::string& help);

/// Parses `argv` into `app`. Returns std::nullopt to go on, else the exit code to return now:
/// 0 after --help (usage on `out`) or --version (on `out`), kExitUsage after a usage error (one
/// line on `err`, above).
std::optional<int> ParseArguments(CLI::App* app, int argc, const char* const* argv, std::ostream& out,
                                  std::ostream& err);

}  // namespace orbed
