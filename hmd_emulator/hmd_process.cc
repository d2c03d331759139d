#include "hmd_emulator/hmd_process.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <utility>

#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/setup_task_t.hpp>

#include "base/format.h"
#include "base/log.h"
#include "base/units.h"
#include "hmd_emulator/headset_trial.h"
#include "lcmtypes/contract/alignment_trial.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/validation.h"
#include "sim/guidance_messages.h"
#include "sim/iiwa_status_check.h"

static_assert(orbed::hmd::kMaxSessionTrials == orbed::kMaxTrialsPerSession,
              "a session's map is rebuilt for exactly the trials a session holds on the bus");

namespace orbed::hmd {
namespace {

constexpr char kWindowName[] = "orbed-hmd";
constexpr double kInteractiveHz = 30.0;
constexpr double kJointLimitSlackRad = 0.01;
using Clock = std::chrono::steady_clock;

double MonotonicSeconds() { return std::chrono::duration<double>(Clock::now().time_since_epoch()).count(); }

}  // namespace

HmdProcess::HmdProcess(const orbed::CommonFlags& flags, const HmdOptions& options) : options_(options) {
  ResolveOptions();
  LoadConfigs();
  const sim::Scene scene = LoadSceneAndRobot();
  RestoreOrStartSession();
  BuildHeadset(scene);
  ConnectToTheBus(flags);
  BuildImagePipeline();
  AddTimers();
  ORBED_LOG(kInfo) << "robot " << options_.urdf_path << ", scene " << options_.scene_path << "; walk of "
                   << config_.walk.waypoints.size() << " waypoints ("
                   << Fixed(stream_->trajectory().length_m(), 2) << " m), user seed " << config_.user.seed
                   << ", " << options_.displays << " reflective display(s); pose " << options_.pose_hz
                   << " Hz, camera " << options_.camera_hz << " Hz"
                   << (options_.interactive ? ", interactive" : "");
}

// Defaults for the model and the scene, the instance names checked, the channels of this headset
// and arm, the rates and flags checked (std::invalid_argument naming the flag).
void HmdProcess::ResolveOptions() {
  if (options_.urdf_path.empty())
    options_.urdf_path = HmdSourcePath(sim::RobotModel::kDefaultUrdfRelativePath);
  if (options_.scene_path.empty()) options_.scene_path = HmdSourcePath(sim::kDefaultSceneRelativePath);
  for (const auto& [flag, name] : {std::pair{"--headset", options_.headset}, std::pair{"--arm", options_.arm},
                                   std::pair{"--collaborator", options_.collaborator}}) {
    if (!name.empty() && !channels::IsInstanceName(name))
      throw std::invalid_argument(std::string(flag) + " " + name + ": expected " +
                                  channels::kInstanceNameRule);
  }
  if (!options_.collaborator.empty() && options_.collaborator == options_.headset)
    throw std::invalid_argument("--collaborator " + options_.collaborator + ": that is this headset");
  for (std::string* channel :
       {&options_.hmd_pose_channel, &options_.hmd_pose_truth_channel, &options_.camera_channel,
        &options_.gaze_channel, &options_.reflective_channel, &options_.ar_view_channel,
        &options_.trial_channel, &options_.session_control_channel, &options_.registration_channel}) {
    *channel = channels::ForHeadset(*channel, options_.headset);
  }
  for (std::string* channel :
       {&options_.iiwa_status_channel, &options_.robot_state_channel, &options_.iiwa_command_channel,
        &options_.guidance_channel, &options_.setup_task_channel}) {
    *channel = channels::ForArm(*channel, options_.arm);
  }
  if (!(options_.camera_hz > 0 && options_.camera_hz <= 1000)) {
    throw std::invalid_argument("--camera-hz must be in (0, 1000] Hz");
  }
  if (!(options_.pose_hz > 0 && options_.pose_hz <= 1000))
    throw std::invalid_argument("--pose-hz must be in (0, 1000] Hz");
  if (options_.jpeg_quality < 1 || options_.jpeg_quality > 100) {
    throw std::invalid_argument("--jpeg-quality must be in [1, 100]");
  }
  if (!options_.screenshot_path.empty() && !options_.interactive) {
    throw std::invalid_argument("--screenshot needs --interactive (it saves the window's image)");
  }
}

// config_: the shipped configs, then --config files over them; --user-seed; --displays checked
// against the displays the config places.
void HmdProcess::LoadConfigs() {
  std::vector<std::string> paths;
  for (const auto& rel : DefaultHmdConfigRelativePaths()) paths.push_back(HmdSourcePath(rel));
  paths.insert(paths.end(), options_.config_paths.begin(), options_.config_paths.end());
  config_ = LoadHmdConfigs(paths);
  if (options_.user_seed) config_.user.seed = *options_.user_seed;
  const int placed = static_cast<int>(config_.hmd.displays.size());  // reflective displays in hmd.yaml
  if (options_.displays < 0 || options_.displays > placed) {
    throw std::invalid_argument("--displays must be in [0, " + std::to_string(placed) +
                                "]: the config places " + std::to_string(placed) +
                                " reflective display(s) (hmd.displays)");
  }
}

// The scene (standing at --arm's place: config_ moved with it), the robot model with the scene's
// tool, the annotation landmarks checked, the user's id and the hologram's start pose.
sim::Scene HmdProcess::LoadSceneAndRobot() {
  sim::Scene scene = sim::LoadSceneFile(options_.scene_path);
  // Another arm than the single one: the same person walks the same way around that arm.
  const Eigen::Isometry3d X_WR_single = scene.X_WR;
  scene.StandAt(options_.arm);
  if (!options_.arm.empty()) config_ = MovedBy(scene.X_WR * X_WR_single.inverse(), config_);
  // With the scene's tool length, before any geometry copies the tool's primitives.
  robot_model_ = std::make_unique<sim::RobotModel>(sim::LoadRobotForScene(options_.urdf_path, scene));
  // Names every annotation landmark the model lacks now rather than at the first trial.
  AnnotationLandmarkPoints(*robot_model_, config_.hmd, Eigen::VectorXd::Zero(robot_model_->num_joints()));
  user_id_ = "emulated-seed-" + std::to_string(config_.user.seed);
  X_WV_start_ = EmulatedUser(config_.user).StartPose(scene.X_WR);
  return scene;
}

// session_: the SESSION_CONTROL state machine, restored from --state-file when there is one.
void HmdProcess::RestoreOrStartSession() {
  HmdSessionOptions session_options;
  session_options.displays_placed = static_cast<int>(config_.hmd.displays.size());
  for (const HeadWaypoint& w : config_.walk.waypoints) session_options.waypoint_names.push_back(w.name);
  session_options.iiwa_status_channel = options_.iiwa_status_channel;
  session_options.robot_state_channel = options_.robot_state_channel;
  session_ = HmdSession(session_options);
  if (!options_.state_file.empty()) {
    saved_ = RestoreSession(options_.state_file, &session_);
    if (session_.state().active()) {
      ORBED_LOG(kInfo) << "continuing " << session_.state().Describe() << " at trial "
                       << session_.state().next_index << " (state file " << options_.state_file << ")";
    }
  }
}

// The interactive mode's state and the walk + SLAM pose stream.
void HmdProcess::BuildHeadset(const sim::Scene& scene) {
  interactive_.emplace(options_.displays, X_WV_start_, options_.scripted_keys, MonotonicSeconds(),
                       robot_model_->num_joints());
  stream_ = std::make_unique<PoseStream>(config_, scene, *robot_model_);
}

// process_ (on the clock of the arm it looks at) and every subscription.
void HmdProcess::ConnectToTheBus(const orbed::CommonFlags& flags) {
  orbed::CommonFlags process_flags = flags;
  process_flags.sim_clock_arm = options_.arm;  // --sim-time follows the clock of the arm it looks at
  process_ = std::make_unique<orbed::Process>(process_flags);
  process_->Subscribe<orbed::iiwa_status_t>(
      options_.iiwa_status_channel,
      [this](const orbed::iiwa_status_t& m, const std::string& ch, int64_t) { OnIiwaStatus(m, ch); });
  process_->Subscribe<orbed::robot_state_t>(
      options_.robot_state_channel,
      [this](const orbed::robot_state_t& m, const std::string& ch, int64_t) { OnRobotState(m, ch); });
  process_->Subscribe<orbed::session_control_t>(
      options_.session_control_channel,
      [this](const orbed::session_control_t& m, const std::string& ch, int64_t) { OnSessionControl(m, ch); });
  process_->Subscribe<orbed::registration_t>(
      options_.registration_channel,
      [this](const orbed::registration_t& m, const std::string& ch, int64_t) { OnRegistration(m, ch); });
  process_->Subscribe<orbed::guidance_t>(
      options_.guidance_channel,
      [this](const orbed::guidance_t& m, const std::string& ch, int64_t) { OnGuidance(m, ch); });
  if (!options_.collaborator.empty()) {
    live_anchor_error_ = AnchorError(config_.hmd.collaborator, process_->seed());
    process_->Subscribe<orbed::hmd_pose_t>(
        channels::ForHeadset(channels::kHmdPoseTruth, options_.collaborator),
        [this](const orbed::hmd_pose_t& m, const std::string& ch, int64_t) { OnCollaboratorPose(m, ch); });
  }
  process_->Subscribe<orbed::alignment_trial_t>(
      options_.trial_channel,
      [this](const orbed::alignment_trial_t& m, const std::string& ch, int64_t) { OnTrial(m, ch); });
}

// pipeline_: the camera frame, reflective views and AR view, published through process_.
void HmdProcess::BuildImagePipeline() {
  ImagePipelineOptions images;
  images.jpeg_quality = options_.jpeg_quality;
  const HeadTrajectory& walk = stream_->trajectory();
  for (int i = 0; i < options_.displays; ++i) {
    images.display_capture_t_s.push_back(
        walk.ArrivalTime(walk.FindWaypoint(config_.hmd.displays[i].capture_waypoint)));
  }
  images.recapture_period_s = config_.hmd.recapture_period_s;
  images.gaze_fallback_distance_m = config_.hmd.gaze_fallback_distance_m;
  images.max_gaze_distance_m = config_.hmd.max_gaze_distance_m;
  images.threaded = options_.threaded;
  ImagePipelineOutputs out;  // called on the worker thread when threaded
  orbed::Process* process = process_.get();
  // The rendered streams run on the wall clock and no process acts on them within a sim tick: they
  // are not publications a lockstep round waits on (else at ~65 frames/s every round would ask
  // for another).
  out.camera = [process, ch = options_.camera_channel](const orbed::image_t& m) {
    process->PublishControl(ch, m);
  };
  out.reflective = [process, ch = options_.reflective_channel](const orbed::reflective_view_t& m) {
    process->PublishControl(ch, m);
  };
  out.ar_view = [process, ch = options_.ar_view_channel](const orbed::image_t& m) {
    process->PublishControl(ch, m);
  };
  out.error = [process](const std::string& error, int64_t count) {
    // Shown as last_error on the heartbeat; an engine error must not take the process down.
    process->SetLastError(error);
    if (count <= 5) ORBED_LOG(kError) << error;
  };
  pipeline_ = std::make_unique<ImagePipeline>(*robot_model_, stream_->scene_objects(), images, out);
}

// The pose and gaze timers on the process clock, the rendered streams' on the wall clock.
void HmdProcess::AddTimers() {
  // Named by what they publish: a timer that falls behind counts its skipped deadlines as
  // "timer/<channel>" drops on the heartbeat.
  process_->AddTimer(
      1.0 / options_.pose_hz, [this] { PublishPose(); }, options_.hmd_pose_channel);
  process_->AddTimer(
      1.0 / config_.hmd.gaze_hz, [this] { PublishGaze(); }, options_.gaze_channel);
  // The rendered streams keep their rates in wall time, also on the sim clock (--sim-time): at a
  // realtime rate R their sim-time rates would be R times the renderer's (30 Hz of 1280x720 at
  // R = 10 is 300 frames a second), every frame it cannot make a counted drop. Nothing in the
  // set-up loop reads images; they show the latest pose sample.
  process_->AddWallTimer(
      1.0 / options_.camera_hz, [this] { RequestCamera(); }, options_.camera_channel);
  if (options_.displays > 0)
    process_->AddWallTimer(
        1.0 / config_.hmd.reflective_hz, [this] { RequestReflective(); }, options_.reflective_channel);
  process_->AddWallTimer(
      1.0 / config_.hmd.ar_view_hz, [this] { RequestArView(); }, options_.ar_view_channel);
  if (options_.interactive)
    process_->AddWallTimer(
        1.0 / kInteractiveHz, [this] { InteractiveTick(); }, "interactive");
}

HmdProcess::~HmdProcess() {
  pipeline_.reset();  // joins the worker before anything it uses goes
  if (window_open_) cv::destroyAllWindows();
}

void HmdProcess::Flush() { pipeline_->Flush(); }

Eigen::Isometry3d HmdProcess::CurrentX_WV() const {
  if (options_.interactive) return interactive_->X_WV();
  if (X_WV_registration_) return *X_WV_registration_;
  if (X_WV_user_) return *X_WV_user_;
  return X_WV_start_;
}

FrameInputs HmdProcess::Inputs() const {
  FrameInputs in;
  in.have_sample = stream_->have_sample();
  in.sample = stream_->sample();
  in.sample_utime = stream_->sample_utime();
  in.robot = robot_;
  in.X_WV = CurrentX_WV();
  const HologramShown hologram = Hologram();
  in.hide_hologram = hologram.hidden;
  in.q_hologram_rad = hologram.q_rad;
  in.hide_reflective_hologram = hologram.reflective_hidden;
  in.q_reflective_rad = hologram.reflective_q_rad;
  in.t_s = stream_->t_s();
  if (collaborator_X_WC_true_ && in.have_sample) {
    // In this headset's map of the moment, through the shared anchor (CollaboratorView's relation).
    const Eigen::Isometry3d M = in.sample.X_WH_est * in.sample.X_WH_true.inverse();
    in.collaborator = FrameInputs::CollaboratorCamera{
        *collaborator_X_WC_true_, live_anchor_error_ * M * *collaborator_X_WC_true_, collaborator_utime_};
  }
  return in;
}

void HmdProcess::PublishPose() {
  // The process clock: the monotonic one, or the sim's (--sim-time), on which the walk keeps its
  // order with the arm at any realtime rate of the sim.
  const double now_s = process_->ClockSeconds();
  if (!started_) {
    started_ = true;
    t0_s_ = now_s;
  }
  const PoseStream::Poses poses = stream_->Step(now_s - t0_s_ + walk_offset_s_, process_->ClockUtime());
  process_->Publish(options_.hmd_pose_channel, poses.estimate);
  process_->Publish(options_.hmd_pose_truth_channel, poses.truth);
  if (pending_trial_ && !stream_->playing_faults()) {
    const TrialOutcome outcome = std::move(*pending_trial_);
    pending_trial_.reset();
    PublishEmulatedTrial(outcome, stream_->t_s() - pending_trial_walk_t_s_);
  }
}

void HmdProcess::PublishGaze() {
  if (const auto gaze = stream_->Gaze(robot_)) process_->Publish(options_.gaze_channel, *gaze);
}

// A request that replaces one the renderer has not started is a frame never made: a drop
// "<channel>/busy" on the heartbeat.
void HmdProcess::RequestCamera() {
  if (pipeline_->Post(ImagePipeline::Job::kCamera, Inputs()))
    process_->CountDrop(options_.camera_channel + "/busy");
}
void HmdProcess::RequestReflective() {
  if (pipeline_->Post(ImagePipeline::Job::kReflective, Inputs()))
    process_->CountDrop(options_.reflective_channel + "/busy");
}
void HmdProcess::RequestArView() {
  if (pipeline_->Post(ImagePipeline::Job::kArView, Inputs(), true))
    process_->CountDrop(options_.ar_view_channel + "/busy");
}

void HmdProcess::OnIiwaStatus(const orbed::iiwa_status_t& msg, const std::string& channel) {
  Eigen::VectorXd q;
  const sim::IiwaStatusProblem problem = sim::CheckIiwaStatus(msg, *robot_model_, kJointLimitSlackRad, &q);
  if (!problem.rejection_class.empty())
    return process_->Reject(channel + "/" + problem.rejection_class, problem.reason);
  robot_.q_rad = q;
  robot_.have_q = true;
}

void HmdProcess::OnCollaboratorPose(const orbed::hmd_pose_t& msg, const std::string& channel) {
  const std::string error = CheckWorldPose(msg.X_WC, "X_WC");
  if (!error.empty()) return process_->Reject(channel + "/pose", error);
  collaborator_X_WC_true_ = FromPose(msg.X_WC);
  collaborator_utime_ = msg.utime;
}

void HmdProcess::OnRobotState(const orbed::robot_state_t& msg, const std::string& channel) {
  const std::string error = CheckPose(msg.X_WR, "X_WR");
  if (!error.empty()) return process_->Reject(channel + "/pose", error);
  robot_.X_WR = FromPose(msg.X_WR);
  robot_.have_X_WR = true;
}

void HmdProcess::OnGuidance(const orbed::guidance_t& msg, const std::string& channel) {
  const std::string problem = guidance::CheckGuidance(msg, *robot_model_, kJointLimitSlackRad);
  if (!problem.empty()) return process_->Reject(channel + "/field", problem);
  guidance_ = msg;
  guidance_received_s_ = process_->ClockSeconds();
}

HmdProcess::HologramShown HmdProcess::Hologram() const {
  HologramShown shown;
  // A person planning a target sees it.
  if (options_.interactive && interactive_->editing_target() && planned_target_q_.size() > 0) {
    shown.q_rad = shown.reflective_q_rad = planned_target_q_;
    return shown;
  }
  // An alignment session in progress aligns the hologram at the real arm's joints.
  if (session_.state().active() || !FreshGuidance()) return shown;
  if (guidance_->mode == orbed::guidance_t::MODE_FIXED_DISPLAY) {
    shown.hidden = shown.reflective_hidden = true;
    return shown;
  }
  shown.q_rad = Eigen::Map<const Eigen::VectorXd>(guidance_->target_position.data(), guidance_->num_joints);
  if (guidance_->mode == orbed::guidance_t::MODE_AR_REFLECTIVE) {
    shown.reflective_q_rad = shown.q_rad;
  } else {
    shown.reflective_hidden = true;
  }
  return shown;
}

void HmdProcess::OnRegistration(const orbed::registration_t& msg, const std::string& channel) {
  if (!msg.valid) return;  // no mean yet: nothing to draw
  if (session_.state().active() && msg.session_id != session_.state().id) return;  // another session's
  const std::string error = CheckPose(msg.X_WV_mean, "X_WV_mean");
  if (!error.empty()) return process_->Reject(channel + "/pose", error);
  X_WV_registration_ = FromPose(msg.X_WV_mean);
}

void HmdProcess::OnSessionControl(const orbed::session_control_t& msg, const std::string& channel) {
  if (pending_trial_ && msg.command == orbed::session_control_t::REQUEST_TRIAL) {
    const HmdSessionState& s = session_.state();
    if (msg.session_id == s.id && msg.request_id != 0 && msg.request_id == s.requested_id) return;  // coming
    return process_->Reject(channel + "/busy", "REQUEST_TRIAL for session '" + msg.session_id +
                                                   "' while trial " + std::to_string(s.next_index) + " of '" +
                                                   s.id + "' waits for its tracking faults to play");
  }
  const SessionDecision decision = session_.Handle(msg, RobotKnown{robot_.have_q, robot_.have_X_WR});
  if (decision.kind == SessionDecision::Kind::kStart || decision.kind == SessionDecision::Kind::kReset ||
      decision.kind == SessionDecision::Kind::kStop) {
    pending_trial_.reset();  // not the session's next trial any more
  }
  switch (decision.kind) {
    case SessionDecision::Kind::kRefuse:
      return process_->Reject(channel + "/" + decision.refusal.key, decision.refusal.reason);
    case SessionDecision::Kind::kStart:
      saved_ = SavedSession{msg, std::nullopt};
      SaveState();
      X_WV_registration_.reset();
      X_WV_user_.reset();
      interactive_->SetEvent(decision.event);
      ORBED_LOG(kInfo) << decision.event;
      return;
    case SessionDecision::Kind::kReset:
      saved_.last_trial.reset();
      SaveState();
      return;
    case SessionDecision::Kind::kStop:
      saved_ = SavedSession{};
      SaveState();
      ORBED_LOG(kInfo) << decision.event;
      return;
    case SessionDecision::Kind::kRepeatedRequest:
      // A retried or duplicated request: the same answer again (a trial is never made twice).
      if (decision.answer) process_->Publish(options_.trial_channel, *decision.answer);
      return;
    case SessionDecision::Kind::kRequestedTrial:
      if (options_.interactive) {
        const HmdSessionState& s = session_.state();
        if (!decision.already_requested) {
          ORBED_LOG(kInfo) << interactive_->TrialRequested(s.id, s.next_index, MonotonicSeconds());
        }
        return;
      }
      return EmulateTrial(channel);
    default:
      return;
  }
}

void HmdProcess::EmulateTrial(const std::string& channel) {
  const HmdSessionState& s = session_.state();
  HeadsetTrialInputs inputs;
  inputs.X_WR = robot_.X_WR;
  inputs.X_WV_start = X_WV_start_;
  inputs.process_seed = process_->seed();
  inputs.session_id = s.id;
  inputs.trial_index = s.next_index;
  inputs.num_mirrors = s.num_mirrors;
  inputs.capture_waypoints = s.capture_waypoints;
  inputs.collaborator_X_WC_true = collaborator_X_WC_true_;
  TrialOutcome outcome;
  try {
    SetRobotAt(*robot_model_, robot_.q_rad, &inputs);
    inputs.p_RL = AnnotationLandmarkPoints(*robot_model_, config_.hmd, robot_.q_rad);
    outcome = RunHeadsetTrial(config_, inputs, &session_map_);
  } catch (const std::exception& e) {
    return process_->Reject(channel + "/trial_failed", std::string("the emulated trial failed: ") + e.what());
  }
  if (outcome.faults.met.empty()) return PublishEmulatedTrial(outcome);
  for (const TimedFault& f : outcome.faults.met) stream_->ScheduleFault(stream_->t_s() + f.at_s, f.fault);
  ORBED_LOG(kInfo) << "trial " << inputs.trial_index << " of '" << s.id << "': " << outcome.faults.met.size()
                   << " tracking fault(s) while aligning, played on " << options_.hmd_pose_channel
                   << " before the answer";
  pending_trial_ = outcome;
  pending_trial_walk_t_s_ = stream_->t_s();
}

double HmdProcess::walk_t_s() const { return stream_->t_s(); }

void HmdProcess::PublishEmulatedTrial(const TrialOutcome& outcome, double played_s) {
  const HmdSessionState& s = session_.state();
  const std::int32_t index = s.next_index;
  X_WV_user_ = outcome.alignment.X_WV;
  // The person spent the trial's emulated seconds aligning: the live walk goes on from there, so
  // that where the person stands after an alignment is the walk's (its end, for trials of a minute)
  // rather than where the wall time the computation took has put the live walk (on the sim clock
  // at a rate R, R times that). A trial whose tracking faults played live has spent that part
  // of its time on the stream already.
  walk_offset_s_ += std::max(0.0, outcome.alignment.duration_s - played_s);
  PublishTrial(outcome.alignment.X_WV, outcome.alignment.duration_s, user_id_, outcome.faults,
               outcome.annotation);
  const TrackingFaultRecord& f = outcome.faults;
  ORBED_LOG(kInfo) << "trial " << index << " of '" << s.id << "' (" << DisplayModeName(s.display_mode) << ", "
                   << s.num_mirrors << " display(s)): " << outcome.alignment.stop_reason << " after "
                   << outcome.alignment.nudges << " nudges, " << Fixed(outcome.alignment.duration_s, 1)
                   << " s emulated; error vs truth "
                   << Fixed(outcome.registration.translation_error_m * 1e3, 1) << " mm, "
                   << Fixed(outcome.registration.rotation_error_deg, 2) << " deg"
                   << (f.losses > 0
                           ? "; tracking lost " + std::to_string(f.losses) + "x, waited " +
                                 Fixed(f.wait_s, 1) + " s, re-aligned " + std::to_string(f.repeats) + "x"
                           : "");
}

void HmdProcess::PublishTrial(const Eigen::Isometry3d& X_WV, double duration_s, const std::string& user_id,
                              const TrackingFaultRecord& faults,
                              const std::vector<AnnotationRay>& annotation) {
  orbed::alignment_trial_t msg{};
  msg.utime = process_->ClockUtime();
  msg.session_id = session_.state().id;
  msg.trial_index = session_.TakeTrialIndex();
  msg.display_mode = session_.state().display_mode;
  msg.num_mirrors = session_.state().num_mirrors;
  msg.num_joints = static_cast<int32_t>(robot_.q_rad.size());
  msg.joint_position = FromVectorX(robot_.q_rad);
  msg.X_WV = ToPose(X_WV);
  msg.duration_s = duration_s;
  msg.user_id = user_id;
  msg.request_id = session_.state().requested_id;
  msg.tracking_losses = faults.losses;
  msg.relocalizations = faults.relocalizations;
  msg.tracking_wait_s = faults.wait_s;
  msg.alignment_repeats = faults.repeats;
  SetAnnotationFields(annotation, &msg);
  // Saved before it goes out: a headset killed in between restores this very message as the answer
  // to its request id, so the conductor's retry gets these bytes (utime included), never a second,
  // different trial with the same index.
  saved_.last_trial = msg;
  SaveState();
  session_.RecordTrial(msg);
  process_->Publish(options_.trial_channel, msg);
}

void HmdProcess::OnTrial(const orbed::alignment_trial_t& msg, const std::string& channel) {
  if (!session_.state().active() || msg.session_id != session_.state().id) return;  // not ours
  const auto checked = CheckAlignmentTrial(msg, robot_model_->num_joints());
  if (const auto* refusal = std::get_if<Refusal>(&checked)) {
    return process_->Reject(channel + "/" + refusal->key, refusal->reason);
  }
  if (!session_.ObserveTrial(msg)) return;  // our own, or one the session is already past
  saved_.last_trial = msg;
  SaveState();
  ORBED_LOG(kInfo) << "trial " << msg.trial_index << " of '" << msg.session_id
                   << "' came from elsewhere: the next trial is " << session_.state().next_index;
}

void HmdProcess::SaveState() {
  if (options_.state_file.empty()) return;
  std::string error;
  if (SaveSession(options_.state_file, saved_, &error)) return;
  process_->SetLastError(error);
  ORBED_LOG(kError) << error;
}

void HmdProcess::HandleKey(int key) {
  switch (interactive_->HandleKey(key)) {
    case InteractiveSession::Request::kRecapture:
      return pipeline_->RequestRecapture(interactive_->shown_display());
    case InteractiveSession::Request::kQuit:
      return process_->RequestStop();
    case InteractiveSession::Request::kSubmit:
      return SubmitInteractiveTrial();
    case InteractiveSession::Request::kMoveJoint:
      return TurnArmJoint(interactive_->selected_joint(), interactive_->joint_step_rad());
    case InteractiveSession::Request::kEditTarget:
      return EditTarget(std::nullopt);
    case InteractiveSession::Request::kMoveTarget:
      return EditTarget(std::make_pair(interactive_->selected_joint(), interactive_->joint_step_rad()));
    case InteractiveSession::Request::kSendTarget:
      return SendPlannedTarget();
    default:
      return;
  }
}

void HmdProcess::TurnArmJoint(int joint, double delta_rad) {
  if (!robot_.have_q) {
    interactive_->SetEvent("cannot turn a joint yet: no " + options_.iiwa_status_channel);
    return;
  }
  // Every press starts from the arm as measured, so nothing else the arm did since is undone and a
  // press back after a collision stop backs it out.
  Eigen::VectorXd q = robot_.q_rad;
  q[joint] = std::clamp(q[joint] + delta_rad, robot_model_->lower_limits_rad()[joint],
                        robot_model_->upper_limits_rad()[joint]);
  orbed::iiwa_command_t command{};
  command.utime = NowMicros();
  command.num_joints = static_cast<int32_t>(q.size());
  command.joint_position = FromVectorX(q);
  process_->Publish(options_.iiwa_command_channel, command);
  char text[96];
  std::snprintf(text, sizeof(text), "joint %d to %+.1f deg", joint + 1, q[joint] * kRadToDeg);
  interactive_->SetEvent(text);
}

// Planning starts from the guidance's target while one is fresh, else from the arm as it is.
void HmdProcess::EditTarget(std::optional<std::pair<int, double>> turn) {
  if (!interactive_->editing_target()) return;
  if (planned_target_q_.size() == 0) {
    if (const orbed::guidance_t* guidance = FreshGuidance()) {
      planned_target_q_ = ToVectorX(guidance->target_position);
    } else if (robot_.have_q) {
      planned_target_q_ = robot_.q_rad;
    } else {
      interactive_->SetEvent("cannot plan yet: no " + options_.iiwa_status_channel + " and no GUIDANCE");
      return;
    }
  }
  if (!turn) return;
  const auto [joint, delta_rad] = *turn;
  planned_target_q_[joint] =
      std::clamp(planned_target_q_[joint] + delta_rad, robot_model_->lower_limits_rad()[joint],
                 robot_model_->upper_limits_rad()[joint]);
  char text[96];
  std::snprintf(text, sizeof(text), "planned target: joint %d at %+.1f deg", joint + 1,
                planned_target_q_[joint] * kRadToDeg);
  interactive_->SetEvent(text);
}

void HmdProcess::SendPlannedTarget() {
  if (planned_target_q_.size() == 0) return EditTarget(std::nullopt);
  orbed::setup_task_t task{};
  task.utime = NowMicros();
  task.request_id = task.utime;
  task.task_id = "interactive-" + std::to_string(++planned_targets_sent_);
  task.mode = FreshGuidance() ? guidance_->mode : +orbed::guidance_t::MODE_AR;
  task.num_joints = static_cast<int32_t>(planned_target_q_.size());
  task.target_position = FromVectorX(planned_target_q_);
  process_->Publish(options_.setup_task_channel, task);
  interactive_->SetEvent("sent " + task.task_id + " on " + options_.setup_task_channel);
  ORBED_LOG(kInfo) << interactive_->last_event();
}

const orbed::guidance_t* HmdProcess::FreshGuidance() const {
  const double age_s = process_->ClockSeconds() - guidance_received_s_;
  return guidance_ && age_s <= kGuidanceFreshS ? &*guidance_ : nullptr;
}

std::string HmdProcess::GuidanceStatus() const {
  const orbed::guidance_t* g = FreshGuidance();
  return g ? GuidanceLine(guidance::GuidanceModeName(g->mode), g->error_deg, g->next_joint, g->done) : "";
}

void HmdProcess::SubmitInteractiveTrial() {
  if (!robot_.known()) {
    interactive_->SetEvent("cannot submit yet: no " + options_.iiwa_status_channel + " / " +
                           options_.robot_state_channel);
    ORBED_LOG(kWarn) << interactive_->last_event();
    return;
  }
  if (!session_.state().active()) {
    // No conductor: a local session, announced so that orbed-registration averages it.
    orbed::session_control_t start{};
    start.utime = NowMicros();
    start.session_id = "interactive-" + std::to_string(start.utime / 1000000);
    start.command = orbed::session_control_t::START;
    start.display_mode = options_.displays > 0 ? +orbed::alignment_trial_t::MODE_AR_REFLECTIVE
                                               : +orbed::alignment_trial_t::MODE_AR;
    start.num_mirrors = options_.displays;
    start.method = orbed::registration_t::METHOD_KARCHER;
    session_.Open({start.session_id, start.display_mode, start.num_mirrors, start.method, 0, 0, {}});
    saved_ = SavedSession{start, std::nullopt};
    process_->Publish(options_.session_control_channel, start);
  }
  const std::string session_id = session_.state().id;
  const int32_t index = session_.state().next_index;
  const double duration_s = interactive_->Submitted(session_id, index, MonotonicSeconds());
  PublishTrial(interactive_->X_WV(), duration_s, "interactive");
  ORBED_LOG(kInfo) << interactive_->last_event();
}

cv::Mat HmdProcess::CurrentWindowImage() {
  const std::string tracking = stream_->have_sample() ? TrackingStateName(stream_->sample().state) : "-";
  return interactive_->Window(pipeline_->LatestArView(),
                              pipeline_->LatestReflective(interactive_->shown_display()), session_.state(),
                              CurrentX_WV(), robot_.known(), tracking, GuidanceStatus());
}

void HmdProcess::InteractiveTick() {
  pipeline_->Post(ImagePipeline::Job::kArView, Inputs(), false);  // the window's AR view, at the window rate
  const cv::Mat window = CurrentWindowImage();
  if (window_open_) cv::imshow(kWindowName, window);
  const int key = window_open_ ? cv::waitKey(1) : -1;
  const int scripted = interactive_->NextScriptedKey();
  if (scripted >= 0) HandleKey(scripted);
  if (key >= 0) HandleKey(key);
}

int HmdProcess::Run() {
  if (options_.interactive) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) {
      throw std::runtime_error(
          "--interactive needs an X display ($DISPLAY is not set); on a headless machine run "
          "it under `xvfb-run -a`");
    }
    try {
      cv::namedWindow(kWindowName, cv::WINDOW_AUTOSIZE);
    } catch (const cv::Exception& e) {
      throw std::runtime_error(std::string("--interactive: cannot open a window: ") + e.what());
    }
    window_open_ = true;
    interactive_->RestartTimer(MonotonicSeconds());
    for (const auto& line : InteractiveHelpLines()) ORBED_LOG(kInfo) << "keys: " << line;
  }
  const int code = process_->Run();
  pipeline_->Flush();
  ORBED_LOG(kInfo) << "camera frames rendered " << pipeline_->rendered() << ", reused " << pipeline_->reused()
                   << ", requests skipped (worker busy) " << pipeline_->skipped();
  if (options_.interactive && !options_.screenshot_path.empty()) {
    const cv::Mat image = CurrentWindowImage();
    if (!cv::imwrite(options_.screenshot_path, image)) {
      ORBED_LOG(kError) << "cannot write the screenshot " << options_.screenshot_path;
      return 1;
    }
    ORBED_LOG(kInfo) << "screenshot " << options_.screenshot_path << " (" << image.cols << "x" << image.rows
                     << ")";
  }
  return code;
}

}  // namespace orbed::hmd
