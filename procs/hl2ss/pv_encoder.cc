#include "procs/hl2ss/pv_encoder.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "procs/hl2ss/frames.h"
#include "procs/hl2ss/protocol.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
}

namespace orbed::hl2ss {
namespace {

static_assert(sizeof(float) == 4, "float32 on the wire");

// Little-endian writers (the wire is little-endian; so is every host orbed builds for, but the
// bytes are placed one by one so the layout is explicit).
void PutU16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void PutU32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void PutU64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void PutF32(std::uint8_t* p, float f) {
  std::uint32_t v;
  std::memcpy(&v, &f, 4);
  PutU32(p, v);
}

std::string AvError(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(code, text, sizeof(text));
  return text;
}

// The access unit delimiter the device's H.264 encoder starts each unit with; the client drops
// these 6 bytes (primary_pic_type 0, then the stop bit).
constexpr int kMaxPictureSide = 4096;  // a picture from outside is refused before it is resized

constexpr std::uint8_t kH264Aud[6] = {0x00, 0x00, 0x00, 0x01, 0x09, 0x10};

}  // namespace

std::optional<VideoProfile> VideoProfileFromByte(std::uint8_t byte) {
  switch (byte) {
    case 0:
      return VideoProfile::kH264Base;
    case 1:
      return VideoProfile::kH264Main;
    case 2:
      return VideoProfile::kH264High;
    case 3:
      return VideoProfile::kH265Main;
    case 0xFF:
      return VideoProfile::kRaw;
    default:
      return std::nullopt;
  }
}

const std::vector<PvFormat>& SupportedPvFormats() {
  static const std::vector<PvFormat> formats = [] {
    std::vector<PvFormat> f;
    for (const PvVideoMode& m : PvVideoModes()) f.push_back({m.width, m.height, m.framerate});
    return f;
  }();
  return formats;
}

std::optional<std::string> CheckPvFormat(const PvFormat& format) {
  bool size_known = false;
  std::ostringstream rates;
  for (const PvFormat& f : SupportedPvFormats()) {
    if (f.width_px != format.width_px || f.height_px != format.height_px) continue;
    if (f.framerate_hz == format.framerate_hz) return std::nullopt;
    rates << (size_known ? ", " : "") << f.framerate_hz;
    size_known = true;
  }
  std::ostringstream why;
  if (size_known) {
    why << "PV " << format.width_px << "x" << format.height_px << " runs at " << rates.str() << " Hz, not "
        << format.framerate_hz;
  } else {
    why << "PV size " << format.width_px << "x" << format.height_px << " is not a video mode of the device (";
    const char* separator = "";
    for (size_t i = 0; i < SupportedPvFormats().size(); ++i) {
      const PvFormat& f = SupportedPvFormats()[i];
      if (i > 0 && f.width_px == SupportedPvFormats()[i - 1].width_px &&
          f.height_px == SupportedPvFormats()[i - 1].height_px)
        continue;
      why << separator << f.width_px << "x" << f.height_px;
      separator = ", ";
    }
    why << ")";
  }
  return why.str();
}

int PvRawStride(int width_px) { return (width_px + 63) & ~63; }

std::optional<std::string> CheckPvEncoderConfig(const PvEncoderConfig& config) {
  if (auto why = CheckPvFormat(config.format)) return why;
  if (config.threads < 1 || config.threads > 8) return "encoder threads must be 1 … 8";
  if (config.divisor < 1 || config.divisor > 255)
    return "divisor " + std::to_string(config.divisor) + " outside 1 … 255";
  if (config.profile == VideoProfile::kRaw) return std::nullopt;
  if (config.bitrate_bps == 0 || config.bitrate_bps > kMaxBitrateBps) {
    return "bitrate " + std::to_string(config.bitrate_bps) + " bit/s outside 1 … " +
           std::to_string(kMaxBitrateBps);
  }
  if (config.gop_frames < 1 || config.gop_frames > 600) {
    return "GOP size " + std::to_string(config.gop_frames) + " frames outside 1 … 600";
  }
  return std::nullopt;
}

geometry::Intrinsics ScaleIntrinsics(const geometry::Intrinsics& K, int width_px, int height_px) {
  const double sx = static_cast<double>(width_px) / K.width_px;
  const double sy = static_cast<double>(height_px) / K.height_px;
  geometry::Intrinsics out = K;
  out.width_px = width_px;
  out.height_px = height_px;
  out.fx_px = sx * K.fx_px;
  out.fy_px = sy * K.fy_px;
  out.cx_px = sx * (K.cx_px + 0.5) - 0.5;
  out.cy_px = sy * (K.cy_px + 0.5) - 0.5;
  return out;
}

std::array<std::uint8_t, kPvTrailerBytes> PackPvTrailer(const geometry::Intrinsics& K,
                                                        const PvCaptureMetadata& m) {
  std::array<std::uint8_t, kPvTrailerBytes> t{};
  std::uint8_t* p = t.data();
  PutF32(p + 0, static_cast<float>(K.fx_px));
  PutF32(p + 4, static_cast<float>(K.fy_px));
  PutF32(p + 8, static_cast<float>(K.cx_px));
  PutF32(p + 12, static_cast<float>(K.cy_px));
  PutU64(p + 16, m.exposure_time_hns);
  PutU64(p + 24, m.exposure_compensation[0]);
  PutU64(p + 32, m.exposure_compensation[1]);
  PutU32(p + 40, m.lens_position);
  PutU32(p + 44, m.focus_state);
  PutU32(p + 48, m.iso_speed);
  PutU32(p + 52, m.white_balance_k);
  PutF32(p + 56, m.iso_gains[0]);
  PutF32(p + 60, m.iso_gains[1]);
  for (int i = 0; i < 3; ++i) PutF32(p + 64 + 4 * i, m.white_balance_gains[i]);
  PutU16(p + 76, static_cast<std::uint16_t>(K.width_px));
  PutU16(p + 78, static_cast<std::uint16_t>(K.height_px));
  return t;
}

std::vector<std::uint8_t> PackPvCalibration(const geometry::Intrinsics& K, const Eigen::Isometry3d& X_NC) {
  std::vector<float> f;
  f.reserve(61);
  const float fx = static_cast<float>(K.fx_px), fy = static_cast<float>(K.fy_px);
  const float cx = static_cast<float>(K.cx_px), cy = static_cast<float>(K.cy_px);
  f.insert(f.end(), {fx, fy, cx, cy});
  f.insert(f.end(), {0, 0, 0, 0, 0});  // radial (3), tangential (2)
  f.insert(f.end(), {-fx, 0, 0, 0, 0, fy, 0, 0, cx, cy, 1, 0, 0, 0, 0, 1});
  const Eigen::Isometry3d X_NCh = X_NC * X_CCh();
  const std::array<float, 16> E = PoseMatrixRowMajor(X_NCh.inverse());  // row-major of X_ĈNᵀ
  f.insert(f.end(), E.begin(), E.end());
  f.insert(f.end(), {fx, fy, cx, cy});
  const Eigen::Quaterniond q(X_NCh.linear());
  const Eigen::Vector3d p = X_NCh.translation();
  f.insert(f.end(), {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()),
                     static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()),
                     static_cast<float>(q.w())});
  std::vector<std::uint8_t> bytes(f.size() * 4);
  for (size_t i = 0; i < f.size(); ++i) PutF32(bytes.data() + 4 * i, f[i]);
  return bytes;
}

