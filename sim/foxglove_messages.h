#pragma once
/// @file
/// The testbed in Foxglove's message shapes, pure: the channels (topic, schema name, JSON Schema) and
/// their JSON messages, the same for the live bridge (orbed-foxglove-bridge, over
/// foxglove.websocket.v1) and for a log written as MCAP (orbed-log export --mcap). Payloads are JSON
/// ("json" encoding) in the shape of Foxglove's schemas foxglove.FrameTransforms,
/// foxglove.SceneUpdate and foxglove.CompressedImage, so Foxglove's 3D and Image panels show them;
/// the registration and the guidance are plain JSON. Every schema is JSON Schema as Foxglove's reader
/// takes it (an object with "properties", one "type" per property; checked by ajv in the MCAP test)
/// and describes a subset of Foxglove's own schema of that name (the test validates the messages
/// against @foxglove/schemas' JSON schemas too).
///
/// Frames (FrameTransforms, metres and unit quaternions): W the world; R the robot base (parent W);
/// each URDF link (parent R) of the real arm; H the headset and C its camera (parent W, the SLAM
/// estimate); V the registered virtual robot base (parent W) and its links "virtual/<link>"
/// (parent V, at the guidance target during a set-up, else at the real joints); D the fixed
/// monitor's camera (parent W). Times: utime [us since the Unix epoch] becomes {sec, nsec}.
///
/// Threading: pure functions.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/registration_t.hpp>

#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::foxglove {

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

struct ChannelSpec {
  ChannelId id;
  std::string topic, schema_name;
  nlohmann::json schema;  ///< JSON Schema (schema encoding "jsonschema")
};
/// Every channel, in id order.
const std::vector<ChannelSpec>& Channels();

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
/// Why an image cannot be shown as a CompressedImage (CheckImage, or not JPEG); "" when it can.
std::string ImageProblem(const orbed::image_t& img);

/// orbed.Registration: a valid registration and its mean X_WV (checked by the caller).
nlohmann::json Registration(const orbed::registration_t& msg, const Eigen::Isometry3d& X_WV);
/// orbed.Guidance: mode name, error per joint [deg], next joint, done.
nlohmann::json Guidance(const orbed::guidance_t& msg);

}  // namespace orbed::foxglove
