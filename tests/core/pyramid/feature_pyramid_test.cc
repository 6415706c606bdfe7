#include "core/pyramid/feature_pyramid.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "core/frame/organized_cloud.h"
#include "core/pyramid/cloud_pyramid.h"
#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

constexpr int kWidth = 512, kHeight = 384;

// Pyramid of a fronto-parallel plane at z = 1 m seen by a 512x384 camera.
CloudPyramid PlanePyramid(int width = kWidth, int height = kHeight,
                          CloudPyramidOptions options = {}) {
  const Intrinsics k{400.0, 400.0, (width - 1) / 2.0, (height - 1) / 2.0};
  const OrganizedCloud cloud = BackProject(testing::PlaneFrame(
      Eigen::Vector3f(0.0f, 0.0f, -1.0f), 1.0f, width, height, k));
  absl::StatusOr<CloudPyramid> pyramid = BuildCloudPyramid(cloud, options);
  EXPECT_TRUE(pyramid.ok()) << pyramid.status();
  return *std::move(pyramid);
}

struct Blob {
  cv::Point2f centre;  // level-0 pixels
  float sigma;         // level-0 pixels
  float peak;
};

// A feature map with Gaussian blobs given in level-0 pixel coordinates,
// drawn at the level's scale (pixel-wise maximum of the blobs).
cv::Mat DrawBlobs(const OrganizedCloud& level, const std::vector<Blob>& blobs) {
  const float scale = static_cast<float>(level.width()) / kWidth;
  cv::Mat map = cv::Mat::zeros(level.height(), level.width(), CV_32FC1);
  for (int v = 0; v < map.rows; ++v) {
    for (int u = 0; u < map.cols; ++u) {
      float value = 0.0f;
      for (const Blob& b : blobs) {
        const float du = u - b.centre.x * scale, dv = v - b.centre.y * scale;
        const float s = b.sigma * scale;
        value = std::max(value,
                         b.peak * std::exp(-(du * du + dv * dv) / (2 * s * s)));
      }
      map.at<float>(v, u) = value;
    }
  }
  return map;
}

cv::Point ArgMax(const cv::Mat& map) {
  cv::Point at;
  cv::minMaxLoc(map, nullptr, nullptr, nullptr, &at);
  return at;
}

double Distance(cv::Point a, cv::Point2f b) {
  return std::hypot(a.x - b.x, a.y - b.y);
}

TEST(FeaturePyramidTest, SimpleAndIttiPeakAtASmallBlobInThe3dCloud) {
  const CloudPyramid pyramid = PlanePyramid();
  // A blob 3 cm wide (sigma) around a point of the plane, evaluated on
  // each level's (filtered) 3D points: pixel (300, 120) at z = 1 m.
  const cv::Point2f blob_pixel(300.0f, 120.0f);
  const Eigen::Vector3f centre((300.0f - 255.5f) / 400.0f,
                               (120.0f - 191.5f) / 400.0f, 1.0f);
  const float sigma_m = 0.03f;
  const LevelFeature feature = [&](int, const OrganizedCloud& cloud) {
    cv::Mat map(cloud.height(), cloud.width(), CV_32FC1);
    for (int v = 0; v < map.rows; ++v) {
      for (int u = 0; u < map.cols; ++u) {
        const cv::Vec3f p = cloud.xyz.at<cv::Vec3f>(v, u);
        const float d2 =
            (Eigen::Vector3f(p[0], p[1], p[2]) - centre).squaredNorm();
        map.at<float>(v, u) = std::exp(-d2 / (2 * sigma_m * sigma_m));
      }
    }
    return absl::StatusOr<cv::Mat>(map);
  };
  for (FeaturePyramidKind kind :
       {FeaturePyramidKind::kSimple, FeaturePyramidKind::kItti}) {
    for (MapNormalization norm :
         {MapNormalization::kLin, MapNormalization::kNms,
          MapNormalization::kNlm}) {
      FeaturePyramidOptions options;
      options.kind = kind;
      options.normalization = norm;
      absl::StatusOr<Conspicuity> result =
          BuildConspicuityMap(pyramid, feature, options);
      ASSERT_TRUE(result.ok()) << result.status();
      ASSERT_EQ(result->map.size(), cv::Size(kWidth, kHeight));
      EXPECT_EQ(result->output_level, 4);
      double lo = 0.0, hi = 0.0;
      cv::minMaxLoc(result->map, &lo, &hi);
      EXPECT_GE(lo, 0.0);
      EXPECT_FLOAT_EQ(hi, 1.0f);
      // Output level 4: a 16 px grid, so within half a cell.
      EXPECT_LT(Distance(ArgMax(result->map), blob_pixel), 8.0)
          << "kind " << static_cast<int>(kind) << " norm "
          << static_cast<int>(norm) << " at " << ArgMax(result->map);
    }
  }
}

