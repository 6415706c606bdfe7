#include "core/base/lab.h"

#include <thread>
#include <vector>

#include "gtest/gtest.h"

namespace fovea {
namespace {

// The first Lab conversion of the process happens on several threads at
// once, the case in which OpenCV 4.6 builds its tables twice and loses one
// set. Under AddressSanitizer (scripts/test --sanitize address) the leak
// checker fails this test if RgbToLab lets that happen; in every build the
// concurrent results must equal a plain conversion made afterwards.
TEST(RgbToLabTest, ConcurrentFirstUseGivesPlainCvtColorResults) {
  cv::Mat rgb8(48, 64, CV_8UC3);
  cv::randu(rgb8, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::Mat rgb32;
  rgb8.convertTo(rgb32, CV_32FC3, 1.0 / 255.0);

  constexpr int kThreads = 4;
  std::vector<cv::Mat> lab8(kThreads), lab32(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      RgbToLab(rgb8, &lab8[t]);
      RgbToLab(rgb32, &lab32[t]);
    });
  }
  for (std::thread& thread : threads) thread.join();

  cv::Mat expected8, expected32;
  cv::cvtColor(rgb8, expected8, cv::COLOR_RGB2Lab);
  cv::cvtColor(rgb32, expected32, cv::COLOR_RGB2Lab);
  for (int t = 0; t < kThreads; ++t) {
    ASSERT_EQ(lab8[t].type(), CV_8UC3);
    ASSERT_EQ(lab32[t].type(), CV_32FC3);
    EXPECT_EQ(cv::norm(lab8[t], expected8, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(lab32[t], expected32, cv::NORM_INF), 0.0);
  }
  // A known colour: white is L = 100, a = b = 0 in float Lab.
  cv::Mat white_lab;
  RgbToLab(cv::Mat(1, 1, CV_32FC3, cv::Scalar(1, 1, 1)), &white_lab);
  const cv::Vec3f white = white_lab.at<cv::Vec3f>(0, 0);
  EXPECT_NEAR(white[0], 100.0f, 0.01f);
  EXPECT_NEAR(white[1], 0.0f, 0.01f);
  EXPECT_NEAR(white[2], 0.0f, 0.01f);
}

}  // namespace
}  // namespace fovea
