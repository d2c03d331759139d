// The deputy's side of launch across hosts (deputy.h) with real child processes and commands
// handed in directly (LCM in memory), and the protocol's message checks (deputy_protocol.h).
#include "procs/launcher/deputy.h"

#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include <gtest/gtest.h>
#include <CLI/CLI.hpp>

#include "procs/launcher/deputy_protocol.h"

namespace orbed::launcher {
namespace {

// The child states, as values (LCM's constants are declared, not defined).
constexpr int8_t kRunning = orbed::deputy_child_t::STATE_RUNNING;
constexpr int8_t kExited = orbed::deputy_child_t::STATE_EXITED;
constexpr int8_t kFailedToStart = orbed::deputy_child_t::STATE_FAILED_TO_START;

orbed::deputy_process_t Wanted(const std::string& name, int instance, bool run, const std::string& script) {
  orbed::deputy_process_t p{};
  p.name = name;
  p.instance = instance;
  p.run = run;
  p.argv = {"/bin/sh", "-c", script};
  p.argc = 3;
  p.stop_signal = SIGTERM;
  p.stop_timeout_s = 5;
  return p;
}

// A command of launcher "bed@hostA/<n>", which started at n us.
orbed::deputy_command_t Command(const std::string& launcher, const std::string& deputy,
                                std::vector<orbed::deputy_process_t> processes) {
  orbed::deputy_command_t c{};
  c.utime = 1;
  c.launcher = launcher;
  c.launcher_start_utime = std::stoll(launcher.substr(launcher.rfind('/') + 1));
  c.deputy = deputy;
  c.processes = std::move(processes);
  c.num_processes = static_cast<int32_t>(c.processes.size());
  return c;
}

class DeputyTest : public ::testing::Test {
 protected:
  DeputyTest() : flags_("deputy-hostB") { flags_.lcm_url = "memq://"; }
  Deputy& MakeDeputy(double orphan_timeout_s = 30) {
    DeputyOptions options;
    options.name = "hostB";
    options.orphan_timeout_s = orphan_timeout_s;
    deputy_ = std::make_unique<Deputy>(flags_, options);
    return *deputy_;
  }
  // The child `name` as the deputy reports it (instance 0 when it reports none).
  orbed::deputy_child_t Child(const std::string& name) const {
    for (const auto& c : deputy_->Status().children) {
      if (c.name == name) return c;
    }
    return orbed::deputy_child_t{};
  }
  // Ticks (polling the children every 5 ms) until `done` or 20 s.
  bool TickUntil(const std::function<bool()>& done) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < end) {
      deputy_->Tick();
      if (done()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }
  CommonFlags flags_;
  std::unique_ptr<Deputy> deputy_;
};

TEST_F(DeputyTest, StartsEachInstanceOnceAndReportsItsExit) {
  Deputy& deputy = MakeDeputy();
  // The child sees the deputy's host name and LCM URL: it exits 3 only if both are right.
  const std::string script =
      "test \"$ORBED_HOST\" = hostB && test \"$ORBED_LCM_URL\" = memq:// && exit 3; exit 9";
  deputy.OnCommand(Command("bed@hostA/1", "hostB", {Wanted("tool", 1, true, script)}));
  ASSERT_TRUE(TickUntil([&] { return Child("tool").state == kExited; }));
  EXPECT_EQ(Child("tool").instance, 1);
  EXPECT_EQ(Child("tool").exit_code, 3);
  EXPECT_EQ(Child("tool").detail, "exited with code 3");
  const int first_pid = Child("tool").pid;
  EXPECT_GT(first_pid, 0);
  EXPECT_EQ(deputy.Status().launcher, "bed@hostA/1");
  // The same instance again (a re-sent command) starts nothing.
  deputy.OnCommand(Command("bed@hostA/1", "hostB", {Wanted("tool", 1, true, script)}));
  deputy.Tick();
  EXPECT_EQ(Child("tool").pid, first_pid);
  EXPECT_EQ(Child("tool").state, kExited);
  // The next instance (a respawn) starts it again.
  deputy.OnCommand(Command("bed@hostA/1", "hostB", {Wanted("tool", 2, true, script)}));
  ASSERT_TRUE(TickUntil([&] { return Child("tool").instance == 2 && Child("tool").state == kExited; }));
  EXPECT_NE(Child("tool").pid, first_pid);
  EXPECT_EQ(Child("tool").exit_code, 3);
}

// The run's folder is made on the deputy's own disk (under its log root, by the name the command
// gives) and ${ORBED_LOG_DIR} in argv and env values is that folder; an exited child's report
// carries its last lines, at most kMaxLastLines, each cut to kMaxLastLineBytes.
TEST_F(DeputyTest, MakesTheRunFolderOnItsOwnDiskAndReportsTheLastLines) {
  const std::string root = ::testing::TempDir() + "deputy_log_root_" + std::to_string(getpid());
  DeputyOptions options;
  options.name = "hostB";
  options.log_root = root;
  deputy_ = std::make_unique<Deputy>(flags_, options);
  // Writes its state where ${ORBED_LOG_DIR} says, prints 8 lines (the last one long) and fails.
  orbed::deputy_process_t wanted = Wanted(
      "tool", 1, true,
      "echo kept > \"$1/tool.state\" && test \"$ORBED_LOG_DIR\" = \"$1\" && test \"$WHERE\" = \"$1/x\" && "
      "for i in 1 2 3 4 5 6 7; do echo line $i; done && printf '%0600d\\n' 0 && exit 4; exit 9");
  wanted.argv.push_back("sh");
  wanted.argv.push_back("${ORBED_LOG_DIR}");
  wanted.argc = static_cast<int32_t>(wanted.argv.size());
  wanted.env_key = {"WHERE"};
  wanted.env_value = {"${ORBED_LOG_DIR}/x"};
  wanted.num_env = 1;
  orbed::deputy_command_t command = Command("bed@hostA/1", "hostB", {wanted});
  command.run_dir = "run1";
  deputy_->OnCommand(command);
  ASSERT_TRUE(TickUntil([&] { return Child("tool").state == kExited; }));
  EXPECT_EQ(Child("tool").exit_code, 4);
  std::ifstream state(root + "/run1/tool.state");
  std::string kept;
  EXPECT_TRUE(std::getline(state, kept));
  EXPECT_EQ(kept, "kept");
  const orbed::deputy_child_t child = Child("tool");
  ASSERT_EQ(child.num_last_lines, static_cast<int32_t>(kMaxLastLines));
  ASSERT_EQ(child.last_lines.size(), kMaxLastLines);
  EXPECT_EQ(child.last_lines[0], "line 4");
  EXPECT_EQ(child.last_lines[3], "line 7");
  EXPECT_EQ(child.last_lines[4], std::string(kMaxLastLineBytes, '0'));
  EXPECT_EQ(CheckDeputyStatus(deputy_->Status()), "");
  std::filesystem::remove_all(root);
}

TEST_F(DeputyTest, StopsOnRunFalseOnAnotherLauncherAndWhenItsLauncherFallsSilent) {
  Deputy& deputy = MakeDeputy(/*orphan_timeout_s=*/0.5);
  // run: false → its stop signal.
  deputy.OnCommand(Command("bed@hostA/1", "hostB", {Wanted("a", 1, true, "exec sleep 30")}));
  deputy.Tick();
  EXPECT_EQ(Child("a").state, kRunning);
  deputy.OnCommand(Command("bed@hostA/1", "hostB", {Wanted("a", 1, false, "exec sleep 30")}));
  ASSERT_TRUE(TickUntil([&] { return Child("a").state == kExited; }));
  EXPECT_EQ(Child("a").term_signal, SIGTERM);
  // Another launcher: the first one's processes are stopped, the new one's started.
  deputy.OnCommand(Command("bed@hostA/1", "hostB", {Wanted("b", 1, true, "exec sleep 30")}));
  deputy.Tick();
  ASSERT_EQ(Child("b").state, kRunning);
  deputy.OnCommand(Command("bed@hostA/2", "hostB", {Wanted("c", 1, true, "exec sleep 30")}));
  EXPECT_EQ(Child("b").instance, 0);  // no longer reported
  EXPECT_EQ(deputy.Status().launcher, "bed@hostA/2");
  ASSERT_TRUE(TickUntil([&] { return Child("c").state == kRunning; }));
  // The earlier launcher's late command changes nothing (no taking turns).
  deputy.OnCommand(Command("bed@hostA/1", "hostB", {Wanted("d", 1, true, "exec sleep 30")}));
  EXPECT_EQ(deputy.Status().launcher, "bed@hostA/2");
  EXPECT_EQ(Child("d").instance, 0);
  // Silent launcher: after 0.5 s without a command, what it started is stopped and it is
  // forgotten; its late datagrams do not bring it back.
  ASSERT_TRUE(TickUntil([&] { return !deputy.AnyRunning(); }));
  EXPECT_EQ(deputy.Status().launcher, "");
  EXPECT_EQ(deputy.Status().num_children, 0);
  deputy.OnCommand(Command("bed@hostA/2", "hostB", {Wanted("c", 1, true, "exec sleep 30")}));
  EXPECT_EQ(deputy.Status().launcher, "");
  EXPECT_FALSE(deputy.AnyRunning());
}

TEST_F(DeputyTest, AGoodbyeStopsEverythingAndAStopBeforeTheStartIsReported) {
  Deputy& deputy = MakeDeputy();
  // The start of "late" was lost; its stop arrives first: reported as exited, never started.
  deputy.OnCommand(
      Command("bed@hostA/1", "hostB",
              {Wanted("a", 1, true, "exec sleep 30"), Wanted("late", 1, false, "exec sleep 30")}));
  EXPECT_EQ(Child("late").state, kExited);
  EXPECT_EQ(Child("late").pid, 0);
  EXPECT_EQ(Child("late").detail, "stopped before it started");
  deputy.OnCommand(
      Command("bed@hostA/1", "hostB",
              {Wanted("a", 1, true, "exec sleep 30"), Wanted("late", 1, true, "exec sleep 30")}));
  EXPECT_EQ(Child("late").state, kExited);  // that instance is over; only a next one would start
  ASSERT_EQ(Child("a").state, kRunning);
  // The launcher's goodbye (no processes): "a" is stopped, the deputy follows nobody, and the next
  // launcher is followed at once.
  deputy.OnCommand(Command("bed@hostA/1", "hostB", {}));
  EXPECT_EQ(deputy.Status().launcher, "");
  ASSERT_TRUE(TickUntil([&] { return !deputy.AnyRunning(); }));
  deputy.OnCommand(Command("bed@hostA/3", "hostB", {Wanted("a", 1, true, "exec sleep 30")}));
  EXPECT_EQ(deputy.Status().launcher, "bed@hostA/3");
  EXPECT_EQ(Child("a").state, kRunning);
}

TEST_F(DeputyTest, IgnoresOtherDeputiesCommandsAndCountsMalformedOnes) {
  Deputy& deputy = MakeDeputy();
  deputy.OnCommand(Command("bed@hostA/1", "hostC", {Wanted("x", 1, true, "exit 0")}));
  EXPECT_EQ(deputy.Status().num_children, 0);
  EXPECT_EQ(deputy.Status().launcher, "");
  auto bad = Command("bed@hostA/1", "hostB", {Wanted("x", 1, true, "exit 0")});
  bad.processes[0].argc = 2;  // not the array's length
  deputy.OnCommand(bad);
  EXPECT_EQ(deputy.Status().num_children, 0);
  EXPECT_EQ(deputy.process().rejections().counts().at("DEPUTY_COMMAND/invalid"), 1);
  // A command that cannot be found is reported, not retried.
  auto missing = Command("bed@hostA/1", "hostB", {Wanted("y", 1, true, "")});
  missing.processes[0].argv = {"no-such-orbed-command"};
  missing.processes[0].argc = 1;
  deputy.OnCommand(missing);
  EXPECT_EQ(Child("y").state, kFailedToStart);
  EXPECT_NE(Child("y").detail.find("cannot find executable 'no-such-orbed-command'"), std::string::npos);
}

TEST(DeputyProtocol, ChecksEveryField) {
  const auto good = Command("bed@hostA/1", "hostB", {Wanted("x", 1, true, "exit 0")});
  EXPECT_EQ(CheckDeputyCommand(good), "");
  auto broken = [&](const std::function<void(orbed::deputy_command_t*)>& edit) {
    orbed::deputy_command_t c = good;
    edit(&c);
    return CheckDeputyCommand(c);
  };
  EXPECT_NE(broken([](auto* c) { c->launcher = ""; }), "");
  EXPECT_NE(broken([](auto* c) { c->launcher_start_utime = 0; }), "");
  EXPECT_NE(broken([](auto* c) { c->deputy = std::string(kMaxDeputyName + 1, 'd'); }), "");
  EXPECT_NE(broken([](auto* c) { c->num_processes = 2; }), "");
  EXPECT_NE(broken([](auto* c) { c->processes.push_back(c->processes[0]), c->num_processes = 2; }), "");
  EXPECT_NE(broken([](auto* c) { c->processes[0].name = "a/b"; }), "");
  EXPECT_NE(broken([](auto* c) { c->processes[0].instance = 0; }), "");
  EXPECT_NE(broken([](auto* c) { c->processes[0].argv[0] = ""; }), "");
  EXPECT_NE(broken([](auto* c) { c->processes[0].argv[2] = std::string(kMaxArgBytes + 1, 'a'); }), "");
  EXPECT_NE(broken([](auto* c) { c->processes[0].num_env = 1; }), "");
  EXPECT_NE(broken([](auto* c) {
              c->processes[0].env_key = {"A=B"}, c->processes[0].env_value = {"1"},
              c->processes[0].num_env = 1;
            }),
            "");
  EXPECT_NE(broken([](auto* c) { c->processes[0].stop_signal = 11; }), "");  // SIGSEGV is no stop signal
  EXPECT_NE(broken([](auto* c) { c->processes[0].stop_timeout_s = std::nan(""); }), "");
  EXPECT_NE(broken([](auto* c) { c->processes[0].stop_timeout_s = -1; }), "");
  EXPECT_EQ(broken([](auto* c) { c->run_dir = "20261204T182632Z-a1b2c3"; }), "");
  EXPECT_NE(broken([](auto* c) { c->run_dir = "../up"; }), "");
  EXPECT_NE(broken([](auto* c) { c->run_dir = ".."; }), "");
  EXPECT_NE(broken([](auto* c) { c->run_dir = std::string(kMaxDeputyName + 1, 'r'); }), "");

  orbed::deputy_status_t status{};
  status.deputy = "hostB";
  orbed::deputy_child_t child{};
  child.name = "x";
  child.instance = 1;
  status.children = {child};
  status.num_children = 1;
  EXPECT_EQ(CheckDeputyStatus(status), "");
  status.children[0].state = 4;
  EXPECT_NE(CheckDeputyStatus(status), "");
  status.children[0].state = 0;
  status.children[0].instance = 0;
  EXPECT_NE(CheckDeputyStatus(status), "");
  status.children[0].instance = 1;
  status.children[0].last_lines = {"error: something"};
  EXPECT_NE(CheckDeputyStatus(status), "");  // num_last_lines says 0
  status.children[0].num_last_lines = 1;
  EXPECT_EQ(CheckDeputyStatus(status), "");
  status.children[0].last_lines = {std::string(kMaxLastLineBytes + 1, 'e')};
  EXPECT_NE(CheckDeputyStatus(status), "");
  status.children[0].last_lines = std::vector<std::string>(kMaxLastLines + 1, "e");
  status.children[0].num_last_lines = kMaxLastLines + 1;
  EXPECT_NE(CheckDeputyStatus(status), "");
  status.children[0].last_lines = {};
  status.children[0].num_last_lines = 0;
  status.num_children = 3;
  EXPECT_NE(CheckDeputyStatus(status), "");
}

}  // namespace
}  // namespace orbed::launcher
