#include "procs/hl2ss/rm_depth.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "procs/hl2ss/frames.h"

namespace orbed::hl2ss {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kPixels = kLongThrowWidth * kLongThrowHeight;

void PutF32(std::uint8_t* p, float f) {
  std::uint32_t v;
  std::memcpy(&v, &f, 4);
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace

geometry::Intrinsics LongThrowIntrinsics() {
  geometry::Intrinsics K;
  K.width_px = kLongThrowWidth;
  K.height_px = kLongThrowHeight;
  K.fx_px = 0.5 * kLongThrowWidth / std::tan(0.5 * 75.0 * kPi / 180.0);
  K.fy_px = K.fx_px;
  K.cx_px = 0.5 * (kLongThrowWidth - 1);
  K.cy_px = 0.5 * (kLongThrowHeight - 1);
  return K;
}

Eigen::Vector2d LongThrowImagePointToUnitPlane(const geometry::Intrinsics& K,
                                               const Eigen::Vector2d& uv_corner) {
  return {(uv_corner.x() - 0.5 - K.cx_px) / K.fx_px, (uv_corner.y() - 0.5 - K.cy_px) / K.fy_px};
}

Eigen::Vector2d LongThrowUnitPlaneToImagePoint(const geometry::Intrinsics& K, const Eigen::Vector2d& xy) {
  return {K.fx_px * xy.x() + K.cx_px + 0.5, K.fy_px * xy.y() + K.cy_px + 0.5};
}

Eigen::Isometry3d LongThrowOptions::DefaultX_HZ() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(-10.0 * kPi / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.0, -0.03, 0.01);
  return X;
}

Eigen::Isometry3d LongThrowOptions::DefaultX_HN() { return X_CCh(); }

LongThrowCamera::LongThrowCamera(const LongThrowOptions& options)
    : options_(options), renderer_(options.intrinsics) {
  const geometry::Intrinsics& K = options_.intrinsics;
  if (K.width_px != kLongThrowWidth || K.height_px != kLongThrowHeight) {
    throw std::invalid_argument("long-throw intrinsics must be 320x288");
  }
  if (!(options_.min_range_m >= 0 && options_.max_range_m > options_.min_range_m)) {
    throw std::invalid_argument("long-throw range must be 0 <= min < max");
  }
  ray_norm_.create(kLongThrowHeight, kLongThrowWidth, CV_64F);
  for (int v = 0; v < kLongThrowHeight; ++v) {
    for (int u = 0; u < kLongThrowWidth; ++u) {
      const double x = (u - K.cx_px) / K.fx_px, y = (v - K.cy_px) / K.fy_px;
      ray_norm_.at<double>(v, u) = std::sqrt(x * x + y * y + 1.0);
    }
  }
}

void LongThrowCamera::Render(const render::Mesh& mesh, const Eigen::Isometry3d& X_WH, LongThrowFrame* frame) {
  renderer_.Render(mesh, X_WZ(X_WH), &bgr_, &z_m_);
  frame->depth_mm.create(kLongThrowHeight, kLongThrowWidth, CV_16UC1);
  frame->ab.create(kLongThrowHeight, kLongThrowWidth, CV_16UC1);
  for (int v = 0; v < kLongThrowHeight; ++v) {
    const float* z = z_m_.ptr<float>(v);
    const double* n = ray_norm_.ptr<double>(v);
    std::uint16_t* d = frame->depth_mm.ptr<std::uint16_t>(v);
    std::uint16_t* a = frame->ab.ptr<std::uint16_t>(v);
    for (int u = 0; u < kLongThrowWidth; ++u) {
      const double r_m = static_cast<double>(z[u]) * n[u];  // 0 where nothing was drawn
      if (!(z[u] > 0.0f) || r_m < options_.min_range_m || r_m > options_.max_range_m) {
        d[u] = 0;
        a[u] = 0;
        continue;
      }
      d[u] = static_cast<std::uint16_t>(std::lround(1000.0 * r_m));
      a[u] = static_cast<std::uint16_t>(std::min(65535.0, std::round(options_.ab_at_1m / (r_m * r_m))));
    }
  }
}

bool EncodeLongThrowPayload(const LongThrowFrame& frame, std::uint64_t sensor_ticks,
                            std::vector<std::uint8_t>* payload, std::string* error) {
  const auto shaped = [](const cv::Mat& m) {
    return m.type() == CV_16UC1 && m.rows == kLongThrowHeight && m.cols == kLongThrowWidth;
  };
  if (!shaped(frame.depth_mm) || !shaped(frame.ab)) {
    *error = "long-throw frame must be two 288x320 u16 pictures";
    return false;
  }
  // Depth rows then AB rows, as one 288×320 BGRA picture (4 bytes a pixel = 2 u16).
  cv::Mat composite(kLongThrowHeight, kLongThrowWidth, CV_8UC4);
  std::uint8_t* dst = composite.ptr<std::uint8_t>(0);
  const size_t half = static_cast<size_t>(kPixels) * 2;
  for (int v = 0; v < kLongThrowHeight; ++v) {
    std::memcpy(dst + static_cast<size_t>(v) * kLongThrowWidth * 2, frame.depth_mm.ptr<std::uint16_t>(v),
                kLongThrowWidth * 2);
    std::memcpy(dst + half + static_cast<size_t>(v) * kLongThrowWidth * 2, frame.ab.ptr<std::uint16_t>(v),
                kLongThrowWidth * 2);
  }
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the u16 pictures are sent in host order");
  payload->clear();
  if (!cv::imencode(".png", composite, *payload, {cv::IMWRITE_PNG_COMPRESSION, 1})) {
    *error = "PNG coding of the long-throw frame failed";
    return false;
  }
  for (int i = 0; i < 8; ++i) payload->push_back(static_cast<std::uint8_t>(sensor_ticks >> (8 * i)));
  return true;
}

std::vector<std::uint8_t> PackLongThrowCalibration(const LongThrowOptions& options) {
  const geometry::Intrinsics& K = options.intrinsics;
  const int W = kLongThrowWidth, H = kLongThrowHeight;
  std::vector<float> uv2x(kPixels), uv2y(kPixels), mapx(kPixels), mapy(kPixels);
  float min_x = std::numeric_limits<float>::infinity(), max_x = -min_x;
  float min_y = min_x, max_y = -min_x;
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const Eigen::Vector2d xy = LongThrowImagePointToUnitPlane(K, {u + 0.5, v + 0.5});
      const float x = static_cast<float>(xy.x()), y = static_cast<float>(xy.y());
      uv2x[v * W + u] = x;
      uv2y[v * W + u] = y;
      min_x = std::min(min_x, x);
      max_x = std::max(max_x, x);
      min_y = std::min(min_y, y);
      max_y = std::max(max_y, y);
    }
  }
  const float span_u = static_cast<float>(W - 1), span_v = static_cast<float>(H - 1);
  const float step_x = (max_x - min_x) / span_u, step_y = (max_y - min_y) / span_v;
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const Eigen::Vector2d uv = LongThrowUnitPlaneToImagePoint(K, {step_x * u + min_x, step_y * v + min_y});
      mapx[v * W + u] = static_cast<float>(uv.x());
      mapy[v * W + u] = static_cast<float>(uv.y());
    }
  }
  const float k[4] = {span_u / (max_x - min_x), span_v / (max_y - min_y), -min_x * span_u / (max_x - min_x),
                      -min_y * span_v / (max_y - min_y)};
  const Eigen::Isometry3d X_NZ = options.X_HN.inverse() * options.X_HZ;
  const std::array<float, 16> E = PoseMatrixRowMajor(X_NZ.inverse());  // row-major of X_ZNᵀ

  std::vector<float> f;
  f.reserve(4 * kPixels + 16 + 1 + 4);
  f.insert(f.end(), uv2x.begin(), uv2x.end());
  f.insert(f.end(), uv2y.begin(), uv2y.end());
  f.insert(f.end(), E.begin(), E.end());
  f.push_back(kLongThrowScale);
  f.insert(f.end(), mapx.begin(), mapx.end());
  f.insert(f.end(), mapy.begin(), mapy.end());
  f.insert(f.end(), k, k + 4);
  std::vector<std::uint8_t> bytes(f.size() * 4);
  for (size_t i = 0; i < f.size(); ++i) PutF32(bytes.data() + 4 * i, f[i]);
  return bytes;
}

Eigen::Isometry3d RigNodePoseForClient(const Eigen::Isometry3d& X_WH, const LongThrowOptions& options) {
  return X_WD().inverse() * X_WH * options.X_HN;
}

}  // namespace orbed::hl2ss
