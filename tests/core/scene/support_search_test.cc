// SearchSupport on small rooms built in the test: the support is the
// surface the objects stand on, not the largest plane, and only its
// connected part.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/frame/frame_transform.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/synth/synth_scene.h"

namespace fovea {
namespace {

using Eigen::Vector2f;
using Eigen::Vector3f;

synth::Primitive Box(const Vector3f& centre, const Vector3f& half,
                     const Vector3f& rgb = {0.8f, 0.3f, 0.2f}) {
  synth::Primitive p;
  p.shape = synth::Shape::kBox;
  p.half_extents = half;
  p.pose.translation() = centre;
  p.rgb = rgb;
  return p;
}

// A 1.0 x 0.6 m table top at z = 0 with `objects`, on a floor 0.7 m below
// that fills most of the view, seen from 1.4 m above the floor and 1.2 m
// back.
synth::SceneSpec TableOnFloor(std::vector<synth::Primitive> objects) {
  synth::SceneSpec spec;
  spec.table_half_size = {0.5f, 0.3f};
  spec.objects = std::move(objects);
  spec.background.push_back(
      {Box({0, 0, -0.7f - 0.01f}, {8.0f, 8.0f, 0.01f}, {0.3f, 0.35f, 0.4f}),
       synth::kFloorLabel});
  spec.camera_pose = synth::LookAt({0.0f, -1.2f, 0.7f}, {0.0f, 0.2f, -0.2f});
  return spec;
}

std::vector<synth::Primitive> ThreeBoxes() {
  return {Box({-0.25f, 0.0f, 0.05f}, {0.04f, 0.04f, 0.05f}),
          Box({0.0f, 0.1f, 0.04f}, {0.05f, 0.03f, 0.04f}),
          Box({0.25f, -0.05f, 0.06f}, {0.03f, 0.05f, 0.06f})};
}

OrganizedCloud CloudOf(const synth::SynthScene& scene) {
  OrganizedCloud cloud = BackProject(scene.frame.frame);
  EstimateNormals({}, cloud);
  return cloud;
}

synth::SynthScene Render(const synth::SceneSpec& spec) {
  return synth::RenderScene(spec, synth::KinectV1Noise(), 5);
}

// Share of the chosen inliers that carry `label`, and how many pixels
// with `label` are inliers.
double ShareOfInliersOn(const SupportPlane& plane, const cv::Mat& labels,
                        int label) {
  const int inliers = cv::countNonZero(plane.inliers);
  return inliers > 0 ? static_cast<double>(cv::countNonZero(
                           plane.inliers & (labels == label))) /
                           inliers
                     : 0.0;
}

bool IsTable(const SupportPlane& plane, const synth::SynthScene& scene) {
  return plane.normal.dot(scene.table_normal_camera) > std::cos(0.05f) &&
         std::abs(plane.d - scene.table_d_camera) < 0.01f;
}

TEST(SupportSearchTest, TheTableObjectsStandOnBeatsTheLargerFloor) {
  const synth::SynthScene scene = Render(TableOnFloor(ThreeBoxes()));
  const cv::Mat& labels = scene.frame.labels;
  ASSERT_GT(cv::countNonZero(labels == synth::kFloorLabel),
            cv::countNonZero(labels == synth::kSupportTableLabel));
  absl::StatusOr<SupportSearch> search = SearchSupport(CloudOf(scene), {});
  ASSERT_TRUE(search.ok()) << search.status();
  EXPECT_TRUE(IsTable(search->chosen, scene));
  EXPECT_GT(ShareOfInliersOn(search->chosen, labels, 1), 0.99);
  // The three boxes (a box's faces may split at the grid's depth jumps, so
  // one may count twice); none stands on the floor: the table, its objects
  // and all are one piece of furniture there.
  EXPECT_GE(search->chosen.score.objects, 3);
  EXPECT_LE(search->chosen.score.objects, 6);
  EXPECT_EQ(search->candidates.back().score.objects, 0);
  ASSERT_GE(search->candidates.size(), 2u);  // the floor was a candidate
  EXPECT_EQ(search->chosen.candidate_count,
            static_cast<int>(search->candidates.size()));
  EXPECT_TRUE(search->candidates.back().score.under_another);
  EXPECT_FALSE(search->chosen.given);
}

TEST(SupportSearchTest, ARolledCameraFindsTheSameTableWithoutGravity) {
  // The table scene seen by the same camera turned a quarter, a half and
  // three quarters about its optical axis (a wrist camera turned sideways,
  // a camera mounted upside down): the support is the same table, its
  // normal rotated with the camera ((x, y, z) -> (-y, x, z) per turn).
  const synth::SynthScene scene = Render(TableOnFloor(ThreeBoxes()));
  for (int turns = 1; turns <= 3; ++turns) {
    const RgbdFrame rolled = RotateFrame(scene.frame.frame, turns);
    OrganizedCloud cloud = BackProject(rolled);
    EstimateNormals({}, cloud);
    absl::StatusOr<SupportPlane> plane = FindSupportPlane(cloud, {});
    ASSERT_TRUE(plane.ok()) << turns << ": " << plane.status();
    Eigen::Vector3f n = scene.table_normal_camera;
    for (int t = 0; t < turns; ++t) n = Eigen::Vector3f(-n.y(), n.x(), n.z());
    EXPECT_GT(plane->normal.dot(n), std::cos(0.05f)) << turns;
    EXPECT_LT(std::abs(plane->d - scene.table_d_camera), 0.01f) << turns;
    EXPECT_GE(plane->score.objects, 3) << turns;
  }
}

TEST(SupportSearchTest, AnEmptyTableNearerThanTheFloorIsStillTheSupport) {
  const synth::SynthScene scene = Render(TableOnFloor({}));
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(CloudOf(scene), {});
  ASSERT_TRUE(plane.ok()) << plane.status();
  EXPECT_TRUE(IsTable(*plane, scene));
  EXPECT_EQ(plane->score.objects, 0);
}

TEST(SupportSearchTest, ASecondTableAtTheSameHeightBeyondAGapIsNotPartOfIt) {
  synth::SceneSpec spec = TableOnFloor(ThreeBoxes());
  // 30 cm behind the support, its top at the same height, with two boxes.
  spec.background.push_back({Box({0.0f, 0.3f + 0.3f + 0.25f, -0.015f},
                                 {0.5f, 0.25f, 0.015f}, {0.6f, 0.6f, 0.55f}),
                             synth::kOtherTableLabel});
  spec.background.push_back(
      {Box({-0.2f, 0.85f, 0.05f}, {0.04f, 0.04f, 0.05f}, {0.2f, 0.7f, 0.3f}),
       synth::kOtherObjectLabel});
  spec.background.push_back(
      {Box({0.2f, 0.8f, 0.04f}, {0.04f, 0.04f, 0.04f}, {0.2f, 0.3f, 0.7f}),
       synth::kOtherObjectLabel});
  const synth::SynthScene scene = Render(spec);
  const OrganizedCloud cloud = CloudOf(scene);
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(cloud, {});
  ASSERT_TRUE(plane.ok()) << plane.status();
  EXPECT_TRUE(IsTable(*plane, scene));
  EXPECT_EQ(
      ShareOfInliersOn(*plane, scene.frame.labels, synth::kOtherTableLabel),
      0.0);
  // Nothing on the second table projects inside the support's hull.
  for (int v = 0; v < cloud.height(); ++v) {
    for (int u = 0; u < cloud.width(); ++u) {
      if (scene.frame.labels.at<int>(v, u) != synth::kOtherObjectLabel)
        continue;
      const cv::Vec3f p = cloud.xyz.at<cv::Vec3f>(v, u);
      ASSERT_FALSE(plane->ProjectsInsideHull({p[0], p[1], p[2]}))
          << u << "," << v;
    }
  }
}

TEST(SupportSearchTest, TablePartsSplitByALongBoxJoinTheRegion) {
  // A 1.2 m long box across the whole table hides its middle band from the
  // camera: the table's image falls into a near and a far part.
  synth::SceneSpec spec =
      TableOnFloor({Box({0.0f, 0.0f, 0.12f}, {0.6f, 0.05f, 0.12f})});
  const synth::SynthScene scene = Render(spec);
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(CloudOf(scene), {});
  ASSERT_TRUE(plane.ok()) << plane.status();
  EXPECT_TRUE(IsTable(*plane, scene));
  // Both parts: table pixels above (farther) and below (nearer) the box in
  // the image are inliers.
  const cv::Mat table = scene.frame.labels == synth::kSupportTableLabel;
  const int table_pixels = cv::countNonZero(table);
  EXPECT_GT(cv::countNonZero(plane->inliers & table), 0.9 * table_pixels);
}

TEST(SupportSearchTest, GravityKeepsOnlyPlanesPerpendicularToIt) {
  const synth::SynthScene scene = Render(TableOnFloor(ThreeBoxes()));
  const OrganizedCloud cloud = CloudOf(scene);
  SupportHints hints;
  hints.gravity = -scene.table_normal_camera;
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(cloud, {}, hints);
  ASSERT_TRUE(plane.ok()) << plane.status();
  EXPECT_TRUE(IsTable(*plane, scene));
  EXPECT_LT(plane->score.tilt_deg, 2.0f);
  // Gravity along the camera's optical axis: nothing in view is level.
  hints.gravity = Vector3f::UnitZ();
  EXPECT_EQ(FindSupportPlane(cloud, {}, hints).status().code(),
            absl::StatusCode::kNotFound);
}

TEST(SupportSearchTest, AGivenPlaneSkipsTheSearch) {
  const synth::SynthScene scene = Render(TableOnFloor(ThreeBoxes()));
  SupportHints hints;
  // Either orientation is accepted; the result faces the camera.
  hints.plane = Eigen::Vector4f(
      -scene.table_normal_camera.x(), -scene.table_normal_camera.y(),
      -scene.table_normal_camera.z(), -scene.table_d_camera);
  absl::StatusOr<SupportPlane> plane =
      FindSupportPlane(CloudOf(scene), {}, hints);
  ASSERT_TRUE(plane.ok()) << plane.status();
  EXPECT_TRUE(plane->given);
  EXPECT_TRUE(IsTable(*plane, scene));
  EXPECT_EQ(plane->candidate_count, 1);
  EXPECT_GT(ShareOfInliersOn(*plane, scene.frame.labels, 1), 0.99);
}

TEST(SupportSearchTest, HintsAreValidatedNamingTheField) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  SupportHints hints;
  EXPECT_TRUE(Validate(hints).ok());
  hints.gravity = Vector3f(0.0f, nan, 0.0f);
  EXPECT_NE(Validate(hints).message().find("gravity: must be finite"),
            std::string::npos);
  hints.gravity = Vector3f::Zero();
  EXPECT_NE(Validate(hints).message().find("gravity: must be a unit vector"),
            std::string::npos);
  hints.gravity = Vector3f(0.0f, 2.0f, 0.0f);
  EXPECT_EQ(Validate(hints).code(), absl::StatusCode::kInvalidArgument);
  hints.gravity.reset();
  hints.plane = Eigen::Vector4f(0.0f, -0.5f, 0.0f, 1.0f);
  EXPECT_NE(Validate(hints).message().find("support_plane.normal"),
            std::string::npos);
  hints.plane = Eigen::Vector4f(0.0f, -1.0f, 0.0f, nan);
  EXPECT_NE(Validate(hints).message().find("support_plane.d"),
            std::string::npos);
  // And SearchSupport refuses them.
  const synth::SynthScene scene = Render(TableOnFloor({}));
  EXPECT_EQ(SearchSupport(CloudOf(scene), {}, hints).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(SupportSearchTest, TheNoiseModelWidensTheBandOnlyWhereItIsLarger) {
  // Far table (3 m): with the Kinect's band (max(12 mm, 3 sigma)) at 3 m
  // sigma is 12.9 mm, so the band is 39 mm; a quieter sensor keeps 12 mm.
  SupportPlaneOptions options;
  options.sigma_per_z2 = 0.0f;
  options.sigma0_m = 0.0f;
  const synth::SynthScene scene = Render(TableOnFloor(ThreeBoxes()));
  absl::StatusOr<SupportPlane> quiet =
      FindSupportPlane(CloudOf(scene), options);
  absl::StatusOr<SupportPlane> kinect = FindSupportPlane(CloudOf(scene), {});
  ASSERT_TRUE(quiet.ok() && kinect.ok());
  EXPECT_GE(kinect->inlier_count, quiet->inlier_count);
}

}  // namespace
}  // namespace fovea
