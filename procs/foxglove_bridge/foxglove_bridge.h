#pragma once
/// @file
/// The Foxglove WebSocket protocol (subprotocol foxglove.websocket.v1) as orbed-foxglove-bridge
/// speaks it, pure: the channels it advertises, its JSON messages (nlohmann::json) and the binary
/// Message Data frame. Message payloads are JSON ("json" encoding) in the shape of Foxglove's
/// schemas foxglove.FrameTransforms, foxglove.SceneUpdate and foxglove.CompressedImage, so Foxglove's
/// 3D and Image panels show them; the registration and the guidance are plain JSON.
///
/// Frames (FrameTransforms, metres and unit quaternions): W the world; R the robot base (parent W);
/// each URDF link (parent R) of the real arm; H the headset and C its camera (parent W, the SLAM
/// estimate); V the registered virtual robot base (parent W) and its links "virtual/<link>"
/// (parent V, at the guidance target during a set-up, else at the real joints).
///
/// Threading: pure functions.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::foxglove {

inline constexpr char kSubprotocol[] = "foxglove.websocket.v1";

/// The channels, fixed ids from 1.
enum ChannelId : uint32_t {
  kTf = 1,            ///< /tf           foxglove.FrameTransforms
  kScene = 2,         ///< /scene        foxglove.SceneUpdate: the OR, the real and the virtual robot
  kCamera = 3,        ///< /hmd/camera   foxglove.CompressedImage (HMD_CAMERA, JPEG as sent)
  kReflective = 4,    ///< /reflective   foxglove.CompressedImage (every display; frame reflective_<id>)
  kRegistration = 5,  ///< /registration orbed.Registration (JSON)
  kGuidance = 6,      ///< /guidance     orbed.Guidance (JSON)
  kFixedView = 7,     ///< /fixed_view   foxglove.CompressedImage (FIXED_VIEW: the fixed monitor, frame D)
  kLastChannel = kFixedView,
};

/// {"op":"serverInfo",...} and {"op":"advertise",...}: what a client receives on connecting.
nlohmann::json ServerInfo(const std::string& session_id);
nlohmann::json Advertise();

/// One transform of /tf.
struct Frame {
  std::string parent, child;
  Eigen::Isometry3d X_PC{Eigen::Isometry3d::Identity()};
};
/// The frames of the real arm at (X_WR, q) and, if X_WV is given, the virtual one at q_virtual.
std::vector<Frame> RobotFrames(const sim::RobotModel& model, const Eigen::Isometry3d& X_WR,
                               const Eigen::VectorXd& q, const std::optional<Eigen::Isometry3d>& X_WV,
                               const Eigen::VectorXd& q_virtual);
nlohmann::json FrameTransforms(const std::vector<Frame>& frames, int64_t utime);

/// The scene's objects (frame W) and both robots' collision shapes, each link an entity locked to
/// its frame (real grey; virtual translucent green, only when `with_virtual`).
nlohmann::json SceneUpdate(const sim::RobotModel& model, const sim::Scene* scene, bool with_virtual,
                           int64_t utime);

/// foxglove.CompressedImage: the encoded bytes base64 (format "jpeg" or "png").
nlohmann::json CompressedImage(const std::vector<uint8_t>& encoded, const std::string& format,
                               const std::string& frame_id, int64_t utime);

/// The binary Message Data frame: opcode 1, subscription id (uint32 LE), timestamp [ns] (uint64 LE),
/// payload.
std::string MessageData(uint32_t subscription_id, uint64_t timestamp_ns, const std::string& payload);

/// What a client asked for. Malformed requests (not JSON, not an object, unknown op, ids that are
/// not unsigned 32-bit integers, more than kMaxSubscriptions) are refused with a reason.
struct ClientRequest {
  enum Kind { kSubscribe, kUnsubscribe, kIgnored } kind{kIgnored};
  std::vector<std::pair<uint32_t, uint32_t>> subscribe;  ///< (subscription id, channel id)
  std::vector<uint32_t> unsubscribe;                     ///< subscription ids
  std::string op;                                        ///< for kIgnored: the op
};
inline constexpr size_t kMaxSubscriptions = 64;
inline constexpr size_t kMaxClientMessageBytes = 64 << 10;
/// The request, or the reason it is refused (returned in *reason, the result then kIgnored with
/// reason non-empty).
ClientRequest ParseClientMessage(const std::string& text, std::string* reason);

}  // namespace orbed::foxglove
