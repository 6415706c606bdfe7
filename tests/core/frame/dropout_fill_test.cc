#include "core/frame/dropout_fill.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace fovea {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kWidth = 80, kHeight = 60;

SensorModel Kinect() {
  return SensorModelFor(SensorKind::kKinectV1, {525, 525, 39.5, 29.5});
}

// A tilted plane z = 1 + 0.002 u (metres) over the whole image, of colour
// `grey`, losing its depth at random with probability `dropout`.
struct Surface {
  cv::Mat color, depth;
};
Surface SpeckledPlane(int grey, double dropout, uint32_t seed) {
  Surface s;
  s.color = cv::Mat(kHeight, kWidth, CV_8UC3, cv::Scalar::all(grey));
  s.depth = cv::Mat(kHeight, kWidth, CV_32FC1);
  std::mt19937 rng(seed);
  std::bernoulli_distribution drop(dropout);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      s.depth.at<float>(v, u) = drop(rng) ? kNaN : 1.0f + 0.002f * u;
    }
  }
  return s;
}

// Fills `s`'s depth in place; the pixels filled, and where when `filled`.
int Fill(Surface& s, cv::Mat* filled = nullptr) {
  absl::StatusOr<FilledDepth> out =
      FillSpeckledDropout({}, Kinect(), s.color, s.depth);
  EXPECT_TRUE(out.ok()) << out.status();
  if (!out.ok()) return 0;
  s.depth = out->depth;
  if (filled != nullptr) *filled = out->filled;
  return out->filled_pixels;
}

int Missing(const cv::Mat& depth) {
  int n = 0;
  depth.forEach<float>([&n](float z, const int*) { n += std::isnan(z); });
  return n;
}

TEST(DropoutFillTest, ADarkSurfaceLosingMostOfItsDepthIsFilledOnItsPlane) {
  Surface s = SpeckledPlane(30, 0.6, 1);
  const int missing = Missing(s.depth);
  ASSERT_GT(missing, kWidth * kHeight / 2);
  cv::Mat filled;
  const int n = Fill(s, &filled);
  EXPECT_EQ(n, cv::countNonZero(filled));
  // All but a few pixels at the image's corners.
  EXPECT_LT(Missing(s.depth), missing / 50) << n << " filled";
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      if (filled.at<uint8_t>(v, u) == 0) continue;
      ASSERT_NEAR(s.depth.at<float>(v, u), 1.0f + 0.002f * u, 1e-4f)
          << u << "," << v;
    }
  }
}

TEST(DropoutFillTest, ABrightSurfaceIsLeftAsTheSensorGaveIt) {
  // The same speckle on a bright surface: a shadow's, not a dark
  // surface's.
  Surface s = SpeckledPlane(200, 0.6, 1);
  const cv::Mat before = s.depth.clone();
  EXPECT_EQ(Fill(s), 0);
  EXPECT_EQ(Missing(s.depth), Missing(before));
}

TEST(DropoutFillTest, AHoleOrAShadowBandWithoutSpeckleStaysEmpty) {
  // A dark surface, whole but for a 6 px wide band and an 8 x 8 hole.
  Surface s = SpeckledPlane(30, 0.0, 1);
  s.depth(cv::Rect(30, 0, 6, kHeight)).setTo(kNaN);
  s.depth(cv::Rect(60, 20, 8, 8)).setTo(kNaN);
  const int missing = Missing(s.depth);
  EXPECT_EQ(Fill(s), 0);
  EXPECT_EQ(Missing(s.depth), missing);
}

TEST(DropoutFillTest, TwoSpeckledSurfacesAtAStepKeepTheirOwnDepths) {
  // Dark and speckled both, 10 cm apart in depth at column 40: no pixel
  // gets a depth between them.
  Surface s = SpeckledPlane(30, 0.6, 2);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 40; u < kWidth; ++u) {
      float& z = s.depth.at<float>(v, u);
      if (!std::isnan(z)) z += 0.1f;
    }
  }
  cv::Mat filled;
  ASSERT_GT(Fill(s, &filled), 0);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      if (filled.at<uint8_t>(v, u) == 0) continue;
      const float plane = 1.0f + 0.002f * u;
      const float z = s.depth.at<float>(v, u);
      ASSERT_TRUE(std::abs(z - plane) < 0.003f ||
                  std::abs(z - plane - 0.1f) < 0.003f)
          << u << "," << v << ": " << z;
    }
  }
}

TEST(DropoutFillTest, AnInterruptStopsItWithItsErrorAndTheDepthUntouched) {
  // A dark plane losing 60 % of its depth (about 2,900 of 4,800 pixels),
  // the interrupt asked after every 100 plane fits: failing at its second
  // call stops the fill there, with its error; the frame's depth is as the
  // sensor gave it.
  Surface s = SpeckledPlane(30, 0.6, 11);
  const cv::Mat before = s.depth.clone();
  DropoutFillOptions options;
  options.fits_per_interrupt_check = 100;
  int calls = 0;
  const InterruptCheck interrupt = [&calls]() {
    return ++calls < 2 ? absl::OkStatus()
                       : absl::DeadlineExceededError("deadline");
  };
  absl::StatusOr<FilledDepth> out =
      FillSpeckledDropout(options, Kinect(), s.color, s.depth, interrupt);
  EXPECT_EQ(out.status().code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(Missing(s.depth), Missing(before));
  // Not interrupted: filled, the interrupt asked once per 100 fits.
  calls = -1000;
  out = FillSpeckledDropout(options, Kinect(), s.color, s.depth, interrupt);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_GT(out->filled_pixels, 2000);
  EXPECT_GE(calls + 1000, out->filled_pixels / 100);
  // With the default (8,192 fits), a frame this small is never asked.
  calls = 0;
  out = FillSpeckledDropout({}, Kinect(), s.color, s.depth, interrupt);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(calls, 0);
}

TEST(DropoutFillTest, BadOptionsNameTheField) {
  DropoutFillOptions options;
  options.half_window = 0;
  EXPECT_NE(Validate(options).message().find("half_window"), std::string::npos);
  options = {};
  options.min_transition_fraction = 1.5f;
  EXPECT_NE(Validate(options).message().find("min_transition_fraction"),
            std::string::npos);
  options = {};
  options.max_luma = 300;
  EXPECT_NE(Validate(options).message().find("max_luma"), std::string::npos);
  options = {};
  options.fits_per_interrupt_check = 0;
  EXPECT_NE(Validate(options).message().find("fits_per_interrupt_check"),
            std::string::npos);
  options = {};
  options.passes = 0;
  EXPECT_NE(Validate(options).message().find("passes"), std::string::npos);
  EXPECT_TRUE(Validate(DropoutFillOptions{}).ok());
}

}  // namespace
}  // namespace fovea
