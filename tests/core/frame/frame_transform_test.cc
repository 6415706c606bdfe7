// RotateFrame / HalveFrame: every pixel's 3D point is the original one,
// rotated about the optical axis or unchanged, so a rolled or smaller
// camera sees the same scene.

#include "core/frame/frame_transform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace fovea {
namespace {

// A 7 x 5 frame whose depth and colour differ at every pixel, with an
// off-centre principal point and unequal focal lengths (so a transform that
// swaps or forgets one shows).
RgbdFrame Ramp() {
  RgbdFrame f;
  f.depth.create(5, 7, CV_32FC1);
  f.color.create(5, 7, CV_8UC3);
  for (int v = 0; v < 5; ++v) {
    for (int u = 0; u < 7; ++u) {
      f.depth.at<float>(v, u) = 1.0f + 0.01f * u + 0.1f * v;
      f.color.at<cv::Vec3b>(v, u) = {static_cast<uchar>(10 * u),
                                     static_cast<uchar>(10 * v), 7};
    }
  }
  f.intrinsics = {500.0, 520.0, 2.3, 1.7};
  return f;
}

cv::Vec3d Point(const RgbdFrame& f, int u, int v) {
  const double z = f.depth.at<float>(v, u);
  const Intrinsics& k = f.intrinsics;
  return {(u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z};
}

TEST(FrameTransformTest, QuarterTurnRotatesEveryPointAboutTheOpticalAxis) {
  const RgbdFrame f = Ramp();
  const RgbdFrame r = RotateFrame(f, 1);
  ASSERT_EQ(r.width(), 5);
  ASSERT_EQ(r.height(), 7);
  for (int v = 0; v < 5; ++v) {
    for (int u = 0; u < 7; ++u) {
      const int ur = 5 - 1 - v, vr = u;
      const cv::Vec3d p = Point(f, u, v);
      const cv::Vec3d q = Point(r, ur, vr);
      EXPECT_NEAR(q[0], -p[1], 1e-9);
      EXPECT_NEAR(q[1], p[0], 1e-9);
      EXPECT_NEAR(q[2], p[2], 1e-9);
      EXPECT_EQ(r.color.at<cv::Vec3b>(vr, ur), f.color.at<cv::Vec3b>(v, u));
    }
  }
}

TEST(FrameTransformTest, EveryTurnKeepsDepthsAndDistances) {
  const RgbdFrame f = Ramp();
  for (int turns : {2, 3, -1, 4}) {
    const RgbdFrame r = RotateFrame(f, turns);
    // The rotated cloud is a rigid rotation about z: each point's distance
    // from the optical axis and its depth are kept, and the multiset of
    // depths is the same.
    double sum_f = 0, sum_r = 0, radius_f = 0, radius_r = 0;
    for (int v = 0; v < f.height(); ++v) {
      for (int u = 0; u < f.width(); ++u) {
        const cv::Vec3d p = Point(f, u, v);
        sum_f += p[2];
        radius_f += std::hypot(p[0], p[1]);
      }
    }
    for (int v = 0; v < r.height(); ++v) {
      for (int u = 0; u < r.width(); ++u) {
        const cv::Vec3d q = Point(r, u, v);
        sum_r += q[2];
        radius_r += std::hypot(q[0], q[1]);
      }
    }
    EXPECT_NEAR(sum_f, sum_r, 1e-6) << turns;
    EXPECT_NEAR(radius_f, radius_r, 1e-9) << turns;
  }
  // Two turns: (u, v) -> (W - 1 - u, H - 1 - v), the point (-x, -y, z).
  const RgbdFrame r = RotateFrame(f, 2);
  const cv::Vec3d p = Point(f, 1, 3);
  const cv::Vec3d q = Point(r, 7 - 1 - 1, 5 - 1 - 3);
  EXPECT_NEAR(q[0], -p[0], 1e-9);
  EXPECT_NEAR(q[1], -p[1], 1e-9);
  // Four turns are none.
  const RgbdFrame same = RotateFrame(f, 4);
  EXPECT_EQ(cv::norm(same.depth, f.depth, cv::NORM_INF), 0.0);
  EXPECT_EQ(same.intrinsics.cx, f.intrinsics.cx);
}

TEST(FrameTransformTest, HalfResolutionKeepsEachSampledPoint) {
  const RgbdFrame f = Ramp();
  const RgbdFrame h = HalveFrame(f);
  ASSERT_EQ(h.width(), 3);
  ASSERT_EQ(h.height(), 2);
  for (int v = 0; v < 2; ++v) {
    for (int u = 0; u < 3; ++u) {
      const cv::Vec3d p = Point(f, 2 * u, 2 * v);
      const cv::Vec3d q = Point(h, u, v);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(q[i], p[i], 1e-9);
    }
  }
  // Colour: the 2 x 2 block's mean (10 * (2u) and 10 * (2u + 1) -> 20u + 5).
  EXPECT_EQ(h.color.at<cv::Vec3b>(1, 2)[0], 45);
  EXPECT_EQ(h.color.at<cv::Vec3b>(1, 2)[1], 25);
}

TEST(FrameTransformTest, LabelsFollowTheirPixels) {
  LabelledFrame f;
  f.name = "learn3";
  f.frame = Ramp();
  f.labels = cv::Mat::zeros(5, 7, CV_32SC1);
  f.labels.at<int>(1, 6) = 20;  // top right
  const LabelledFrame r = RotateLabelledFrame(f, 1);
  EXPECT_EQ(r.name, "learn3-rot90");
  EXPECT_EQ(r.labels.at<int>(6, 5 - 1 - 1), 20);
  EXPECT_EQ(cv::countNonZero(r.labels), 1);
  f.labels.at<int>(2, 4) = 30;
  const LabelledFrame h = HalveLabelledFrame(f);
  EXPECT_EQ(h.name, "learn3-half");
  EXPECT_EQ(h.labels.at<int>(1, 2), 30);
  EXPECT_EQ(cv::countNonZero(h.labels), 1);  // (1, 6) is not sampled
}

}  // namespace
}  // namespace fovea
