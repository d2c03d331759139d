#pragma once
/// @file
/// orbed-igtl-bridge: the testbed over OpenIGTLink (protocol v2, Debian's OpenIGTLink 1.11), for 3D
/// Slicer's OpenIGTLinkIF connector (a client to localhost:18944) or any OpenIGTLink client. The
/// bridge is the server; poses are in millimetres, expressed in orbed's world frame W.
///
///   Sends (to every client; device names in parentheses):
///     TRANSFORM at transform_hz: the robot base X_WR (RobotBase) and every link of the URDF
///               X_WL (iiwa_link_0 … iiwa_link_7, iiwa_link_ee, iiwa_tool, tool_tip) from the
///               latest ROBOT_STATE (X_WR, q) and the model's forward kinematics; the headset
///               X_WH (HMD) and its camera X_WC (HMDCamera) from the latest HMD_POSE (the SLAM
///               estimate); the registration X_WV_mean (Registration) from the latest valid
///               REGISTRATION. A frame is sent once its message has arrived.
///     IMAGE at most image_hz per source: HMD_CAMERA (HMDCamera) and each REFLECTIVE_VIEW display
///               (Reflective<display_id>), decoded to 8-bit RGB (igtl_bridge.h: PackImage).
///     STATUS    for every PROCESS_STATUS (the process's name, at most 20 bytes): code OK when
///               RUNNING, NOT_READY when STARTING, SHUT_DOWN when STOPPING, UNKNOWN_ERROR when
///               FAILED; error name the state; status string its counts and last error.
///     STRING    (Events) for SESSION_CONTROL commands, ALIGNMENT_TRIAL and SETUP_RESULT: one line.
///   Poses from sim/testbed_poses.h (ROBOT_STATE, HMD_POSE, REGISTRATION, checked there).
///   Receives: TRANSFORM or POSITION from a client → IGTL_TARGET (target_pose_t, source "igtl",
///             name = the device name, X_WT in metres): a target planned in Slicer, for the tools
///             on the bus. Other types are skipped; refusals as igtl_bridge.h says.
///
/// Every LCM input is checked (lcmtypes/contract) before use and refused with a counted reason. A
/// client that reads slower than the bridge sends misses packets (counted as drops
/// "igtl/backlog"), never slows the bus. Connections and the first target of each client and device
/// are logged; refusals are counted as "igtl/refused", skipped types as drops "igtl/skipped".
///
/// Threading: everything on the Process::Run thread; the sockets are polled by a timer every
/// poll_period_s without blocking.

#include <iosfwd>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "procs/igtl_bridge/igtl_server.h"
#include "runtime/process.h"
#include "sim/robot_model.h"
#include "sim/testbed_poses.h"

namespace orbed::igtl_bridge {

struct BridgeOptions {
  IgtlServerOptions server;
  std::string urdf_path;  ///< "" = the shipped model
  double transform_hz{30.0};
  double image_hz{2.0};
  double poll_period_s{0.005};
};

/// The frames sent as TRANSFORM for a robot at X_WR with joints q: RobotBase and every link, by
/// device name, in the model's link order. Pure.
std::vector<std::pair<std::string, Eigen::Isometry3d>> RobotFrames(const sim::RobotModel& model,
                                                                   const Eigen::Isometry3d& X_WR,
                                                                   const Eigen::VectorXd& q_rad);

class IgtlBridge {
 public:
  /// Throws std::runtime_error when the model cannot be read or the port cannot be opened.
  IgtlBridge(const CommonFlags& flags, const BridgeOptions& options);
  int Run() { return process_.Run(); }
  Process& process() { return process_; }
  int port() const { return server_.port(); }

 private:
  void SendTransforms();
  void Send(const std::vector<uint8_t>& packet);
  // True (and the time noted) when `source` may send an image now.
  bool ImageDue(const std::string& source, int64_t now_us);

  Process process_;
  BridgeOptions options_;
  sim::RobotModel model_;
  IgtlServer server_;
  sim::TestbedPoses poses_;
  std::map<std::string, int64_t> last_image_us_;
  std::set<std::string> logged_targets_;  // "peer/device" of the targets logged once
};

/// orbed-igtl-bridge's command line (--help). Exit 0; 2 or CLI11's usage code on bad arguments;
/// 1 when it cannot start (the port is taken, the model cannot be read).
int RunIgtlBridge(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::igtl_bridge
