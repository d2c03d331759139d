#pragma once
/// @file
/// The registration server's crash recovery: a RegistrationService whose session inputs are
/// journaled (runtime/journal.h), so that a respawned orbed-registration continues the
/// session it had, and its REGISTRATIONs from then on are byte for byte those of a server that
/// never stopped.
///
/// What is journaled: every SESSION_CONTROL and ALIGNMENT_TRIAL message that changed the service
/// (RegistrationService::changes()), as its LCM encoding, before the answer is published (a trial
/// whose REGISTRATION went out is in the journal). Since the service is a pure function of those
/// inputs in order, replaying them into a fresh service rebuilds its state exactly, including the
/// utime of the periodic state. Record channels name the message type: "SESSION_CONTROL",
/// "ALIGNMENT_TRIAL" (whatever channels the server listens on).
///
/// Bounded: a START replaces the file by itself; a RESET of the active session replaces it by the
/// session's START stamped with the RESET's utime (which leaves a service in the same state); a STOP,
/// a RESET after it, and each accepted trial are appended. Since a repeated STOP or an empty RESET
/// changes nothing (registration_service.h), the journal holds at most max_trials_per_session + 3
/// records.
///
/// Reading: the journal is checked like input from the bus. Damage after the last whole record (a
/// torn record from a SIGKILL, or worse) is cut off and reported; a record that does not decode as
/// its type, or names another type, is refused under "journal/decode" or "journal/channel"; a
/// decoded message goes through the service's own checks.
///
/// A write failure (disk full) does not stop the server: it is reported once through the reject
/// callback ("journal/write") and journaling stops.
///
/// Threading: not thread-safe; the server's Run() thread.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <orbed/alignment_trial_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/session_control_t.hpp>

#include "experiments/viraal/registration_service.h"
#include "runtime/journal.h"

namespace orbed::registration {

class SessionJournal {
 public:
  using RejectFn = RegistrationService::RejectFn;

  /// Opens (or creates) the journal at `path` and replays it into `service`, which must be fresh.
  /// Throws std::runtime_error naming the path when the file cannot be read or written.
  SessionJournal(const std::string& path, RegistrationService* service, RejectFn reject);

  /// The service's handlers, with what changed the session journaled first.
  std::optional<orbed::registration_t> HandleSessionControl(const orbed::session_control_t& msg);
  std::optional<orbed::registration_t> HandleTrial(const orbed::alignment_trial_t& msg);

  /// What the replay found, for the log: "replayed N records (session 's', k trials, active)" and
  /// any damage cut off.
  const std::string& replay_summary() const { return replay_summary_; }
  const std::string& path() const { return journal_->path(); }

  /// Record channels.
  static constexpr char kSessionControl[] = "SESSION_CONTROL";
  static constexpr char kAlignmentTrial[] = "ALIGNMENT_TRIAL";

 private:
  void Write(bool replace, const std::vector<JournalRecord>& records);

  RegistrationService* service_;
  RejectFn reject_;
  std::unique_ptr<Journal> journal_;
  std::optional<orbed::session_control_t> start_;  // the session's START (a RESET's compaction)
  bool failed_ = false;
  std::string replay_summary_;
};

}  // namespace orbed::registration
