#include "core/frame/frame_scale.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/frame/organized_cloud.h"

namespace fovea {
namespace {

// A 1280 x 720 frame of a slanted plane, colour a horizontal gradient.
RgbdFrame WideFrame() {
  RgbdFrame frame;
  frame.intrinsics = {920.0, 920.0, 639.5, 359.5};
  frame.color = cv::Mat(720, 1280, CV_8UC3);
  frame.depth = cv::Mat(720, 1280, CV_32FC1);
  for (int v = 0; v < 720; ++v) {
    for (int u = 0; u < 1280; ++u) {
      frame.color.at<cv::Vec3b>(v, u) = cv::Vec3b(u / 5, 0, 0);
      frame.depth.at<float>(v, u) = 1.0f + 0.0005f * v;
    }
  }
  return frame;
}

TEST(FrameScaleTest, NarrowFramesAreNotTouched) {
  RgbdFrame frame = WideFrame();
  const ReducedFrame same = ReduceForProcessing(frame, 1280);
  EXPECT_FALSE(same.scale.reduced());
  EXPECT_EQ(same.frame.depth.data, frame.depth.data);  // shared pixels
  EXPECT_EQ(same.scale.ToInput({7, 9}), cv::Point(7, 9));
}

TEST(FrameScaleTest, HalfSizeKeepsTheGeometry) {
  const RgbdFrame frame = WideFrame();
  const ReducedFrame half = ReduceForProcessing(frame, 640);
  ASSERT_TRUE(half.scale.reduced());
  EXPECT_EQ(half.frame.depth.size(), cv::Size(640, 360));
  EXPECT_DOUBLE_EQ(half.frame.intrinsics.fx, 460.0);
  EXPECT_DOUBLE_EQ(half.frame.intrinsics.cx, 319.5);
  // The reduced pixel and the input pixel it was taken from back-project
  // to the same point.
  const OrganizedCloud big = BackProject(frame);
  const OrganizedCloud small = BackProject(half.frame);
  for (const cv::Point q :
       {cv::Point(0, 0), cv::Point(320, 180), cv::Point(639, 359)}) {
    const cv::Point p = half.scale.ToInput(q);
    const cv::Vec3f a = small.xyz.at<cv::Vec3f>(q),
                    b = big.xyz.at<cv::Vec3f>(p);
    EXPECT_NEAR(cv::norm(a - b), 0.0, 0.002) << q;
    EXPECT_EQ(half.scale.ToProcessing(p), q);
  }
}

TEST(FrameScaleTest, MasksComeBackAtTheInputSizeCoveringTheSamePlace) {
  const ReducedFrame half = ReduceForProcessing(WideFrame(), 640);
  cv::Mat mask(360, 640, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(100, 50, 40, 20)).setTo(255);
  const cv::Mat big = half.scale.MaskToInput(mask);
  ASSERT_EQ(big.size(), cv::Size(1280, 720));
  EXPECT_EQ(cv::countNonZero(big), 4 * 40 * 20);
  EXPECT_EQ(cv::boundingRect(big), cv::Rect(200, 100, 80, 40));
}

TEST(FrameScaleTest, NonIntegerFactorsStayInsideTheImage) {
  RgbdFrame frame = WideFrame();
  const ReducedFrame r = ReduceForProcessing(frame, 500);
  EXPECT_EQ(r.frame.depth.cols, 500);
  EXPECT_EQ(r.frame.depth.rows, 281);
  EXPECT_EQ(r.scale.ToInput({499, 280}).x <= 1279, true);
  EXPECT_EQ(r.scale.ToProcessing({1279, 719}), cv::Point(499, 280));
  EXPECT_EQ(
      r.scale.MaskToInput(cv::Mat(281, 500, CV_8UC1, cv::Scalar(255))).size(),
      cv::Size(1280, 720));
}

}  // namespace
}  // namespace fovea
