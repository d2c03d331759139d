#include "procs/igtl_bridge/igtl_bridge.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <igtlImageMessage.h>
#include <igtlMessageHeader.h>
#include <igtlPositionMessage.h>
#include <igtlStatusMessage.h>
#include <igtlStringMessage.h>
#include <igtlTimeStamp.h>
#include <igtlTransformMessage.h>
#include <opencv2/imgproc.hpp>

namespace orbed::igtl_bridge {
namespace {

constexpr size_t kDeviceNameBytes = 20;  // the header's device-name field

template <class MessagePointer>
std::vector<uint8_t> Packed(MessagePointer& msg, const std::string& device, int64_t utime) {
  if (device.size() > kDeviceNameBytes)
    throw std::invalid_argument("OpenIGTLink device name '" + device + "' is longer than 20 bytes");
  msg->SetDeviceName(device.c_str());
  igtl::TimeStamp::Pointer stamp = igtl::TimeStamp::New();
  stamp->SetTime(static_cast<igtlUint32>(utime / 1000000), static_cast<igtlUint32>((utime % 1000000) * 1000));
  msg->SetTimeStamp(stamp);
  msg->Pack();
  const auto* bytes = static_cast<const uint8_t*>(msg->GetPackPointer());
  return std::vector<uint8_t>(bytes, bytes + msg->GetPackSize());
}

// X (metres) as OpenIGTLink's 4x4 (row-major, translation in millimetres).
void ToIgtlMatrix(const Eigen::Isometry3d& X_m, igtl::Matrix4x4& m) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[r][c] = static_cast<float>(X_m.linear()(r, c));
    m[r][3] = static_cast<float>(X_m.translation()(r) * 1000.0);
  }
  m[3][0] = m[3][1] = m[3][2] = 0.0f;
  m[3][3] = 1.0f;
}

uint64_t BigEndian(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

// The NUL-padded text field of a header.
std::string Field(const uint8_t* p, size_t size) {
  size_t n = 0;
  while (n < size && p[n] != 0) ++n;
  return std::string(reinterpret_cast<const char*>(p), n);
}

bool Printable(const std::string& text) {
  return std::all_of(text.begin(), text.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
}

// "" or why a received pose is not one.
std::string CheckPose(const Eigen::Isometry3d& X_m) {
  if (!X_m.matrix().allFinite()) return "non-finite values";
  const Eigen::Matrix3d R = X_m.linear();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > kRigidTolerance ||
      R.determinant() < 0)
    return "the rotation is not a rotation (R^T R != I or det < 0)";
  if (X_m.translation().cwiseAbs().maxCoeff() * 1000.0 > kMaxCoordinateMm) return "position beyond 1e7 mm";
  return "";
}

}  // namespace

std::vector<uint8_t> PackTransform(const std::string& device, const Eigen::Isometry3d& X_m, int64_t utime) {
  igtl::TransformMessage::Pointer msg = igtl::TransformMessage::New();
  igtl::Matrix4x4 m;
  ToIgtlMatrix(X_m, m);
  msg->SetMatrix(m);
  return Packed(msg, device, utime);
}

std::vector<uint8_t> PackStatus(const std::string& device, int code, const std::string& error_name,
                                const std::string& text, int64_t utime) {
  igtl::StatusMessage::Pointer msg = igtl::StatusMessage::New();
  msg->SetCode(code);
  msg->SetSubCode(0);
  msg->SetErrorName(error_name.substr(0, 19).c_str());  // a 20-byte field with its NUL
  msg->SetStatusString(text.c_str());
  return Packed(msg, device, utime);
}

std::vector<uint8_t> PackString(const std::string& device, const std::string& text, int64_t utime) {
  igtl::StringMessage::Pointer msg = igtl::StringMessage::New();
  std::string copy = text;
  msg->SetString(copy);
  msg->SetEncoding(3);  // IANA MIBenum 3: US-ASCII
  return Packed(msg, device, utime);
}

std::vector<uint8_t> PackImage(const std::string& device, const cv::Mat& bgr, const Eigen::Isometry3d& X_WC_m,
                               double fx_px, int64_t utime) {
  if (bgr.type() != CV_8UC3 || bgr.empty()) throw std::invalid_argument("PackImage: not an 8-bit BGR image");
  if (!(fx_px > 0) || !std::isfinite(fx_px)) throw std::invalid_argument("PackImage: fx_px must be > 0");
  igtl::ImageMessage::Pointer msg = igtl::ImageMessage::New();
  msg->SetDimensions(bgr.cols, bgr.rows, 1);
  const float spacing_mm = static_cast<float>(1000.0 / fx_px);
  msg->SetSpacing(spacing_mm, spacing_mm, spacing_mm);
  msg->SetScalarTypeToUint8();
  msg->SetNumComponents(3);
  msg->SetEndian(igtl::ImageMessage::ENDIAN_BIG);
  // The image plane 1 m along the camera's z, its centre on the optical axis, axes the camera's.
  Eigen::Isometry3d X_WP = X_WC_m;
  X_WP.translation() += X_WC_m.linear() * Eigen::Vector3d(0, 0, 1.0);
  igtl::Matrix4x4 m;
  ToIgtlMatrix(X_WP, m);
  msg->SetMatrix(m);
  msg->AllocateScalars();
  cv::Mat rgb(bgr.rows, bgr.cols, CV_8UC3, msg->GetScalarPointer());
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return Packed(msg, device, utime);
}

