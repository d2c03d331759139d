// orbed-launch's core without children or a clock: the children's command lines, readiness by
// heartbeat, the group's and the respawned process's timeouts, the exits' verdicts with the
// respawn back-off worked out by hand, the stop and the summary.
#include "procs/launcher/launch_plan.h"

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "runtime/process.h"

namespace orbed::launcher {
namespace {

using Action = LaunchPlan::ExitVerdict::Action;

ProcessSpec Proc(const std::string& name) {
  ProcessSpec p;
  p.name = name;
  p.command = "orbed-" + name;
  return p;
}

// Group "core": sim (respawn) and logger (optional); group "study": scenario (exit_stops_all).
LaunchSpec Spec() {
  LaunchSpec spec;
  spec.name = "viraal";
  spec.path = "viraal.yaml";
  ProcessSpec sim = Proc("sim");
  sim.respawn = true;
  sim.args = {"--state-file", "${ORBED_LOG_DIR}/sim.state"};
  ProcessSpec logger = Proc("logger");
  logger.required = false;
  logger.ready = ReadyCheck::kNone;
  logger.env = {{"ORBED_CHAOS", ""}, {"ORBED_HOST", "mine"}};
  ProcessSpec scenario = Proc("scenario");
  scenario.exit_stops_all = true;
  scenario.args = {"--name", "conductor"};
  spec.groups = {{"core", {sim, logger}}, {"study", {scenario}}};
  return spec;
}

const auto kAlwaysRunning = [](size_t) { return true; };
const auto kPid = [](size_t i) { return static_cast<int64_t>(100 + i); };

TEST(LaunchPlan, BuildsEachChildsCommandLine) {
  LaunchPlan plan(Spec(), "or-pc");
  const auto& e = plan.entries();
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e[0].prefix, "sim      | ");  // padded to "scenario"
  ChildCommand c = plan.Command(e[0], true, "logs/run", "udpm://239.255.76.67:7667");
  EXPECT_EQ(c.argv,
            (std::vector<std::string>{"orbed-sim", "--state-file", "logs/run/sim.state", "--name", "sim"}));
  EXPECT_EQ(c.env.at("ORBED_LCM_URL"), "udpm://239.255.76.67:7667");
  EXPECT_EQ(c.env.at("ORBED_HOST"), "or-pc");
  EXPECT_EQ(c.env.at("ORBED_LOG_PREFIXED"), "1");
  // Left for the deputy to expand.
  EXPECT_EQ(plan.Command(e[0], false, "logs/run", "memq://").argv[2], "${ORBED_LOG_DIR}/sim.state");
  // `ready: none`: no --name; the spec's own ORBED_HOST kept.
  c = plan.Command(e[1], true, "logs/run", "memq://");
  EXPECT_EQ(c.argv, (std::vector<std::string>{"orbed-logger"}));
  EXPECT_EQ(c.env.at("ORBED_HOST"), "mine");
  EXPECT_EQ(c.env.at("ORBED_CHAOS"), "");
  // Its own --name: none added.
  EXPECT_EQ(plan.Command(e[2], true, "", "memq://").argv.size(), 3u);
}

TEST(LaunchPlan, RefusesWhatADeputyCannotCarry) {
  LaunchSpec spec = Spec();
  spec.groups[0].processes[0].host = "cart";
  spec.groups[0].processes[0].stop_timeout_s = 4000;
  try {
    LaunchPlan plan(spec, "or-pc");
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "process 'sim' on host 'cart': stop_timeout_s over 3600 s");
  }
  spec.groups[0].processes[0].host = "or-pc";  // this host: no deputy, no limit
  EXPECT_NO_THROW(LaunchPlan(spec, "or-pc"));
}

TEST(LaunchPlan, AGroupIsReadyWithEveryHeartbeatAndTimesOutFromItsStart) {
  LaunchPlan plan(Spec(), "or-pc");
  auto& e = plan.entries();
  plan.BeginGroup(0, 100.0);
  plan.Started(&e[0], 100.0);
  plan.Started(&e[1], 100.0);
  EXPECT_FALSE(e[0].ready);
  EXPECT_TRUE(e[1].ready);  // ready: none
  const auto heard = [](const std::string&) { return true; };
  EXPECT_FALSE(plan.CheckGroup(105.0, heard, "memq://").ready);
  // Another instance's heartbeat (pid 7) does not count; its own (pid 100) does.
  EXPECT_TRUE(plan.OnHeartbeat("sim", 7, "", kAlwaysRunning, kPid, 101.0).empty());
  const std::vector<Note> notes = plan.OnHeartbeat("sim", 100, "", kAlwaysRunning, kPid, 101.5);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].text, "sim is ready (first heartbeat after 1.5 s)");
  EXPECT_TRUE(plan.CheckGroup(105.0, heard, "memq://").ready);
  EXPECT_TRUE(plan.NextGroup());
  plan.BeginGroup(1, 106.0);
  plan.Started(&e[2], 106.0);
  EXPECT_EQ(plan.CheckGroup(116.0, heard, "memq://").failure, "");  // 10 s: not yet past
  const LaunchPlan::GroupCheck late = plan.CheckGroup(116.5, heard, "memq://");
  EXPECT_FALSE(late.ready);
  EXPECT_EQ(
      late.failure,
      "process 'scenario' sent no heartbeat on PROCESS_STATUS within 10.000000 s (if it is not an orbed "
      "process, set `ready: none` in viraal.yaml)");
}

