#pragma once
/// @file
/// Everything of the headset that is made of pixels, without a bus: from a snapshot of the inputs
/// (FrameInputs: the latest SLAM sample, the real robot, the hologram pose) it makes
///   - the camera frame: the scene and the real robot at (q, X_WR) rendered from the TRUE camera
///     pose X_WC_true of the sample, JPEG, stamped with the ESTIMATED pose X_WC_est and the
///     sample's utime (capture time = sample time), intrinsics K_o (HMD_CAMERA);
///   - per live display i, its reflective view: the frame the display captured when the walk time t
///     first reached capture_t_s[i] (or when asked to re-capture), composited with the virtual robot
///     at X_WV: K_m = diag(1, −1, 1) · K_o, X_WM = X_WC_est · [R_x(π) | (0, 0, D)], D = distance
///     from the capture camera centre to the gaze hit on the real robot along the capture-time line
///     of sight (gaze_fallback_distance_m when it misses the robot or no robot is known)
///     (REFLECTIVE_VIEW);
///   - the AR view: the hologram at X_WV over the latest camera frame, drawn with that frame's
///     estimated pose (AR_VIEW);
/// a client's holograms (FrameInputs::holograms) in the same overlay as the virtual robot, in the
/// AR view and the reflective views alike;
/// and hands each message to a callback (ImagePipelineOutputs). It neither publishes nor logs.
///
/// Reuse: a camera frame whose inputs (X_WC_true, q, X_WR) equal the previous frame's reuses its
/// JPEG bytes (a standing wearer and a resting arm give the same picture), restamped. A reflective
/// view is composited again only when its frame, X_WV or the client's holograms changed. After the robot
/// moved, a captured display renders its frame again from the same viewpoint, at most every
/// recapture_period_s.
///
/// Threading: with options.threaded the work runs on one worker thread owned by the pipeline.
/// Post() hands it a job with its inputs, latest wins: a job that finds the previous request of its
/// kind still pending replaces it and counts as skipped, so that a busy frame never delays the
/// caller. The callbacks are then called on the worker thread. Without threading Post() does the
/// work at once on the caller's thread (deterministic). Post() and Flush() are called from one
/// thread (the owner's); RequestRecapture() and the Latest*() accessors from any. The callbacks must
/// not call back into the pipeline.
///
/// Clocks (injected, ImagePipelineClocks): wall_utime stamps REFLECTIVE_VIEW.utime [µs];
/// monotonic_s paces the re-captures [s]. Everything else comes from the inputs.
///
/// Frames: W world (= the SLAM map for estimates), H head, C camera, M reversed frustum, R real
/// robot base, V virtual robot base. Units: m, rad, px, s; utime µs.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <orbed/image_t.hpp>
#include <orbed/reflective_view_t.hpp>

#include "geometry/camera_model.h"
#include "hmd_emulator/reflective.h"
#include "hmd_emulator/robot_state.h"
#include "hmd_emulator/slam_model.h"
#include "render/renderer.h"
#include "render/room_mesh.h"
#include "render/scene_geometry.h"
#include "sim/robot_model.h"

namespace orbed::hmd {

/// What a frame is made from (copied into the pipeline).
struct FrameInputs {
  bool have_sample{false};
  SlamSample sample;        ///< the latest SLAM sample (true and estimated poses)
  int64_t sample_utime{0};  ///< its utime [µs]
  RobotState robot;
  Eigen::Isometry3d X_WV{Eigen::Isometry3d::Identity()};  ///< the hologram (map coordinates)
  /// The hologram's joints in AR_VIEW during a set-up (GUIDANCE's target); empty = the real arm's.
  Eigen::VectorXd q_hologram_rad;
  /// No hologram in AR_VIEW (the fixed-display mode: the guidance is on a monitor).
  bool hide_hologram{false};
  /// The hologram's joints in the reflective displays during a set-up (GUIDANCE's target in the
  /// ar_reflective mode); empty = the joints of the captured frame (the alignment's view).
  Eigen::VectorXd q_reflective_rad;
  /// The displays show their captured frame alone (a set-up in the ar and fixed modes, which have
  /// no reflective display).
  bool hide_reflective_hologram{false};
  double t_s{0};  ///< walk time of the sample [s]
  /// A client's holograms (HOLOGRAMS tessellated in W, holograms.h): drawn in AR_VIEW and over
  /// every display's frame with the virtual robot (whatever hides the robot: they are the
  /// client's). Shared, not copied, per frame; a new pointer is a new scene. Null or empty: none.
  std::shared_ptr<const render::Mesh> holograms;
  /// A live collaborator's camera as display 0 (orbed-hmd --collaborator; viraal_trial.h's
  /// CollaboratorDisplay): truly at X_WC_true, placed in this headset's map at X_WC_est. Display 0
  /// then shows the scene and the real robot rendered from X_WC_true (the picture that camera
  /// takes) with the hologram composed from X_WC_est, renewed at each camera frame in which the
  /// pose or the robot changed, instead of the frame it captured on the walk.
  struct CollaboratorCamera {
    Eigen::Isometry3d X_WC_true{Eigen::Isometry3d::Identity()};
    Eigen::Isometry3d X_WC_est{Eigen::Isometry3d::Identity()};
    int64_t utime{0};  ///< its sample's [µs]
  };
  std::optional<CollaboratorCamera> collaborator;
};

struct ImagePipelineOptions {
  geometry::Intrinsics intrinsics{geometry::Intrinsics::HoloLensPv()};  ///< K_o of the camera
  int jpeg_quality{85};                                                 ///< 1..100
  /// One entry per live display: the walk time at which it captures its frame [s].
  std::vector<double> display_capture_t_s;
  double recapture_period_s{0.5};
  double gaze_fallback_distance_m{1.5};
  double max_gaze_distance_m{10.0};
  bool threaded{true};
};

/// Where the messages go. Any may be empty (the message is then dropped).
struct ImagePipelineOutputs {
  std::function<void(const orbed::image_t&)> camera;
  std::function<void(const orbed::reflective_view_t&)> reflective;
  std::function<void(const orbed::image_t&)> ar_view;
  /// An engine error: "image pipeline: <what>" and the number of errors so far, this one included
  /// (the job is dropped; the pipeline keeps going).
  std::function<void(const std::string& message, int64_t count)> error;
};

struct ImagePipelineClocks {
  std::function<int64_t()> wall_utime;  ///< µs since the Unix epoch
  std::function<double()> monotonic_s;  ///< s from any fixed origin
  /// The system's: NowMicros-style wall clock and std::chrono::steady_clock.
  static ImagePipelineClocks System();
};

class ImagePipeline {
 public:
  enum class Job { kCamera = 0, kReflective = 1, kArView = 2 };

