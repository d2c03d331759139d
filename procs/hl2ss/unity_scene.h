#pragma once
/// @file
/// The remote Unity scene of hl2ss's Unity plugin (RemoteUnityScene.cs), served from orbed: what a
/// client builds over the plugin's message queue (port 3816, hl2ss's IPCPort.UNITY_MESSAGE_QUEUE)
/// with hl2ss_rus.py's command_buffer: create a primitive, set its transform, colour and whether it
/// is shown, remove it. A pure core: bytes in, the plugin's answers out, and the scene state, which
/// HologramSceneMessage() turns into a HOLOGRAMS message (lcmtypes/orbed_hologram_scene_t.lcm) for
/// orbed-hmd to draw. No sockets, no LCM, no clock.
///
/// The wire (hl2ss.py's umq_command_buffer and ipc_umq, the plugin's MQ server): the client sends
/// commands back to back, each `id (u32) | size (u32) | data (size bytes)`, little-endian, split
/// over TCP reads in any way; the plugin answers every command with one u32 (little-endian), in
/// order. Commands and answers (RemoteUnityScene.cs; a "key" is the u32 a create command answered;
/// in target mode UseLast every key in the data is replaced by the last created object's):
///    0 create primitive  data u32 type (0 sphere, 1 capsule, 2 cylinder, 3 cube, 4 plane, any
///                        other value a quad): a new, inactive, white object; answers its key
///    1 set active        key, i32 state (≠ 0 shown): 1
///    2 set world transform  key, 10 f32: position (x, y, z), rotation (x, y, z, w), scale: 1
///    3 set local transform  the same relative to the plugin's object, at Unity's origin: 1
///    4 set color         key, 4 f32 (r, g, b, a): 1
///    5 set texture       key, image bytes (kept by Unity, ignored here): 1
///    6 create text       no data: a new, inactive text object; answers its key
///    7 set text          key, f32 font size, 4 f32 colour, UTF-8 text (not kept): 1 if a text object
///    8 say               UTF-8 text (text to speech; not spoken here): 1
///   16 remove            key: 1
///   17 remove all        1
///   18 / 19 begin / end display list: 1 (Unity then runs the commands in one frame; here every
///                        command takes effect at once, and the server publishes between lists)
///   20 set target mode   u32 (0 UseID, other UseLast): 1
///   0xFFFFFF00 .. 03     debug: try-lock / unlock the PV and EV mutexes (recursive): 1, or 0 for
///                        an unlock without a lock
///   0xFFFFFFFE debug message  UTF-8 text (last_debug_message()): 1
///   0xFFFFFFFF disconnect  resets the target mode and the last key: answers 0xFFFFFFFF
/// A command whose data is shorter than it needs, or that names no object, answers 0 and changes
/// nothing, as the plugin. Unknown ids (15, load mesh, which the plugin does not handle, among
/// them) answer 0. Objects outlive the connection that made them (the Unity scene does); a
/// disconnect resets only the target mode and the last key.
///
/// Bounded, and stricter than Unity where Unity would misbehave (each refused with a counted
/// reason, Refusal{key, reason}; the command answers 0 and changes nothing):
///   size            a command's declared size > limits.max_command_bytes: the connection is to be
///                   closed (Consume returns false) before any of its data is read;
///   unknown_command an id not listed above;
///   short           data shorter than the command needs;
///   unknown_key     no object with that key (a text command on a primitive too);
///   non_finite      a float not finite;
///   range           a position beyond limits.max_position_m, a scale beyond limits.max_scale, a
///                   rotation of norm < 1e-6 (others are normalised);
///   objects         a create with limits.max_objects objects in the scene (or the keys used up).
/// Memory: a session keeps at most kHeadBytes of a command (what the commands read); the rest of a
/// command's data is counted off without being kept, so a session costs O(1) whatever it is sent,
/// and the scene O(max_objects).
///
/// Frames (procs/hl2ss/frames.h): Unity's scene U is left-handed, y up, with D's origin, which is
/// W's; a Unity position p_U is p_D = (x, y, −z) and p_W = R_WD · p_D. An object's frame G is its
/// Unity local frame with z negated (right-handed): R_DG = S R_U S (S = diag(1, 1, −1)), and its
/// Unity localScale scales along G's axes. Poses are those of the headset's map (W as everything
/// the headset reports, docs/design.md §2). Units: m; scale and colour dimensionless.
///
/// Threading: not synchronised. One UnityScene and its sessions are used from one thread (the
/// server's loop).

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <orbed/hologram_scene_t.hpp>

#include "lcmtypes/contract/session_control.h"

