#include "procs/assistant/assistant_machine.h"

#include <cmath>
#include <limits>
#include <sstream>

#include <orbed/robot_state_t.hpp>

#include "base/json.h"
#include "base/units.h"
#include "sim/guidance_messages.h"

namespace orbed::assistant {
namespace {

// The distances from the base at which FIXED_VIEW's camera is taken as the monitor's [m]
// (orbed-fixed-display's orbit keeps 0.8-6 m from a point 0.5 m above the base).
constexpr double kMinMonitorDistance_m = 0.3;
constexpr double kMaxMonitorDistance_m = 20.0;

std::vector<double> Degrees(const Eigen::VectorXd& q_rad) {
  std::vector<double> out;
  for (int i = 0; i < q_rad.size(); ++i) out.push_back(q_rad[i] * kRadToDeg);
  return out;
}

}  // namespace

std::string SetupResultJson(const SetupResult& r) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("mode").String(guidance::GuidanceModeName(r.mode));
  json.Key("seed").Int(static_cast<int64_t>(r.seed));
  json.Key("person_scale").Number(r.person_scale);
  json.Key("q_start_deg").Array(Degrees(r.q_start_rad));
  json.Key("q_target_deg").Array(Degrees(r.q_target_rad));
  json.Key("q_reached_deg").Array(Degrees(r.q_reached_rad));
  std::vector<double> error;
  for (int i = 0; i < r.q_reached_rad.size(); ++i) {
    error.push_back(std::abs(r.q_reached_rad[i] - r.q_target_rad[i]) * kRadToDeg);
  }
  json.Key("error_deg").Array(error);
  json.Key("twisting").Array(r.twisting);
  json.Key("ranges").Array(r.ranges);
  json.Key("execution_s").Number(r.execution_s);
  json.Key("headset_pose").Bool(r.headset_pose);
  json.EndObject();
  return json.str() + "\n";
}

AssistantMachine::AssistantMachine(const sim::RobotModel& model, const AssistantConfig& config,
                                   const MachineOptions& options)
    : model_(&model), options_(options), assistant_(model, config) {
  if (options_.once) phase_ = Phase::kWait;
}

void AssistantMachine::OnRobotState(const Eigen::Isometry3d& X_WR, int8_t motion_state) {
  X_WR_ = X_WR;
  motion_state_ = motion_state;
}

void AssistantMachine::OnHeadPose(bool truth, int64_t seq, const Eigen::Isometry3d& X_WH) {
  auto& mine = truth ? X_WH_true_ : X_WH_est_;
  const auto& other = truth ? X_WH_est_ : X_WH_true_;
  mine = std::make_pair(seq, X_WH);
  if (other && other->first == seq) {
    A_ = X_WH_true_->second * X_WH_est_->second.inverse();
    p_WE_ = X_WH_true_->second.translation();
  }
}

bool AssistantMachine::OnMonitorCamera(const Eigen::Vector3d& p_WD, double t_s) {
  const bool moved = !p_WD_ || (p_WD - *p_WD_).norm() > 1e-6;
  p_WD_ = p_WD;
  p_WD_received_s_ = t_s;
  return moved;
}

TaskAnswer AssistantMachine::OnSetupTask(const orbed::setup_task_t& msg) {
  TaskAnswer answer;
  if (options_.once) return answer;
  if (task_ && msg.request_id == task_->request_id) {
    answer.kind = TaskAnswer::kRepeat;
    answer.reply = task_result_;
    return answer;
  }
  answer.problem = guidance::CheckSetupTask(msg, *model_, 0.0);
  if (!answer.problem.empty()) {
    answer.kind = TaskAnswer::kRefused;
    return answer;
  }
  answer.kind = TaskAnswer::kStarted;
  task_ = msg;
  task_result_.reset();
  phase_ = Phase::kWait;
  waiting_noted_ = false;
  return answer;
}

