// The part of a frame segmented again when only some of it changed
// (core/track/region.h), on hand-made masks and boxes.

#include "core/track/region.h"

#include <gtest/gtest.h>

#include <vector>

namespace fovea {
namespace {

cv::Mat Changed(cv::Size size, const cv::Rect& where) {
  cv::Mat changed(size, CV_8UC1, cv::Scalar(0));
  changed(where).setTo(255);
  return changed;
}

TEST(Region, TheChangeGrownByTheMarginAndToTheSmallestSize) {
  RegionOptions options;  // margin 16, at least 160 x 120 at 640 wide
  const cv::Mat changed = Changed({640, 480}, {300, 200, 20, 20});
  const std::optional<cv::Rect> region = RegionToSegment(changed, {}, options);
  ASSERT_TRUE(region.has_value());
  // 20 + 2 x 16 = 52 px, grown about its centre (310, 210) to 160 x 120.
  EXPECT_EQ(*region, cv::Rect(230, 150, 160, 120));
  // A 1280-wide frame: the margin and the smallest size scale with it.
  const cv::Mat wide = Changed({1280, 960}, {600, 400, 400, 300});
  EXPECT_EQ(*RegionToSegment(wide, {}, options), cv::Rect(568, 368, 464, 364));
}

TEST(Region, HeldObjectsItOverlapsComeInWholeOneAfterAnother) {
  RegionOptions options;
  options.margin_px = 0;
  options.min_size = {1, 1};
  const cv::Mat changed = Changed({640, 480}, {100, 100, 10, 10});
  // The first overlaps the change; the second only the first; the third
  // neither.
  const std::vector<cv::Rect> held = {
      {300, 300, 40, 40}, {105, 105, 30, 30}, {130, 130, 20, 20}};
  const std::optional<cv::Rect> region =
      RegionToSegment(changed, held, options);
  ASSERT_TRUE(region.has_value());
  EXPECT_EQ(*region, cv::Rect(100, 100, 50, 50));
  EXPECT_TRUE((*region & held[0]).empty());
}

TEST(Region, NoneWhenNothingChangedOrTooMuch) {
  const RegionOptions options;  // at most half the frame
  EXPECT_FALSE(
      RegionToSegment(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)), {}, options)
          .has_value());
  EXPECT_FALSE(RegionToSegment(cv::Mat(), {}, options).has_value());
  EXPECT_FALSE(
      RegionToSegment(Changed({640, 480}, {0, 0, 500, 300}), {}, options)
          .has_value());
  // A small change that takes in an object held over most of the frame.
  EXPECT_FALSE(RegionToSegment(Changed({640, 480}, {10, 10, 4, 4}),
                               {{0, 0, 600, 400}}, options)
                   .has_value());
}

TEST(Region, ACutOutSeesThePointsTheFrameSeesAndItsObjectsGoBack) {
  RgbdFrame frame;
  frame.depth = cv::Mat(48, 64, CV_32FC1, cv::Scalar(1.0f));
  frame.color = cv::Mat(48, 64, CV_8UC3, cv::Scalar(1, 2, 3));
  frame.depth.at<float>(20, 30) = 2.0f;
  frame.intrinsics = {50.0, 50.0, 31.5, 23.5};
  const cv::Rect region(10, 12, 32, 24);
  const RgbdFrame crop = CropFrame(frame, region);
  ASSERT_EQ(crop.depth.size(), region.size());
  ASSERT_EQ(crop.color.size(), region.size());
  EXPECT_EQ(crop.depth.at<float>(20 - 12, 30 - 10), 2.0f);
  // The ray through the crop's pixel is the frame's: (u - cx) / fx alike.
  EXPECT_DOUBLE_EQ((20 - crop.intrinsics.cx) / crop.intrinsics.fx,
                   (30 - frame.intrinsics.cx) / frame.intrinsics.fx);
  EXPECT_DOUBLE_EQ((8 - crop.intrinsics.cy) / crop.intrinsics.fy,
                   (20 - frame.intrinsics.cy) / frame.intrinsics.fy);

  SegmentedObject o;
  o.mask = cv::Mat(region.size(), CV_8UC1, cv::Scalar(0));
  o.box = cv::Rect(4, 5, 6, 7);
  o.mask(o.box).setTo(255);
  o.seed.u = 6;
  o.seed.v = 8;
  o.point_indices = {1, 2, 3};
  ObjectToFrame(region, frame.depth.size(), o);
  ASSERT_EQ(o.mask.size(), frame.depth.size());
  EXPECT_EQ(o.box, cv::Rect(14, 17, 6, 7));
  EXPECT_EQ(cv::countNonZero(o.mask(o.box)), 42);
  EXPECT_EQ(cv::countNonZero(o.mask), 42);
  EXPECT_EQ(o.seed.u, 16);
  EXPECT_EQ(o.seed.v, 20);
  EXPECT_TRUE(o.point_indices.empty());  // the crop's, not the frame's
}

TEST(Region, OnlyAnInnerBorderMayCutAnObject) {
  const cv::Size frame(640, 480);
  // A region in the middle: every border is inner.
  const cv::Rect middle(100, 100, 200, 150);
  EXPECT_FALSE(ReachesInnerBorder({1, 1, 50, 50}, middle, frame));
  EXPECT_TRUE(ReachesInnerBorder({0, 10, 50, 50}, middle, frame));
  EXPECT_TRUE(ReachesInnerBorder({150, 10, 50, 50}, middle, frame));
  EXPECT_TRUE(ReachesInnerBorder({10, 100, 50, 50}, middle, frame));
  // A region at the frame's top-left corner: its left and top borders
  // are the frame's.
  const cv::Rect corner(0, 0, 200, 150);
  EXPECT_FALSE(ReachesInnerBorder({0, 0, 50, 50}, corner, frame));
  EXPECT_TRUE(ReachesInnerBorder({0, 0, 200, 50}, corner, frame));
}

}  // namespace
}  // namespace fovea
