// Per-frame cost of the emulated HoloLens 2's pictures at their real rates, in one process:
// PV 1280×720 at 30 Hz both raw (NV12) and H.264 main (hl2ss_lnm's default bitrate), and the
// long-throw depth camera at 5 Hz (render + PNG). Prints p50 / p99 per stream [ms] and the
// process's CPU share of one core over the run. Pictures are rendered beforehand (the headset
// renders them anyway); only the depth camera renders here, as the server will.
//   hl2ss_pictures_bench [seconds (default 10)] [encoder threads (default 1)] [h265]
// With "h265" the H.264 stream is replaced by the client's default: H.265 main at 1920×1080 30 Hz
// (bitrate 1920·1080·30·12/150), from the same 1280×720 pictures resized.
// Pacing sleeps until each stream's next frame time: a benchmark at the device's rates, not a test.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "base/source_paths.h"
#include "procs/hl2ss/pv_encoder.h"
#include "procs/hl2ss/rm_depth.h"
#include "render/renderer.h"
#include "render/room_mesh.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

double CpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

struct Stream {
  Stream(std::string n, double p) : name(std::move(n)), period_s(p) {}
  std::string name;
  double period_s;
  double next_s{0};
  std::vector<double> ms;  // per-frame times
  size_t bytes{0};
};

}  // namespace

int main(int argc, char** argv) {
  using namespace orbed;
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  const int threads = argc > 2 ? std::atoi(argv[2]) : 1;
  const bool hevc = argc > 3 && std::string(argv[3]) == "h265";

  const std::optional<sim::Scene> scene = sim::LoadSceneFlag("");
  const sim::RobotModel robot =
      sim::LoadRobotForScene(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath), *scene);
  render::SceneGeometry objects;
  objects.AddSceneObjects(*scene);
  render::RoomMesh room(robot, objects);
  room.PoseRobot(Eigen::VectorXd::Zero(robot.num_joints()), scene->X_WR);

  // A head walking slowly around the robot, looking at it.
  const Eigen::Vector3d target = scene->X_WR * Eigen::Vector3d(0, 0, 0.6);
  const auto head_at = [&](int i) {
    const double a = 0.01 * i;
    return geometry::LookAt(target + Eigen::Vector3d(-1.8 * std::cos(a), -1.8 * std::sin(a), 0.9), target);
  };
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  render::Renderer renderer(K);
  std::vector<cv::Mat> pictures(30);
  for (int i = 0; i < 30; ++i) renderer.Render(room.mesh(), head_at(i), &pictures[i]);

  std::string error;
  hl2ss::PvEncoderConfig raw_config;
  raw_config.format = {1280, 720, 30};
  raw_config.profile = hl2ss::VideoProfile::kRaw;
  hl2ss::PvEncoderConfig h264_config = raw_config;
  h264_config.profile = hl2ss::VideoProfile::kH264Main;
  h264_config.bitrate_bps = 1280 * 720 * 30 * 12 / 75;
  h264_config.gop_frames = 30;
  h264_config.threads = threads;
  if (hevc) {
    h264_config.format = {1920, 1080, 30};
    h264_config.profile = hl2ss::VideoProfile::kH265Main;
    h264_config.bitrate_bps = 1920 * 1080 * 30 * 12 / 150;
  }
  auto raw = hl2ss::PvEncoder::Create(raw_config, &error);
  auto h264 = hl2ss::PvEncoder::Create(h264_config, &error);
  if (!raw || !h264) {
    std::fprintf(stderr, "hl2ss_pictures_bench: %s\n", error.c_str());
    return 1;
  }
  hl2ss::LongThrowCamera depth_camera;
  hl2ss::LongThrowFrame depth_frame;

  std::vector<Stream> streams = {
      {"PV raw NV12 1280x720 30 Hz", 1.0 / 30},
      {hevc ? "PV H.265 main 1920x1080 30 Hz" : "PV H.264 main 1280x720 30 Hz", 1.0 / 30},
      {"depth render 320x288 5 Hz", 1.0 / hl2ss::kLongThrowHz},
      {"depth PNG 5 Hz", 1.0 / hl2ss::kLongThrowHz}};
  std::vector<std::uint8_t> payload;
  const Clock::time_point t0 = Clock::now();
  const double cpu0 = CpuSeconds();
  int frame = 0, depth_index = 0;
  const auto since = [&](Clock::time_point a) {
    return std::chrono::duration<double, std::milli>(Clock::now() - a).count();
  };
  for (;;) {
    const double now_s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (now_s >= seconds) break;
    if (now_s >= streams[0].next_s) {  // both PV streams take the same picture
      const cv::Mat& picture = pictures[frame++ % pictures.size()];
      for (int s = 0; s < 2; ++s) {
        const Clock::time_point a = Clock::now();
        if (!(s == 0 ? raw : h264)->Encode(picture, K, {}, &payload, &error)) {
          std::fprintf(stderr, "hl2ss_pictures_bench: %s\n", error.c_str());
          return 1;
        }
        streams[s].ms.push_back(since(a));
        streams[s].bytes += payload.size();
        streams[s].next_s += streams[s].period_s;
      }
    }
    if (now_s >= streams[2].next_s) {
      Clock::time_point a = Clock::now();
      depth_camera.Render(room.mesh(), head_at(depth_index++), &depth_frame);
      streams[2].ms.push_back(since(a));
      a = Clock::now();
      if (!hl2ss::EncodeLongThrowPayload(depth_frame, 0, &payload, &error)) {
        std::fprintf(stderr, "hl2ss_pictures_bench: %s\n", error.c_str());
        return 1;
      }
      streams[3].ms.push_back(since(a));
      streams[3].bytes += payload.size();
      streams[2].next_s += streams[2].period_s;
    }
    const double next_s = std::min(streams[0].next_s, streams[2].next_s);
    std::this_thread::sleep_until(
        t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(next_s)));
  }
  const double wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  const double cpu_s = CpuSeconds() - cpu0;
  std::printf("hl2ss_pictures_bench: %.1f s, encoder threads %d\n", wall_s, threads);
  std::printf("%-32s %7s %9s %9s %12s\n", "stream", "frames", "p50 [ms]", "p99 [ms]", "kB/frame");
  for (const Stream& s : streams) {
    std::printf("%-32s %7zu %9.2f %9.2f %12.1f\n", s.name.c_str(), s.ms.size(), Percentile(s.ms, 0.5),
                Percentile(s.ms, 0.99), s.bytes ? s.bytes / 1024.0 / s.ms.size() : 0.0);
  }
  std::printf("CPU: %.1f %% of one core (all four streams together)\n", 100.0 * cpu_s / wall_s);
  return 0;
}
