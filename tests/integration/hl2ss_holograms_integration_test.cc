// A hologram placed by an hl2ss client shows in the headset's AR view and over its reflective
// display's frame: the real orbed-hl2ss and the real orbed-hmd (one display) over real LCM and real
// TCP in a private network namespace (ctest wraps this binary in scripts/netns-exec), with no robot
// on the bus (AR_VIEW then holds the camera frame and the client's holograms only, the display its
// frozen frame and the holograms).
//
// The client is the test's own, written from hl2ss_rus.py's layouts on the Unity message queue
// (3816): commands back to back, each `id (u32) | size (u32) | data`, little-endian, one u32 answer
// each. The headset walks slowly (a walk of the test's own, 3 cm/s, so that the sphere stays in
// view) and its SLAM estimate jitters, so no two frames are alike: every AR_VIEW is compared with
// the HMD_CAMERA of the same utime, the frame it was composed on.
//   1. before anything is placed, an AR_VIEW decodes to its HMD_CAMERA frame (no pixel differs by
//      more than the threshold);
//   2. the client creates a sphere (diameter 0.1 m), sets its world transform to the Unity position
//      of p_W = X_WC · (0, 0, 1 m) of that AR_VIEW's X_WC (Unity (x, y, z) = W (x, z, y),
//      procs/hl2ss/frames.h), colours it red and shows it; answers: its key, then 1, 1, 1;
//   3. from the first AR_VIEW that differs from its camera frame on, three AR_VIEWs in a row: the
//      centroid of the differing pixels is within kMaxCentroidErrorPx of where the AR_VIEW's own
//      camera model (its intrinsics and X_WC) projects the sphere's centre, their number within
//      [0.85, 1.1] of the silhouette's area π (f r / z)², and the pixel there is red; likewise in
//      the first REFLECTIVE_VIEW that differs from the one before placement (the same frame, captured
//      at the walk's first waypoint), with that frame's camera model;
//   4. the client removes it (command 16; answer 1): from the first AR_VIEW with no differing pixel
//      on, three in a row equal their camera frames byte for byte (the same encoder on the same
//      pixels), and REFLECTIVE_VIEW is the one before placement again, byte for byte;
//   5. neither process refused anything (PROCESS_STATUS).
// Time: about 1.3 s (of it up to 1 s for both heartbeats after the removal). Measured: centroids
// 0.25-0.4 px from the projection, 97 % of the disk differing.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <orbed/image_t.hpp>
#include <orbed/reflective_view_t.hpp>

#include "lcmtypes/contract/conversions.h"
#include "runtime/flags.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

constexpr double kSphereDiameterM = 0.1;
constexpr double kAheadM = 1.0;              // the sphere's centre on the camera's axis at placement
constexpr double kMaxCentroidErrorPx = 1.5;  // rasterisation, JPEG, the off-axis silhouette
constexpr int kDiffThreshold = 40;           // a pixel differs: > 40 in some BGR channel

// ---- the message-queue client: a blocking socket with a generous receive timeout ---------------
class UmqClient {
 public:
  UmqClient() {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    timeval tv{static_cast<time_t>(20 * TestTimeFactor()), 0};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(3816);
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    connected_ = WaitFor([&] { return connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0; }, 20);
  }
  ~UmqClient() { close(fd_); }
  bool connected() const { return connected_; }