Viewing AssistantMachine::CurrentView(double t_s) const {
  Viewing view;
  view.mode = guidance_->mode;
  view.X_WR = *X_WR_;
  view.X_WV_seen = (A_ ? *A_ : Eigen::Isometry3d::Identity()) * (X_WV_ ? *X_WV_ : *X_WR_);
  view.p_WE = p_WE_ ? *p_WE_ : assistant_.config().eye_position_m;
  // The reflective display: captured at the config's viewpoint, the hologram at the registration.
  if (view.mode == orbed::guidance_t::MODE_AR_REFLECTIVE) {
    view.p_WC_display = assistant_.config().display_capture_m;
    view.X_WV_display = X_WV_ ? *X_WV_ : *X_WR_;
  }
  // A monitor camera on or far from the robot is no view of it: the configured one instead.
  if (p_WD_ && t_s - p_WD_received_s_ <= options_.fixed_view_stale_s) {
    const double d_m = (*p_WD_ - X_WR_->translation()).norm();
    if (d_m >= kMinMonitorDistance_m && d_m <= kMaxMonitorDistance_m) view.p_WD = p_WD_;
  }
  // The view as the person turned it for this set-up.
  if (p_WD_turned_ && view.mode == orbed::guidance_t::MODE_FIXED_DISPLAY) view.p_WD = p_WD_turned_;
  return view;
}

StepOutput AssistantMachine::Step(double t_s, int64_t utime) {
  StepOutput out;
  switch (phase_) {
    case Phase::kIdle:
    case Phase::kDone:
      return out;
    case Phase::kWait:
      StartSetUp(t_s, &out);
      if (phase_ != Phase::kLook) return out;
      [[fallthrough]];
    case Phase::kLook:
      LookAtJoint(t_s, &out);
      [[fallthrough]];
    case Phase::kMove:
      Move(t_s, utime, &out);
      return out;
  }
  return out;
}

// kWait: starts the set-up (phase kLook) once everything it needs is there.
void AssistantMachine::StartSetUp(double t_s, StepOutput* out) {
  const int n = model_->num_joints();
  const bool headset = guidance_ && guidance_->mode != orbed::guidance_t::MODE_FIXED_DISPLAY;
  bool shows_task = true;  // the GUIDANCE is this task's
  if (task_ && guidance_) {
    shows_task = guidance_->mode == task_->mode;
    for (int i = 0; i < n && shows_task; ++i) {
      shows_task = std::abs(guidance_->target_position[i] - task_->target_position[i]) < 1e-9;
    }
  }
  const bool ready = guidance_ && shows_task && q_rad_ && X_WR_ &&
                     motion_state_ == orbed::robot_state_t::MOTION_IDLE && (!headset || X_WV_);
  if (!ready) {
    if (guidance_ && headset && !X_WV_ && !waiting_noted_) {
      waiting_noted_ = true;
      out->notes.push_back({false, "assistant: mode " +
                                       std::string(guidance::GuidanceModeName(guidance_->mode)) +
                                       ": waiting for a valid REGISTRATION (where the hologram is drawn)"});
    }
    return;
  }
  partial_ = SetupResult{};
  partial_.mode = guidance_->mode;
  partial_.seed = assistant_.config().seed;
  partial_.person_scale = assistant_.person_scale();
  partial_.q_start_rad = *q_rad_;
  partial_.q_target_rad = Eigen::Map<const Eigen::VectorXd>(guidance_->target_position.data(), n);
  for (int8_t kind : guidance_->joint_kind)
    partial_.twisting.push_back(kind == orbed::guidance_t::JOINT_TWIST);
  partial_.headset_pose = A_.has_value();
  // On the fixed monitor the person first turns (and zooms) its view towards their own.
  p_WD_turned_.reset();
  std::string turned;
  if (guidance_->mode == orbed::guidance_t::MODE_FIXED_DISPLAY) {
    const MonitorTurn turn = assistant_.PlanMonitorView(CurrentView(t_s));
    p_WD_turned_ = turn.p_WD;
    partial_.execution_s += turn.time_s;
    std::ostringstream note;
    note << " (monitor's view turned " << turn.turned_deg << " deg" << (turn.zoomed ? ", zoomed in" : "")
         << ")";
    turned = note.str();
  }
  out->notes.push_back(
      {false,
       "assistant: set-up in mode " + std::string(guidance::GuidanceModeName(guidance_->mode)) +
           (headset ? (A_ ? " (eye and SLAM error from HMD_POSE)" : " (eye from the config, no SLAM error)")
                    : turned)});
  joint_ = 0;
  look_ = 0;
  phase_ = Phase::kLook;
}

