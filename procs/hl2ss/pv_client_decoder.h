#pragma once
/// @file
/// For tests: a PV payload's image decoded the way hl2ss's Python client decodes it (hl2ss.py
/// _codec_h264 / _codec_hevc on PyAV, i.e. libavcodec): an H.264 payload loses its first 6 bytes
/// (the device's access unit delimiter), an access unit delimiter is appended so the parser
/// closes the unit, the bytes are parsed and decoded, and the first picture that comes out is
/// kept, converted to BGR (BT.601 limited range, as the client's to_ndarray(format='bgr24')).
/// An independent reader of what pv_encoder.h writes: libavcodec's decoders, not its encoders.
///
/// Threading: one thread per decoder.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

struct AVCodecContext;
struct AVCodecParserContext;
struct AVPacket;
struct AVFrame;

namespace orbed::hl2ss {

class PvClientDecoder {
 public:
  /// hevc: the H.265 profile; else H.264. Throws std::runtime_error when the codec cannot open.
  explicit PvClientDecoder(bool hevc);
  ~PvClientDecoder();
  PvClientDecoder(const PvClientDecoder&) = delete;
  PvClientDecoder& operator=(const PvClientDecoder&) = delete;

  /// The BGR picture of one payload's image part (the payload without its 80-byte trailer);
  /// empty when none came out.
  cv::Mat Decode(const std::vector<std::uint8_t>& image);
  /// libavcodec's profile of the stream decoded (FF_PROFILE_*).
  int profile() const;
  /// Whether the last picture decoded was a key frame.
  bool last_was_key() const { return key_; }

 private:
  cv::Mat ToBgr();
  void Free();
  bool hevc_;
  bool key_{false};
  AVCodecContext* ctx_{nullptr};
  AVCodecParserContext* parser_{nullptr};
  AVPacket* packet_{nullptr};
  AVFrame* frame_{nullptr};
};

}  // namespace orbed::hl2ss
