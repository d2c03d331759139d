#include "procs/assistant/assistant_process.h"

#include <exception>

#include <CLI/CLI.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "base/format.h"
#include "base/log.h"
#include "base/replace_file.h"
#include "base/source_paths.h"
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

AssistantConfig LoadConfig(const AssistantOptions& o) {
  AssistantConfig c =
      LoadAssistantConfig(o.config_path.empty() ? SourceTreePath(kDefaultConfigRelativePath) : o.config_path);
  if (o.seed) c.seed = *o.seed;
  return c;
}

MachineOptions MachineOptionsOf(const AssistantOptions& o) {
  MachineOptions m;
  m.once = o.once;
  m.command_resend_s = o.command_resend_s;
  m.move_timeout_s = o.move_timeout_s;
  m.arrived_deg = o.arrived_deg;
  m.fixed_view_stale_s = o.fixed_view_stale_s;
  return m;
}

}  // namespace

AssistantProcess::AssistantProcess(const CommonFlags& flags, const AssistantOptions& options)
    : process_(flags),
      model_(sim::RobotModel::LoadFlag(options.urdf_path)),
      options_(options),
      machine_(model_, LoadConfig(options), MachineOptionsOf(options)) {
  process_.Subscribe<orbed::guidance_t>(
      options_.guidance_channel, [this](const orbed::guidance_t& msg, const std::string& channel, int64_t) {
        const std::string problem = guidance::CheckGuidance(msg, model_, kJointLimitSlackRad);
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        machine_.OnGuidance(msg);
      });
  process_.Subscribe<orbed::iiwa_status_t>(
      options_.iiwa_status_channel,
      [this](const orbed::iiwa_status_t& msg, const std::string& channel, int64_t) {
        Eigen::VectorXd q;
        const sim::IiwaStatusProblem problem = sim::CheckIiwaStatus(msg, model_, kJointLimitSlackRad, &q);
        if (!problem.rejection_class.empty()) {
          return process_.Reject(channel + "/" + problem.rejection_class, problem.reason);
        }
        machine_.OnJoints(q);
      });
  process_.Subscribe<orbed::robot_state_t>(
      options_.robot_state_channel,
      [this](const orbed::robot_state_t& msg, const std::string& channel, int64_t) {
        const std::string problem = CheckRobotState(msg, model_.num_joints());
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        machine_.OnRobotState(FromPose(msg.X_WR), msg.motion_state);
      });
  process_.Subscribe<orbed::registration_t>(
      options_.registration_channel,
      [this](const orbed::registration_t& msg, const std::string& channel, int64_t) {
        if (!msg.valid) return;  // no mean yet
        const std::string problem = CheckPose(msg.X_WV_mean, "REGISTRATION.X_WV_mean");
        if (!problem.empty()) return process_.Reject(channel + "/pose", problem);
        machine_.OnRegistration(FromPose(msg.X_WV_mean));
      });
  auto on_pose = [this](bool truth) {
    return [this, truth](const orbed::hmd_pose_t& msg, const std::string& channel, int64_t) {
      const std::string problem = CheckPose(msg.X_WH, "X_WH");
      if (!problem.empty()) return process_.Reject(channel + "/pose", problem);
      machine_.OnHeadPose(truth, msg.seq, FromPose(msg.X_WH));
    };
  };
  process_.Subscribe<orbed::image_t>(
      options_.fixed_view_channel, [this](const orbed::image_t& msg, const std::string& channel, int64_t) {
        const std::string problem = CheckImage(msg);
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        const Eigen::Vector3d p_WD = FromPose(msg.X_WC).translation();
        if (machine_.OnMonitorCamera(p_WD, process_.ClockSeconds())) {
          ORBED_LOG(kInfo) << "assistant: the monitor's camera is at (" << Fixed(p_WD.x(), 2) << ", "
                           << Fixed(p_WD.y(), 2) << ", " << Fixed(p_WD.z(), 2) << ") m (" << channel << ")";
        }
      });
  process_.Subscribe<orbed::hmd_pose_t>(options_.hmd_pose_channel, on_pose(false));
  process_.Subscribe<orbed::hmd_pose_t>(options_.hmd_pose_truth_channel, on_pose(true));
  process_.Subscribe<orbed::setup_task_t>(
      options_.setup_task_channel,
      [this](const orbed::setup_task_t& msg, const std::string& channel, int64_t) {
        const TaskAnswer answer = machine_.OnSetupTask(msg);
        if (answer.reply) process_.Publish(options_.setup_result_channel, *answer.reply);  // a repeat
        if (answer.kind == TaskAnswer::kRefused) return process_.Reject(channel + "/field", answer.problem);
        if (answer.kind == TaskAnswer::kStarted) {
          ORBED_LOG(kInfo) << "assistant: task " << EscapeText(msg.task_id) << " (mode "
                           << guidance::GuidanceModeName(msg.mode) << ")";
        }
      });
  process_.AddTimer(
      options_.step_period_s, [this] { Step(); }, "step");
  const Assistant& person = machine_.assistant();
  ORBED_LOG(kInfo) << "assistant: person seed " << person.config().seed << " (noise scale "
                   << person.person_scale() << ", pace " << person.pace() << "), "
                   << person.config().looks_per_joint
                   << " looks per joint; waiting for GUIDANCE, IIWA_STATUS and ROBOT_STATE";
}

void AssistantProcess::Step() {
  const StepOutput out = machine_.Step(process_.ClockSeconds(), process_.ClockUtime());
  for (const MachineNote& note : out.notes) {
    if (note.warning) {
      ORBED_LOG(kWarn) << note.text;
    } else {
      ORBED_LOG(kInfo) << note.text;
    }
  }
  if (out.command) process_.Publish(options_.iiwa_command_channel, *out.command);
  if (!out.failure.empty()) {
    process_.Fail(out.failure);
    process_.RequestStop();
    return;
  }
  if (out.task_reply) process_.Publish(options_.setup_result_channel, *out.task_reply);
  if (out.finished && !options_.result_path.empty()) {
    std::string error;
    if (!ReplaceFile(options_.result_path, SetupResultJson(*machine_.result()), &error)) {
      process_.Fail("cannot write " + options_.result_path + ": " + error);
    }
  }
  if (out.stop) process_.RequestStop();
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
