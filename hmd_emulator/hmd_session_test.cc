// The headset's session state machine on its own: every command path, the refusals with their keys
// (the common validator's and the headset's own), repeated START as a no-op, commands for a
// session that is not the active one, and repeated request ids answered with their first answer.
#include "hmd_emulator/hmd_session.h"

#include <string>

#include <gtest/gtest.h>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/registration_t.hpp>

#include "lcmtypes/contract/alignment_trial.h"

namespace orbed::hmd {
namespace {

using SC = orbed::session_control_t;
using AT = orbed::alignment_trial_t;
using Kind = SessionDecision::Kind;

constexpr RobotKnown kRobot{true, true};
constexpr RobotKnown kNoRobot{false, false};

orbed::session_control_t Control(const std::string& id, int8_t command, int8_t mode = +AT::MODE_AR,
                                 int32_t mirrors = 0,
                                 int8_t method = +orbed::registration_t::METHOD_KARCHER) {
  orbed::session_control_t m{};
  m.utime = 1000;
  m.session_id = id;
  m.command = command;
  m.display_mode = mode;
  m.num_mirrors = mirrors;
  m.method = method;
  return m;
}

HmdSession TwoDisplays() { return HmdSession({2, "IIWA_STATUS", "ROBOT_STATE", {}}); }

TEST(HmdSession, StartOpensTheSessionAtIndexZero) {
  HmdSession session = TwoDisplays();
  EXPECT_FALSE(session.state().active());
  const SessionDecision d = session.Handle(Control("s", +SC::START, +AT::MODE_AR_REFLECTIVE, 2), kNoRobot);
  EXPECT_EQ(d.kind, Kind::kStart);
  EXPECT_EQ(d.event, "session 's' started (ar_reflective, 2 display(s))");
  EXPECT_TRUE(session.state().active());
  EXPECT_EQ(session.state().id, "s");
  EXPECT_EQ(session.state().display_mode, +AT::MODE_AR_REFLECTIVE);
  EXPECT_EQ(session.state().num_mirrors, 2);
  EXPECT_EQ(session.state().method, +orbed::registration_t::METHOD_KARCHER);
  EXPECT_EQ(session.state().next_index, 0);
  EXPECT_EQ(session.state().Describe(), "session 's' (ar_reflective, 2 display(s))");
}

TEST(HmdSession, RepeatedStartIsANoOpAndAnotherStartReplaces) {
  HmdSession session = TwoDisplays();
  session.Handle(Control("s", +SC::START, +AT::MODE_AR_REFLECTIVE, 1), kRobot);
  EXPECT_EQ(session.TakeTrialIndex(), 0);
  EXPECT_EQ(session.TakeTrialIndex(), 1);
  // The same session, mode and mirrors: nothing changes, the index keeps counting.
  EXPECT_EQ(session.Handle(Control("s", +SC::START, +AT::MODE_AR_REFLECTIVE, 1), kRobot).kind,
            Kind::kRepeatedStart);
  EXPECT_EQ(session.state().next_index, 2);
  // The same id with other mirrors is a new session.
  EXPECT_EQ(session.Handle(Control("s", +SC::START, +AT::MODE_AR_REFLECTIVE, 2), kRobot).kind, Kind::kStart);
  EXPECT_EQ(session.state().num_mirrors, 2);
  EXPECT_EQ(session.state().next_index, 0);
  // Another id replaces the active session.
  EXPECT_EQ(session.Handle(Control("t", +SC::START), kRobot).kind, Kind::kStart);
  EXPECT_EQ(session.state().id, "t");
  EXPECT_EQ(session.state().display_mode, +AT::MODE_AR);
}

TEST(HmdSession, LocalSessionIsRepeatedByItsEchoedStart) {
  HmdSession session = TwoDisplays();
  session.Open(
      {"interactive-1", +AT::MODE_AR_REFLECTIVE, 1, +orbed::registration_t::METHOD_KARCHER, 0, 0, {}});
  session.TakeTrialIndex();
  EXPECT_EQ(session.Handle(Control("interactive-1", +SC::START, +AT::MODE_AR_REFLECTIVE, 1), kRobot).kind,
            Kind::kRepeatedStart);
  EXPECT_EQ(session.state().next_index, 1);
}

TEST(HmdSession, ResetStopComputeAndRequestTrial) {
  HmdSession session = TwoDisplays();
  session.Handle(Control("s", +SC::START), kRobot);
  EXPECT_EQ(session.Handle(Control("s", +SC::REQUEST_TRIAL), kRobot).kind, Kind::kRequestedTrial);
  EXPECT_EQ(session.state().next_index, 0);  // the caller takes it when it publishes
  session.TakeTrialIndex();
  session.TakeTrialIndex();
  EXPECT_EQ(session.Handle(Control("s", +SC::RESET), kNoRobot).kind, Kind::kReset);
  EXPECT_EQ(session.state().next_index, 0);
  EXPECT_EQ(session.state().id, "s");
  // COMPUTE is the registration server's, whatever session it names.
  EXPECT_EQ(session.Handle(Control("other", +SC::COMPUTE), kNoRobot).kind, Kind::kIgnore);
  EXPECT_EQ(session.Handle(Control("s", +SC::COMPUTE), kNoRobot).kind, Kind::kIgnore);
  session.TakeTrialIndex();
  const SessionDecision stop = session.Handle(Control("s", +SC::STOP), kNoRobot);
  EXPECT_EQ(stop.kind, Kind::kStop);
  EXPECT_EQ(stop.event, "session 's' stopped after 1 trial(s)");
  EXPECT_FALSE(session.state().active());
  EXPECT_EQ(session.state().next_index, 0);
}

TEST(HmdSession, CommandsForAnUnknownSessionAreRefused) {
  HmdSession session = TwoDisplays();
  // No session at all.
  for (int8_t command : {+SC::RESET, +SC::STOP, +SC::REQUEST_TRIAL}) {
    const SessionDecision d = session.Handle(Control("s", command), kRobot);
    EXPECT_EQ(d.kind, Kind::kRefuse) << int(command);
    EXPECT_EQ(d.refusal.key, "unknown_session");
    EXPECT_NE(d.refusal.reason.find("'(none)'"), std::string::npos) << d.refusal.reason;
  }
  // Another session is active: refused, and it stays active with its index.
  session.Handle(Control("active", +SC::START), kRobot);
  session.TakeTrialIndex();
  for (int8_t command : {+SC::RESET, +SC::STOP, +SC::REQUEST_TRIAL}) {
    const SessionDecision d = session.Handle(Control("other", command), kRobot);
    EXPECT_EQ(d.kind, Kind::kRefuse);
    EXPECT_EQ(d.refusal.key, "unknown_session");
    EXPECT_NE(d.refusal.reason.find("'other'"), std::string::npos) << d.refusal.reason;
    EXPECT_NE(d.refusal.reason.find("'active'"), std::string::npos) << d.refusal.reason;
  }
  EXPECT_NE(
      session.Handle(Control("other", +SC::REQUEST_TRIAL), kRobot).refusal.reason.find("send START first"),
      std::string::npos);
  EXPECT_EQ(session.state().id, "active");
  EXPECT_EQ(session.state().next_index, 1);
  // An unknown session is refused as such even before the robot is known.
  EXPECT_EQ(session.Handle(Control("other", +SC::REQUEST_TRIAL), kNoRobot).refusal.key, "unknown_session");
}

// A session holds kMaxTrialsPerSession trials (each replays the session's earlier walks): a trial
// published elsewhere cannot move the index beyond that, and the last request after it is refused.
TEST(HmdSession, ASessionHoldsAThousandTrials) {
  HmdSession session = TwoDisplays();
  session.Handle(Control("s", +SC::START), kRobot);
  AT trial{};
  trial.session_id = "s";
  trial.display_mode = +AT::MODE_AR;
  trial.trial_index = kMaxTrialsPerSession;
  EXPECT_FALSE(session.ObserveTrial(trial));
  EXPECT_EQ(session.state().next_index, 0);
  trial.trial_index = kMaxTrialsPerSession - 2;
  EXPECT_TRUE(session.ObserveTrial(trial));
  EXPECT_EQ(session.Handle(Control("s", +SC::REQUEST_TRIAL), kRobot).kind, Kind::kRequestedTrial);
  EXPECT_EQ(session.TakeTrialIndex(), kMaxTrialsPerSession - 1);
  trial.trial_index = kMaxTrialsPerSession - 1;
  session.RecordTrial(trial);
  const SessionDecision full = session.Handle(Control("s", +SC::REQUEST_TRIAL), kRobot);
  EXPECT_EQ(full.kind, Kind::kRefuse);
  EXPECT_EQ(full.refusal.key, "session_full");
}

TEST(HmdSession, RequestTrialNeedsTheRobot) {
  HmdSession session = TwoDisplays();
  session.Handle(Control("s", +SC::START), kNoRobot);
  const SessionDecision neither = session.Handle(Control("s", +SC::REQUEST_TRIAL), kNoRobot);
  EXPECT_EQ(neither.kind, Kind::kRefuse);
  EXPECT_EQ(neither.refusal.key, "no_robot_state");
  EXPECT_NE(neither.refusal.reason.find("IIWA_STATUS and ROBOT_STATE"), std::string::npos);
  const SessionDecision no_q = session.Handle(Control("s", +SC::REQUEST_TRIAL), RobotKnown{false, true});
  EXPECT_EQ(no_q.refusal.key, "no_robot_state");
  EXPECT_NE(no_q.refusal.reason.find("valid IIWA_STATUS:"), std::string::npos) << no_q.refusal.reason;
  const SessionDecision no_pose = session.Handle(Control("s", +SC::REQUEST_TRIAL), RobotKnown{true, false});
  EXPECT_EQ(no_pose.refusal.key, "no_robot_state");
  EXPECT_NE(no_pose.refusal.reason.find("valid ROBOT_STATE:"), std::string::npos) << no_pose.refusal.reason;
  EXPECT_EQ(session.state().next_index, 0);
  EXPECT_EQ(session.Handle(Control("s", +SC::REQUEST_TRIAL), kRobot).kind, Kind::kRequestedTrial);
}

TEST(HmdSession, RefusalsOfTheCommonValidatorKeepTheirKeys) {
  HmdSession session = TwoDisplays();
  session.Handle(Control("s", +SC::START), kRobot);
  struct Case {
    orbed::session_control_t msg;
    std::string key;
  };
  const Case cases[] = {
      {Control("x", 9), "command"},
      {Control("x", -1), "command"},
      {Control("", +SC::START), "session_id"},
      {Control("", +SC::REQUEST_TRIAL), "session_id"},
      {Control(std::string(kMaxSessionIdLength + 1, 'x'), +SC::START), "session_id"},
      {Control("x", +SC::START, 7), "display_mode"},
      {Control("x", +SC::START, +AT::MODE_AR, 1), "num_mirrors"},
      {Control("x", +SC::START, +AT::MODE_AR_REFLECTIVE, 0), "num_mirrors"},
      {Control("x", +SC::START, +AT::MODE_AR_REFLECTIVE, 99), "num_mirrors"},
      {Control("x", +SC::START, +AT::MODE_AR, 0, 42), "method"},
  };
  for (const Case& c : cases) {
    const SessionDecision d = session.Handle(c.msg, kRobot);
    EXPECT_EQ(d.kind, Kind::kRefuse) << c.key;
    EXPECT_EQ(d.refusal.key, c.key) << d.refusal.reason;
    EXPECT_FALSE(d.refusal.reason.empty());
  }
  EXPECT_EQ(session.state().id, "s");  // nothing changed
}

// Contract change 6: a START may say where each display captures; the names must be waypoints of the
// headset's walk and the session keeps them. A START of the active session with other waypoints is
// refused: every other reader takes it as a repeat, so the headset may not start over.
TEST(HmdSession, CaptureWaypointsMustBeOnTheWalk) {
  HmdSession session({2, "IIWA_STATUS", "ROBOT_STATE", {"foot_end", "head_end"}});
  orbed::session_control_t start = Control("s", +SC::START, +AT::MODE_AR_REFLECTIVE, 1);
  start.capture_waypoint = {"nowhere"};
  start.num_capture_waypoints = 1;
  const SessionDecision refused = session.Handle(start, kRobot);
  EXPECT_EQ(refused.kind, Kind::kRefuse);
  EXPECT_EQ(refused.refusal.key, "capture_waypoint");
  EXPECT_FALSE(session.state().active());
  start.capture_waypoint = {"head_end"};
  EXPECT_EQ(session.Handle(start, kRobot).kind, Kind::kStart);
  EXPECT_EQ(session.state().capture_waypoints, (std::vector<std::string>{"head_end"}));
  EXPECT_EQ(session.TakeTrialIndex(), 0);
  EXPECT_EQ(session.Handle(start, kRobot).kind, Kind::kRepeatedStart);
  start.capture_waypoint = {"foot_end"};
  const SessionDecision other = session.Handle(start, kRobot);
  EXPECT_EQ(other.kind, Kind::kRefuse);
  EXPECT_EQ(other.refusal.key, "capture_waypoint");
  EXPECT_EQ(session.state().next_index, 1);  // the session goes on as it was
  EXPECT_EQ(session.state().capture_waypoints, (std::vector<std::string>{"head_end"}));
  start.session_id = "t";  // a new session may capture elsewhere
  EXPECT_EQ(session.Handle(start, kRobot).kind, Kind::kStart);
  EXPECT_EQ(session.state().capture_waypoints, (std::vector<std::string>{"foot_end"}));
}

TEST(HmdSession, StartBeyondThePlacedDisplaysIsRefused) {
  HmdSession session = TwoDisplays();
  const SessionDecision d = session.Handle(Control("s", +SC::START, +AT::MODE_AR_REFLECTIVE, 3), kRobot);
  EXPECT_EQ(d.kind, Kind::kRefuse);
  EXPECT_EQ(d.refusal.key, "num_mirrors");
  EXPECT_NE(d.refusal.reason.find("2 display(s)"), std::string::npos) << d.refusal.reason;
  EXPECT_FALSE(session.state().active());
  // A headset without displays takes MODE_AR only.
  HmdSession bare({0, "IIWA_STATUS", "ROBOT_STATE", {}});
  EXPECT_EQ(bare.Handle(Control("s", +SC::START, +AT::MODE_AR_REFLECTIVE, 1), kRobot).refusal.key,
            "num_mirrors");
  EXPECT_EQ(bare.Handle(Control("s", +SC::START, +AT::MODE_AR, 0), kRobot).kind, Kind::kStart);
}

TEST(HmdSession, ApplyTakesACheckedCommand) {
  HmdSession session = TwoDisplays();
  SessionCommand start;
  start.session_id = "s";
  start.kind = SessionCommand::Kind::kStart;
  start.display_mode = +AT::MODE_AR_REFLECTIVE;
  start.num_mirrors = 1;
  EXPECT_EQ(session.Apply(start, kRobot).kind, Kind::kStart);
  SessionCommand request = start;
  request.kind = SessionCommand::Kind::kRequestTrial;
  EXPECT_EQ(session.Apply(request, kRobot).kind, Kind::kRequestedTrial);
}

orbed::session_control_t WithId(orbed::session_control_t msg, int64_t request_id) {
  msg.request_id = request_id;
  return msg;
}

TEST(HmdSession, ARepeatedRequestIdGetsItsFirstAnswerAndChangesNothing) {
  HmdSession session = TwoDisplays();
  EXPECT_EQ(session.Handle(WithId(Control("s", +SC::START), 1), kRobot).kind, Kind::kStart);
  // Refused (no robot yet): not remembered, so the retry is judged afresh and accepted.
  const auto request = WithId(Control("s", +SC::REQUEST_TRIAL), 2);
  EXPECT_EQ(session.Handle(request, kNoRobot).kind, Kind::kRefuse);
  SessionDecision d = session.Handle(request, kRobot);
  EXPECT_EQ(d.kind, Kind::kRequestedTrial);
  EXPECT_FALSE(d.already_requested);
  EXPECT_EQ(session.state().requested_id, 2);
  // Asked again before the trial is out (a person still aligning): the same request.
  d = session.Handle(request, kRobot);
  EXPECT_EQ(d.kind, Kind::kRequestedTrial);
  EXPECT_TRUE(d.already_requested);
  orbed::alignment_trial_t trial{};
  trial.session_id = "s";
  trial.trial_index = session.TakeTrialIndex();
  trial.request_id = 2;
  session.RecordTrial(trial);
  EXPECT_EQ(session.state().requested_id, 0);
  // Answered: repeats get the trial back; the index does not move.
  d = session.Handle(request, kRobot);
  EXPECT_EQ(d.kind, Kind::kRepeatedRequest);
  ASSERT_TRUE(d.answer.has_value());
  EXPECT_EQ(d.answer->request_id, 2);
  EXPECT_EQ(d.answer->trial_index, 0);
  EXPECT_EQ(session.state().next_index, 1);
  // START's id repeated after another START: nothing to answer, nothing changes.
  EXPECT_EQ(session.Handle(WithId(Control("t", +SC::START), 3), kRobot).kind, Kind::kStart);
  d = session.Handle(WithId(Control("s", +SC::START), 1), kRobot);
  EXPECT_EQ(d.kind, Kind::kRepeatedRequest);
  EXPECT_FALSE(d.answer.has_value());
  EXPECT_EQ(session.state().id, "t");
  // Id 0 is no id: acted on every time.
  EXPECT_EQ(session.Handle(Control("t", +SC::REQUEST_TRIAL), kRobot).kind, Kind::kRequestedTrial);
  EXPECT_EQ(session.Handle(Control("t", +SC::REQUEST_TRIAL), kRobot).kind, Kind::kRequestedTrial);
}

TEST(HmdSession, DisplayModeNames) {
  EXPECT_STREQ(DisplayModeName(+AT::MODE_AR), "ar");
  EXPECT_STREQ(DisplayModeName(+AT::MODE_AR_REFLECTIVE), "ar_reflective");
}

}  // namespace
}  // namespace orbed::hmd
