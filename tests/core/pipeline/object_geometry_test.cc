#include "core/pipeline/object_geometry.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/synth/synth_scene.h"

namespace fovea {
namespace {

constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);

// One primitive standing on the table (world z = 0 up), seen from above
// and in front as a Kinect on a robot would; Kinect noise. What the test
// needs: the object's points (its ground-truth label), the support plane
// the pipeline finds, and the truth in the camera frame.
struct Rendered {
  std::vector<Eigen::Vector3f> points;
  SupportPlane plane;
  Eigen::Isometry3f world_to_camera;
};

Rendered RenderOne(const synth::Primitive& object, uint64_t seed,
                   const std::vector<synth::Primitive>& others = {}) {
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.1f, -0.7f, 0.65f}, {0.0f, 0.0f, 0.05f});
  spec.objects.push_back(object);
  for (const synth::Primitive& other : others) spec.objects.push_back(other);
  const synth::SynthScene scene =
      synth::RenderScene(spec, synth::NoiseOptions{}, seed);
  Rendered r;
  r.world_to_camera = spec.camera_pose.inverse();
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  EXPECT_TRUE(cloud.ok()) << cloud.status();
  absl::StatusOr<SupportPlane> plane = FindSupportPlane(*cloud, {});
  EXPECT_TRUE(plane.ok()) << plane.status();
  if (plane.ok()) r.plane = *plane;
  const cv::Mat& labels = scene.frame.labels;
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      if (labels.at<int>(v, u) != 20) continue;  // the first object
      const cv::Vec3f& p = cloud->xyz.at<cv::Vec3f>(v, u);
      if (!std::isnan(p[2])) r.points.emplace_back(p[0], p[1], p[2]);
    }
  }
  return r;
}

synth::Primitive Box(const Eigen::Vector3f& half, float yaw_deg,
                     const Eigen::Vector2f& at) {
  synth::Primitive box;
  box.shape = synth::Shape::kBox;
  box.half_extents = half;
  box.pose = Eigen::Translation3f(at.x(), at.y(), half.z()) *
             Eigen::AngleAxisf(yaw_deg * kDegToRad, Eigen::Vector3f::UnitZ());
  return box;
}

// The angle between two directions, ignoring their sign (a box's length
// axis points either way), degrees.
float AxisAngleDeg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  const float c = std::min(1.0f, std::abs(a.normalized().dot(b.normalized())));
  return std::acos(c) / kDegToRad;
}

// Boxes at several yaws: the box's vertical axis is the table's normal,
// its length axis the true one within 4 degrees, its size within 1.5 cm
// (Kinect noise at 0.9 m is 1-2 mm; the silhouette's flying pixels are
// trimmed), its base on the table and its centre within 1.5 cm.
TEST(ObjectGeometryTest, BoxesAtAnyYawGiveTheirPoseAndSize) {
  const Eigen::Vector3f half(0.07f, 0.035f, 0.05f);
  float worst_angle = 0.0f, worst_size = 0.0f, worst_centre = 0.0f;
  for (const float yaw : {0.0f, 20.0f, 45.0f, 70.0f, 110.0f}) {
    const synth::Primitive box = Box(half, yaw, {0.02f, 0.03f});
    const Rendered r = RenderOne(box, static_cast<uint64_t>(yaw) + 1);
    ASSERT_GT(r.points.size(), 1000u) << yaw;
    absl::StatusOr<ObjectGeometry> g = FitSupportAlignedBox(r.points, r.plane);
    ASSERT_TRUE(g.ok()) << g.status();
    const Eigen::Matrix3f axes = g->box.orientation.toRotationMatrix();
    const Eigen::Matrix3f to_camera = r.world_to_camera.linear();
    // Up is the table's normal.
    EXPECT_GT(axes.col(2).dot(to_camera * Eigen::Vector3f::UnitZ()), 0.999f)
        << yaw;
    worst_angle = std::max(
        worst_angle,
        AxisAngleDeg(axes.col(0), to_camera * box.pose.linear().col(0)));
    const Eigen::Vector3f truth = 2.0f * half;
    worst_size =
        std::max(worst_size, (g->box.size - truth).cwiseAbs().maxCoeff());
    worst_centre = std::max(
        worst_centre,
        (g->box.center - r.world_to_camera * box.pose.translation()).norm());
    EXPECT_NEAR(g->height_above_support, truth.z(), 0.015f) << yaw;
    EXPECT_NEAR(g->footprint_area_m2, truth.x() * truth.y(), 0.0025f) << yaw;
  }
  EXPECT_LT(worst_angle, 4.0f);
  EXPECT_LT(worst_size, 0.015f);
  EXPECT_LT(worst_centre, 0.015f);
}