  // Appends one command: id, size, then the data (u32 words, then f32s).
  void Add(uint32_t id, const std::vector<uint32_t>& words, const std::vector<float>& floats = {}) {
    U32(id);
    U32(static_cast<uint32_t>(4 * (words.size() + floats.size())));
    for (uint32_t w : words) U32(w);
    for (float f : floats) {
      uint32_t w;
      std::memcpy(&w, &f, 4);
      U32(w);
    }
    ++pending_;
  }
  // Sends the commands added so far; returns their answers (fewer if the server closed or was late).
  std::vector<uint32_t> Send() {
    std::vector<uint32_t> answers;
    if (send(fd_, buffer_.data(), buffer_.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(buffer_.size())) {
      return answers;
    }
    std::vector<uint8_t> in(4 * pending_);
    size_t got = 0;
    while (got < in.size()) {
      const ssize_t k = recv(fd_, in.data() + got, in.size() - got, 0);
      if (k <= 0) break;
      got += static_cast<size_t>(k);
    }
    for (size_t i = 0; i + 4 <= got; i += 4) {
      answers.push_back(uint32_t{in[i]} | uint32_t{in[i + 1]} << 8 | uint32_t{in[i + 2]} << 16 |
                        uint32_t{in[i + 3]} << 24);
    }
    buffer_.clear();
    pending_ = 0;
    return answers;
  }

 private:
  void U32(uint32_t v) {
    for (int i = 0; i < 4; ++i) buffer_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  int fd_{-1};
  bool connected_{false};
  std::vector<uint8_t> buffer_;
  size_t pending_{0};
};

// ---- the headset's pictures: AR_VIEW paired with the HMD_CAMERA of the same utime ---------------
struct Pair {
  orbed::image_t ar;
  orbed::image_t camera;
};

// Handles LCM on its own thread (a raised receive buffer: the JPEGs are ~100 kB); keeps the last
// second of HMD_CAMERA by utime and queues each AR_VIEW with its camera frame.
class Pictures {
 public:
  Pictures() : lcm_(WithRecvBufSize(DefaultLcmUrl(), 8 << 20)) {
    if (!lcm_.good()) throw std::runtime_error("LCM not available");
    lcm_.subscribe("HMD_CAMERA", &Pictures::OnCamera, this);
    lcm_.subscribe("AR_VIEW", &Pictures::OnArView, this);
    lcm_.subscribe("REFLECTIVE_VIEW", &Pictures::OnReflective, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(20);
    });
  }
  ~Pictures() {
    stop_ = true;
    thread_.join();
  }
  // The next pair that arrived after the last one returned (waits up to `timeout_s`).
  std::optional<Pair> Next(double timeout_s) {
    std::optional<Pair> out;
    WaitFor(
        [&] {
          std::lock_guard<std::mutex> lock(mutex_);
          if (pairs_.empty()) return false;
          out = std::move(pairs_.front());
          pairs_.pop_front();
          return true;
        },
        timeout_s);
    return out;
  }
  // Forgets the pairs not yet returned.
  void Clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    pairs_.clear();
  }
  // The picture of the latest REFLECTIVE_VIEW of display 0, if one came.
  std::optional<orbed::image_t> reflective() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return reflective_;
  }
  int unpaired() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return unpaired_;
  }

 private:
  void OnCamera(const lcm::ReceiveBuffer*, const std::string&, const orbed::image_t* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    cameras_[m->utime] = *m;
    while (cameras_.size() > 30) cameras_.erase(cameras_.begin());
  }
  void OnArView(const lcm::ReceiveBuffer*, const std::string&, const orbed::image_t* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = cameras_.find(m->utime);
    if (it == cameras_.end()) {  // its HMD_CAMERA was lost on the way
      ++unpaired_;
      return;
    }
    if (pairs_.size() < 30) pairs_.push_back({*m, it->second});
  }

  void OnReflective(const lcm::ReceiveBuffer*, const std::string&, const orbed::reflective_view_t* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (m->display_id == 0) reflective_ = m->image;
  }

  lcm::LCM lcm_;
  mutable std::mutex mutex_;
  std::optional<orbed::image_t> reflective_;
  std::map<int64_t, orbed::image_t> cameras_;
  std::deque<Pair> pairs_;
  int unpaired_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

cv::Mat Decode(const std::vector<uint8_t>& jpeg) { return cv::imdecode(jpeg, cv::IMREAD_COLOR); }

// Where a picture with holograms and the same picture without (an AR_VIEW and its camera frame) differ by
// more than kDiffThreshold in some channel.
struct Difference {
  int pixels{0};
  Eigen::Vector2d centroid_px{Eigen::Vector2d::Zero()};
};

Difference Differ(const orbed::image_t& drawn, const orbed::image_t& base) {
  const cv::Mat a = Decode(drawn.data), b = Decode(base.data);
  EXPECT_FALSE(a.empty() || b.empty());
  if (a.empty() || b.empty() || a.size() != b.size()) return {};
  cv::Mat diff, channels[3];
  cv::absdiff(a, b, diff);
  cv::split(diff, channels);
  const cv::Mat mask = cv::max(channels[0], cv::max(channels[1], channels[2])) > kDiffThreshold;
  const cv::Moments m = cv::moments(mask, true);
  Difference d;
  d.pixels = cv::countNonZero(mask);
  if (d.pixels > 0) d.centroid_px = Eigen::Vector2d(m.m10 / m.m00, m.m01 / m.m00);
  return d;
}

