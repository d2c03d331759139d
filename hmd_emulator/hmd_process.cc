#include "hmd_emulator/hmd_process.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <orbed/gaze_ray_t.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/reflective_view_t.hpp>

#include "geometry/camera_model.h"
#include "hmd_emulator/gaze.h"
#include "hmd_emulator/reflective.h"
#include "hmd_emulator/renderer.h"
#include "hmd_emulator/scene_geometry.h"
#include "hmd_emulator/viraal_trial.h"
#include "procs/common/conversions.h"
#include "procs/common/log.h"
#include "procs/common/validation.h"

namespace orbed::hmd {
namespace {

static_assert(static_cast<int>(TrackingState::kTracking) == orbed::hmd_pose_t::TRACKING &&
                  static_cast<int>(TrackingState::kLimited) == orbed::hmd_pose_t::LIMITED &&
                  static_cast<int>(TrackingState::kLost) == orbed::hmd_pose_t::LOST &&
                  static_cast<int>(TrackingState::kRelocalized) == orbed::hmd_pose_t::RELOCALIZED,
              "TrackingState must number as hmd_pose_t's constants");

constexpr char kWindowName[] = "orbed-hmd";
constexpr double kInteractiveHz = 30.0;
constexpr double kJointLimitSlackRad = 0.01;
using Clock = std::chrono::steady_clock;

std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// A seed per (process seed, session, trial, purpose): the same inputs give the same trial.
std::uint64_t TrialSeed(std::uint64_t seed, const std::string& session, int32_t index,
                        std::uint64_t purpose) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a of the session id
  for (unsigned char c : session) h = (h ^ c) * 1099511628211ULL;
  return SplitMix64(SplitMix64(SplitMix64(seed ^ h) ^ static_cast<std::uint64_t>(index)) ^ purpose);
}

bool SamePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) { return a.matrix() == b.matrix(); }

std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, value);
  return text;
}

const char* ModeName(int8_t mode) {
  return mode == orbed::alignment_trial_t::MODE_AR_REFLECTIVE ? "ar_reflective" : "ar";
}

orbed::image_t JpegImage(const std::vector<std::uint8_t>& jpeg, const geometry::Intrinsics& K, int64_t utime,
                         const Eigen::Isometry3d& X_WC_est, int64_t pose_utime) {
  orbed::image_t img{};
  img.utime = utime;
  img.width = K.width_px;
  img.height = K.height_px;
  img.row_stride = 0;
  img.pixel_format = orbed::image_t::FORMAT_JPEG;
  img.fx_px = K.fx_px;
  img.fy_px = K.fy_px;
  img.cx_px = K.cx_px;
  img.cy_px = K.cy_px;
  img.X_WC = ToPose(X_WC_est);
  img.pose_utime = pose_utime;
  img.num_bytes = static_cast<int32_t>(jpeg.size());
  img.data = jpeg;
  return img;
}

// Decodes the two-character escapes "\n" (Enter) and "\e" (Esc) of --scripted-keys.
std::vector<int> ScriptedKeys(const std::string& text) {
  std::vector<int> keys;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\\' && i + 1 < text.size() && (text[i + 1] == 'n' || text[i + 1] == 'e')) {
      keys.push_back(text[++i] == 'n' ? 13 : 27);
    } else {
      keys.push_back(static_cast<unsigned char>(text[i]));
    }
  }
  return keys;
}

}  // namespace

// What a frame is made from: the latest SLAM sample, robot and X_WV (copied off the Run() thread).
struct HmdProcess::FrameInputs {
  bool have_sample{false};
  SlamSample sample;
  int64_t sample_utime{0};
  bool robot_known{false};
  Eigen::VectorXd q_rad;
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d X_WV{Eigen::Isometry3d::Identity()};
  double t_s{0};
};

// The head and SLAM stream and the spatial map used for gaze (Run() thread only).
struct HmdProcess::Live {
  Live(const HeadTrajectoryConfig& walk, const SlamConfig& slam) : trajectory(walk), slam(slam) {}
  HeadTrajectory trajectory;
  SlamModel slam;
  bool started{false};
  Clock::time_point t0;
  double t_s{0};
  bool have_sample{false};
  SlamSample sample;
  int64_t sample_utime{0};
  SceneGeometry scene_geometry;  // scene objects only
  SceneGeometry robot_geometry;  // the real robot only, handle 0
};

// Camera, reflective displays and AR view: everything made of pixels. Runs on the worker thread
// (or inline); only the Latest*() accessors and the request queue are used from other threads.
class HmdProcess::ImagePipeline {
 public:
  ImagePipeline(const sim::RobotModel& robot, const sim::Scene& scene, const HmdConfigSet& config,
                const HmdOptions& options, const HeadTrajectory& trajectory, orbed::Process* process)
      : robot_(robot),
        config_(config),
        options_(options),
        process_(process),
        renderer_(geometry::Intrinsics::HoloLensPv()),
        compositor_(robot) {
    scene_geometry_.AddSceneObjects(scene);
    robot_geometry_.AddRobot(robot, BodyKind::kRealRobot);
    Tessellate(scene_geometry_, kAllKinds, {}, &scene_mesh_);
    mesh_ = scene_mesh_;
    for (int i = 0; i < options.displays; ++i) {
      Display d;
      d.capture_t_s =
          trajectory.ArrivalTime(trajectory.FindWaypoint(config.hmd.displays[i].capture_waypoint));
      displays_.push_back(std::move(d));
    }
    if (options.threaded) worker_ = std::thread([this] { WorkerLoop(); });
  }

