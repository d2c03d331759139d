#pragma once
/// @file
/// The orbed-hmd process: the headset and the person wearing it, wired to the bus. A thin shell:
/// the work is done by cores that know nothing of LCM or of the clock, and this class checks what
/// arrives (the contract's checks), feeds it to them with the time, drives them from its timers and
/// carries out what they answer (publish, reject, save the state file):
///   hmd.h              the core, Headset: the options resolved, the inputs kept, the hologram's
///                      pose and joints, the sessions' trials, the person's keys (HeadsetActions);
///   pose_stream.h      the walk, the SLAM model, HMD_POSE / HMD_POSE_TRUTH and GAZE_RAY;
///   image_pipeline.h   HMD_CAMERA, REFLECTIVE_VIEW and AR_VIEW (threaded or inline);
///   hmd_session.h      the SESSION_CONTROL state machine and its refusals;
///   headset_trial.h    the emulated trial answering a REQUEST_TRIAL;
///   interactive.h      the person at the window (--interactive).
///
///   Subscribes: IIWA_STATUS (iiwa_status_t): q of the real robot [rad] (drawn, and the trial's q);
///               ROBOT_STATE (robot_state_t): X_WR, the true robot base (drawn, and the trial's truth);
///               SESSION_CONTROL (session_control_t): START / RESET / STOP / REQUEST_TRIAL;
///               REGISTRATION (registration_t): X_WV_mean, where the hologram is drawn when valid;
///               ALIGNMENT_TRIAL (alignment_trial_t): another's trial of the active session moves
///               the next trial index past it (HmdSession::ObserveTrial);
///               HMD_POSE_TRUTH_<NAME> (hmd_pose_t) with --collaborator NAME: where that headset's
///               camera truly is, display 0 and the trials' first display (CollaboratorDisplay);
///               HOLOGRAMS (hologram_scene_t): the holograms an hl2ss client placed (orbed-hl2ss),
///               drawn with the virtual robot in AR_VIEW and over the REFLECTIVE_VIEW frames while
///               the latest came within 3 s (holograms.h: Unity's primitives at Unity's sizes).
///   Publishes:  HMD_POSE and HMD_POSE_TRUTH (hmd_pose_t) at pose_hz (pose_stream.h);
///               HMD_CAMERA (image_t, JPEG) at camera_hz, REFLECTIVE_VIEW (reflective_view_t) at
///               hmd.reflective_hz per display (--displays), AR_VIEW (image_t, JPEG) at
///               hmd.ar_view_hz (image_pipeline.h), from the latest sample, robot and X_WV;
///               GAZE_RAY (gaze_ray_t) at hmd.gaze_hz (pose_stream.h);
///               ALIGNMENT_TRIAL (alignment_trial_t): one per accepted REQUEST_TRIAL (emulated user)
///               or Enter (interactive); IIWA_COMMAND (interactive, keys , and .: the measured joints
///               with the selected one turned by the rotation step, within the model's limits);
///               SETUP_TASK (interactive, t then
///               Enter: the planned target, task id "interactive-<n>", the guidance's mode or ar);
///               SESSION_CONTROL START once, for a local session, when a person submits in interactive mode
///               with no session active; PROCESS_STATUS at 1 Hz.
/// Drops under load, counted on the heartbeat (Process::CountDrop): "timer/<channel>" for a stream's
/// skipped deadlines (e.g. timer/HMD_POSE), "<channel>/busy" for an image request that replaced one
/// the renderer had not started (HMD_CAMERA/busy, REFLECTIVE_VIEW/busy, AR_VIEW/busy).
///
/// The robot (one RobotState, robot_state.h: the latest valid q and X_WR), the hologram's pose
/// X_WV and what it shows are the core's (hmd.h).
///
/// Sessions (hmd_session.h, hmd.h): an accepted REQUEST_TRIAL runs RunHeadsetTrial()
/// (headset_trial.h) at once, in emulated time, at the latest q against the latest X_WR from the
/// start offset, seeded from (--seed, session, index); then, stamped on the process clock when the
/// run is done, ALIGNMENT_TRIAL {session, index (per session from 0), mode,
/// num_mirrors, q, X_WV, duration_s = the emulated alignment time, user_id "emulated-seed-<user
/// seed>", request_id = the REQUEST_TRIAL's, the tracking faults the person met while aligning
/// (tracking_losses, relocalizations, tracking_wait_s, alignment_repeats)}.
/// Tracking faults (slam.faults, forced for chosen trials; viraal_trial.h): a trial that met any
/// is not answered at once. Its faults are played on the live HMD_POSE stream at their times from
/// the moment the request was accepted (the alignment's start; PoseStream::ScheduleFault), and the
/// ALIGNMENT_TRIAL goes out right after the HMD_POSE of the last one's RELOCALIZED sample: on the
/// bus, REQUEST_TRIAL, then HMD_POSE LIMITED / LOST ... RELOCALIZED, then the trial. Keep the
/// faults' times within the conductor's trial timeout (60 s). Meanwhile a repeat of that request
/// is not acted on (its answer is coming) and another REQUEST_TRIAL is refused
/// (SESSION_CONTROL/busy); START, RESET or STOP drop the trial. In interactive mode REQUEST_TRIAL only tells
/// the person, and the trial submitted next answers it. A repeated request id (a retry, a duplicated
/// datagram) is answered by publishing the same ALIGNMENT_TRIAL again, byte for byte; a repeated
/// START / RESET / STOP changes nothing (hmd_session.h).
///
/// Crash recovery (options.state_file, session_file.h): the session and its last trial are saved on
/// every change (a trial just before it is published), and a headset started on the file continues the
/// session with the next index.
///
/// Rejections (Process::Reject, key "<channel>/<class>"; the process keeps running):
///   IIWA_STATUS/num_joints, /non_finite, /limits (beyond a joint limit by > 0.01 rad);
///   ROBOT_STATE/pose (X_WR not finite or not a unit quaternion);
///   HMD_POSE_TRUTH_<NAME>/pose (the collaborator's X_WC not a world pose, CheckWorldPose);
///   REGISTRATION/pose (a valid mean with a bad X_WV_mean);
///   HOLOGRAMS/<field> (orbed::CheckHologramScene's keys: num_holograms, id, kind, pose, scale,
///   rgba), the whole message refused and the holograms drawn before kept;
///   SESSION_CONTROL/<key> with the keys of hmd_session.h, /trial_failed, and /busy (a request
///   while a trial waits for its tracking faults to play);
///   ALIGNMENT_TRIAL/<key> (orbed::CheckAlignmentTrial's keys) for a bad trial of the active session;
///   and <channel>/decode for undecodable bytes (Process).
///
/// Threading: handlers and timers run on the Process::Run() thread. With options.threaded (the
/// default) the images are made on the pipeline's worker thread, which publishes them itself
/// (LCM's publish is thread-safe), so that a frame never delays a 60 Hz pose. Without it
/// everything runs inline on the Run() thread (deterministic, for tests).
///
/// Clocks: the process clock (Process::ClockSeconds / ClockUtime: the monotonic and wall clocks, or
/// with --sim-time the sim's) runs the pose and gaze timers (the rendered streams' timers stay on
/// the monotonic clock: a renderer's rate is wall frames per second), the walk's time t [s] from the first
/// pose tick (plus the emulated durations of the trials published: the person walked on while aligning), and
/// stamps the poses and trials; the images keep the wall clock of their sample or render (the pipeline's
/// worker thread does not read the process clock), the interactive window too. Frames: W world (= the SLAM
/// map for estimates), H head, C camera, M reversed frustum, R real robot base, V virtual robot base. Units:
/// m, rad, px, Hz; utime µs.

