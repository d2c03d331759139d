#include "procs/hl2ss/pv_client_decoder.h"

#include <cstring>
#include <iterator>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

extern "C" {
#include <libavcodec/avcodec.h>
}

namespace orbed::hl2ss {

PvClientDecoder::PvClientDecoder(bool hevc) : hevc_(hevc) {
  const AVCodec* codec = avcodec_find_decoder(hevc ? AV_CODEC_ID_HEVC : AV_CODEC_ID_H264);
  if (!codec) throw std::runtime_error("libavcodec has no H.264/HEVC decoder");
  ctx_ = avcodec_alloc_context3(codec);
  parser_ = av_parser_init(codec->id);
  packet_ = av_packet_alloc();
  frame_ = av_frame_alloc();
  if (!ctx_ || !parser_ || !packet_ || !frame_ || avcodec_open2(ctx_, codec, nullptr) != 0) {
    Free();
    throw std::runtime_error("cannot open libavcodec's decoder");
  }
}

PvClientDecoder::~PvClientDecoder() { Free(); }

void PvClientDecoder::Free() {
  av_frame_free(&frame_);
  av_packet_free(&packet_);
  if (parser_) av_parser_close(parser_);
  parser_ = nullptr;
  avcodec_free_context(&ctx_);
}

int PvClientDecoder::profile() const { return ctx_->profile; }

cv::Mat PvClientDecoder::Decode(const std::vector<std::uint8_t>& image) {
  static const std::uint8_t kAud264[] = {0x00, 0x00, 0x00, 0x01, 0x09, 0x10};
  static const std::uint8_t kAud265[] = {0x00, 0x00, 0x00, 0x01, 0x46, 0x01, 0x03};
  const size_t skip = hevc_ ? 0 : 6;
  if (image.size() < skip) return {};
  std::vector<std::uint8_t> in(image.begin() + static_cast<std::ptrdiff_t>(skip), image.end());
  if (hevc_) {
    in.insert(in.end(), std::begin(kAud265), std::end(kAud265));
  } else {
    in.insert(in.end(), std::begin(kAud264), std::end(kAud264));
  }
  const int size = static_cast<int>(in.size());
  in.resize(in.size() + AV_INPUT_BUFFER_PADDING_SIZE, 0);
  const std::uint8_t* data = in.data();
  int left = size;
  while (left > 0) {
    std::uint8_t* out = nullptr;
    int out_size = 0;
    const int used =
        av_parser_parse2(parser_, ctx_, &out, &out_size, data, left, AV_NOPTS_VALUE, AV_NOPTS_VALUE, 0);
    if (used < 0) return {};
    data += used;
    left -= used;
    if (out_size == 0) continue;
    packet_->data = out;
    packet_->size = out_size;
    if (avcodec_send_packet(ctx_, packet_) < 0) return {};
    if (avcodec_receive_frame(ctx_, frame_) == 0) return ToBgr();
  }
  return {};
}

cv::Mat PvClientDecoder::ToBgr() {
  key_ = frame_->key_frame != 0;
  const int w = frame_->width, h = frame_->height;
  if (frame_->format != AV_PIX_FMT_YUV420P) {
    av_frame_unref(frame_);
    return {};
  }
  cv::Mat i420(h * 3 / 2, w, CV_8UC1);
  std::uint8_t* dst = i420.ptr<std::uint8_t>(0);
  for (int r = 0; r < h; ++r) std::memcpy(dst + r * w, frame_->data[0] + r * frame_->linesize[0], w);
  dst += w * h;
  for (int p = 1; p <= 2; ++p) {
    for (int r = 0; r < h / 2; ++r)
      std::memcpy(dst + r * (w / 2), frame_->data[p] + r * frame_->linesize[p], w / 2);
    dst += (w / 2) * (h / 2);
  }
  cv::Mat bgr;
  cv::cvtColor(i420, bgr, cv::COLOR_YUV2BGR_I420);
  av_frame_unref(frame_);
  return bgr;
}

}  // namespace orbed::hl2ss
