#include "procs/igtl_bridge/igtl_bridge_process.h"

#include <exception>
#include <variant>

#include <igtlStatusMessage.h>
#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/process_status_t.hpp>
#include <orbed/reflective_view_t.hpp>
#include <orbed/session_control_t.hpp>
#include <orbed/setup_result_t.hpp>
#include <orbed/target_pose_t.hpp>

#include "base/format.h"
#include "base/log.h"
#include "lcmtypes/contract/alignment_trial.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/session_control.h"
#include "lcmtypes/contract/validation.h"
#include "render/image_message.h"
#include "runtime/flags.h"
#include "sim/guidance_messages.h"

namespace orbed::igtl_bridge {
namespace {

// "" or why an image_t cannot be shown (CheckImage, then the decoding); on success *bgr holds it.
std::string DecodeImage(const orbed::image_t& img, cv::Mat* bgr) {
  const std::string problem = CheckImage(img);
  return problem.empty() ? render::DecodeImageMessage(img, bgr) : problem;
}

int StatusCode(int8_t state) {
  switch (state) {
    case orbed::process_status_t::STATE_RUNNING:
      return igtl::StatusMessage::STATUS_OK;
    case orbed::process_status_t::STATE_STARTING:
      return igtl::StatusMessage::STATUS_NOT_READY;
    case orbed::process_status_t::STATE_STOPPING:
      return igtl::StatusMessage::STATUS_SHUT_DOWN;
    default:
      return igtl::StatusMessage::STATUS_UNKNOWN_ERROR;
  }
}

const char* StateName(int8_t state) {
  static const char* const kNames[] = {"STARTING", "RUNNING", "STOPPING", "FAILED"};
  return state >= 0 && state <= 3 ? kNames[state] : "?";
}

}  // namespace

std::vector<std::pair<std::string, Eigen::Isometry3d>> RobotFrames(const sim::RobotModel& model,
                                                                   const Eigen::Isometry3d& X_WR,
                                                                   const Eigen::VectorXd& q_rad) {
  std::vector<std::pair<std::string, Eigen::Isometry3d>> frames = {{"RobotBase", X_WR}};
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(q_rad);
  for (int i = 0; i < model.num_links(); ++i) frames.emplace_back(model.links()[i].name, X_WR * X_RL[i]);
  return frames;
}

IgtlBridge::IgtlBridge(const CommonFlags& flags, const BridgeOptions& options)
    : process_(flags),
      options_(options),
      model_(sim::RobotModel::LoadFlag(options.urdf_path)),
      server_(options.server),
      poses_(&process_, model_, sim::TestbedPoses::Channels{}) {
  for (const sim::RobotLink& link : model_.links())
    if (link.name.size() > 20)
      throw std::runtime_error("link name '" + link.name + "' is longer than 20 bytes");
  process_.Subscribe<orbed::process_status_t>(
      channels::kProcessStatus,
      [this](const orbed::process_status_t& msg, const std::string& channel, int64_t) {
        std::string problem = CheckEnum(msg.state, 0, 3, "state");
        if (msg.name.empty() || msg.name.size() > 20 || EscapeText(msg.name) != msg.name)
          problem = "name: empty, longer than 20 bytes or not printable";
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        const std::string text =
            "in " + std::to_string(msg.messages_in) + ", out " + std::to_string(msg.messages_out) +
            ", rejected " + std::to_string(msg.rejected_inputs) + ", dropped " + std::to_string(msg.dropped) +
            (msg.last_error.empty() ? "" : "; last error: " + EscapeText(msg.last_error));
        Send(PackStatus(msg.name, StatusCode(msg.state), StateName(msg.state), text, NowMicros()));
      });
  const auto on_image = [this](const orbed::image_t& img, const std::string& device,
                               const std::string& channel) {
    if (!ImageDue(device, NowMicros()) || server_.num_clients() == 0) return;
    cv::Mat bgr;
    const std::string problem = DecodeImage(img, &bgr);
    if (!problem.empty()) return process_.Reject(channel + "/image", problem);
    Send(PackImage(device, bgr, FromPose(img.X_WC), img.fx_px, img.utime));
  };
  process_.Subscribe<orbed::image_t>(
      channels::kHmdCamera, [on_image](const orbed::image_t& msg, const std::string& channel, int64_t) {
        on_image(msg, "HMDCamera", channel);
      });
  process_.Subscribe<orbed::reflective_view_t>(
      channels::kReflectiveView,
      [this, on_image](const orbed::reflective_view_t& msg, const std::string& channel, int64_t) {
        if (msg.display_id < 0 || msg.display_id > 999)
          return process_.Reject(channel + "/field", "display_id outside 0..999");
        on_image(msg.image, "Reflective" + std::to_string(msg.display_id), channel);
      });
  process_.Subscribe<orbed::session_control_t>(
      channels::kSessionControl,
      [this](const orbed::session_control_t& msg, const std::string& channel, int64_t) {
        const auto checked = CheckSessionControl(msg);
        if (const auto* refusal = std::get_if<Refusal>(&checked))
          return process_.Reject(channel + "/" + refusal->key, refusal->reason);
        const auto& command = std::get<SessionCommand>(checked);
        Send(PackString("Events",
                        std::string("SESSION_CONTROL ") + SessionCommandName(command.kind) + " " +
                            EscapeText(command.session_id),
                        command.utime));
      });
  process_.Subscribe<orbed::alignment_trial_t>(
      channels::kAlignmentTrial,
      [this](const orbed::alignment_trial_t& msg, const std::string& channel, int64_t) {
        const auto checked = CheckAlignmentTrial(msg, model_.num_joints());
        if (const auto* refusal = std::get_if<Refusal>(&checked))
          return process_.Reject(channel + "/" + refusal->key, refusal->reason);
        Send(PackString("Events",
                        "ALIGNMENT_TRIAL " + EscapeText(msg.session_id) + " #" +
                            std::to_string(msg.trial_index) + " in " + Fixed(msg.duration_s, 1) + " s",
                        msg.utime));
      });
  process_.Subscribe<orbed::setup_result_t>(
      channels::kSetupResult, [this](const orbed::setup_result_t& msg, const std::string& channel, int64_t) {
        const std::string problem = guidance::CheckSetupResult(msg, model_, 0.01);
        if (!problem.empty()) return process_.Reject(channel + "/field", problem);
        Send(PackString("Events",
                        "SETUP_RESULT " + EscapeText(msg.task_id) + " in " + Fixed(msg.execution_s, 1) + " s",
                        msg.utime));
      });
  process_.AddTimer(
      1.0 / options_.transform_hz, [this] { SendTransforms(); }, "igtl/transforms");
  process_.AddTimer(
      options_.poll_period_s,
      [this] {
        server_.Poll(
            [this](const IgtlPose& pose, const std::string& peer) {
              orbed::target_pose_t target{};
              target.utime = NowMicros();
              target.source = "igtl";
              target.name = pose.device;
              target.X_WT = ToPose(pose.X_m);
              process_.Publish(channels::kIgtlTarget, target);
              if (logged_targets_.insert(peer + "/" + pose.device).second)  // the first of each
                ORBED_LOG(kInfo) << "igtl: " << pose.type << " '" << EscapeText(pose.device) << "' from "
                                 << peer << " -> " << channels::kIgtlTarget;
            },
            [this](const IgtlEvent& event) {
              switch (event.kind) {
                case IgtlEvent::kConnected:
                  ORBED_LOG(kInfo) << "igtl: client " << event.peer << " connected";
                  break;
                case IgtlEvent::kDisconnected:
                  ORBED_LOG(kInfo) << "igtl: client " << event.peer << " left: " << event.detail;
                  break;
                case IgtlEvent::kSkipped:
                  process_.CountDrop("igtl/skipped");
                  break;
                case IgtlEvent::kRefused:
                  process_.Reject("igtl/refused", event.peer + ": " + event.detail);
                  break;
              }
            });
      },
      "igtl/poll");
  ORBED_LOG(kInfo) << "igtl bridge: OpenIGTLink server on " << options_.server.bind_address << ":"
                   << server_.port() << " (" << model_.num_links()
                   << " links + RobotBase, HMD, HMDCamera, Registration at " << options_.transform_hz
                   << " Hz; images at " << options_.image_hz << " Hz)";
}

void IgtlBridge::Send(const std::vector<uint8_t>& packet) {
  const int missed = server_.Broadcast(packet);
  if (missed > 0) process_.CountDrop("igtl/backlog", missed);
}

bool IgtlBridge::ImageDue(const std::string& source, int64_t now_us) {
  const auto it = last_image_us_.find(source);
  if (it != last_image_us_.end() && now_us - it->second < static_cast<int64_t>(1e6 / options_.image_hz))
    return false;
  last_image_us_[source] = now_us;
  return true;
}

void IgtlBridge::SendTransforms() {
  if (server_.num_clients() == 0) return;
  const int64_t now = NowMicros();
  if (poses_.X_WR())
    for (const auto& [name, X] : RobotFrames(model_, *poses_.X_WR(), poses_.q()))
      Send(PackTransform(name, X, now));
  if (poses_.X_WH()) Send(PackTransform("HMD", *poses_.X_WH(), now));
  if (poses_.X_WC()) Send(PackTransform("HMDCamera", *poses_.X_WC(), now));
  if (poses_.X_WV()) Send(PackTransform("Registration", *poses_.X_WV(), now));
}

int RunIgtlBridge(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-igtl-bridge: the testbed over OpenIGTLink for 3D Slicer (OpenIGTLinkIF: a client to\n"
      "localhost:18944). Sends TRANSFORM (RobotBase, every link, HMD, HMDCamera, Registration; mm, in\n"
      "the world frame W), IMAGE (HMDCamera, Reflective<N>), STATUS (each process) and STRING (Events);\n"
      "publishes each TRANSFORM or POSITION a client sends on IGTL_TARGET."};
  CommonFlags common("orbed-igtl-bridge");
  AddCommonFlags(&app, &common);
  BridgeOptions options;
  app.add_option("--port", options.server.port, "TCP port (0: any free port, printed at start)")
      ->check(orbed::NumberIn(0, 65535))
      ->capture_default_str();
  app.add_option("--bind", options.server.bind_address,
                 "IPv4 address to listen on (0.0.0.0: every interface, for Slicer on another host)")
      ->capture_default_str();
  app.add_option("--max-clients", options.server.max_clients, "Connections served at once")
      ->check(orbed::NumberIn(1, 64))
      ->capture_default_str();
  app.add_option("--transform-hz", options.transform_hz, "TRANSFORM rate [Hz]")
      ->check(orbed::NumberIn(0.1, 1000.0))
      ->capture_default_str();
  app.add_option("--image-hz", options.image_hz, "IMAGE rate per camera or display [Hz]")
      ->check(orbed::NumberIn(0.01, 60.0))
      ->capture_default_str();
  app.add_option("--urdf", options.urdf_path, "Robot URDF (default: the shipped iiwa 7)");
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  try {
    IgtlBridge bridge(common, options);
    return bridge.Run();
  } catch (const std::exception& e) {
    err << "orbed-igtl-bridge: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::igtl_bridge
