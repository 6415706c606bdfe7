#include "core/segmentation/surface_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <utility>

#include "core/frame/organized_cloud.h"
#include "core/segmentation/planar_patches.h"
#include "core/synth/synth_scene.h"

namespace fovea {
namespace {

constexpr float kPi = static_cast<float>(M_PI);
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// The Kinect's axial noise, as synth::NoiseOptions draws it.
constexpr float kSigmaPerZ2 = 1.43e-3f;

// Moves p along its viewing ray by Gaussian depth noise of sigma
// kSigmaPerZ2 * z^2 (the Kinect's axial noise, Khoshelham & Elberink 2012).
Eigen::Vector3f WithDepthNoise(const Eigen::Vector3f& p, std::mt19937& rng) {
  std::normal_distribution<float> noise(0.0f, kSigmaPerZ2 * p.z() * p.z());
  return p * ((p.z() + noise(rng)) / p.z());
}

// An nx x ny grid over [0, 1]^2 mapped through `surface`, in raster order,
// with depth noise when `noisy`.
template <typename Surface>
std::vector<Eigen::Vector3f> Grid(int nx, int ny, Surface surface,
                                  bool noisy = true, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::vector<Eigen::Vector3f> points;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector3f p = surface((i + 0.5f) / nx, (j + 0.5f) / ny);
      points.push_back(noisy ? WithDepthNoise(p, rng) : p);
    }
  }
  return points;
}

// A 10 x 8 cm rectangle of a plane tilted 30 degrees about x, centred
// 0.8 m away, shifted `dx` along x.
std::vector<Eigen::Vector3f> TiltedPlane(int nx = 20, int ny = 20,
                                         float dx = 0.0f, unsigned seed = 7) {
  const Eigen::Vector3f c(dx, 0.0f, 0.8f);
  const Eigen::Vector3f ex = Eigen::Vector3f::UnitX();
  const Eigen::Vector3f ey(0.0f, std::cos(kPi / 6), std::sin(kPi / 6));
  return Grid(
      nx, ny,
      [&](float s, float t) {
        return Eigen::Vector3f(c + (s - 0.5f) * 0.10f * ex +
                               (t - 0.5f) * 0.08f * ey);
      },
      true, seed);
}

// The part of a vertical cylinder (axis along camera y, radius 4 cm,
// 10 cm high, axis 0.84 m away, so its front is 0.8 m away) between the
// angles `from` and `to` (radians, 0 facing the camera).
std::vector<Eigen::Vector3f> CylinderPatch(float from, float to, int na = 20,
                                           int nh = 20, unsigned seed = 7) {
  const Eigen::Vector3f axis(0.0f, 0.0f, 0.84f);
  constexpr float kRadius = 0.04f;
  return Grid(
      na, nh,
      [&](float s, float t) {
        const float a = from + s * (to - from);
        return Eigen::Vector3f(axis + Eigen::Vector3f(kRadius * std::sin(a),
                                                      (t - 0.5f) * 0.10f,
                                                      -kRadius * std::cos(a)));
      },
      true, seed);
}

// A cap of a sphere of radius 5 cm, centre 0.85 m away: the points up to
// 50 degrees from the one facing the camera.
std::vector<Eigen::Vector3f> SphereCap() {
  const Eigen::Vector3f centre(0.0f, 0.0f, 0.85f);
  constexpr float kRadius = 0.05f;
  return Grid(24, 24, [&](float s, float t) {
    const float polar = std::sqrt(s) * 50.0f * kPi / 180.0f;  // even area
    const float azimuth = t * 2.0f * kPi;
    return Eigen::Vector3f(
        centre + kRadius * Eigen::Vector3f(std::sin(polar) * std::cos(azimuth),
                                           std::sin(polar) * std::sin(azimuth),
                                           -std::cos(polar)));
  });
}

