/// @file
/// orbed-user-study: runs the emulated ViRAAl study (user_study.h) and prints, per display mode, the
/// error statistics next to the paper's Table 1, and the rank tests comparing the modes.
/// No LCM. Usage: orbed-user-study [--trials N] [--source DIR] [--user FILE] [--slam FILE]
///                               [--display-at WAYPOINT]...
/// DIR defaults to orbed::SourceDir() ($ORBED_SOURCE_DIR, else the source tree it was built from); a
/// bad argument exits 2, a failed run 1.
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "hmd_emulator/user_study.h"
#include "base/source_paths.h"

namespace {

// A positive decimal integer that fits an int, the whole argument; else false.
bool ParsePositiveInt(const char* text, int* value) {
  if (text == nullptr || *text < '0' || *text > '9') return false;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text, &end, 10);
  if (errno != 0 || *end != '\0' || v < 1 || v > INT_MAX) return false;
  *value = static_cast<int>(v);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  orbed::hmd::StudyOptions o;
  o.source_dir = orbed::SourceDir();
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--help" || a == "-h") {
      std::printf(
          "usage: orbed-user-study [--trials N] [--source DIR] [--user FILE] [--slam FILE] [--display-at "
          "WAYPOINT]...\n"
          "  --trials N            trials per display mode, a positive integer (default %d)\n"
          "  --display-at WAYPOINT where the reflective display captures its frame (repeat for more\n"
          "                        displays; default: the walk's first waypoint)\n",
          o.trials_per_mode);
      return 0;
    } else if (a == "--trials") {
      if (!has_value || !ParsePositiveInt(argv[i + 1], &o.trials_per_mode)) {
        std::fprintf(stderr, "orbed-user-study: --trials needs a positive integer, got '%s'\n",
                     has_value ? argv[i + 1] : "(nothing)");
        return 2;
      }
      ++i;
    } else if (a == "--source" && has_value) {
      o.source_dir = argv[++i];
    } else if (a == "--user" && has_value) {
      o.user_config_path = argv[++i];
    } else if (a == "--slam" && has_value) {
      o.slam_config_path = argv[++i];
    } else if (a == "--display-at" && has_value) {
      o.display_waypoints.push_back(argv[++i]);
    } else {
      std::fprintf(stderr, "orbed-user-study: unknown argument '%s' (try --help)\n", a.c_str());
      return 2;
    }
  }
  try {
    std::fputs(orbed::hmd::FormatStudyReport(orbed::hmd::RunStudy(o)).c_str(), stdout);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "orbed-user-study: %s\n", e.what());
    return 1;
  }
  return 0;
}
