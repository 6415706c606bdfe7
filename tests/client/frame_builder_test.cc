#include "client/frame_builder.h"

#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace fovea::client {
namespace {

using ::testing::HasSubstr;

std::string Encode(const std::string& extension, const cv::Mat& image) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(extension, image, bytes));
  return std::string(bytes.begin(), bytes.end());
}

TEST(MakeRawImageTest, TightRgb8KeepsBytesAndFillsHeader) {
  std::vector<uint8_t> pixels(4 * 2 * 3);
  for (size_t i = 0; i < pixels.size(); ++i)
    pixels[i] = static_cast<uint8_t>(i);
  absl::StatusOr<fovea::v1::Image> image =
      MakeRawImage(pixels.data(), pixels.size(), 4, 2, "rgb8");
  ASSERT_TRUE(image.ok()) << image.status();
  EXPECT_EQ(image->width(), 4u);
  EXPECT_EQ(image->height(), 2u);
  EXPECT_EQ(image->encoding(), "rgb8");
  EXPECT_EQ(image->step(), 12u);
  EXPECT_FALSE(image->is_bigendian());
  EXPECT_TRUE(image->compressed().empty());
  EXPECT_EQ(image->data(), std::string(pixels.begin(), pixels.end()));
}

TEST(MakeRawImageTest, PaddedRowsAreRepackedTightly) {
  // 3 x 2 16UC1 pixels in rows of 10 bytes (6 pixel bytes + 4 padding); the
  // last row is short, as in a view into a larger image.
  std::vector<uint8_t> buffer(10 + 6, 0xEE);
  const uint16_t values[2][3] = {{1, 2, 3}, {400, 500, 600}};
  std::memcpy(buffer.data(), values[0], 6);
  std::memcpy(buffer.data() + 10, values[1], 6);
  absl::StatusOr<fovea::v1::Image> image =
      MakeRawImage(buffer.data(), buffer.size(), 3, 2, "16UC1", 10);
  ASSERT_TRUE(image.ok()) << image.status();
  EXPECT_EQ(image->step(), 6u);
  ASSERT_EQ(image->data().size(), 12u);
  uint16_t out[2][3];
  std::memcpy(out, image->data().data(), 12);
  EXPECT_EQ(out[0][2], 3);
  EXPECT_EQ(out[1][0], 400);
  EXPECT_EQ(out[1][2], 600);
}

TEST(MakeRawImageTest, BytesPerPixelFollowsEncoding) {
  EXPECT_EQ(BytesPerPixel("rgb8"), 3);
  EXPECT_EQ(BytesPerPixel("bgr8"), 3);
  EXPECT_EQ(BytesPerPixel("16UC1"), 2);
  EXPECT_EQ(BytesPerPixel("32FC1"), 4);
  EXPECT_EQ(BytesPerPixel("mono8"), 0);
  const std::vector<float> depth(5 * 3, 1.5f);
  absl::StatusOr<fovea::v1::Image> image =
      MakeRawImage(depth.data(), depth.size() * sizeof(float), 5, 3, "32FC1");
  ASSERT_TRUE(image.ok()) << image.status();
  EXPECT_EQ(image->step(), 20u);
  EXPECT_EQ(image->data().size(), 60u);
}

