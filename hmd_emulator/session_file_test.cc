// orbed-hmd's crash recovery (session_file.h): a headset stopped after any trial and started again
// on its state file publishes the rest of the session's trials exactly as one that never stopped;
// trials of the session published by someone else move the index on; damaged state files and
// records the session machine refuses keep the headset from starting.
#include "hmd_emulator/session_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"
#include "hmd_emulator/hmd_process.h"
#include "lcmtypes/contract/conversions.h"
#include "runtime/journal.h"

namespace orbed::hmd {
namespace {

namespace fs = std::filesystem;
using SC = orbed::session_control_t;
using AT = orbed::alignment_trial_t;

std::string TempPath(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("orbed_hmd_session_file_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  fs::remove(dir / name);
  return (dir / name).string();
}

SC Control(const std::string& id, int8_t command, int32_t mirrors = 1) {
  SC m{};
  m.utime = NowMicros();
  m.session_id = id;
  m.command = command;
  m.display_mode = mirrors > 0 ? +AT::MODE_AR_REFLECTIVE : +AT::MODE_AR;
  m.num_mirrors = mirrors;
  m.method = +orbed::registration_t::METHOD_KARCHER;
  return m;
}

AT Trial(const std::string& id, int index, int32_t mirrors = 1) {
  AT t{};
  t.utime = NowMicros();
  t.session_id = id;
  t.trial_index = index;
  t.display_mode = mirrors > 0 ? +AT::MODE_AR_REFLECTIVE : +AT::MODE_AR;
  t.num_mirrors = mirrors;
  t.num_joints = 7;
  t.joint_position.assign(7, 0.2);
  t.X_WV = ToPose(Eigen::Isometry3d::Identity());
  t.duration_s = 30;
  t.user_id = "someone";
  return t;
}

HmdSession TwoDisplays() { return HmdSession({2, "IIWA_STATUS", "ROBOT_STATE", {}}); }

TEST(SessionFile, SavedSessionsRestoreWithTheirNextIndex) {
  const std::string path = TempPath("session.state");
  HmdSession fresh = TwoDisplays();
  EXPECT_FALSE(RestoreSession(path, &fresh).start);  // no file: no session
  std::string error;
  ASSERT_TRUE(SaveSession(path, SavedSession{Control("s", SC::START), Trial("s", 4)}, &error)) << error;
  HmdSession session = TwoDisplays();
  const SavedSession saved = RestoreSession(path, &session);
  ASSERT_TRUE(saved.start && saved.last_trial);
  EXPECT_EQ(session.state().id, "s");
  EXPECT_EQ(session.state().num_mirrors, 1);
  EXPECT_EQ(session.state().next_index, 5);
  ASSERT_TRUE(SaveSession(path, SavedSession{Control("s", SC::START), std::nullopt}, &error));
  HmdSession started = TwoDisplays();
  RestoreSession(path, &started);
  EXPECT_EQ(started.state().next_index, 0);
  ASSERT_TRUE(SaveSession(path, SavedSession{}, &error));  // no session: an empty file
  HmdSession none = TwoDisplays();
  RestoreSession(path, &none);
  EXPECT_FALSE(none.state().active());
}

TEST(SessionFile, ObservedTrialsOfTheSessionMoveTheIndexOn) {
  HmdSession session = TwoDisplays();
  session.Handle(Control("s", SC::START), RobotKnown{});
  EXPECT_TRUE(session.ObserveTrial(Trial("s", 0)));
  EXPECT_TRUE(session.ObserveTrial(Trial("s", 1)));
  EXPECT_EQ(session.state().next_index, 2);
  EXPECT_FALSE(session.ObserveTrial(Trial("s", 1)));           // already past it
  EXPECT_FALSE(session.ObserveTrial(Trial("other", 5)));       // another session
  EXPECT_FALSE(session.ObserveTrial(Trial("s", 5, 0)));        // another mode
  EXPECT_FALSE(session.ObserveTrial(Trial("s", 5, 2)));        // other mirrors
  EXPECT_FALSE(session.ObserveTrial(Trial("s", 2147483647)));  // no index after it
  EXPECT_EQ(session.state().next_index, 2);
  EXPECT_EQ(session.TakeTrialIndex(), 2);
}

std::string RefusalOf(const std::string& path) {
  HmdSession session = TwoDisplays();
  try {
    RestoreSession(path, &session);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(SessionFile, DamagedOrRefusedStatesAreRefusedNamingTheProblem) {
  const std::string path = TempPath("bad.state");
  std::string error;
  ASSERT_TRUE(SaveSession(path, SavedSession{Control("s", SC::START), Trial("s", 1)}, &error));
  fs::resize_file(path, fs::file_size(path) - 1);
  EXPECT_NE(RefusalOf(path).find("cut short"), std::string::npos) << RefusalOf(path);
  const auto write = [&](const std::vector<JournalRecord>& records) {
    ASSERT_TRUE(WriteJournalFile(path, records, &error)) << error;
  };
  write({MakeJournalRecord("SESSION_CONTROL", Control("s", SC::STOP))});
  EXPECT_NE(RefusalOf(path).find("not a START"), std::string::npos) << RefusalOf(path);
  write({MakeJournalRecord("SESSION_CONTROL", Control("s", SC::START, 3))});  // 2 displays placed
  EXPECT_NE(RefusalOf(path).find("START refused"), std::string::npos) << RefusalOf(path);
  write({MakeJournalRecord("SESSION_CONTROL", Control("s", SC::START)),
         MakeJournalRecord("ALIGNMENT_TRIAL", Trial("t", 1))});
  EXPECT_NE(RefusalOf(path).find("is not one of session 's'"), std::string::npos) << RefusalOf(path);
  AT nan_trial = Trial("s", 1);
  nan_trial.duration_s = std::nan("");
  write({MakeJournalRecord("SESSION_CONTROL", Control("s", SC::START)),
         MakeJournalRecord("ALIGNMENT_TRIAL", nan_trial)});
  EXPECT_NE(RefusalOf(path).find("ALIGNMENT_TRIAL: "), std::string::npos) << RefusalOf(path);
  write({MakeJournalRecord("ALIGNMENT_TRIAL", Trial("s", 1))});
  EXPECT_NE(RefusalOf(path).find("expected a SESSION_CONTROL record"), std::string::npos) << RefusalOf(path);
  write({JournalRecord{"SESSION_CONTROL", {0, 1}}});
  EXPECT_NE(RefusalOf(path).find("state file " + path), std::string::npos) << RefusalOf(path);
}

// The process on memq://, images inline: the robot known, a session, trials on request.
struct Headset {
  std::vector<AT> trials;
  std::unique_ptr<HmdProcess> hmd;
  void OnTrial(const lcm::ReceiveBuffer*, const std::string&, const AT* m) { trials.push_back(*m); }

  explicit Headset(const std::string& state_file) {
    CommonFlags flags("orbed-hmd");
    flags.lcm_url = "memq://";
    flags.log_level = "warn";
    HmdOptions options;
    options.threaded = false;
    options.state_file = state_file;
    hmd = std::make_unique<HmdProcess>(flags, options);
    lcm().subscribe("ALIGNMENT_TRIAL", &Headset::OnTrial, this);
    orbed::iiwa_status_t status{};
    status.utime = NowMicros();
    status.num_joints = 7;
    status.joint_position_measured = {0, 30 * kDegToRad, 0, -60 * kDegToRad, 0, 45 * kDegToRad, 0};
    for (auto* v :
         {&status.joint_velocity_estimated, &status.joint_position_commanded, &status.joint_position_ipo,
          &status.joint_torque_measured, &status.joint_torque_commanded, &status.joint_torque_external}) {
      v->assign(7, 0.0);
    }
    lcm().publish("IIWA_STATUS", &status);
    orbed::robot_state_t state{};
    state.utime = NowMicros();
    state.robot_name = "iiwa7";
    state.X_WR = ToPose(sim::LoadSceneFile(HmdSourcePath(sim::kDefaultSceneRelativePath)).X_WR);
    state.X_RF = ToPose(Eigen::Isometry3d::Identity());
    state.X_RT = state.X_RF;
    lcm().publish("ROBOT_STATE", &state);
    Drain();
  }
  lcm::LCM& lcm() { return hmd->process().lcm(); }
  void Drain() {
    while (lcm().handleTimeout(0) > 0) {
    }
  }
  void Send(const SC& msg) {
    lcm().publish("SESSION_CONTROL", &msg);
    Drain();
  }
};

// X_WV and duration of a trial: what the emulated user chose, the part a restart must not change.
void ExpectSameTrial(const AT& got, const AT& expected) {
  EXPECT_EQ(got.session_id, expected.session_id);
  EXPECT_EQ(got.trial_index, expected.trial_index);
  EXPECT_EQ(got.duration_s, expected.duration_s);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(got.X_WV.position_m[i], expected.X_WV.position_m[i]);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(got.X_WV.quaternion_wxyz[i], expected.X_WV.quaternion_wxyz[i]);
}

TEST(SessionFile, ARespawnedHeadsetContinuesTheSessionWithTheSameTrials) {
  std::vector<AT> expected;
  {
    Headset uninterrupted("");
    uninterrupted.Send(Control("run-ar_reflective", SC::START));
    for (int i = 0; i < 3; ++i) uninterrupted.Send(Control("run-ar_reflective", SC::REQUEST_TRIAL));
    expected = uninterrupted.trials;
  }
  ASSERT_EQ(expected.size(), 3u);
  const std::string path = TempPath("respawn.state");
  std::vector<AT> got;
  {
    Headset before(path);
    before.Send(Control("run-ar_reflective", SC::START));
    before.Send(Control("run-ar_reflective", SC::REQUEST_TRIAL));
    got = before.trials;
  }  // killed after trial 0
  Headset after(path);
  EXPECT_EQ(after.hmd->active_session(), "run-ar_reflective");
  after.Send(Control("run-ar_reflective", SC::REQUEST_TRIAL));
  after.Send(Control("run-ar_reflective", SC::REQUEST_TRIAL));
  got.insert(got.end(), after.trials.begin(), after.trials.end());
  ASSERT_EQ(got.size(), 3u);
  for (size_t i = 0; i < 3; ++i) ExpectSameTrial(got[i], expected[i]);

  // STOP: the file says no session, and a headset started on it has none.
  after.Send(Control("run-ar_reflective", SC::STOP));
  Headset stopped(path);
  EXPECT_EQ(stopped.hmd->active_session(), "");
}

TEST(SessionFile, TrialsPublishedByOthersAreSkippedOver) {
  // A resumed conductor re-sends the two trials it kept; the headset's next trial is trial 2.
  std::vector<AT> expected;
  {
    Headset uninterrupted("");
    uninterrupted.Send(Control("run-ar", SC::START, 0));
    for (int i = 0; i < 3; ++i) uninterrupted.Send(Control("run-ar", SC::REQUEST_TRIAL, 0));
    expected = uninterrupted.trials;
  }
  const std::string path = TempPath("observed.state");
  Headset fresh(path);
  fresh.Send(Control("run-ar", SC::START, 0));
  fresh.lcm().publish("ALIGNMENT_TRIAL", &expected[0]);
  fresh.lcm().publish("ALIGNMENT_TRIAL", &expected[1]);
  fresh.Drain();
  fresh.trials.clear();  // what it heard
  fresh.Send(Control("run-ar", SC::REQUEST_TRIAL, 0));
  ASSERT_EQ(fresh.trials.size(), 1u);
  ExpectSameTrial(fresh.trials[0], expected[2]);
  EXPECT_EQ(fresh.hmd->process().rejections().total(), 0);
  HmdSession restored = TwoDisplays();
  EXPECT_EQ(RestoreSession(path, &restored).last_trial->trial_index, 2);
}

}  // namespace
}  // namespace orbed::hmd
