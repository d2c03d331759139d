#include "procs/drake_viewer/drake_viewer_process.h"

#include <exception>

#include <CLI/CLI.hpp>

#include "base/log.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/drake_viewer/drake_viewer.h"
#include "runtime/flags.h"

namespace orbed::viewer {
ViewerBridge::ViewerBridge(const CommonFlags& flags, const ViewerOptions& options)
    : process_(flags),
      options_(options),
      scene_(sim::LoadSceneFlag(options.scene_path)),
      model_(sim::RobotModel::LoadFlag(options.urdf_path)),
      poses_(
          &process_, model_,
          {options.robot_state_channel, options.registration_channel, options.guidance_channel, "HMD_POSE"}) {
  const orbed::viewer_load_robot_t load = MakeLoadRobot(model_, scene_ ? &*scene_ : nullptr);
  process_.AddTimer(
      options_.load_period_s, [this, load] { process_.Publish(options_.load_channel, load); },
      options_.load_channel);
  process_.AddTimer(
      1.0 / options_.rate_hz,
      [this] {
        if (const auto draw = DrawNow(NowMicros())) process_.Publish(options_.draw_channel, *draw);
      },
      options_.draw_channel);
  process_.Publish(options_.load_channel, load);
  ORBED_LOG(kInfo) << "drake viewer: " << load.num_links << " links (real robot, virtual robot"
                   << (scene_ ? ", " + std::to_string(scene_->objects.size()) + " scene objects" : "")
                   << ") on " << options_.load_channel << ", poses at " << options_.rate_hz << " Hz on "
                   << options_.draw_channel;
}

std::optional<orbed::viewer_draw_t> ViewerBridge::DrawNow(int64_t utime) const {
  if (!poses_.X_WR()) return std::nullopt;
  return MakeDraw(model_, scene_ ? &*scene_ : nullptr, *poses_.X_WR(), poses_.q(), poses_.X_WV(),
                  poses_.q_virtual(), utime);
}

int RunViewerBridge(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-drake-viewer: the testbed in Drake's viewer. Publishes DRAKE_VIEWER_LOAD_ROBOT (the real\n"
      "and the virtual iiwa and the scene's objects) and DRAKE_VIEWER_DRAW (their poses) with Drake's\n"
      "lcmt_viewer_* types, from ROBOT_STATE, REGISTRATION and GUIDANCE. Start Meldis on the same LCM\n"
      "URL: python3 -m pydrake.visualization.meldis"};
  CommonFlags common("orbed-drake-viewer");
  AddCommonFlags(&app, &common);
  ViewerOptions options;
  app.add_option("--urdf", options.urdf_path, "Robot URDF (default: the shipped iiwa 7)");
  app.add_option("--scene", options.scene_path, "Scene YAML (default: the shipped OR; none: no scene)");
  app.add_option("--rate-hz", options.rate_hz, "DRAKE_VIEWER_DRAW rate [Hz]")
      ->check(orbed::NumberIn(0.1, 1000.0))
      ->capture_default_str();
  app.add_option("--load-period-s", options.load_period_s, "Period of DRAKE_VIEWER_LOAD_ROBOT [s]")
      ->check(orbed::NumberIn(0.1, 3600.0))
      ->capture_default_str();
  app.add_option("--robot-state-channel", options.robot_state_channel)->capture_default_str();
  app.add_option("--registration-channel", options.registration_channel)->capture_default_str();
  app.add_option("--guidance-channel", options.guidance_channel)->capture_default_str();
  app.add_option("--load-channel", options.load_channel)->capture_default_str();
  app.add_option("--draw-channel", options.draw_channel)->capture_default_str();
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  try {
    ViewerBridge bridge(common, options);
    return bridge.Run();
  } catch (const std::exception& e) {
    err << "orbed-drake-viewer: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::viewer
