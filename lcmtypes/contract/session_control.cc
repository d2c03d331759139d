#include "lcmtypes/contract/session_control.h"

#include <algorithm>

#include <orbed/alignment_trial_t.hpp>
#include <orbed/registration_t.hpp>

#include "lcmtypes/contract/validation.h"

namespace orbed {

bool IsWaypointName(const std::string& name) {
  return !name.empty() && name.size() <= kMaxWaypointNameLength &&
         std::all_of(name.begin(), name.end(), [](char c) { return c > ' ' && c < 127; });
}

namespace {

using SC = orbed::session_control_t;
using AT = orbed::alignment_trial_t;
using RT = orbed::registration_t;

SessionCommand::Kind KindOf(int8_t command) {
  switch (command) {
    case SC::START:
      return SessionCommand::Kind::kStart;
    case SC::RESET:
      return SessionCommand::Kind::kReset;
    case SC::COMPUTE:
      return SessionCommand::Kind::kCompute;
    case SC::STOP:
      return SessionCommand::Kind::kStop;
    default:
      return SessionCommand::Kind::kRequestTrial;
  }
}

}  // namespace

const char* SessionCommandName(SessionCommand::Kind kind) {
  switch (kind) {
    case SessionCommand::Kind::kStart:
      return "START";
    case SessionCommand::Kind::kReset:
      return "RESET";
    case SessionCommand::Kind::kCompute:
      return "COMPUTE";
    case SessionCommand::Kind::kStop:
      return "STOP";
    case SessionCommand::Kind::kRequestTrial:
      return "REQUEST_TRIAL";
  }
  return "?";
}

std::variant<SessionCommand, Refusal> CheckSessionControl(const orbed::session_control_t& msg) {
  std::string error = CheckEnum(msg.command, SC::START, SC::REQUEST_TRIAL, "SESSION_CONTROL.command");
  if (!error.empty()) return Refusal{"command", error};
  if (msg.session_id.empty()) return Refusal{"session_id", "SESSION_CONTROL.session_id is empty"};
  if (msg.session_id.size() > kMaxSessionIdLength) {
    return Refusal{"session_id", "SESSION_CONTROL.session_id is " + std::to_string(msg.session_id.size()) +
                                     " bytes, at most " + std::to_string(kMaxSessionIdLength) + " allowed"};
  }
  SessionCommand command;
  command.utime = msg.utime;
  command.session_id = msg.session_id;
  command.kind = KindOf(msg.command);
  command.display_mode = msg.display_mode;
  command.num_mirrors = msg.num_mirrors;
  command.method = msg.method;
  command.request_id = msg.request_id;
  if (command.kind != SessionCommand::Kind::kStart) return command;

  error = CheckEnum(msg.display_mode, AT::MODE_AR, AT::MODE_AR_REFLECTIVE, "SESSION_CONTROL.display_mode");
  if (!error.empty()) return Refusal{"display_mode", error};
  if (msg.display_mode == AT::MODE_AR ? msg.num_mirrors != 0
                                      : (msg.num_mirrors < 1 || msg.num_mirrors > kMaxMirrors)) {
    return Refusal{"num_mirrors",
                   "SESSION_CONTROL START '" + msg.session_id + "': num_mirrors " +
                       std::to_string(msg.num_mirrors) +
                       (msg.display_mode == AT::MODE_AR
                            ? " with MODE_AR, expected 0"
                            : " with MODE_AR_REFLECTIVE, expected 1.." + std::to_string(kMaxMirrors))};
  }
  error = CheckEnum(msg.method, RT::METHOD_CHORDAL, RT::METHOD_ROBUST, "SESSION_CONTROL.method");
  if (!error.empty()) return Refusal{"method", error};
  const std::string start = "SESSION_CONTROL START '" + msg.session_id + "': ";
  if (msg.num_capture_waypoints < 0 ||
      static_cast<size_t>(msg.num_capture_waypoints) != msg.capture_waypoint.size()) {
    return Refusal{"capture_waypoint", start + "num_capture_waypoints " +
                                           std::to_string(msg.num_capture_waypoints) + " for " +
                                           std::to_string(msg.capture_waypoint.size()) + " names"};
  }
  if (msg.num_capture_waypoints != 0 && msg.num_capture_waypoints != msg.num_mirrors) {
    return Refusal{"capture_waypoint", start + std::to_string(msg.num_capture_waypoints) +
                                           " capture waypoints for " + std::to_string(msg.num_mirrors) +
                                           " display(s), expected none or one per display"};
  }
  for (const std::string& name : msg.capture_waypoint) {
    if (!IsWaypointName(name)) {
      return Refusal{"capture_waypoint", start + "a capture waypoint name must be 1.." +
                                             std::to_string(kMaxWaypointNameLength) +
                                             " printable bytes without spaces"};
    }
  }
  command.capture_waypoints = msg.capture_waypoint;
  return command;
}

}  // namespace orbed