void AppendNv12(const cv::Mat& bgr, int stride_px, std::vector<std::uint8_t>* out) {
  const int w = bgr.cols, h = bgr.rows;
  cv::Mat i420;
  cv::cvtColor(bgr, i420, cv::COLOR_BGR2YUV_I420);  // h·3/2 rows of w: Y, then U (w/2 × h/2), then V
  const size_t start = out->size();
  out->resize(start + static_cast<size_t>(stride_px) * h * 3 / 2, 0);
  std::uint8_t* dst = out->data() + start;
  const std::uint8_t* y = i420.ptr<std::uint8_t>(0);
  for (int r = 0; r < h; ++r)
    std::memcpy(dst + static_cast<size_t>(r) * stride_px, y + static_cast<size_t>(r) * w, w);
  const std::uint8_t* u = y + static_cast<size_t>(w) * h;
  const std::uint8_t* v = u + static_cast<size_t>(w / 2) * (h / 2);
  std::uint8_t* uv = dst + static_cast<size_t>(stride_px) * h;
  for (int r = 0; r < h / 2; ++r) {
    std::uint8_t* row = uv + static_cast<size_t>(r) * stride_px;
    for (int c = 0; c < w / 2; ++c) {
      row[2 * c] = u[static_cast<size_t>(r) * (w / 2) + c];
      row[2 * c + 1] = v[static_cast<size_t>(r) * (w / 2) + c];
    }
  }
}

