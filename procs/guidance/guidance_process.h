#pragma once
/// @file
/// orbed-guidance's shell: subscribes IIWA_STATUS (checked like every subscriber with a robot model:
/// sim/iiwa_status_check.h; refused ones counted), and every 1/rate_hz publishes GUIDANCE for the
/// latest measured configuration (guidance.h): nothing before the first good IIWA_STATUS, and nothing
/// while the latest is older than stale_after_s (a stopped arm's last pose is not guidance; logged
/// when it goes stale and when it is fresh again).
///
/// SETUP_TASK (setup_task_t, from orbed-setup; checked by CheckSetupTask) replaces the target and
/// the mode, keeping the tolerance; a repeated request id changes nothing.
///
/// IGTL_TARGET (target_pose_t, from orbed-igtl-bridge: a pose planned in 3D Slicer) named
/// igtl_target_name ("Trocar") is read as the trocar in W: the tool tip T at its origin, the tool
/// axis along its +z. The trocar IK (sim/trocar_ik.h, with the scene's base pose, tool length and
/// clearance objective, as `orbed-robot ik`) turns it into the joint target, which replaces the
/// current one (mode and tolerance kept). Other names are ignored; a pose that is not one, or that
/// the IK cannot dock collision-free, is refused (IGTL_TARGET/pose, IGTL_TARGET/ik) and the target
/// stays; the same pose again is not solved again. The IK (about 0.1 s) runs on the process thread.
///
/// Threading: everything on the Process::Run thread.

#include <optional>
#include <string>

#include <Eigen/Core>

#include "lcmtypes/contract/channels.h"
#include "procs/guidance/guidance.h"
#include "runtime/process.h"
#include "sim/robot_model.h"
#include "sim/scene.h"
#include "sim/trocar_ik.h"

namespace orbed::guidance {

struct GuidanceOptions {
  std::string urdf_path;  ///< "" = the shipped model
  /// q_target_rad filled by the command line; empty: no GUIDANCE until a SETUP_TASK gives one.
  GuidanceTarget target;
  double rate_hz{30.0};
  /// No GUIDANCE from an IIWA_STATUS received longer ago than this [s] (the sim sends 200 Hz).
  double stale_after_s{0.5};
  /// One of several arms (the scene's `arms:`): the guidance of that arm; every channel
  /// below gets the suffix _NAME (channels::ForArm) and IGTL_TARGET's IK stands at its base.
  std::string arm;
  std::string iiwa_status_channel{channels::kIiwaStatus};
  std::string guidance_channel{channels::kGuidance};
  std::string setup_task_channel{channels::kSetupTask};
  std::string igtl_target_channel{channels::kIgtlTarget};
  std::string igtl_target_name{"Trocar"};  ///< "" = IGTL_TARGET ignored
  std::string scene_path;                  ///< for IGTL_TARGET's IK; "" = the shipped scene
};

class GuidanceProcess {
 public:
  /// Throws std::runtime_error / std::invalid_argument for an unreadable model or a bad target.
  GuidanceProcess(const CommonFlags& flags, const GuidanceOptions& options);
  int Run() { return process_.Run(); }
  Process& process() { return process_; }
  /// The GUIDANCE the timer would publish at `utime` (the process clock [µs]: wall, or the sim's
  /// with --sim-time): none before the first good IIWA_STATUS or when the latest was received more
  /// than stale_after_s before.
  std::optional<orbed::guidance_t> GuidanceNow(int64_t utime) const;

 private:
  Process process_;
  sim::RobotModel model_;
  std::optional<GuidanceCore> core_;  ///< none until a target (command line or SETUP_TASK)
  GuidanceOptions options_;
  Eigen::VectorXd q_rad_;
  bool have_q_{false};
  int64_t q_received_utime_{0};
  bool stale_logged_{false};
  int64_t task_request_id_{0};
  // IGTL_TARGET: the scene, the model with its tool and the clearance objective (loaded at the
  // first target), and the last pose solved.
  void OnIgtlTarget(const Eigen::Isometry3d& X_WT);
  std::optional<sim::Scene> scene_;
  std::optional<sim::RobotModel> ik_model_;
  sim::ClearanceFunction clearance_;
  std::optional<Eigen::Isometry3d> last_X_WT_;
};

/// orbed-guidance's command line (flags: --help): the target from --target-deg, or from --plan FILE
/// [--target N] (orbed-robot plan), or none (then from SETUP_TASK). Exit 0; on bad arguments 2 or CLI11's
/// usage code (106-109); 1 when it cannot start (an unreadable plan or model, a target outside the limits).
int RunGuidance(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::guidance
