#pragma once
/// @file
/// The one check of SESSION_CONTROL (session_control_t): every process that reads the message turns
/// it into a SessionCommand here, or refuses it with the same reason, so the registration server,
/// the headset and any later reader agree on what a valid command is.
///
/// The contract:
///   - session_id: 1..kMaxSessionIdLength bytes;
///   - command: START, RESET, COMPUTE, STOP or REQUEST_TRIAL;
///   - START only: display_mode MODE_AR with num_mirrors 0, or MODE_AR_REFLECTIVE with
///     1..kMaxMirrors mirrors; method one of registration_t's METHOD_*; capture waypoints (contract
///     change 6): none, or exactly num_mirrors names of 1..kMaxWaypointNameLength printable bytes
///     (num_capture_waypoints equal to the array's length). The other commands name a session that
///     START opened; their mode, mirror, method and waypoint fields are not read.
/// A repeated START of the session that is already active with the same mode and mirrors is a
/// no-op for every reader (SessionCommand::RepeatsStartOf tells it): it neither clears trials nor
/// restarts the trial count. The headset refuses one that names other capture waypoints. How many displays a
/// headset has placed is that headset's own check.
///
/// Refusal keys are "<field>" (session_id, command, display_mode, num_mirrors, method,
/// capture_waypoint); processes
/// count them as "<channel>/<field>" on PROCESS_STATUS.
///
/// request_id is not checked (any value): a reader acts on a nonzero id once and answers a repeat
/// with its first answer, changing nothing (runtime/recent_answers.h); 0 is acted on every time.
///
/// Threading: pure functions.

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include <orbed/session_control_t.hpp>

namespace orbed {

inline constexpr size_t kMaxSessionIdLength = 256;
inline constexpr int32_t kMaxMirrors = 64;
inline constexpr size_t kMaxWaypointNameLength = 64;

/// A capture waypoint's name as SESSION_CONTROL carries it (and a scenario file names it):
/// 1..kMaxWaypointNameLength printable ASCII bytes, no spaces.
bool IsWaypointName(const std::string& name);

/// Why a message was refused: `key` names the field (the counter's class), `reason` is one line.
struct Refusal {
  std::string key;
  std::string reason;
};

struct SessionCommand {
  enum class Kind { kStart, kReset, kCompute, kStop, kRequestTrial };
  int64_t utime{0};
  std::string session_id;
  Kind kind{Kind::kStart};
  int8_t display_mode{0};  ///< alignment_trial_t::MODE_* (START; else as sent)
  int32_t num_mirrors{0};  ///< (START; else as sent)
  int8_t method{0};        ///< registration_t::METHOD_* (START; else as sent)
  int64_t request_id{0};   ///< the sender's request id; 0 = none
  /// Where each display captures (START; empty = the headset's own configuration).
  std::vector<std::string> capture_waypoints;

  /// True when this START names the active session `session_id` with the same mode and mirrors
  /// (a reader to whom the capture waypoints matter compares those too).
  bool RepeatsStartOf(const std::string& active_session_id, int8_t active_display_mode,
                      int32_t active_num_mirrors) const {
    return kind == Kind::kStart && session_id == active_session_id && display_mode == active_display_mode &&
           num_mirrors == active_num_mirrors;
  }
};

/// "START", "RESET", ... for log lines.
const char* SessionCommandName(SessionCommand::Kind kind);

/// The checked command, or the refusal.
std::variant<SessionCommand, Refusal> CheckSessionControl(const orbed::session_control_t& msg);

}  // namespace orbed