void IgtlReader::Feed(const uint8_t* data, size_t size) {
  if (consumed_ > 0 && consumed_ >= buffer_.size() / 2) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(consumed_));
    consumed_ = 0;
  }
  buffer_.insert(buffer_.end(), data, data + size);
}

IgtlReader::Result IgtlReader::Next(IgtlPose* pose, std::string* reason) {
  if (fatal_) {
    *reason = "the stream was given up";
    return Result::kFatal;
  }
  if (skip_ > 0) {
    const uint64_t take = std::min<uint64_t>(skip_, buffered());
    consumed_ += take;
    skip_ -= take;
    if (skip_ > 0) return Result::kNeedMore;
  }
  if (buffered() < kHeaderBytes) return Result::kNeedMore;
  const uint8_t* h = buffer_.data() + consumed_;
  const uint64_t version = BigEndian(h, 2);
  const std::string type = Field(h + 2, 12);
  const std::string device = Field(h + 14, kDeviceNameBytes);
  const uint64_t body = BigEndian(h + 42, 8);
  if (body > kMaxBodyBytes) {
    fatal_ = true;
    *reason = "a body of " + std::to_string(body) + " bytes (at most " + std::to_string(kMaxBodyBytes) + ")";
    return Result::kFatal;
  }
  const bool pose_type = type == "TRANSFORM" || type == "POSITION";
  if (!pose_type || (version != 1 && version != 2)) {
    consumed_ += kHeaderBytes;
    skip_ = body;
    const uint64_t take = std::min<uint64_t>(skip_, buffered());
    consumed_ += take;
    skip_ -= take;
    if (!Printable(type)) {
      *reason = "a type that is not printable text";
      return Result::kRefused;
    }
    if (pose_type) {
      *reason = type + " of protocol version " + std::to_string(version) + " (this bridge reads 1 and 2)";
      return Result::kRefused;
    }
    *reason = "type " + type;
    return Result::kSkipped;
  }
  if (buffered() < kHeaderBytes + body) return Result::kNeedMore;
  consumed_ += kHeaderBytes + body;
  if (!Printable(device)) {
    *reason = type + ": a device name that is not printable ASCII";
    return Result::kRefused;
  }
  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  header->InitPack();
  std::memcpy(header->GetPackPointer(), h, kHeaderBytes);
  header->Unpack();
  Eigen::Isometry3d X_m = Eigen::Isometry3d::Identity();
  if (type == "TRANSFORM") {
    if (body != 48) {
      *reason = "TRANSFORM with a body of " + std::to_string(body) + " bytes (48 expected)";
      return Result::kRefused;
    }
    igtl::TransformMessage::Pointer msg = igtl::TransformMessage::New();
    msg->SetMessageHeader(header);
    msg->AllocatePack();
    std::memcpy(msg->GetPackBodyPointer(), h + kHeaderBytes, body);
    if (!(msg->Unpack(1) & igtl::MessageHeader::UNPACK_BODY)) {
      *reason = "TRANSFORM '" + device + "': CRC mismatch";
      return Result::kRefused;
    }
    igtl::Matrix4x4 m;
    msg->GetMatrix(m);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) X_m.matrix()(r, c) = m[r][c];
      X_m.matrix()(r, 3) = m[r][3] / 1000.0;
    }
  } else {
    if (body != 12 && body != 24 && body != 28) {
      *reason = "POSITION with a body of " + std::to_string(body) + " bytes (12, 24 or 28 expected)";
      return Result::kRefused;
    }
    igtl::PositionMessage::Pointer msg = igtl::PositionMessage::New();
    msg->SetMessageHeader(header);
    msg->AllocatePack();
    std::memcpy(msg->GetPackBodyPointer(), h + kHeaderBytes, body);
    if (!(msg->Unpack(1) & igtl::MessageHeader::UNPACK_BODY)) {
      *reason = "POSITION '" + device + "': CRC mismatch";
      return Result::kRefused;
    }
    float p[3] = {0, 0, 0}, q_xyzw[4] = {0, 0, 0, 1};
    msg->GetPosition(p);
    if (body > 12) msg->GetQuaternion(q_xyzw);
    const Eigen::Quaterniond q(q_xyzw[3], q_xyzw[0], q_xyzw[1], q_xyzw[2]);
    if (!std::isfinite(q.norm()) || std::abs(q.norm() - 1.0) > kRigidTolerance) {
      *reason = "POSITION '" + device + "': the quaternion is not a unit quaternion";
      return Result::kRefused;
    }
    X_m.linear() = q.normalized().toRotationMatrix();
    X_m.translation() = Eigen::Vector3d(p[0], p[1], p[2]) / 1000.0;
  }
  const std::string problem = CheckPose(X_m);
  if (!problem.empty()) {
    *reason = type + " '" + device + "': " + problem;
    return Result::kRefused;
  }
  pose->type = type;
  pose->device = device;
  pose->X_m = X_m;
  return Result::kPose;
}

}  // namespace orbed::igtl_bridge
