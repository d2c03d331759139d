#include "procs/fixed_display/fixed_display_process.h"

#include <cmath>
#include <exception>
#include <stdexcept>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>

#include "base/format.h"
#include "base/log.h"
#include "base/number_list.h"
#include "base/replace_file.h"
#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "runtime/flags.h"
#include "sim/guidance_messages.h"

namespace orbed::fixed_display {
namespace {

constexpr char kWindowName[] = "orbed-fixed-display";

bool SameView(const OrbitView& a, const OrbitView& b) {
  return a.azimuth_rad == b.azimuth_rad && a.elevation_rad == b.elevation_rad && a.distance_m == b.distance_m;
}

std::string Caption(const OrbitView& v) {
  return "TARGET CONFIGURATION   view: azimuth " + Fixed(v.azimuth_rad / kDegToRad, 0) + " deg, elevation " +
         Fixed(v.elevation_rad / kDegToRad, 0) + " deg, " + Fixed(v.distance_m, 2) + " m";
}

}  // namespace

FixedDisplay::FixedDisplay(const CommonFlags& flags, const FixedDisplayOptions& options)
    : process_(flags),
      options_(options),
      model_(sim::RobotModel::LoadFlag(options.urdf_path)),
      scene_(sim::LoadSceneFlag(options.scene_path)),
      poses_(&process_, model_, {options.robot_state_channel, "", options.guidance_channel, ""},
             {nullptr,
              [this](const orbed::guidance_t& g) {
                mode_ = g.mode;
                guidance_received_utime_ = process_.ClockUtime();
              }}),
      renderer_(model_, scene_ ? &*scene_ : nullptr, options.picture) {
  // The home view is the configured camera about the scene's base (the robot alone: the origin);
  // ROBOT_STATE's base moves the centre, the view keeps its angles and distance.
  home_ = OrbitView::Through(options_.camera_m,
                             OrbitCentre(scene_ ? scene_->X_WR : Eigen::Isometry3d::Identity()));
  view_ = home_;
  process_.AddTimer(
      1.0 / options_.rate_hz, [this] { Tick(); }, options_.fixed_view_channel);
  ORBED_LOG(kInfo) << "fixed display: " << options_.picture.width_px << "x" << options_.picture.height_px
                   << " on " << options_.fixed_view_channel << " at " << options_.rate_hz << " Hz"
                   << (options_.all_modes ? " in every guidance mode" : " in the fixed-display mode")
                   << "; camera at (" << Fixed(options_.camera_m.x(), 2) << ", "
                   << Fixed(options_.camera_m.y(), 2) << ", " << Fixed(options_.camera_m.z(), 2) << ") m";
}

void FixedDisplay::PressKey(int key) {
  if (const auto v = ApplyKey(key, view_, home_)) view_ = *v;
}

std::optional<orbed::image_t> FixedDisplay::PictureNow(int64_t utime) {
  const bool fresh = guidance_received_utime_ > 0 &&
                     utime - guidance_received_utime_ <= static_cast<int64_t>(options_.stale_after_s * 1e6);
  if (!poses_.X_WR() || !fresh) return std::nullopt;
  if (!options_.all_modes && mode_ != orbed::guidance_t::MODE_FIXED_DISPLAY) return std::nullopt;
  const Eigen::Isometry3d& X_WR = *poses_.X_WR();
  const Eigen::VectorXd& q_target = poses_.q_virtual();  // GUIDANCE's target (one came: fresh)
  const Eigen::Isometry3d X_WD = view_.X_WD(OrbitCentre(X_WR));
  if (!last_ || last_q_ != q_target || X_WR.matrix() != last_X_WR_.matrix() || !SameView(last_view_, view_)) {
    const cv::Mat bgr = renderer_.Render(q_target, X_WR, X_WD, Caption(view_));
    std::vector<std::uint8_t> jpeg;
    if (!render::EncodeJpeg(bgr, options_.picture.jpeg_quality, &jpeg)) {
      throw std::runtime_error("JPEG encoding failed");
    }
    last_ = JpegImageMessage(jpeg, renderer_.intrinsics(), utime, X_WD, utime);
    last_q_ = q_target;
    last_X_WR_ = X_WR;
    last_view_ = view_;
    ++renders_;
    if (!options_.png_path.empty()) {
      std::vector<std::uint8_t> png;
      std::string error;
      if (!cv::imencode(".png", bgr, png) ||
          !ReplaceFile(options_.png_path, std::string(png.begin(), png.end()), &error)) {
        ORBED_LOG(kWarn) << "fixed display: cannot write " << options_.png_path << ": " << error;
      }
    }
    if (options_.window) {
      cv::imshow(kWindowName, bgr);
      window_open_ = true;
    }
  }
  last_->utime = utime;
  last_->pose_utime = utime;
  return last_;
}

void FixedDisplay::Tick() {
  if (window_open_) PressKey(cv::waitKey(1));
  if (const auto picture = PictureNow(process_.ClockUtime()))
    process_.Publish(options_.fixed_view_channel, *picture);
}

int RunFixedDisplay(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-fixed-display: the set-up study's fixed external monitor. Renders GUIDANCE's target\n"
      "configuration, the robot at its real base (ROBOT_STATE) in the operating room, and publishes it\n"
      "on FIXED_VIEW (image_t JPEG; X_WC is the monitor's camera) while the guidance mode is `fixed`.\n"
      "The camera orbits the robot's middle; with --window the keys turn and zoom it:\n  " +
      std::string(kKeyHelp)};
  CommonFlags common("orbed-fixed-display");
  AddCommonFlags(&app, &common);
  AddSimTimeFlag(&app, &common);
  FixedDisplayOptions options;
  std::string camera_m = "1.5,0.3,1.8";
  app.add_option("--urdf", options.urdf_path, "Robot URDF (default: the shipped iiwa 7)");
  app.add_option("--scene", options.scene_path,
                 "Scene YAML (default: the shipped OR; none: the robot alone)");
  app.add_option("--camera-m", camera_m, "The monitor camera's home position x,y,z [m, W]")
      ->capture_default_str();
  app.add_option("--rate-hz", options.rate_hz, "FIXED_VIEW rate [Hz]")
      ->check(orbed::NumberIn(0.1, 60.0))
      ->capture_default_str();
  app.add_option("--stale-after-s", options.stale_after_s, "A GUIDANCE older than this shows nothing [s]")
      ->check(orbed::NumberIn(0.05, 3600.0))
      ->capture_default_str();
  app.add_option("--width-px", options.picture.width_px, "Picture width [px]")
      ->check(orbed::NumberIn(64, 3840))
      ->capture_default_str();
  app.add_option("--height-px", options.picture.height_px, "Picture height [px]")
      ->check(orbed::NumberIn(48, 2160))
      ->capture_default_str();
  app.add_option("--fov-deg", options.picture.horizontal_fov_deg, "Horizontal field of view [deg]")
      ->check(orbed::NumberIn(10.0, 120.0))
      ->capture_default_str();
  app.add_flag("--all-modes", options.all_modes, "Show the target in every guidance mode, not only `fixed`");
  app.add_flag("--window", options.window, "Show the picture in a window whose keys move the view");
  app.add_option("--png", options.png_path, "Also write every new picture to this PNG file");
  app.add_option("--robot-state-channel", options.robot_state_channel)->capture_default_str();
  app.add_option("--guidance-channel", options.guidance_channel)->capture_default_str();
  app.add_option("--fixed-view-channel", options.fixed_view_channel)->capture_default_str();
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  try {
    const std::vector<double> p = ParseNumberList(camera_m, "--camera-m");
    if (p.size() != 3) throw std::invalid_argument("--camera-m: give x,y,z");
    options.camera_m = Eigen::Vector3d(p[0], p[1], p[2]);
  } catch (const std::invalid_argument& e) {
    err << "orbed-fixed-display: " << e.what() << "\n";
    return 2;
  }
  try {
    FixedDisplay display(common, options);
    return display.Run();
  } catch (const std::exception& e) {
    err << "orbed-fixed-display: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::fixed_display