// The figures over random boxes (yaw, size and place drawn) and cylinders:
// median and worst errors of the length axis's angle (boxes), each size
// and the centre; printed (the closing figures of the box's accuracy) and
// bounded.
TEST(ObjectGeometryTest, RandomBoxesAndCylindersErrorFigures) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> yaw(0.0f, 180.0f);
  std::uniform_real_distribution<float> half(0.025f, 0.07f);
  std::uniform_real_distribution<float> place(-0.12f, 0.12f);
  std::vector<float> angle, size, centre;
  for (int k = 0; k < 30; ++k) {
    const bool cylinder = k % 3 == 2;
    synth::Primitive object;
    Eigen::Vector3f truth;
    if (cylinder) {
      object.shape = synth::Shape::kCylinder;
      object.radius = half(rng);
      object.half_extents = {object.radius, object.radius, half(rng)};
      truth = 2.0f * object.half_extents;
      object.pose.translation() =
          Eigen::Vector3f(place(rng), place(rng), object.half_extents.z());
    } else {
      Eigen::Vector3f h(half(rng), half(rng), half(rng));
      if (h.y() > h.x()) std::swap(h.x(), h.y());
      h.x() = std::max(h.x(), h.y() + 0.01f);  // a length axis to find
      object = Box(h, yaw(rng), {place(rng), place(rng)});
      truth = 2.0f * h;
    }
    const Rendered r = RenderOne(object, 100 + k);
    absl::StatusOr<ObjectGeometry> g = FitSupportAlignedBox(r.points, r.plane);
    ASSERT_TRUE(g.ok()) << k << ": " << g.status();
    if (!cylinder) {
      angle.push_back(AxisAngleDeg(
          g->box.orientation.toRotationMatrix().col(0),
          r.world_to_camera.linear() * object.pose.linear().col(0)));
    }
    size.push_back((g->box.size - truth).cwiseAbs().maxCoeff());
    centre.push_back(
        (g->box.center - r.world_to_camera * object.pose.translation()).norm());
  }
  const auto median = [](std::vector<float> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  const auto worst = [](const std::vector<float>& v) {
    return *std::max_element(v.begin(), v.end());
  };
  std::printf(
      "box fit over %zu boxes and %zu cylinders: length axis %.2f / %.2f deg, "
      "size %.1f / %.1f mm, centre %.1f / %.1f mm (median / worst)\n",
      angle.size(), size.size() - angle.size(), median(angle), worst(angle),
      1e3f * median(size), 1e3f * worst(size), 1e3f * median(centre),
      1e3f * worst(centre));
  EXPECT_LT(worst(angle), 5.0f);
  EXPECT_LT(worst(size), 0.02f);
  EXPECT_LT(worst(centre), 0.02f);
}

// A standing cylinder: a square footprint of its diameter (the minimum-area
// rectangle of a disc), its height, its axis up, its centre on its axis.
TEST(ObjectGeometryTest, CylinderGivesItsDiameterHeightAndAxis) {
  synth::Primitive can;
  can.shape = synth::Shape::kCylinder;
  can.radius = 0.04f;
  can.half_extents = {0.04f, 0.04f, 0.06f};
  can.pose.translation() = Eigen::Vector3f(-0.05f, 0.0f, 0.06f);
  const Rendered r = RenderOne(can, 7);
  absl::StatusOr<ObjectGeometry> g = FitSupportAlignedBox(r.points, r.plane);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_NEAR(g->box.size.x(), 0.08f, 0.012f);
  EXPECT_NEAR(g->box.size.y(), 0.08f, 0.012f);
  EXPECT_NEAR(g->box.size.z(), 0.12f, 0.012f);
  const Eigen::Vector3f centre = r.world_to_camera * can.pose.translation();
  EXPECT_LT((g->box.center - centre).norm(), 0.012f);
}

