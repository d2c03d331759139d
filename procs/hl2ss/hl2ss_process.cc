#include "procs/hl2ss/hl2ss_process.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>

#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/log.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/validation.h"
#include "procs/hl2ss/frames.h"
#include "procs/hl2ss/rm_depth.h"
#include "render/image_message.h"
#include "runtime/flags.h"

namespace orbed::hl2ss {
namespace {

constexpr int kMaxCameraSide = 4096;  // PvEncoder's limit: refused before the picture is decoded

int64_t MonotonicMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// "" or why an HMD_CAMERA message cannot be served (checked before its picture is decoded).
std::string CheckCameraImage(const orbed::image_t& img) {
  std::string problem = CheckImage(img);
  if (problem.empty() && (!std::isfinite(img.cx_px) || !std::isfinite(img.cy_px)))
    problem = "image: cx_px, cy_px must be finite";
  if (!problem.empty()) return problem;
  if (img.width % 2 || img.height % 2) return "image: odd size (NV12 needs even sides)";
  if (img.width > kMaxCameraSide || img.height > kMaxCameraSide)
    return "image: larger than " + std::to_string(kMaxCameraSide) + " pixels a side";
  if (img.pixel_format != orbed::image_t::FORMAT_JPEG && img.pixel_format != orbed::image_t::FORMAT_BGR8)
    return "image: pixel format " + std::to_string(img.pixel_format) + " (JPEG and BGR8 are served)";
  return "";
}

}  // namespace

Hl2ssProcess::Hl2ssProcess(const CommonFlags& flags, const Hl2ssOptions& options)
    : process_(flags),
      options_(options),
      server_(options.server),
      device_(TimeBase{NowMicros()}, options.app_version, options.rm_depth.camera),
      unity_scene_(options.unity_limits),
      depth_(std::make_unique<DepthStream>(options.rm_depth, device_.time_base())) {
  handlers_.on_configured = [this](int client, PortKind port, const StreamConfig& config) {
    return OnConfigured(client, port, config);
  };
  handlers_.on_rc = [this](int, const RcCommand& command) {
    const RcOutcome outcome = device_.HandleRc(command, NowMicros());
    Decision d;
    if (outcome.refused) {
      d.kind = Decision::kRefuse;
      d.key = outcome.key;
      d.reason = outcome.reason;
    }
    d.reply = outcome.reply;
    return d;
  };
  handlers_.on_event = [this](const ServerEvent& event) { OnEvent(event); };
  handlers_.on_bytes = [this](int client, const uint8_t* data, size_t size, std::vector<uint8_t>* reply) {
    return OnUmqBytes(client, data, size, reply);
  };

  process_.Subscribe<orbed::hmd_pose_t>(
      options_.pose_channel,
      [this](const orbed::hmd_pose_t& msg, const std::string& channel, int64_t) { OnPose(msg, channel); });
  process_.Subscribe<orbed::gaze_ray_t>(
      options_.gaze_channel,
      [this](const orbed::gaze_ray_t& msg, const std::string& channel, int64_t) { OnGaze(msg, channel); });
  process_.Subscribe<orbed::image_t>(
      options_.camera_channel,
      [this](const orbed::image_t& msg, const std::string& channel, int64_t) { OnCamera(msg, channel); });
  process_.AddWallTimer(
      1.0 / options_.si_hz, [this] { SendSpatialInput(); }, "hl2ss/si");
  // The depth stream's inputs (checked in depth_stream.cc) and its 5 Hz frames.
  const auto refused = [this](const std::string& channel, const std::optional<Refusal>& r) {
    if (r) process_.Reject(channel + "/" + r->key, r->reason);
  };
  process_.Subscribe<orbed::iiwa_status_t>(
      options_.iiwa_status_channel,
      [this, refused](const orbed::iiwa_status_t& msg, const std::string& channel, int64_t) {
        refused(channel, depth_->OnJoints(msg));
      });
  process_.Subscribe<orbed::robot_state_t>(
      options_.robot_state_channel,
      [this, refused](const orbed::robot_state_t& msg, const std::string& channel, int64_t) {
        refused(channel, depth_->OnRobotState(msg));
      });
  process_.Subscribe<orbed::hmd_pose_t>(
      options_.truth_channel,
      [this, refused](const orbed::hmd_pose_t& msg, const std::string& channel, int64_t) {
        refused(channel, depth_->OnTruth(msg, MonotonicMicros()));
      });
  if (server_.port(PortKind::kRmDepthLongThrow) != 0)
    process_.AddWallTimer(
        1.0 / kLongThrowHz,
        [this] {
          if (depth_->Tick(MonotonicMicros())) process_.CountDrop("rm_depth/busy");
        },
        "hl2ss/rm_depth");
  if (server_.port(PortKind::kUmq) != 0)
    process_.AddWallTimer(
        1.0,
        [this] {
          if (unity_scene_.revision() != 0) PublishHolograms();  // nothing placed yet: nothing to say
        },
        "hl2ss/holograms");
  process_.AddWallPoll(options_.poll_period_s, [this] {
    SendDepth();
    SendEncodedPv();
    server_.Poll(MonotonicMicros(), handlers_);
  });

  std::ostringstream ports;
  for (PortKind kind :
       {PortKind::kRc, PortKind::kPv, PortKind::kSi, PortKind::kRmDepthLongThrow, PortKind::kUmq})
    if (server_.port(kind) != 0) ports << " " << PortName(kind) << " " << server_.port(kind);
  ORBED_LOG(kInfo) << "hl2ss: serving on " << options_.server.bind_address << ":" << ports.str()
                   << "; UTC offset " << device_.time_base().UtcOffset();
}

void Hl2ssProcess::OnPose(const orbed::hmd_pose_t& msg, const std::string& channel) {
  const std::string problem = FirstError({CheckWorldPose(msg.X_WH, "X_WH"), CheckWorldPose(msg.X_WC, "X_WC"),
                                          CheckEnum(msg.tracking_state, 0, 3, "tracking_state")});
  if (!problem.empty()) return process_.Reject(channel + "/field", problem);
  pose_ = msg;
  pose_received_us_ = MonotonicMicros();
  device_.RecordPose(msg.utime, FromPose(msg.X_WH), msg.tracking_state != orbed::hmd_pose_t::LOST);
  depth_->OnEstimate(FromPose(msg.X_WH), msg.utime);
}

void Hl2ssProcess::OnGaze(const orbed::gaze_ray_t& msg, const std::string& channel) {
  const Eigen::Vector3d origin = ToVector3(msg.origin_W_m), direction = ToVector3(msg.direction_W);
  std::string problem = FirstError({CheckBounded(msg.origin_W_m, 3, kMaxWorldDistance_m, "origin_W_m"),
                                    CheckFinite(msg.direction_W, 3, "direction_W")});
  if (problem.empty() && std::abs(direction.norm() - 1.0) > 1e-6)
    problem = "direction_W is not a unit vector";
  if (!problem.empty()) return process_.Reject(channel + "/field", problem);
  gaze_ = GazeSample{origin, direction};
  gaze_received_us_ = MonotonicMicros();
  gaze_utime_ = msg.utime;
}

void Hl2ssProcess::SendSpatialInput() {
  const auto clients = server_.Serving(PortKind::kSi);
  if (clients.empty()) return;
  const int64_t now = MonotonicMicros();
  const int64_t stale_us = static_cast<int64_t>(options_.stale_s * 1e6);
  std::optional<HeadSample> head;
  if (pose_ && now - pose_received_us_ <= stale_us)
    head = HeadSample{FromPose(pose_->X_WH), pose_->tracking_state == orbed::hmd_pose_t::LOST};
  std::optional<GazeSample> gaze;
  if (gaze_ && now - gaze_received_us_ <= stale_us) gaze = gaze_;
  const uint64_t stamp = device_.time_base().TicksOf(head ? pose_->utime : NowMicros());
  const std::vector<uint8_t> packet = PackPacket(stamp, SiPayload(head, gaze), nullptr);
  for (const auto& [client, config] : clients) server_.Send(client, packet, handlers_.on_event);
}

void Hl2ssProcess::OnCamera(const orbed::image_t& msg, const std::string& channel) {
  const std::string problem = CheckCameraImage(msg);
  if (!problem.empty()) return process_.Reject(channel + "/image", problem);
  geometry::Intrinsics K;
  K.width_px = msg.width;
  K.height_px = msg.height;
  K.fx_px = msg.fx_px;
  K.fy_px = msg.fy_px;
  K.cx_px = msg.cx_px;
  K.cy_px = msg.cy_px;
  camera_K_ = K;  // for mode 2, also while nobody streams
  std::vector<PvEncoderWorker*> due;
  for (const auto& [client, config] : server_.Serving(PortKind::kPv)) {
    const auto it = pv_clients_.find(client);
    if (it != pv_clients_.end() && it->second.pacer.Next()) due.push_back(it->second.worker.get());
  }
  if (due.empty()) return;
  PvJob job;
  const std::string undecodable = render::DecodeImageMessage(msg, &job.bgr);
  if (!undecodable.empty()) return process_.Reject(channel + "/image", undecodable);
  job.K = K;
  job.metadata = PvCaptureMetadataFromSettings(device_.pv_settings());
  job.timestamp = device_.time_base().TicksOf(msg.utime);
  const std::array<float, 16> pose = PoseMatrixRowMajor(CameraPoseForClient(FromPose(msg.X_WC)));
  for (PvEncoderWorker* worker : due) {
    PvJob mine = job;  // the picture is shared, read-only
    if (pv_clients_.at(worker->client()).mode1) mine.pose = pose;
    if (!worker->Offer(std::move(mine))) process_.CountDrop("pv/encoder_busy");
  }
}

void Hl2ssProcess::SendEncodedPv() {
  for (PvResult& r : pv_hand_back_.TakeAll()) {
    const auto it = pv_clients_.find(r.client);
    if (it == pv_clients_.end()) continue;  // left while this was queued
    if (!r.error.empty()) {
      process_.CountDrop("pv/encode_failed");
      process_.SetLastError("pv encoder: " + r.error);
      continue;
    }
    // After a lost packet, pictures encoded before the key frame asked for cannot be decoded.
    if (!it->second.gate.Pass(r.key_frame)) {
      process_.CountDrop("pv/before_key_frame");
      continue;
    }
    server_.Send(r.client, PackPacket(r.timestamp, r.payload, r.pose ? &*r.pose : nullptr),
                 handlers_.on_event);
  }
}

// A frame the depth worker finished: to the clients due (one render, one packet per mode).
void Hl2ssProcess::SendDepth() {
  std::optional<DepthPackets> frame = depth_->TakeReady();
  if (!frame) return;
  if (!frame->error.empty()) return process_.SetLastError(frame->error);
  for (int client : frame->mode0) server_.Send(client, frame->packet0, handlers_.on_event);
  for (int client : frame->mode1) server_.Send(client, frame->packet1, handlers_.on_event);
}

void Hl2ssProcess::RemovePvClient(int client) {
  const auto it = pv_clients_.find(client);
  if (it == pv_clients_.end()) return;
  pv_clients_.erase(it);          // joins its worker: at most one picture's encode
  pv_hand_back_.Discard(client);  // what it finished meanwhile
}

bool Hl2ssProcess::OnUmqBytes(int client, const uint8_t* data, size_t size, std::vector<uint8_t>* reply) {
  UmqSession& session = umq_sessions_.try_emplace(client, &unity_scene_).first->second;
  const bool keep = session.Consume(data, size, reply);
  for (const Refusal& r : session.TakeRefusals()) process_.Reject("umq/" + r.key, r.reason);
  if (unity_scene_.revision() != published_revision_ && !session.in_display_list()) PublishHolograms();
  return keep;
}

void Hl2ssProcess::PublishHolograms() {
  // Every second even when unchanged: orbed-hmd forgets holograms it has not heard of for 3 s.
  process_.Publish(options_.holograms_channel, HologramSceneMessage(unity_scene_, NowMicros()));
  published_revision_ = unity_scene_.revision();
}

Decision Hl2ssProcess::OnConfigured(int client, PortKind port, const StreamConfig& config) {
  Decision d;
  const auto refuse = [&d](const std::string& key, const std::string& reason) {
    d.kind = Decision::kRefuse;
    d.key = key;
    d.reason = reason;
    return d;
  };
  if (port == PortKind::kSi) return d;
  if (port == PortKind::kRmDepthLongThrow)
    return depth_->Configure(client, std::get<RmDepthLongThrowConfig>(config));
  if (port != PortKind::kPv) return refuse(PortName(port) + "/unexpected", "no stream on this port");
  const PvConfig& c = std::get<PvConfig>(config);
  if (c.start) {
    device_.OpenPv(c.mrc);
    ORBED_LOG(kInfo) << "hl2ss: PV subsystem opened";
  }
  if (c.mode == kMode3) {
    if (c.stop && device_.pv_open()) {
      device_.ClosePv();
      ORBED_LOG(kInfo) << "hl2ss: PV subsystem closed";
    }
    d.kind = Decision::kReplyAndClose;
    return d;
  }
  if (!device_.pv_open())
    return refuse("pv/subsystem_closed",
                  "the PV subsystem is not open (a client opens it first: start_subsystem_pv)");
  if (auto format_refusal = CheckPvClientFormat(c))
    return refuse(format_refusal->key, format_refusal->reason);
  if (c.mode == kMode2) {
    if (!camera_K_)
      return refuse("pv/no_camera", "no HMD_CAMERA picture yet: the calibration is the camera's intrinsics");
    if (!pose_) return refuse("pv/no_pose", "no HMD_POSE yet: the calibration places the camera on the head");
    d.kind = Decision::kReplyAndClose;
    d.reply = PvCalibrationFor(*camera_K_, c.width, c.height, FromPose(pose_->X_WH), FromPose(pose_->X_WC),
                               options_.rm_depth.camera.X_HN);  // the rig node the depth camera is on
    return d;
  }
  PvRefusal refusal;
  const std::optional<PvEncoderConfig> encoder_config =
      PvEncoderConfigFromClient(c, options_.pv_encoder_threads, &refusal);
  if (!encoder_config) return refuse(refusal.key, refusal.reason);
  std::string error;
  std::shared_ptr<PvEncoder> encoder = PvEncoder::Create(*encoder_config, &error);
  if (!encoder) return refuse("pv/encoder", error);
  PvEncodeFn encode = [encoder](const PvJob& job, std::vector<uint8_t>* payload, std::string* why) {
    if (job.key_frame) encoder->ForceKeyFrame();
    return encoder->Encode(job.bgr, job.K, job.metadata, payload, why);
  };
  RemovePvClient(client);
  pv_clients_.emplace(
      client, PvClient{std::make_unique<PvEncoderWorker>(client, std::move(encode), &pv_hand_back_),
                       PvPacer(c), c.mode == kMode1, c.stop, PvKeyFrameGate(c.profile != kProfileRaw)});
  return d;
}

void Hl2ssProcess::OnEvent(const ServerEvent& event) {
  const std::string who = PortName(event.port) + " client " + event.peer;
  switch (event.kind) {
    case ServerEvent::kConnected:
      ORBED_LOG(kInfo) << "hl2ss: " << who << " connected";
      break;
    case ServerEvent::kDisconnected: {
      const auto it = pv_clients_.find(event.client);
      if (it != pv_clients_.end() && it->second.stop_after && device_.pv_open()) {
        device_.ClosePv();
        ORBED_LOG(kInfo) << "hl2ss: PV subsystem closed";
      }
      RemovePvClient(event.client);
      depth_->Disconnected(event.client);
      const auto umq = umq_sessions_.find(event.client);
      if (umq != umq_sessions_.end()) {
        umq->second.OnDisconnect();
        umq_sessions_.erase(umq);
      }
      ORBED_LOG(kInfo) << "hl2ss: " << who << " left: " << event.detail;
      break;
    }
    case ServerEvent::kRefused:
      process_.Reject(event.key, event.peer + ": " + event.detail);
      break;
    case ServerEvent::kDropped: {
      process_.CountDrop(event.key);
      // A video client that lost a packet decodes nothing more until an IDR: ask its encoder for
      // one, and send it nothing before.
      const auto it = pv_clients_.find(event.client);
      if (event.port == PortKind::kPv && it != pv_clients_.end() && it->second.gate.OnDropped())
        it->second.worker->RequestKeyFrame();
      break;
    }
    case ServerEvent::kStalled:
      process_.CountDrop(event.key);
      ORBED_LOG(kWarn) << "hl2ss: " << who << " dropped: " << event.detail;
      break;
  }
}

int RunHl2ss(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-hl2ss: the emulated headset served as hl2ss serves a HoloLens 2, for unmodified hl2ss\n"
      "clients (viewer/hl2ss.py, hl2ss_lnm.py): remote configuration on 3809, the front camera (PV,\n"
      "RAW NV12, H.264 or H.265 with the pose; its calibration) on 3810 from HMD_CAMERA, spatial\n"
      "input (head pose, eye-gaze ray) on 3812 from HMD_POSE and GAZE_RAY; research-mode depth long\n"
      "throw on 3805 (5 Hz, rendered from HMD_POSE_TRUTH, the scene and the real arm); the Unity\n"
      "message queue on 3816 (holograms a client places, published on HOLOGRAMS). docs/hl2ss.md."};
  CommonFlags common("orbed-hl2ss");
  AddCommonFlags(&app, &common);
  Hl2ssOptions options;
  int pv_port = kPortPersonalVideo, si_port = kPortSpatialInput, rc_port = kPortRemoteConfiguration,
      rm_depth_port = kPortRmDepthLongThrow, umq_port = kPortUnityMessageQueue;
  double max_queue_mb = 64;
  std::string app_version = "1.0.0.0";
  app.add_option("--bind", options.server.bind_address,
                 "IPv4 address to listen on (0.0.0.0: every interface, for a client on another host)")
      ->capture_default_str();
  app.add_option("--pv-port", pv_port, "Personal-video port (0: any free port, printed at start)")
      ->check(orbed::NumberIn(0, 65535))
      ->capture_default_str();
  app.add_option("--si-port", si_port, "Spatial-input port")
      ->check(orbed::NumberIn(0, 65535))
      ->capture_default_str();
  app.add_option("--rc-port", rc_port, "Remote-configuration port")
      ->check(orbed::NumberIn(0, 65535))
      ->capture_default_str();
  app.add_option("--rm-depth-port", rm_depth_port, "Research-mode depth long-throw port")
      ->check(orbed::NumberIn(0, 65535))
      ->capture_default_str();
  app.add_option("--umq-port", umq_port, "Unity message-queue port (holograms a client places)")
      ->check(orbed::NumberIn(0, 65535))
      ->capture_default_str();
  app.add_option("--max-clients", options.server.max_clients, "Connections served at once per port")
      ->check(orbed::NumberIn(1, 64))
      ->capture_default_str();
  app.add_option("--max-queue-mb", max_queue_mb,
                 "Bytes queued per client before its packets are dropped [MiB]")
      ->check(orbed::NumberIn(1.0, 1024.0))
      ->capture_default_str();
  app.add_option("--max-drops", options.server.max_consecutive_drops,
                 "Packets dropped in a row before a client that stopped reading is closed")
      ->check(orbed::NumberIn(1, 100000))
      ->capture_default_str();
  app.add_option("--config-timeout-s", options.server.config_timeout_s,
                 "Seconds a client has to send its configuration (or finish an RC command)")
      ->check(orbed::NumberIn(0.1, 600.0))
      ->capture_default_str();
  app.add_option("--pv-encoder-threads", options.pv_encoder_threads,
                 "libavcodec threads of each PV client's encoder (each client has its own encoder thread)")
      ->check(orbed::NumberIn(1, 8))
      ->capture_default_str();
  app.add_option("--si-hz", options.si_hz, "Spatial-input rate [Hz]")
      ->check(orbed::NumberIn(1.0, 120.0))
      ->capture_default_str();
  app.add_option("--stale-s", options.stale_s, "Age after which a pose or gaze ray is reported invalid [s]")
      ->check(orbed::NumberIn(0.01, 60.0))
      ->capture_default_str();
  app.add_option("--app-version", app_version, "What RC's application version answers (four numbers)")
      ->capture_default_str();
  app.add_option("--pose-channel", options.pose_channel, "hmd_pose_t channel (the head)")
      ->capture_default_str();
  app.add_option("--gaze-channel", options.gaze_channel, "gaze_ray_t channel (the eye-gaze ray)")
      ->capture_default_str();
  app.add_option("--camera-channel", options.camera_channel, "image_t channel (the front camera)")
      ->capture_default_str();
  app.add_option(
      "--urdf", options.rm_depth.urdf_path,
      "Robot URDF the depth camera sees (default: sim/models/iiwa7.urdf under $ORBED_SOURCE_DIR, else "
      "the source tree)");
  app.add_option("--scene", options.rm_depth.scene_path,
                 "Scene YAML whose objects the depth camera sees (default: sim/models/scenes/trocar_or.yaml, "
                 "found like --urdf; none: the robot alone)");
  app.add_option("--truth-channel", options.truth_channel,
                 "hmd_pose_t channel of the true head (where the depth camera renders from)")
      ->capture_default_str();
  app.add_option("--iiwa-status-channel", options.iiwa_status_channel,
                 "iiwa_status_t channel (the real arm's joints, for the depth camera)")
      ->capture_default_str();
  app.add_option("--robot-state-channel", options.robot_state_channel,
                 "robot_state_t channel (the real arm's base X_WR, for the depth camera)")
      ->capture_default_str();
  app.add_option("--holograms-channel", options.holograms_channel,
                 "hologram_scene_t channel the Unity message queue's scene is published on")
      ->capture_default_str();
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  {
    unsigned a = 0, b = 0, c = 0, d = 0;
    char tail = 0;
    if (std::sscanf(app_version.c_str(), "%u.%u.%u.%u%c", &a, &b, &c, &d, &tail) != 4 || a > 65535 ||
        b > 65535 || c > 65535 || d > 65535) {
      err << "orbed-hl2ss: --app-version: expected four numbers 0..65535 as a.b.c.d, got '" << app_version
          << "'\n";
      return 2;
    }
    options.app_version = {static_cast<uint16_t>(a), static_cast<uint16_t>(b), static_cast<uint16_t>(c),
                           static_cast<uint16_t>(d)};
  }
  options.server.ports = {{PortKind::kPv, pv_port},
                          {PortKind::kSi, si_port},
                          {PortKind::kRc, rc_port},
                          {PortKind::kRmDepthLongThrow, rm_depth_port},
                          {PortKind::kUmq, umq_port}};
  options.server.max_queue_bytes = static_cast<size_t>(max_queue_mb * (1 << 20));
  try {
    Hl2ssProcess hl2ss(common, options);
    return hl2ss.Run();
  } catch (const std::exception& e) {
    err << "orbed-hl2ss: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::hl2ss
