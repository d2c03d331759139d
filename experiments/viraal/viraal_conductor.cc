#include "experiments/viraal/viraal_conductor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "base/format.h"
#include "base/units.h"
#include "experiments/viraal/exchange.h"
#include "lcmtypes/contract/alignment_trial.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/validation.h"

namespace orbed::scenario {
namespace {

constexpr int kMaxJoints = 64;
constexpr int kMaxPairs = 10000;
// Only a ROBOT_STATE received this long after the last IIWA_COMMAND counts as a stop [s].
constexpr double kFreshStateAfterCommand_s = 0.050;

std::string JointList(const std::vector<double>& q_deg, int digits) {
  std::string out = "(";
  for (size_t i = 0; i < q_deg.size(); ++i) out += (i ? ", " : "") + Fixed(q_deg[i], digits);
  return out + ")";
}

}  // namespace

void CheckConductorOptions(const ConductorOptions& options) {
  const std::pair<const char*, double> positive[] = {{"--tolerance-deg", options.tolerance_deg},
                                                     {"--startup-timeout-s", options.startup_timeout_s},
                                                     {"--request-deadline-s", options.request_deadline_s},
                                                     {"--move-timeout-s", options.move_timeout_s},
                                                     {"--stopped-grace-s", options.stopped_grace_s},
                                                     {"command resend period", options.command_resend_s},
                                                     {"--retry-initial-s", options.retry_initial_s},
                                                     {"--retry-max-s", options.retry_max_s}};
  for (const auto& [name, value] : positive) {
    if (!(value > 0) || !std::isfinite(value)) {
      throw std::invalid_argument(std::string(name) + " must be a finite number > 0");
    }
  }
  if (options.retry_max_s < options.retry_initial_s) {
    throw std::invalid_argument("--retry-max-s must be >= --retry-initial-s");
  }
}

void UseInstanceChannels(ConductorOptions* o, const std::string& headset, const std::string& arm) {
  for (std::string* channel : {&o->session_control_channel, &o->trial_channel, &o->registration_channel,
                               &o->landmark_request_channel, &o->landmark_channel,
                               &o->misalignment_request_channel, &o->misalignment_channel}) {
    *channel = channels::ForHeadset(*channel, headset);
  }
  for (std::string* channel : {&o->robot_state_channel, &o->iiwa_command_channel,
                               &o->plan_check_request_channel, &o->plan_check_reply_channel}) {
    *channel = channels::ForArm(*channel, arm);
  }
}

ViraalConductor::ViraalConductor(ConductorOptions options, orbed::sim::RobotModel model)
    : options_(std::move(options)), model_(std::make_unique<orbed::sim::RobotModel>(std::move(model))) {
  CheckConductorOptions(options_);
  if (options_.run_id.empty()) throw std::invalid_argument("the run id is empty");
  const viraal::ScenarioConfig& config = options_.config;
  viraal::ValidateScenarioConfig(config, model_->num_joints());
  for (size_t k = 0; k < config.configurations_deg.size(); ++k) {
    const std::string why =
        model_->ValidateJointVector(orbed::sim::DegToRad(ToVectorX(config.configurations_deg[k])));
    if (!why.empty()) throw std::invalid_argument("configuration " + std::to_string(k) + ": " + why);
  }
  points_ = std::make_unique<viraal::RobotPointSet>(*model_, config.landmarks);
  results_.run_id = options_.run_id;
  results_.seed = options_.seed;
  results_.landmarks = config.landmarks;
  results_.configurations_deg = config.configurations_deg;
  results_.resumed_from = options_.resumed_from;
  results_.sessions = options_.kept_sessions;
  while (mode_index_ < results_.sessions.size() && results_.sessions[mode_index_].mean) ++mode_index_;
}

ViraalConductor::~ViraalConductor() = default;

ViraalConductor::Status ViraalConductor::status() const {
  if (phase_ != Phase::kDone) return Status::kRunning;
  return results_.ok ? Status::kSucceeded : Status::kFailed;
}

// ---------------------------------------------------------------------------------------------
// Calls

void ViraalConductor::Begin(const ConductorTime& now) {
  if (phase_ == Phase::kNotStarted) throw std::logic_error("ViraalConductor: an input before Start()");
  now_ = now;
  actions_.clear();
}

ConductorActions ViraalConductor::TakeActions() {
  ConductorActions out;
  out.swap(actions_);
  return out;
}

ConductorActions ViraalConductor::Start(const ConductorTime& now) {
  if (phase_ != Phase::kNotStarted) throw std::logic_error("ViraalConductor: Start() twice");
  now_ = now;
  actions_.clear();
  run_start_s_ = phase_start_s_ = last_command_s_ = now.t_s;
  results_.started_utime = now.utime;
  request_id_base_ = now.utime;
  phase_ = Phase::kWaitRobot;
  Say("ViRAAl run " + options_.run_id + ": waiting for the robot (" + options_.robot_state_channel + ")");
  return TakeActions();
}

ConductorActions ViraalConductor::Tick(const ConductorTime& now) {
  Begin(now);
  Step();
  return TakeActions();
}

ConductorActions ViraalConductor::Abort(const std::string& reason, const ConductorTime& now) {
  Begin(now);
  FailRun(reason);
  return TakeActions();
}

// ---------------------------------------------------------------------------------------------
// Handlers: validate, record, advance.

ConductorActions ViraalConductor::OnRobotState(const orbed::robot_state_t& msg, const ConductorTime& now) {
  Begin(now);
  const std::string problem = CheckRobotState(msg, model_->num_joints());
  if (!problem.empty()) {
    Refuse(options_.robot_state_channel + "/field", problem);
    return TakeActions();
  }
  robot_state_ = msg;
  robot_state_received_s_ = now_.t_s;
  if (phase_ == Phase::kWaitRobot || phase_ == Phase::kMove) Step();
  return TakeActions();
}

ConductorActions ViraalConductor::OnPlanCheckReply(const orbed::plan_check_reply_t& msg,
                                                   const ConductorTime& now) {
  Begin(now);
  if (phase_ != Phase::kCheckPlans) return TakeActions();  // not ours, or a late repeat
  size_t k = 0;
  while (k < plan_requests_.size() && plan_requests_[k].request_id != msg.request_id) ++k;
  if (k == plan_requests_.size()) return TakeActions();  // not ours
  const std::string problem =
      CheckLength(msg.num_pairs, msg.pairs.size(), kMaxPairs, "PLAN_CHECK_REPLY.num_pairs");
  if (!problem.empty()) {
    Refuse(options_.plan_check_reply_channel + "/field", problem);
    return TakeActions();
  }
  const auto& q_deg = options_.config.configurations_deg[k];
  if (!msg.request_valid) {
    FailRun("orbed-iiwa-sim refused the plan check of configuration " + std::to_string(k) + " " +
            JointList(q_deg, 1) + " deg: " + msg.reason);
    return TakeActions();
  }
  if (!msg.feasible) {
    FailRun("configuration " + std::to_string(k) + " " + JointList(q_deg, 1) +
            " deg is infeasible in the sim's scene: " + (msg.reason.empty() ? "not feasible" : msg.reason) +
            " (change configurations_deg in the scenario file or --q-deg)");
    return TakeActions();
  }
  if (!plan_answered_[k]) {
    plan_answered_[k] = true;
    std::ostringstream line;
    line << "configuration " << k << " feasible, min distance " << msg.min_distance_m << " m";
    Log(orbed::LogLevel::kInfo, line.str());
  }
  Step();
  return TakeActions();
}

ConductorActions ViraalConductor::OnTrial(const orbed::alignment_trial_t& msg, const ConductorTime& now) {
  Begin(now);
  const std::string prefix = options_.run_id + "-";
  const bool ours = msg.session_id.compare(0, prefix.size(), prefix) == 0;
  if (!ours) return TakeActions();  // another run's trial
  if (!results_.sessions.empty() && msg.session_id == results_.sessions.back().session_id &&
      msg.trial_index < trial_index_) {
    return TakeActions();  // one it has (e.g. a kept trial it re-sent)
  }
  const bool requested = phase_ == Phase::kAwaitTrial && msg.request_id == trial_request_.request_id;
  if (!requested && IssuedRequestId(msg.request_id)) return TakeActions();  // a repeat: ignored
  if (!requested || mode_index_ >= options_.config.modes.size() ||
      msg.session_id != results_.sessions.back().session_id || msg.trial_index != trial_index_) {
    Refuse(options_.trial_channel + "/unexpected", "ALIGNMENT_TRIAL for session '" + msg.session_id +
                                                       "' trial " + std::to_string(msg.trial_index) +
                                                       " was not requested now");
    return TakeActions();
  }
  const viraal::ModeSpec& mode = options_.config.modes[mode_index_];
  const auto checked = CheckAlignmentTrial(msg, kMaxJoints);
  if (const auto* refusal = std::get_if<orbed::Refusal>(&checked)) {
    Refuse(options_.trial_channel + "/" + refusal->key, refusal->reason);
    return TakeActions();
  }
  // The conductor's own rules: the session's mode, the robot model's joints and limits.
  std::string problem = FirstError(
      {CheckSize(msg.num_joints, model_->num_joints(), "ALIGNMENT_TRIAL.num_joints"),
       CheckEnum(msg.display_mode, mode.display_mode, mode.display_mode, "ALIGNMENT_TRIAL.display_mode")});
  if (problem.empty()) {
    const std::string limits = model_->ValidateJointVector(ToVectorX(msg.joint_position), 1e-6);
    if (!limits.empty()) problem = "ALIGNMENT_TRIAL.joint_position: " + limits;
  }
  if (!problem.empty()) {
    Refuse(options_.trial_channel + "/field", problem);
    return TakeActions();
  }
  if (msg.num_mirrors != mode.num_mirrors) {
    Log(orbed::LogLevel::kWarn, "trial " + std::to_string(msg.trial_index) + " reports " +
                                    std::to_string(msg.num_mirrors) + " mirrors, the session has " +
                                    std::to_string(mode.num_mirrors));
  }
  trial_ = msg;
  const Eigen::VectorXd q = ToVectorX(msg.joint_position);
  const Eigen::VectorXd q_target = orbed::sim::DegToRad(ToVectorX(TargetDeg()));
  const double off_deg = (q - q_target).cwiseAbs().maxCoeff() * kRadToDeg;
  if (off_deg > options_.tolerance_deg) {
    Log(orbed::LogLevel::kWarn, "trial " + std::to_string(msg.trial_index) + " was made at a q " +
                                    Fixed(off_deg, 3) +
                                    " deg from the commanded configuration; its errors use the trial's q");
  }
  const viraal::RobotPoints points = viraal::TrialPoints(*points_, msg);
  session_points_.push_back(points);
  pending_error_ = viraal::TrialError(robot_state_->X_WR, msg, points);
  if (const auto eye = viraal::AlignmentViewpoint(std::get<orbed::AlignmentTrial>(checked)))
    pending_error_ = viraal::WithViewer(pending_error_, *eye);
  Enter(Phase::kAwaitTrialResults);
  landmark_requests_ = viraal::LandmarkRequests(std::get<orbed::AlignmentTrial>(checked), now_.utime, 0);
  landmark_answers_.assign(landmark_requests_.size(), std::nullopt);
  misalignment_.reset();
  misalignment_request_ = orbed::misalignment_request_t{};
  if (landmark_requests_.empty()) {
    SendMisalignment(pending_error_);
  } else {
    for (orbed::landmark_request_t& request : landmark_requests_) {
      request.request_id = NewRequestId();
      Publish(options_.landmark_request_channel, request);
    }
  }
  Step();
  return TakeActions();
}

ConductorActions ViraalConductor::OnLandmark(const orbed::landmark_t& msg, const ConductorTime& now) {
  Begin(now);
  if (phase_ != Phase::kAwaitTrialResults) return TakeActions();  // not ours, or a late repeat
  size_t k = 0;
  while (k < landmark_requests_.size() && landmark_requests_[k].request_id != msg.request_id) ++k;
  if (k == landmark_requests_.size() || landmark_answers_[k]) return TakeActions();  // not ours, or a repeat
  if (msg.valid) {
    const std::string problem =
        FirstError({CheckBounded(msg.p_W_m, 3, kMaxAlignmentCoordinate_m, "LANDMARK.p_W_m"),
                    CheckFinite(&msg.ray_angle_deg, 1, "LANDMARK.ray_angle_deg"),
                    CheckFinite(&msg.gap_m, 1, "LANDMARK.gap_m")});
    if (!problem.empty()) {
      Refuse(options_.landmark_channel + "/field", problem);
      return TakeActions();
    }
  } else {
    FailRun("orbed-registration could not triangulate landmark " + landmark_requests_[k].name + ": " +
            msg.reason);
    return TakeActions();
  }
  landmark_answers_[k] = msg;
  if (LandmarksAnswered()) {
    std::vector<orbed::landmark_t> answers;
    for (const auto& a : landmark_answers_) answers.push_back(*a);
    try {
      pending_error_ = viraal::WithAnnotation(pending_error_, answers);
    } catch (const std::invalid_argument& e) {
      FailRun(e.what());
      return TakeActions();
    }
    SendMisalignment(pending_error_);
  }
  Step();
  return TakeActions();
}

bool ViraalConductor::LandmarksAnswered() const {
  return std::all_of(landmark_answers_.begin(), landmark_answers_.end(),
                     [](const std::optional<orbed::landmark_t>& a) { return a.has_value(); });
}

ConductorActions ViraalConductor::OnRegistration(const orbed::registration_t& msg, const ConductorTime& now) {
  Begin(now);
  if (results_.sessions.empty() || msg.session_id != results_.sessions.back().session_id)
    return TakeActions();  // not ours
  if (msg.reason == orbed::registration_t::REASON_PERIODIC) return TakeActions();
  std::string problem = FirstError(
      {CheckEnum(msg.reason, orbed::registration_t::REASON_TRIAL, orbed::registration_t::REASON_COMPUTE,
                 "REGISTRATION.reason"),
       CheckLength(msg.num_rejected, msg.rejected_indices.size(), kMaxPairs, "REGISTRATION.num_rejected"),
       msg.valid ? CheckPose(msg.X_WV_mean, "REGISTRATION.X_WV_mean") : std::string()});
  if (!problem.empty()) {
    Refuse(options_.registration_channel + "/field", problem);
    return TakeActions();
  }
  // Only the answer to the request the phase waits for counts; repeats and strays are ignored.
  if (msg.reason == orbed::registration_t::REASON_TRIAL) {
    if ((phase_ == Phase::kAwaitTrial || phase_ == Phase::kAwaitTrialResults) &&
        msg.request_id == trial_request_.request_id) {
      trial_registration_ = msg;
    }
  } else if (phase_ == Phase::kAwaitMean && msg.request_id == compute_request_.request_id) {
    mean_registration_ = msg;
  }
  Step();
  return TakeActions();
}

ConductorActions ViraalConductor::OnMisalignment(const orbed::misalignment_t& msg, const ConductorTime& now) {
  Begin(now);
  if ((phase_ != Phase::kAwaitTrialResults && phase_ != Phase::kAwaitMeanMisalignment) ||
      misalignment_request_.request_id == 0 || msg.request_id != misalignment_request_.request_id)
    return TakeActions();  // not ours, or a late repeat
  std::string problem;
  if (msg.valid) {
    problem =
        FirstError({CheckLength(msg.num_pairs, msg.error_norm_m.size(), kMaxPairs, "MISALIGNMENT.num_pairs"),
                    CheckFinite(msg.mean_error_W_m, 3, "MISALIGNMENT.mean_error_W_m"),
                    CheckFinite(&msg.mean_error_norm_m, 1, "MISALIGNMENT.mean_error_norm_m"),
                    CheckFinite(&msg.mean_pair_distance_m, 1, "MISALIGNMENT.mean_pair_distance_m")});
    if (problem.empty() && msg.num_pairs != static_cast<int32_t>(pending_error_.p_W_real.size())) {
      problem = "MISALIGNMENT.num_pairs is " + std::to_string(msg.num_pairs) + ", the request had " +
                std::to_string(pending_error_.p_W_real.size());
    }
  }
  if (!problem.empty()) {
    Refuse(options_.misalignment_channel + "/field", problem);
    return TakeActions();
  }
  if (!msg.valid) {
    FailRun("orbed-registration refused the misalignment request: " + msg.reason);
    return TakeActions();
  }
  misalignment_ = msg;
  Step();
  return TakeActions();
}

// ---------------------------------------------------------------------------------------------
// The phases

void ViraalConductor::Enter(Phase phase) {
  phase_ = phase;
  phase_start_s_ = now_.t_s;
  attempts_ = 1;
  retry_interval_s_ = options_.retry_initial_s;
  next_retry_s_ = now_.t_s + retry_interval_s_;
}

void ViraalConductor::RetryIfDue() {
  if (now_.t_s < next_retry_s_) return;
  const size_t before = actions_.size();
  switch (phase_) {
    case Phase::kCheckPlans:
      for (size_t k = 0; k < plan_requests_.size(); ++k) {
        if (!plan_answered_[k]) Publish(options_.plan_check_request_channel, plan_requests_[k]);
      }
      break;
    case Phase::kAwaitTrial:
    case Phase::kAwaitTrialResults:
      if (!TrialRegistered()) {
        Publish(options_.session_control_channel, start_request_);
        for (const orbed::alignment_trial_t& kept : kept_trials_) Publish(options_.trial_channel, kept);
        Publish(options_.session_control_channel, trial_request_);
      }
      if (phase_ == Phase::kAwaitTrialResults && !LandmarksAnswered()) {
        for (size_t k = 0; k < landmark_requests_.size(); ++k) {
          if (!landmark_answers_[k]) Publish(options_.landmark_request_channel, landmark_requests_[k]);
        }
      } else if (phase_ == Phase::kAwaitTrialResults && !misalignment_) {
        Publish(options_.misalignment_request_channel, misalignment_request_);
      }
      break;
    case Phase::kAwaitMean:
      Publish(options_.session_control_channel, compute_request_);
      break;
    case Phase::kAwaitMeanMisalignment:
      Publish(options_.misalignment_request_channel, misalignment_request_);
      break;
    default:
      return;
  }
  retries_ += static_cast<int64_t>(actions_.size() - before);
  ++attempts_;
  Log(orbed::LogLevel::kDebug, "no answer yet: re-sent " + std::to_string(actions_.size() - before) +
                                   " request(s), attempt " + std::to_string(attempts_));
  retry_interval_s_ = std::min(2 * retry_interval_s_, options_.retry_max_s);
  next_retry_s_ = now_.t_s + retry_interval_s_;
}

bool ViraalConductor::TrialRegistered() const {
  return trial_ && trial_registration_ && trial_registration_->utime == trial_->utime &&
         trial_registration_->num_trials == trial_index_ + 1;
}

std::string ViraalConductor::Attempts() const { return ", sent " + std::to_string(attempts_) + " times"; }

void ViraalConductor::Step() {
  const double waited = PhaseSeconds();
  const std::string refusal = last_refusal_.empty() ? "" : " (last refused input: " + last_refusal_ + ")";
  switch (phase_) {
    case Phase::kNotStarted:
      return;
    case Phase::kWaitRobot:
      if (robot_state_) {
        results_.X_WR = FromPose(robot_state_->X_WR);
        StartPlanChecks();
      } else if (waited > options_.startup_timeout_s) {
        FailRun("no valid ROBOT_STATE on " + options_.robot_state_channel + " within " +
                Fixed(options_.startup_timeout_s, 1) + " s: is orbed-iiwa-sim running?" + refusal);
      }
      return;
    case Phase::kCheckPlans: {
      const size_t answered = std::count(plan_answered_.begin(), plan_answered_.end(), true);
      if (answered == plan_answered_.size()) {
        Say("[plan] " + std::to_string(answered) +
            " configurations checked with orbed-iiwa-sim: within limits and collision-free");
        StartSession();
      } else if (waited > options_.request_deadline_s) {
        FailRun("orbed-iiwa-sim answered " + std::to_string(answered) + " of " +
                std::to_string(plan_answered_.size()) + " PLAN_CHECK_REQUESTs within " +
                Fixed(options_.request_deadline_s, 1) + " s" + Attempts() + refusal);
      } else {
        RetryIfDue();
      }
      return;
    }
    case Phase::kMove: {
      const std::vector<double>& q_deg = TargetDeg();
      const orbed::robot_state_t& state = *robot_state_;
      double off_deg = 0;
      for (int i = 0; i < model_->num_joints(); ++i) {
        off_deg = std::max(off_deg, std::abs(state.joint_position[i] * kRadToDeg - q_deg[i]));
      }
      if (off_deg < options_.tolerance_deg && state.motion_state == orbed::robot_state_t::MOTION_IDLE) {
        reach_s_ = waited;
        RequestTrial();
        return;
      }
      const bool stopped = state.motion_state != orbed::robot_state_t::MOTION_IDLE &&
                           state.motion_state != orbed::robot_state_t::MOTION_MOVING;
      // Only states the sim produced after it had the command count as a stop.
      const bool fresh = robot_state_received_s_ - last_command_s_ > kFreshStateAfterCommand_s;
      if (stopped && fresh) {
        if (!stopped_since_s_) stopped_since_s_ = now_.t_s;
        if (now_.t_s - *stopped_since_s_ > options_.stopped_grace_s) {
          FailRun("the arm stopped " + Fixed(off_deg, 2) + " deg short of configuration " +
                  JointList(q_deg, 1) +
                  " deg: " + (state.stop_reason.empty() ? "stopped" : state.stop_reason));
          return;
        }
      } else {
        stopped_since_s_.reset();
      }
      if (waited > options_.move_timeout_s) {
        std::vector<double> at_deg;
        for (double v : state.joint_position) at_deg.push_back(v * kRadToDeg);
        FailRun("the arm did not reach configuration " + JointList(q_deg, 1) + " deg within " +
                Fixed(options_.move_timeout_s, 1) + " s (it is at " + JointList(at_deg, 2) + " deg, " +
                Fixed(off_deg, 3) + " deg off, motion state " + std::to_string(state.motion_state) +
                "): is orbed-iiwa-sim receiving " + options_.iiwa_command_channel + "?");
        return;
      }
      if (now_.t_s - last_command_s_ > options_.command_resend_s) StartMove(false);
      return;
    }
    case Phase::kAwaitTrial:
      if (waited > options_.request_deadline_s) {
        FailRun("no ALIGNMENT_TRIAL for session '" + results_.sessions.back().session_id + "' trial " +
                std::to_string(trial_index_) + " within " + Fixed(options_.request_deadline_s, 1) +
                " s of SESSION_CONTROL REQUEST_TRIAL" + Attempts() +
                ": is orbed-hmd running (its emulated user answers REQUEST_TRIAL on " +
                options_.trial_channel + ")?" + refusal);
      } else {
        RetryIfDue();
      }
      return;
    case Phase::kAwaitTrialResults: {
      const bool registered = TrialRegistered();
      if (registered && misalignment_) {
        FinishTrial();
      } else if (waited > options_.request_deadline_s) {
        const size_t answered = std::count_if(landmark_answers_.begin(), landmark_answers_.end(),
                                              [](const auto& a) { return a.has_value(); });
        const std::string missing = !registered ? "no REGISTRATION (reason TRIAL)"
                                    : !LandmarksAnswered()
                                        ? "LANDMARK answers to " + std::to_string(answered) + " of " +
                                              std::to_string(landmark_requests_.size()) + " LANDMARK_REQUESTs"
                                        : "no MISALIGNMENT answer";
        FailRun(missing + " from orbed-registration for session '" + results_.sessions.back().session_id +
                "' trial " + std::to_string(trial_index_) + " within " +
                Fixed(options_.request_deadline_s, 1) + " s" + Attempts() +
                " (is it running? did it refuse the trial? see its PROCESS_STATUS rejections)" + refusal);
      } else {
        RetryIfDue();
      }
      return;
    }
    case Phase::kAwaitMean:
      if (mean_registration_) {
        const orbed::registration_t& mean = *mean_registration_;
        if (!mean.valid || mean.num_trials != options_.config.trials) {
          FailRun("orbed-registration's mean for session '" + mean.session_id + "' holds " +
                  std::to_string(mean.num_trials) + " trials (valid " + (mean.valid ? "true" : "false") +
                  "), expected " + std::to_string(options_.config.trials));
          return;
        }
        try {
          pending_error_ = viraal::MeanError(robot_state_->X_WR, mean, session_points_,
                                             viraal::AnnotatedRealLandmarks(results_.sessions.back()),
                                             viraal::ViewerEyes(results_.sessions.back()));
        } catch (const std::invalid_argument& e) {
          FailRun(e.what());
          return;
        }
        Enter(Phase::kAwaitMeanMisalignment);
        SendMisalignment(pending_error_);
      } else if (waited > options_.request_deadline_s) {
        FailRun("no REGISTRATION (reason COMPUTE) from orbed-registration for session '" +
                results_.sessions.back().session_id + "' within " + Fixed(options_.request_deadline_s, 1) +
                " s" + Attempts() + refusal);
      } else {
        RetryIfDue();
      }
      return;
    case Phase::kAwaitMeanMisalignment:
      if (misalignment_) {
        FinishSession();
      } else if (waited > options_.request_deadline_s) {
        FailRun("no MISALIGNMENT answer from orbed-registration for the mean of session '" +
                results_.sessions.back().session_id + "' within " + Fixed(options_.request_deadline_s, 1) +
                " s" + Attempts() + refusal);
      } else {
        RetryIfDue();
      }
      return;
    case Phase::kDone:
      return;
  }
}

void ViraalConductor::StartPlanChecks() {
  const auto& configurations = options_.config.configurations_deg;
  plan_requests_.clear();
  plan_answered_.assign(configurations.size(), false);
  Enter(Phase::kCheckPlans);
  for (const std::vector<double>& q_deg : configurations) {
    orbed::plan_check_request_t request{};
    request.utime = now_.utime;
    request.request_id = NewRequestId();
    request.num_joints = static_cast<int32_t>(q_deg.size());
    request.joint_position = FromVectorX(orbed::sim::DegToRad(ToVectorX(q_deg)));
    Publish(options_.plan_check_request_channel, request);
    plan_requests_.push_back(request);
  }
}

orbed::session_control_t ViraalConductor::SendSessionControl(int8_t command) {
  const viraal::ModeSpec& mode = options_.config.modes[mode_index_];
  orbed::session_control_t msg{};
  msg.utime = now_.utime;
  msg.session_id = results_.sessions.back().session_id;
  msg.command = command;
  msg.display_mode = mode.display_mode;
  msg.num_mirrors = mode.num_mirrors;
  msg.method = options_.config.method;
  msg.request_id = NewRequestId();
  if (command == orbed::session_control_t::START && mode.num_mirrors > 0) {
    msg.capture_waypoint = options_.config.capture_waypoints;  // empty: the headset's own
    msg.num_capture_waypoints = static_cast<int32_t>(msg.capture_waypoint.size());
  }
  Publish(options_.session_control_channel, msg);
  return msg;
}

void ViraalConductor::StartSession() {
  const viraal::ModeSpec& mode = options_.config.modes[mode_index_];
  if (results_.sessions.size() <= mode_index_) {  // else a kept session in progress (resuming)
    viraal::SessionResult session;
    session.mode = mode.name;
    session.session_id = options_.run_id + "-" + mode.name;
    session.display_mode = mode.display_mode;
    session.num_mirrors = mode.num_mirrors;
    if (mode.num_mirrors > 0) session.capture_waypoints = options_.config.capture_waypoints;
    results_.sessions.push_back(session);
  }
  const viraal::SessionResult& session = results_.sessions.back();
  trial_index_ = static_cast<int>(session.trials.size());
  session_points_.clear();
  mean_registration_.reset();
  start_request_ = SendSessionControl(+orbed::session_control_t::START);
  kept_trials_.clear();
  for (const viraal::TrialResult& kept : session.trials) {
    const orbed::alignment_trial_t trial = viraal::TrialMessageFrom(kept, session, now_.utime);
    session_points_.push_back(viraal::TrialPoints(*points_, trial));
    Publish(options_.trial_channel, trial);
    kept_trials_.push_back(trial);
  }
  Say("[" + mode.name + "] session " + session.session_id +
      " started: " + std::to_string(options_.config.trials) + " trials, " + std::to_string(mode.num_mirrors) +
      " reflective display(s)" +
      (trial_index_ > 0 ? "; resumed with the " + std::to_string(trial_index_) + " trial(s) kept" : ""));
  if (trial_index_ < options_.config.trials) {
    StartMove(true);
  } else {
    RequestMean();
  }
}

void ViraalConductor::StartMove(bool first) {
  const std::vector<double>& q_deg = TargetDeg();
  orbed::iiwa_command_t command{};
  command.utime = now_.utime;
  command.num_joints = static_cast<int32_t>(q_deg.size());
  command.joint_position = FromVectorX(orbed::sim::DegToRad(ToVectorX(q_deg)));
  command.num_torques = 0;
  Publish(options_.iiwa_command_channel, command);
  last_command_s_ = now_.t_s;
  if (first) {
    stopped_since_s_.reset();
    Enter(Phase::kMove);
    Log(orbed::LogLevel::kInfo, StepLabel() + ": moving to q=" + JointList(q_deg, 1) + " deg");
  }
}

void ViraalConductor::RequestTrial() {
  trial_.reset();
  trial_registration_.reset();
  trial_request_ = SendSessionControl(+orbed::session_control_t::REQUEST_TRIAL);
  Enter(Phase::kAwaitTrial);
}

void ViraalConductor::SendMisalignment(const viraal::AlignmentError& error) {
  misalignment_.reset();
  misalignment_request_ =
      viraal::MisalignmentRequest(error, results_.sessions.back().session_id, now_.utime, NewRequestId());
  Publish(options_.misalignment_request_channel, misalignment_request_);
}

void ViraalConductor::FinishTrial() {
  const orbed::alignment_trial_t& trial = *trial_;
  const viraal::TrialResult result =
      viraal::TrialResultFrom(trial, robot_state_->X_WR, viraal::Measures(pending_error_, *misalignment_),
                              pending_error_.p_W_real_annotated, pending_error_.p_WE);
  results_.sessions.back().trials.push_back(result);
  Say(StepLabel() + ": robot at q=" + JointList(result.q_deg, 1) + " deg (reached in " + Fixed(reach_s_, 1) +
      " s); aligned in " + Fixed(trial.duration_s, 1) + " s of user time: " +
      Fixed(result.errors.translation_error_mm, 1) + " mm, " + Fixed(result.errors.rotation_error_deg, 2) +
      " deg, misalignment " + Fixed(result.errors.misalignment_mm, 1) + " mm" +
      (result.tracking_faults.any()
           ? "; tracking lost " + std::to_string(result.tracking_faults.losses) +
                 "x while aligning, waited " + Fixed(result.tracking_faults.wait_s, 1) + " s, re-aligned " +
                 std::to_string(result.tracking_faults.repeats) + "x"
           : ""));
  ++trial_index_;
  if (trial_index_ < options_.config.trials) {
    StartMove(true);
  } else {
    RequestMean();
  }
}

void ViraalConductor::RequestMean() {
  mean_registration_.reset();
  compute_request_ = SendSessionControl(+orbed::session_control_t::COMPUTE);
  Enter(Phase::kAwaitMean);
}

void ViraalConductor::FinishSession() {
  const orbed::registration_t& reg = *mean_registration_;
  const viraal::MeanResult mean =
      viraal::MeanResultFrom(reg, viraal::Measures(pending_error_, *misalignment_));
  viraal::SessionResult& session = results_.sessions.back();
  session.mean = mean;
  Say("[" + session.mode + "] mean of " + std::to_string(reg.num_used) + " trials (SE(3), " +
      (reg.converged ? "converged" : "NOT converged") + "): " + Fixed(mean.errors.translation_error_mm, 1) +
      " mm, " + Fixed(mean.errors.rotation_error_deg, 2) + " deg, misalignment " +
      Fixed(mean.errors.misalignment_mm, 1) + " mm");
  SendSessionControl(+orbed::session_control_t::STOP);
  ++mode_index_;
  if (mode_index_ < options_.config.modes.size()) {
    StartSession();
  } else {
    FinishRun();
  }
}

void ViraalConductor::FinishRun() {
  results_.ok = true;
  results_.duration_s = now_.t_s - run_start_s_;
  results_.rejected_inputs = refusals_;
  phase_ = Phase::kDone;
}

void ViraalConductor::FailRun(const std::string& reason) {
  if (phase_ == Phase::kDone) return;
  phase_ = Phase::kDone;
  results_.ok = false;
  results_.error = reason;
  results_.duration_s = now_.t_s - run_start_s_;
  results_.rejected_inputs = refusals_;
}

// ---------------------------------------------------------------------------------------------
// Small helpers

const std::vector<double>& ViraalConductor::TargetDeg() const {
  const auto& configurations = options_.config.configurations_deg;
  return configurations[trial_index_ % configurations.size()];
}

std::string ViraalConductor::StepLabel() const {
  const int total = static_cast<int>(options_.config.modes.size()) * options_.config.trials;
  const int step = static_cast<int>(mode_index_) * options_.config.trials + trial_index_ + 1;
  const std::string mode =
      mode_index_ < options_.config.modes.size() ? options_.config.modes[mode_index_].name : "";
  return "[" + std::to_string(step) + "/" + std::to_string(total) + "] " + mode + " trial " +
         std::to_string(trial_index_);
}

void ViraalConductor::Refuse(const std::string& key, const std::string& reason) {
  last_refusal_ = reason;
  ++refusals_;
  actions_.push_back(Refusal{key, reason});
}

void ViraalConductor::Say(const std::string& line) { actions_.push_back(ProgressLine{line}); }

void ViraalConductor::Log(orbed::LogLevel level, const std::string& text) {
  actions_.push_back(LogEntry{level, text});
}

}  // namespace orbed::scenario
