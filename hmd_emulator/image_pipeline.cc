#include "hmd_emulator/image_pipeline.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "hmd_emulator/gaze.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::hmd {
namespace {

bool SamePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) { return a.matrix() == b.matrix(); }

// The client's holograms when there is anything to draw, else null.
const render::Mesh* Drawable(const std::shared_ptr<const render::Mesh>& holograms) {
  return holograms && !holograms->triangles.empty() ? holograms.get() : nullptr;
}

void Encode(const cv::Mat& bgr, int quality, std::vector<std::uint8_t>* jpeg) {
  if (!render::EncodeJpeg(bgr, quality, jpeg)) throw std::runtime_error("JPEG encoding failed");
}

}  // namespace

ImagePipelineClocks ImagePipelineClocks::System() {
  ImagePipelineClocks clocks;
  clocks.wall_utime = [] { return NowMicros(); };
  clocks.monotonic_s = [] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  };
  return clocks;
}

ImagePipeline::ImagePipeline(const sim::RobotModel& robot, const render::SceneGeometry& scene_objects,
                             ImagePipelineOptions options, ImagePipelineOutputs outputs,
                             ImagePipelineClocks clocks)
    : options_(std::move(options)),
      outputs_(std::move(outputs)),
      clocks_(std::move(clocks)),
      renderer_(options_.intrinsics),
      compositor_(robot),
      room_(robot, scene_objects) {
  for (double t_s : options_.display_capture_t_s) {
    Display d;
    d.capture_t_s = t_s;
    displays_.push_back(std::move(d));
  }
  if (options_.threaded) worker_ = std::thread([this] { WorkerLoop(); });
}