TEST(MakeRawImageTest, UnknownEncodingIsNamed) {
  const std::vector<uint8_t> pixels(16);
  absl::StatusOr<fovea::v1::Image> image =
      MakeRawImage(pixels.data(), pixels.size(), 4, 4, "mono8");
  ASSERT_EQ(image.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(image.status().message(), HasSubstr("encoding"));
  EXPECT_THAT(image.status().message(), HasSubstr("mono8"));
}

TEST(MakeRawImageTest, StepShorterThanRowIsRefused) {
  const std::vector<uint8_t> pixels(100);
  absl::StatusOr<fovea::v1::Image> image =
      MakeRawImage(pixels.data(), pixels.size(), 4, 2, "rgb8", 11);
  ASSERT_EQ(image.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(image.status().message(), HasSubstr("step"));
}

TEST(MakeRawImageTest, BufferTooSmallIsRefused) {
  const std::vector<uint8_t> pixels(4 * 2 * 3 - 1);
  absl::StatusOr<fovea::v1::Image> image =
      MakeRawImage(pixels.data(), pixels.size(), 4, 2, "rgb8");
  ASSERT_EQ(image.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(image.status().message(), HasSubstr("data"));
}

TEST(MakeRawImageTest, ZeroSizeIsRefused) {
  const std::vector<uint8_t> pixels(12);
  EXPECT_EQ(
      MakeRawImage(pixels.data(), pixels.size(), 0, 2, "rgb8").status().code(),
      absl::StatusCode::kInvalidArgument);
}

TEST(MakeCompressedImageTest, PngIsSentAsIsWithItsSize) {
  const cv::Mat depth(7, 9, CV_16UC1, cv::Scalar(1234));
  const std::string bytes = Encode(".png", depth);
  absl::StatusOr<CompressedInfo> info = ProbeCompressedImage(bytes);
  ASSERT_TRUE(info.ok()) << info.status();
  EXPECT_EQ(info->format, "png");
  EXPECT_EQ(info->width, 9u);
  EXPECT_EQ(info->height, 7u);
  EXPECT_EQ(info->channels, 1);
  EXPECT_EQ(info->bit_depth, 16);

  absl::StatusOr<fovea::v1::Image> image = MakeCompressedImage(bytes);
  ASSERT_TRUE(image.ok()) << image.status();
  EXPECT_EQ(image->compressed(), bytes);
  EXPECT_TRUE(image->data().empty());
  EXPECT_TRUE(image->encoding().empty());
  EXPECT_EQ(image->step(), 0u);
  EXPECT_EQ(image->width(), 9u);
  EXPECT_EQ(image->height(), 7u);
}

TEST(MakeCompressedImageTest, ColourPngAndJpegAreProbed) {
  const cv::Mat colour(12, 20, CV_8UC3, cv::Scalar(10, 200, 30));
  absl::StatusOr<CompressedInfo> png =
      ProbeCompressedImage(Encode(".png", colour));
  ASSERT_TRUE(png.ok()) << png.status();
  EXPECT_EQ(png->channels, 3);
  EXPECT_EQ(png->bit_depth, 8);
  absl::StatusOr<CompressedInfo> jpeg =
      ProbeCompressedImage(Encode(".jpg", colour));
  ASSERT_TRUE(jpeg.ok()) << jpeg.status();
  EXPECT_EQ(jpeg->format, "jpeg");
  EXPECT_EQ(jpeg->width, 20u);
  EXPECT_EQ(jpeg->height, 12u);
  EXPECT_EQ(jpeg->channels, 3);
}

TEST(MakeCompressedImageTest, OtherBytesAreRefused) {
  absl::StatusOr<fovea::v1::Image> image = MakeCompressedImage("GIF89a....");
  EXPECT_EQ(image.status().code(), absl::StatusCode::kInvalidArgument);
  const std::string truncated_png("\x89PNG\r\n\x1a\n\0\0\0\x0dIH", 14);
  EXPECT_EQ(ProbeCompressedImage(truncated_png).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(MakeFrameTest, CarriesImagesIntrinsicsAndScale) {
  const std::vector<uint8_t> colour(2 * 2 * 3, 7);
  const std::vector<uint16_t> depth(2 * 2, 1000);
  absl::StatusOr<fovea::v1::Image> c =
      MakeRawImage(colour.data(), colour.size(), 2, 2, "bgr8");
  absl::StatusOr<fovea::v1::Image> d =
      MakeRawImage(depth.data(), depth.size() * 2, 2, 2, "16UC1");
  ASSERT_TRUE(c.ok() && d.ok());
  const fovea::v1::Frame frame =
      MakeFrame(*c, *d, MakeIntrinsics(525, 526, 319.5, 239.5), 0.0001);
  EXPECT_EQ(frame.color().encoding(), "bgr8");
  EXPECT_EQ(frame.depth().encoding(), "16UC1");
  EXPECT_EQ(frame.intrinsics().fx(), 525);
  EXPECT_EQ(frame.intrinsics().fy(), 526);
  EXPECT_EQ(frame.intrinsics().cx(), 319.5);
  EXPECT_EQ(frame.intrinsics().cy(), 239.5);
  EXPECT_DOUBLE_EQ(frame.depth_scale(), 0.0001);
}

TEST(ReadFileBytesTest, MissingFileIsNotFound) {
  EXPECT_EQ(ReadFileBytes("/nonexistent/fovea/x.png").status().code(),
            absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace fovea::client
