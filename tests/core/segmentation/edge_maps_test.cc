#include "core/segmentation/edge_maps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/frame/organized_cloud.h"
#include "core/synth/synth_scene.h"
#include "tests/core/testing/scenes.h"

namespace fovea {
namespace {

OrganizedCloud CloudOf(const RgbdFrame& frame) {
  absl::StatusOr<OrganizedCloud> cloud = BuildOrganizedCloud(frame, {});
  EXPECT_TRUE(cloud.ok()) << cloud.status();
  return cloud.ok() ? *std::move(cloud) : OrganizedCloud{};
}

// Pixels of `where` (CV_8UC1, non-zero) at which `map` is defined.
std::vector<float> ValuesAt(const cv::Mat& map, const cv::Mat& where) {
  std::vector<float> values;
  for (int v = 0; v < map.rows; ++v) {
    for (int u = 0; u < map.cols; ++u) {
      const float x = map.at<float>(v, u);
      if (where.at<uint8_t>(v, u) != 0 && !std::isnan(x)) values.push_back(x);
    }
  }
  return values;
}

float Median(std::vector<float> values) {
  if (values.empty()) return std::numeric_limits<float>::quiet_NaN();
  std::nth_element(values.begin(), values.begin() + values.size() / 2,
                   values.end());
  return values[values.size() / 2];
}

float Percentile(std::vector<float> values, double q) {
  if (values.empty()) return std::numeric_limits<float>::quiet_NaN();
  const size_t k = static_cast<size_t>(q * (values.size() - 1));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

// A box standing on the table seen from in front and above, without noise:
// its silhouette against the table behind it is a depth jump, its foot on
// the table a concave crease, its top a plane.
class BoxOnTableEdgesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = testing::BoxOnTable(Eigen::Vector3f(0.08f, 0.06f, 0.05f));
    cloud_ = CloudOf(scene_.frame.frame);
    maps_ = ComputeEdgeMaps(cloud_, EdgeMapOptions{});
    const cv::Mat& labels = scene_.frame.labels;
    box_ = labels >= 20;
    table_ = labels == 1;
    height_ = testing::HeightAboveTable(scene_);
  }

  // Pixels of `a` with a pixel of `b` within `r` px.
  static cv::Mat Touching(const cv::Mat& a, const cv::Mat& b, int r) {
    cv::Mat near;
    cv::dilate(
        b, near,
        cv::getStructuringElement(cv::MORPH_RECT, {2 * r + 1, 2 * r + 1}));
    return a & near;
  }