  ~ImagePipeline() {
    {
      std::lock_guard<std::mutex> lock(jobs_mutex_);
      stop_ = true;
    }
    jobs_cv_.notify_all();
    if (worker_.joinable()) worker_.join();
  }

  enum Job { kCamera = 0, kReflective = 1, kArView = 2 };

  // Hands a job to the worker (latest wins) or runs it now.
  void Post(Job job, const FrameInputs& in, bool publish_ar = true) {
    if (!options_.threaded) {
      Run(job, in, publish_ar);
      return;
    }
    {
      std::lock_guard<std::mutex> lock(jobs_mutex_);
      if (pending_[job]) ++skipped_;
      pending_[job] = true;
      inputs_[job] = in;
      if (job == kArView) publish_ar_ = publish_ar_ || publish_ar;
    }
    jobs_cv_.notify_all();
  }

  void Flush() {
    if (!options_.threaded) return;
    std::unique_lock<std::mutex> lock(jobs_mutex_);
    done_cv_.wait(lock, [this] { return stop_ || (!busy_ && !pending_[0] && !pending_[1] && !pending_[2]); });
  }

  void RequestRecapture(int display) {
    std::lock_guard<std::mutex> lock(out_mutex_);
    if (display >= 0 && display < static_cast<int>(displays_.size())) recapture_now_.push_back(display);
  }

  cv::Mat LatestArView() {
    std::lock_guard<std::mutex> lock(out_mutex_);
    return ar_latest_;
  }
  cv::Mat LatestReflective(int display) {
    std::lock_guard<std::mutex> lock(out_mutex_);
    if (display < 0 || display >= static_cast<int>(reflective_latest_.size())) return cv::Mat();
    return reflective_latest_[display];
  }
  int64_t skipped() const { return skipped_; }
  int64_t rendered() const { return rendered_; }
  int64_t reused() const { return reused_; }

