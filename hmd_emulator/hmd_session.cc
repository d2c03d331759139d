#include "hmd_emulator/hmd_session.h"

#include <algorithm>

#include "lcmtypes/contract/alignment_trial.h"

#include <utility>
#include <variant>

namespace orbed::hmd {
namespace {

using Kind = SessionDecision::Kind;

SessionDecision Refuse(std::string key, std::string reason) {
  SessionDecision d;
  d.kind = Kind::kRefuse;
  d.refusal = Refusal{std::move(key), std::move(reason)};
  return d;
}

SessionDecision Decide(Kind kind, std::string event = "") {
  SessionDecision d;
  d.kind = kind;
  d.event = std::move(event);
  return d;
}

}  // namespace

const char* DisplayModeName(std::int8_t display_mode) {
  return display_mode == orbed::alignment_trial_t::MODE_AR_REFLECTIVE ? "ar_reflective" : "ar";
}

std::string HmdSessionState::Describe() const {
  return "session '" + id + "' (" + DisplayModeName(display_mode) + ", " + std::to_string(num_mirrors) +
         " display(s))";
}

HmdSession::HmdSession(HmdSessionOptions options) : options_(std::move(options)) {}

SessionDecision HmdSession::Handle(const orbed::session_control_t& msg, RobotKnown robot) {
  auto checked = CheckSessionControl(msg);
  if (const Refusal* refusal = std::get_if<Refusal>(&checked)) return Refuse(refusal->key, refusal->reason);
  return Apply(std::get<SessionCommand>(checked), robot);
}

SessionDecision HmdSession::Apply(const SessionCommand& command, RobotKnown robot) {
  if (const auto* answer = answers_.Find(command.request_id)) {
    SessionDecision d = Decide(Kind::kRepeatedRequest);
    d.answer = *answer;
    return d;
  }
  SessionDecision d = Transition(command, robot);
  switch (d.kind) {
    case Kind::kStart:
    case Kind::kRepeatedStart:
    case Kind::kReset:
    case Kind::kStop:
      answers_.Remember(command.request_id, std::nullopt);
      break;
    case Kind::kRequestedTrial:
      d.already_requested = command.request_id != 0 && command.request_id == state_.requested_id;
      state_.requested_id = command.request_id;
      break;
    default:
      break;
  }
  return d;
}

void HmdSession::RecordTrial(const orbed::alignment_trial_t& trial) {
  answers_.Remember(trial.request_id, trial);
  if (trial.request_id == state_.requested_id) state_.requested_id = 0;
}

SessionDecision HmdSession::Transition(const SessionCommand& command, RobotKnown robot) {
  using K = SessionCommand::Kind;
  if (command.kind == K::kStart) {
    if (command.num_mirrors > options_.displays_placed) {
      return Refuse("num_mirrors", "SESSION_CONTROL START '" + command.session_id + "': num_mirrors " +
                                       std::to_string(command.num_mirrors) + ", but hmd.displays places " +
                                       std::to_string(options_.displays_placed) + " display(s)");
    }
    for (const std::string& name : command.capture_waypoints) {
      if (std::find(options_.waypoint_names.begin(), options_.waypoint_names.end(), name) ==
          options_.waypoint_names.end()) {
        return Refuse("capture_waypoint", "SESSION_CONTROL START '" + command.session_id +
                                              "': capture waypoint '" + name +
                                              "' is not a waypoint of the walk");
      }
    }
    if (command.RepeatsStartOf(state_.id, state_.display_mode, state_.num_mirrors)) {
      // Every reader takes this START as a repeat (the registration server keeps the session's
      // trials), so the headset may not start over either: other capture points need a new session.
      if (command.capture_waypoints != state_.capture_waypoints) {
        return Refuse("capture_waypoint", "SESSION_CONTROL START '" + command.session_id +
                                              "' repeats the active session with other capture waypoints; "
                                              "START a new session to capture elsewhere");
      }
      return Decide(Kind::kRepeatedStart);
    }
    state_ = HmdSessionState{};
    state_.id = command.session_id;
    state_.display_mode = command.display_mode;
    state_.num_mirrors = command.num_mirrors;
    state_.method = command.method;
    state_.capture_waypoints = command.capture_waypoints;
    return Decide(Kind::kStart, "session '" + state_.id + "' started (" +
                                    DisplayModeName(state_.display_mode) + ", " +
                                    std::to_string(state_.num_mirrors) + " display(s))");
  }
  if (command.kind == K::kCompute) return Decide(Kind::kIgnore);
  if (command.session_id != state_.id) {
    return Refuse("unknown_session", std::string(SessionCommandName(command.kind)) + " for session '" +
                                         command.session_id + "', the active session is '" +
                                         (state_.active() ? state_.id : std::string("(none)")) + "'" +
                                         (command.kind == K::kRequestTrial ? " (send START first)" : ""));
  }
  switch (command.kind) {
    case K::kReset:
      state_.next_index = 0;
      return Decide(Kind::kReset);
    case K::kStop: {
      const std::string event =
          "session '" + state_.id + "' stopped after " + std::to_string(state_.next_index) + " trial(s)";
      state_ = HmdSessionState{};
      return Decide(Kind::kStop, event);
    }
    default:  // kRequestTrial
      break;
  }
  if (!(robot.q && robot.X_WR)) {
    return Refuse("no_robot_state",
                  "REQUEST_TRIAL for session '" + command.session_id + "' before any valid " +
                      (robot.q ? "" : options_.iiwa_status_channel + (robot.X_WR ? "" : " and ")) +
                      (robot.X_WR ? "" : options_.robot_state_channel) +
                      ": the user cannot align without the robot's configuration and base pose (is "
                      "orbed-iiwa-sim running?)");
  }
  if (state_.next_index >= kMaxTrialsPerSession) {
    return Refuse("session_full", "REQUEST_TRIAL for session '" + command.session_id + "': it has had its " +
                                      std::to_string(kMaxTrialsPerSession) + " trials; START a new session");
  }
  return Decide(Kind::kRequestedTrial);
}

bool HmdSession::ObserveTrial(const orbed::alignment_trial_t& msg) {
  if (!state_.active() || msg.session_id != state_.id || msg.display_mode != state_.display_mode ||
      msg.num_mirrors != state_.num_mirrors || msg.trial_index < state_.next_index ||
      msg.trial_index >= kMaxTrialsPerSession) {
    return false;
  }
  state_.next_index = msg.trial_index + 1;
  return true;
}

}  // namespace orbed::hmd
