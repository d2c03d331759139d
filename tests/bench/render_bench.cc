/// @file
/// The HMD camera and displays per frame, one thread (goals: render + JPEG of a
/// 1280×720 frame <= 10 ms; reflective compositing <= 5 ms):
///   BM_RenderFrame           FK of the real robot + tessellation + z-buffered render of the shipped
///                            OR scene (HoloLens PV intrinsics) into BGR
///   BM_JpegEncode            cv::imencode of that frame alone (quality 85)
///   BM_RenderAndJpeg         the two together: what the camera does for every HMD_CAMERA frame
///   BM_ReflectiveCompose     copy the captured frame + draw the virtual robot as a hologram with the
///                            capture-time estimate + the display geometry (REFLECTIVE_VIEW content)
///   BM_GazeRay               one analytic gaze ray against the scene and the real robot
/// Robot configurations come from a seeded pool, camera poses from a walk around the bed.
/// Counters: `triangles` rasterised per frame, `jpeg_kB` per frame.
/// Run: build-*/bench/render_bench (needs $ORBED_SOURCE_DIR or runs from the source root).
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "base/source_paths.h"
#include "hmd_emulator/gaze.h"
#include "hmd_emulator/reflective.h"
#include "render/renderer.h"
#include "render/scene_geometry.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

struct Fixture {
  sim::RobotModel robot =
      sim::RobotModel::LoadFile(orbed::SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
  sim::Scene scene = sim::LoadSceneFile(orbed::SourceTreePath(sim::kDefaultSceneRelativePath));
  std::vector<Eigen::VectorXd> q_pool;
  std::vector<Eigen::Isometry3d> cameras;
  Fixture() {
    robot.SetToolLength(scene.tool_length_m);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-0.6, 0.6);
    for (int n = 0; n < 64; ++n) {
      Eigen::VectorXd q(robot.num_joints());
      for (int i = 0; i < q.size(); ++i) q[i] = u(rng);
      q_pool.push_back(q);
    }
    // Standing 2-2.5 m from the robot, walking half way round the bed, eyes at 1.7 m.
    for (int k = 0; k < 16; ++k) {
      const double a = -2.6 + 2.2 * k / 15.0;
      const Eigen::Vector3d eye(0.25 + 2.3 * std::cos(a), -0.3 + 2.3 * std::sin(a), 1.7);
      cameras.push_back(geometry::LookAt(eye, {0.25, -0.45, 1.1}));
    }
  }
};

Fixture& F() {
  static Fixture f;
  return f;
}

// Renders frame `i` of the walk into `bgr`; returns the triangles rasterised.
int RenderOne(render::SceneGeometry* g, render::Mesh* mesh, render::Renderer* renderer, size_t i,
              cv::Mat* bgr) {
  Fixture& f = F();
  g->PoseRobot(0, f.q_pool[i % f.q_pool.size()], f.scene.X_WR);
  mesh->Clear();
  render::Tessellate(*g, render::kRealWorld, {}, mesh);
  renderer->Render(*mesh, f.cameras[i % f.cameras.size()], bgr);
  return renderer->last_triangle_count();
}

void BM_RenderFrame(benchmark::State& state) {
  Fixture& f = F();
  render::SceneGeometry g =
      render::SceneGeometry::MakeOperatingRoom(f.scene, f.robot, f.q_pool[0], f.scene.X_WR);
  render::Mesh mesh;
  render::Renderer renderer(geometry::Intrinsics::HoloLensPv());
  cv::Mat bgr;
  size_t i = 0;
  double triangles = 0;
  for (auto _ : state) {
    triangles += RenderOne(&g, &mesh, &renderer, i++, &bgr);
    benchmark::DoNotOptimize(bgr.data);
  }
  state.counters["triangles"] = triangles / static_cast<double>(i);
}
BENCHMARK(BM_RenderFrame)->Unit(benchmark::kMillisecond);