 private:
  struct Display {
    double capture_t_s{0};
    bool captured{false};
    CapturedFrame frame;
    Eigen::Isometry3d X_WC_true{Eigen::Isometry3d::Identity()};
    Eigen::Isometry3d X_WH_true{Eigen::Isometry3d::Identity()};
    bool has_robot{false};
    Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};
    double D_m{0};
    int64_t version{0};
    Clock::time_point captured_at;
    // The composed view, cached until the frame or X_WV changes.
    int64_t composed_version{-1};
    Eigen::Isometry3d composed_X_WV{Eigen::Isometry3d::Identity()};
    ReflectiveGeometry geometry;
    std::vector<std::uint8_t> jpeg;
  };

  void WorkerLoop() {
    std::unique_lock<std::mutex> lock(jobs_mutex_);
    while (true) {
      jobs_cv_.wait(lock, [this] { return stop_ || pending_[0] || pending_[1] || pending_[2]; });
      if (stop_) break;
      bool run[3];
      FrameInputs in[3];
      for (int j = 0; j < 3; ++j) {
        run[j] = pending_[j];
        pending_[j] = false;
        if (run[j]) in[j] = inputs_[j];
      }
      const bool publish_ar = publish_ar_;
      publish_ar_ = false;
      busy_ = true;
      lock.unlock();
      for (int j = 0; j < 3; ++j) {
        if (run[j]) Run(static_cast<Job>(j), in[j], publish_ar);
      }
      lock.lock();
      busy_ = false;
      done_cv_.notify_all();
    }
    busy_ = false;
    done_cv_.notify_all();
  }

  void Run(Job job, const FrameInputs& in, bool publish_ar) {
    try {
      if (job == kCamera) Camera(in);
      if (job == kReflective) Reflective(in);
      if (job == kArView) ArView(in, publish_ar);
    } catch (const std::exception& e) {
      // An engine error must not take the process down; it shows as last_error on the heartbeat.
      process_->SetLastError(std::string("image pipeline: ") + e.what());
      if (errors_++ < 5) ORBED_LOG(kError) << "image pipeline: " << e.what();
    }
  }

  bool RobotDiffers(bool known, const Eigen::VectorXd& q, const Eigen::Isometry3d& X_WR, bool ref_known,
                    const Eigen::VectorXd& ref_q, const Eigen::Isometry3d& ref_X_WR) const {
    if (known != ref_known) return true;
    if (!known) return false;
    return q.size() != ref_q.size() || q != ref_q || !SamePose(X_WR, ref_X_WR);
  }

  // Poses the real robot and rebuilds the mesh when the robot changed.
  void UpdateRobot(const FrameInputs& in) {
    if (!RobotDiffers(in.robot_known, in.q_rad, in.X_WR, mesh_robot_known_, mesh_q_, mesh_X_WR_)) return;
    mesh_ = scene_mesh_;
    if (in.robot_known) {
      robot_geometry_.PoseRobot(0, in.q_rad, in.X_WR);
      Tessellate(robot_geometry_, kAllKinds, {}, &mesh_);
    }
    mesh_robot_known_ = in.robot_known;
    mesh_q_ = in.q_rad;
    mesh_X_WR_ = in.X_WR;
  }

  // D (paper Sec. II-B, issue 5 item 4): from the camera centre to where the line of sight of a
  // head at X_WH hits the ROBOT (the real robot's primitives only: the first robot surface along
  // the ray, whatever scene object may stand in front of it). When the gaze misses the robot (or
  // no robot pose is known yet) D is hmd.gaze_fallback_distance_m: D only places the display, and
  // a wall or the floor behind the robot would place it far from where the person works.
  double GazeDistance(const Eigen::Isometry3d& X_WH, const Eigen::Isometry3d& X_WC) const {
    if (!mesh_robot_known_) return config_.hmd.gaze_fallback_distance_m;
    const Eigen::Vector3d p = X_WH.translation(), d = X_WH.linear().col(2);
    const RayHit hit = CastRay(robot_geometry_, p, d, kRealWorld, config_.hmd.max_gaze_distance_m);
    if (!hit.hit) return config_.hmd.gaze_fallback_distance_m;
    const double D = (hit.p_WQ - X_WC.translation()).norm();
    return std::isfinite(D) && D > 0.01 ? D : config_.hmd.gaze_fallback_distance_m;
  }

  void Capture(Display* d, const FrameInputs& in) {
    d->frame.bgr = bgr_.clone();
    d->frame.intrinsics = renderer_.intrinsics();
    d->frame.X_WC_est = frame_X_WC_est_;
    d->frame.q_rad = frame_robot_known_ ? frame_q_ : Eigen::VectorXd();
    d->frame.utime = frame_utime_;
    d->X_WC_true = frame_X_WC_true_;
    d->X_WH_true = in.sample.X_WH_true;
    d->has_robot = frame_robot_known_;
    d->X_WR = frame_X_WR_;
    d->D_m = GazeDistance(d->X_WH_true, d->X_WC_true);
    d->captured = true;
    d->captured_at = Clock::now();
    ++d->version;
  }

  // The robot moved since the display captured: render its frame again from the same viewpoint.
  void Recapture(Display* d) {
    renderer_.Render(mesh_, d->X_WC_true, &d->frame.bgr);
    d->frame.bgr = d->frame.bgr.clone();  // own its pixels (the renderer may reuse the buffer)
    d->frame.q_rad = mesh_robot_known_ ? mesh_q_ : Eigen::VectorXd();
    d->has_robot = mesh_robot_known_;
    d->X_WR = mesh_X_WR_;
    d->D_m = GazeDistance(d->X_WH_true, d->X_WC_true);
    d->captured_at = Clock::now();
    ++d->version;
  }

  void Camera(const FrameInputs& in) {
    if (!in.have_sample) return;
    const Eigen::Isometry3d& X_WC_true = in.sample.X_WC_true;
    const bool same =
        have_frame_ && SamePose(X_WC_true, frame_X_WC_true_) &&
        !RobotDiffers(in.robot_known, in.q_rad, in.X_WR, frame_robot_known_, frame_q_, frame_X_WR_);
    if (same) {
      ++reused_;
    } else {
      UpdateRobot(in);
      renderer_.Render(mesh_, X_WC_true, &bgr_);
      if (!EncodeJpeg(bgr_, options_.jpeg_quality, &jpeg_)) throw std::runtime_error("JPEG encoding failed");
      ++rendered_;
    }
    have_frame_ = true;
    frame_X_WC_true_ = X_WC_true;
    frame_X_WC_est_ = in.sample.X_WC_est;
    frame_utime_ = in.sample_utime;
    frame_robot_known_ = in.robot_known;
    frame_q_ = in.q_rad;
    frame_X_WR_ = in.X_WR;
    process_->Publish(options_.camera_channel, JpegImage(jpeg_, renderer_.intrinsics(), in.sample_utime,
                                                         in.sample.X_WC_est, in.sample_utime));

    std::vector<int> now;
    {
      std::lock_guard<std::mutex> lock(out_mutex_);
      now.swap(recapture_now_);
    }
    for (std::size_t i = 0; i < displays_.size(); ++i) {
      Display& d = displays_[i];
      bool wanted = !d.captured && in.t_s >= d.capture_t_s - 1e-9;
      for (int k : now) wanted = wanted || k == static_cast<int>(i);
      if (wanted) {
        Capture(&d, in);
      } else if (d.captured &&
                 RobotDiffers(mesh_robot_known_, mesh_q_, mesh_X_WR_, d.has_robot, d.frame.q_rad, d.X_WR) &&
                 Clock::now() - d.captured_at >=
                     std::chrono::duration<double>(config_.hmd.recapture_period_s)) {
        UpdateRobot(in);
        Recapture(&d);
      }
    }
  }

  void Reflective(const FrameInputs& in) {
    for (std::size_t i = 0; i < displays_.size(); ++i) {
      Display& d = displays_[i];
      if (!d.captured) continue;
      if (d.composed_version != d.version || !SamePose(d.composed_X_WV, in.X_WV)) {
        ReflectiveView view;
        if (d.has_robot) {
          compositor_.ComposeReflective(d.frame, d.D_m, in.X_WV, &view);
        } else {  // no robot known at capture: the frame without a hologram
          view.bgr = d.frame.bgr.clone();
          view.geometry = MakeReflectiveGeometry(d.frame.intrinsics, d.frame.X_WC_est, d.D_m);
        }
        if (!EncodeJpeg(view.bgr, options_.jpeg_quality, &d.jpeg))
          throw std::runtime_error("JPEG encoding failed");
        d.geometry = view.geometry;
        d.composed_version = d.version;
        d.composed_X_WV = in.X_WV;
        std::lock_guard<std::mutex> lock(out_mutex_);
        if (reflective_latest_.size() < displays_.size()) reflective_latest_.resize(displays_.size());
        reflective_latest_[i] = view.bgr;
      }
      orbed::reflective_view_t msg{};
      msg.utime = NowMicros();
      msg.display_id = static_cast<int32_t>(i);
      msg.image = JpegImage(d.jpeg, d.frame.intrinsics, d.frame.utime, d.frame.X_WC_est, d.frame.utime);
      FromMatrix3(d.geometry.K_m, msg.K_m);
      msg.X_WM = ToPose(d.geometry.X_WM);
      msg.distance_m = d.geometry.distance_m;
      msg.source_utime = d.frame.utime;
      msg.X_WV = ToPose(d.composed_X_WV);
      process_->Publish(options_.reflective_channel, msg);
    }
  }

  void ArView(const FrameInputs& in, bool publish) {
    if (!have_frame_) return;
    cv::Mat ar;
    if (frame_robot_known_) {
      compositor_.ComposeArView(bgr_, renderer_.intrinsics(), frame_X_WC_est_, frame_q_, in.X_WV, &ar);
    } else {
      ar = bgr_.clone();
    }
    {
      std::lock_guard<std::mutex> lock(out_mutex_);
      ar_latest_ = ar;
    }
    if (!publish) return;
    if (!EncodeJpeg(ar, options_.jpeg_quality, &ar_jpeg_)) throw std::runtime_error("JPEG encoding failed");
    process_->Publish(options_.ar_view_channel, JpegImage(ar_jpeg_, renderer_.intrinsics(), frame_utime_,
                                                          frame_X_WC_est_, frame_utime_));
  }

  const sim::RobotModel& robot_;
  const HmdConfigSet& config_;
  const HmdOptions& options_;
  orbed::Process* process_;
  Renderer renderer_;
  Compositor compositor_;
  SceneGeometry scene_geometry_, robot_geometry_;
  Mesh scene_mesh_, mesh_;
  bool mesh_robot_known_{false};
  Eigen::VectorXd mesh_q_;
  Eigen::Isometry3d mesh_X_WR_{Eigen::Isometry3d::Identity()};
  // The latest camera frame and what it was made from.
  bool have_frame_{false};
  cv::Mat bgr_;
  std::vector<std::uint8_t> jpeg_, ar_jpeg_;
  Eigen::Isometry3d frame_X_WC_true_{Eigen::Isometry3d::Identity()},
      frame_X_WC_est_{Eigen::Isometry3d::Identity()};
  int64_t frame_utime_{0};
  bool frame_robot_known_{false};
  Eigen::VectorXd frame_q_;
  Eigen::Isometry3d frame_X_WR_{Eigen::Isometry3d::Identity()};
  std::vector<Display> displays_;
  int errors_{0};
  std::atomic<int64_t> skipped_{0}, rendered_{0}, reused_{0};

  // Outputs read by the interactive window, and recapture requests (out_mutex_).
  std::mutex out_mutex_;
  cv::Mat ar_latest_;
  std::vector<cv::Mat> reflective_latest_;
  std::vector<int> recapture_now_;

  // The worker's queue (jobs_mutex_).
  std::mutex jobs_mutex_;
  std::condition_variable jobs_cv_, done_cv_;
  bool pending_[3]{false, false, false};
  FrameInputs inputs_[3];
  bool publish_ar_{false};
  bool busy_{false};
  bool stop_{false};
  std::thread worker_;
};