namespace orbed::hl2ss {

/// The command ids (hl2ss_rus.py's command_buffer, RemoteUnityScene.cs).
namespace umq {
inline constexpr std::uint32_t kCreatePrimitive = 0;
inline constexpr std::uint32_t kSetActive = 1;
inline constexpr std::uint32_t kSetWorldTransform = 2;
inline constexpr std::uint32_t kSetLocalTransform = 3;
inline constexpr std::uint32_t kSetColor = 4;
inline constexpr std::uint32_t kSetTexture = 5;
inline constexpr std::uint32_t kCreateText = 6;
inline constexpr std::uint32_t kSetText = 7;
inline constexpr std::uint32_t kSay = 8;
inline constexpr std::uint32_t kRemove = 16;
inline constexpr std::uint32_t kRemoveAll = 17;
inline constexpr std::uint32_t kBeginDisplayList = 18;
inline constexpr std::uint32_t kEndDisplayList = 19;
inline constexpr std::uint32_t kSetTargetMode = 20;
inline constexpr std::uint32_t kDebugTryLockPv = 0xFFFFFF00u;
inline constexpr std::uint32_t kDebugUnlockPv = 0xFFFFFF01u;
inline constexpr std::uint32_t kDebugTryLockEv = 0xFFFFFF02u;
inline constexpr std::uint32_t kDebugUnlockEv = 0xFFFFFF03u;
inline constexpr std::uint32_t kDebugMessage = 0xFFFFFFFEu;
inline constexpr std::uint32_t kDisconnect = 0xFFFFFFFFu;
}  // namespace umq

/// What an object is (the values of hologram_scene_t's KIND_*; the primitive ids are the client's).
enum class ObjectKind : std::int8_t {
  kSphere = 0,
  kCapsule = 1,
  kCylinder = 2,
  kCube = 3,
  kPlane = 4,
  kQuad = 5,
  kText = 6
};

/// One object of the scene.
struct UnityObject {
  ObjectKind kind{ObjectKind::kCube};
  Eigen::Isometry3d X_WG{Eigen::Isometry3d::Identity()};  ///< pose of G in W (the headset's map)
  Eigen::Vector3d scale{1, 1, 1};                         ///< Unity's localScale along G's axes
  std::array<float, 4> rgba{1, 1, 1, 1};                  ///< as the client set it
  bool active{false};                                     ///< shown
};

struct UnitySceneLimits {
  int max_objects{1024};                       ///< at most hologram_scene_t::MAX_HOLOGRAMS
  std::uint32_t max_command_bytes{16u << 20};  ///< a command's data [bytes] (a texture's image fits)
  double max_position_m{1e4};                  ///< |p_W| of an object [m]
  double max_scale{1e3};                       ///< |scale| on each axis
};

/// The objects, by key (shared by every connection, as the Unity scene is).
class UnityScene {
 public:
  /// Throws std::invalid_argument for limits out of range (max_objects in 1 .. MAX_HOLOGRAMS,
  /// max_command_bytes ≥ 64, the bounds > 0).
  explicit UnityScene(const UnitySceneLimits& limits = {});

  const UnitySceneLimits& limits() const { return limits_; }
  const std::map<std::int32_t, UnityObject>& objects() const { return objects_; }
  /// Counts the changes of the objects (0 = none since construction).
  std::int64_t revision() const { return revision_; }
  /// The last debug message (at most 256 bytes of it, bytes outside printable ASCII as \xNN).
  const std::string& last_debug_message() const { return last_debug_message_; }

 private:
  friend class UmqSession;
  UnitySceneLimits limits_;
  std::map<std::int32_t, UnityObject> objects_;
  std::int64_t next_key_{1};
  std::int64_t revision_{0};
  int pv_locks_{0}, ev_locks_{0};
  std::string last_debug_message_;
};

/// One client's connection to the message queue: the TCP-session adapter a server feeds.
///   - Consume() with the bytes as they arrive (any split); it appends the answers to send back;
///     false: close the connection (after sending what *reply holds);
///   - OnDisconnect() when the client goes (a server-closed connection included);
///   - TakeRefusals() after each Consume(): what to count on PROCESS_STATUS (suggested key
///     "umq/<key>") and log.
/// The plugin serves one client at a time; a server that lets several connect at once gives each a
/// session on the same scene (their target modes and last keys are their own).
class UmqSession {
 public:
  /// Bytes of a command's data a session keeps (set text reads 24, a debug message keeps 256).
  static constexpr std::size_t kHeadBytes = 256;

  /// `scene` must outlive the session.
  explicit UmqSession(UnityScene* scene) : scene_(scene) {}

  bool Consume(const std::uint8_t* data, std::size_t size, std::vector<std::uint8_t>* reply);
  void OnDisconnect();
  std::vector<Refusal> TakeRefusals();

  /// Between a begin and an end display list: a server publishes the scene when it is not.
  bool in_display_list() const { return in_display_list_; }
  /// Commands answered so far.
  std::int64_t commands() const { return commands_; }

 private:
  std::uint32_t Execute(std::uint32_t id);
  std::uint32_t CreateObject(ObjectKind kind);
  // The object the command's key (or the last key, UseLast) names, or null (refused unknown_key).
  UnityObject* Target(const char* command);
  std::uint32_t SetTransform();
  std::uint32_t SetColor();
  std::uint32_t SetText();
  std::uint32_t Refuse(const std::string& key, const std::string& reason);  // counts; answers 0
  bool Short(std::size_t need, const char* command);

  UnityScene* scene_;
  // The command being read.
  std::array<std::uint8_t, 8> header_{};
  std::size_t header_got_{0};
  std::uint32_t id_{0}, size_{0};
  std::uint32_t data_got_{0};
  std::array<std::uint8_t, kHeadBytes> head_{};
  bool closed_{false};
  // The plugin's per-client state.
  bool use_last_{false};
  std::int32_t last_key_{0};
  bool in_display_list_{false};
  std::int64_t commands_{0};
  std::vector<Refusal> refusals_;
};

/// The HOLOGRAMS message of the scene now: every object in key order, stamped `utime` [µs].
orbed::hologram_scene_t HologramSceneMessage(const UnityScene& scene, std::int64_t utime);

/// X_WG from a client's Unity position and rotation (x, y, z, w), by frames.h. The rotation is
/// normalised (the caller checks that its norm is not 0).
Eigen::Isometry3d PoseFromUnity(const Eigen::Vector3d& p_U, const Eigen::Vector4d& q_U_xyzw);

}  // namespace orbed::hl2ss
