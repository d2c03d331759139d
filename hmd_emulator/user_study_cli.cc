#include "hmd_emulator/user_study_cli.h"

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include "base/source_paths.h"
#include "hmd_emulator/user_study.h"

namespace orbed::hmd {
namespace {

// A positive decimal integer that fits an int, the whole text; else false.
bool ParsePositiveInt(const std::string& text, int* value) {
  if (text.empty() || text[0] < '0' || text[0] > '9') return false;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (errno != 0 || *end != '\0' || v < 1 || v > INT_MAX) return false;
  *value = static_cast<int>(v);
  return true;
}

// --trials' transform: refuses what ParsePositiveInt refuses and hands CLI11 the plain decimal form
// (CLI11's own integer parser would read "010" as octal and "0x10" as hex).
CLI::Validator PositiveDecimalInt() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        int value = 0;
        if (!ParsePositiveInt(text, &value)) return "needs a positive integer, got '" + text + "'";
        text = std::to_string(value);
        return "";
      },
      "POSITIVE");
}

}  // namespace

int RunUserStudy(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-user-study: run the emulated ViRAAl study and print, per display mode, the error\n"
      "statistics next to the paper's Table 1, and the rank tests comparing the modes."};
  StudyOptions o;
  o.source_dir = SourceDir();
  app.add_option("--trials", o.trials_per_mode, "Trials per display mode, a positive integer")
      ->transform(PositiveDecimalInt())
      ->capture_default_str();
  app.add_option("--source", o.source_dir,
                 "Repository root with the model, scene and configs (default: $ORBED_SOURCE_DIR, else the "
                 "source tree it was built from)");
  app.add_option("--user", o.user_config_path, "User model config (default: hmd_emulator/config/user.yaml)");
  app.add_option("--slam", o.slam_config_path, "SLAM error config (default: hmd_emulator/config/slam.yaml)");
  app.add_option("--display-at", o.display_waypoints,
                 "Where the reflective display captures its frame (repeat for more displays; default: the "
                 "walk's first waypoint)")
      ->allow_extra_args(false);  // one WAYPOINT per --display-at
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e, out, err);
    return code == 0 ? 0 : 2;  // this tool's bad-argument code, not CLI11's
  }
  try {
    out << FormatStudyReport(RunStudy(o));
  } catch (const std::exception& e) {
    err << "orbed-user-study: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace orbed::hmd
