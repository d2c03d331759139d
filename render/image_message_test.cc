// render/image_message.h: the JPEG frame header read without decoding against cv::imencode's own
// output (the size it was given), and a message whose JPEG declares another size than the message
// refused before decoding; truncated, garbage and empty bytes refused; BGR8 rows copied by stride.
#include "render/image_message.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

namespace orbed::render {
namespace {

std::vector<std::uint8_t> Jpeg(int width, int height) {
  cv::Mat bgr(height, width, CV_8UC3, cv::Scalar(10, 120, 230));
  std::vector<std::uint8_t> bytes;
  cv::imencode(".jpg", bgr, bytes);
  return bytes;
}

orbed::image_t Message(int width, int height, std::vector<std::uint8_t> data) {
  orbed::image_t m{};
  m.width = width;
  m.height = height;
  m.pixel_format = orbed::image_t::FORMAT_JPEG;
  m.num_bytes = static_cast<int32_t>(data.size());
  m.data = std::move(data);
  return m;
}

TEST(ImageMessage, JpegDeclaredSizeIsTheEncodedSize) {
  EXPECT_EQ(JpegDeclaredSize(Jpeg(64, 48)), cv::Size(64, 48));
  EXPECT_EQ(JpegDeclaredSize(Jpeg(1280, 720)), cv::Size(1280, 720));
  EXPECT_EQ(JpegDeclaredSize({}), std::nullopt);
  EXPECT_EQ(JpegDeclaredSize({0xFF, 0xD8, 0xFF}), std::nullopt);
  EXPECT_EQ(JpegDeclaredSize({1, 2, 3, 4, 5, 6}), std::nullopt);
  std::vector<std::uint8_t> cut = Jpeg(64, 48);
  cut.resize(20);  // ends inside the header segments, before the frame header
  EXPECT_EQ(JpegDeclaredSize(cut), std::nullopt);
}

TEST(ImageMessage, DecodesAJpegOfItsSize) {
  cv::Mat bgr;
  EXPECT_EQ(DecodeImageMessage(Message(64, 48, Jpeg(64, 48)), &bgr), "");
  EXPECT_EQ(bgr.cols, 64);
  EXPECT_EQ(bgr.rows, 48);
  EXPECT_NEAR(bgr.at<cv::Vec3b>(10, 10)[2], 230, 3);
}

TEST(ImageMessage, AJpegDeclaringAnotherSizeIsRefusedBeforeDecoding) {
  // The frame header patched to say 60000 x 60000: refused by the header, not by OpenCV.
  std::vector<std::uint8_t> bomb = Jpeg(64, 48);
  for (size_t i = 2; i + 8 < bomb.size(); ++i) {
    if (bomb[i] == 0xFF && bomb[i + 1] == 0xC0) {
      bomb[i + 5] = bomb[i + 7] = 0xEA;
      bomb[i + 6] = bomb[i + 8] = 0x60;
      break;
    }
  }
  ASSERT_EQ(JpegDeclaredSize(bomb), cv::Size(60000, 60000));
  cv::Mat bgr;
  EXPECT_EQ(DecodeImageMessage(Message(64, 48, bomb), &bgr),
            "image: the JPEG declares 60000x60000, the message 64x48");
  EXPECT_TRUE(bgr.empty());
  EXPECT_NE(DecodeImageMessage(Message(64, 48, {9, 9, 9}), &bgr), "");
  std::vector<std::uint8_t> truncated = Jpeg(64, 48);
  truncated.resize(truncated.size() / 2);  // header whole, scan cut: OpenCV cannot give the picture whole
  const std::string why = DecodeImageMessage(Message(64, 48, truncated), &bgr);
  EXPECT_TRUE(why.empty() || why == "image: the data do not decode to its size") << why;
}

TEST(ImageMessage, Bgr8RowsAreCopiedByStride) {
  orbed::image_t m{};
  m.width = 2;
  m.height = 2;
  m.row_stride = 8;  // 6 bytes of pixels, 2 of padding
  m.pixel_format = orbed::image_t::FORMAT_BGR8;
  m.data = {1, 2, 3, 4, 5, 6, 0, 0, 7, 8, 9, 10, 11, 12, 0, 0};
  m.num_bytes = 16;
  cv::Mat bgr;
  ASSERT_EQ(DecodeImageMessage(m, &bgr), "");
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 1), cv::Vec3b(10, 11, 12));
  m.pixel_format = orbed::image_t::FORMAT_GRAY8;
  EXPECT_NE(DecodeImageMessage(m, &bgr), "");
}

}  // namespace
}  // namespace orbed::render