#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/hologram_scene_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/session_control_t.hpp>

#include "hmd_emulator/hmd.h"
#include "hmd_emulator/image_pipeline.h"
#include "runtime/process.h"

namespace orbed::hmd {

class HmdProcess {
 public:
  /// Validates the options (ResolveHmdOptions: std::invalid_argument naming the flag), builds the
  /// core (Headset: loads the URDF, scene and configs, std::runtime_error naming the file and key),
  /// opens LCM (std::runtime_error naming the URL), starts the worker thread (threaded).
  /// Interactive mode opens its window in Run().
  HmdProcess(const orbed::CommonFlags& flags, const HmdOptions& options);
  ~HmdProcess();
  HmdProcess(const HmdProcess&) = delete;
  HmdProcess& operator=(const HmdProcess&) = delete;

  /// Runs until stopped; in interactive mode also until q/Esc (std::runtime_error without a
  /// display). Writes the screenshot at the end.
  int Run();
  orbed::Process& process() { return *process_; }
  const HmdOptions& options() const { return headset_->options(); }
  const HmdConfigSet& config() const { return headset_->config(); }
  /// The live walk's time at the last HMD_POSE [s], and how far the emulated trials have moved it
  /// on (the alignment time not already spent on the live stream) [s].
  double walk_t_s() const { return headset_->walk_t_s(); }
  double walk_offset_s() const { return headset_->walk_offset_s(); }

