// The image pipeline without a bus: the same scripted inputs through the worker thread (a Flush()
// after every request, so nothing is skipped) and inline give the same messages, byte for byte
// (JPEG data, stamps, poses, K_m, X_WM, D); JPEG bytes are reused for an unchanged frame; the
// displays capture at their walk times, re-capture after the robot moved and on request; a burst of
// requests on the worker is latest-wins with the skipped ones counted.
#include "hmd_emulator/image_pipeline.h"

#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"
#include "hmd_emulator/hmd_config.h"
#include "hmd_emulator/pose_stream.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::hmd {
namespace {

template <class Msg>
std::vector<std::uint8_t> Bytes(const Msg& msg) {
  std::vector<std::uint8_t> bytes(msg.getEncodedSize());
  EXPECT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

// Everything a pipeline handed out, in order (callbacks may run on the worker thread).
struct Published {
  std::mutex mutex;
  std::vector<orbed::image_t> camera, ar;
  std::vector<orbed::reflective_view_t> reflective;
  std::vector<std::string> errors;
};

// The shipped robot, scene and configs; samples of the shipped walk.
struct World {
  World()
      : config(LoadConfigs()),
        scene(sim::LoadSceneFile(HmdSourcePath(sim::kDefaultSceneRelativePath))),
        robot(sim::LoadRobotForScene(HmdSourcePath(sim::RobotModel::kDefaultUrdfRelativePath), scene)),
        stream(config, scene, robot) {}
  static HmdConfigSet LoadConfigs() {
    std::vector<std::string> paths;
    for (const auto& rel : DefaultHmdConfigRelativePaths()) paths.push_back(HmdSourcePath(rel));
    return LoadHmdConfigs(paths);
  }
  std::vector<double> CaptureTimes() const {
    std::vector<double> t_s;
    for (const auto& d : config.hmd.displays) {
      t_s.push_back(stream.trajectory().ArrivalTime(stream.trajectory().FindWaypoint(d.capture_waypoint)));
    }
    return t_s;
  }
  FrameInputs Sample(double t_s, int64_t utime) {
    stream.Step(t_s, utime);
    FrameInputs in;
    in.have_sample = true;
    in.sample = stream.sample();
    in.sample_utime = utime;
    in.t_s = t_s;
    return in;
  }
  HmdConfigSet config;
  sim::Scene scene;
  sim::RobotModel robot;
  PoseStream stream;
};

RobotState Robot(const std::vector<double>& q_deg, const Eigen::Isometry3d& X_WR) {
  RobotState robot;
  robot.have_q = robot.have_X_WR = true;
  robot.q_rad.resize(static_cast<int>(q_deg.size()));
  for (std::size_t i = 0; i < q_deg.size(); ++i) robot.q_rad[i] = q_deg[i] * kDegToRad;
  robot.X_WR = X_WR;
  return robot;
}

// One scripted step: the inputs, the monotonic time of the step, and whether the person asks
// display 0 to re-capture first.
struct Step {
  FrameInputs in;
  double monotonic_s{0};
  bool recapture0{false};
};

std::vector<Step> Script(World* world) {
  const Eigen::Isometry3d X_WR = world->scene.X_WR;
  const Eigen::Isometry3d X_WV0 = X_WR * Eigen::Translation3d(0.10, -0.08, 0.05);
  const Eigen::Isometry3d X_WV1 = X_WR * Eigen::Translation3d(0.02, 0.01, -0.01);
  std::vector<Step> steps;
  auto add = [&](double t_s, const RobotState& robot, const Eigen::Isometry3d& X_WV,
                 bool recapture0 = false) {
    Step s;
    s.in = world->Sample(t_s, 1'700'000'000'000'000 + static_cast<int64_t>(steps.size()) * 33'000);
    s.in.robot = robot;
    s.in.X_WV = X_WV;
    s.monotonic_s = 100.0 + static_cast<double>(steps.size());
    s.recapture0 = recapture0;
    steps.push_back(s);
  };
  const RobotState unknown;
  const RobotState arm = Robot({0, 30, 0, -60, 0, 45, 0}, X_WR);
  const RobotState moved = Robot({10, 35, 0, -60, 0, 45, 0}, X_WR);
  add(0.0, unknown, X_WV0);      // display 0 captures a frame without the robot
  add(0.5, unknown, X_WV0);      // standing: the same frame (JPEG reused)
  add(1.0, arm, X_WV0);          // the robot appears: rendered; display 0 re-captures
  add(1.5, arm, X_WV1);          // the hologram moves: the reflective view is composed again
  add(3.0, moved, X_WV1);        // walking, the arm moved
  add(5.5, moved, X_WV1);        // at head_end: display 1 captures
  add(5.5, moved, X_WV1, true);  // display 0 re-captured on request
  return steps;
}

struct ScriptRun {
  std::unique_ptr<Published> out = std::make_unique<Published>();
  int64_t rendered{0}, reused{0}, skipped{0};
  std::vector<cv::Mat> reflective_latest;
  cv::Mat ar_latest;
};

ScriptRun RunScript(World* world, const std::vector<Step>& steps, bool threaded) {
  ScriptRun run;
  Published* out = run.out.get();
  auto wall = std::make_shared<std::atomic<int64_t>>(5'000);
  auto monotonic = std::make_shared<std::atomic<double>>(0.0);
  ImagePipelineOptions options;
  options.display_capture_t_s = world->CaptureTimes();
  EXPECT_EQ(options.display_capture_t_s.size(), 2u);
  options.threaded = threaded;
  ImagePipelineOutputs outputs;
  outputs.camera = [out](const orbed::image_t& m) {
    std::lock_guard<std::mutex> lock(out->mutex);
    out->camera.push_back(m);
  };
  outputs.reflective = [out](const orbed::reflective_view_t& m) {
    std::lock_guard<std::mutex> lock(out->mutex);
    out->reflective.push_back(m);
  };
  outputs.ar_view = [out](const orbed::image_t& m) {
    std::lock_guard<std::mutex> lock(out->mutex);
    out->ar.push_back(m);
  };
  outputs.error = [out](const std::string& e, int64_t) {
    std::lock_guard<std::mutex> lock(out->mutex);
    out->errors.push_back(e);
  };
  ImagePipelineClocks clocks;
  clocks.wall_utime = [wall] { return (*wall)++; };
  clocks.monotonic_s = [monotonic] { return monotonic->load(); };
  ImagePipeline pipeline(world->robot, world->stream.scene_objects(), options, outputs, clocks);
  for (const Step& s : steps) {
    *monotonic = s.monotonic_s;
    if (s.recapture0) pipeline.RequestRecapture(0);
    for (auto job :
         {ImagePipeline::Job::kCamera, ImagePipeline::Job::kReflective, ImagePipeline::Job::kArView}) {
      pipeline.Post(job, s.in);
      pipeline.Flush();
    }
  }
  run.rendered = pipeline.rendered();
  run.reused = pipeline.reused();
  run.skipped = pipeline.skipped();
  run.reflective_latest = {pipeline.LatestReflective(0), pipeline.LatestReflective(1)};
  run.ar_latest = pipeline.LatestArView();
  return run;
}

TEST(ImagePipeline, ThreadedPublishesWhatInlinePublishes) {
  World world;
  const std::vector<Step> steps = Script(&world);
  const ScriptRun inline_run = RunScript(&world, steps, false);
  const ScriptRun threaded = RunScript(&world, steps, true);

  EXPECT_TRUE(inline_run.out->errors.empty()) << inline_run.out->errors.front();
  EXPECT_TRUE(threaded.out->errors.empty());
  EXPECT_EQ(threaded.skipped, 0);
  EXPECT_EQ(threaded.rendered, inline_run.rendered);
  EXPECT_EQ(threaded.reused, inline_run.reused);

  // One camera frame and one AR view per step; reflective views from the first step on.
  const Published& a = *inline_run.out;
  const Published& b = *threaded.out;
  ASSERT_EQ(a.camera.size(), steps.size());
  ASSERT_EQ(a.ar.size(), steps.size());
  ASSERT_EQ(b.camera.size(), a.camera.size());
  ASSERT_EQ(b.ar.size(), a.ar.size());
  ASSERT_EQ(b.reflective.size(), a.reflective.size());
  for (std::size_t i = 0; i < a.camera.size(); ++i) {
    EXPECT_EQ(Bytes(b.camera[i]), Bytes(a.camera[i])) << "camera " << i;
    EXPECT_EQ(Bytes(b.ar[i]), Bytes(a.ar[i])) << "AR view " << i;
    // Stamped with the sample: capture time = sample time, the estimated camera pose.
    EXPECT_EQ(a.camera[i].utime, steps[i].in.sample_utime);
    EXPECT_EQ(a.camera[i].pose_utime, steps[i].in.sample_utime);
    const orbed::pose_t X_WC_est = ToPose(steps[i].in.sample.X_WC_est);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.camera[i].X_WC.position_m[k], X_WC_est.position_m[k]);
    const cv::Mat decoded = render::DecodeJpeg(b.camera[i].data);
    EXPECT_EQ(decoded.cols, 1280);
    EXPECT_EQ(decoded.rows, 720);
  }
  for (std::size_t i = 0; i < a.reflective.size(); ++i) {
    EXPECT_EQ(Bytes(b.reflective[i]), Bytes(a.reflective[i])) << "reflective " << i;
    EXPECT_EQ(b.reflective[i].utime, a.reflective[i].utime);  // the injected wall clock
  }
  // Display 0 from step 0 on, display 1 from step 5 (head_end) on.
  EXPECT_EQ(a.reflective.size(), steps.size() + 2);
  // The latest pictures the window shows agree too.
  for (int d = 0; d < 2; ++d) {
    ASSERT_FALSE(inline_run.reflective_latest[d].empty());
    EXPECT_EQ(cv::norm(inline_run.reflective_latest[d], threaded.reflective_latest[d], cv::NORM_INF), 0.0);
  }
  EXPECT_EQ(cv::norm(inline_run.ar_latest, threaded.ar_latest, cv::NORM_INF), 0.0);
}

TEST(ImagePipeline, ReusesCapturesAndRecaptures) {
  World world;
  const std::vector<Step> steps = Script(&world);
  const ScriptRun run = RunScript(&world, steps, false);
  const Published& p = *run.out;
  // Step 1 stands where step 0 stood with the same (unknown) robot: the same JPEG, restamped.
  EXPECT_EQ(p.camera[1].data, p.camera[0].data);
  EXPECT_NE(p.camera[1].utime, p.camera[0].utime);
  EXPECT_EQ(run.reused, 3);  // steps 1, 3 (still dwelling at foot_end) and 6
  EXPECT_EQ(run.rendered, static_cast<int64_t>(steps.size()) - 3);
  // Step 2: the robot appeared, the frame is new.
  EXPECT_NE(p.camera[2].data, p.camera[1].data);

  // Reflective views in order: step 0..4 display 0; step 5 and 6 displays 0 and 1.
  auto display0 = [&p](std::size_t step) { return p.reflective[step <= 5 ? step : 7]; };
  // Display 0 captured at step 0 (source = that frame) and re-captured at step 2 after the robot
  // appeared (same viewpoint, same source stamp, a new picture).
  EXPECT_EQ(display0(0).source_utime, steps[0].in.sample_utime);
  EXPECT_EQ(display0(2).source_utime, steps[0].in.sample_utime);
  EXPECT_NE(display0(2).image.data, display0(1).image.data);
  // Without the robot D is the fallback distance; with it, the gaze hit on the robot.
  EXPECT_DOUBLE_EQ(display0(0).distance_m, world.config.hmd.gaze_fallback_distance_m);
  EXPECT_NE(display0(2).distance_m, world.config.hmd.gaze_fallback_distance_m);
  // Step 3 moved the hologram: a new composition, the same source.
  EXPECT_NE(display0(3).image.data, display0(2).image.data);
  EXPECT_EQ(display0(3).X_WV.position_m[0], ToPose(steps[3].in.X_WV).position_m[0]);
  // Display 1 captured at head_end (step 5).
  EXPECT_EQ(p.reflective[6].display_id, 1);
  EXPECT_EQ(p.reflective[6].source_utime, steps[5].in.sample_utime);
  // Step 6 asked display 0 to capture again: its source is now step 6's frame.
  EXPECT_EQ(p.reflective[7].display_id, 0);
  EXPECT_EQ(p.reflective[7].source_utime, steps[6].in.sample_utime);
}

// The guidance in the reflective displays: the display's captured frame with the hologram at the
// set-up's target (a new composition; the frame's own joints give back the alignment's picture
// byte for byte), or with none: then it is the captured camera frame itself, the same JPEG bytes
// as HMD_CAMERA sent at the capture.
TEST(ImagePipeline, TheDisplaysShowTheSetUpsTargetOrNoHologram) {
  World world;
  const Eigen::Isometry3d X_WR = world.scene.X_WR;
  const RobotState arm = Robot({0, 30, 0, -60, 0, 45, 0}, X_WR);
  std::vector<orbed::image_t> camera;
  std::vector<orbed::reflective_view_t> reflective;
  ImagePipelineOptions options;
  options.display_capture_t_s = {0.0};
  options.threaded = false;
  ImagePipelineOutputs outputs;
  outputs.camera = [&](const orbed::image_t& m) { camera.push_back(m); };
  outputs.reflective = [&](const orbed::reflective_view_t& m) { reflective.push_back(m); };
  ImagePipelineClocks clocks;
  clocks.wall_utime = [] { return int64_t{5'000}; };
  clocks.monotonic_s = [] { return 0.0; };
  ImagePipeline pipeline(world.robot, world.stream.scene_objects(), options, outputs, clocks);
  FrameInputs in = world.Sample(0.0, 1'700'000'000'000'000);
  in.robot = arm;
  in.X_WV = X_WR * Eigen::Translation3d(0.02, 0.01, 0.0);
  auto show = [&](const FrameInputs& inputs) {
    pipeline.Post(ImagePipeline::Job::kCamera, inputs);
    pipeline.Post(ImagePipeline::Job::kReflective, inputs);
    return reflective.back().image.data;
  };
  const std::vector<std::uint8_t> alignment = show(in);  // the frame's joints
  ASSERT_EQ(camera.size(), 1u);
  FrameInputs target = in;
  target.q_reflective_rad = Robot({30, 60, 0, -30, 0, 20, 0}, X_WR).q_rad;
  const std::vector<std::uint8_t> at_target = show(target);
  EXPECT_NE(at_target, alignment);
  FrameInputs same = in;
  same.q_reflective_rad = arm.q_rad;
  EXPECT_EQ(show(same), alignment);
  FrameInputs none = in;
  none.hide_reflective_hologram = true;
  EXPECT_EQ(show(none), camera.front().data);
  EXPECT_EQ(show(target), at_target);
  EXPECT_EQ(reflective.back().source_utime, in.sample_utime);  // one capture throughout
}

// A display due at a time when tracking is lost waits for the first TRACKING frame.
TEST(ImagePipeline, ADisplayCapturesOnlyWhileTracking) {
  World world;
  std::vector<orbed::reflective_view_t> reflective;
  ImagePipelineOptions options;
  options.display_capture_t_s = {0.0};
  options.threaded = false;
  ImagePipelineOutputs outputs;
  outputs.camera = [](const orbed::image_t&) {};
  outputs.reflective = [&](const orbed::reflective_view_t& m) { reflective.push_back(m); };
  ImagePipelineClocks clocks;
  clocks.wall_utime = [] { return int64_t{5'000}; };
  clocks.monotonic_s = [] { return 0.0; };
  ImagePipeline pipeline(world.robot, world.stream.scene_objects(), options, outputs, clocks);
  const RobotState arm = Robot({0, 30, 0, -60, 0, 45, 0}, world.scene.X_WR);
  auto frame = [&](double t_s, int64_t utime, TrackingState state) {
    FrameInputs in = world.Sample(t_s, utime);
    in.robot = arm;
    in.sample.state = state;
    pipeline.Post(ImagePipeline::Job::kCamera, in);
    pipeline.Post(ImagePipeline::Job::kReflective, in);
  };
  frame(0.0, 1'000, TrackingState::kLost);
  frame(0.5, 2'000, TrackingState::kRelocalized);
  EXPECT_TRUE(reflective.empty()) << "nothing captured while not tracking";
  frame(1.0, 3'000, TrackingState::kTracking);
  ASSERT_EQ(reflective.size(), 1u);
  EXPECT_EQ(reflective.back().source_utime, 3'000);
}

TEST(ImagePipeline, WorkerIsLatestWinsAndCountsSkipped) {
  World world;
  const RobotState arm = Robot({0, 30, 0, -60, 0, 45, 0}, world.scene.X_WR);
  std::vector<FrameInputs> inputs;
  for (int k = 0; k < 12; ++k) {
    inputs.push_back(world.Sample(2.0 + 0.1 * k, 1'000'000 + k));
    inputs.back().robot = arm;
  }
  Published threaded_out, inline_out;
  auto outputs = [](Published* out) {
    ImagePipelineOutputs o;
    o.camera = [out](const orbed::image_t& m) {
      std::lock_guard<std::mutex> lock(out->mutex);
      out->camera.push_back(m);
    };
    return o;
  };
  ImagePipelineOptions options;
  ImagePipeline pipeline(world.robot, world.stream.scene_objects(), options, outputs(&threaded_out));
  int64_t replaced = 0;  // what Post() said: the caller's drop count
  for (const FrameInputs& in : inputs) replaced += pipeline.Post(ImagePipeline::Job::kCamera, in) ? 1 : 0;
  pipeline.Flush();
  const int64_t published = static_cast<int64_t>(threaded_out.camera.size());
  EXPECT_GE(published, 1);
  EXPECT_EQ(published + pipeline.skipped(), static_cast<int64_t>(inputs.size()));
  EXPECT_EQ(replaced, pipeline.skipped());
  // The last request always wins, and its frame is the frame of those inputs.
  ASSERT_FALSE(threaded_out.camera.empty());
  EXPECT_EQ(threaded_out.camera.back().utime, inputs.back().sample_utime);
  options.threaded = false;
  ImagePipeline reference(world.robot, world.stream.scene_objects(), options, outputs(&inline_out));
  reference.Post(ImagePipeline::Job::kCamera, inputs.back());
  ASSERT_EQ(inline_out.camera.size(), 1u);
  EXPECT_EQ(Bytes(threaded_out.camera.back()), Bytes(inline_out.camera[0]));
}

}  // namespace
}  // namespace orbed::hmd