// The support frame and the box in it are the camera-frame box, re-expressed:
// support pose times box-in-support is the box; the support frame's origin
// lies on the plane, below the box's centre.
TEST(ObjectGeometryTest, TheBoxInTheSupportFrameIsTheSameBox) {
  const synth::Primitive box = Box({0.05f, 0.03f, 0.04f}, 30.0f, {0, 0});
  const Rendered r = RenderOne(box, 3);
  absl::StatusOr<ObjectGeometry> g = FitSupportAlignedBox(r.points, r.plane);
  ASSERT_TRUE(g.ok()) << g.status();
  const Eigen::Isometry3f support =
      Eigen::Translation3f(g->support_origin) * g->support_orientation;
  EXPECT_LT((support * g->box_in_support.center - g->box.center).norm(), 1e-5f);
  EXPECT_TRUE((g->support_orientation * g->box_in_support.orientation)
                  .toRotationMatrix()
                  .isApprox(g->box.orientation.toRotationMatrix(), 1e-5f));
  EXPECT_NEAR(r.plane.Height(g->support_origin), 0.0f, 1e-5f);
  EXPECT_LT((g->support_origin - g->box.center)
                .cross(g->support_orientation * Eigen::Vector3f::UnitZ())
                .norm(),
            1e-5f);
  // In the support frame the box's z axis is the frame's: only yaw.
  EXPECT_TRUE(g->box_in_support.orientation.toRotationMatrix().col(2).isApprox(
      Eigen::Vector3f::UnitZ(), 1e-5f));
  EXPECT_NEAR(g->box_in_support.center.z(), 0.5f * g->box.size.z(), 1e-5f);
}

// A box resting on another: its base is its own lowest point, not the
// table, and its height above the table is the top of the stack.
TEST(ObjectGeometryTest, AnObjectOnAnotherKeepsItsOwnBase) {
  synth::Primitive top = Box({0.03f, 0.03f, 0.025f}, 10.0f, {0, 0});
  top.pose.translation().z() = 0.08f + 0.025f;  // on an 8 cm box
  const synth::Primitive below = Box({0.06f, 0.05f, 0.04f}, 0.0f, {0, 0});
  const Rendered r = RenderOne(top, 5, {below});
  absl::StatusOr<ObjectGeometry> g = FitSupportAlignedBox(r.points, r.plane);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_NEAR(g->box.size.z(), 0.05f, 0.015f);
  EXPECT_NEAR(g->height_above_support, 0.13f, 0.015f);
  EXPECT_GT(g->box_in_support.center.z() - 0.5f * g->box.size.z(), 0.06f);
}

TEST(ObjectGeometryTest, TooFewPointsAndBadOptionsAreErrorsNamingThem) {
  SupportPlane plane;  // z = 0 facing -z... axes x, y
  plane.normal = -Eigen::Vector3f::UnitZ();
  plane.d = 1.0f;
  plane.axis_u = Eigen::Vector3f::UnitX();
  plane.axis_v = -Eigen::Vector3f::UnitY();
  const std::vector<Eigen::Vector3f> two = {{0, 0, 0.9f}, {0.01f, 0, 0.9f}};
  EXPECT_EQ(FitSupportAlignedBox(two, plane).status().code(),
            absl::StatusCode::kFailedPrecondition);
  const std::vector<Eigen::Vector3f> nan = {
      {NAN, 0, 1}, {0, NAN, 1}, {0, 0, NAN}, {0, 0, 0.9f}};
  EXPECT_EQ(FitSupportAlignedBox(nan, plane).status().code(),
            absl::StatusCode::kFailedPrecondition);
  BoxFitOptions options;
  options.trim_percent = 30.0f;
  EXPECT_THAT(std::string(Validate(options).message()),
              testing::HasSubstr("box_fit.trim_percent"));
  options = {};
  options.rest_on_support_m = -1.0f;
  EXPECT_THAT(std::string(Validate(options).message()),
              testing::HasSubstr("box_fit.rest_on_support_m"));
}

TEST(ObjectGeometryTest, EvenSampleSpreadsOverTheWholeRangeInOrder) {
  EXPECT_THAT(EvenSample(10, 0),
              testing::ElementsAre(0, 1, 2, 3, 4, 5, 6, 7, 8, 9));
  EXPECT_THAT(EvenSample(10, 4), testing::ElementsAre(0, 2, 5, 7));
  EXPECT_THAT(EvenSample(3, 8), testing::ElementsAre(0, 1, 2));
  EXPECT_TRUE(EvenSample(0, 5).empty());
  cv::Mat mask(3, 4, CV_8UC1, cv::Scalar(0));
  mask.at<uint8_t>(0, 1) = mask.at<uint8_t>(2, 3) = mask.at<uint8_t>(1, 0) =
      255;
  EXPECT_THAT(MaskIndices(mask, 0), testing::ElementsAre(1, 4, 11));
  EXPECT_THAT(MaskIndices(mask, 2), testing::ElementsAre(1, 4));
}

}  // namespace
}  // namespace fovea
