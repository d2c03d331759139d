#include "procs/guidance/guidance_process.h"

#include <cmath>
#include <exception>

#include <CLI/CLI.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/setup_task_t.hpp>
#include <orbed/target_pose_t.hpp>

#include "base/format.h"
#include "base/log.h"
#include "base/number_list.h"
#include "base/source_paths.h"
#include "base/units.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/validation.h"
#include "runtime/flags.h"
#include "sim/iiwa_status_check.h"
#include "sim/trocar_clearance.h"

namespace orbed::guidance {
namespace {

// The sim clamps to the limits; this absorbs rounding (as orbed-hmd).
constexpr double kJointLimitSlackRad = 0.01;

GuidanceOptions WithArmChannels(GuidanceOptions o) {
  for (std::string* channel :
       {&o.iiwa_status_channel, &o.guidance_channel, &o.setup_task_channel, &o.igtl_target_channel}) {
    *channel = channels::ForArm(*channel, o.arm);
  }
  return o;
}

}  // namespace

GuidanceProcess::GuidanceProcess(const CommonFlags& flags, const GuidanceOptions& options)
    : process_(flags),
      model_(sim::RobotModel::LoadFlag(options.urdf_path)),
      core_(options.target.q_target_rad.size() > 0
                ? std::optional<GuidanceCore>(GuidanceCore(model_, options.target))
                : std::nullopt),
      options_(WithArmChannels(options)) {
  process_.Subscribe<orbed::iiwa_status_t>(
      options_.iiwa_status_channel,
      [this](const orbed::iiwa_status_t& msg, const std::string& channel, int64_t received_utime) {
        Eigen::VectorXd q;
        const sim::IiwaStatusProblem problem = sim::CheckIiwaStatus(msg, model_, kJointLimitSlackRad, &q);
        if (!problem.rejection_class.empty()) {
          process_.Reject(channel + "/" + problem.rejection_class, problem.reason);
          return;
        }
        q_rad_ = q;
        have_q_ = true;
        q_received_utime_ = process_.sim_time() ? process_.ClockUtime() : received_utime;
      });
  process_.Subscribe<orbed::setup_task_t>(
      options_.setup_task_channel,
      [this](const orbed::setup_task_t& msg, const std::string& channel, int64_t) {
        if (msg.request_id != 0 && msg.request_id == task_request_id_) return;  // a repeat
        const std::string problem = CheckSetupTask(msg, model_, 0.0);
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        GuidanceTarget target = options_.target;
        target.mode = msg.mode;
        target.q_target_rad = Eigen::Map<const Eigen::VectorXd>(msg.target_position.data(), msg.num_joints);
        core_.emplace(model_, target);
        task_request_id_ = msg.request_id;
        ORBED_LOG(kInfo) << "guidance: task " << EscapeText(msg.task_id) << ", mode "
                         << GuidanceModeName(msg.mode);
      });
  if (!options_.igtl_target_name.empty()) {
    process_.Subscribe<orbed::target_pose_t>(
        options_.igtl_target_channel,
        [this](const orbed::target_pose_t& msg, const std::string& channel, int64_t) {
          if (msg.name != options_.igtl_target_name) return;  // another frame from the planner
          const std::string problem = CheckPose(msg.X_WT, "X_WT");
          if (!problem.empty()) return process_.Reject(channel + "/pose", problem);
          OnIgtlTarget(FromPose(msg.X_WT));
        });
  }
  process_.AddTimer(
      1.0 / options_.rate_hz,
      [this] {
        const auto guidance = GuidanceNow(process_.ClockUtime());
        if (guidance) process_.Publish(options_.guidance_channel, *guidance);
        if (core_ && have_q_ && !guidance != stale_logged_) {
          stale_logged_ = !guidance;
          if (stale_logged_) {
            ORBED_LOG(kWarn) << "no IIWA_STATUS for " << options_.stale_after_s << " s: GUIDANCE paused";
          } else {
            ORBED_LOG(kInfo) << "IIWA_STATUS again: GUIDANCE resumed";
          }
        }
      },
      options_.guidance_channel);
  if (!core_) {
    ORBED_LOG(kInfo) << "guidance: no target yet; waiting for SETUP_TASK on " << options_.setup_task_channel
                     << (options_.igtl_target_name.empty() ? std::string()
                                                           : " or a '" + options_.igtl_target_name + "' on " +
                                                                 options_.igtl_target_channel);
    return;
  }
  std::string target;
  for (int i = 0; i < options_.target.q_target_rad.size(); ++i) {
    target += (i ? ", " : "") +
              std::to_string(static_cast<int>(std::lround(options_.target.q_target_rad[i] * kRadToDeg)));
  }
  ORBED_LOG(kInfo) << "guidance: mode " << GuidanceModeName(options_.target.mode) << ", target (" << target
                   << ") deg, tolerance " << options_.target.tolerance_deg << " deg, " << options_.rate_hz
                   << " Hz on " << options_.guidance_channel;
}

void GuidanceProcess::OnIgtlTarget(const Eigen::Isometry3d& X_WT) {
  if (last_X_WT_ && last_X_WT_->isApprox(X_WT, 1e-12)) return;  // solved already
  last_X_WT_ = X_WT;
  const std::string key = options_.igtl_target_channel + "/ik";
  try {
    if (!scene_) {
      scene_ = sim::LoadSceneFile(options_.scene_path.empty() ? SourceTreePath(sim::kDefaultSceneRelativePath)
                                                              : options_.scene_path);
      scene_->StandAt(options_.arm);
      ik_model_ = sim::LoadRobotForScene(options_.urdf_path.empty()
                                             ? SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath)
                                             : options_.urdf_path,
                                         *scene_);
      clearance_ = sim::MakeTrocarClearanceFunction(*ik_model_, *scene_);
    }
  } catch (const std::exception& e) {
    scene_.reset();
    return process_.Reject(key, std::string("cannot load the scene: ") + e.what());
  }
  const Eigen::Isometry3d X_RT = scene_->X_WR.inverse() * X_WT;
  sim::TrocarIkTarget trocar;
  trocar.p_RT = X_RT.translation();
  trocar.axis_R = X_RT.linear().col(2);
  const sim::TrocarIkResult ik = sim::SolveTrocarIk(*ik_model_, trocar, sim::TrocarIkOptions{}, clearance_);
  if (!ik.success) return process_.Reject(key, "no collision-free docking: " + ik.message);
  GuidanceTarget target = core_ ? core_->target() : options_.target;
  target.q_target_rad = ik.q_rad;
  core_.emplace(model_, target);
  std::string q_deg;
  for (int i = 0; i < ik.q_rad.size(); ++i)
    q_deg += (i ? ", " : "") + std::to_string(static_cast<int>(std::lround(ik.q_rad[i] * kRadToDeg)));
  ORBED_LOG(kInfo) << "guidance: target from " << options_.igtl_target_channel << " '"
                   << options_.igtl_target_name << "': (" << q_deg << ") deg";
}

