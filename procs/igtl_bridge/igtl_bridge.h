#pragma once
/// @file
/// OpenIGTLink messages for orbed-igtl-bridge, packed and unpacked by Debian's OpenIGTLink 1.11
/// library (protocol version 2, 58-byte header, CRC-64 over the body). Pure; not thread-safe (one
/// IgtlReader per connection).
///
/// Outgoing (Pack*): poses in OpenIGTLink's millimetres (orbed's are metres), frames named by the
/// device name; images 8-bit RGB; STATUS and STRING as text. Device names are at most 20 bytes
/// (the header's field): longer names are refused with std::invalid_argument.
///
/// Incoming (IgtlReader): a byte stream from one client, cut into messages. TRANSFORM and POSITION
/// are read as a pose (mm → m) after the library's CRC check; every other type is skipped. What is
/// refused, with its reason, and the stream goes on: a bad CRC, a body of the wrong size for its
/// type, a device name that is not printable ASCII, non-finite or non-rigid matrices (|R^T R − I| >
/// kRigidTolerance), a non-unit quaternion, coordinates beyond kMaxCoordinateMm, a header version
/// other than 1 or 2. What ends the connection (the stream cannot be trusted to continue): a body
/// size larger than kMaxBodyBytes. Nothing is allocated from a size field before it is checked, so
/// n bytes cost O(n) time and at most kMaxBodyBytes + one read of memory.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace orbed::igtl_bridge {

/// The header of every OpenIGTLink message [bytes].
constexpr size_t kHeaderBytes = 58;
/// The largest body a client may send (TRANSFORM is 48 bytes, POSITION at most 28; other types are
/// skipped up to this size).
constexpr uint64_t kMaxBodyBytes = 1 << 20;
/// |R^T R − I| (max entry) above this is not a rotation (the wire carries 32-bit floats).
constexpr double kRigidTolerance = 1e-3;
/// Positions beyond this many millimetres from the origin are not an operating room.
constexpr double kMaxCoordinateMm = 1e7;

/// Microseconds since the Unix epoch → OpenIGTLink's timestamp is set from it in every Pack*.
std::vector<uint8_t> PackTransform(const std::string& device, const Eigen::Isometry3d& X_m, int64_t utime);
std::vector<uint8_t> PackStatus(const std::string& device, int code, const std::string& error_name,
                                const std::string& text, int64_t utime);
std::vector<uint8_t> PackString(const std::string& device, const std::string& text, int64_t utime);
/// An 8-bit BGR (OpenCV) picture as IMAGE: RGB, 3 components, dimensions (width, height, 1). It is
/// placed as the camera's image plane 1 m in front of the camera: pixel spacing 1000 / fx_px mm,
/// axes the camera's (x right, y down, z forward) from X_WC, the plane's centre on the optical axis.
std::vector<uint8_t> PackImage(const std::string& device, const cv::Mat& bgr, const Eigen::Isometry3d& X_WC_m,
                               double fx_px, int64_t utime);

/// One pose a client sent.
struct IgtlPose {
  std::string type;    ///< "TRANSFORM" or "POSITION"
  std::string device;  ///< the sender's device name
  Eigen::Isometry3d X_m{Eigen::Isometry3d::Identity()};
};

class IgtlReader {
 public:
  enum class Result {
    kNeedMore,  ///< no complete message yet
    kPose,      ///< *pose holds a TRANSFORM or POSITION
    kSkipped,   ///< another type, skipped; *reason names it ("type STATUS")
    kRefused,   ///< a message refused; *reason says why; the stream goes on
    kFatal,     ///< the stream cannot continue (*reason); close the connection
  };
  /// Appends received bytes.
  void Feed(const uint8_t* data, size_t size);
  /// The next message in what was fed.
  Result Next(IgtlPose* pose, std::string* reason);
  /// Bytes held (at most kHeaderBytes + kMaxBodyBytes + the last Feed).
  size_t buffered() const { return buffer_.size() - consumed_; }

 private:
  std::vector<uint8_t> buffer_;
  size_t consumed_ = 0;
  uint64_t skip_ = 0;  // body bytes of a skipped message still to come
  bool fatal_ = false;
};

}  // namespace orbed::igtl_bridge
