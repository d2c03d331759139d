#pragma once
/// @file
/// orbed-hl2ss: the emulated headset served the way hl2ss serves a HoloLens 2, so that an
/// unmodified hl2ss client (viewer/hl2ss.py and hl2ss_lnm.py) connected to it gets orbed's data
/// (docs/hl2ss.md). One TCP port per stream (hl2ss_server.h; loopback by default):
///
///   RC  3809  remote configuration (emulated_device.h): application version, UTC offset, PV
///             subsystem status, current time, the PV settings; rig-node world poses at the
///             client's timestamps from the last 10 s of HMD_POSE (the depth camera's rig node);
///             the long-throw camera's points mapped (other sensors refused)
///   PV  3810  the front camera (pv_stream.h, pv_encoder.h): each HMD_CAMERA (JPEG, 30 Hz) decoded
///             once, then encoded for each client at its size (the device's video sizes, 15 or
///             30 fps, divisor) and profile (RAW NV12, H.264 base/main/high, H.265 main) with its
///             bitrate and GOP, the 80-byte trailer (intrinsics, the RC settings' exposure, ISO and
///             white balance), stamped with HMD_CAMERA's utime and, in mode 1, posed with its X_WC
///             (the SLAM estimate) in D. Encoding runs on one thread per client (pv_worker.h):
///             the newest picture wins, one still waiting when the next arrives is dropped
///             ("pv/encoder_busy"); payloads come back through a queue drained by the poll, so
///             only this thread sends. When an H.264/H.265 packet finds the client's queue full
///             ("pv/backlog"), its worker is asked for a key frame and the pictures encoded before
///             it are not sent ("pv/before_key_frame"): the client's next picture is an IDR, the
///             first it can decode after the loss. Mode 2 answers the calibration: the latest HMD_CAMERA's
///             intrinsics at the requested size and the camera on the rig node N from the latest
///             HMD_POSE (refused "pv/no_camera", "pv/no_pose" until they arrived). The subsystem
///             must be opened first (the START bit), as on the device.
///   SI  3812  spatial input at si_hz (30 Hz): the latest HMD_POSE's X_WH (the estimate) and
///             GAZE_RAY's ray in D, stamped with that HMD_POSE's utime; a pose or ray older than
///             stale_s is not valid; hands not tracked
///   RM depth long throw 3805: 320×288 depth + AB at 5 Hz (depth_stream.h): the room (the scene's
///             objects, the real robot at IIWA_STATUS's joints and ROBOT_STATE's base) rendered
///             from HMD_POSE_TRUTH's head on a worker thread, PNG, stamped with that pose's utime;
///             mode 1 posed with HMD_POSE's rig node, mode 2 the calibration
///   UMQ 3816  the Unity plugin's message queue (unity_scene.h): the remote Unity scene a client
///             builds (primitives, poses, colours) is published on HOLOGRAMS after each command
///             outside a display list that changed it, and every second, for orbed-hmd to draw in
///             AR_VIEW and the reflective displays
///
/// Timestamps: hl2ss ticks since the process started (protocol.h TimeBase), so ticks + the UTC
/// offset RC answers is the message's utime as a FILETIME.
///
/// Every LCM input is checked before use and refused with a counted reason ("<channel>/field");
/// every client refusal is counted under its key ("pv/size", "rc/unknown", "si/unexpected", ...);
/// frames a slow client misses are counted as drops "<port>/backlog", a client dropped for it as
/// "<port>/stalled". Connections are logged.
///
/// Threading: everything on the Process::Run thread, except the PV encoders (one thread per PV
/// client, at most --max-clients, joined when the client leaves) and the depth camera's render and
/// PNG (DepthStream's worker); both hand their packets back to the process thread, which polls the
/// sockets by a timer every poll_period_s without blocking and sends them there.

#include <array>
#include <iosfwd>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <orbed/gaze_ray_t.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "geometry/camera_model.h"
#include "procs/hl2ss/depth_stream.h"
#include "procs/hl2ss/emulated_device.h"
#include "procs/hl2ss/hl2ss_server.h"
#include "procs/hl2ss/pv_stream.h"
#include "procs/hl2ss/pv_worker.h"
#include "procs/hl2ss/streams.h"
#include "procs/hl2ss/unity_scene.h"
#include "runtime/process.h"

namespace orbed::hl2ss {

struct Hl2ssOptions {
  ServerOptions server;
  std::string pose_channel{"HMD_POSE"};
  std::string gaze_channel{"GAZE_RAY"};
  std::string camera_channel{"HMD_CAMERA"};
  std::string holograms_channel{"HOLOGRAMS"};
  UnitySceneLimits unity_limits;
  double si_hz{30.0};
  double stale_s{0.5};  ///< an HMD_POSE or GAZE_RAY older than this is not reported valid
  double poll_period_s{0.002};
  std::array<uint16_t, 4> app_version{1, 0, 0, 0};
  int pv_encoder_threads{1};  ///< libavcodec threads per PV client's encoder (1 … 8)
  /// The depth stream's robot, scene and camera (depth_stream.h), and its inputs.
  DepthStreamOptions rm_depth;
  std::string truth_channel{"HMD_POSE_TRUTH"};
  std::string iiwa_status_channel{"IIWA_STATUS"};
  std::string robot_state_channel{"ROBOT_STATE"};
};

class Hl2ssProcess {
 public:
  /// Throws std::runtime_error when a port cannot be opened.
  Hl2ssProcess(const CommonFlags& flags, const Hl2ssOptions& options);
  int Run() { return process_.Run(); }
  Process& process() { return process_; }
  const Hl2ssServer& server() const { return server_; }
  const EmulatedDevice& device() const { return device_; }

 private:
  void OnPose(const orbed::hmd_pose_t& msg, const std::string& channel);
  void OnGaze(const orbed::gaze_ray_t& msg, const std::string& channel);
  void OnCamera(const orbed::image_t& msg, const std::string& channel);
  void SendSpatialInput();
  Decision OnConfigured(int client, PortKind port, const StreamConfig& config);
  void OnEvent(const ServerEvent& event);
  void SendEncodedPv();
  void RemovePvClient(int client);
  bool OnUmqBytes(int client, const uint8_t* data, size_t size, std::vector<uint8_t>* reply);
  void PublishHolograms();
  void SendDepth();

  Process process_;
  Hl2ssOptions options_;
  Hl2ssServer server_;
  EmulatedDevice device_;
  ServerHandlers handlers_;
  struct PvClient {
    std::unique_ptr<PvEncoderWorker> worker;
    PvPacer pacer;
    bool mode1{true};
    bool stop_after{false};  // the STOP bit: close the subsystem when this client leaves
    PvKeyFrameGate gate;     // a lost packet: nothing sent until the key frame asked for
  };
  PvHandBack pv_hand_back_;  // before pv_clients_: outlives the workers that push into it
  std::map<int, PvClient> pv_clients_;
  std::optional<geometry::Intrinsics> camera_K_;  // the latest HMD_CAMERA's
  std::optional<orbed::hmd_pose_t> pose_;
  int64_t pose_received_us_{0};
  std::optional<GazeSample> gaze_;
  int64_t gaze_received_us_{0};
  int64_t gaze_utime_{0};
  UnityScene unity_scene_;
  std::map<int, UmqSession> umq_sessions_;
  int64_t published_revision_{-1};
  std::unique_ptr<DepthStream> depth_;  // constructed after the server (its port) and device (time base)
};

/// orbed-hl2ss's command line (--help). Exit 0; 2 on bad arguments; 1 when it cannot start (a
/// port is taken).
int RunHl2ss(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::hl2ss
