#pragma once
/// @file
/// Test helper shared by the command-line tools' tests (not part of any library): runs a tool's
/// `int Run...(int argc, const char* const* argv, std::ostream& out, std::ostream& err)` in-process
/// on an argument list and keeps its exit code and both streams.
///   const test::CommandRun r = test::RunCommand(RunMonitor, "orbed-monitor", {"--help"});
///   EXPECT_EQ(r.code, 0);

#include <sstream>
#include <string>
#include <vector>

namespace orbed::test {

struct CommandRun {
  int code = 0;
  std::string out;
  std::string err;
};

/// Calls `run` with argv = {program, args...}.
template <typename RunFunction>
CommandRun RunCommand(RunFunction run, const std::string& program, const std::vector<std::string>& args) {
  std::vector<const char*> argv{program.c_str()};
  for (const std::string& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  CommandRun r;
  r.code = run(static_cast<int>(argv.size()), argv.data(), out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

}  // namespace orbed::test
