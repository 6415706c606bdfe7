#include "core/segmentation/polar_contour.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace fovea {
namespace {

// An edge probability map: uniform noise in [low, high] with the outline
// drawn by `draw` at probability 0.95.
template <typename Draw>
cv::Mat NoisyMapWith(Draw draw, float low = 0.1f, float high = 0.5f,
                     cv::Size size = {320, 240}) {
  cv::Mat p(size, CV_32FC1);
  cv::RNG rng(3);
  rng.fill(p, cv::RNG::UNIFORM, low, high);
  draw(p);
  return p;
}

double IoU(const cv::Mat& a, const cv::Mat& b) {
  const double inter = cv::countNonZero(a & b);
  const double uni = cv::countNonZero(a | b);
  return uni > 0 ? inter / uni : 0.0;
}

cv::Mat Disk(cv::Size size, cv::Point centre, int radius) {
  cv::Mat m(size, CV_8UC1, cv::Scalar(0));
  cv::circle(m, centre, radius, cv::Scalar(255), cv::FILLED);
  return m;
}

TEST(PolarContourTest, FindsTheCircleOfHighEdgeProbabilityAroundTheSeed) {
  const cv::Point centre(160, 120);
  const cv::Mat p = NoisyMapWith(
      [&](cv::Mat& m) { cv::circle(m, centre, 60, cv::Scalar(0.95), 2); });
  // The seed off the centre: the contour is found around the seed, not
  // assumed centred on it.
  absl::StatusOr<cv::Mat> mask = SegmentAtFixation(p, {140, 130}, {});
  ASSERT_TRUE(mask.ok()) << mask.status();
  ASSERT_EQ(mask->type(), CV_8UC1);
  ASSERT_EQ(mask->size(), p.size());
  EXPECT_GT(IoU(*mask, Disk(p.size(), centre, 60)), 0.9);
}

TEST(PolarContourTest, FindsASquare) {
  const cv::Rect square(100, 60, 120, 120);
  const cv::Mat p = NoisyMapWith(
      [&](cv::Mat& m) { cv::rectangle(m, square, cv::Scalar(0.95), 2); });
  absl::StatusOr<cv::Mat> mask = SegmentAtFixation(p, {160, 120}, {});
  ASSERT_TRUE(mask.ok()) << mask.status();
  cv::Mat truth(p.size(), CV_8UC1, cv::Scalar(0));
  truth(square).setTo(255);
  EXPECT_GT(IoU(*mask, truth), 0.9);
}

// A gap of 40 degrees in the outline: the contour bridges it rather than
// leaking out to the image border.
TEST(PolarContourTest, BridgesAGapInTheOutline) {
  const cv::Point centre(160, 120);
  const cv::Mat p = NoisyMapWith([&](cv::Mat& m) {
    cv::ellipse(m, centre, {50, 50}, 0.0, 20.0, 340.0, cv::Scalar(0.95), 2);
  });
  absl::StatusOr<cv::Mat> mask = SegmentAtFixation(p, centre, {});
  ASSERT_TRUE(mask.ok()) << mask.status();
  EXPECT_GT(IoU(*mask, Disk(p.size(), centre, 50)), 0.9);
}

// A small circle of texture edges near the seed is weaker than the object
// outline; the polar cost does not pull the contour onto it for being
// short (Mishra et al. 2009).
TEST(PolarContourTest, PrefersTheStrongOutlineToAWeakInnerRing) {
  const cv::Point centre(160, 120);
  const cv::Mat p = NoisyMapWith([&](cv::Mat& m) {
    cv::circle(m, centre, 80, cv::Scalar(0.95), 2);
    cv::circle(m, centre, 15, cv::Scalar(0.6), 2);
  });
  absl::StatusOr<cv::Mat> mask =
      SegmentAtFixation(p, {centre.x, centre.y + 25}, {});
  ASSERT_TRUE(mask.ok()) << mask.status();
  EXPECT_GT(IoU(*mask, Disk(p.size(), centre, 80)), 0.9);
}

// Past the border the map reads as an edge: an object cut by the image
// border is closed along the border.
TEST(PolarContourTest, ClosesAlongTheImageBorder) {
  const cv::Point centre(300, 120);  // 20 px from the right border
  const cv::Mat p = NoisyMapWith(
      [&](cv::Mat& m) { cv::circle(m, centre, 60, cv::Scalar(0.95), 2); });
  absl::StatusOr<cv::Mat> mask = SegmentAtFixation(p, {280, 120}, {});
  ASSERT_TRUE(mask.ok()) << mask.status();
  EXPECT_GT(IoU(*mask, Disk(p.size(), centre, 60)), 0.9);
}

TEST(PolarContourTest, NaNReadsAsEdge) {
  const cv::Point centre(160, 120);
  cv::Mat p = NoisyMapWith([](cv::Mat&) {});
  // Everything outside a 50 px disk has no data.
  p.setTo(std::numeric_limits<float>::quiet_NaN(), ~Disk(p.size(), centre, 50));
  absl::StatusOr<cv::Mat> mask = SegmentAtFixation(p, centre, {});
  ASSERT_TRUE(mask.ok()) << mask.status();
  EXPECT_GT(IoU(*mask, Disk(p.size(), centre, 50)), 0.9);
}

TEST(PolarContourTest, ContourIsClosedAndWithinTheRadii) {
  const cv::Mat p = NoisyMapWith([](cv::Mat& m) {
    cv::rectangle(m, cv::Rect(90, 80, 150, 70), cv::Scalar(0.95), 2);
  });
  PolarContourOptions options;
  options.angles = 180;
  absl::StatusOr<PolarContour> c = FindPolarContour(p, {150, 110}, options);
  ASSERT_TRUE(c.ok()) << c.status();
  ASSERT_EQ(c->radii.size(), 180u);
  const float dtheta = static_cast<float>(2.0 * M_PI / 180);
  for (size_t a = 0; a < c->radii.size(); ++a) {
    const float r = c->radii[a];
    const float next = c->radii[(a + 1) % c->radii.size()];
    EXPECT_GE(r, options.min_radius_px);
    EXPECT_LE(r, options.max_radius_px);
    // The slope limit holds across the closing step too.
    EXPECT_LE(std::abs(next - r),
              std::max(options.radial_step_px,
                       options.max_slope * std::max(r, next) * dtheta) +
                  1e-3f)
        << "angle " << a;
  }
}

TEST(PolarContourTest, SeedOutsideTheMapIsInvalidArgument) {
  const cv::Mat p(100, 100, CV_32FC1, cv::Scalar(0.5));
  for (const cv::Point seed : {cv::Point(-1, 5), cv::Point(100, 5),
                               cv::Point(5, 100), cv::Point(5, -3)}) {
    EXPECT_EQ(SegmentAtFixation(p, seed, {}).status().code(),
              absl::StatusCode::kInvalidArgument)
        << seed;
  }
  EXPECT_TRUE(SegmentAtFixation(p, {99, 99}, {}).ok());
}

TEST(PolarContourTest, RejectsAMapOfTheWrongType) {
  EXPECT_EQ(SegmentAtFixation(cv::Mat(), {0, 0}, {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(
      SegmentAtFixation(cv::Mat(10, 10, CV_8UC1, cv::Scalar(0)), {5, 5}, {})
          .status()
          .code(),
      absl::StatusCode::kInvalidArgument);
}

TEST(PolarContourTest, InterruptStopsItWithItsStatus) {
  const cv::Mat p = NoisyMapWith([](cv::Mat& m) {
    cv::circle(m, {160, 120}, 60, cv::Scalar(0.95), 2);
  });
  int calls = 0;
  const InterruptCheck cancel_third = [&calls]() {
    return ++calls >= 3 ? absl::CancelledError("stop") : absl::OkStatus();
  };
  absl::StatusOr<cv::Mat> mask =
      SegmentAtFixation(p, {160, 120}, {}, cancel_third);
  EXPECT_EQ(mask.status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(calls, 3);
  // Asked inside the passes, not only once at the start.
  calls = 0;
  const InterruptCheck count = [&calls]() {
    ++calls;
    return absl::OkStatus();
  };
  ASSERT_TRUE(SegmentAtFixation(p, {160, 120}, {}, count).ok());
  EXPECT_GT(calls, 10);
}

TEST(PolarContourTest, ValidateNamesTheBadField) {
  EXPECT_TRUE(Validate(PolarContourOptions{}).ok());
  const auto message = [](auto edit) {
    PolarContourOptions o;
    edit(o);
    const absl::Status s = Validate(o);
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
    return std::string(s.message());
  };
  EXPECT_NE(message([](auto& o) { o.angles = 4; }).find("angles"),
            std::string::npos);
  EXPECT_NE(
      message([](auto& o) { o.radial_step_px = 0.0f; }).find("radial_step_px"),
      std::string::npos);
  EXPECT_NE(
      message([](auto& o) { o.min_radius_px = -1.0f; }).find("min_radius_px"),
      std::string::npos);
  EXPECT_NE(
      message([](auto& o) { o.max_radius_px = 2.0f; }).find("max_radius_px"),
      std::string::npos);
  EXPECT_NE(message([](auto& o) { o.max_slope = 0.0f; }).find("max_slope"),
            std::string::npos);
  EXPECT_NE(message([](auto& o) {
              o.min_probability = std::numeric_limits<float>::quiet_NaN();
            }).find("min_probability"),
            std::string::npos);
  EXPECT_NE(message([](auto& o) {
              o.interrupt_every_angles = 0;
            }).find("interrupt_every_angles"),
            std::string::npos);
  EXPECT_EQ(SegmentAtFixation(cv::Mat(10, 10, CV_32FC1, cv::Scalar(0)), {5, 5},
                              [] {
                                PolarContourOptions o;
                                o.angles = 0;
                                return o;
                              }())
                .status()
                .code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace fovea