  // The timers' callbacks, public so tests can drive them without waiting (Run() thread only).
  /// Steps the head and SLAM model to t and publishes HMD_POSE + HMD_POSE_TRUTH (then a trial
  /// whose tracking faults have played).
  void PublishPose();
  void PublishGaze();
  /// Requests (threaded) or makes and publishes (inline) a camera frame / the reflective views /
  /// the AR view from the latest state.
  void RequestCamera();
  void RequestReflective();
  void RequestArView();
  /// Interactive mode: handles one key as if typed (Headset::HandleKey, then its actions).
  void HandleKey(int key);
  /// The window's current picture (interactive mode's content; works without a window).
  cv::Mat CurrentWindowImage();
  /// Waits until the worker has finished every pending request (no-op inline).
  void Flush();

  /// What the hologram shows now (Headset::Hologram on the process clock).
  using HologramShown = hmd::HologramShown;
  static constexpr double kGuidanceFreshS = hmd::kGuidanceFreshS;
  HologramShown Hologram() const { return headset_->Hologram(process_->ClockSeconds()); }

  /// The current X_WV (hmd.h) and the active session ("" when none).
  Eigen::Isometry3d CurrentX_WV() const { return headset_->CurrentX_WV(); }
  const std::string& active_session() const { return headset_->session().state().id; }
  int64_t skipped_frames() const { return pipeline_->skipped(); }

 private:
  HeadsetClock Now() const;
  void ConnectToTheBus(const orbed::CommonFlags& flags);
  void BuildImagePipeline();
  void AddTimers();

  template <typename Message>
  void Listen(const std::string& channel, void (HmdProcess::*handler)(const Message&, const std::string&));
  // Posts `job` with the latest inputs; a request that replaced one not started: "<channel>/busy".
  void Request(ImagePipeline::Job job, const std::string& channel);
  void OnSessionControl(const orbed::session_control_t& msg, const std::string& channel);
  void OnIiwaStatus(const orbed::iiwa_status_t& msg, const std::string& channel);
  void OnRobotState(const orbed::robot_state_t& msg, const std::string& channel);
  void OnRegistration(const orbed::registration_t& msg, const std::string& channel);
  void OnTrial(const orbed::alignment_trial_t& msg, const std::string& channel);
  void OnGuidance(const orbed::guidance_t& msg, const std::string& channel);
  void OnCollaboratorPose(const orbed::hmd_pose_t& msg, const std::string& channel);
  void OnHolograms(const orbed::hologram_scene_t& msg, const std::string& channel);
  /// Carries out the core's actions in HeadsetActions' order; a refusal under "<channel>/<key>".
  void Act(const HeadsetActions& actions, const std::string& channel = "");
  void InteractiveTick();

  std::unique_ptr<Headset> headset_;
  std::unique_ptr<orbed::Process> process_;
  std::unique_ptr<ImagePipeline> pipeline_;
  bool window_open_{false};
};

}  // namespace orbed::hmd
