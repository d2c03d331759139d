// orbed-hmd's command line in-process: --help prints the usage on `out` and exits 0; an unknown flag
// or a bad value exits non-zero with one message on `err`; options the process refuses exit 1.
#include "hmd_emulator/hmd_cli.h"

#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace orbed::hmd {
namespace {

struct Result {
  int code;
  std::string out, err;
};

Result Hmd(std::vector<const char*> args) {
  args.insert(args.begin(), "orbed-hmd");
  std::ostringstream out, err;
  const int code = RunHmd(static_cast<int>(args.size()), args.data(), out, err);
  return {code, out.str(), err.str()};
}

TEST(RunHmd, HelpPrintsTheUsageAndExitsZero) {
  const Result r = Hmd({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("orbed-hmd: the emulated headset"), std::string::npos) << r.out;
  for (const char* flag : {"--lcm-url", "--seed", "--displays", "--interactive", "--scripted-keys",
                           "--trial-channel", "--user-seed", "--config"}) {
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
  }
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(RunHmd, UnknownFlagExitsNonZeroWithAMessage) {
  const Result r = Hmd({"--no-such-flag-xyz"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("no-such-flag-xyz"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  const Result bad_value = Hmd({"--camera-hz", "fast"});
  EXPECT_NE(bad_value.code, 0);
  EXPECT_FALSE(bad_value.err.empty());
  const Result bad_level = Hmd({"--log-level", "loud"});
  EXPECT_NE(bad_level.code, 0);
  EXPECT_FALSE(bad_level.err.empty());
}

TEST(RunHmd, OptionsTheProcessRefusesExitOne) {
  const Result r = Hmd({"--lcm-url", "memq://", "--displays", "9"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("orbed-hmd: --displays must be in [0, 2]"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace orbed::hmd
