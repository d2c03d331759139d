#pragma once
/// @file
/// The registration server's message logic without a bus: sessions driven by session_control_t,
/// alignment trials in, registration_t / landmark_t / misalignment_t out. RegistrationServer
/// (registration_server_process.h) wires it to LCM channels; tests drive it directly.
///
/// Purity: every output is a function of the inputs handled so far, in order, and nothing else (no
/// clock, no randomness). Output utimes are input utimes: a REGISTRATION for a trial carries that
/// trial's utime; a COMPUTE answer the command's utime; the periodic state the utime of the last
/// input that changed the session; LANDMARK / MISALIGNMENT the request's utime. Replaying a log
/// therefore reproduces the same bytes.
///
/// Sessions (commands checked by lcmtypes/contract/session_control.h): START(session_id, display_mode,
/// num_mirrors, method) opens a session (replacing any other; a repeated START of the active session
/// with the same mode and mirrors changes nothing); trials for it are collected until STOP; RESET drops its
/// trials; COMPUTE asks for the full state now. The last session's state stays available (periodic state,
/// COMPUTE) after STOP until the next START. A STOP of a stopped session and a RESET of a session without
/// trials change nothing either, so every input that changes the state changes the session (what the
/// journal of session_journal.h relies on to stay bounded).
///
/// Frames and units: trials carry X_WV (virtual robot base V in the OR world W) [m]; the mean is
/// X_WV_mean; rays and landmarks are in W [m]; angles in messages are [deg] where named.
///
/// Repeats (runtime/recent_answers.h): a SESSION_CONTROL command whose nonzero request_id was
/// already acted on changes nothing and returns its first answer (a COMPUTE its REGISTRATION, the
/// others nothing); the answers to the last 64 ids are kept. A trial identical to one the session
/// holds (same index, utime, request_id and X_WV: a re-sent or duplicated datagram) changes nothing:
/// the latest trial's repeat returns its REGISTRATION again, an older one's nothing. Neither is a
/// rejection, and neither counts in changes() (so neither is journaled). A REGISTRATION echoes the
/// request it answers (request_id: the COMPUTE's, the trial's, 0 for the periodic state). After a
/// journal replay the START's id and the trials are known again; a COMPUTE is not journaled, and a
/// repeated one, answered afresh from the same state, gets the same bytes.
///
/// Rejections: a trial or command that fails validation changes nothing; the reject callback gets
/// a class key ("ALIGNMENT_TRIAL/pose") and a one-line reason. Invalid landmark / misalignment
/// requests are answered with valid = false and the reason, and also reported as rejections.
///
/// Threading: not thread-safe; call from one thread (the Process::Run() thread).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/landmark_request_t.hpp>
#include <orbed/landmark_t.hpp>
#include <orbed/misalignment_request_t.hpp>
#include <orbed/misalignment_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/session_control_t.hpp>

#include "geometry/robust.h"
#include "geometry/triangulation.h"
#include "runtime/recent_answers.h"

namespace orbed::registration {

struct RegistrationServiceOptions {
  /// Model centroid C in V [m] for averaging translations about it (se3_mean.h); unset = eq. 3.
  std::optional<Eigen::Vector3d> p_VC;
  /// Robust-mode rejection (robust.h).
  geometry::OutlierOptions outlier;
  /// Landmark triangulation (triangulation.h).
  geometry::TriangulationOptions triangulation;
  /// Bounds that keep a flood of input from growing memory without limit.
  int max_trials_per_session = 10000;
  int max_rays = 1000;
  int max_pairs = 10000;
  int max_joints = 64;
};

class RegistrationService {
 public:
  using RejectFn = std::function<void(const std::string& key, const std::string& reason)>;

  RegistrationService(RegistrationServiceOptions options, RejectFn reject);

  /// START / RESET / STOP return nothing; COMPUTE returns the full state (reason COMPUTE); a
  /// repeated request id its first answer.
  std::optional<orbed::registration_t> HandleSessionControl(const orbed::session_control_t& msg);
  /// An accepted trial returns the new state (reason TRIAL); a rejected one nothing; a repeat of
  /// the latest trial its state again, of an older one nothing.
  std::optional<orbed::registration_t> HandleTrial(const orbed::alignment_trial_t& msg);
  orbed::landmark_t HandleLandmarkRequest(const orbed::landmark_request_t& msg);
  orbed::misalignment_t HandleMisalignmentRequest(const orbed::misalignment_request_t& msg);
  /// The full state (reason PERIODIC) once a session has been started, else nothing.
  std::optional<orbed::registration_t> PeriodicState() const;

  /// Counts the inputs that changed the state (START, RESET, STOP, accepted trials); a caller compares
  /// it before and after a call to know whether the call changed anything.
  int64_t changes() const { return changes_; }
  bool has_session() const { return has_session_; }
  bool session_active() const { return active_; }
  const std::string& session_id() const { return session_id_; }
  int num_trials() const { return static_cast<int>(trials_.size()); }

 private:
  struct Trial {
    int32_t trial_index;
    Eigen::Quaterniond quat_WV;
    Eigen::Vector3d p_WV;
    // As received, to recognise a repeat.
    int64_t utime;
    int64_t request_id;
    orbed::pose_t X_WV;
  };

  // The repeated trial of the session equal to `msg`, if there is one.
  const Trial* FindRepeat(const orbed::alignment_trial_t& msg) const;
  orbed::registration_t MakeState(int64_t utime, int8_t reason, int64_t request_id) const;
  void Reject(const std::string& key, const std::string& reason) const;

  RegistrationServiceOptions options_;
  RejectFn reject_;
  bool has_session_ = false;
  bool active_ = false;
  std::string session_id_;
  int8_t display_mode_ = 0;
  int32_t num_mirrors_ = 0;
  int8_t method_ = orbed::registration_t::METHOD_KARCHER;
  std::vector<Trial> trials_;
  int64_t last_utime_ = 0;
  int64_t changes_ = 0;
  // The REGISTRATION of the latest accepted trial, answered again to its repeats.
  std::optional<orbed::registration_t> latest_trial_state_;
  RecentAnswers<std::optional<orbed::registration_t>> command_answers_;
};

}  // namespace orbed::registration