SurfaceModel Fit(const std::vector<Eigen::Vector3f>& points,
                 const SurfaceModelOptions& options = {}) {
  absl::StatusOr<SurfaceModel> model = FitSurface(points, options);
  EXPECT_TRUE(model.ok()) << model.status();
  return model.ok() ? *std::move(model) : SurfaceModel{};
}

FusionVerdict Fuse(const std::vector<Eigen::Vector3f>& a,
                   const std::vector<Eigen::Vector3f>& b) {
  absl::StatusOr<FusionVerdict> verdict = ShouldFuse(a, Fit(a), b, Fit(b), {});
  EXPECT_TRUE(verdict.ok()) << verdict.status();
  return verdict.ok() ? *std::move(verdict) : FusionVerdict{};
}

// Depth noise sigma at 0.8 m, metres (0.92 mm).
constexpr float kSigmaAt08 = kSigmaPerZ2 * 0.8f * 0.8f;

TEST(SurfaceModelTest, NoisyPlaneIsAPlane) {
  const std::vector<Eigen::Vector3f> points = TiltedPlane();
  const SurfaceModel model = Fit(points);
  EXPECT_EQ(model.kind, SurfaceKind::kPlane);
  EXPECT_EQ(model.points, 400);
  EXPECT_GE(model.explained, 390);
  EXPECT_LT(model.rms, 1.5f * kSigmaAt08);
  // Its normal is the plane's (tilted 30 degrees about x), to the camera.
  const Eigen::Vector3f normal(0.0f, -std::sin(kPi / 6), std::cos(kPi / 6));
  EXPECT_GT(std::abs(model.plane.head<3>().dot(normal)), 0.999f);
  EXPECT_LT(model.plane.head<3>().dot(Eigen::Vector3f(0.0f, 0.0f, 0.8f)), 0.0f);
  // A B-spline fits as well but costs its 16 extra parameters.
  absl::StatusOr<SurfaceModel> spline = FitBSplineModel(points, {});
  ASSERT_TRUE(spline.ok()) << spline.status();
  EXPECT_GE(spline->explained, 390);
  EXPECT_GT(spline->description_length, model.description_length + 30.0);
}

TEST(SurfaceModelTest, QuarterCylinderIsABSplineThatThePlaneMisses) {
  // A quarter cylinder of radius 4 cm bulges 11.7 mm from its chord; the
  // best plane misses by up to ~6 mm, beyond three sigma (~4 mm).
  const std::vector<Eigen::Vector3f> points = CylinderPatch(-kPi / 4, kPi / 4);
  const SurfaceModel model = Fit(points);
  ASSERT_EQ(model.kind, SurfaceKind::kBSpline);
  EXPECT_GE(model.explained, 390);
  // Residuals are the noise (the depth noise seen along the normal is
  // at most sigma(0.84 m) = 1.0 mm), not the shape.
  EXPECT_GT(model.rms, 0.5f * kSigmaAt08);
  EXPECT_LT(model.rms, 1.2f * kSigmaAt08);
  absl::StatusOr<SurfaceModel> plane = FitPlaneModel(points, {});
  ASSERT_TRUE(plane.ok()) << plane.status();
  EXPECT_LT(plane->explained, 0.8 * 400);
  EXPECT_GT(plane->rms, 2.0 * model.rms);
  EXPECT_GT(plane->description_length, 3.0 * model.description_length);
}

TEST(SurfaceModelTest, SphereCapIsABSpline) {
  const std::vector<Eigen::Vector3f> points = SphereCap();
  const SurfaceModel model = Fit(points);
  ASSERT_EQ(model.kind, SurfaceKind::kBSpline);
  EXPECT_GE(model.explained, 0.97 * points.size());
  EXPECT_LT(model.rms, 1.2f * kSigmaAt08);
  absl::StatusOr<SurfaceModel> plane = FitPlaneModel(points, {});
  ASSERT_TRUE(plane.ok()) << plane.status();
  EXPECT_LT(plane->explained, 0.6 * points.size());
}

