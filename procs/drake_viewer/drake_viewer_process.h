#pragma once
/// @file
/// orbed-drake-viewer: the testbed in Drake's viewer (Meldis: `python3 -m pydrake.visualization.meldis`
/// on the same LCM URL). drake_viewer.h says what is drawn.
///
///   Subscribes (sim/testbed_poses.h): ROBOT_STATE (X_WR and q: the real robot), REGISTRATION (the
///               latest valid X_WV_mean: the virtual robot), GUIDANCE (its target is the virtual
///               robot's configuration during a set-up; without GUIDANCE the virtual robot takes the
///               real q, as in an alignment), each checked, refusals counted.
///   Publishes:  DRAKE_VIEWER_LOAD_ROBOT at start and every load_period_s (a viewer started later
///               loads the model too); DRAKE_VIEWER_DRAW every 1/rate_hz from the first good
///               ROBOT_STATE on.
///
/// Threading: everything on the Process::Run thread.

#include <iosfwd>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lcmtypes/contract/channels.h"
#include "runtime/process.h"
#include "sim/robot_model.h"
#include "sim/scene.h"
#include "sim/testbed_poses.h"

namespace orbed::viewer {

struct ViewerOptions {
  std::string urdf_path;   ///< "" = the shipped model
  std::string scene_path;  ///< "" = the shipped scene; "none" = no scene objects
  double rate_hz{30.0};
  double load_period_s{2.0};
  std::string robot_state_channel{channels::kRobotState};
  std::string registration_channel{channels::kRegistration};
  std::string guidance_channel{channels::kGuidance};
  std::string load_channel{"DRAKE_VIEWER_LOAD_ROBOT"};
  std::string draw_channel{"DRAKE_VIEWER_DRAW"};
};

class ViewerBridge {
 public:
  /// Throws std::runtime_error for an unreadable model or scene.
  ViewerBridge(const CommonFlags& flags, const ViewerOptions& options);
  int Run() { return process_.Run(); }
  Process& process() { return process_; }
  /// The draw the timer would publish now, or none before the first good ROBOT_STATE.
  std::optional<orbed::viewer_draw_t> DrawNow(int64_t utime) const;

 private:
  Process process_;
  ViewerOptions options_;
  std::optional<sim::Scene> scene_;
  sim::RobotModel model_;
  sim::TestbedPoses poses_;
};

/// orbed-drake-viewer's command line (flags: --help). Exit 0; 2 or CLI11's usage code (106-109) on
/// bad arguments; 1 when it cannot start.
int RunViewerBridge(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::viewer
