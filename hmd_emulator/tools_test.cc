// orbed-render-snapshot and orbed-user-study, run in-process: help on `out`, bad arguments exit 2
// with the flag named on `err`, and a real run of each (small, fast).
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/test_command.h"
#include "hmd_emulator/render_snapshot.h"
#include "hmd_emulator/user_study_cli.h"

namespace orbed::hmd {
namespace {

namespace fs = std::filesystem;

TEST(RenderSnapshotCli, HelpGoesToOutAndExitsZero) {
  const test::CommandRun r = test::RunCommand(RunRenderSnapshot, "orbed-render-snapshot", {"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--out"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(RenderSnapshotCli, BadArgumentsExitTwo) {
  test::CommandRun r = test::RunCommand(RunRenderSnapshot, "orbed-render-snapshot", {"--no-such-flag"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--no-such-flag"), std::string::npos) << r.err;
  r = test::RunCommand(RunRenderSnapshot, "orbed-render-snapshot", {"--out"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
  r = test::RunCommand(RunRenderSnapshot, "orbed-render-snapshot", {"--out", "/nonexistent/folder"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(RenderSnapshotCli, WritesBothPictures) {
  const fs::path dir = fs::temp_directory_path() / ("orbed_tools_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const test::CommandRun r =
      test::RunCommand(RunRenderSnapshot, "orbed-render-snapshot", {"--out", dir.string()});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("reflective_view.png"), std::string::npos) << r.out;
  // Real pictures, not empty files (each is > 100 kB of PNG).
  EXPECT_GT(fs::file_size(dir / "camera_frame.png"), 50000u);
  EXPECT_GT(fs::file_size(dir / "reflective_view.png"), 50000u);
  fs::remove_all(dir);
}

TEST(UserStudyCli, HelpGoesToOutAndExitsZero) {
  const test::CommandRun r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--display-at"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("=200"), std::string::npos) << r.out;  // the --trials default
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(UserStudyCli, BadArgumentsExitTwo) {
  test::CommandRun r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--no-such-flag"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--no-such-flag"), std::string::npos) << r.err;
  // --trials: a positive decimal integer that fits an int, nothing else (010 would be octal 8 and
  // 0x10 hex 16 for CLI11's own integer parser).
  for (const char* bad : {"0", "-3", "abc", "12x", "1e3", "99999999999", "0x10", "+5", ""}) {
    r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--trials", bad});
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.err.find("--trials"), std::string::npos) << bad << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--trials"});
  EXPECT_EQ(r.code, 2);
  // One WAYPOINT per --display-at.
  r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--display-at", "foot_end", "head_end"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("head_end"), std::string::npos) << r.err;
}

TEST(UserStudyCli, RunsASmallStudy) {
  test::CommandRun r =
      test::RunCommand(RunUserStudy, "orbed-user-study",
                       {"--trials", "010", "--display-at", "foot_end", "--display-at", "head_end"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("paper Table 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("of 10 pairs"), std::string::npos) << r.out;  // 010 read as decimal
  // A waypoint the walk does not have: the study fails, exit 1, the name on err.
  r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--trials", "3", "--display-at", "nowhere"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace orbed::hmd