TEST(SurfaceModelTest, DistanceIsZeroOnTheFittedSurfaceAndCountsAlongW) {
  const SurfaceModel model = Fit(CylinderPatch(-kPi / 4, kPi / 4));
  ASSERT_EQ(model.kind, SurfaceKind::kBSpline);
  const BSplineSurface& spline = model.spline;
  EXPECT_EQ(spline.control.size(), spline.nu * spline.nv);
  EXPECT_NEAR(spline.axes.determinant(), 1.0f, 1e-5f);
  for (float u = 0.0f; u <= 1.0f; u += 0.125f) {
    for (float v = 0.0f; v <= 1.0f; v += 0.125f) {
      const Eigen::Vector3f on = spline.PointAt(u, v);
      EXPECT_LT(spline.Distance(on), 2e-6f) << u << " " << v;
      EXPECT_FLOAT_EQ(model.Distance(on), spline.Distance(on));
      // 5 mm off along w (in the middle, where u and v stay put).
      const Eigen::Vector3f off = on + 0.005f * spline.axes.col(2);
      EXPECT_NEAR(spline.Distance(off), 0.005f, 2e-6f) << u << " " << v;
    }
  }
  // The surface follows the cylinder: its front point lies on it.
  EXPECT_LT(spline.Distance(Eigen::Vector3f(0.0f, 0.0f, 0.8f)), 1e-3f);
}

TEST(SurfaceModelTest, QuadraticHeightFieldIsReproducedWithoutNoise) {
  // z = 0.8 + 3 x^2 + 2 y^2 over a 12 x 8 cm rectangle: symmetric, so its
  // principal axes are the camera's and w(u, v) is a quadratic, which
  // cubic B-splines hold exactly; only the regularisers bend it.
  const std::vector<Eigen::Vector3f> points = Grid(
      30, 20,
      [](float s, float t) {
        const float x = (s - 0.5f) * 0.12f, y = (t - 0.5f) * 0.08f;
        return Eigen::Vector3f(x, y, 0.8f + 3.0f * x * x + 2.0f * y * y);
      },
      false);
  absl::StatusOr<SurfaceModel> model = FitBSplineModel(points, {});
  ASSERT_TRUE(model.ok()) << model.status();
  float worst = 0.0f;
  for (const Eigen::Vector3f& p : points) {
    worst = std::max(worst, model->spline.Distance(p));
  }
  EXPECT_LT(worst, 5e-6f);
  EXPECT_EQ(model->explained, static_cast<int>(points.size()));
}

TEST(SurfaceModelTest, AdjacentHalvesOfACylinderFuse) {
  // A quarter cylinder split along its axis into two 45-degree halves.
  const std::vector<Eigen::Vector3f> a =
      CylinderPatch(-kPi / 4, 0.0f, 20, 20, 1);
  const std::vector<Eigen::Vector3f> b =
      CylinderPatch(0.0f, kPi / 4, 20, 20, 2);
  const FusionVerdict verdict = Fuse(a, b);
  EXPECT_TRUE(verdict.fuse);
  EXPECT_GT(verdict.saving_bits, 30.0);
  EXPECT_EQ(verdict.fused.kind, SurfaceKind::kBSpline);
  EXPECT_EQ(verdict.fused.points, 800);
  EXPECT_GE(verdict.fused.explained, 0.97 * 800);
}