TEST(FeaturePyramidTest, IttiSuppressesAUniformRegionThatSimpleKeeps) {
  // A small blob plus a large uniformly salient area (u < 200): SIMPLE
  // rates the area's inside as high as the blob; ITTI's centre-surround
  // difference is ~0 inside it and high at the blob.
  const CloudPyramid pyramid = PlanePyramid();
  const Blob blob{{400.0f, 190.0f}, 10.0f, 1.0f};
  const LevelFeature feature = [&](int, const OrganizedCloud& cloud) {
    cv::Mat map = DrawBlobs(cloud, {blob});
    const int edge = 200 * cloud.width() / kWidth;
    map.colRange(0, edge).setTo(1.0f);
    return absl::StatusOr<cv::Mat>(map);
  };
  FeaturePyramidOptions options;
  options.kind = FeaturePyramidKind::kSimple;
  absl::StatusOr<Conspicuity> simple =
      BuildConspicuityMap(pyramid, feature, options);
  options.kind = FeaturePyramidKind::kItti;
  absl::StatusOr<Conspicuity> itti =
      BuildConspicuityMap(pyramid, feature, options);
  ASSERT_TRUE(simple.ok() && itti.ok());
  const cv::Point inside(64, 192);
  EXPECT_GT(simple->map.at<float>(inside), 0.9f);
  EXPECT_LT(itti->map.at<float>(inside), 0.2f);
  // The blob stands out of the region's inside in ITTI, not in SIMPLE.
  // (The region's edge is a centre-surround contrast too, about as strong
  // as the blob, as in Itti's model.)
  const cv::Point blob_pixel(blob.centre);
  EXPECT_GT(itti->map.at<float>(blob_pixel), 0.4f);
  EXPECT_GT(itti->map.at<float>(blob_pixel),
            3.0f * itti->map.at<float>(inside));
  EXPECT_LT(simple->map.at<float>(blob_pixel),
            1.2f * simple->map.at<float>(inside));
}

TEST(FeaturePyramidTest, SumRewardsConsistencyAcrossScalesMaxTheStrongest) {
  // Level 2: A = 1.0, B = 0.6. Level 3: B = 0.6, C = 1.0 (C keeps level 3's
  // LIN scale at 1). SUM (eq. 2.40): A ~ 1.0 < B ~ 1.2. MAX (eq. 2.41):
  // A = 1.0 > B = 0.6.
  const CloudPyramid pyramid = PlanePyramid();
  const Blob a{{128, 96}, 48, 1.0f}, b{{384, 96}, 48, 0.6f},
      c{{256, 300}, 48, 1.0f};
  const LevelFeature feature = [&](int level, const OrganizedCloud& cloud) {
    return absl::StatusOr<cv::Mat>(level == 2 ? DrawBlobs(cloud, {a, b})
                                              : DrawBlobs(cloud, {b, c}));
  };
  FeaturePyramidOptions options;
  options.simple_levels = {2, 3};
  options.output_level = 2;
  options.combination = ScaleCombination::kSum;
  absl::StatusOr<Conspicuity> sum =
      BuildConspicuityMap(pyramid, feature, options);
  options.combination = ScaleCombination::kMax;
  absl::StatusOr<Conspicuity> max =
      BuildConspicuityMap(pyramid, feature, options);
  ASSERT_TRUE(sum.ok() && max.ok());
  const auto at = [](const Conspicuity& r, const Blob& blob) {
    return r.map.at<float>(cv::Point(blob.centre));
  };
  EXPECT_GT(at(*sum, b), at(*sum, a) + 0.1f);
  EXPECT_NEAR(at(*sum, b), 1.0f, 0.02f);
  EXPECT_GT(at(*max, a), at(*max, b) + 0.3f);
  EXPECT_NEAR(at(*max, b), 0.6f, 0.02f);
}