HmdProcess::HmdProcess(const orbed::CommonFlags& flags, const HmdOptions& options) : options_(options) {
  if (options_.urdf_path.empty())
    options_.urdf_path = HmdSourcePath(sim::RobotModel::kDefaultUrdfRelativePath);
  if (options_.scene_path.empty()) options_.scene_path = HmdSourcePath(sim::kDefaultSceneRelativePath);
  if (!(options_.camera_hz > 0 && options_.camera_hz <= 120)) {
    throw std::invalid_argument("--camera-hz must be in (0, 120] Hz");
  }
  if (!(options_.pose_hz > 0 && options_.pose_hz <= 1000))
    throw std::invalid_argument("--pose-hz must be in (0, 1000] Hz");
  if (options_.jpeg_quality < 1 || options_.jpeg_quality > 100) {
    throw std::invalid_argument("--jpeg-quality must be in [1, 100]");
  }
  if (!options_.screenshot_path.empty() && !options_.interactive) {
    throw std::invalid_argument("--screenshot needs --interactive (it saves the window's image)");
  }
  std::vector<std::string> paths;
  for (const auto& rel : DefaultHmdConfigRelativePaths()) paths.push_back(HmdSourcePath(rel));
  paths.insert(paths.end(), options_.config_paths.begin(), options_.config_paths.end());
  config_ = LoadHmdConfigs(paths);
  if (options_.user_seed) config_.user.seed = *options_.user_seed;
  const int placed = static_cast<int>(config_.hmd.displays.size());
  if (options_.displays < 0 || options_.displays > placed) {
    throw std::invalid_argument("--displays must be in [0, " + std::to_string(placed) +
                                "]: the config places " + std::to_string(placed) +
                                " reflective display(s) (hmd.displays)");
  }

  scene_ = sim::LoadSceneFile(options_.scene_path);
  // With the scene's tool length, before any geometry copies the tool's primitives.
  robot_ = std::make_unique<sim::RobotModel>(sim::LoadRobotForScene(options_.urdf_path, scene_));
  user_ = std::make_unique<EmulatedUser>(config_.user);
  user_id_ = "emulated-seed-" + std::to_string(config_.user.seed);
  X_WV_start_ = user_->StartPose(scene_.X_WR);
  X_WV_manual_ = X_WV_start_;

  live_ = std::make_unique<Live>(config_.walk, config_.slam);
  live_->scene_geometry.AddSceneObjects(scene_);
  live_->robot_geometry.AddRobot(*robot_, BodyKind::kRealRobot);

  process_ = std::make_unique<orbed::Process>(flags);
  process_->Subscribe<orbed::iiwa_status_t>(
      options_.iiwa_status_channel,
      [this](const orbed::iiwa_status_t& m, const std::string& ch, int64_t) { OnIiwaStatus(m, ch); });
  process_->Subscribe<orbed::robot_state_t>(
      options_.robot_state_channel,
      [this](const orbed::robot_state_t& m, const std::string& ch, int64_t) { OnRobotState(m, ch); });
  process_->Subscribe<orbed::session_control_t>(
      options_.session_control_channel,
      [this](const orbed::session_control_t& m, const std::string& ch, int64_t) { OnSessionControl(m, ch); });
  process_->Subscribe<orbed::registration_t>(
      options_.registration_channel,
      [this](const orbed::registration_t& m, const std::string& ch, int64_t) { OnRegistration(m, ch); });

  pipeline_ =
      std::make_unique<ImagePipeline>(*robot_, scene_, config_, options_, live_->trajectory, process_.get());

  process_->AddTimer(1.0 / options_.pose_hz, [this] { PublishPose(); });
  process_->AddTimer(1.0 / config_.hmd.gaze_hz, [this] { PublishGaze(); });
  process_->AddTimer(1.0 / options_.camera_hz, [this] { RequestCamera(); });
  if (options_.displays > 0)
    process_->AddTimer(1.0 / config_.hmd.reflective_hz, [this] { RequestReflective(); });
  process_->AddTimer(1.0 / config_.hmd.ar_view_hz, [this] { RequestArView(); });
  if (options_.interactive) process_->AddTimer(1.0 / kInteractiveHz, [this] { InteractiveTick(); });

  ORBED_LOG(kInfo) << "robot " << options_.urdf_path << ", scene " << options_.scene_path << "; walk of "
                   << config_.walk.waypoints.size() << " waypoints ("
                   << Fixed(live_->trajectory.length_m(), 2) << " m), user seed " << config_.user.seed << ", "
                   << options_.displays << " reflective display(s); pose " << options_.pose_hz
                   << " Hz, camera " << options_.camera_hz << " Hz"
                   << (options_.interactive ? ", interactive" : "");
}