// p_W in the AR view's camera: p_C = X_WC⁻¹ p_W.
Eigen::Vector3d InCamera(const orbed::image_t& view, const Eigen::Vector3d& p_W) {
  return FromPose(view.X_WC).inverse() * p_W;
}

// (u, v) = (fx x/z + cx, fy y/z + cy), the image_t's pinhole model.
Eigen::Vector2d Project(const orbed::image_t& view, const Eigen::Vector3d& p_C) {
  return {view.fx_px * p_C.x() / p_C.z() + view.cx_px, view.fy_px * p_C.y() / p_C.z() + view.cy_px};
}

// The inputs `name` had refused by its last heartbeat, if that came after `since`; else -1.
// The sphere of diameter kSphereDiameterM at p_W drawn in `view`, where `diff` says it differs from the
// picture without it: the centroid at the projection of its centre, the area of its silhouette, red.
void ExpectSphereAt(const orbed::image_t& view, const Difference& diff, const Eigen::Vector3d& p_W,
                    const std::string& label) {
  const Eigen::Vector3d p_C = InCamera(view, p_W);
  const Eigen::Vector2d uv = Project(view, p_C);
  const double radius_px = view.fx_px * kSphereDiameterM / 2 / p_C.z();
  const double area_px = M_PI * radius_px * radius_px;
  ASSERT_GT(uv.x() - radius_px, 0) << label;  // the sphere wholly in view
  ASSERT_LT(uv.x() + radius_px, view.width) << label;
  ASSERT_GT(uv.y() - radius_px, 0) << label;
  ASSERT_LT(uv.y() + radius_px, view.height) << label;
  std::printf("%s: %d pixels differ (disk %.0f), centroid (%.2f, %.2f), projected (%.2f, %.2f)\n",
              label.c_str(), diff.pixels, area_px, diff.centroid_px.x(), diff.centroid_px.y(), uv.x(),
              uv.y());
  EXPECT_GT(diff.pixels, 0.85 * area_px) << label;
  EXPECT_LT(diff.pixels, 1.1 * area_px) << label;
  EXPECT_LT((diff.centroid_px - uv).norm(), kMaxCentroidErrorPx)
      << label << " drawn at " << diff.centroid_px.transpose() << ", projected " << uv.transpose();
  const cv::Mat bgr = Decode(view.data);
  const cv::Vec3b at =
      bgr.at<cv::Vec3b>(static_cast<int>(std::lround(uv.y())), static_cast<int>(std::lround(uv.x())));
  EXPECT_GT(int{at[2]} - int{at[1]}, 60) << label << ": red over the room, BGR " << at;
}

int64_t Rejected(const BusWatcher& bus, const std::string& name,
                 std::chrono::steady_clock::time_point since) {
  const auto beats = bus.Heartbeats(name);
  return beats.empty() || beats.back().received < since ? -1 : beats.back().status.rejected_inputs;
}