std::optional<orbed::guidance_t> GuidanceProcess::GuidanceNow(int64_t utime) const {
  const int64_t stale_after_us = static_cast<int64_t>(options_.stale_after_s * 1e6);
  if (!core_ || !have_q_ || utime - q_received_utime_ > stale_after_us) return std::nullopt;
  return core_->Compute(q_rad_, utime);
}

int RunGuidance(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-guidance: joint-by-joint set-up guidance toward a target configuration. Subscribes\n"
      "IIWA_STATUS; publishes GUIDANCE (target and current joints, per-joint error [deg], the next\n"
      "joint to move from the base outwards, twisting or revolving per joint, done) at --rate-hz.\n"
      "Without --target-deg or --plan it waits for a target on SETUP_TASK (orbed-setup). A trocar pose\n"
      "named --igtl-target-name on IGTL_TARGET (3D Slicer through orbed-igtl-bridge) replaces the target\n"
      "with the trocar IK's docking configuration."};
  CommonFlags common("orbed-guidance");
  AddCommonFlags(&app, &common);
  AddSimTimeFlag(&app, &common);
  GuidanceOptions options;
  std::string target_deg, mode = "ar", plan_path;
  int plan_target = 1;
  auto* target_flag = app.add_option("--target-deg", target_deg,
                                     "Target configuration q1,...,q7 [deg] (within the joint limits)");
  auto* plan_flag =
      app.add_option("--plan", plan_path, "A plan from `orbed-robot plan`: its --target is the target")
          ->excludes(target_flag);
  app.add_option("--target", plan_target, "Which target of --plan (1-based)")
      ->check(orbed::NumberIn(1, 20))
      ->capture_default_str()
      ->needs(plan_flag);
  app.add_option("--mode", mode, "Guidance mode on GUIDANCE: ar, ar_reflective or fixed")
      ->capture_default_str();
  app.add_option("--tolerance-deg", options.target.tolerance_deg,
                 "A joint within this of its target is done [deg]")
      ->check(orbed::NumberIn(0.001, 90.0))
      ->capture_default_str();
  app.add_option("--rate-hz", options.rate_hz, "GUIDANCE rate [Hz]")
      ->check(orbed::NumberIn(0.1, 1000.0))
      ->capture_default_str();
  app.add_option("--stale-after-s", options.stale_after_s,
                 "No GUIDANCE while the latest IIWA_STATUS is older than this [s]")
      ->check(orbed::NumberIn(0.01, 60.0))
      ->capture_default_str();
  app.add_option("--urdf", options.urdf_path,
                 "Robot URDF (default: sim/models/iiwa7.urdf under $ORBED_SOURCE_DIR, else the source tree)");
  AddInstanceFlag(
      &app, "--arm", &options.arm,
      "Guide the arm NAME (one of several): every channel below gets the suffix _NAME (IIWA_STATUS_A1, "
      "GUIDANCE_A1, ...) and IGTL_TARGET's IK stands at its base in --scene");
  app.add_option("--iiwa-status-channel", options.iiwa_status_channel)->capture_default_str();
  app.add_option("--guidance-channel", options.guidance_channel)->capture_default_str();
  app.add_option("--setup-task-channel", options.setup_task_channel)->capture_default_str();
  app.add_option("--igtl-target-channel", options.igtl_target_channel)->capture_default_str();
  app.add_option(
         "--igtl-target-name", options.igtl_target_name,
         "IGTL_TARGET pose read as the trocar (tool tip, axis +z) and docked by trocar IK; \"\": none")
      ->capture_default_str();
  app.add_option("--scene", options.scene_path, "Scene YAML for IGTL_TARGET's IK (default: the shipped OR)");
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  try {
    options.target.mode = GuidanceModeFromName(mode);
    if (!target_deg.empty()) {
      const std::vector<double> q_deg = ParseNumberList(target_deg, "--target-deg");
      options.target.q_target_rad = Eigen::Map<const Eigen::VectorXd>(q_deg.data(), q_deg.size()) * kDegToRad;
    }
  } catch (const std::invalid_argument& e) {
    err << "orbed-guidance: " << e.what() << "\n";
    return 2;
  }
  try {
    if (!plan_path.empty()) {
      const sim::RobotModel model = sim::RobotModel::LoadFlag(options.urdf_path);
      options.target.q_target_rad = ReadPlanTarget(plan_path, plan_target, model.num_joints());
    }
    common.sim_clock_arm = options.arm;
    GuidanceProcess guidance(common, options);
    return guidance.Run();
  } catch (const std::exception& e) {
    err << "orbed-guidance: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::guidance