HmdProcess::~HmdProcess() {
  pipeline_.reset();  // joins the worker before anything it uses goes
  if (window_open_) cv::destroyAllWindows();
}

int64_t HmdProcess::skipped_frames() const { return pipeline_->skipped(); }

void HmdProcess::Flush() { pipeline_->Flush(); }

Eigen::Isometry3d HmdProcess::CurrentX_WV() const {
  if (options_.interactive) return X_WV_manual_;
  if (X_WV_registration_) return *X_WV_registration_;
  if (X_WV_user_) return *X_WV_user_;
  return X_WV_start_;
}

HmdProcess::FrameInputs HmdProcess::Inputs() const {
  FrameInputs in;
  in.have_sample = live_->have_sample;
  in.sample = live_->sample;
  in.sample_utime = live_->sample_utime;
  in.robot_known = have_q_ && have_X_WR_;
  if (in.robot_known) {
    in.q_rad = q_rad_;
    in.X_WR = X_WR_;
  }
  in.X_WV = CurrentX_WV();
  in.t_s = live_->t_s;
  return in;
}

void HmdProcess::PublishPose() {
  const Clock::time_point now = Clock::now();
  if (!live_->started) {
    live_->started = true;
    live_->t0 = now;
  }
  live_->t_s = std::chrono::duration<double>(now - live_->t0).count();
  const SlamSample s = live_->slam.Step(live_->trajectory.X_WH(live_->t_s), live_->t_s);
  const int64_t utime = NowMicros();
  orbed::hmd_pose_t est{};
  est.utime = utime;
  est.seq = s.seq;
  est.hmd_name = config_.hmd.name;
  est.X_WH = ToPose(s.X_WH_est);
  est.X_WC = ToPose(s.X_WC_est);
  est.tracking_state = static_cast<int8_t>(s.state);
  orbed::hmd_pose_t truth = est;
  truth.X_WH = ToPose(s.X_WH_true);
  truth.X_WC = ToPose(s.X_WC_true);
  process_->Publish(options_.hmd_pose_channel, est);
  process_->Publish(options_.hmd_pose_truth_channel, truth);
  live_->sample = s;
  live_->sample_utime = utime;
  live_->have_sample = true;
}