TEST(SurfaceModelTest, BoxTopAndFrontFaceDoNotFuse) {
  // Two faces meeting at a 90-degree edge 0.8 m away, seen from 45 degrees
  // above (camera y down): the top runs back from the edge, the front
  // down; both face the camera.
  const Eigen::Vector3f edge(0.0f, 0.0f, 0.8f);
  const Eigen::Vector3f back = Eigen::Vector3f(0.0f, -1.0f, 1.0f).normalized();
  const Eigen::Vector3f down = Eigen::Vector3f(0.0f, 1.0f, 1.0f).normalized();
  auto face = [&](const Eigen::Vector3f& direction, float depth,
                  unsigned seed) {
    return Grid(
        20, 16,
        [&](float s, float t) {
          return Eigen::Vector3f(edge +
                                 (s - 0.5f) * 0.08f * Eigen::Vector3f::UnitX() +
                                 (0.002f + t * depth) * direction);
        },
        true, seed);
  };
  const std::vector<Eigen::Vector3f> top = face(back, 0.06f, 1);
  const std::vector<Eigen::Vector3f> front = face(down, 0.05f, 2);
  EXPECT_EQ(Fit(top).kind, SurfaceKind::kPlane);
  EXPECT_EQ(Fit(front).kind, SurfaceKind::kPlane);
  const FusionVerdict verdict = Fuse(top, front);
  EXPECT_FALSE(verdict.fuse);
  // Not a close call: one surface bending 90 degrees leaves points
  // unexplained near the edge and costs its parameters.
  EXPECT_LT(verdict.saving_bits, -100.0);
}

TEST(SurfaceModelTest, APlaneAndAParallelPlane5cmBehindDoNotFuse) {
  const std::vector<Eigen::Vector3f> near = TiltedPlane(12, 20, -0.06f, 1);
  std::vector<Eigen::Vector3f> far = TiltedPlane(12, 20, 0.06f, 2);
  for (Eigen::Vector3f& p : far) p.z() += 0.05f;
  const FusionVerdict verdict = Fuse(near, far);
  EXPECT_FALSE(verdict.fuse);
  EXPECT_LT(verdict.saving_bits, -100.0);
}

TEST(SurfaceModelTest, CoplanarNeighboursFuseIntoOnePlane) {
  // The two halves of one plane: one plane of 3 parameters describes both.
  const FusionVerdict verdict =
      Fuse(TiltedPlane(12, 20, -0.06f, 1), TiltedPlane(12, 20, 0.06f, 2));
  EXPECT_TRUE(verdict.fuse);
  EXPECT_GT(verdict.saving_bits, 0.0);
  EXPECT_EQ(verdict.fused.kind, SurfaceKind::kPlane);
}

TEST(SurfaceModelTest, ATinyPatchDoesNotFuseIntoAHugeOneItDoesNotContinue) {
  // A table-sized plane of 40000 points and a 6 x 6 mm, 100-point curved
  // bump standing 1 cm off it: the sample of the union must still see the
  // bump's points (each patch is sampled on its own).
  std::vector<Eigen::Vector3f> table = TiltedPlane(200, 200, 0.0f, 3);
  const std::vector<Eigen::Vector3f> bump = Grid(10, 10, [](float s, float t) {
    const float x = (s - 0.5f) * 0.006f, y = (t - 0.5f) * 0.006f;
    return Eigen::Vector3f(0.06f + x, y, 0.79f - 20.0f * (x * x + y * y));
  });
  const FusionVerdict verdict = Fuse(table, bump);
  EXPECT_FALSE(verdict.fuse);
  EXPECT_LT(verdict.saving_bits, -100.0);
}

TEST(SurfaceModelTest, LargePatchesAreSubsampledWithoutChangingTheirKind) {
  // 40000 points: fitted to max_fit_points, measured on as many others.
  const std::vector<Eigen::Vector3f> plane = TiltedPlane(200, 200);
  const SurfaceModel flat = Fit(plane);
  EXPECT_EQ(flat.kind, SurfaceKind::kPlane);
  EXPECT_EQ(flat.points, 40000);
  EXPECT_NEAR(flat.explained, 40000, 400);
  const SurfaceModel curved = Fit(CylinderPatch(-kPi / 4, kPi / 4, 200, 200));
  EXPECT_EQ(curved.kind, SurfaceKind::kBSpline);
  EXPECT_NEAR(curved.explained, 40000, 400);
}