TEST(Hl2ssHolograms, ASpherePlacedThroughTheMessageQueueShowsInArViewAndOnTheDisplayAtItsPixel) {
  // The walk: 3 cm/s past the foot end (the shipped walk's names, which config/hmd.yaml's displays
  // and alignment use), looking at the robot's middle; AR_VIEW at 10 Hz.
  const std::string config = MakeTempDir("hl2ss_holograms") + "/slow_walk.yaml";
  std::ofstream(config) << "head_trajectory:\n"
                           "  speed_m_per_s: 0.03\n"
                           "  look_at_m: [0.25, -0.45, 1.25]\n"
                           "  waypoints:\n"
                           "    - {name: foot_end, position_m: [1.45, -1.20, 1.70]}\n"
                           "    - {name: head_end, position_m: [1.15, -1.30, 1.70], dwell_s: 60.0}\n"
                           "hmd:\n"
                           "  ar_view_hz: 10\n";
  BusWatcher bus;
  bus.Start();
  Pictures pictures;
  RunningProcess hl2ss({BinPath("orbed-hl2ss"), "--name", "hl2ss"});
  RunningProcess hmd({BinPath("orbed-hmd"), "--name", "hmd", "--displays", "1", "--config", config});
  const auto next = [&] {
    hl2ss.running();  // drain their output
    hmd.running();
    return pictures.Next(20);
  };

  // 1. Nothing placed: an AR_VIEW is its camera frame.
  const std::optional<Pair> before = next();
  ASSERT_TRUE(before) << "no AR_VIEW with its HMD_CAMERA within 20 s";
  EXPECT_EQ(Differ(before->ar, before->camera).pixels, 0);
  // The reflective display's frame, frozen since it captured it at the walk's first waypoint.
  std::optional<orbed::image_t> mirror_before;
  ASSERT_TRUE(WaitFor([&] { return (mirror_before = pictures.reflective()).has_value(); }, 20))
      << "no REFLECTIVE_VIEW within 20 s";

  // 2. A red sphere a metre ahead of that AR_VIEW's camera.
  const Eigen::Vector3d p_W = FromPose(before->ar.X_WC) * Eigen::Vector3d(0, 0, kAheadM);
  const Eigen::Vector3f p_U = Eigen::Vector3d(p_W.x(), p_W.z(), p_W.y()).cast<float>();
  const float d = static_cast<float>(kSphereDiameterM);
  UmqClient client;
  ASSERT_TRUE(client.connected());
  client.Add(0, {0});  // create primitive: sphere
  std::vector<uint32_t> answers = client.Send();
  ASSERT_EQ(answers.size(), 1u);
  const uint32_t key = answers[0];
  EXPECT_NE(key, 0u);
  client.Add(2, {key}, {p_U.x(), p_U.y(), p_U.z(), 0, 0, 0, 1, d, d, d});  // world transform
  client.Add(4, {key}, {1, 0, 0, 1});                                      // colour: red
  client.Add(1, {key, 1});                                                 // shown
  answers = client.Send();
  EXPECT_EQ(answers, (std::vector<uint32_t>{1, 1, 1}));

  // 3. From the first AR_VIEW that shows it, three in a row at the projected pixel.
  pictures.Clear();
  std::optional<Pair> pair;
  Difference diff;
  ASSERT_TRUE(WaitFor(
      [&] {
        pair = next();
        diff = pair ? Differ(pair->ar, pair->camera) : Difference{};
        return diff.pixels > 0;
      },
      20))
      << "the sphere never showed in AR_VIEW";
  for (int i = 0; i < 3; ++i) {
    if (i > 0) {
      pair = next();
      ASSERT_TRUE(pair);
      diff = Differ(pair->ar, pair->camera);
    }
    ExpectSphereAt(pair->ar, diff, p_W, "AR_VIEW " + std::to_string(i));
  }

  // And over the reflective display's frame: its first REFLECTIVE_VIEW that differs from the frame
  // before, where that frame's own camera model projects the centre.
  std::optional<orbed::image_t> mirror;
  ASSERT_TRUE(WaitFor(
      [&] {
        mirror = pictures.reflective();
        return mirror && mirror->data != mirror_before->data;
      },
      20))
      << "the sphere never showed over the reflective display's frame";
  EXPECT_EQ(mirror->utime, mirror_before->utime) << "the same frame";
  ExpectSphereAt(*mirror, Differ(*mirror, *mirror_before), p_W, "REFLECTIVE_VIEW");

  // 4. Removed: from the first AR_VIEW without it, three in a row are their camera frames.
  client.Add(16, {key});
  EXPECT_EQ(client.Send(), (std::vector<uint32_t>{1}));
  pictures.Clear();
  ASSERT_TRUE(WaitFor(
      [&] {
        pair = next();
        return pair && Differ(pair->ar, pair->camera).pixels == 0;
      },
      20))
      << "the sphere stayed in AR_VIEW";
  for (int i = 0; i < 3; ++i) {
    if (i > 0) pair = next();
    ASSERT_TRUE(pair);
    EXPECT_EQ(pair->ar.data, pair->camera.data) << "AR_VIEW " << i << " after the removal";
  }

  ASSERT_TRUE(WaitFor(
      [&] {
        mirror = pictures.reflective();
        return mirror && mirror->data == mirror_before->data;
      },
      20))
      << "the sphere stayed over the reflective display's frame";

  // 5. Nothing refused on the way: each process's first heartbeat after the removal.
  const auto removed_at = std::chrono::steady_clock::now();
  ASSERT_TRUE(WaitFor(
      [&] { return Rejected(bus, "hmd", removed_at) >= 0 && Rejected(bus, "hl2ss", removed_at) >= 0; }, 10));
  EXPECT_EQ(Rejected(bus, "hmd", removed_at), 0);
  EXPECT_EQ(Rejected(bus, "hl2ss", removed_at), 0);
  std::printf("AR_VIEWs whose HMD_CAMERA was lost: %d\n", pictures.unpaired());
}

}  // namespace
}  // namespace orbed::testing