TEST(LaunchPlan, RespawnsAtOnceThenBacksOffWhileItKeepsDyingAtStart) {
  LaunchPlan plan(Spec(), "or-pc");
  LaunchPlan::Entry& sim = plan.entries()[0];
  plan.BeginGroup(0, 0.0);
  plan.Started(&sim, 0.0);
  sim.ready = true;
  // Died after 10 s: at once (a slow death resets the count).
  LaunchPlan::ExitVerdict v = plan.OnExit(&sim, 1, 0, "exited with code 1", "", 10.0);
  EXPECT_EQ(v.action, Action::kNone);
  EXPECT_EQ(v.note.text, "sim exited with code 1; respawning");
  EXPECT_EQ(sim.fast_failures, 0);
  EXPECT_TRUE(plan.RespawnDue(sim, 10.0));
  EXPECT_EQ(sim.unready_since_s, 10.0);
  // Then dying within 1 s of each start: 0, 0.25, 0.5, 1, 2, 4, 5, 5 s.
  const double expected[] = {0, 0.25, 0.5, 1, 2, 4, 5, 5};
  double now = 10.0;
  for (double delay : expected) {
    plan.Started(&sim, now);
    v = plan.OnExit(&sim, 1, 0, "exited with code 1", "", now + 0.5);
    EXPECT_EQ(sim.respawn_at_s, now + 0.5 + delay);
    EXPECT_FALSE(plan.RespawnDue(sim, now + 0.5 + delay - 0.01) && delay > 0);
    EXPECT_TRUE(plan.RespawnDue(sim, now + 0.5 + delay));
    ++sim.restarts;
    now += 0.5 + delay;
  }
  EXPECT_EQ(v.note.text, "sim exited with code 1; respawning in 5.000000 s");
  // Not ready again 10 s after it died (at 10 s, its last readiness): the testbed fails, once its
  // group is up (the group being started has its own timeout).
  EXPECT_EQ(plan.RespawnTimeout(20.1), "");
  ASSERT_TRUE(plan.NextGroup());
  plan.BeginGroup(1, 20.0);
  EXPECT_EQ(plan.RespawnTimeout(19.9), "");
  EXPECT_EQ(
      plan.RespawnTimeout(20.1),
      "process 'sim' was respawned 8 time(s) and sent no heartbeat within 10.000000 s of dying (exited with "
      "code 1)");
  plan.BeginStop();
  EXPECT_FALSE(plan.RespawnDue(sim, 1e9));
}

TEST(LaunchPlan, ExitsDecideTheTestbed) {
  LaunchPlan plan(Spec(), "or-pc");
  auto& e = plan.entries();
  for (auto& entry : e) plan.Started(&entry, 0.0);
  // The logger cannot write (optional): not respawned, the launch goes on.
  LaunchPlan::ExitVerdict v =
      plan.OnExit(&e[1], kExitCannotWrite, 0, "exited with code 74", "disk full", 5.0);
  EXPECT_EQ(v.action, Action::kNone);
  EXPECT_EQ(v.note.text,
            "optional process 'logger' exited with code 74: it cannot write its output, not respawned (it "
            "said: disk "
            "full); continuing without it");
  EXPECT_TRUE(e[1].finished);
  // The sim, required, cannot write either: the testbed fails even though it respawns.
  v = plan.OnExit(&e[0], kExitCannotWrite, 0, "exited with code 74", "", 5.0);
  EXPECT_EQ(v.action, Action::kFail);
  EXPECT_EQ(v.note.text,
            "required process 'sim' exited with code 74: it cannot write its output, not respawned");
  // The conductor killed: the testbed stops, exit code 1.
  v = plan.OnExit(&e[2], -1, 9, "killed by SIGKILL", "", 6.0);
  EXPECT_EQ(v.action, Action::kStopAll);
  EXPECT_EQ(v.note.level, LogLevel::kError);
  EXPECT_EQ(v.note.text, "scenario killed by SIGKILL before it finished: stopping the testbed");
  EXPECT_EQ(plan.exit_code(), 1);
}

TEST(LaunchPlan, AConductorsExitCodeIsTheLaunchersAndStoppingFailsOnlyARequiredCode) {
  LaunchPlan plan(Spec(), "or-pc");
  auto& e = plan.entries();
  for (auto& entry : e) plan.Started(&entry, 0.0);
  LaunchPlan::ExitVerdict v = plan.OnExit(&e[2], 3, 0, "exited with code 3", "", 1.0);
  EXPECT_EQ(v.action, Action::kStopAll);
  EXPECT_EQ(v.note.text, "scenario exited with code 3: stopping the testbed");
  EXPECT_EQ(plan.exit_code(), 3);

  LaunchPlan stopping(Spec(), "or-pc");
  auto& s = stopping.entries();
  for (auto& entry : s) stopping.Started(&entry, 0.0);
  stopping.BeginStop();
  EXPECT_EQ(stopping.OnExit(&s[0], 1, 0, "exited with code 1", "", 1.0).action, Action::kNone);  // stopping
  EXPECT_EQ(stopping.StoppedWith(s[1], 2).text, "");                                             // optional
  EXPECT_EQ(stopping.StoppedWith(s[0], -1).text, "");  // its stop signal
  EXPECT_EQ(stopping.StoppedWith(s[0], 1).text, "required process 'sim' exited with code 1 while stopping");
  EXPECT_EQ(stopping.exit_code(), 1);
}

TEST(LaunchPlan, SummarisesEveryProcess) {
  LaunchPlan plan(Spec(), "or-pc");
  auto& e = plan.entries();
  plan.Started(&e[0], 0.0);
  e[0].restarts = 2;
  e[0].last_exit = "killed by SIGINT";
  EXPECT_EQ(plan.Summary(),
            "\norbed-launch summary (viraal):\n"
            "  process   restarts  last state\n"
            "  sim       2         killed by SIGINT\n"
            "  logger    0         not started\n"
            "  scenario  0         not started\n");
}

}  // namespace
}  // namespace orbed::launcher