TEST(SurfaceModelTest, ValidateNamesTheField) {
  EXPECT_TRUE(Validate(SurfaceModelOptions{}).ok());
  const std::vector<std::pair<std::string, void (*)(SurfaceModelOptions&)>>
      cases = {
          {"sigma_per_z2", [](SurfaceModelOptions& o) { o.sigma_per_z2 = -1; }},
          {"grazing_sigma",
           [](SurfaceModelOptions& o) { o.grazing_sigma = kNaN; }},
          {"surface_sigma",
           [](SurfaceModelOptions& o) { o.surface_sigma = 0; }},
          {"tolerance_sigmas",
           [](SurfaceModelOptions& o) { o.tolerance_sigmas = 0; }},
          {"kappa_parameter",
           [](SurfaceModelOptions& o) { o.kappa_parameter = 0; }},
          // At 3 sigma an explained point may cost 6.5 bits.
          {"outlier_bits", [](SurfaceModelOptions& o) { o.outlier_bits = 6; }},
          {"max_control", [](SurfaceModelOptions& o) { o.max_control = 3; }},
          {"max_control", [](SurfaceModelOptions& o) { o.max_control = 13; }},
          {"points_per_control",
           [](SurfaceModelOptions& o) { o.points_per_control = 0.5f; }},
          {"smoothness_weight",
           [](SurfaceModelOptions& o) { o.smoothness_weight = -1; }},
          {"ridge_weight", [](SurfaceModelOptions& o) { o.ridge_weight = 0; }},
          {"min_bspline_points",
           [](SurfaceModelOptions& o) { o.min_bspline_points = 15; }},
          {"max_fit_points",
           [](SurfaceModelOptions& o) { o.max_fit_points = 20; }},
          {"fusion_bias_bits",
           [](SurfaceModelOptions& o) { o.fusion_bias_bits = -1; }},
      };
  for (const auto& [field, spoil] : cases) {
    SurfaceModelOptions options;
    spoil(options);
    const absl::Status status = Validate(options);
    EXPECT_TRUE(absl::IsInvalidArgument(status)) << field;
    EXPECT_NE(std::string(status.message()).find("surface_model." + field),
              std::string::npos)
        << status;
  }
  SurfaceModelOptions bad;
  bad.ridge_weight = 0;
  const std::vector<Eigen::Vector3f> points = TiltedPlane();
  EXPECT_TRUE(absl::IsInvalidArgument(FitSurface(points, bad).status()));
  EXPECT_TRUE(absl::IsInvalidArgument(FitPlaneModel(points, bad).status()));
  EXPECT_TRUE(absl::IsInvalidArgument(FitBSplineModel(points, bad).status()));
  EXPECT_TRUE(absl::IsInvalidArgument(
      ShouldFuse(points, {}, points, {}, bad).status()));
}

TEST(SurfaceModelTest, FewerThanThreePointsAreAnErrorThreeArePlane) {
  const std::vector<Eigen::Vector3f> three = {
      {0.0f, 0.0f, 1.0f}, {0.1f, 0.0f, 1.0f}, {0.0f, 0.1f, 1.1f}};
  for (size_t n = 0; n < 3; ++n) {
    const std::vector<Eigen::Vector3f> few(three.begin(), three.begin() + n);
    EXPECT_TRUE(absl::IsInvalidArgument(FitSurface(few, {}).status())) << n;
  }
  const SurfaceModel model = Fit(three);
  EXPECT_EQ(model.kind, SurfaceKind::kPlane);
  for (const Eigen::Vector3f& p : three) EXPECT_LT(model.Distance(p), 1e-6f);
  EXPECT_NEAR(model.plane.head<3>().norm(), 1.0f, 1e-6f);
}

TEST(SurfaceModelTest, TooFewPointsForASplineGiveThePlane) {
  // 20 points of the quarter cylinder: fewer than min_bspline_points.
  const std::vector<Eigen::Vector3f> points =
      CylinderPatch(-kPi / 4, kPi / 4, 5, 4);
  EXPECT_EQ(Fit(points).kind, SurfaceKind::kPlane);
  EXPECT_TRUE(absl::IsInvalidArgument(FitBSplineModel(points, {}).status()));
}