void BM_JpegEncode(benchmark::State& state) {
  Fixture& f = F();
  render::SceneGeometry g =
      render::SceneGeometry::MakeOperatingRoom(f.scene, f.robot, f.q_pool[0], f.scene.X_WR);
  render::Mesh mesh;
  render::Renderer renderer(geometry::Intrinsics::HoloLensPv());
  cv::Mat bgr;
  RenderOne(&g, &mesh, &renderer, 3, &bgr);
  std::vector<std::uint8_t> jpeg;
  for (auto _ : state) {
    render::EncodeJpeg(bgr, 85, &jpeg);
    benchmark::DoNotOptimize(jpeg.data());
  }
  state.counters["jpeg_kB"] = jpeg.size() / 1000.0;
}
BENCHMARK(BM_JpegEncode)->Unit(benchmark::kMillisecond);

void BM_RenderAndJpeg(benchmark::State& state) {
  Fixture& f = F();
  render::SceneGeometry g =
      render::SceneGeometry::MakeOperatingRoom(f.scene, f.robot, f.q_pool[0], f.scene.X_WR);
  render::Mesh mesh;
  render::Renderer renderer(geometry::Intrinsics::HoloLensPv());
  cv::Mat bgr;
  std::vector<std::uint8_t> jpeg;
  size_t i = 0;
  double bytes = 0;
  for (auto _ : state) {
    RenderOne(&g, &mesh, &renderer, i++, &bgr);
    render::EncodeJpeg(bgr, 85, &jpeg);
    bytes += jpeg.size();
    benchmark::DoNotOptimize(jpeg.data());
  }
  state.counters["jpeg_kB"] = bytes / 1000.0 / static_cast<double>(i);
}
BENCHMARK(BM_RenderAndJpeg)->Unit(benchmark::kMillisecond);

void BM_ReflectiveCompose(benchmark::State& state) {
  Fixture& f = F();
  render::SceneGeometry g =
      render::SceneGeometry::MakeOperatingRoom(f.scene, f.robot, f.q_pool[0], f.scene.X_WR);
  render::Mesh mesh;
  render::Renderer renderer(geometry::Intrinsics::HoloLensPv());
  // A few captured frames, each with a slightly wrong capture-pose estimate.
  std::vector<CapturedFrame> frames;
  for (size_t k = 0; k < 8; ++k) {
    CapturedFrame fr;
    RenderOne(&g, &mesh, &renderer, 2 * k, &fr.bgr);
    fr.intrinsics = geometry::Intrinsics::HoloLensPv();
    fr.X_WC_est = f.cameras[(2 * k) % f.cameras.size()] *
                  Eigen::Isometry3d(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()));
    fr.q_rad = f.q_pool[(2 * k) % f.q_pool.size()];
    frames.push_back(fr);
  }
  Eigen::Isometry3d X_WV = f.scene.X_WR;
  X_WV.translation() += Eigen::Vector3d(0.02, -0.01, 0.015);
  Compositor compositor(f.robot);
  ReflectiveView view;
  size_t i = 0;
  for (auto _ : state) {
    compositor.ComposeReflective(frames[i++ % frames.size()], 1.6, X_WV, &view);
    benchmark::DoNotOptimize(view.bgr.data);
  }
}
BENCHMARK(BM_ReflectiveCompose)->Unit(benchmark::kMillisecond);

void BM_GazeRay(benchmark::State& state) {
  Fixture& f = F();
  render::SceneGeometry g =
      render::SceneGeometry::MakeOperatingRoom(f.scene, f.robot, f.q_pool[0], f.scene.X_WR);
  size_t i = 0;
  for (auto _ : state) {
    const Eigen::Isometry3d& X_WC = f.cameras[i++ % f.cameras.size()];
    benchmark::DoNotOptimize(CastRay(g, X_WC.translation(), X_WC.linear().col(2)));
  }
}
BENCHMARK(BM_GazeRay)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace orbed::hmd

BENCHMARK_MAIN();
