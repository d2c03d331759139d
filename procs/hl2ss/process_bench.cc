// orbed-hl2ss as a whole process at the device's rates, measured from outside: this program starts
// it (run it inside a private network namespace: scripts/bench-hl2ss process), plays the headset
// and the sim on the bus, and is the hl2ss client.
//   bus in:  HMD_CAMERA 30 Hz (1280×720 JPEG of the shipped OR at quality 85, as orbed-hmd sends
//            it), HMD_POSE and HMD_POSE_TRUTH 60 Hz (a head walking around the robot), IIWA_STATUS
//            and ROBOT_STATE 200 Hz (as orbed-iiwa-sim; joint 1 turning slowly, so the depth
//            camera's room is posed anew for every frame);
//   clients: the long-throw depth stream (mode 1, 5 Hz) throughout: alone for S seconds, then
//            beside the PV stream at 1280×720 30 Hz, RAW for S seconds, then H.264 main
//            (hl2ss_lnm's default bitrate) for S seconds.
// Prints per phase orbed-hl2ss's CPU share of one core (/proc/PID/stat, all its threads) and per
// stream the latency from capture (the message's utime, recovered from the packet's stamp and RC's
// UTC offset) to the client's receipt of the whole packet, p50 / p99 [ms], and the drops its last
// PROCESS_STATUS counted (rm_depth/busy: a depth frame replaced before the worker started it).
//   hl2ss_process_bench ORBED_HL2SS [S (default 10)]
// A benchmark, not a test: pacing sleeps until each stream's next message.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/process_status_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "base/source_paths.h"
#include "lcmtypes/contract/conversions.h"
#include "render/renderer.h"
#include "render/room_mesh.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace {

using Clock = std::chrono::steady_clock;
constexpr uint64_t kUnixEpochFiletime = 116444736000000000ULL;

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

// CPU seconds (user + system, every thread) of a process so far.
double ProcessCpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t close = text.rfind(')');  // the name may hold spaces
  if (close == std::string::npos) return NAN;
  std::istringstream fields(text.substr(close + 2));
  std::string f;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> f; ++i) {  // fields 14 and 15: utime, stime [clock ticks]
    if (i == 14) utime = std::stoull(f);
    if (i == 15) stime = std::stoull(f);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

class Socket {
 public:
  explicit Socket(int port) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    timeval tv{5, 0};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(port));
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    const Clock::time_point give_up = Clock::now() + std::chrono::seconds(20);
    while (connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0 && Clock::now() < give_up) {
      close(fd_);  // the server is starting: a fresh socket for the next try
      fd_ = socket(AF_INET, SOCK_STREAM, 0);
      setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  ~Socket() { close(fd_); }
  void Send(const std::vector<uint8_t>& b) { (void)!send(fd_, b.data(), b.size(), MSG_NOSIGNAL); }
  bool Read(uint8_t* out, size_t n) {
    for (size_t got = 0; got < n;) {
      const ssize_t k = recv(fd_, out + got, n - got, 0);
      if (k <= 0) return false;
      got += static_cast<size_t>(k);
    }
    return true;
  }

 private:
  int fd_{-1};
};

template <class T>
T Le(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

// One packet's stamp; false when the server closed or went quiet.
bool ReadPacket(Socket* s, bool mode1, std::vector<uint8_t>* buffer, uint64_t* stamp) {
  uint8_t header[12];
  if (!s->Read(header, 12)) return false;
  *stamp = Le<uint64_t>(header);
  buffer->resize(Le<uint32_t>(header + 8) + (mode1 ? 64 : 0));
  return s->Read(buffer->data(), buffer->size());
}

std::vector<uint8_t> PvConfig(uint8_t profile, uint32_t bitrate) {  // '<BHHBBBBI' + '<B' (no options)
  std::vector<uint8_t> b = {0x01, 1280 & 0xFF, 1280 >> 8, 720 & 0xFF, 720 >> 8, 30, 1, profile, 0xFF};
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<uint8_t>(bitrate >> (8 * i)));
  b.push_back(0);
  return b;
}

std::vector<uint8_t> MrcStart() {  // 0x04|3, then '<BBBBBBBfffII' as hl2ss_lnm.start_subsystem_pv's defaults
  std::vector<uint8_t> b = {0x07, 0, 1, 0, 0, 0, 0, 0};
  const float f[3] = {0.9f, 0.0f, 0.0f};
  const uint32_t u[2] = {0, 1};
  b.insert(b.end(), reinterpret_cast<const uint8_t*>(f), reinterpret_cast<const uint8_t*>(f) + 12);
  b.insert(b.end(), reinterpret_cast<const uint8_t*>(u), reinterpret_cast<const uint8_t*>(u) + 8);
  return b;
}

struct Latencies {
  std::mutex mutex;
  std::vector<double> ms[3];  // per phase
  int phase{0};
  void Add(double v) {
    std::lock_guard<std::mutex> lock(mutex);
    ms[phase].push_back(v);
  }
};

}  // namespace

