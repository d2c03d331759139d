#include "procs/foxglove_bridge/foxglove_bridge_process.h"

#include <exception>

#include <CLI/CLI.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/reflective_view_t.hpp>
#include <orbed/registration_t.hpp>

#include "base/format.h"
#include "base/log.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/validation.h"
#include "procs/foxglove_bridge/foxglove_bridge.h"
#include "runtime/flags.h"
#include "sim/guidance_messages.h"

namespace orbed::foxglove {
FoxgloveBridge::FoxgloveBridge(const CommonFlags& flags, const BridgeOptions& options)
    : process_(flags),
      options_(options),
      model_(sim::RobotModel::LoadFlag(options.urdf_path)),
      scene_(sim::LoadSceneFlag(options.scene_path)),
      server_(options.server,
              [this](const ServerEvent& e) {
                if (e.kind == ServerEvent::kConnected)
                  ORBED_LOG(kInfo) << "foxglove: client " << e.peer << " connected";
                if (e.kind == ServerEvent::kDisconnected)
                  ORBED_LOG(kInfo) << "foxglove: client " << e.peer << " left";
                if (e.kind == ServerEvent::kRefused)
                  process_.Reject("foxglove/refused", e.peer + ": " + e.detail);
              }),
      poses_(&process_, model_, sim::TestbedPoses::Channels{},
             {[this](const orbed::registration_t& msg) { SendRegistration(msg); },
              [this](const orbed::guidance_t& msg) { SendGuidance(msg); }}) {
  const auto on_image = [this](const orbed::image_t& img, uint32_t channel_id, const std::string& frame,
                               const std::string& channel) {
    if (!server_.HasSubscribers(channel_id) || !Due(frame, options_.image_hz, NowMicros())) return;
    const std::string problem = ImageProblem(img);
    if (!problem.empty()) return process_.Reject(channel + "/image", problem);
    Send(channel_id, img.utime, CompressedImage(img.data, "jpeg", frame, img.utime).dump());
  };
  process_.Subscribe<orbed::image_t>(
      channels::kHmdCamera, [on_image](const orbed::image_t& msg, const std::string& channel, int64_t) {
        on_image(msg, kCamera, "C", channel);
      });
  process_.Subscribe<orbed::reflective_view_t>(
      channels::kReflectiveView,
      [this, on_image](const orbed::reflective_view_t& msg, const std::string& channel, int64_t) {
        if (msg.display_id < 0 || msg.display_id > 999)
          return process_.Reject(channel + "/field", "display_id outside 0..999");
        on_image(msg.image, kReflective, "reflective_" + std::to_string(msg.display_id), channel);
      });
  process_.Subscribe<orbed::image_t>(
      channels::kFixedView, [this, on_image](const orbed::image_t& msg, const std::string& channel, int64_t) {
        const std::string problem = CheckPose(msg.X_WC, "FIXED_VIEW.X_WC");
        if (!problem.empty()) return process_.Reject(channel + "/pose", problem);
        X_WD_ = FromPose(msg.X_WC);
        on_image(msg, kFixedView, "D", channel);
      });
  process_.AddTimer(
      1.0 / options_.rate_hz,
      [this] {
        if (!poses_.X_WR() || !server_.HasSubscribers(kTf)) return;
        std::vector<Frame> frames =
            RobotFrames(model_, *poses_.X_WR(), poses_.q(), poses_.X_WV(), poses_.q_virtual());
        if (poses_.X_WH()) frames.push_back({"W", "H", *poses_.X_WH()});
        if (poses_.X_WC()) frames.push_back({"W", "C", *poses_.X_WC()});
        if (X_WD_) frames.push_back({"W", "D", *X_WD_});
        const int64_t now = NowMicros();
        Send(kTf, now, FrameTransforms(frames, now).dump());
      },
      "foxglove/tf");
  process_.AddTimer(
      options_.scene_period_s,
      [this] {
        if (!server_.HasSubscribers(kScene)) return;
        const int64_t now = NowMicros();
        Send(kScene, now,
             SceneUpdate(model_, scene_ ? &*scene_ : nullptr, poses_.X_WV().has_value(), now).dump());
      },
      "foxglove/scene");
  process_.AddTimer(
      options_.poll_period_s, [this] { server_.Poll(); }, "foxglove/poll");
  ORBED_LOG(kInfo) << "foxglove bridge: ws://" << options_.server.bind_address << ":" << server_.port()
                   << " (foxglove.websocket.v1: /tf, /scene, /hmd/camera, /reflective, /registration, "
                      "/guidance, /fixed_view)";
}

void FoxgloveBridge::SendRegistration(const orbed::registration_t& msg) {
  if (!server_.HasSubscribers(kRegistration)) return;
  Send(kRegistration, msg.utime, Registration(msg, *poses_.X_WV()).dump());
}

void FoxgloveBridge::SendGuidance(const orbed::guidance_t& msg) {
  if (!server_.HasSubscribers(kGuidance) || !Due("guidance", options_.rate_hz, NowMicros())) return;
  Send(kGuidance, msg.utime, Guidance(msg).dump());
}

void FoxgloveBridge::Send(uint32_t channel, int64_t utime, const std::string& payload) {
  const int missed = server_.Publish(channel, static_cast<uint64_t>(utime) * 1000, payload);
  if (missed > 0) process_.CountDrop("foxglove/backlog", missed);
}

bool FoxgloveBridge::Due(const std::string& source, double hz, int64_t now_us) {
  const auto it = last_sent_us_.find(source);
  if (it != last_sent_us_.end() && now_us - it->second < static_cast<int64_t>(1e6 / hz)) return false;
  last_sent_us_[source] = now_us;
  return true;
}

int RunFoxgloveBridge(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-foxglove-bridge: the testbed live in Foxglove (open a Foxglove WebSocket connection to\n"
      "ws://localhost:8765). Frames W, R, the links, H, C, V and the virtual links on /tf; the OR and\n"
      "both robots on /scene; the headset camera and the reflective displays; the registration and\n"
      "the guidance as JSON."};
  CommonFlags common("orbed-foxglove-bridge");
  AddCommonFlags(&app, &common);
  BridgeOptions options;
  app.add_option("--port", options.server.port, "WebSocket port (0: any free port, printed at start)")
      ->check(orbed::NumberIn(0, 65535))
      ->capture_default_str();
  app.add_option("--bind", options.server.bind_address, "Address to listen on (0.0.0.0: every interface)")
      ->capture_default_str();
  app.add_option("--max-clients", options.server.max_clients, "Connections served at once")
      ->check(orbed::NumberIn(1, 64))
      ->capture_default_str();
  app.add_option("--rate-hz", options.rate_hz, "/tf rate [Hz]")
      ->check(orbed::NumberIn(0.1, 1000.0))
      ->capture_default_str();
  app.add_option("--image-hz", options.image_hz, "Image rate per camera or display [Hz]")
      ->check(orbed::NumberIn(0.01, 60.0))
      ->capture_default_str();
  app.add_option("--scene-period-s", options.scene_period_s, "Period of /scene [s]")
      ->check(orbed::NumberIn(0.1, 3600.0))
      ->capture_default_str();
  app.add_option("--urdf", options.urdf_path, "Robot URDF (default: the shipped iiwa 7)");
  app.add_option("--scene", options.scene_path, "Scene YAML (default: the shipped OR; none: no scene)");
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  try {
    FoxgloveBridge bridge(common, options);
    return bridge.Run();
  } catch (const std::exception& e) {
    err << "orbed-foxglove-bridge: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::foxglove
