#include "procs/assistant/assistant_process.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <limits>

#include <CLI/CLI.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "base/format.h"
#include "base/json.h"
#include "base/log.h"
#include "base/replace_file.h"
#include "base/source_paths.h"
#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/validation.h"
#include "runtime/flags.h"
#include "sim/guidance_messages.h"
#include "sim/iiwa_status_check.h"

namespace orbed::assistant {
namespace {

// The sim clamps to the limits; this absorbs rounding (as orbed-hmd and orbed-guidance).
constexpr double kJointLimitSlackRad = 0.01;

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

namespace {
AssistantConfig LoadConfig(const AssistantOptions& o) {
  AssistantConfig c =
      LoadAssistantConfig(o.config_path.empty() ? SourceTreePath(kDefaultConfigRelativePath) : o.config_path);
  if (o.seed) c.seed = *o.seed;
  return c;
}
}  // namespace

AssistantProcess::AssistantProcess(const CommonFlags& flags, const AssistantOptions& options)
    : process_(flags),
      model_(sim::RobotModel::LoadFlag(options.urdf_path)),
      options_(options),
      assistant_(model_, LoadConfig(options)) {
  process_.Subscribe<orbed::guidance_t>(
      options_.guidance_channel, [this](const orbed::guidance_t& msg, const std::string& channel, int64_t) {
        const std::string problem = guidance::CheckGuidance(msg, model_, kJointLimitSlackRad);
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        guidance_ = msg;
      });
  process_.Subscribe<orbed::iiwa_status_t>(
      options_.iiwa_status_channel,
      [this](const orbed::iiwa_status_t& msg, const std::string& channel, int64_t) {
        Eigen::VectorXd q;
        const sim::IiwaStatusProblem problem = sim::CheckIiwaStatus(msg, model_, kJointLimitSlackRad, &q);
        if (!problem.rejection_class.empty()) {
          return process_.Reject(channel + "/" + problem.rejection_class, problem.reason);
        }
        q_rad_ = q;
        have_q_ = true;
      });
  process_.Subscribe<orbed::robot_state_t>(
      options_.robot_state_channel,
      [this](const orbed::robot_state_t& msg, const std::string& channel, int64_t) {
        const std::string problem = CheckRobotState(msg, model_.num_joints());
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        X_WR_ = FromPose(msg.X_WR);
        motion_state_ = msg.motion_state;
      });
  process_.Subscribe<orbed::registration_t>(
      options_.registration_channel,
      [this](const orbed::registration_t& msg, const std::string& channel, int64_t) {
        if (!msg.valid) return;  // no mean yet
        const std::string problem = CheckPose(msg.X_WV_mean, "REGISTRATION.X_WV_mean");
        if (!problem.empty()) return process_.Reject(channel + "/pose", problem);
        X_WV_ = FromPose(msg.X_WV_mean);
      });
  auto on_pose = [this](bool truth) {
    return [this, truth](const orbed::hmd_pose_t& msg, const std::string& channel, int64_t) {
      const std::string problem = CheckPose(msg.X_WH, "X_WH");
      if (!problem.empty()) return process_.Reject(channel + "/pose", problem);
      auto& mine = truth ? X_WH_true_ : X_WH_est_;
      const auto& other = truth ? X_WH_est_ : X_WH_true_;
      mine = std::make_pair(msg.seq, FromPose(msg.X_WH));
      if (other && other->first == msg.seq) {
        A_ = X_WH_true_->second * X_WH_est_->second.inverse();
        p_WE_ = X_WH_true_->second.translation();
      }
    };
  };
  process_.Subscribe<orbed::image_t>(
      options_.fixed_view_channel, [this](const orbed::image_t& msg, const std::string& channel, int64_t) {
        const std::string problem = CheckImage(msg);
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        const Eigen::Vector3d p_WD = FromPose(msg.X_WC).translation();
        if (!p_WD_ || (p_WD - *p_WD_).norm() > 1e-6) {
          ORBED_LOG(kInfo) << "assistant: the monitor's camera is at (" << Fixed(p_WD.x(), 2) << ", "
                           << Fixed(p_WD.y(), 2) << ", " << Fixed(p_WD.z(), 2) << ") m (" << channel << ")";
        }
        p_WD_ = p_WD;
        p_WD_received_s_ = process_.ClockSeconds();
      });
  process_.Subscribe<orbed::hmd_pose_t>(options_.hmd_pose_channel, on_pose(false));
  process_.Subscribe<orbed::hmd_pose_t>(options_.hmd_pose_truth_channel, on_pose(true));
  process_.Subscribe<orbed::setup_task_t>(
      options_.setup_task_channel,
      [this](const orbed::setup_task_t& msg, const std::string& channel, int64_t) {
        if (options_.once) return;
        if (task_ && msg.request_id == task_->request_id) {
          if (task_result_) process_.Publish(options_.setup_result_channel, *task_result_);  // a repeat
          return;
        }
        const std::string problem = guidance::CheckSetupTask(msg, model_, 0.0);
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        task_ = msg;
        task_result_.reset();
        phase_ = Phase::kWait;
        waiting_logged_ = false;
        ORBED_LOG(kInfo) << "assistant: task " << EscapeText(msg.task_id) << " (mode "
                         << guidance::GuidanceModeName(msg.mode) << ")";
      });
  if (options_.once) phase_ = Phase::kWait;
  process_.AddTimer(
      options_.step_period_s, [this] { Step(); }, "step");
  ORBED_LOG(kInfo) << "assistant: person seed " << assistant_.config().seed << " (noise scale "
                   << assistant_.person_scale() << ", pace " << assistant_.pace() << "), "
                   << assistant_.config().looks_per_joint
                   << " looks per joint; waiting for GUIDANCE, IIWA_STATUS and ROBOT_STATE";
}

Viewing AssistantProcess::CurrentView() const {
  Viewing view;
  view.mode = guidance_->mode;
  view.X_WR = *X_WR_;
  view.X_WV_seen = (A_ ? *A_ : Eigen::Isometry3d::Identity()) * (X_WV_ ? *X_WV_ : *X_WR_);
  view.p_WE = p_WE_ ? *p_WE_ : assistant_.config().eye_position_m;
  // A monitor camera on or far from the robot is no view of it: the configured one instead.
  if (p_WD_ && process_.ClockSeconds() - p_WD_received_s_ <= options_.fixed_view_stale_s) {
    const double d_m = (*p_WD_ - X_WR_->translation()).norm();
    if (d_m >= kMinMonitorDistance_m && d_m <= kMaxMonitorDistance_m) view.p_WD = p_WD_;
  }
  return view;
}

void AssistantProcess::Step() {
  const double t_s = process_.ClockSeconds();
  const int n = model_.num_joints();
  switch (phase_) {
    case Phase::kIdle:
      return;
    case Phase::kWait: {
      const bool headset = guidance_ && guidance_->mode != orbed::guidance_t::MODE_FIXED_DISPLAY;
      bool shows_task = true;  // the GUIDANCE is this task's
      if (task_ && guidance_) {
        shows_task = guidance_->mode == task_->mode;
        for (int i = 0; i < n && shows_task; ++i) {
          shows_task = std::abs(guidance_->target_position[i] - task_->target_position[i]) < 1e-9;
        }
      }
      const bool ready = guidance_ && shows_task && have_q_ && X_WR_ &&
                         motion_state_ == orbed::robot_state_t::MOTION_IDLE && (!headset || X_WV_);
      if (!ready) {
        if (guidance_ && headset && !X_WV_ && !waiting_logged_) {
          waiting_logged_ = true;
          ORBED_LOG(kInfo) << "assistant: mode " << guidance::GuidanceModeName(guidance_->mode)
                           << ": waiting for a valid REGISTRATION (where the hologram is drawn)";
        }
        return;
      }
      partial_ = SetupResult{};
      partial_.mode = guidance_->mode;
      partial_.seed = assistant_.config().seed;
      partial_.person_scale = assistant_.person_scale();
      partial_.q_start_rad = q_rad_;
      partial_.q_target_rad = Eigen::Map<const Eigen::VectorXd>(guidance_->target_position.data(), n);
      for (int8_t kind : guidance_->joint_kind)
        partial_.twisting.push_back(kind == orbed::guidance_t::JOINT_TWIST);
      partial_.headset_pose = A_.has_value();
      ORBED_LOG(kInfo) << "assistant: set-up in mode " << guidance::GuidanceModeName(guidance_->mode)
                       << (headset ? (A_ ? " (eye and SLAM error from HMD_POSE)"
                                         : " (eye from the config, no SLAM error)")
                                   : "");
      joint_ = 0;
      look_ = 0;
      phase_ = Phase::kLook;
      [[fallthrough]];
    }
    case Phase::kLook: {
      const Eigen::VectorXd q_target =
          Eigen::Map<const Eigen::VectorXd>(guidance_->target_position.data(), n);
      const double window = look_ == 0 ? std::numeric_limits<double>::infinity()
                                       : assistant_.config().correction_window_deg * kDegToRad;
      const JointLook look = assistant_.Look(joint_, q_rad_, q_target, CurrentView(), window);
      if (look_ == 0) {
        partial_.execution_s += assistant_.JointOverhead_s();
        partial_.ranges.push_back(look.ranges);
      }
      partial_.execution_s += look.time_s + assistant_.TravelTime_s(look.q_rad - q_rad_[joint_]);
      q_goal_ = q_rad_;
      q_goal_[joint_] = look.q_rad;
      ORBED_LOG(kInfo) << "assistant: joint " << joint_ + 1 << " look " << look_ + 1 << ": "
                       << q_rad_[joint_] * kRadToDeg << " -> " << look.q_rad * kRadToDeg << " deg (target "
                       << q_target[joint_] * kRadToDeg << ", " << look.ranges << " range(s) looked right)";
      phase_ = Phase::kMove;
      move_started_s_ = t_s;
      last_command_s_ = -1e9;
      [[fallthrough]];
    }
    case Phase::kMove: {
      const bool arrived = std::abs(q_rad_[joint_] - q_goal_[joint_]) * kRadToDeg < options_.arrived_deg &&
                           motion_state_ == orbed::robot_state_t::MOTION_IDLE;
      const bool stopped = motion_state_ >= orbed::robot_state_t::MOTION_STOPPED_AT_LIMIT &&
                           t_s - move_started_s_ > 2 * options_.command_resend_s;
      if (arrived || stopped) {
        if (stopped && !arrived) {
          ORBED_LOG(kWarn) << "assistant: joint " << joint_ + 1 << " stopped by the sim at "
                           << q_rad_[joint_] * kRadToDeg << " deg (wanted " << q_goal_[joint_] * kRadToDeg
                           << ")";
        }
        if (++look_ >= assistant_.config().looks_per_joint) {
          look_ = 0;
          ++joint_;
        }
        if (joint_ >= n) return Finish();
        phase_ = Phase::kLook;
        return;
      }
      if (t_s - move_started_s_ > options_.move_timeout_s) {
        process_.Fail("joint " + std::to_string(joint_ + 1) + " did not reach " +
                      std::to_string(q_goal_[joint_] * kRadToDeg) + " deg within " +
                      std::to_string(options_.move_timeout_s) + " s (is orbed-iiwa-sim running?)");
        process_.RequestStop();
        phase_ = Phase::kDone;
        return;
      }
      if (t_s - last_command_s_ >= options_.command_resend_s) {
        orbed::iiwa_command_t command{};
        command.utime = process_.ClockUtime();
        command.num_joints = n;
        for (int i = 0; i < n; ++i) command.joint_position.push_back(q_goal_[i]);
        command.num_torques = 0;
        process_.Publish(options_.iiwa_command_channel, command);
        last_command_s_ = t_s;
      }
      return;
    }
    case Phase::kDone:
      return;
  }
}

void AssistantProcess::Finish() {
  phase_ = Phase::kDone;
  partial_.q_reached_rad = q_rad_;
  result_ = partial_;
  double worst = 0;
  for (int i = 0; i < q_rad_.size(); ++i)
    worst = std::max(worst, std::abs(q_rad_[i] - partial_.q_target_rad[i]));
  ORBED_LOG(kInfo) << "assistant: done in " << partial_.execution_s << " s (time model); largest joint error "
                   << worst * kRadToDeg << " deg";
  if (task_) {
    orbed::setup_result_t r{};
    r.utime = process_.ClockUtime();
    r.request_id = task_->request_id;
    r.task_id = task_->task_id;
    r.mode = partial_.mode;
    r.num_joints = static_cast<int32_t>(q_rad_.size());
    for (int i = 0; i < q_rad_.size(); ++i) r.reached_position.push_back(q_rad_[i]);
    r.ranges = partial_.ranges;
    r.execution_s = partial_.execution_s;
    r.person_scale = partial_.person_scale;
    task_result_ = r;
    process_.Publish(options_.setup_result_channel, r);
  }
  if (!options_.result_path.empty()) {
    std::string error;
    if (!ReplaceFile(options_.result_path, SetupResultJson(*result_), &error)) {
      process_.Fail("cannot write " + options_.result_path + ": " + error);
    }
  }
  if (options_.once) process_.RequestStop();
}

int RunAssistant(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-assistant: the emulated set-up assistant. Follows GUIDANCE's target (the virtual robot\n"
      "or the fixed monitor's picture, never its numbers) and moves the real arm joint by joint with\n"
      "IIWA_COMMAND to where the target looks right to it (procs/assistant/assistant.h). Serves\n"
      "SETUP_TASK (orbed-setup) with SETUP_RESULT, or with --once one set-up on its own."};
  CommonFlags common("orbed-assistant");
  AddCommonFlags(&app, &common);
  AddSimTimeFlag(&app, &common);
  AssistantOptions options;
  uint64_t seed = 0;
  app.add_option("--config", options.config_path,
                 "Assistant parameters (default: procs/assistant/assistant.yaml in the source tree)");
  auto* seed_flag = app.add_option("--person-seed", seed, "The person (overrides the config's seed)");
  app.add_option("--result", options.result_path, "Write the set-up's result (JSON) to this file when done");
  app.add_flag("--once", options.once,
               "Carry out the first GUIDANCE's target without a SETUP_TASK, then stop (exit 0)");
  app.add_option("--move-timeout-s", options.move_timeout_s,
                 "A move not finished after this fails the run [s]")
      ->check(orbed::NumberIn(0.1, 3600.0))
      ->capture_default_str();
  app.add_option("--urdf", options.urdf_path,
                 "Robot URDF (default: sim/models/iiwa7.urdf under $ORBED_SOURCE_DIR, else the source tree)");
  app.add_option("--guidance-channel", options.guidance_channel)->capture_default_str();
  app.add_option("--iiwa-status-channel", options.iiwa_status_channel)->capture_default_str();
  app.add_option("--robot-state-channel", options.robot_state_channel)->capture_default_str();
  app.add_option("--registration-channel", options.registration_channel)->capture_default_str();
  app.add_option("--hmd-pose-channel", options.hmd_pose_channel)->capture_default_str();
  app.add_option("--hmd-pose-truth-channel", options.hmd_pose_truth_channel)->capture_default_str();
  app.add_option("--iiwa-command-channel", options.iiwa_command_channel)->capture_default_str();
  app.add_option("--setup-task-channel", options.setup_task_channel)->capture_default_str();
  app.add_option("--setup-result-channel", options.setup_result_channel)->capture_default_str();
  app.add_option("--fixed-view-channel", options.fixed_view_channel)->capture_default_str();
  bool check_config = false;
  app.add_flag("--check-config", check_config,
               "Read --config as a run would, say whether it is valid (exit code 0, else 2), and exit");
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  if (seed_flag->count() > 0) options.seed = seed;
  if (check_config) {
    try {
      LoadConfig(options);
      out << "orbed-assistant: the configuration is valid\n";
      return 0;
    } catch (const std::exception& e) {
      err << "orbed-assistant: " << e.what() << "\n";
      return 2;
    }
  }
  try {
    AssistantProcess assistant(common, options);
    return assistant.Run();
  } catch (const std::exception& e) {
    err << "orbed-assistant: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::assistant