void HmdProcess::PublishGaze() {
  if (!live_->have_sample) return;
  const SlamSample& s = live_->sample;
  const double range = config_.hmd.max_gaze_distance_m;
  const Eigen::Vector3d p_true = s.X_WH_true.translation(), d_true = s.X_WH_true.linear().col(2);
  RayHit hit = CastRay(live_->scene_geometry, p_true, d_true, kRealWorld, range);
  if (have_q_ && have_X_WR_) {
    live_->robot_geometry.PoseRobot(0, q_rad_, X_WR_);
    const RayHit r = CastRay(live_->robot_geometry, p_true, d_true, kRealWorld, range);
    if (r.hit && r.distance_m < hit.distance_m) hit = r;
  }
  const Eigen::Vector3d p_est = s.X_WH_est.translation(), d_est = s.X_WH_est.linear().col(2);
  orbed::gaze_ray_t msg{};
  msg.utime = live_->sample_utime;
  msg.hmd_name = config_.hmd.name;
  FromVector3(p_est, msg.origin_W_m);
  FromVector3(d_est, msg.direction_W);
  msg.valid = hit.hit;
  if (hit.hit) {
    FromVector3(p_est + hit.distance_m * d_est, msg.hit_W_m);
    msg.hit_distance_m = hit.distance_m;
    msg.hit_body = hit.body_name;
  }
  process_->Publish(options_.gaze_channel, msg);
}

void HmdProcess::RequestCamera() { pipeline_->Post(ImagePipeline::kCamera, Inputs()); }
void HmdProcess::RequestReflective() { pipeline_->Post(ImagePipeline::kReflective, Inputs()); }
void HmdProcess::RequestArView() { pipeline_->Post(ImagePipeline::kArView, Inputs(), true); }

void HmdProcess::OnIiwaStatus(const orbed::iiwa_status_t& msg, const std::string& channel) {
  std::string error = CheckSize(msg.num_joints, robot_->num_joints(), "num_joints");
  if (error.empty() && msg.joint_position_measured.size() != static_cast<size_t>(msg.num_joints)) {
    error = "joint_position_measured has " + std::to_string(msg.joint_position_measured.size()) + " entries";
  }
  if (!error.empty()) {
    process_->Reject(channel + "/num_joints", error);
    return;
  }
  error = CheckFinite(msg.joint_position_measured, "joint_position_measured");
  if (!error.empty()) {
    process_->Reject(channel + "/non_finite", error);
    return;
  }
  const Eigen::VectorXd q = ToVectorX(msg.joint_position_measured);
  error = robot_->ValidateJointVector(q, kJointLimitSlackRad);
  if (!error.empty()) {
    process_->Reject(channel + "/limits", "joint_position_measured: " + error);
    return;
  }
  q_rad_ = q;
  have_q_ = true;
}

void HmdProcess::OnRobotState(const orbed::robot_state_t& msg, const std::string& channel) {
  const std::string error = CheckPose(msg.X_WR, "X_WR");
  if (!error.empty()) {
    process_->Reject(channel + "/pose", error);
    return;
  }
  X_WR_ = FromPose(msg.X_WR);
  have_X_WR_ = true;
}

void HmdProcess::OnRegistration(const orbed::registration_t& msg, const std::string& channel) {
  if (!msg.valid) return;                                             // no mean yet: nothing to draw
  if (!session_.id.empty() && msg.session_id != session_.id) return;  // another session's mean
  const std::string error = CheckPose(msg.X_WV_mean, "X_WV_mean");
  if (!error.empty()) {
    process_->Reject(channel + "/pose", error);
    return;
  }
  X_WV_registration_ = FromPose(msg.X_WV_mean);
}

