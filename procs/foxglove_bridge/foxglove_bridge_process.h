#pragma once
/// @file
/// orbed-foxglove-bridge: a live 3D view of the testbed in Foxglove (its "Foxglove WebSocket"
/// connection to ws://localhost:8765), over the foxglove.websocket.v1 protocol with JSON payloads
/// (foxglove_bridge.h says the channels, shapes and frames).
///
///   Subscribes: ROBOT_STATE, REGISTRATION, GUIDANCE and HMD_POSE through sim/testbed_poses.h (X_WR
///               and q, the latest valid X_WV_mean, the guidance target as the virtual robot's
///               configuration, X_WH and X_WC); HMD_CAMERA, REFLECTIVE_VIEW and FIXED_VIEW (CheckImage;
///               JPEG passed on as sent; FIXED_VIEW's X_WC is the monitor camera's frame D on /tf).
///   Sends:      /tf at rate_hz from the first good ROBOT_STATE; /scene every scene_period_s;
///               /hmd/camera, /reflective and /fixed_view at most image_hz per source; /registration and
///               /guidance as they come (at most rate_hz for the guidance). Nothing is encoded for a
///               channel nobody subscribed to.
///
/// Every LCM input is checked before use and refused with a counted reason; a client that reads
/// slower than the bridge sends misses frames (drops "foxglove/backlog"); what clients send wrong
/// is counted under "foxglove/refused".
///
/// Threading: everything on the Process::Run thread; the server is polled every poll_period_s.

#include <iosfwd>
#include <map>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "procs/foxglove_bridge/foxglove_server.h"
#include "runtime/process.h"
#include "sim/robot_model.h"
#include "sim/scene.h"
#include "sim/testbed_poses.h"

namespace orbed::foxglove {

struct BridgeOptions {
  ServerOptions server;
  std::string urdf_path;   ///< "" = the shipped model
  std::string scene_path;  ///< "" = the shipped scene; "none" = no scene objects
  double rate_hz{30.0};
  double scene_period_s{1.0};
  double image_hz{5.0};
  double poll_period_s{0.005};
};

class FoxgloveBridge {
 public:
  /// Throws std::runtime_error when the model or scene cannot be read or the port cannot be opened.
  FoxgloveBridge(const CommonFlags& flags, const BridgeOptions& options);
  int Run() { return process_.Run(); }
  Process& process() { return process_; }
  int port() const { return server_.port(); }

 private:
  void Send(uint32_t channel, int64_t utime, const std::string& payload);
  void SendRegistration(const orbed::registration_t& msg);
  void SendGuidance(const orbed::guidance_t& msg);
  bool Due(const std::string& source, double hz, int64_t now_us);

  Process process_;
  BridgeOptions options_;
  sim::RobotModel model_;
  std::optional<sim::Scene> scene_;
  FoxgloveServer server_;
  sim::TestbedPoses poses_;
  std::map<std::string, int64_t> last_sent_us_;
  std::optional<Eigen::Isometry3d> X_WD_;  // the fixed monitor's camera (FIXED_VIEW)
};

/// orbed-foxglove-bridge's command line (--help). Exit 0; 2 or CLI11's usage code on bad arguments;
/// 1 when it cannot start.
int RunFoxgloveBridge(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::foxglove
