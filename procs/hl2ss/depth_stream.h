#pragma once
/// @file
/// The research-mode long-throw depth stream of orbed-hl2ss (port 3805): the depth camera of
/// rm_depth.h rendered from the real room (the scene's objects and the real robot at its IIWA_STATUS
/// joints and ROBOT_STATE base, as orbed-hmd draws it) seen from where the head truly is
/// (HMD_POSE_TRUTH), posed in mode 1 with the rig node of the head the device believes in at that
/// moment (the HMD_POSE of the same utime: RigNodePoseForClient), the calibration in mode 2
/// (PackLongThrowCalibration).
///
/// Pacing: the owner calls Tick() at kLongThrowHz (5 Hz); each mode-0/1 client gets every
/// divisor-th frame made since it connected. A frame is rendered once, whatever the number of
/// clients due, and only when one is due and the true head pose is at most stale_s old. It is
/// rendered from the newest of the last kKeptPoses HMD_POSE_TRUTH whose HMD_POSE (same utime, as
/// orbed-hmd publishes the pair) has come, else from the newest with the newest HMD_POSE (else the
/// truth itself), and stamped with that utime in hl2ss ticks (the packet and the payload's
/// trailing sensor ticks alike).
///
/// Threading: render + PNG (~4 ms p50, ~15 ms p99) run on a worker thread the DepthStream owns.
/// Tick() hands it the frame's inputs through a one-slot mailbox, latest wins: inputs the worker
/// has not started are replaced and Tick() says so (the owner counts "rm_depth/busy"). Finished
/// packets wait in a second slot for the owner's thread (TakeReady(), non-blocking). Every other
/// method is for one thread, the owner's (the process thread); the worker owns the room mesh and
/// the camera.
///
/// Frames: W world, H head (truth or estimate), R real robot base. Units: m, rad; depth [mm].

#include <array>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "lcmtypes/contract/session_control.h"
#include "procs/hl2ss/hl2ss_server.h"
#include "procs/hl2ss/protocol.h"
#include "procs/hl2ss/rm_depth.h"
#include "render/room_mesh.h"
#include "sim/robot_model.h"

namespace orbed::hl2ss {

struct DepthStreamOptions {
  std::string urdf_path;   ///< the robot; "" the shipped model (base/source_paths.h)
  std::string scene_path;  ///< the scene's objects; "" the shipped scene, "none" the robot alone
  LongThrowOptions camera;
  double stale_s{0.5};  ///< a true head pose older than this renders nothing
};

/// One finished frame: the packet for mode-0 and for mode-1 clients, and who is due.
struct DepthPackets {
  uint64_t stamp{0};              ///< hl2ss ticks
  std::vector<int> mode0, mode1;  ///< the clients due
  std::vector<uint8_t> packet0, packet1;
  std::string error;  ///< non-empty: the frame failed (nothing to send)
};

class DepthStream {
 public:
  /// Loads the robot and the scene (std::runtime_error naming the file) and starts the worker.
  DepthStream(const DepthStreamOptions& options, const TimeBase& time_base);
  ~DepthStream();  ///< joins the worker
  DepthStream(const DepthStream&) = delete;
  DepthStream& operator=(const DepthStream&) = delete;

  // Inputs, each checked: a refusal (key: the field class, e.g. "pose", "limits") or kept.
  std::optional<Refusal> OnJoints(const orbed::iiwa_status_t& msg);
  std::optional<Refusal> OnRobotState(const orbed::robot_state_t& msg);
  /// HMD_POSE_TRUTH; `now_us` a monotonic clock [µs] for staleness.
  std::optional<Refusal> OnTruth(const orbed::hmd_pose_t& msg, int64_t now_us);
  /// The checked HMD_POSE's X_WH at its utime (the owner checks HMD_POSE for its other streams).
  void OnEstimate(const Eigen::Isometry3d& X_WH, int64_t utime);

  /// A configured client of port 3805: served (modes 0, 1) or answered with the calibration and
  /// closed (mode 2).
  Decision Configure(int client, const RmDepthLongThrowConfig& config);
  void Disconnected(int client) { clients_.erase(client); }

  /// At 5 Hz: posts a frame when a client is due. True when it replaced a frame the worker had
  /// not started (a drop, "rm_depth/busy").
  bool Tick(int64_t now_us);
  /// The finished frame, if one is waiting.
  std::optional<DepthPackets> TakeReady();
  /// Blocks until a frame is waiting or `timeout_s` passes (tests).
  bool WaitReady(double timeout_s);

  int64_t frames_rendered() const;
  const sim::RobotModel& robot() const { return *robot_; }

 private:
  struct Client {
    uint8_t mode{kMode1};
    int divisor{1};
    int64_t ticks{0};
  };
  struct Job {
    bool robot_known{false};
    Eigen::VectorXd q_rad;
    Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};
    Eigen::Isometry3d X_WH_true{Eigen::Isometry3d::Identity()};
    Eigen::Isometry3d X_WH_estimate{Eigen::Isometry3d::Identity()};
    uint64_t stamp{0};
    std::vector<int> mode0, mode1;
  };
  void WorkerLoop();
  DepthPackets Make(const Job& job);  // worker thread

  DepthStreamOptions options_;
  TimeBase time_base_;
  std::unique_ptr<sim::RobotModel> robot_;
  std::vector<uint8_t> calibration_;  // the mode-2 answer, made once
  std::map<int, Client> clients_;
  std::optional<Eigen::VectorXd> q_rad_;
  std::optional<Eigen::Isometry3d> X_WR_;
  static constexpr size_t kKeptPoses = 8;  // of each: 130 ms at 60 Hz
  struct Truth {
    Eigen::Isometry3d X_WH;
    int64_t received_us;
  };
  std::map<int64_t, Truth> truths_;                 // by utime, the newest kKeptPoses
  std::map<int64_t, Eigen::Isometry3d> estimates_;  // by utime, the newest kKeptPoses

  // The worker's own (after construction only it touches them).
  std::unique_ptr<render::RoomMesh> room_;
  std::unique_ptr<LongThrowCamera> camera_;
  LongThrowFrame frame_;
  bool posed_{false};
  Eigen::VectorXd posed_q_;
  Eigen::Isometry3d posed_X_WR_{Eigen::Isometry3d::Identity()};

  mutable std::mutex mutex_;
  std::condition_variable wake_, ready_cv_;
  std::optional<Job> job_;
  std::optional<DepthPackets> ready_;
  int64_t rendered_{0};
  bool stop_{false};
  std::thread worker_;
};

}  // namespace orbed::hl2ss
