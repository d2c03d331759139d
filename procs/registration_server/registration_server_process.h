#pragma once
/// @file
/// The orbed-registration LCM process: RegistrationService (registration_service.h) on the bus.
///   Subscribes: SESSION_CONTROL (session_control_t), ALIGNMENT_TRIAL (alignment_trial_t),
///               LANDMARK_REQUEST (landmark_request_t), MISALIGNMENT_REQUEST (misalignment_request_t).
///   Publishes:  REGISTRATION (registration_t) after every accepted trial, on COMPUTE, and every
///               state_period_s as the full state; LANDMARK (landmark_t) and MISALIGNMENT
///               (misalignment_t) answering each request; PROCESS_STATUS at 1 Hz (Process).
/// Every request is answered idempotently: a repeated COMPUTE or a repeat of the latest trial gets
/// its first REGISTRATION again (registration_service.h), and a repeated LANDMARK_REQUEST or
/// MISALIGNMENT_REQUEST the same answer, which is a pure function of the request (its utime
/// included), so a client may retry any request with the same request_id.
/// Bad inputs are counted per class on PROCESS_STATUS and logged (Process::Reject); the process
/// keeps serving. Outputs take their utime from inputs (see registration_service.h), so a replayed
/// log gives the same REGISTRATION bytes.
/// With a journal (journal_path, session_journal.h) the session survives a crash: the constructor
/// replays the journal, so a respawned server answers as if it had never stopped.
///
/// Threading: everything runs on the Run() thread (Process).

#include <memory>
#include <optional>
#include <string>

#include "experiments/viraal/registration_service.h"
#include "lcmtypes/contract/channels.h"
#include "procs/registration_server/session_journal.h"
#include "runtime/process.h"

namespace orbed::registration {

struct RegistrationServerOptions {
  RegistrationServiceOptions service;
  /// Period of the full-state REGISTRATION [s]; 0 disables it.
  double state_period_s = 1.0;
  /// The session journal (session_journal.h); "" = none.
  std::string journal_path;
  /// One of several headsets: the registration of that headset's map to the arm it
  /// looks at; every channel below gets the suffix _NAME (channels::ForHeadset). "" = plain names.
  std::string headset;
  std::string session_control_channel = channels::kSessionControl;
  std::string trial_channel = channels::kAlignmentTrial;
  std::string registration_channel = channels::kRegistration;
  std::string landmark_request_channel = channels::kLandmarkRequest;
  std::string landmark_channel = channels::kLandmark;
  std::string misalignment_request_channel = channels::kMisalignmentRequest;
  std::string misalignment_channel = channels::kMisalignment;
};

class RegistrationServer : public orbed::Process {
 public:
  /// Throws std::runtime_error when LCM cannot start on flags.lcm_url (from Process) or the journal
  /// cannot be read or written.
  RegistrationServer(const orbed::CommonFlags& flags, const RegistrationServerOptions& options);

  const RegistrationService& service() const { return service_; }

 private:
  // The service's session handlers, through the journal when there is one.
  std::optional<orbed::registration_t> HandleSessionControl(const orbed::session_control_t& msg);
  std::optional<orbed::registration_t> HandleTrial(const orbed::alignment_trial_t& msg);

  RegistrationServerOptions options_;
  RegistrationService service_;
  std::unique_ptr<SessionJournal> journal_;
};

}  // namespace orbed::registration