ImagePipeline::~ImagePipeline() {
  {
    std::lock_guard<std::mutex> lock(jobs_mutex_);
    stop_ = true;
  }
  jobs_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

bool ImagePipeline::Post(Job job, const FrameInputs& inputs, bool publish) {
  if (!options_.threaded) {
    Run(job, inputs, publish);
    return false;
  }
  const int j = static_cast<int>(job);
  bool replaced = false;
  {
    std::lock_guard<std::mutex> lock(jobs_mutex_);
    replaced = pending_[j];
    if (replaced) ++skipped_;
    pending_[j] = true;
    inputs_[j] = inputs;
    if (job == Job::kArView) publish_ar_ = publish_ar_ || publish;
  }
  jobs_cv_.notify_all();
  return replaced;
}

void ImagePipeline::Flush() {
  if (!options_.threaded) return;
  std::unique_lock<std::mutex> lock(jobs_mutex_);
  done_cv_.wait(lock, [this] { return stop_ || (!busy_ && !pending_[0] && !pending_[1] && !pending_[2]); });
}

void ImagePipeline::RequestRecapture(int display) {
  std::lock_guard<std::mutex> lock(out_mutex_);
  if (display >= 0 && display < static_cast<int>(displays_.size())) recapture_now_.push_back(display);
}

cv::Mat ImagePipeline::LatestArView() {
  std::lock_guard<std::mutex> lock(out_mutex_);
  return ar_latest_;
}

cv::Mat ImagePipeline::LatestReflective(int display) {
  std::lock_guard<std::mutex> lock(out_mutex_);
  if (display < 0 || display >= static_cast<int>(reflective_latest_.size())) return cv::Mat();
  return reflective_latest_[display];
}

void ImagePipeline::WorkerLoop() {
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

void ImagePipeline::Run(Job job, const FrameInputs& in, bool publish) {
  try {
    if (job == Job::kCamera) Camera(in);
    if (job == Job::kReflective) Reflective(in);
    if (job == Job::kArView) ArView(in, publish);
  } catch (const std::exception& e) {
    // An engine error must not take the process down.
    if (outputs_.error) outputs_.error(std::string("image pipeline: ") + e.what(), ++errors_);
  }
}

void ImagePipeline::PoseRobot(const RobotState& robot) {
  if (robot.SameAs(robot_)) return;
  if (robot.known()) {
    room_.PoseRobot(robot.q_rad, robot.X_WR);
  } else {
    room_.ClearRobot();
  }
  robot_ = robot;
}

// D (paper Sec. II-B): from the camera centre to where the line of sight of a head at X_WH hits the
// ROBOT (the real robot's primitives only: the first robot surface along the ray, whatever scene
// object may stand in front of it). When the gaze misses the robot (or no robot pose is known yet)
// D is gaze_fallback_distance_m: D only places the display, and a wall or the floor behind the
// robot would place it far from where the person works.
double ImagePipeline::GazeDistance(const Eigen::Isometry3d& X_WH, const Eigen::Isometry3d& X_WC) const {
  const double fallback_m = options_.gaze_fallback_distance_m;
  if (!robot_.known()) return fallback_m;
  const Eigen::Vector3d p_WH = X_WH.translation(), d_W = X_WH.linear().col(2);
  const RayHit hit =
      CastRay(room_.robot_geometry(), p_WH, d_W, render::kRealWorld, options_.max_gaze_distance_m);
  if (!hit.hit) return fallback_m;
  const double D_m = (hit.p_WQ - X_WC.translation()).norm();
  return std::isfinite(D_m) && D_m > 0.01 ? D_m : fallback_m;
}

void ImagePipeline::Capture(Display* d, const FrameInputs& in) {
  d->frame.bgr = bgr_.clone();
  d->frame.intrinsics = renderer_.intrinsics();
  d->frame.X_WC_est = frame_X_WC_est_;
  d->frame.q_rad = robot_.known() ? robot_.q_rad : Eigen::VectorXd();
  d->frame.utime = frame_utime_;
  d->X_WC_true = frame_X_WC_true_;
  d->X_WH_true = in.sample.X_WH_true;
  d->robot = robot_;
  d->D_m = GazeDistance(d->X_WH_true, d->X_WC_true);
  d->captured = true;
  d->captured_at_s = clocks_.monotonic_s();
  ++d->version;
}

// The robot moved since the display captured: render its frame again from the same viewpoint.
void ImagePipeline::Recapture(Display* d) {
  renderer_.Render(room_.mesh(), d->X_WC_true, &d->frame.bgr);
  d->frame.bgr = d->frame.bgr.clone();  // own its pixels (the renderer may reuse the buffer)
  d->frame.q_rad = robot_.known() ? robot_.q_rad : Eigen::VectorXd();
  d->robot = robot_;
  d->D_m = GazeDistance(d->X_WH_true, d->X_WC_true);
  d->captured_at_s = clocks_.monotonic_s();
  ++d->version;
}

void ImagePipeline::FromCollaborator(Display* d, const FrameInputs::CollaboratorCamera& camera) {
  if (d->captured && SamePose(d->X_WC_true, camera.X_WC_true) &&
      SamePose(d->frame.X_WC_est, camera.X_WC_est) && robot_.SameAs(d->robot)) {
    return;
  }
  renderer_.Render(room_.mesh(), camera.X_WC_true, &d->frame.bgr);
  d->frame.bgr = d->frame.bgr.clone();  // own its pixels (the renderer may reuse the buffer)
  d->frame.intrinsics = renderer_.intrinsics();
  d->frame.X_WC_est = camera.X_WC_est;
  d->frame.q_rad = robot_.known() ? robot_.q_rad : Eigen::VectorXd();
  d->frame.utime = camera.utime;
  d->X_WC_true = camera.X_WC_true;
  d->X_WH_true = camera.X_WC_true;  // D along the camera's own line of sight
  d->robot = robot_;
  d->D_m = GazeDistance(d->X_WH_true, d->X_WC_true);
  d->captured = true;
  d->captured_at_s = clocks_.monotonic_s();
  ++d->version;
}

void ImagePipeline::Camera(const FrameInputs& in) {
  if (!in.have_sample) return;
  const Eigen::Isometry3d& X_WC_true = in.sample.X_WC_true;
  if (have_frame_ && SamePose(X_WC_true, frame_X_WC_true_) && in.robot.SameAs(robot_)) {
    ++reused_;
  } else {
    have_frame_ = false;
    PoseRobot(in.robot);
    renderer_.Render(room_.mesh(), X_WC_true, &bgr_);
    Encode(bgr_, options_.jpeg_quality, &jpeg_);
    ++rendered_;
  }
  have_frame_ = true;
  frame_X_WC_true_ = X_WC_true;
  frame_X_WC_est_ = in.sample.X_WC_est;
  frame_utime_ = in.sample_utime;
  if (outputs_.camera) {
    outputs_.camera(JpegImageMessage(jpeg_, renderer_.intrinsics(), in.sample_utime, in.sample.X_WC_est,
                                     in.sample_utime));
  }

  std::vector<int> now;
  {
    std::lock_guard<std::mutex> lock(out_mutex_);
    now.swap(recapture_now_);
  }
  for (std::size_t i = 0; i < displays_.size(); ++i) {
    Display& d = displays_[i];
    if (i == 0 && in.collaborator) {
      FromCollaborator(&d, *in.collaborator);
      continue;
    }
    // Due at the arrival, once tracking: a frame taken while tracking is limited or lost has no
    // pose to place it with (as the emulated trial's display, viraal_trial.h).
    bool wanted =
        !d.captured && in.t_s >= d.capture_t_s - 1e-9 && in.sample.state == TrackingState::kTracking;
    for (int k : now) wanted = wanted || k == static_cast<int>(i);
    if (wanted) {
      Capture(&d, in);
    } else if (d.captured && !robot_.SameAs(d.robot) &&
               clocks_.monotonic_s() - d.captured_at_s >= options_.recapture_period_s) {
      Recapture(&d);
    }
  }
}

void ImagePipeline::Reflective(const FrameInputs& in) {
  for (std::size_t i = 0; i < displays_.size(); ++i) {
    Display& d = displays_[i];
    if (!d.captured) continue;
    // The hologram: at the set-up's target, at the captured frame's joints, or none (no robot
    // known at capture, or a set-up mode without a display).
    const bool hidden = in.hide_reflective_hologram || !d.robot.known();
    const Eigen::VectorXd& q =
        in.q_reflective_rad.size() == d.frame.q_rad.size() ? in.q_reflective_rad : d.frame.q_rad;
    const render::Mesh* holograms = Drawable(in.holograms);
    if (d.composed_version != d.version || !SamePose(d.composed_X_WV, in.X_WV) ||
        hidden != d.composed_hidden || (!hidden && q != d.composed_q_rad) ||
        in.holograms != d.composed_holograms) {
      ReflectiveView view;
      if (!hidden) {
        CapturedFrame frame = d.frame;  // shares the pixels
        frame.q_rad = q;
        compositor_.ComposeReflective(frame, d.D_m, in.X_WV, &view, nullptr, holograms);
      } else {
        if (holograms) {
          compositor_.ComposeHolograms(d.frame.bgr, d.frame.intrinsics, d.frame.X_WC_est, *holograms,
                                       &view.bgr);
        } else {
          view.bgr = d.frame.bgr.clone();
        }
        view.geometry = MakeReflectiveGeometry(d.frame.intrinsics, d.frame.X_WC_est, d.D_m);
      }
      Encode(view.bgr, options_.jpeg_quality, &d.jpeg);
      d.geometry = view.geometry;
      d.composed_version = d.version;
      d.composed_X_WV = in.X_WV;
      d.composed_hidden = hidden;
      d.composed_q_rad = hidden ? Eigen::VectorXd() : q;
      d.composed_holograms = in.holograms;
      std::lock_guard<std::mutex> lock(out_mutex_);
      if (reflective_latest_.size() < displays_.size()) reflective_latest_.resize(displays_.size());
      reflective_latest_[i] = view.bgr;
    }
    orbed::reflective_view_t msg{};
    msg.utime = clocks_.wall_utime();
    msg.display_id = static_cast<int32_t>(i);
    msg.image = JpegImageMessage(d.jpeg, d.frame.intrinsics, d.frame.utime, d.frame.X_WC_est, d.frame.utime);
    FromMatrix3(d.geometry.K_m, msg.K_m);
    msg.X_WM = ToPose(d.geometry.X_WM);
    msg.distance_m = d.geometry.distance_m;
    msg.source_utime = d.frame.utime;
    msg.X_WV = ToPose(d.composed_X_WV);
    if (outputs_.reflective) outputs_.reflective(msg);
  }
}

void ImagePipeline::ArView(const FrameInputs& in, bool publish) {
  if (!have_frame_) return;
  cv::Mat ar;
  const render::Mesh* holograms = Drawable(in.holograms);
  if (robot_.known() && !in.hide_hologram) {
    const Eigen::VectorXd& q =
        in.q_hologram_rad.size() == robot_.q_rad.size() ? in.q_hologram_rad : robot_.q_rad;
    compositor_.ComposeArView(bgr_, renderer_.intrinsics(), frame_X_WC_est_, q, in.X_WV, &ar, nullptr,
                              holograms);
  } else if (holograms) {
    compositor_.ComposeHolograms(bgr_, renderer_.intrinsics(), frame_X_WC_est_, *holograms, &ar);
  } else {
    ar = bgr_.clone();
  }
  {
    std::lock_guard<std::mutex> lock(out_mutex_);
    ar_latest_ = ar;
  }
  if (!publish) return;
  Encode(ar, options_.jpeg_quality, &ar_jpeg_);
  if (outputs_.ar_view) {
    outputs_.ar_view(
        JpegImageMessage(ar_jpeg_, renderer_.intrinsics(), frame_utime_, frame_X_WC_est_, frame_utime_));
  }
}

}  // namespace orbed::hmd