// kLook: the person looks at joint_ and decides where to put it; the move starts (phase kMove).
void AssistantMachine::LookAtJoint(double t_s, StepOutput* out) {
  const Eigen::VectorXd& q = *q_rad_;
  const Eigen::VectorXd q_target =
      Eigen::Map<const Eigen::VectorXd>(guidance_->target_position.data(), model_->num_joints());
  const double window = look_ == 0 ? std::numeric_limits<double>::infinity()
                                   : assistant_.config().correction_window_deg * kDegToRad;
  const JointLook look = assistant_.Look(joint_, q, q_target, CurrentView(t_s), window);
  if (look_ == 0) {
    partial_.execution_s += assistant_.JointOverhead_s();
    partial_.ranges.push_back(look.ranges);
  }
  partial_.execution_s += look.time_s + assistant_.TravelTime_s(look.q_rad - q[joint_]);
  q_goal_ = q;
  q_goal_[joint_] = look.q_rad;
  std::ostringstream note;
  note << "assistant: joint " << joint_ + 1 << " look " << look_ + 1 << ": " << q[joint_] * kRadToDeg
       << " -> " << look.q_rad * kRadToDeg << " deg (target " << q_target[joint_] * kRadToDeg << ", "
       << look.ranges << " range(s) looked right)";
  out->notes.push_back({false, note.str()});
  phase_ = Phase::kMove;
  move_started_s_ = t_s;
  last_command_s_ = -1e9;
}

// kMove: commands the goal until the joint arrives or the sim stops it, then the next look.
void AssistantMachine::Move(double t_s, int64_t utime, StepOutput* out) {
  const Eigen::VectorXd& q = *q_rad_;
  const int n = model_->num_joints();
  const bool arrived = std::abs(q[joint_] - q_goal_[joint_]) * kRadToDeg < options_.arrived_deg &&
                       motion_state_ == orbed::robot_state_t::MOTION_IDLE;
  const bool stopped = motion_state_ >= orbed::robot_state_t::MOTION_STOPPED_AT_LIMIT &&
                       t_s - move_started_s_ > 2 * options_.command_resend_s;
  if (arrived || stopped) {
    if (stopped && !arrived) {
      std::ostringstream note;
      note << "assistant: joint " << joint_ + 1 << " stopped by the sim at " << q[joint_] * kRadToDeg
           << " deg (wanted " << q_goal_[joint_] * kRadToDeg << ")";
      out->notes.push_back({true, note.str()});
    }
    if (++look_ >= assistant_.config().looks_per_joint) {
      look_ = 0;
      ++joint_;
    }
    if (joint_ >= n) return Finish(utime, out);
    phase_ = Phase::kLook;
    return;
  }
  if (t_s - move_started_s_ > options_.move_timeout_s) {
    out->failure = "joint " + std::to_string(joint_ + 1) + " did not reach " +
                   std::to_string(q_goal_[joint_] * kRadToDeg) + " deg within " +
                   std::to_string(options_.move_timeout_s) + " s (is orbed-iiwa-sim running?)";
    phase_ = Phase::kDone;
    return;
  }
  if (t_s - last_command_s_ >= options_.command_resend_s) {
    orbed::iiwa_command_t command{};
    command.utime = utime;
    command.num_joints = n;
    for (int i = 0; i < n; ++i) command.joint_position.push_back(q_goal_[i]);
    command.num_torques = 0;
    out->command = command;
    last_command_s_ = t_s;
  }
}

// The last joint arrived: the result, and the task's answer.
void AssistantMachine::Finish(int64_t utime, StepOutput* out) {
  const Eigen::VectorXd& q = *q_rad_;
  phase_ = Phase::kDone;
  partial_.q_reached_rad = q;
  result_ = partial_;
  out->finished = true;
  double worst = 0;
  for (int i = 0; i < q.size(); ++i) worst = std::max(worst, std::abs(q[i] - partial_.q_target_rad[i]));
  std::ostringstream note;
  note << "assistant: done in " << partial_.execution_s << " s (time model); largest joint error "
       << worst * kRadToDeg << " deg";
  out->notes.push_back({false, note.str()});
  if (task_) {
    orbed::setup_result_t r{};
    r.utime = utime;
    r.request_id = task_->request_id;
    r.task_id = task_->task_id;
    r.mode = partial_.mode;
    r.num_joints = static_cast<int32_t>(q.size());
    for (int i = 0; i < q.size(); ++i) r.reached_position.push_back(q[i]);
    r.ranges = partial_.ranges;
    r.execution_s = partial_.execution_s;
    r.person_scale = partial_.person_scale;
    task_result_ = r;
    out->task_reply = r;
  }
  out->stop = options_.once;
}

}  // namespace orbed::assistant