struct PvEncoder::Codec {
  AVCodecContext* context{nullptr};
  AVFrame* frame{nullptr};
  AVPacket* packet{nullptr};
  ~Codec() {
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&context);
  }
};

PvEncoder::PvEncoder(const PvEncoderConfig& config) : config_(config) {}
PvEncoder::~PvEncoder() = default;

std::unique_ptr<PvEncoder> PvEncoder::Create(const PvEncoderConfig& config, std::string* error) {
  if (auto why = CheckPvEncoderConfig(config)) {
    *error = *why;
    return nullptr;
  }
  std::unique_ptr<PvEncoder> encoder(new PvEncoder(config));
  if (config.profile == VideoProfile::kRaw) return encoder;

  const bool hevc = config.profile == VideoProfile::kH265Main;
  const char* name = hevc ? "libx265" : "libx264";
  const AVCodec* codec = avcodec_find_encoder_by_name(name);
  if (codec == nullptr) {
    *error = std::string("libavcodec has no ") + name + " encoder";
    return nullptr;
  }
  av_log_set_level(AV_LOG_ERROR);  // the codecs' banners and statistics stay off the process's output
  auto c = std::make_unique<Codec>();
  c->context = avcodec_alloc_context3(codec);
  c->frame = av_frame_alloc();
  c->packet = av_packet_alloc();
  if (c->context == nullptr || c->frame == nullptr || c->packet == nullptr) {
    *error = "out of memory opening the encoder";
    return nullptr;
  }
  AVCodecContext* ctx = c->context;
  ctx->width = config.format.width_px;
  ctx->height = config.format.height_px;
  ctx->pix_fmt = AV_PIX_FMT_YUV420P;
  ctx->time_base = AVRational{config.divisor, config.format.framerate_hz};
  ctx->framerate = AVRational{config.format.framerate_hz, config.divisor};
  ctx->bit_rate = config.bitrate_bps;
  ctx->gop_size = config.gop_frames;
  ctx->max_b_frames = 0;
  ctx->thread_count = config.threads;
  // BT.601 limited range, as the client's decoder converts by default.
  ctx->color_range = AVCOL_RANGE_MPEG;
  ctx->colorspace = AVCOL_SPC_SMPTE170M;
  av_opt_set(ctx->priv_data, "preset", "ultrafast", 0);
  av_opt_set(ctx->priv_data, "tune", "zerolatency", 0);
  av_opt_set(ctx->priv_data, "forced-idr", "1", 0);  // a picture asked to be I is an IDR (ForceKeyFrame)
  if (hevc) {
    ctx->profile = FF_PROFILE_HEVC_MAIN;
    // One frame in flight (frame-threads=1: each picture's unit comes back at once); the threads
    // work within the picture (wavefront rows). SAO back on (the fastest preset turns it off):
    // libx265 3.5 leaks its filter's buffers, ~115 kB an encoder, when SAO is off. Closed GOPs:
    // each key frame (the GOP's, a forced one) an IDR, not a CRA.
    const std::string params =
        "log-level=error:repeat-headers=1:aud=0:sao=1:open-gop=0:frame-threads=1:pools=" +
        std::to_string(config.threads);
    av_opt_set(ctx->priv_data, "x265-params", params.c_str(), 0);
  } else {
    // x264 signals the lowest profile its tools fit, and the ultrafast preset's fit baseline: the
    // tool that defines main (CABAC) and high's (8×8 transform) are switched back on.
    const bool base = config.profile == VideoProfile::kH264Base,
               main = config.profile == VideoProfile::kH264Main;
    av_opt_set(ctx->priv_data, "profile", base ? "baseline" : main ? "main" : "high", 0);
    av_opt_set(ctx->priv_data, "x264-params",
               base   ? "aud=0:repeat-headers=1"
               : main ? "aud=0:repeat-headers=1:cabac=1"
                      : "aud=0:repeat-headers=1:cabac=1:8x8dct=1",
               0);
  }
  const int opened = avcodec_open2(ctx, codec, nullptr);
  if (opened < 0) {
    *error = std::string("cannot open ") + name + ": " + AvError(opened);
    return nullptr;
  }
  c->frame->format = ctx->pix_fmt;
  c->frame->width = ctx->width;
  c->frame->height = ctx->height;
  const int allocated = av_frame_get_buffer(c->frame, 0);
  if (allocated < 0) {
    *error = "cannot allocate the encoder's picture: " + AvError(allocated);
    return nullptr;
  }
  encoder->codec_ = std::move(c);
  return encoder;
}