  synth::SynthScene scene_;
  OrganizedCloud cloud_;
  EdgeMaps maps_;
  cv::Mat box_, table_, height_;
};

TEST_F(BoxOnTableEdgesTest, MapsHaveTheCloudsSizeAndType) {
  for (const cv::Mat* m : {&maps_.color, &maps_.depth, &maps_.curvature}) {
    EXPECT_EQ(m->type(), CV_32FC1);
    EXPECT_EQ(m->size(), cloud_.xyz.size());
  }
}

TEST_F(BoxOnTableEdgesTest, DepthEdgeIsHighOnTheSilhouetteAndLowOnTheTop) {
  // Silhouette: box pixels next to table pixels more than 3 cm behind them
  // (the top edge of the box against the table beyond it).
  cv::Mat silhouette(box_.size(), CV_8UC1, cv::Scalar(0));
  const cv::Mat& depth = scene_.frame.frame.depth;
  for (int v = 1; v + 1 < box_.rows; ++v) {
    for (int u = 1; u + 1 < box_.cols; ++u) {
      if (!box_.at<uint8_t>(v, u)) continue;
      for (const cv::Point d : {cv::Point(0, -1), cv::Point(-1, 0),
                                cv::Point(1, 0), cv::Point(0, 1)}) {
        if (table_.at<uint8_t>(v + d.y, u + d.x) &&
            depth.at<float>(v + d.y, u + d.x) > depth.at<float>(v, u) + 0.03f) {
          silhouette.at<uint8_t>(v, u) = 255;
        }
      }
    }
  }
  ASSERT_GT(cv::countNonZero(silhouette), 50);
  // The top face, away from its edges.
  cv::Mat top = box_ & (height_ > 0.095f);
  cv::erode(top, top, cv::Mat::ones(9, 9, CV_8UC1));
  ASSERT_GT(cv::countNonZero(top), 200);
  const float on_silhouette = Median(ValuesAt(maps_.depth, silhouette));
  const float on_top = Percentile(ValuesAt(maps_.depth, top), 0.95);
  // The jump is about 20-30 % of the depth; the top's slope reads well
  // under 2 %.
  EXPECT_GT(on_silhouette, 0.1f);
  EXPECT_LT(on_top, 0.02f);
}

TEST_F(BoxOnTableEdgesTest, CurvatureEdgeIsHighAtTheFootAndLowOnTheTop) {
  // The foot: box pixels within 2 px of the table, less than 2 cm above
  // it (no depth jump there, the faces meet).
  const cv::Mat foot = Touching(box_, table_, 2) & (height_ < 0.02f);
  ASSERT_GT(cv::countNonZero(foot), 50);
  // Pairs reach 6 px and normals are smoothed over about 5 px: the top
  // face farther than that from its rims.
  cv::Mat top = box_ & (height_ > 0.095f);
  cv::erode(top, top, cv::Mat::ones(25, 25, CV_8UC1));
  const std::vector<float> at_foot = ValuesAt(maps_.curvature, foot);
  const std::vector<float> on_top = ValuesAt(maps_.curvature, top);
  ASSERT_GT(at_foot.size(), 50u);
  ASSERT_GT(on_top.size(), 100u);
  // A 90 degree fold: the pair straddling it sees most of the 90 degrees.
  EXPECT_GT(Median(at_foot), 0.3f);
  std::vector<float> abs_top;
  for (const float x : on_top) abs_top.push_back(std::abs(x));
  // The top reads 0 but for its back rows, whose normals the smoothing
  // pulls towards the table behind the silhouette.
  EXPECT_LT(Percentile(abs_top, 0.5), 1e-3f);
  EXPECT_LT(Percentile(abs_top, 0.9), 0.01f);
}

TEST_F(BoxOnTableEdgesTest, CurvatureSignTellsConcaveFootFromConvexRim) {
  // The rim between the front and the top face: box pixels within 3 px of
  // the top's height (there is no table near them).
  const cv::Mat rim = box_ & (height_ > 0.09f) & (height_ < 0.099f) &
                      ~Touching(box_, table_, 6);
  const cv::Mat foot = Touching(box_, table_, 2) & (height_ < 0.02f);
  ASSERT_GT(cv::countNonZero(rim), 50);
  EXPECT_LT(Median(ValuesAt(maps_.curvature, rim)), -0.05f);
  EXPECT_GT(Median(ValuesAt(maps_.curvature, foot)), 0.05f);

  EdgeMapOptions unsigned_options;
  unsigned_options.signed_curvature = false;
  const EdgeMaps unsigned_maps = ComputeEdgeMaps(cloud_, unsigned_options);
  EXPECT_GT(Median(ValuesAt(unsigned_maps.curvature, rim)), 0.05f);
}

TEST_F(BoxOnTableEdgesTest, MapsAreNaNWhereTheirInputIsMissing) {
  int normals = 0, curvatures = 0;
  for (int v = 0; v < box_.rows; ++v) {
    for (int u = 0; u < box_.cols; ++u) {
      ASSERT_EQ(std::isnan(maps_.depth.at<float>(v, u)),
                !cloud_.HasPoint(u, v));
      const bool has_curvature = !std::isnan(maps_.curvature.at<float>(v, u));
      // A curvature needs the pixel's normal and a pair of normals.
      if (has_curvature) {
        ASSERT_TRUE(cloud_.HasNormal(u, v));
      }
      normals += cloud_.HasNormal(u, v);
      curvatures += has_curvature;
      ASSERT_FALSE(std::isnan(maps_.color.at<float>(v, u)));
    }
  }
  EXPECT_GT(curvatures, 0.95 * normals);
}

// A flat plane half red, half blue: the colour edge reads the step at the
// boundary and nothing on either side; depth and curvature see nothing.
TEST(EdgeMapsTest, ColourEdgeIsHighAtAColourBoundaryOnly) {
  RgbdFrame frame =
      testing::PlaneFrame(Eigen::Vector3f(0.0f, 0.0f, -1.0f), 1.0f);
  const int boundary = frame.color.cols / 2;
  frame.color.colRange(0, boundary).setTo(cv::Scalar(200, 30, 30));
  frame.color.colRange(boundary, frame.color.cols)
      .setTo(cv::Scalar(30, 30, 200));
  const OrganizedCloud cloud = CloudOf(frame);
  const EdgeMaps maps = ComputeEdgeMaps(cloud, EdgeMapOptions{});
  const int v = frame.color.rows / 2;
  float at_boundary = 0.0f;
  for (int u = boundary - 2; u <= boundary + 1; ++u) {
    at_boundary = std::max(at_boundary, maps.color.at<float>(v, u));
  }
  // Red and blue differ by far more than 50 in every 8-bit Lab channel
  // but L.
  EXPECT_GT(at_boundary, 50.0f);
  EXPECT_LT(maps.color.at<float>(v, boundary - 10), 0.5f);
  EXPECT_LT(maps.color.at<float>(v, boundary + 10), 0.5f);
  EXPECT_LT(maps.depth.at<float>(v, boundary), 0.01f);
  EXPECT_LT(std::abs(maps.curvature.at<float>(v, boundary)), 0.01f);
}

// SD is normalised by depth: the same fractional jump reads the same near
// and far.
TEST(EdgeMapsTest, DepthEdgeReadsTheJumpFractionAtAnyRange) {
  for (const float z : {0.6f, 1.5f}) {
    RgbdFrame frame =
        testing::PlaneFrame(Eigen::Vector3f(0.0f, 0.0f, -1.0f), z);
    const int boundary = frame.depth.cols / 2;
    frame.depth.colRange(boundary, frame.depth.cols)
        .setTo(cv::Scalar(z * 1.1f));
    const EdgeMaps maps = ComputeEdgeMaps(CloudOf(frame), EdgeMapOptions{});
    const int v = frame.depth.rows / 2;
    float peak = 0.0f;
    for (int u = boundary - 3; u <= boundary + 3; ++u) {
      peak = std::max(peak, maps.depth.at<float>(v, u));
    }
    EXPECT_NEAR(peak, 0.1f, 0.01f) << "z = " << z;
    EXPECT_LT(maps.depth.at<float>(v, boundary - 10), 1e-3f);
  }
}

TEST(EdgeMapsTest, EmptyCloudGivesEmptyMaps) {
  const EdgeMaps maps = ComputeEdgeMaps(OrganizedCloud{}, EdgeMapOptions{});
  EXPECT_TRUE(maps.color.empty());
  EXPECT_TRUE(maps.depth.empty());
  EXPECT_TRUE(maps.curvature.empty());
}

TEST(EdgeMapsTest, ValidateNamesTheBadField) {
  EXPECT_TRUE(Validate(EdgeMapOptions{}).ok());
  EdgeMapOptions o;
  o.sobel_aperture = 4;
  EXPECT_NE(Validate(o).message().find("sobel_aperture"),
            absl::string_view::npos);
  o = {};
  o.color_blur_sigma_px = -1.0f;
  EXPECT_NE(Validate(o).message().find("color_blur_sigma_px"),
            absl::string_view::npos);
  o = {};
  o.depth_radius_px = 0;
  EXPECT_NE(Validate(o).message().find("depth_radius_px"),
            absl::string_view::npos);
  o = {};
  o.curvature_radius_px = 17;
  EXPECT_EQ(Validate(o).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(Validate(o).message().find("curvature_radius_px"),
            absl::string_view::npos);
}

}  // namespace
}  // namespace fovea