TEST(SurfaceModelTest, CollinearAndCoincidentPointsGiveAPlaneNotASpline) {
  std::vector<Eigen::Vector3f> line;
  for (int i = 0; i < 100; ++i) line.emplace_back(0.001f * i, 0.0f, 1.0f);
  const SurfaceModel model = Fit(line);
  EXPECT_EQ(model.kind, SurfaceKind::kPlane);
  for (const Eigen::Vector3f& p : line) EXPECT_LT(model.Distance(p), 1e-6f);
  EXPECT_TRUE(absl::IsInvalidArgument(FitBSplineModel(line, {}).status()));
  const std::vector<Eigen::Vector3f> same(50, Eigen::Vector3f(0, 0, 1));
  EXPECT_EQ(Fit(same).kind, SurfaceKind::kPlane);
}

TEST(SurfaceModelTest, NonFinitePointsAreSkipped) {
  const std::vector<Eigen::Vector3f> clean = TiltedPlane();
  std::vector<Eigen::Vector3f> dirty;
  const float inf = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < clean.size(); ++i) {
    dirty.push_back(clean[i]);
    if (i % 3 == 0) dirty.emplace_back(kNaN, kNaN, kNaN);
    if (i % 7 == 0) dirty.emplace_back(0.0f, inf, 1.0f);
  }
  const SurfaceModel a = Fit(clean), b = Fit(dirty);
  EXPECT_EQ(b.points, 400);
  EXPECT_EQ(b.kind, a.kind);
  EXPECT_TRUE(b.plane.isApprox(a.plane, 1e-6f));
  EXPECT_DOUBLE_EQ(b.description_length, a.description_length);
  const std::vector<Eigen::Vector3f> nans(10, Eigen::Vector3f(kNaN, 0, 1));
  EXPECT_TRUE(absl::IsInvalidArgument(FitSurface(nans, {}).status()));
  EXPECT_TRUE(
      absl::IsInvalidArgument(ShouldFuse(nans, {}, nans, {}, {}).status()));
}

// Surface models of a rendered scene's planar patches: what incremental
// segmentation will feed them.
struct RenderedPatches {
  std::vector<std::vector<Eigen::Vector3f>> points;
  std::vector<int> label;  // ground-truth majority label per patch
  std::vector<std::pair<int, int>> adjacency;
  Eigen::Isometry3f camera_pose;  // camera to world
};

RenderedPatches PatchesOf(const synth::Primitive& object) {
  synth::SceneSpec spec;
  spec.camera_pose = synth::LookAt({0.0f, -0.75f, 0.75f}, {0.0f, 0.0f, 0.0f});
  spec.objects.push_back(object);
  const synth::SynthScene scene =
      synth::RenderScene(spec, synth::NoiseOptions{}, 3);
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(scene.frame.frame, {});
  EXPECT_TRUE(cloud.ok()) << cloud.status();
  absl::StatusOr<PlanarPatches> patches = FindPlanarPatches(*cloud, {}, {});
  EXPECT_TRUE(patches.ok()) << patches.status();
  RenderedPatches out;
  out.points.resize(patches->patches.size());
  std::vector<std::map<int, int>> labels(patches->patches.size());
  for (int v = 0; v < cloud->height(); ++v) {
    for (int u = 0; u < cloud->width(); ++u) {
      const int id = patches->labels.at<int>(v, u);
      if (id < 0) continue;
      const cv::Vec3f& p = cloud->xyz.at<cv::Vec3f>(v, u);
      out.points[id].emplace_back(p[0], p[1], p[2]);
      ++labels[id][scene.frame.labels.at<int>(v, u)];
    }
  }
  for (const auto& counts : labels) {
    out.label.push_back(std::max_element(counts.begin(), counts.end(),
                                         [](const auto& x, const auto& y) {
                                           return x.second < y.second;
                                         })
                            ->first);
  }
  out.adjacency = patches->adjacency;
  out.camera_pose = spec.camera_pose;
  return out;
}