void HmdProcess::OnSessionControl(const orbed::session_control_t& msg, const std::string& channel) {
  using SC = orbed::session_control_t;
  using AT = orbed::alignment_trial_t;
  std::string error = CheckEnum(msg.command, SC::START, SC::REQUEST_TRIAL, "command");
  if (!error.empty()) {
    process_->Reject(channel + "/command", error);
    return;
  }
  if (msg.session_id.empty()) {
    process_->Reject(channel + "/session_id", "session_id is empty");
    return;
  }
  switch (msg.command) {
    case SC::START: {
      error = CheckEnum(msg.display_mode, AT::MODE_AR, AT::MODE_AR_REFLECTIVE, "display_mode");
      if (!error.empty()) {
        process_->Reject(channel + "/display_mode", error);
        return;
      }
      const int placed = static_cast<int>(config_.hmd.displays.size());
      if (msg.display_mode == AT::MODE_AR ? msg.num_mirrors != 0
                                          : (msg.num_mirrors < 1 || msg.num_mirrors > placed)) {
        process_->Reject(channel + "/num_mirrors",
                         "session '" + msg.session_id + "': num_mirrors " + std::to_string(msg.num_mirrors) +
                             (msg.display_mode == AT::MODE_AR
                                  ? " with MODE_AR, expected 0"
                                  : " with MODE_AR_REFLECTIVE, expected 1.." + std::to_string(placed) +
                                        " (the displays placed in hmd.displays)"));
        return;
      }
      if (msg.session_id == session_.id && msg.display_mode == session_.display_mode &&
          msg.num_mirrors == session_.num_mirrors) {
        return;  // a repeated START (e.g. our own, echoed back) changes nothing
      }
      session_ = Session{msg.session_id, msg.display_mode, msg.num_mirrors, msg.method, 0};
      X_WV_registration_.reset();
      X_WV_user_.reset();
      last_event_ = "session '" + session_.id + "' started (" + ModeName(session_.display_mode) + ", " +
                    std::to_string(session_.num_mirrors) + " display(s))";
      ORBED_LOG(kInfo) << last_event_;
      return;
    }
    case SC::RESET:
      if (msg.session_id != session_.id) {
        process_->Reject(channel + "/unknown_session", "RESET for session '" + msg.session_id +
                                                           "', the active session is '" + session_.id + "'");
        return;
      }
      session_.next_index = 0;
      return;
    case SC::COMPUTE:
      return;  // for the registration server
    case SC::STOP:
      if (msg.session_id == session_.id) {
        ORBED_LOG(kInfo) << "session '" << session_.id << "' stopped after " << session_.next_index
                         << " trial(s)";
        session_ = Session{};
      }
      return;
    case SC::REQUEST_TRIAL:
      if (msg.session_id != session_.id) {
        process_->Reject(channel + "/unknown_session",
                         "REQUEST_TRIAL for session '" + msg.session_id + "', the active session is '" +
                             (session_.id.empty() ? std::string("(none)") : session_.id) +
                             "' (send START first)");
        return;
      }
      if (!(have_q_ && have_X_WR_)) {
        process_->Reject(channel + "/no_robot_state",
                         "REQUEST_TRIAL for session '" + msg.session_id + "' before any valid " +
                             (have_q_ ? "" : options_.iiwa_status_channel + (have_X_WR_ ? "" : " and ")) +
                             (have_X_WR_ ? "" : options_.robot_state_channel) +
                             ": the user cannot align without the robot's configuration and base pose (is "
                             "orbed-iiwa-sim running?)");
        return;
      }
      if (options_.interactive) {
        trial_requested_ = true;
        trial_started_ = Clock::now();
        last_event_ = "trial " + std::to_string(session_.next_index) + " of '" + session_.id +
                      "' requested: align the hologram, then press Enter";
        ORBED_LOG(kInfo) << last_event_;
        return;
      }
      EmulateTrial(channel);
      return;
    default:
      return;
  }
}

void HmdProcess::EmulateTrial(const std::string& channel) {
  TrialSetup setup;
  setup.X_WR = X_WR_;
  setup.walk = config_.walk;
  setup.align_waypoint = config_.hmd.align_waypoint;
  setup.settle_s = config_.hmd.settle_s;
  setup.max_wait_s = config_.hmd.max_wait_s;
  setup.intrinsics = geometry::Intrinsics::HoloLensPv();
  for (int i = 0; i < session_.num_mirrors; ++i) {
    setup.capture_waypoints.push_back(config_.hmd.displays[i].capture_waypoint);
  }
  SlamConfig slam = config_.slam;
  slam.seed = TrialSeed(process_->seed(), session_.id, session_.next_index, 1);
  const std::uint64_t trial_seed = TrialSeed(process_->seed(), session_.id, session_.next_index, 2);
  TrialOutcome outcome;
  try {
    setup.p_RQ = RobotModelPoints(*robot_, q_rad_);
    outcome = RunTrial(setup, slam, *user_, X_WV_start_, trial_seed);
  } catch (const std::exception& e) {
    process_->Reject(channel + "/trial_failed", std::string("the emulated trial failed: ") + e.what());
    return;
  }
  X_WV_user_ = outcome.alignment.X_WV;
  const int32_t index = session_.next_index;
  PublishTrial(outcome.alignment.X_WV, outcome.alignment.duration_s, user_id_);
  ORBED_LOG(kInfo) << "trial " << index << " of '" << session_.id << "' (" << ModeName(session_.display_mode)
                   << ", " << session_.num_mirrors << " display(s)): " << outcome.alignment.stop_reason
                   << " after " << outcome.alignment.nudges << " nudges, "
                   << Fixed(outcome.alignment.duration_s, 1) << " s emulated; error vs truth "
                   << Fixed(outcome.registration.translation_error_m * 1e3, 1) << " mm, "
                   << Fixed(outcome.registration.rotation_error_deg, 2) << " deg";
}

void HmdProcess::PublishTrial(const Eigen::Isometry3d& X_WV, double duration_s, const std::string& user_id) {
  orbed::alignment_trial_t msg{};
  msg.utime = NowMicros();
  msg.session_id = session_.id;
  msg.trial_index = session_.next_index++;
  msg.display_mode = session_.display_mode;
  msg.num_mirrors = session_.num_mirrors;
  msg.num_joints = static_cast<int32_t>(q_rad_.size());
  msg.joint_position = FromVectorX(q_rad_);
  msg.X_WV = ToPose(X_WV);
  msg.duration_s = duration_s;
  msg.user_id = user_id;
  process_->Publish(options_.trial_channel, msg);
}

