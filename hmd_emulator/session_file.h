#pragma once
/// @file
/// orbed-hmd's state file: the session it is in, so that a respawned headset continues the session
/// with the right next trial index (its trials are functions of the session and the index, so the
/// respawned headset's trials are those the original would have made).
///
/// The file is a journal (runtime/journal.h) replaced whole on every change (temporary file +
/// rename): no records when no session is active; otherwise "SESSION_CONTROL", the START that
/// opened the session, and, once the session has a trial, "ALIGNMENT_TRIAL", its last trial (as
/// the headset published it, or as it observed it on the bus). RestoreSession replays the records
/// through the session machine's own entry points (HmdSession::Handle, ObserveTrial, RecordTrial)
/// after checking them like input from the bus (DecodeBounded, orbed::CheckAlignmentTrial); a file
/// that is damaged, or whose records the machine refuses, is refused with the reason and the headset
/// does not start (it would run trials with the wrong index). The START's and the trial's request
/// ids are remembered as before the crash: a retried REQUEST_TRIAL of the saved trial gets that
/// trial again, never a new one.
///
/// Threading: plain functions.

#include <optional>
#include <string>

#include <orbed/alignment_trial_t.hpp>
#include <orbed/session_control_t.hpp>

#include "hmd_emulator/hmd_session.h"

namespace orbed::hmd {

/// What the file holds.
struct SavedSession {
  std::optional<orbed::session_control_t> start;
  std::optional<orbed::alignment_trial_t> last_trial;
};

/// Reads the file at `path` into `session` (a fresh one) and returns what it held; an absent or
/// empty file is no session. Throws std::runtime_error "state file <path>: <why>".
SavedSession RestoreSession(const std::string& path, HmdSession* session);

/// Replaces the file by `saved`. Returns false and sets *error on failure.
bool SaveSession(const std::string& path, const SavedSession& saved, std::string* error);

}  // namespace orbed::hmd