int main(int argc, char** argv) {
  using namespace orbed;
  if (argc < 2) {
    std::fprintf(stderr, "usage: hl2ss_process_bench ORBED_HL2SS [seconds per phase]\n");
    return 2;
  }
  const double seconds = argc > 2 ? std::atof(argv[2]) : 10.0;

  // The headset's pictures: the shipped OR from a head walking around the robot.
  const std::optional<sim::Scene> scene = sim::LoadSceneFlag("");
  const sim::RobotModel robot =
      sim::LoadRobotForScene(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath), *scene);
  render::SceneGeometry objects;
  objects.AddSceneObjects(*scene);
  render::RoomMesh room(robot, objects);
  room.PoseRobot(Eigen::VectorXd::Zero(robot.num_joints()), scene->X_WR);
  const Eigen::Vector3d target = scene->X_WR * Eigen::Vector3d(0, 0, 0.5);
  const auto head_at = [&](double t_s) {
    const double a = 0.3 * t_s;
    return geometry::LookAt(target + Eigen::Vector3d(-1.6 * std::cos(a), -1.6 * std::sin(a), 0.8), target);
  };
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  render::Renderer renderer(K);
  std::vector<std::vector<uint8_t>> jpegs(30);
  for (int i = 0; i < 30; ++i) {
    cv::Mat bgr;
    renderer.Render(room.mesh(), head_at(i / 30.0), &bgr);
    render::EncodeJpeg(bgr, 85, &jpegs[i]);
  }

  const pid_t server = fork();
  if (server == 0) {
    execl(argv[1], argv[1], "--max-queue-mb", "64", static_cast<char*>(nullptr));
    std::perror("hl2ss_process_bench: exec");
    _exit(127);
  }

  std::atomic<bool> stop{false};
  std::mutex status_mutex;
  orbed::process_status_t last_status{};
  struct OnStatus {
    std::mutex* mutex;
    orbed::process_status_t* last;
    void Handle(const lcm::ReceiveBuffer*, const std::string&, const orbed::process_status_t* m) {
      if (m->name != "orbed-hl2ss") return;
      std::lock_guard<std::mutex> lock(*mutex);
      *last = *m;
    }
  } on_status{&status_mutex, &last_status};
  std::thread bus([&] {
    lcm::LCM lcm;
    lcm.subscribe("PROCESS_STATUS", &OnStatus::Handle, &on_status);
    const Clock::time_point t0 = Clock::now();
    int64_t n_robot = 0, n_pose = 0, n_camera = 0;
    while (!stop) {
      const auto at = [&](int64_t n, double hz) {
        return t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(n / hz));
      };
      const Clock::time_point next = std::min({at(n_robot, 200), at(n_pose, 60), at(n_camera, 30)});
      while (Clock::now() < next) lcm.handleTimeout(1);  // the heartbeats while waiting
      const double t_s = std::chrono::duration<double>(Clock::now() - t0).count();
      const int64_t utime = NowMicros();
      if (next == at(n_robot, 200)) {
        ++n_robot;
        Eigen::VectorXd q = Eigen::VectorXd::Zero(robot.num_joints());
        q(0) = 0.3 * std::sin(0.5 * t_s);
        orbed::iiwa_status_t status{};
        status.utime = utime;
        status.num_joints = robot.num_joints();
        for (auto* v :
             {&status.joint_position_measured, &status.joint_velocity_estimated,
              &status.joint_position_commanded, &status.joint_position_ipo, &status.joint_torque_measured,
              &status.joint_torque_commanded, &status.joint_torque_external})
          v->assign(robot.num_joints(), 0.0);
        for (int j = 0; j < robot.num_joints(); ++j) status.joint_position_measured[j] = q(j);
        lcm.publish("IIWA_STATUS", &status);
        orbed::robot_state_t state{};
        state.utime = utime;
        state.robot_name = "iiwa";
        state.X_WR = ToPose(scene->X_WR);
        state.X_RF = state.X_RT = ToPose(Eigen::Isometry3d::Identity());
        lcm.publish("ROBOT_STATE", &state);
      } else if (next == at(n_pose, 60)) {
        ++n_pose;
        orbed::hmd_pose_t pose{};
        pose.utime = utime;
        pose.seq = n_pose;
        pose.hmd_name = "hmd";
        pose.tracking_state = orbed::hmd_pose_t::TRACKING;
        pose.X_WH = pose.X_WC = ToPose(head_at(t_s));
        lcm.publish("HMD_POSE_TRUTH", &pose);
        lcm.publish("HMD_POSE", &pose);
      } else {
        const orbed::image_t img =
            JpegImageMessage(jpegs[n_camera % jpegs.size()], K, utime, head_at(t_s), utime);
        ++n_camera;
        lcm.publish("HMD_CAMERA", &img);
      }
    }
  });

  uint64_t offset = 0;
  {
    Socket rc(3809);
    uint8_t answer[8];
    rc.Send({0x01});
    if (!rc.Read(answer, 8)) {
      std::fprintf(stderr, "hl2ss_process_bench: no answer from orbed-hl2ss's RC port\n");
      stop = true;
      bus.join();
      kill(server, SIGKILL);
      waitpid(server, nullptr, 0);
      return 1;
    }
    offset = Le<uint64_t>(answer);
    Socket start(3810);
    start.Send(MrcStart());
    start.Read(answer, 1);  // closed once the subsystem is open
  }
  const auto latency_ms = [offset](uint64_t stamp) {
    const int64_t capture_us = static_cast<int64_t>((stamp + offset - kUnixEpochFiletime) / 10);
    return (NowMicros() - capture_us) / 1000.0;
  };

  Latencies depth_latency, pv_latency;
  std::atomic<int> depth_frames{0};
  std::thread depth([&] {
    Socket s(3805);
    s.Send({0x01, 0x01, 0x00, 0x00, 0x00, 0x00});  // mode 1, divisor 1, PNG filter 0
    std::vector<uint8_t> buffer;
    uint64_t stamp = 0;
    while (!stop && ReadPacket(&s, true, &buffer, &stamp)) {
      depth_latency.Add(latency_ms(stamp));
      ++depth_frames;
    }
  });

  const char* names[3] = {"depth alone", "PV RAW NV12 1280x720 30 Hz", "PV H.264 main 1280x720 30 Hz"};
  double cpu_share[3] = {NAN, NAN, NAN}, wall[3] = {0, 0, 0};
  bool served[3] = {true, false, false};
  for (int phase = 0; phase < 3; ++phase) {
    {
      std::lock_guard<std::mutex> a(depth_latency.mutex), b(pv_latency.mutex);
      depth_latency.phase = pv_latency.phase = phase;
    }
    if (phase == 0) {
      const Clock::time_point t0 = Clock::now();
      const double cpu0 = ProcessCpuSeconds(server);
      std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
      wall[0] = std::chrono::duration<double>(Clock::now() - t0).count();
      cpu_share[0] = 100.0 * (ProcessCpuSeconds(server) - cpu0) / wall[0];
      continue;
    }
    Socket pv(3810);
    pv.Send(phase == 1 ? PvConfig(0xFF, 1280 * 720 * 30 * 12) : PvConfig(1, 1280 * 720 * 30 * 12 / 75));
    std::vector<uint8_t> buffer;
    uint64_t stamp = 0;
    // The first packet starts the phase's clock (the encoder opened, the queues filled).
    served[phase] = ReadPacket(&pv, true, &buffer, &stamp);
    if (!served[phase]) continue;
    const Clock::time_point t0 = Clock::now();
    const double cpu0 = ProcessCpuSeconds(server);
    while (Clock::now() - t0 < std::chrono::duration<double>(seconds)) {
      if (!ReadPacket(&pv, true, &buffer, &stamp)) break;
      pv_latency.Add(latency_ms(stamp));
    }
    wall[phase] = std::chrono::duration<double>(Clock::now() - t0).count();
    cpu_share[phase] = 100.0 * (ProcessCpuSeconds(server) - cpu0) / wall[phase];
  }
  stop = true;
  kill(server, SIGINT);
  depth.join();  // its socket closes with the server
  bus.join();
  waitpid(server, nullptr, 0);

  std::printf("hl2ss_process_bench: orbed-hl2ss at the device's rates, %.0f s per phase\n", seconds);
  std::printf("%-30s %-30s %7s %9s %9s %9s\n", "phase", "stream", "packets", "p50 [ms]", "p99 [ms]",
              "CPU [%]");
  for (int phase = 0; phase < 3; ++phase) {
    if (!served[phase]) {
      std::printf("%-30s refused by this orbed-hl2ss\n", names[phase]);
      continue;
    }
    if (phase > 0)
      std::printf("%-30s %-30s %7zu %9.1f %9.1f\n", names[phase], "PV", pv_latency.ms[phase].size(),
                  Percentile(pv_latency.ms[phase], 0.5), Percentile(pv_latency.ms[phase], 0.99));
    std::printf("%-30s %-30s %7zu %9.1f %9.1f %9.1f\n", phase > 0 ? "" : names[phase],
                "depth 320x288 5 Hz (mode 1)", depth_latency.ms[phase].size(),
                Percentile(depth_latency.ms[phase], 0.5), Percentile(depth_latency.ms[phase], 0.99),
                cpu_share[phase]);
  }
  std::lock_guard<std::mutex> lock(status_mutex);
  std::printf("orbed-hl2ss's drops:");
  for (size_t i = 0; i < last_status.drop_reason.size(); ++i)
    std::printf(" %s %lld", last_status.drop_reason[i].c_str(),
                static_cast<long long>(last_status.drop_count[i]));
  std::printf("%s\n", last_status.drop_reason.empty() ? " none" : "");
  return 0;
}
