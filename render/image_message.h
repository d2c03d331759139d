#pragma once
/// @file
/// The picture an image_t carries (HMD_CAMERA, AR_VIEW, a reflective view), decoded once for every
/// process that receives images from the bus (orbed-hl2ss, orbed-igtl-bridge). A JPEG's own frame
/// header is read first, without decoding, and must declare the message's width × height: a JPEG
/// that says 60000 × 60000 inside a message that says 1280 × 720 is refused before OpenCV
/// allocates for it; a decoder error is a refusal, never an exception.
///
/// Threading: pure functions.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <orbed/image_t.hpp>

namespace orbed::render {

/// The (width, height) a JPEG's first frame header (SOF0..SOF15) declares, read from the markers
/// without decoding; nullopt when the bytes are not a JPEG or end before one.
std::optional<cv::Size> JpegDeclaredSize(const std::vector<std::uint8_t>& bytes);

/// "" or why `img` does not decode to its declared size; on success *bgr holds the picture (CV_8UC3).
/// JPEG and BGR8 are decoded; other formats are refused. Call after CheckImage (lcmtypes/contract):
/// the raw formats' strides and byte counts are checked there.
std::string DecodeImageMessage(const orbed::image_t& img, cv::Mat* bgr);

}  // namespace orbed::render
