// Tests of the orbed-robot command line, run in-process.
#include "sim/robot_tool.h"

#include "base/source_paths.h"
#include "base/test_command.h"

#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace orbed::sim {
namespace {

using ToolRun = test::CommandRun;

ToolRun Tool(const std::vector<std::string>& args) {
  return test::RunCommand(RunRobotTool, "orbed-robot", args);
}

std::string Scene() { return orbed::SourceTreePath("sim/models/scenes/trocar_or.yaml"); }

int Lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

TEST(RobotToolTest, FkPrintsTheFlangeAtTheZeroPose) {
  const ToolRun r = Tool({"fk", "--q-deg", "0,0,0,0,0,0,0"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("{\"frame\":\"R\"", 0), 0u) << r.out;
  // Read back by nlohmann's parser: the flange at the data sheet's 0.34 + 0.4 + 0.4 + 0.126 m.
  const nlohmann::json fk = nlohmann::json::parse(r.out);
  EXPECT_EQ(fk["flange"]["position_m"], nlohmann::json::parse("[0, 0, 1.266]")) << r.out;
  EXPECT_EQ(fk["flange"]["rotation"], nlohmann::json::parse("[[1, 0, 0], [0, 1, 0], [0, 0, 1]]")) << r.out;
  EXPECT_NE(r.out.find("\"links\":{\"iiwa_link_0\""), std::string::npos);
}

TEST(RobotToolTest, CheckAndIkOnTheScene) {
  ToolRun r = Tool({"check", "--q-deg", "0,0,0,0,0,0,0", "--scene", Scene()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"in_collision\":false"), std::string::npos) << r.out;
  r = Tool({"check", "--q-deg=0,120,0,-120,0,0,0"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"in_collision\":true"), std::string::npos) << r.out;
  r = Tool({"ik", "--scene", Scene()});
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("\"success\":true"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"q_deg\":["), std::string::npos) << r.out;
}

TEST(RobotToolTest, BadArgumentsGiveOneLineAndExitTwo) {
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"fk", "--q-deg", "1,2,3"},
           {"fk", "--q-deg", "0,0,0,0,0,0,abc"},
           {"fk", "--q-deg", "0,121,0,0,0,0,0"},
           {"fk", "--q-deg", "0,nan,0,0,0,0,0"},
           {"fk"},
           {"check", "--q-deg", "0,0,0,0,0,0,0", "--scene", "/nonexistent.yaml"},
           {"ik"},
           {"fk", "--q-deg", "0,0,0,0,0,0,0", "--urdf", "/nonexistent.urdf"},
           {"frobnicate"}}) {
    const ToolRun r = Tool(args);
    EXPECT_EQ(r.code, 2) << args[0];
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

}  // namespace
}  // namespace orbed::sim