TEST(SurfaceModelTest, RenderedBoxFacesArePlanesThatStayApart) {
  synth::Primitive box;
  box.shape = synth::Shape::kBox;
  box.half_extents = {0.05f, 0.04f, 0.04f};
  box.pose.translation() = Eigen::Vector3f(0.0f, 0.0f, 0.04f);
  const RenderedPatches rendered = PatchesOf(box);
  std::vector<int> faces;
  for (size_t i = 0; i < rendered.points.size(); ++i) {
    if (rendered.label[i] == 20 && rendered.points[i].size() >= 500) {
      faces.push_back(static_cast<int>(i));
    }
  }
  ASSERT_EQ(faces.size(), 2u);  // the top and the front face
  const SurfaceModel top = Fit(rendered.points[faces[0]]);
  const SurfaceModel front = Fit(rendered.points[faces[1]]);
  EXPECT_EQ(top.kind, SurfaceKind::kPlane);
  EXPECT_EQ(front.kind, SurfaceKind::kPlane);
  absl::StatusOr<FusionVerdict> verdict = ShouldFuse(
      rendered.points[faces[0]], top, rendered.points[faces[1]], front, {});
  ASSERT_TRUE(verdict.ok()) << verdict.status();
  EXPECT_FALSE(verdict->fuse);
  // The table (label 1, the largest patch) is a plane too.
  const auto table = std::max_element(
      rendered.points.begin(), rendered.points.end(),
      [](const auto& x, const auto& y) { return x.size() < y.size(); });
  EXPECT_EQ(Fit(*table).kind, SurfaceKind::kPlane);
}

TEST(SurfaceModelTest, RenderedCylinderSidePatchesFuseNotWithTheTable) {
  // A standing cylinder's side breaks into a few planar strips; the
  // neighbouring strips are one curved surface, the table and the top cap
  // are not.
  synth::Primitive cylinder;
  cylinder.shape = synth::Shape::kCylinder;
  cylinder.radius = 0.04f;
  cylinder.half_extents = {0.04f, 0.04f, 0.06f};
  cylinder.pose.translation() = Eigen::Vector3f(0.0f, 0.0f, 0.06f);
  const RenderedPatches rendered = PatchesOf(cylinder);
  std::vector<SurfaceModel> models;
  for (const auto& points : rendered.points) models.push_back(Fit(points));
  int side_pairs = 0, side_fused = 0, table_pairs = 0;
  for (const auto& [a, b] : rendered.adjacency) {
    absl::StatusOr<FusionVerdict> verdict = ShouldFuse(
        rendered.points[a], models[a], rendered.points[b], models[b], {});
    ASSERT_TRUE(verdict.ok()) << verdict.status();
    if (rendered.label[a] == 1 || rendered.label[b] == 1) {
      ++table_pairs;
      EXPECT_FALSE(verdict->fuse) << a << "-" << b;
      continue;
    }
    // Side strips: nine in ten points within 5 mm of the radius and below
    // the cap (world frame: the axis is z through the origin, 12 cm high).
    auto on_side = [&](int patch) {
      int side = 0;
      for (const Eigen::Vector3f& p : rendered.points[patch]) {
        const Eigen::Vector3f w = rendered.camera_pose * p;
        side += std::abs(w.head<2>().norm() - 0.04f) < 0.005f && w.z() < 0.115f;
      }
      return side >= 0.9 * rendered.points[patch].size();
    };
    if (on_side(a) && on_side(b)) {
      ++side_pairs;
      side_fused += verdict->fuse ? 1 : 0;
    }
  }
  EXPECT_GT(table_pairs, 0);
  ASSERT_GE(side_pairs, 2);
  EXPECT_EQ(side_fused, side_pairs);
}

}  // namespace
}  // namespace fovea
