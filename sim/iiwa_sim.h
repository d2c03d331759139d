#pragma once
/// @file
/// The orbed-iiwa-sim process: a simulated KUKA LBR iiwa 7 R800 in the OR scene, driven like a
/// hand-guided arm in manual mode (the motion law is ManualArm's, sim/manual_arm.h: synchronised
/// straight joint-space moves at the URDF velocity limits, commands clamped to the joint limits,
/// steps refused before a collision).
///
///   Subscribes: IIWA_COMMAND (iiwa_command_t, Drake's lcmt_iiwa_command layout) — the target;
///               PLAN_CHECK_REQUEST (plan_check_request_t).
///   Publishes, every tick (period_sec, default 5 ms = 200 Hz), all with the same utime:
///               IIWA_STATUS (iiwa_status_t, Drake's lcmt_iiwa_status layout), ROBOT_STATE
///               (robot_state_t: true X_WR from the scene, X_RF, X_RT, every link's X_RL, limit
///               flags, motion state and stop reason), COLLISION_STATUS (collision_status_t: pairs
///               closer than report_distance_m, per-link clearance, the duration of the query that
///               produced it — made when the arm last moved; the scene is static);
///               PLAN_CHECK_REPLY (plan_check_reply_t) answering each request, echoing request_id —
///               an invalid request gets request_valid = false and a reason, never silence;
///               PROCESS_STATUS at 1 Hz (Process), with rejections counted per class.
///
/// IIWA_STATUS fields: joint_position_measured = q after this tick's step; joint_velocity_estimated
/// = that step / period_sec; joint_position_commanded = the last accepted command as sent
/// (unclamped; q0 before any); joint_position_ipo = the set point tracked this tick (= measured:
/// the simulated servo is perfect); torques 0 (no dynamics).
///
/// Rejected commands (Process::Reject, keys "<channel>/<class>"), the process keeps running:
///   num_joints (!= the arm's), num_torques (neither 0 nor num_joints), non_finite (a NaN or inf
///   position or torque), stale (utime more than stale_command_sec away from the wall clock, older
///   or ahead; 0 disables), decode (undecodable bytes, by Process).
/// A command beyond a joint limit is not rejected: it is clamped, and the arm stops at the limit
/// with motion_state STOPPED_AT_LIMIT and the joint named in stop_reason.
///
/// Clocks: utime of every output = wall clock (NowMicros) at the tick; the stale check compares a
/// command's utime with the same clock. The tick itself runs on the monotonic clock (Process timer;
/// late ticks are skipped, never bunched, and a step never exceeds v_max * period_sec).
///
/// Threading: everything on the Process::Run() thread.

#include <memory>
#include <string>
#include <vector>

#include <orbed/iiwa_command_t.hpp>
#include <orbed/plan_check_request_t.hpp>

#include "procs/common/channels.h"
#include "procs/common/process.h"
#include "sim/manual_arm.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::sim {

struct IiwaSimOptions {
  /// URDF and scene files; "" = the files shipped in the source tree (SourceTreePath()).
  std::string urdf_path;
  std::string scene_path;
  /// Tick = status period [s], > 0.
  double period_sec{0.005};
  /// Initial joint vector [deg]; empty = all zero (the arm upright). Must be within the limits.
  std::vector<double> initial_q_deg;
  /// Commands whose utime is further than this from the wall clock are rejected [s]; 0 = never.
  double stale_command_sec{1.0};
  /// Motion stops this far before contact [m] (ManualArmOptions::stop_margin_m).
  double stop_margin_m{0.01};
  /// COLLISION_STATUS lists pairs closer than this [m].
  double report_distance_m{0.05};
  /// robot_state_t::robot_name.
  std::string robot_name{"iiwa7"};
  std::string iiwa_status_channel{channels::kIiwaStatus};
  std::string iiwa_command_channel{channels::kIiwaCommand};
  std::string robot_state_channel{channels::kRobotState};
  std::string collision_status_channel{channels::kCollisionStatus};
  std::string plan_check_request_channel{channels::kPlanCheckRequest};
  std::string plan_check_reply_channel{channels::kPlanCheckReply};
};

/// `relative` (e.g. "sim/models/iiwa7.urdf") under $ORBED_SOURCE_DIR if set, else under the
/// source tree this library was built from (as `orbed-robot` does).
std::string SourceTreePath(const std::string& relative);

class IiwaSim {
 public:
  /// Loads the URDF and scene (std::runtime_error naming the file, element/key and what was
  /// expected), validates the options (std::invalid_argument naming the option), then opens LCM
  /// (std::runtime_error naming the URL).
  IiwaSim(const orbed::CommonFlags& flags, const IiwaSimOptions& options);
  ~IiwaSim();

  int Run() { return process_->Run(); }
  orbed::Process& process() { return *process_; }
  /// The options with the file paths resolved.
  const IiwaSimOptions& options() const { return options_; }
  const Scene& scene() const { return scene_; }
  const ManualArm& arm() const { return *arm_; }

  /// One tick: step the arm and publish IIWA_STATUS, ROBOT_STATE, COLLISION_STATUS (the timer's
  /// callback; public so tests can drive it without waiting).
  void Tick();

 private:
  void OnCommand(const orbed::iiwa_command_t& msg, const std::string& channel);
  void OnPlanCheck(const orbed::plan_check_request_t& msg, const std::string& channel);
  void PublishAll(int64_t utime);

  IiwaSimOptions options_;
  Scene scene_;
  std::unique_ptr<ManualArm> arm_;
  std::unique_ptr<orbed::Process> process_;
  std::vector<int> reported_links_;  // links with geometry and a finite clearance
  std::vector<Eigen::Isometry3d> X_RL_;
};

}  // namespace orbed::sim