bool PvEncoder::Encode(const cv::Mat& bgr, const geometry::Intrinsics& K_picture,
                       const PvCaptureMetadata& metadata, std::vector<std::uint8_t>* payload,
                       std::string* error) {
  if (bgr.type() != CV_8UC3 || bgr.empty()) {
    *error = "PV picture is not 8-bit BGR";
    return false;
  }
  if (bgr.cols > kMaxPictureSide || bgr.rows > kMaxPictureSide) {
    *error = "PV picture larger than 4096 pixels a side";
    return false;
  }
  if (bgr.cols != K_picture.width_px || bgr.rows != K_picture.height_px) {
    *error = "PV picture size differs from its intrinsics";
    return false;
  }
  if (!(K_picture.fx_px > 0 && K_picture.fy_px > 0 && std::isfinite(K_picture.fx_px) &&
        std::isfinite(K_picture.fy_px) && std::isfinite(K_picture.cx_px) && std::isfinite(K_picture.cy_px))) {
    *error = "PV picture intrinsics not finite and positive";
    return false;
  }
  const int w = config_.format.width_px, h = config_.format.height_px;
  const cv::Mat* picture = &bgr;
  if (bgr.cols != w || bgr.rows != h) {
    cv::resize(bgr, resized_, cv::Size(w, h), 0, 0, cv::INTER_AREA);
    picture = &resized_;
  }
  payload->clear();
  if (config_.profile == VideoProfile::kRaw) {
    AppendNv12(*picture, PvRawStride(w), payload);
  } else if (!EncodeVideo(*picture, payload, error)) {
    return false;
  }
  const auto trailer = PackPvTrailer(ScaleIntrinsics(K_picture, w, h), metadata);
  payload->insert(payload->end(), trailer.begin(), trailer.end());
  ++frames_;
  return true;
}

bool PvEncoder::EncodeVideo(const cv::Mat& bgr, std::vector<std::uint8_t>* payload, std::string* error) {
  AVCodecContext* ctx = codec_->context;
  AVFrame* frame = codec_->frame;
  const int writable = av_frame_make_writable(frame);
  if (writable < 0) {
    *error = "encoder picture not writable: " + AvError(writable);
    return false;
  }
  cv::cvtColor(bgr, i420_, cv::COLOR_BGR2YUV_I420);
  const int w = bgr.cols, h = bgr.rows;
  const std::uint8_t* src = i420_.ptr<std::uint8_t>(0);
  const std::uint8_t* planes[3] = {src, src + static_cast<size_t>(w) * h,
                                   src + static_cast<size_t>(w) * h + static_cast<size_t>(w / 2) * (h / 2)};
  const int widths[3] = {w, w / 2, w / 2}, heights[3] = {h, h / 2, h / 2};
  for (int p = 0; p < 3; ++p) {
    for (int r = 0; r < heights[p]; ++r) {
      std::memcpy(frame->data[p] + static_cast<size_t>(r) * frame->linesize[p],
                  planes[p] + static_cast<size_t>(r) * widths[p], widths[p]);
    }
  }
  frame->pts = frames_;
  // The first picture of a connection is an IDR with the parameter sets, and so is one forced
  // (ForceKeyFrame); the others follow the GOP.
  frame->pict_type = frames_ == 0 || key_frame_next_ ? AV_PICTURE_TYPE_I : AV_PICTURE_TYPE_NONE;
  key_frame_next_ = false;
  int sent = avcodec_send_frame(ctx, frame);
  if (sent < 0) {
    *error = "encoder refused the picture: " + AvError(sent);
    return false;
  }
  if (config_.profile != VideoProfile::kH265Main)
    payload->insert(payload->end(), std::begin(kH264Aud), std::end(kH264Aud));
  const size_t start = payload->size();
  for (;;) {
    const int got = avcodec_receive_packet(ctx, codec_->packet);
    if (got == AVERROR(EAGAIN) || got == AVERROR_EOF) break;
    if (got < 0) {
      *error = "encoder failed: " + AvError(got);
      return false;
    }
    payload->insert(payload->end(), codec_->packet->data, codec_->packet->data + codec_->packet->size);
    av_packet_unref(codec_->packet);
  }
  if (payload->size() == start) {
    *error = "encoder returned no access unit for the picture";
    return false;
  }
  return true;
}

}  // namespace orbed::hl2ss
