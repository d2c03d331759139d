#include "render/image_message.h"

#include <opencv2/imgcodecs.hpp>

namespace orbed::render {

std::optional<cv::Size> JpegDeclaredSize(const std::vector<std::uint8_t>& b) {
  const size_t n = b.size();
  if (n < 4 || b[0] != 0xFF || b[1] != 0xD8) return std::nullopt;
  size_t i = 2;
  while (i + 1 < n) {
    if (b[i] != 0xFF) return std::nullopt;
    const std::uint8_t marker = b[i + 1];
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) {  // markers without a length
      i += 2;
      continue;
    }
    if (marker == 0xD9 || marker == 0xDA || i + 3 >= n) return std::nullopt;  // no frame header first
    const size_t length = (size_t{b[i + 2]} << 8) | b[i + 3];
    const bool frame_header =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame_header) {
      if (length < 7 || i + 8 >= n) return std::nullopt;
      const int height = (b[i + 5] << 8) | b[i + 6], width = (b[i + 7] << 8) | b[i + 8];
      return cv::Size(width, height);
    }
    if (length < 2) return std::nullopt;
    i += 2 + length;
  }
  return std::nullopt;
}

std::string DecodeImageMessage(const orbed::image_t& img, cv::Mat* bgr) {
  if (img.pixel_format == orbed::image_t::FORMAT_JPEG) {
    const std::optional<cv::Size> declared = JpegDeclaredSize(img.data);
    if (!declared) return "image: data are not a JPEG with a frame header";
    if (declared->width != img.width || declared->height != img.height)
      return "image: the JPEG declares " + std::to_string(declared->width) + "x" +
             std::to_string(declared->height) + ", the message " + std::to_string(img.width) + "x" +
             std::to_string(img.height);
    try {
      *bgr = cv::imdecode(img.data, cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
      bgr->release();
    }
  } else if (img.pixel_format == orbed::image_t::FORMAT_BGR8) {
    *bgr = cv::Mat(img.height, img.width, CV_8UC3, const_cast<std::uint8_t*>(img.data.data()), img.row_stride)
               .clone();
  } else {
    return "image: pixel format " + std::to_string(img.pixel_format) + " (JPEG and BGR8 are decoded)";
  }
  if (bgr->empty() || bgr->cols != img.width || bgr->rows != img.height)
    return "image: the data do not decode to its size";
  return "";
}

}  // namespace orbed::render
