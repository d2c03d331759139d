// The one SESSION_CONTROL check: each field's rule, by hand-built messages.
#include "lcmtypes/contract/session_control.h"

#include <gtest/gtest.h>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/registration_t.hpp>

namespace orbed {
namespace {

using SC = orbed::session_control_t;
using AT = orbed::alignment_trial_t;

SC Start(int8_t mode, int32_t mirrors) {
  SC msg{};
  msg.utime = 42;
  msg.session_id = "run-ar";
  msg.command = SC::START;
  msg.display_mode = mode;
  msg.num_mirrors = mirrors;
  msg.method = orbed::registration_t::METHOD_KARCHER;
  return msg;
}

std::string RefusalKey(const SC& msg) {
  const auto checked = CheckSessionControl(msg);
  const auto* refusal = std::get_if<Refusal>(&checked);
  if (refusal == nullptr) return "";
  EXPECT_FALSE(refusal->reason.empty());
  return refusal->key;
}

TEST(SessionControl, ValidStartBecomesACommandWithItsFields) {
  SC msg = Start(AT::MODE_AR_REFLECTIVE, 2);
  msg.request_id = -77;  // any value: the id is the sender's
  const auto checked = CheckSessionControl(msg);
  ASSERT_TRUE(std::holds_alternative<SessionCommand>(checked));
  const SessionCommand& command = std::get<SessionCommand>(checked);
  EXPECT_EQ(command.kind, SessionCommand::Kind::kStart);
  EXPECT_EQ(command.utime, 42);
  EXPECT_EQ(command.session_id, "run-ar");
  EXPECT_EQ(command.num_mirrors, 2);
  EXPECT_EQ(command.request_id, -77);
  EXPECT_TRUE(command.RepeatsStartOf("run-ar", AT::MODE_AR_REFLECTIVE, 2));
  EXPECT_FALSE(command.RepeatsStartOf("run-ar", AT::MODE_AR_REFLECTIVE, 1));
  EXPECT_FALSE(command.RepeatsStartOf("other", AT::MODE_AR_REFLECTIVE, 2));
}

// Contract change 6: a START may name where each display captures, none or one per display, each
// a printable name of 1..64 bytes; the command carries them.
TEST(SessionControl, CaptureWaypointsAreNoneOrOnePerDisplay) {
  SC msg = Start(AT::MODE_AR_REFLECTIVE, 2);
  msg.capture_waypoint = {"foot_end", "side"};
  msg.num_capture_waypoints = 2;
  const auto checked = CheckSessionControl(msg);
  ASSERT_TRUE(std::holds_alternative<SessionCommand>(checked));
  EXPECT_EQ(std::get<SessionCommand>(checked).capture_waypoints,
            (std::vector<std::string>{"foot_end", "side"}));
  msg.num_capture_waypoints = 3;  // the count must be the array's
  EXPECT_EQ(RefusalKey(msg), "capture_waypoint");
  msg.num_capture_waypoints = -1;
  EXPECT_EQ(RefusalKey(msg), "capture_waypoint");
  msg.capture_waypoint = {"foot_end"};
  msg.num_capture_waypoints = 1;  // one for two displays
  EXPECT_EQ(RefusalKey(msg), "capture_waypoint");
  msg.capture_waypoint = {"foot_end", ""};
  msg.num_capture_waypoints = 2;
  EXPECT_EQ(RefusalKey(msg), "capture_waypoint");
  msg.capture_waypoint = {"foot_end", std::string(kMaxWaypointNameLength + 1, 'w')};
  EXPECT_EQ(RefusalKey(msg), "capture_waypoint");
  msg.capture_waypoint = {"foot_end", "head end"};
  EXPECT_EQ(RefusalKey(msg), "capture_waypoint");
  msg.capture_waypoint = {"foot_end", std::string(kMaxWaypointNameLength, 'w')};
  EXPECT_EQ(RefusalKey(msg), "");
  msg = Start(AT::MODE_AR, 0);
  msg.capture_waypoint = {"foot_end"};
  msg.num_capture_waypoints = 1;  // AR only has no display
  EXPECT_EQ(RefusalKey(msg), "capture_waypoint");
}

TEST(SessionControl, EachFieldIsRefusedByName) {
  SC msg = Start(AT::MODE_AR, 0);
  EXPECT_EQ(RefusalKey(msg), "");
  msg.command = 5;
  EXPECT_EQ(RefusalKey(msg), "command");
  msg.command = -1;
  EXPECT_EQ(RefusalKey(msg), "command");
  msg = Start(AT::MODE_AR, 0);
  msg.session_id = "";
  EXPECT_EQ(RefusalKey(msg), "session_id");
  msg.session_id = std::string(kMaxSessionIdLength + 1, 'x');
  EXPECT_EQ(RefusalKey(msg), "session_id");
  msg.session_id = std::string(kMaxSessionIdLength, 'x');
  EXPECT_EQ(RefusalKey(msg), "");
  EXPECT_EQ(RefusalKey(Start(2, 0)), "display_mode");
  EXPECT_EQ(RefusalKey(Start(AT::MODE_AR, 1)), "num_mirrors");
  EXPECT_EQ(RefusalKey(Start(AT::MODE_AR_REFLECTIVE, 0)), "num_mirrors");
  EXPECT_EQ(RefusalKey(Start(AT::MODE_AR_REFLECTIVE, kMaxMirrors)), "");
  EXPECT_EQ(RefusalKey(Start(AT::MODE_AR_REFLECTIVE, kMaxMirrors + 1)), "num_mirrors");
  msg = Start(AT::MODE_AR, 0);
  msg.method = 3;
  EXPECT_EQ(RefusalKey(msg), "method");
}

TEST(SessionControl, OtherCommandsDoNotReadTheStartFields) {
  for (int8_t command : {SC::RESET, SC::COMPUTE, SC::STOP, SC::REQUEST_TRIAL}) {
    SC msg = Start(7, -3);
    msg.method = 99;
    msg.command = command;
    const auto checked = CheckSessionControl(msg);
    ASSERT_TRUE(std::holds_alternative<SessionCommand>(checked)) << int(command);
    EXPECT_FALSE(std::get<SessionCommand>(checked).RepeatsStartOf("run-ar", 7, -3));
  }
  SC msg = Start(AT::MODE_AR, 0);
  msg.command = SC::REQUEST_TRIAL;
  EXPECT_EQ(std::get<SessionCommand>(CheckSessionControl(msg)).kind, SessionCommand::Kind::kRequestTrial);
  EXPECT_STREQ(SessionCommandName(SessionCommand::Kind::kRequestTrial), "REQUEST_TRIAL");
}

}  // namespace
}  // namespace orbed
