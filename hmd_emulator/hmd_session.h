#pragma once
/// @file
/// The headset's session state machine (the contract with orbed-scenario), without a bus or a
/// clock: SESSION_CONTROL commands in, decisions out. HmdProcess (hmd_process.h) feeds it what
/// arrives and acts on the decision (refuse, forget the hologram pose, run or announce a trial).
///
/// Every message is first checked by the common validator (orbed::CheckSessionControl,
/// lcmtypes/contract/session_control.h: refusal keys session_id, command, display_mode, num_mirrors,
/// method, capture_waypoint); the headset then adds its own checks:
///   - START: num_mirrors <= the displays placed in hmd.yaml (key "num_mirrors"); every capture
///     waypoint a waypoint of the walk, and a START repeating the active session (same id, mode
///     and mirrors) with the same capture waypoints (key "capture_waypoint": every other reader
///     takes such a START as a repeat, so the headset may not start over);
///   - RESET, STOP, REQUEST_TRIAL for a session that is not the active one (key "unknown_session");
///   - REQUEST_TRIAL before a valid joint vector q and base pose X_WR are known (key
///     "no_robot_state": the person cannot align without the robot);
///   - REQUEST_TRIAL once the session has had kMaxTrialsPerSession trials (key "session_full":
///     lcmtypes/contract/alignment_trial.h; each trial replays the session's earlier walks).
/// The emulated trial itself may still fail; the shell refuses that under "trial_failed".
///
/// Transitions: START opens session s (mode, mirrors, method), trial index 0, replacing any other;
/// a repeated START of the active session with the same mode, mirrors and capture waypoints is a
/// no-op (e.g. the
/// headset's own local START, echoed back); RESET sets the index to 0; STOP closes the session;
/// COMPUTE is for the registration server (ignored); REQUEST_TRIAL accepted means "run trial
/// next_index now" for request state().requested_id, and the caller takes the index with
/// TakeTrialIndex() and hands the published trial to RecordTrial(). An ALIGNMENT_TRIAL of the
/// active session (same mode and mirrors) with an index at or beyond next_index, published by
/// someone else (a resumed conductor re-sending the trials it kept), moves next_index past it
/// (ObserveTrial), so the next trial gets the next index.
///
/// Repeats (runtime/recent_answers.h): a command whose nonzero request_id was acted on is a
/// kRepeatedRequest and changes nothing: for a REQUEST_TRIAL its answer is the very ALIGNMENT_TRIAL
/// published for it (the caller publishes it again: a retried request never makes a second,
/// different trial); for START / RESET / STOP there is nothing to answer. A REQUEST_TRIAL whose id
/// is the one still being worked on (a person aligning) is kRequestedTrial with already_requested.
/// Refused commands are not remembered, so their retries are judged afresh. A headset restored from
/// its state file remembers the saved START and last trial the same way (session_file.h).
///
/// Threading: not synchronised; one thread (the Process::Run() thread).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <orbed/alignment_trial_t.hpp>
#include <orbed/session_control_t.hpp>

#include "lcmtypes/contract/session_control.h"
#include "runtime/recent_answers.h"

namespace orbed::hmd {

/// "ar_reflective" for alignment_trial_t::MODE_AR_REFLECTIVE, else "ar".
const char* DisplayModeName(std::int8_t display_mode);

/// The active session ("" id = none).
struct HmdSessionState {
  std::string id;
  std::int8_t display_mode{0};  ///< alignment_trial_t::MODE_*
  std::int32_t num_mirrors{0};
  std::int8_t method{0};  ///< registration_t::METHOD_*
  std::int32_t next_index{0};
  /// The request_id of the REQUEST_TRIAL being answered (0: none, or it had no id).
  std::int64_t requested_id{0};
  /// Where each display captures, as the START named them (empty: hmd.displays').
  std::vector<std::string> capture_waypoints;

  bool active() const { return !id.empty(); }
  /// "session 's' (ar_reflective, 1 display(s))".
  std::string Describe() const;
};

/// What the robot state is known to be, as far as the session cares.
struct RobotKnown {
  bool q{false};     ///< a valid IIWA_STATUS arrived
  bool X_WR{false};  ///< a valid ROBOT_STATE arrived
};

struct SessionDecision {
  enum class Kind {
    kRefuse,           ///< refusal.key / refusal.reason; nothing changed
    kStart,            ///< a new session is active (the previous one's hologram poses are stale)
    kRepeatedStart,    ///< the active session again: nothing changed
    kReset,            ///< the trial index is back at 0
    kStop,             ///< the session closed
    kIgnore,           ///< COMPUTE: not for the headset
    kRequestedTrial,   ///< run (or ask the person for) trial state().next_index now
    kRepeatedRequest,  ///< a request id acted on before: publish `answer` again, if any
  };
  Kind kind{Kind::kIgnore};
  Refusal refusal;    ///< kRefuse only
  std::string event;  ///< kStart, kStop: one line for the log
  /// kRepeatedRequest: the ALIGNMENT_TRIAL that answered the request (REQUEST_TRIAL), else none.
  std::optional<orbed::alignment_trial_t> answer;
  /// kRequestedTrial: this request id is the one already being worked on (do not ask twice).
  bool already_requested{false};
};

struct HmdSessionOptions {
  int displays_placed{0};  ///< hmd.displays.size(): START's num_mirrors bound
  /// Named in the no_robot_state reason.
  std::string iiwa_status_channel{"IIWA_STATUS"};
  std::string robot_state_channel{"ROBOT_STATE"};
  /// The walk's waypoint names: a START's capture waypoints must be among them.
  std::vector<std::string> waypoint_names;
};

class HmdSession {
 public:
  explicit HmdSession(HmdSessionOptions options = {});

  /// Checks `msg` with orbed::CheckSessionControl, then Apply().
  SessionDecision Handle(const orbed::session_control_t& msg, RobotKnown robot);
  /// Applies a checked command (see the file comment).
  SessionDecision Apply(const SessionCommand& command, RobotKnown robot);

  /// Opens `state` as the active session without a message (the interactive headset's local
  /// session, which it announces itself); state.next_index is kept.
  void Open(const HmdSessionState& state) { state_ = state; }

  /// Returns the active session's next trial index and advances it.
  std::int32_t TakeTrialIndex() { return state_.next_index++; }
  /// A trial seen on ALIGNMENT_TRIAL, already checked (orbed::CheckAlignmentTrial): advances
  /// next_index past it when it is one of the active session's at or beyond next_index. Returns
  /// whether it did.
  bool ObserveTrial(const orbed::alignment_trial_t& msg);
  /// Remembers the published `trial` as the answer to its request_id (the pending request is then
  /// answered); a trial without a request id is not remembered.
  void RecordTrial(const orbed::alignment_trial_t& trial);

  const HmdSessionState& state() const { return state_; }

 private:
  // The command's effect on the session (Apply() without the repeats).
  SessionDecision Transition(const SessionCommand& command, RobotKnown robot);

  HmdSessionOptions options_;
  HmdSessionState state_;
  // What each request id acted on was answered with (a trial for REQUEST_TRIAL, else nothing).
  RecentAnswers<std::optional<orbed::alignment_trial_t>> answers_;
};

}  // namespace orbed::hmd
