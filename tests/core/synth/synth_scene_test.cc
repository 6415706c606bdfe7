#include "core/synth/synth_scene.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/synth/footprint.h"
#include "core/synth/textures.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/synth/synth_test_util.h"

namespace fovea::synth {
namespace {

using Eigen::Vector2f;
using Eigen::Vector3f;
using ::testing::HasSubstr;

// Principal point on a pixel centre, so pixel (320, 240) looks along the
// optical axis.
constexpr Intrinsics kCentredIntrinsics{525.0, 525.0, 320.0, 240.0};

NoiseOptions NoNoise() {
  NoiseOptions noise;
  noise.enabled = false;
  return noise;
}

SceneSpec EmptySpec(const Vector3f& eye, const Vector3f& target) {
  SceneSpec spec;
  spec.intrinsics = kCentredIntrinsics;
  spec.camera_pose = LookAt(eye, target);
  return spec;
}

// A camera `height` metres straight above the table centre.
SceneSpec TopDownSpec(float height) {
  return EmptySpec(Vector3f(0, 0, height), Vector3f::Zero());
}

Primitive MakePrimitive(Shape shape, const Vector3f& centre,
                        const Vector3f& half_extents, float radius,
                        float yaw = 0.0f) {
  Primitive p;
  p.shape = shape;
  p.half_extents = half_extents;
  p.radius = radius;
  p.pose = Eigen::Isometry3f::Identity();
  p.pose.linear() =
      Eigen::AngleAxisf(yaw, Vector3f::UnitZ()).toRotationMatrix();
  p.pose.translation() = centre;
  return p;
}

// The camera-frame point of pixel (u, v) with depth z.
Vector3f BackProject(const Intrinsics& k, int u, int v, float z) {
  return {static_cast<float>((u - k.cx) * z / k.fx),
          static_cast<float>((v - k.cy) * z / k.fy), z};
}

int CountLabel(const cv::Mat& labels, int label) {
  return cv::countNonZero(labels == label);
}

float DepthAt(const SynthScene& scene, int u, int v) {
  return scene.frame.frame.depth.at<float>(v, u);
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && a.isContinuous() &&
         b.isContinuous() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

Footprint Disc(const Vector2f& centre, float radius) {
  Footprint f;
  f.centre = centre;
  f.radius = radius;
  f.z_max = 0.1f;
  return f;
}

Footprint Rectangle(const Vector2f& centre, const Vector2f& half, float yaw) {
  Footprint f;
  f.is_circle = false;
  f.centre = centre;
  f.half = half;
  f.yaw = yaw;
  f.z_max = 0.1f;
  return f;
}

TEST(FootprintTest, OverlapFindsContactOfDiscsAndRotatedRectangles) {
  EXPECT_TRUE(Overlap(Disc({0, 0}, 0.05f), Disc({0.09f, 0}, 0.05f), 0));
  EXPECT_FALSE(Overlap(Disc({0, 0}, 0.05f), Disc({0.11f, 0}, 0.05f), 0));
  EXPECT_TRUE(Overlap(Disc({0, 0}, 0.05f), Disc({0.11f, 0}, 0.05f), 0.02f));
  // A square turned 45 degrees reaches sqrt(2) * 0.05 along x.
  const Footprint diamond =
      Rectangle({0, 0}, {0.05f, 0.05f}, std::numbers::pi_v<float> / 4);
  EXPECT_TRUE(Overlap(diamond, Rectangle({0.12f, 0}, {0.05f, 0.05f}, 0), 0));
  EXPECT_FALSE(Overlap(diamond, Rectangle({0.125f, 0}, {0.05f, 0.05f}, 0), 0));
  // Disc near a rectangle's corner: the corner is sqrt(2) * 0.05 away.
  const Footprint square = Rectangle({0, 0}, {0.05f, 0.05f}, 0);
  EXPECT_FALSE(Overlap(square, Disc({0.1f, 0.1f}, 0.07f), 0));
  EXPECT_TRUE(Overlap(square, Disc({0.1f, 0.1f}, 0.071f), 0));
  // Objects one above the other do not collide.
  Footprint above = square;
  above.z_min = 0.1f;
  above.z_max = 0.2f;
  EXPECT_FALSE(Collides(square, above, 0));
  EXPECT_TRUE(Collides(square, square, 0));
}

TEST(FootprintTest, ContactDistanceIsWhereFootprintsJustTouch) {
  const Vector2f x(1, 0);
  EXPECT_NEAR(
      ContactDistance(Disc({0, 0}, 0.05f), Disc({0, 0}, 0.03f), {0, 0}, x),
      0.08f, 1e-6f);
  const Footprint diamond =
      Rectangle({0, 0}, {0.05f, 0.05f}, std::numbers::pi_v<float> / 4);
  EXPECT_NEAR(
      ContactDistance(diamond, Rectangle({0, 0}, {0.02f, 0.03f}, 0), {0, 0}, x),
      0.05f * std::numbers::sqrt2_v<float> + 0.02f, 1e-6f);
  EXPECT_EQ(
      ContactDistance(Disc({0, 0}, 0.01f), Disc({1, 0}, 0.01f), {1, 0}, x),
      0.0f);
}

TEST(LookAtTest, TargetProjectsToPrincipalPointAndImageIsUpright) {
  const Vector3f eye(0.1f, -0.8f, 0.7f);
  const Vector3f target(-0.05f, 0.1f, 0.0f);
  const SceneSpec spec = EmptySpec(eye, target);
  const Vector2f p = Project(spec, target);
  EXPECT_NEAR(p.x(), 320.0f, 1e-3f);
  EXPECT_NEAR(p.y(), 240.0f, 1e-3f);
  const Eigen::Matrix3f r = spec.camera_pose.linear();
  EXPECT_NEAR(r.col(0).z(), 0.0f, 1e-6f);  // image rows are horizontal
  EXPECT_LT(r.col(1).z(), 0.0f);           // image y points down
  EXPECT_NEAR(r.determinant(), 1.0f, 1e-5f);
  // Something higher than the target appears higher in the image.
  EXPECT_LT(Project(spec, target + Vector3f(0, 0, 0.1f)).y(), 240.0f);
}

TEST(LookAtTest, StraightDownHasWorldPlusYUp) {
  const SceneSpec spec = TopDownSpec(1.0f);
  EXPECT_LT(Project(spec, Vector3f(0, 0.1f, 0)).y(), 240.0f);
  EXPECT_GT(Project(spec, Vector3f(0.1f, 0, 0)).x(), 320.0f);
}

TEST(ValidateTest, NamesTheBrokenField) {
  SceneSpec spec;
  spec.width = 0;
  EXPECT_THAT(Validate(spec).message(), HasSubstr("width"));
  spec = SceneSpec();
  spec.objects.push_back(
      MakePrimitive(Shape::kSphere, Vector3f::Zero(), Vector3f::Zero(), -1));
  EXPECT_THAT(Validate(spec).message(), HasSubstr("objects[0].radius"));
  spec.objects[0].radius = 0.05f;
  spec.objects[0].print_rgb = Vector3f(0.5f, 1.5f, 0.5f);
  EXPECT_THAT(Validate(spec).message(), HasSubstr("objects[0].print_rgb"));
  EXPECT_TRUE(Validate(SceneSpec()).ok());

  NoiseOptions noise;
  noise.dark_dropout_probability = 1.5f;
  EXPECT_THAT(Validate(noise).message(), HasSubstr("dark_dropout_probability"));
  EXPECT_TRUE(Validate(NoiseOptions()).ok());

  RandomSceneOptions options;
  options.min_objects = 5;
  options.max_objects = 3;
  EXPECT_EQ(Validate(options).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(Validate(options).message(), HasSubstr("max_objects"));
  EXPECT_TRUE(Validate(RandomSceneOptions()).ok());
}

// Seen from straight above its centre, a box shows only its top face: the
// label covers exactly the pixel centres inside the projected top face.
TEST(RenderSceneTest, BoxFromAboveCoversProjectedTopFace) {
  SceneSpec spec = TopDownSpec(1.0f);
  const Vector3f half(0.06f, 0.04f, 0.03f);
  spec.objects.push_back(
      MakePrimitive(Shape::kBox, Vector3f(0, 0, half.z()), half, 0.0f));
  const SynthScene scene = RenderScene(spec, NoNoise(), 1);

  const Vector2f lo =
      Project(spec, Vector3f(-half.x(), half.y(), 2 * half.z()));
  const Vector2f hi =
      Project(spec, Vector3f(half.x(), -half.y(), 2 * half.z()));
  ASSERT_LT(lo.x(), hi.x());
  ASSERT_LT(lo.y(), hi.y());
  int expected = 0;
  for (int v = 0; v < spec.height; ++v) {
    for (int u = 0; u < spec.width; ++u) {
      const bool inside =
          u >= lo.x() && u <= hi.x() && v >= lo.y() && v <= hi.y();
      expected += inside;
      EXPECT_EQ(scene.frame.labels.at<int>(v, u) == 20, inside)
          << "pixel " << u << ", " << v;
    }
  }
  EXPECT_EQ(CountLabel(scene.frame.labels, 20), expected);
  ASSERT_EQ(scene.objects.size(), 1u);
  EXPECT_EQ(scene.objects[0].label, 20);
  EXPECT_EQ(scene.objects[0].visible_pixels, expected);
  EXPECT_NEAR(DepthAt(scene, 320, 240), 1.0f - 2 * half.z(), 1e-5f);
  EXPECT_NEAR(DepthAt(scene, 100, 100), 1.0f, 1e-5f);  // the table
  EXPECT_EQ(scene.frame.labels.at<int>(100, 100), 1);
  EXPECT_TRUE(std::isnan(DepthAt(scene, 0, 0)));  // beyond the table
  EXPECT_EQ(scene.frame.labels.at<int>(0, 0), 0);
}

struct AnalyticCase {
  std::string name;
  Primitive primitive;
  Vector3f eye;
  Vector3f target;
  float depth;  // expected camera z at pixel (320, 240)
};

// The depth on the optical axis equals the analytic distance to each
// shape's surface, from above and from the side (rotated poses included).
TEST(RenderSceneTest, DepthOnAxisMatchesAnalyticDistanceForEveryShape) {
  const float r = 0.04f;
  const float h = 0.06f;
  Primitive lying =
      MakePrimitive(Shape::kCylinder, Vector3f(0, 0, r), Vector3f(r, r, h), r);
  lying.pose.linear() =
      Eigen::AngleAxisf(0.3f, Vector3f::UnitZ()).toRotationMatrix() *
      Eigen::AngleAxisf(std::numbers::pi_v<float> / 2, Vector3f::UnitX())
          .toRotationMatrix();
  const Vector3f above(0, 0, 1);
  const std::vector<AnalyticCase> cases = {
      {"box yawed 45 deg, seen on its vertical edge",
       MakePrimitive(Shape::kBox, Vector3f(0, 0, 0.05f),
                     Vector3f::Constant(0.05f), 0.0f,
                     std::numbers::pi_v<float> / 4),
       Vector3f(-1, 0, 0.05f), Vector3f(0, 0, 0.05f),
       1.0f - 0.05f * std::numbers::sqrt2_v<float>},
      {"upright cylinder side",
       MakePrimitive(Shape::kCylinder, Vector3f(0, 0, h), Vector3f(r, r, h), r),
       Vector3f(-1, 0, h), Vector3f(0, 0, h), 1.0f - r},
      {"upright cylinder cap",
       MakePrimitive(Shape::kCylinder, Vector3f(0, 0, h), Vector3f(r, r, h), r),
       above, Vector3f::Zero(), 1.0f - 2 * h},
      {"lying cylinder side from above", lying, above, Vector3f::Zero(),
       1.0f - 2 * r},
      {"sphere from the side",
       MakePrimitive(Shape::kSphere, Vector3f(0, 0, r), Vector3f::Zero(), r),
       Vector3f(-1, 0, r), Vector3f(0, 0, r), 1.0f - r},
      {"cone apex from above",
       MakePrimitive(Shape::kCone, Vector3f(0, 0, h), Vector3f(r, r, h), r),
       above, Vector3f::Zero(), 1.0f - 2 * h},
      {"cone side at mid height (radius r / 2)",
       MakePrimitive(Shape::kCone, Vector3f(0, 0, h), Vector3f(r, r, h), r),
       Vector3f(-1, 0, h), Vector3f(0, 0, h), 1.0f - r / 2},
  };
  for (const AnalyticCase& c : cases) {
    SceneSpec spec = EmptySpec(c.eye, c.target);
    spec.objects.push_back(c.primitive);
    const SynthScene scene = RenderScene(spec, NoNoise(), 1);
    EXPECT_NEAR(DepthAt(scene, 320, 240), c.depth, 1e-5f) << c.name;
    EXPECT_EQ(scene.frame.labels.at<int>(240, 320), 20) << c.name;
  }
}

// A cone seen from below its base level would show the base disc; seen from
// the side its silhouette narrows towards the apex.
TEST(RenderSceneTest, ConeSilhouetteNarrowsTowardsApex) {
  const float r = 0.05f;
  const float h = 0.06f;
  SceneSpec spec = EmptySpec(Vector3f(-1, 0, h), Vector3f(0, 0, h));
  spec.objects.push_back(
      MakePrimitive(Shape::kCone, Vector3f(0, 0, h), Vector3f(r, r, h), r));
  const SynthScene scene = RenderScene(spec, NoNoise(), 1);
  const cv::Mat mask = scene.frame.labels == 20;
  const int near_base = cv::countNonZero(mask.row(240 + 25));
  const int middle = cv::countNonZero(mask.row(240));
  const int near_apex = cv::countNonZero(mask.row(240 - 25));
  EXPECT_GT(near_base, middle);
  EXPECT_GT(middle, near_apex);
  // Width at mid height: the radius there is r / 2, at distance ~1 m.
  EXPECT_NEAR(middle, 2 * 525.0f * (r / 2) / 1.0f, 3.0f);
}

// The silhouette of a sphere seen from distance L is a disc of angular
// radius asin(r / L).
TEST(RenderSceneTest, SphereSilhouetteIsDiscOfExpectedRadius) {
  const float r = 0.05f;
  SceneSpec spec = TopDownSpec(1.0f);
  spec.objects.push_back(
      MakePrimitive(Shape::kSphere, Vector3f(0, 0, r), Vector3f::Zero(), r));
  const SynthScene scene = RenderScene(spec, NoNoise(), 1);
  const float distance = 1.0f - r;
  const float rho = 525.0f * std::tan(std::asin(r / distance));
  for (int v = 0; v < spec.height; ++v) {
    for (int u = 0; u < spec.width; ++u) {
      const float d = std::hypot(u - 320.0f, v - 240.0f);
      const bool labelled = scene.frame.labels.at<int>(v, u) == 20;
      if (d < rho - 0.5f) {
        EXPECT_TRUE(labelled) << u << ", " << v;
      } else if (d > rho + 0.5f) {
        EXPECT_FALSE(labelled) << u << ", " << v;
      }
    }
  }
  const float equivalent_radius =
      std::sqrt(CountLabel(scene.frame.labels, 20) / std::numbers::pi_v<float>);
  EXPECT_NEAR(equivalent_radius, rho, 0.3f);
}

TEST(RenderSceneTest, CylinderInFrontOccludesBox) {
  SceneSpec spec = EmptySpec(Vector3f(0, -0.8f, 0.4f), Vector3f(0, 0, 0.05f));
  spec.objects.push_back(MakePrimitive(Shape::kBox, Vector3f(0, 0.1f, 0.06f),
                                       Vector3f::Constant(0.06f), 0.0f));
  const SynthScene alone = RenderScene(spec, NoNoise(), 1);
  spec.objects.push_back(MakePrimitive(Shape::kCylinder,
                                       Vector3f(0, -0.1f, 0.08f),
                                       Vector3f(0.04f, 0.04f, 0.08f), 0.04f));
  const SynthScene both = RenderScene(spec, NoNoise(), 1);

  const int box_alone = alone.objects[0].visible_pixels;
  const int box_behind = both.objects[0].visible_pixels;
  EXPECT_GT(box_alone, 1000);
  EXPECT_GT(box_behind, 0);
  EXPECT_LT(box_behind, 0.8 * box_alone);
  EXPECT_GT(both.objects[1].visible_pixels, 1000);
  // Every box pixel left was a box pixel before, and the box pixels lost
  // now show the cylinder.
  const cv::Mat box_before = alone.frame.labels == 20;
  const cv::Mat box_after = both.frame.labels == 20;
  EXPECT_EQ(cv::countNonZero(box_after & ~box_before), 0);
  const cv::Mat lost = box_before & ~box_after;
  EXPECT_EQ(cv::countNonZero(lost & (both.frame.labels == 30)),
            cv::countNonZero(lost));
}

// Lambertian shading: the top and the camera-facing side of one box get
// different brightness.
TEST(RenderSceneTest, FacesOfOneBoxDifferInBrightness) {
  SceneSpec spec = EmptySpec(Vector3f(0, -0.7f, 0.5f), Vector3f::Zero());
  const float a = 0.06f;
  Primitive box = MakePrimitive(Shape::kBox, Vector3f(0, 0, a),
                                Vector3f::Constant(a), 0.0f);
  box.rgb = Vector3f(0.2f, 0.6f, 0.9f);
  spec.objects.push_back(box);
  const SynthScene scene = RenderScene(spec, NoNoise(), 1);
  const Eigen::Isometry3f camera_to_world = spec.camera_pose;
  double top_sum = 0, front_sum = 0;
  int top_n = 0, front_n = 0;
  for (int v = 0; v < spec.height; ++v) {
    for (int u = 0; u < spec.width; ++u) {
      if (scene.frame.labels.at<int>(v, u) != 20) continue;
      const Vector3f p = camera_to_world * BackProject(spec.intrinsics, u, v,
                                                       DepthAt(scene, u, v));
      const cv::Vec3b rgb = scene.frame.frame.color.at<cv::Vec3b>(v, u);
      if (std::abs(p.z() - 2 * a) < 1e-3f) {
        top_sum += rgb[1];
        ++top_n;
      } else if (std::abs(p.y() + a) < 1e-3f) {
        front_sum += rgb[1];
        ++front_n;
      }
    }
  }
  ASSERT_GT(top_n, 500);
  ASSERT_GT(front_n, 500);
  EXPECT_GT(std::abs(top_sum / top_n - front_sum / front_n), 15.0);
  // Neither face is brighter than its albedo allows.
  EXPECT_LE(top_sum / top_n, 255.0 * 0.6 + 1);
}

// A printed box shows its albedo and its print colour, each over a share
// of its pixels, with the same depth and labels as the plain box; the
// print is fixed to the box: moved with it, the pattern moves too.
TEST(RenderSceneTest, PrintedBoxShowsBothColoursAndTheSameGeometry) {
  SceneSpec spec = EmptySpec(Vector3f(0, -0.7f, 0.5f), Vector3f::Zero());
  const float a = 0.08f;
  Primitive box = MakePrimitive(Shape::kBox, Vector3f(0, 0, a),
                                Vector3f::Constant(a), 0.0f);
  box.rgb = Vector3f(0.9f, 0.1f, 0.1f);        // red
  box.print_rgb = Vector3f(0.1f, 0.1f, 0.9f);  // blue
  spec.objects.push_back(box);
  const SynthScene plain = RenderScene(spec, NoNoise(), 1);
  spec.objects[0].texture = Texture::kPrint;
  const SynthScene printed = RenderScene(spec, NoNoise(), 1);
  EXPECT_TRUE(SameBytes(plain.frame.frame.depth, printed.frame.frame.depth));
  EXPECT_TRUE(SameBytes(plain.frame.labels, printed.frame.labels));
  int red = 0, blue = 0, object = 0;
  for (int v = 0; v < spec.height; ++v) {
    for (int u = 0; u < spec.width; ++u) {
      if (printed.frame.labels.at<int>(v, u) != 20) continue;
      ++object;
      const cv::Vec3b rgb = printed.frame.frame.color.at<cv::Vec3b>(v, u);
      if (rgb[0] > 2 * rgb[2]) ++red;
      if (rgb[2] > 2 * rgb[0]) ++blue;
    }
  }
  ASSERT_GT(object, 2000);
  EXPECT_GT(red, object / 10);
  EXPECT_GT(blue, object / 10);

  // Shifted sideways by 3 cm with the camera, the box looks the same.
  SceneSpec moved = spec;
  const Eigen::Translation3f shift(0.03f, 0.0f, 0.0f);
  moved.objects[0].pose = shift * moved.objects[0].pose;
  moved.camera_pose = shift * moved.camera_pose;
  const SynthScene seen = RenderScene(moved, NoNoise(), 1);
  int same = 0;
  for (int v = 0; v < spec.height; ++v) {
    for (int u = 0; u < spec.width; ++u) {
      if (printed.frame.labels.at<int>(v, u) != 20 ||
          seen.frame.labels.at<int>(v, u) != 20) {
        continue;
      }
      const cv::Vec3b p = printed.frame.frame.color.at<cv::Vec3b>(v, u);
      const cv::Vec3b q = seen.frame.frame.color.at<cv::Vec3b>(v, u);
      if (cv::norm(p, q, cv::NORM_INF) <= 2) ++same;
    }
  }
  EXPECT_GT(same, object * 95 / 100);
}

// AddPrints prints about the share asked for, an object's parts alike, and
// leaves every primitive's shape and pose as they were.
TEST(AddPrintsTest, PrintsTheShareAskedForAndLeavesGeometryAlone) {
  SceneSpec spec = RandomSceneSpec(7, PileOptions());
  ASSERT_GE(spec.objects.size(), 8u);
  spec.object_parts.push_back({spec.objects[0], 0});
  SceneSpec none = spec;
  AddPrints(7, 0.0f, none);
  SceneSpec all = spec;
  AddPrints(7, 1.0f, all);
  int printed_total = 0, objects_total = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    SceneSpec half = spec;
    AddPrints(seed, 0.5f, half);
    for (const Primitive& p : half.objects) {
      printed_total += p.texture == Texture::kPrint ? 1 : 0;
      ++objects_total;
    }
    EXPECT_EQ(half.object_parts[0].primitive.texture, half.objects[0].texture);
  }
  EXPECT_NEAR(static_cast<double>(printed_total) / objects_total, 0.5, 0.1);
  for (size_t k = 0; k < spec.objects.size(); ++k) {
    EXPECT_EQ(none.objects[k].texture, spec.objects[k].texture);
    EXPECT_EQ(all.objects[k].texture, Texture::kPrint);
    EXPECT_TRUE(all.objects[k].pose.isApprox(spec.objects[k].pose));
    EXPECT_EQ(all.objects[k].half_extents, spec.objects[k].half_extents);
    EXPECT_EQ(all.objects[k].rgb, spec.objects[k].rgb);
    EXPECT_TRUE(Validate(all).ok());
  }
  EXPECT_EQ(all.object_parts[0].primitive.print_rgb, all.objects[0].print_rgb);
}

TEST(RenderSceneTest, TablePointsSatisfyReportedPlane) {
  const SceneSpec spec = RandomSceneSpec(3, RandomSceneOptions());
  for (const bool noisy : {false, true}) {
    NoiseOptions noise;
    noise.enabled = noisy;
    const SynthScene scene = RenderScene(spec, noise, 3);
    const Vector3f n = scene.table_normal_camera;
    EXPECT_NEAR(n.norm(), 1.0f, 1e-5f);
    EXPECT_GT(scene.table_d_camera, 0.0f);  // the camera is on n's side
    int count = 0;
    int outliers = 0;
    double sum_sq = 0;
    for (int v = 0; v < spec.height; ++v) {
      for (int u = 0; u < spec.width; ++u) {
        if (scene.frame.labels.at<int>(v, u) != 1) continue;
        const float z = DepthAt(scene, u, v);
        const float residual =
            n.dot(BackProject(spec.intrinsics, u, v, z)) + scene.table_d_camera;
        // Noise sigma and quantisation step at this depth, plus a margin.
        const float step = z * z / (525.0f * 0.075f) * 0.125f;
        const float bound = noisy ? 4 * 1.43e-3f * z * z + step : 1e-4f;
        ++count;
        sum_sq += residual * residual;
        outliers += std::abs(residual) > bound;
      }
    }
    ASSERT_GT(count, 50000);
    EXPECT_LT(outliers, count / 1000) << "noisy " << noisy;
    EXPECT_LT(std::sqrt(sum_sq / count), noisy ? 4e-3 : 1e-5)
        << "noisy " << noisy;
  }
}

TEST(RenderSceneTest, DepthNoiseGrowsWithDistance) {
  std::vector<double> stddev;
  for (const float height : {0.8f, 1.5f}) {
    SceneSpec spec = TopDownSpec(height);
    spec.table_half_size = Vector2f(3, 3);
    const SynthScene scene = RenderScene(spec, NoiseOptions(), 5);
    const cv::Mat patch = scene.frame.frame.depth(cv::Rect(220, 140, 200, 200));
    cv::Scalar mean, sd;
    cv::meanStdDev(patch, mean, sd);
    ASSERT_EQ(cv::countNonZero(patch != patch), 0);  // no NaN on the plane
    const double step = height * height / (525.0 * 0.075) * 0.125;
    EXPECT_NEAR(mean[0], height, step);
    stddev.push_back(sd[0]);
  }
  EXPECT_GT(stddev[0], 2e-4);  // noise is on at all
  EXPECT_GT(stddev[1], 2.0 * stddev[0]);
}

TEST(RenderSceneTest, DarkObjectLosesDepthPixels) {
  SceneSpec spec = TopDownSpec(1.0f);
  Primitive dark = MakePrimitive(Shape::kBox, Vector3f(-0.12f, 0, 0.05f),
                                 Vector3f::Constant(0.05f), 0.0f);
  dark.rgb = Vector3f(0.05f, 0.05f, 0.06f);
  Primitive bright = dark;
  bright.pose.translation().x() = 0.12f;
  bright.rgb = Vector3f(0.9f, 0.8f, 0.2f);
  spec.objects = {dark, bright};
  const SynthScene clean = RenderScene(spec, NoNoise(), 2);
  const SynthScene noisy = RenderScene(spec, NoiseOptions(), 2);
  const auto with_depth = [&](const SynthScene& scene, int k) {
    const cv::Mat depth = scene.frame.frame.depth;
    return static_cast<double>(cv::countNonZero(
        (scene.frame.labels == scene.objects[k].label) & (depth == depth)));
  };
  const double dark_kept = with_depth(noisy, 0) / with_depth(clean, 0);
  const double bright_kept = with_depth(noisy, 1) / with_depth(clean, 1);
  // Both lose their (few) edge pixels; only the dark one loses the rest.
  EXPECT_GT(bright_kept, 0.95);
  EXPECT_NEAR(dark_kept / bright_kept,
              1.0 - NoiseOptions().dark_dropout_probability, 0.07);
  // The dark object is labelled whole all the same: only its edge
  // dropouts lose their label, as the bright one's do.
  const double dark_labelled =
      static_cast<double>(noisy.objects[0].visible_pixels) /
      clean.objects[0].visible_pixels;
  EXPECT_GT(dark_labelled, 0.95);
  EXPECT_NEAR(dark_labelled,
              static_cast<double>(noisy.objects[1].visible_pixels) /
                  clean.objects[1].visible_pixels,
              0.02);
}

// The Chebyshev distance from (u, v) to the nearest pixel labelled
// `label`, within 6 pixels; 1000 beyond.
int DistanceToLabel(const cv::Mat& labels, int u, int v, int label) {
  int nearest = 1000;
  for (int dv = -6; dv <= 6; ++dv) {
    for (int du = -6; du <= 6; ++du) {
      if (labels.at<int>(v + dv, u + du) == label) {
        nearest = std::min(nearest, std::max(std::abs(du), std::abs(dv)));
      }
    }
  }
  return nearest;
}

// The far side of every depth jump loses depth over edge_dropout_px
// pixels; the near side and surfaces away from edges keep it.
TEST(RenderSceneTest, DepthEdgesHaveNaNDropoutsOnTheFarSide) {
  SceneSpec spec = TopDownSpec(1.0f);
  spec.objects.push_back(MakePrimitive(Shape::kBox, Vector3f(0, 0, 0.05f),
                                       Vector3f::Constant(0.05f), 0.0f));
  const NoiseOptions noise;
  const SynthScene clean = RenderScene(spec, NoNoise(), 4);
  const SynthScene noisy = RenderScene(spec, noise, 4);
  const cv::Mat& box = clean.frame.labels;
  int band = 0, band_dropped = 0, away = 0, away_dropped = 0;
  for (int v = 10; v < spec.height - 10; ++v) {
    for (int u = 10; u < spec.width - 10; ++u) {
      const bool dropped = std::isnan(DepthAt(noisy, u, v));
      if (box.at<int>(v, u) == 20) {
        EXPECT_FALSE(dropped) << "near side " << u << ", " << v;
        continue;
      }
      if (box.at<int>(v, u) != 1) continue;
      const int nearest = DistanceToLabel(box, u, v, 20);
      if (nearest <= noise.edge_dropout_px) {
        ++band;
        band_dropped += dropped;
      } else if (nearest > noise.edge_dropout_px + 1 && nearest < 1000) {
        ++away;
        away_dropped += dropped;
      }
    }
  }
  EXPECT_GT(band, 400);
  EXPECT_EQ(band_dropped, band);
  EXPECT_GT(away, 400);
  EXPECT_EQ(away_dropped, 0);
}

// Time of flight: no shadow beside the box (illuminator and sensor sit
// together); along its edge about 30 % of the far side's band keep a depth
// between the table's and the box top's, belonging to no object.
TEST(RenderSceneTest, TimeOfFlightEdgesHoldMixedPixelsAndNoShadow) {
  SceneSpec spec = TopDownSpec(1.0f);
  spec.objects.push_back(MakePrimitive(Shape::kBox, Vector3f(0, 0, 0.05f),
                                       Vector3f::Constant(0.05f), 0.0f));
  const NoiseOptions noise = TimeOfFlightNoise();
  const SynthScene clean = RenderScene(spec, NoNoise(), 4);
  const SynthScene tof = RenderScene(spec, noise, 4);
  const cv::Mat& box = clean.frame.labels;
  int band = 0, mixed = 0, away = 0, away_dropped = 0;
  for (int v = 10; v < spec.height - 10; ++v) {
    for (int u = 10; u < spec.width - 10; ++u) {
      if (box.at<int>(v, u) != 1) continue;
      const int nearest = DistanceToLabel(box, u, v, 20);
      const float z = DepthAt(tof, u, v);
      if (nearest <= noise.edge_dropout_px) {
        ++band;
        if (!std::isnan(z)) {
          // The table lies at 1.0 m, the box top at 0.9 m: a mixed pixel
          // is well inside, more than 4 sigma (6 mm) from either.
          EXPECT_GT(z, 0.906f) << u << ", " << v;
          EXPECT_LT(z, 0.994f) << u << ", " << v;
          EXPECT_EQ(tof.frame.labels.at<int>(v, u), 0);
          ++mixed;
        }
      } else if (nearest > noise.edge_dropout_px + 1 && nearest < 1000) {
        ++away;
        away_dropped += std::isnan(z);
      }
    }
  }
  EXPECT_GT(band, 400);
  EXPECT_NEAR(static_cast<double>(mixed) / band, noise.flying_pixel_probability,
              0.08);
  EXPECT_GT(away, 400);
  EXPECT_EQ(away_dropped, 0);  // no shadow on either side
}

TEST(GenerateSceneTest, SameSeedGivesIdenticalBytesOtherSeedDiffers) {
  const SynthScene a = GenerateScene(7);
  const SynthScene b = GenerateScene(7);
  EXPECT_TRUE(SameBytes(a.frame.frame.color, b.frame.frame.color));
  EXPECT_TRUE(SameBytes(a.frame.frame.depth, b.frame.frame.depth));
  EXPECT_TRUE(SameBytes(a.frame.labels, b.frame.labels));
  const SynthScene c = GenerateScene(8);
  EXPECT_FALSE(SameBytes(a.frame.frame.color, c.frame.frame.color));
  EXPECT_FALSE(SameBytes(a.frame.frame.depth, c.frame.frame.depth));
  EXPECT_FALSE(SameBytes(a.frame.labels, c.frame.labels));
}

// The demo seeds: OSD-style labels only, label 0 exactly where depth is
// missing, truthful visible counts and 2-6 clearly visible objects.
TEST(GenerateSceneTest, DemoSeedsHaveValidLabelsAndTwoToSixObjects) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE(seed);
    const SynthScene scene = GenerateScene(seed);
    const LabelledFrame& f = scene.frame;
    EXPECT_EQ(f.name, "synth-" + std::to_string(seed));
    EXPECT_EQ(f.frame.intrinsics.fx, kKinectV1Intrinsics.fx);
    ASSERT_EQ(f.frame.color.type(), CV_8UC3);
    ASSERT_EQ(f.frame.depth.type(), CV_32FC1);
    ASSERT_EQ(f.labels.type(), CV_32SC1);
    EXPECT_EQ(f.frame.depth.size(), cv::Size(640, 480));
    EXPECT_EQ(f.labels.size(), cv::Size(640, 480));

    std::set<int> allowed = {0, 1};
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      EXPECT_EQ(scene.objects[i].label, 10 * (static_cast<int>(i) + 2));
      allowed.insert(scene.objects[i].label);
    }
    int bad = 0;
    int unlabelled_with_depth = 0;
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const int label = f.labels.at<int>(v, u);
        bad += allowed.count(label) == 0;
        // A dark surface's dropouts are labelled without depth; nothing
        // with depth goes unlabelled.
        unlabelled_with_depth +=
            label == 0 && !std::isnan(f.frame.depth.at<float>(v, u));
      }
    }
    EXPECT_EQ(bad, 0);
    EXPECT_EQ(unlabelled_with_depth, 0);
    int visible = 0;
    for (const ObjectTruth& o : scene.objects) {
      EXPECT_EQ(o.visible_pixels, CountLabel(f.labels, o.label));
      visible += o.visible_pixels >= 150;
    }
    EXPECT_GE(visible, 2);
    EXPECT_LE(visible, 6);
    EXPECT_GT(CountLabel(f.labels, 1), 640 * 480 / 5);  // the table
  }
}

}  // namespace
}  // namespace fovea::synth
