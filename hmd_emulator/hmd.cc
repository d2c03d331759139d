#include "hmd_emulator/hmd.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "base/format.h"
#include "base/log.h"
#include "base/units.h"
#include "hmd_emulator/holograms.h"
#include "lcmtypes/contract/alignment_trial.h"
#include "lcmtypes/contract/conversions.h"
#include "sim/guidance_messages.h"

static_assert(orbed::hmd::kMaxSessionTrials == orbed::kMaxTrialsPerSession,
              "a session's map is rebuilt for exactly the trials a session holds on the bus");

namespace orbed::hmd {

HmdOptions ResolveHmdOptions(HmdOptions o) {
  if (o.urdf_path.empty()) o.urdf_path = HmdSourcePath(sim::RobotModel::kDefaultUrdfRelativePath);
  if (o.scene_path.empty()) o.scene_path = HmdSourcePath(sim::kDefaultSceneRelativePath);
  for (const auto& [flag, name] : {std::pair{"--headset", o.headset}, std::pair{"--arm", o.arm},
                                   std::pair{"--collaborator", o.collaborator}}) {
    if (!name.empty() && !channels::IsInstanceName(name))
      throw std::invalid_argument(std::string(flag) + " " + name + ": expected " +
                                  channels::kInstanceNameRule);
  }
  if (!o.collaborator.empty() && o.collaborator == o.headset)
    throw std::invalid_argument("--collaborator " + o.collaborator + ": that is this headset");
  for (std::string* channel : {&o.hmd_pose_channel, &o.hmd_pose_truth_channel, &o.camera_channel,
                               &o.gaze_channel, &o.reflective_channel, &o.ar_view_channel, &o.trial_channel,
                               &o.session_control_channel, &o.registration_channel, &o.holograms_channel}) {
    *channel = channels::ForHeadset(*channel, o.headset);
  }
  for (std::string* channel : {&o.iiwa_status_channel, &o.robot_state_channel, &o.iiwa_command_channel,
                               &o.guidance_channel, &o.setup_task_channel}) {
    *channel = channels::ForArm(*channel, o.arm);
  }
  if (!(o.camera_hz > 0 && o.camera_hz <= 1000))
    throw std::invalid_argument("--camera-hz must be in (0, 1000] Hz");
  if (!(o.pose_hz > 0 && o.pose_hz <= 1000)) throw std::invalid_argument("--pose-hz must be in (0, 1000] Hz");
  if (o.jpeg_quality < 1 || o.jpeg_quality > 100)
    throw std::invalid_argument("--jpeg-quality must be in [1, 100]");
  if (!o.screenshot_path.empty() && !o.interactive)
    throw std::invalid_argument("--screenshot needs --interactive (it saves the window's image)");
  return o;
}

Headset::Headset(const HmdOptions& options, std::uint64_t process_seed, double monotonic_s)
    : options_(options), process_seed_(process_seed) {
  LoadConfigs();
  const sim::Scene scene = LoadSceneAndRobot();
  RestoreSession();
  interactive_.emplace(options_.displays, X_WV_start_, options_.scripted_keys, monotonic_s,
                       robot_model_->num_joints());
  stream_ = std::make_unique<PoseStream>(config_, scene, *robot_model_);
  if (!options_.collaborator.empty())
    live_anchor_error_ = AnchorError(config_.hmd.collaborator, process_seed_);
}

// config_: the shipped configs, then --config files over them; --user-seed; --displays checked
// against the displays the config places.
void Headset::LoadConfigs() {
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
sim::Scene Headset::LoadSceneAndRobot() {
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
void Headset::RestoreSession() {
  HmdSessionOptions session_options;
  session_options.displays_placed = static_cast<int>(config_.hmd.displays.size());
  for (const HeadWaypoint& w : config_.walk.waypoints) session_options.waypoint_names.push_back(w.name);
  session_options.iiwa_status_channel = options_.iiwa_status_channel;
  session_options.robot_state_channel = options_.robot_state_channel;
  session_ = HmdSession(session_options);
  if (options_.state_file.empty()) return;
  saved_ = orbed::hmd::RestoreSession(options_.state_file, &session_);
  if (session_.state().active()) {
    ORBED_LOG(kInfo) << "continuing " << session_.state().Describe() << " at trial "
                     << session_.state().next_index << " (state file " << options_.state_file << ")";
  }
}

std::string Headset::Summary() const {
  const HmdOptions& o = options_;
  std::ostringstream out;
  out << "robot " << o.urdf_path << ", scene " << o.scene_path << "; walk of "
      << config_.walk.waypoints.size() << " waypoints (" << Fixed(stream_->trajectory().length_m(), 2)
      << " m), user seed " << config_.user.seed << ", " << o.displays << " reflective display(s); pose "
      << o.pose_hz << " Hz, camera " << o.camera_hz << " Hz" << (o.interactive ? ", interactive" : "");
  return out.str();
}

void Headset::OnJoints(const Eigen::VectorXd& q_rad) {
  robot_.q_rad = q_rad;
  robot_.have_q = true;
}

void Headset::OnRobotBase(const Eigen::Isometry3d& X_WR) {
  robot_.X_WR = X_WR;
  robot_.have_X_WR = true;
}

void Headset::OnCollaboratorCamera(const Eigen::Isometry3d& X_WC_true, std::int64_t utime) {
  collaborator_X_WC_true_ = X_WC_true;
  collaborator_utime_ = utime;
}

void Headset::OnGuidance(const orbed::guidance_t& msg, double clock_s) {
  guidance_ = msg;
  guidance_received_s_ = clock_s;
}

void Headset::OnHolograms(const orbed::hologram_scene_t& msg, double clock_s) {
  orbed::hologram_scene_t scene = msg;
  scene.utime = 0;  // the same scene re-sent is the same scene
  std::vector<std::uint8_t> bytes(scene.getEncodedSize());
  scene.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  if (!holograms_ || bytes != holograms_bytes_) {
    auto mesh = std::make_shared<render::Mesh>();
    TessellateHolograms(msg, {}, mesh.get());
    holograms_ = std::move(mesh);
    holograms_bytes_ = std::move(bytes);
  }
  holograms_received_s_ = clock_s;
}

std::shared_ptr<const render::Mesh> Headset::Holograms(double clock_s) const {
  return clock_s - holograms_received_s_ <= kHologramsFreshS ? holograms_ : nullptr;
}

bool Headset::WantsRegistration(const orbed::registration_t& msg) const {
  if (!msg.valid) return false;                                                // no mean yet: nothing to draw
  return !session_.state().active() || msg.session_id == session_.state().id;  // else another session's
}

bool Headset::WantsTrial(const orbed::alignment_trial_t& msg) const {
  return session_.state().active() && msg.session_id == session_.state().id;
}

HeadsetActions Headset::OnTrial(const orbed::alignment_trial_t& msg) {
  HeadsetActions out;
  if (!session_.ObserveTrial(msg)) return out;  // our own, or one the session is already past
  saved_.last_trial = msg;
  out.save = true;
  ORBED_LOG(kInfo) << "trial " << msg.trial_index << " of '" << msg.session_id
                   << "' came from elsewhere: the next trial is " << session_.state().next_index;
  return out;
}

HeadsetActions Headset::OnSessionControl(const orbed::session_control_t& msg, const HeadsetClock& now) {
  HeadsetActions out;
  if (pending_trial_ && msg.command == orbed::session_control_t::REQUEST_TRIAL) {
    const HmdSessionState& s = session_.state();
    if (msg.session_id == s.id && msg.request_id != 0 && msg.request_id == s.requested_id)
      return out;  // coming
    out.refusal = Refusal{"busy", "REQUEST_TRIAL for session '" + msg.session_id + "' while trial " +
                                      std::to_string(s.next_index) + " of '" + s.id +
                                      "' waits for its tracking faults to play"};
    return out;
  }
  const SessionDecision decision = session_.Handle(msg, RobotKnown{robot_.have_q, robot_.have_X_WR});
  using Kind = SessionDecision::Kind;
  if (decision.kind == Kind::kStart || decision.kind == Kind::kReset || decision.kind == Kind::kStop) {
    pending_trial_.reset();  // not the session's next trial any more
  }
  switch (decision.kind) {
    case Kind::kRefuse:
      out.refusal = decision.refusal;
      break;
    case Kind::kStart:
      saved_ = SavedSession{msg, std::nullopt};
      out.save = true;
      X_WV_registration_.reset();
      X_WV_user_.reset();
      interactive_->SetEvent(decision.event);
      ORBED_LOG(kInfo) << decision.event;
      break;
    case Kind::kReset:
      saved_.last_trial.reset();
      out.save = true;
      break;
    case Kind::kStop:
      saved_ = SavedSession{};
      out.save = true;
      ORBED_LOG(kInfo) << decision.event;
      break;
    case Kind::kRepeatedRequest:
      // A retried or duplicated request: the same answer again (a trial is never made twice).
      out.trial = decision.answer;
      break;
    case Kind::kRequestedTrial:
      if (!options_.interactive) {
        EmulateTrial(&out);
      } else if (!decision.already_requested) {
        const HmdSessionState& s = session_.state();
        ORBED_LOG(kInfo) << interactive_->TrialRequested(s.id, s.next_index, now.monotonic_s);
      }
      break;
    default:
      break;
  }
  return out;
}

void Headset::EmulateTrial(HeadsetActions* out) {
  const HmdSessionState& s = session_.state();
  HeadsetTrialInputs inputs;
  inputs.X_WR = robot_.X_WR;
  inputs.X_WV_start = X_WV_start_;
  inputs.process_seed = process_seed_;
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
    out->refusal = Refusal{"trial_failed", std::string("the emulated trial failed: ") + e.what()};
    return;
  }
  if (outcome.faults.met.empty()) {
    ready_trial_ = std::move(outcome);
    return;
  }
  for (const TimedFault& f : outcome.faults.met) stream_->ScheduleFault(stream_->t_s() + f.at_s, f.fault);
  ORBED_LOG(kInfo) << "trial " << inputs.trial_index << " of '" << s.id << "': " << outcome.faults.met.size()
                   << " tracking fault(s) while aligning, played on " << options_.hmd_pose_channel
                   << " before the answer";
  pending_trial_ = outcome;
  pending_trial_walk_t_s_ = stream_->t_s();
}

HeadsetActions Headset::PublishReadyTrial(std::int64_t clock_utime) {
  HeadsetActions out;
  if (!ready_trial_) return out;
  const TrialOutcome outcome = std::move(*ready_trial_);
  ready_trial_.reset();
  PublishEmulatedTrial(outcome, clock_utime, 0, &out);
  return out;
}

void Headset::PublishEmulatedTrial(const TrialOutcome& outcome, std::int64_t clock_utime, double played_s,
                                   HeadsetActions* out) {
  const HmdSessionState& s = session_.state();
  const std::int32_t index = s.next_index;
  X_WV_user_ = outcome.alignment.X_WV;
  // The person spent the trial's emulated seconds aligning: the live walk goes on from there, so
  // that where the person stands after an alignment is the walk's (its end, for trials of a minute)
  // rather than where the wall time the computation took has put the live walk (on the sim clock
  // at a rate R, R times that). A trial whose tracking faults played live has spent that part
  // of its time on the stream already.
  walk_offset_s_ += std::max(0.0, outcome.alignment.duration_s - played_s);
  PublishTrial(outcome.alignment.X_WV, outcome.alignment.duration_s, user_id_, clock_utime, outcome.faults,
               outcome.annotation, out);
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

void Headset::PublishTrial(const Eigen::Isometry3d& X_WV, double duration_s, const std::string& user_id,
                           std::int64_t clock_utime, const TrackingFaultRecord& faults,
                           const std::vector<AnnotationRay>& annotation, HeadsetActions* out) {
  orbed::alignment_trial_t msg{};
  msg.utime = clock_utime;
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
  // Saved before it goes out (HeadsetActions' order): a headset killed in between restores this
  // very message as the answer to its request id, so the conductor's retry gets these bytes (utime
  // included), never a second, different trial with the same index.
  saved_.last_trial = msg;
  out->save = true;
  session_.RecordTrial(msg);
  out->trial = msg;
}

Headset::PoseStep Headset::StepPose(const HeadsetClock& now) {
  if (!started_) {
    started_ = true;
    t0_s_ = now.clock_s;
  }
  PoseStep step;
  step.poses = stream_->Step(now.clock_s - t0_s_ + walk_offset_s_, now.clock_utime);
  if (pending_trial_ && !stream_->playing_faults()) {
    const TrialOutcome outcome = std::move(*pending_trial_);
    pending_trial_.reset();
    PublishEmulatedTrial(outcome, now.clock_utime, stream_->t_s() - pending_trial_walk_t_s_, &step.actions);
  }
  return step;
}

HeadsetActions Headset::HandleKey(int key, const HeadsetClock& now) {
  HeadsetActions out;
  using Request = InteractiveSession::Request;
  const Request request = interactive_->HandleKey(key);
  const int joint = interactive_->selected_joint();
  const double step_rad = interactive_->joint_step_rad();
  if (request == Request::kRecapture) out.recapture = interactive_->shown_display();
  if (request == Request::kQuit) out.stop = true;
  if (request == Request::kSubmit) SubmitInteractiveTrial(now, &out);
  if (request == Request::kMoveJoint) TurnArmJoint(joint, step_rad, now.wall_utime, &out);
  if (request == Request::kEditTarget) EditTarget(std::nullopt, now.clock_s);
  if (request == Request::kMoveTarget) EditTarget(std::make_pair(joint, step_rad), now.clock_s);
  if (request == Request::kSendTarget) SendPlannedTarget(now, &out);
  return out;
}

void Headset::TurnArmJoint(int joint, double delta_rad, std::int64_t wall_utime, HeadsetActions* out) {
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
  command.utime = wall_utime;
  command.num_joints = static_cast<int32_t>(q.size());
  command.joint_position = FromVectorX(q);
  out->command = command;
  char text[96];
  std::snprintf(text, sizeof(text), "joint %d to %+.1f deg", joint + 1, q[joint] * kRadToDeg);
  interactive_->SetEvent(text);
}

// Planning starts from the guidance's target while one is fresh, else from the arm as it is.
void Headset::EditTarget(std::optional<std::pair<int, double>> turn, double clock_s) {
  if (!interactive_->editing_target()) return;
  if (planned_target_q_.size() == 0) {
    if (const orbed::guidance_t* guidance = FreshGuidance(clock_s)) {
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

void Headset::SendPlannedTarget(const HeadsetClock& now, HeadsetActions* out) {
  if (planned_target_q_.size() == 0) return EditTarget(std::nullopt, now.clock_s);
  orbed::setup_task_t task{};
  task.utime = now.wall_utime;
  task.request_id = task.utime;
  task.task_id = "interactive-" + std::to_string(++planned_targets_sent_);
  task.mode = FreshGuidance(now.clock_s) ? guidance_->mode : +orbed::guidance_t::MODE_AR;
  task.num_joints = static_cast<int32_t>(planned_target_q_.size());
  task.target_position = FromVectorX(planned_target_q_);
  out->task = task;
  interactive_->SetEvent("sent " + task.task_id + " on " + options_.setup_task_channel);
  ORBED_LOG(kInfo) << interactive_->last_event();
}

void Headset::SubmitInteractiveTrial(const HeadsetClock& now, HeadsetActions* out) {
  if (!robot_.known()) {
    interactive_->SetEvent("cannot submit yet: no " + options_.iiwa_status_channel + " / " +
                           options_.robot_state_channel);
    ORBED_LOG(kWarn) << interactive_->last_event();
    return;
  }
  if (!session_.state().active()) {
    // No conductor: a local session, announced so that orbed-registration averages it.
    orbed::session_control_t start{};
    start.utime = now.wall_utime;
    start.session_id = "interactive-" + std::to_string(start.utime / 1000000);
    start.command = orbed::session_control_t::START;
    start.display_mode = options_.displays > 0 ? +orbed::alignment_trial_t::MODE_AR_REFLECTIVE
                                               : +orbed::alignment_trial_t::MODE_AR;
    start.num_mirrors = options_.displays;
    start.method = orbed::registration_t::METHOD_KARCHER;
    session_.Open({start.session_id, start.display_mode, start.num_mirrors, start.method, 0, 0, {}});
    saved_ = SavedSession{start, std::nullopt};
    out->start = start;
  }
  const std::string session_id = session_.state().id;
  const int32_t index = session_.state().next_index;
  const double duration_s = interactive_->Submitted(session_id, index, now.monotonic_s);
  PublishTrial(interactive_->X_WV(), duration_s, "interactive", now.clock_utime, {}, {}, out);
  ORBED_LOG(kInfo) << interactive_->last_event();
}

const orbed::guidance_t* Headset::FreshGuidance(double clock_s) const {
  const double age_s = clock_s - guidance_received_s_;
  return guidance_ && age_s <= kGuidanceFreshS ? &*guidance_ : nullptr;
}

Eigen::Isometry3d Headset::CurrentX_WV() const {
  if (options_.interactive) return interactive_->X_WV();
  if (X_WV_registration_) return *X_WV_registration_;
  if (X_WV_user_) return *X_WV_user_;
  return X_WV_start_;
}

HologramShown Headset::Hologram(double clock_s) const {
  HologramShown shown;
  // A person planning a target sees it.
  if (options_.interactive && interactive_->editing_target() && planned_target_q_.size() > 0) {
    shown.q_rad = shown.reflective_q_rad = planned_target_q_;
    return shown;
  }
  // An alignment session in progress aligns the hologram at the real arm's joints.
  if (session_.state().active() || !FreshGuidance(clock_s)) return shown;
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

FrameInputs Headset::Inputs(double clock_s) const {
  FrameInputs in;
  in.have_sample = stream_->have_sample();
  in.sample = stream_->sample();
  in.sample_utime = stream_->sample_utime();
  in.robot = robot_;
  in.X_WV = CurrentX_WV();
  const HologramShown hologram = Hologram(clock_s);
  in.hide_hologram = hologram.hidden;
  in.q_hologram_rad = hologram.q_rad;
  in.hide_reflective_hologram = hologram.reflective_hidden;
  in.q_reflective_rad = hologram.reflective_q_rad;
  in.t_s = stream_->t_s();
  in.holograms = Holograms(clock_s);
  if (collaborator_X_WC_true_ && in.have_sample) {
    // In this headset's map of the moment, through the shared anchor (CollaboratorView's relation).
    const Eigen::Isometry3d M = in.sample.X_WH_est * in.sample.X_WH_true.inverse();
    in.collaborator = FrameInputs::CollaboratorCamera{
        *collaborator_X_WC_true_, live_anchor_error_ * M * *collaborator_X_WC_true_, collaborator_utime_};
  }
  return in;
}

ImagePipelineOptions Headset::PipelineOptions() const {
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
  return images;
}

cv::Mat Headset::Window(const cv::Mat& ar_view, const cv::Mat& reflective, double clock_s) const {
  const std::string tracking = stream_->have_sample() ? TrackingStateName(stream_->sample().state) : "-";
  const orbed::guidance_t* g = FreshGuidance(clock_s);
  const std::string guidance =
      g ? GuidanceLine(guidance::GuidanceModeName(g->mode), g->error_deg, g->next_joint, g->done) : "";
  return interactive_->Window(ar_view, reflective, session_.state(), CurrentX_WV(), robot_.known(), tracking,
                              guidance);
}

}  // namespace orbed::hmd