void HmdProcess::HandleKey(int key) {
  Eigen::Isometry3d X_WV = X_WV_manual_;
  switch (ApplyKey(key, options_.displays, &ui_, &X_WV)) {
    case KeyAction::kMoved:
      X_WV_manual_ = X_WV;
      return;
    case KeyAction::kReset:
      X_WV_manual_ = X_WV_start_;
      last_event_ = "back at the start pose";
      return;
    case KeyAction::kRecapture:
      pipeline_->RequestRecapture(ui_.shown_display);
      last_event_ = "display " + std::to_string(ui_.shown_display) + " re-captured from here";
      return;
    case KeyAction::kQuit:
      process_->RequestStop();
      return;
    case KeyAction::kSubmit: {
      if (!(have_q_ && have_X_WR_)) {
        last_event_ =
            "cannot submit yet: no " + options_.iiwa_status_channel + " / " + options_.robot_state_channel;
        ORBED_LOG(kWarn) << last_event_;
        return;
      }
      if (session_.id.empty()) {
        // No conductor: a local session, announced so that orbed-registration averages it.
        orbed::session_control_t start{};
        start.utime = NowMicros();
        start.session_id = "interactive-" + std::to_string(start.utime / 1000000);
        start.command = orbed::session_control_t::START;
        start.display_mode = options_.displays > 0 ? +orbed::alignment_trial_t::MODE_AR_REFLECTIVE
                                                   : +orbed::alignment_trial_t::MODE_AR;
        start.num_mirrors = options_.displays;
        start.method = orbed::registration_t::METHOD_KARCHER;
        session_ = Session{start.session_id, start.display_mode, start.num_mirrors, start.method, 0};
        process_->Publish(options_.session_control_channel, start);
      }
      const double duration_s = std::chrono::duration<double>(Clock::now() - trial_started_).count();
      const int32_t index = session_.next_index;
      PublishTrial(X_WV_manual_, duration_s, "interactive");
      trial_requested_ = false;
      trial_started_ = Clock::now();
      last_event_ = "submitted trial " + std::to_string(index) + " of '" + session_.id + "' (" +
                    Fixed(duration_s, 1) + " s)";
      ORBED_LOG(kInfo) << last_event_;
      return;
    }
    default:
      return;
  }
}

cv::Mat HmdProcess::CurrentWindowImage() {
  std::vector<std::string> lines;
  std::string session = session_.id.empty()
                            ? std::string("no session (Enter starts a local one)")
                            : "session '" + session_.id + "' (" + ModeName(session_.display_mode) + ", " +
                                  std::to_string(session_.num_mirrors) + " display(s)), next trial " +
                                  std::to_string(session_.next_index);
  if (trial_requested_) session += "   >> TRIAL REQUESTED: align, then Enter <<";
  lines.push_back(session);
  const Eigen::Isometry3d X_WV = CurrentX_WV();
  const Eigen::Vector3d dp_mm = (X_WV.translation() - X_WV_start_.translation()) * 1e3;
  const double dtheta_deg =
      Eigen::AngleAxisd(X_WV_start_.linear().transpose() * X_WV.linear()).angle() * 180.0 / M_PI;
  char text[256];
  std::snprintf(text, sizeof(text),
                "X_WV from the start pose: (%+.1f, %+.1f, %+.1f) mm, %.2f deg   robot: %s   tracking: %s",
                dp_mm.x(), dp_mm.y(), dp_mm.z(), dtheta_deg,
                have_q_ && have_X_WR_ ? "live" : "waiting for IIWA_STATUS + ROBOT_STATE",
                live_->have_sample ? TrackingStateName(live_->sample.state) : "-");
  lines.push_back(text);
  lines.push_back(last_event_.empty() ? std::string(" ") : last_event_);
  return WindowImage(pipeline_->LatestArView(), pipeline_->LatestReflective(ui_.shown_display), ui_, lines);
}

void HmdProcess::InteractiveTick() {
  pipeline_->Post(ImagePipeline::kArView, Inputs(), false);  // the window's AR view, at the window rate
  last_window_ = CurrentWindowImage();
  if (window_open_) cv::imshow(kWindowName, last_window_);
  const int key = window_open_ ? cv::waitKey(1) : -1;
  const std::vector<int> scripted = ScriptedKeys(options_.scripted_keys);
  if (scripted_next_ < scripted.size()) HandleKey(scripted[scripted_next_++]);
  if (key >= 0) HandleKey(key);
}

int HmdProcess::Run() {
  if (options_.interactive) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) {
      throw std::runtime_error(
          "--interactive needs an X display ($DISPLAY is not set); on a headless machine run "
          "it under `xvfb-run -a`");
    }
    try {
      cv::namedWindow(kWindowName, cv::WINDOW_AUTOSIZE);
    } catch (const cv::Exception& e) {
      throw std::runtime_error(std::string("--interactive: cannot open a window: ") + e.what());
    }
    window_open_ = true;
    trial_started_ = Clock::now();
    for (const auto& line : InteractiveHelpLines()) ORBED_LOG(kInfo) << "keys: " << line;
  }
  const int code = process_->Run();
  pipeline_->Flush();
  ORBED_LOG(kInfo) << "camera frames rendered " << pipeline_->rendered() << ", reused " << pipeline_->reused()
                   << ", requests skipped (worker busy) " << pipeline_->skipped();
  if (options_.interactive && !options_.screenshot_path.empty()) {
    const cv::Mat image = CurrentWindowImage();
    if (!cv::imwrite(options_.screenshot_path, image)) {
      ORBED_LOG(kError) << "cannot write the screenshot " << options_.screenshot_path;
      return 1;
    }
    ORBED_LOG(kInfo) << "screenshot " << options_.screenshot_path << " (" << image.cols << "x" << image.rows
                     << ")";
  }
  return code;
}

}  // namespace orbed::hmd