  /// `robot` must outlive the pipeline; `scene_objects` is tessellated now (not kept).
  /// Starts the worker when options.threaded.
  ImagePipeline(const sim::RobotModel& robot, const render::SceneGeometry& scene_objects,
                ImagePipelineOptions options, ImagePipelineOutputs outputs,
                ImagePipelineClocks clocks = ImagePipelineClocks::System());
  /// Joins the worker (a job in progress finishes; pending ones are dropped).
  ~ImagePipeline();
  ImagePipeline(const ImagePipeline&) = delete;
  ImagePipeline& operator=(const ImagePipeline&) = delete;

  /// Makes (inline) or requests (threaded) one job from `inputs`. kArView with publish = false only
  /// refreshes LatestArView() (the interactive window) without an AR_VIEW message. Returns true when
  /// the request replaced one of its kind still pending (counted in skipped(): that frame is never
  /// made), false otherwise (always false inline).
  bool Post(Job job, const FrameInputs& inputs, bool publish = true);
  /// Waits until the worker has done every pending job (no-op inline).
  void Flush();
  /// Display `display` captures again at the next camera frame (out-of-range indices are ignored).
  void RequestRecapture(int display);

  /// The latest AR view / reflective view of `display` (BGR; empty before the first).
  cv::Mat LatestArView();
  cv::Mat LatestReflective(int display);
  int64_t skipped() const { return skipped_; }    ///< requests replaced while pending
  int64_t rendered() const { return rendered_; }  ///< camera frames rendered
  int64_t reused() const { return reused_; }      ///< camera frames that reused the JPEG

 private:
  struct Display {
    double capture_t_s{0};
    bool captured{false};
    CapturedFrame frame;  // frame.q_rad = robot.q_rad when robot.known()
    Eigen::Isometry3d X_WC_true{Eigen::Isometry3d::Identity()};
    Eigen::Isometry3d X_WH_true{Eigen::Isometry3d::Identity()};
    RobotState robot;  // what the frame shows
    double D_m{0};
    int64_t version{0};
    double captured_at_s{0};
    // The composed view, cached until the frame, X_WV or the hologram's joints change.
    int64_t composed_version{-1};
    Eigen::Isometry3d composed_X_WV{Eigen::Isometry3d::Identity()};
    Eigen::VectorXd composed_q_rad;  // empty: no hologram
    bool composed_hidden{false};
    std::shared_ptr<const render::Mesh> composed_holograms;
    ReflectiveGeometry geometry;
    std::vector<std::uint8_t> jpeg;
  };

  void WorkerLoop();
  void Run(Job job, const FrameInputs& in, bool publish);
  void PoseRobot(const RobotState& robot);
  double GazeDistance(const Eigen::Isometry3d& X_WH, const Eigen::Isometry3d& X_WC) const;
  void Capture(Display* d, const FrameInputs& in);
  void Recapture(Display* d);
  // Display 0 from the collaborator's camera (FrameInputs::collaborator).
  void FromCollaborator(Display* d, const FrameInputs::CollaboratorCamera& camera);
  void Camera(const FrameInputs& in);
  void Reflective(const FrameInputs& in);
  void ArView(const FrameInputs& in, bool publish);

  const ImagePipelineOptions options_;
  const ImagePipelineOutputs outputs_;
  const ImagePipelineClocks clocks_;

  // Worker state (the worker thread, or the caller's inline).
  render::Renderer renderer_;
  Compositor compositor_;
  render::RoomMesh room_;  // the scene + the robot at robot_ when known (render/room_mesh.h)
  RobotState robot_;       // the robot drawn in room_ and bgr_
  // The latest camera frame.
  bool have_frame_{false};
  cv::Mat bgr_;
  std::vector<std::uint8_t> jpeg_, ar_jpeg_;
  Eigen::Isometry3d frame_X_WC_true_{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d frame_X_WC_est_{Eigen::Isometry3d::Identity()};
  int64_t frame_utime_{0};
  std::vector<Display> displays_;
  int64_t errors_{0};
  std::atomic<int64_t> skipped_{0}, rendered_{0}, reused_{0};

  // Outputs read by other threads, and re-capture requests (out_mutex_).
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

}  // namespace orbed::hmd