TEST(FeaturePyramidTest, MissingLevelsAndPairsAreSkipped) {
  int calls = 0;
  const LevelFeature feature = [&](int, const OrganizedCloud& cloud) {
    ++calls;
    return absl::StatusOr<cv::Mat>(
        DrawBlobs(cloud, {{{256.0f, 192.0f}, 20.0f, 1.0f}}));
  };
  // 512x384 with min_size 4: levels 0..6 (level 7 would be 4x3).
  const CloudPyramid pyramid = PlanePyramid();
  ASSERT_EQ(pyramid.size(), 7);
  FeaturePyramidOptions options;
  options.kind = FeaturePyramidKind::kItti;
  absl::StatusOr<Conspicuity> itti =
      BuildConspicuityMap(pyramid, feature, options);
  ASSERT_TRUE(itti.ok()) << itti.status();
  ASSERT_EQ(itti->scales.size(), 3u);  // (2,5), (2,6), (3,6)
  EXPECT_EQ(itti->scales[0].centre, 2);
  EXPECT_EQ(itti->scales[0].surround, 5);
  EXPECT_EQ(itti->scales[2].centre, 3);
  EXPECT_EQ(itti->scales[2].surround, 6);
  EXPECT_EQ(calls, 4);  // levels 2, 3, 5, 6, each once

  // 64x48: levels 0..3. No ITTI pair fits; SIMPLE uses 0..3 and combines
  // at level 3, the deepest.
  const CloudPyramid small = PlanePyramid(64, 48);
  ASSERT_EQ(small.size(), 4);
  EXPECT_EQ(BuildConspicuityMap(small, feature, options).status().code(),
            absl::StatusCode::kFailedPrecondition);
  options.kind = FeaturePyramidKind::kSimple;
  absl::StatusOr<Conspicuity> simple =
      BuildConspicuityMap(small, feature, options);
  ASSERT_TRUE(simple.ok()) << simple.status();
  EXPECT_EQ(simple->scales.size(), 4u);
  EXPECT_EQ(simple->output_level, 3);
  EXPECT_EQ(simple->map.size(), cv::Size(64, 48));
}

TEST(FeaturePyramidTest, ResamplingKeepsThePyramidGeometry) {
  // An impulse at level-3 pixel (5, 4) lands on level-0 pixel (40, 32).
  const CloudPyramid pyramid = PlanePyramid();
  cv::Mat impulse = cv::Mat::zeros(pyramid.levels[3].height(),
                                   pyramid.levels[3].width(), CV_32FC1);
  impulse.at<float>(4, 5) = 1.0f;
  absl::StatusOr<cv::Mat> up = ResampleBetweenLevels(impulse, 3, 0, pyramid);
  ASSERT_TRUE(up.ok()) << up.status();
  EXPECT_EQ(ArgMax(*up), cv::Point(40, 32));
  absl::StatusOr<cv::Mat> down = ResampleBetweenLevels(*up, 0, 3, pyramid);
  ASSERT_TRUE(down.ok());
  EXPECT_EQ(ArgMax(*down), cv::Point(5, 4));
}

TEST(FeaturePyramidTest, ZeroFeatureGivesZeroMapAndErrorsPropagate) {
  const CloudPyramid pyramid = PlanePyramid(128, 96);
  FeaturePyramidOptions options;
  options.normalization = MapNormalization::kNms;
  const LevelFeature zero = [](int, const OrganizedCloud& cloud) {
    return absl::StatusOr<cv::Mat>(
        cv::Mat::zeros(cloud.height(), cloud.width(), CV_32FC1));
  };
  absl::StatusOr<Conspicuity> result =
      BuildConspicuityMap(pyramid, zero, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(cv::countNonZero(result->map), 0);

  const LevelFeature wrong_size = [](int, const OrganizedCloud&) {
    return absl::StatusOr<cv::Mat>(cv::Mat::zeros(3, 3, CV_32FC1));
  };
  absl::Status status =
      BuildConspicuityMap(pyramid, wrong_size, options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("level 0"), std::string::npos) << status;

  const LevelFeature failing = [](int, const OrganizedCloud&) {
    return absl::StatusOr<cv::Mat>(absl::DeadlineExceededError("late"));
  };
  EXPECT_EQ(BuildConspicuityMap(pyramid, failing, options).status().code(),
            absl::StatusCode::kDeadlineExceeded);

  options.itti_deltas = {};
  status = BuildConspicuityMap(pyramid, zero, options).status();
  EXPECT_NE(status.message().find("itti_deltas"), std::string::npos) << status;
}

}  // namespace
}  // namespace fovea
