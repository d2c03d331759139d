// orbed-render-snapshot, run in-process: help on `out`, bad arguments exit 2
// with the flag named on `err`, and a real run of each (small, fast).
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/test_command.h"
#include "hmd_emulator/render_snapshot.h"

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

}  // namespace
}  // namespace orbed::hmd
