#include "core/synth/synth_scene.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/frame/osd_pcd.h"
#include "core/synth/random.h"
#include "core/synth/raycast.h"

namespace fovea::synth {
namespace {

// Lighting, in the world frame: a directional light from above, slightly
// left and from the camera's side of the table, plus ambient light. Faces of
// one object differ in brightness by their orientation.
const Eigen::Vector3f kLightDirection =
    Eigen::Vector3f(-0.35f, -0.55f, 1.0f).normalized();  // towards the light
constexpr float kAmbient = 0.3f;  // share of albedo lit everywhere
constexpr float kDiffuse = 1.0f - kAmbient;
// Colour of pixels that see nothing (a far, dim wall), RGB in [0, 1].
constexpr float kBackgroundRgb[3] = {0.32f, 0.33f, 0.36f};
// Stream id mixed into the noise seed, so a scene's noise is not correlated
// with a RandomSceneSpec drawn from the same seed.
constexpr uint64_t kNoiseStream = 0x6e6f697365ULL;  // "noise"
constexpr int kTableLabel = 1;

bool IsUnit(float x) { return x >= 0.0f && x <= 1.0f; }
bool IsUnitRgb(const Eigen::Vector3f& rgb) {
  return IsUnit(rgb.x()) && IsUnit(rgb.y()) && IsUnit(rgb.z());
}
bool IsRotation(const Eigen::Matrix3f& r) {
  return (r.transpose() * r - Eigen::Matrix3f::Identity()).norm() < 1e-3f &&
         r.determinant() > 0.0f;
}

int ObjectLabel(int index) { return 10 * (index + 2); }

float Luminance(const Eigen::Vector3f& rgb) {
  return 0.299f * rgb.x() + 0.587f * rgb.y() + 0.114f * rgb.z();
}

// Rounds to the nearest 8-bit value, saturating.
uint8_t ToByte(float value) {
  return static_cast<uint8_t>(std::clamp(value, 0.0f, 255.0f) + 0.5f);
}

// Per pixel: how far it lies behind the nearest surface within `radius`
// pixels (Chebyshev), metres; 0 or negative where it is the nearest, and
// hugely negative where depth is NaN.
cv::Mat DepthBehindNearest(const cv::Mat& depth, int radius) {
  constexpr float kFar = 1e6f;  // stands in for NaN in the min filter
  cv::Mat filled = depth.clone();
  cv::patchNaNs(filled, kFar);
  cv::Mat nearest;
  cv::erode(filled, nearest,
            cv::getStructuringElement(cv::MORPH_RECT,
                                      cv::Size(2 * radius + 1, 2 * radius + 1)),
            cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
  cv::Mat behind = depth - nearest;
  cv::patchNaNs(behind, -kFar);
  return behind;
}

// CV_8UC1, 255 where depth must drop out at a depth edge: the far side of
// every jump of more than `edge_jump_m` between 8-neighbours, over
// `edge_dropout_px` pixels (where a Kinect's projector casts its shadow and
// stereo matching fails). Pixels next to no data are not edges; steep but
// continuous surfaces keep their depth.
cv::Mat EdgeDropoutMask(const cv::Mat& depth, const NoiseOptions& noise) {
  const int k = noise.edge_dropout_px;
  if (k <= 0) return cv::Mat::zeros(depth.size(), CV_8UC1);
  const cv::Mat far_of_jump = DepthBehindNearest(depth, 1) > noise.edge_jump_m;
  cv::Mat band;
  cv::dilate(far_of_jump, band,
             cv::getStructuringElement(cv::MORPH_RECT,
                                       cv::Size(2 * k - 1, 2 * k - 1)));
  return band & (DepthBehindNearest(depth, k) > noise.edge_jump_m);
}

// Axial noise and disparity quantisation of one depth, or NaN when the
// quantised disparity is not positive (out of range).
float NoisyDepth(float z, float focal_px, const NoiseOptions& noise,
                 Random& rng) {
  const float sigma = noise.sigma_per_z2 * z * z;
  const float noisy = z + sigma * static_cast<float>(rng.Normal());
  const float fb = focal_px * noise.baseline_m;  // disparity = fb / z
  const float disparity = std::round(fb / noisy / noise.disparity_step_px) *
                          noise.disparity_step_px;
  if (!(disparity > 0.0f)) return std::numeric_limits<float>::quiet_NaN();
  return fb / disparity;
}

}  // namespace

absl::Status Validate(const SceneSpec& spec) {
  if (spec.width <= 0 || spec.height <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("SceneSpec.width and height must be > 0, got ", spec.width,
                     " x ", spec.height));
  }
  if (!(spec.intrinsics.fx > 0.0) || !(spec.intrinsics.fy > 0.0)) {
    return absl::InvalidArgumentError(
        "SceneSpec.intrinsics.fx and fy must be > 0");
  }
  if (!(spec.table_half_size.x() > 0.0f) ||
      !(spec.table_half_size.y() > 0.0f)) {
    return absl::InvalidArgumentError("SceneSpec.table_half_size must be > 0");
  }
  if (!IsUnitRgb(spec.table_rgb)) {
    return absl::InvalidArgumentError("SceneSpec.table_rgb must be in [0, 1]");
  }
  if (!IsRotation(spec.camera_pose.linear())) {
    return absl::InvalidArgumentError(
        "SceneSpec.camera_pose must be a rigid transform");
  }
  for (size_t k = 0; k < spec.objects.size(); ++k) {
    const Primitive& p = spec.objects[k];
    const std::string field = absl::StrCat("SceneSpec.objects[", k, "]");
    if (!IsRotation(p.pose.linear())) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".pose must be a rigid transform"));
    }
    if (!IsUnitRgb(p.rgb)) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".rgb must be in [0, 1]"));
    }
    const bool needs_radius = p.shape != Shape::kBox;
    const bool needs_half_z = p.shape != Shape::kSphere;
    if (needs_radius && !(p.radius > 0.0f)) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".radius must be > 0"));
    }
    if (p.shape == Shape::kBox && !(p.half_extents.minCoeff() > 0.0f)) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".half_extents must be > 0"));
    }
    if (needs_half_z && !(p.half_extents.z() > 0.0f)) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".half_extents.z must be > 0"));
    }
  }
  return absl::OkStatus();
}

absl::Status Validate(const NoiseOptions& options) {
  if (!(options.sigma_per_z2 >= 0.0f)) {
    return absl::InvalidArgumentError("NoiseOptions.sigma_per_z2 must be >= 0");
  }
  if (!(options.baseline_m > 0.0f)) {
    return absl::InvalidArgumentError("NoiseOptions.baseline_m must be > 0");
  }
  if (!(options.disparity_step_px > 0.0f)) {
    return absl::InvalidArgumentError(
        "NoiseOptions.disparity_step_px must be > 0");
  }
  if (options.edge_dropout_px < 0 || !(options.edge_jump_m > 0.0f)) {
    return absl::InvalidArgumentError(
        "NoiseOptions.edge_dropout_px must be >= 0 and edge_jump_m > 0");
  }
  if (!IsUnit(options.dark_albedo) ||
      !IsUnit(options.dark_dropout_probability)) {
    return absl::InvalidArgumentError(
        "NoiseOptions.dark_albedo and dark_dropout_probability must be in "
        "[0, 1]");
  }
  if (!(options.color_sigma >= 0.0f)) {
    return absl::InvalidArgumentError("NoiseOptions.color_sigma must be >= 0");
  }
  return absl::OkStatus();
}

SynthScene RenderScene(const SceneSpec& spec, const NoiseOptions& noise,
                       uint64_t seed) {
  FOVEA_CHECK(Validate(spec).ok());
  FOVEA_CHECK(Validate(noise).ok());
  RaycastImage ray = RaycastScene(spec);
  Random rng(seed ^ kNoiseStream);
  const bool noisy = noise.enabled;
  const cv::Mat edge_dropout =
      noisy ? EdgeDropoutMask(ray.depth, noise) : cv::Mat();
  const float focal = static_cast<float>(spec.intrinsics.fx);

  // Albedo, label and darkness of each hit index (0 table, k + 1 object).
  std::vector<Eigen::Vector3f> albedo = {spec.table_rgb};
  std::vector<int> label = {kTableLabel};
  for (size_t k = 0; k < spec.objects.size(); ++k) {
    albedo.push_back(spec.objects[k].rgb);
    label.push_back(ObjectLabel(static_cast<int>(k)));
  }
  std::vector<bool> dark;
  for (const Eigen::Vector3f& rgb : albedo) {
    dark.push_back(Luminance(rgb) < noise.dark_albedo);
  }

  SynthScene scene;
  cv::Mat depth = std::move(ray.depth);
  cv::Mat color(spec.height, spec.width, CV_8UC3);
  cv::Mat labels(spec.height, spec.width, CV_32SC1);
  std::vector<int> visible(spec.objects.size(), 0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < spec.height; ++v) {
    const int* hit_row = ray.hit.ptr<int>(v);
    const cv::Vec3f* normal_row = ray.normal.ptr<cv::Vec3f>(v);
    float* depth_row = depth.ptr<float>(v);
    cv::Vec3b* color_row = color.ptr<cv::Vec3b>(v);
    int* label_row = labels.ptr<int>(v);
    for (int u = 0; u < spec.width; ++u) {
      const int hit = hit_row[u];
      Eigen::Vector3f rgb(kBackgroundRgb[0], kBackgroundRgb[1],
                          kBackgroundRgb[2]);
      label_row[u] = 0;
      if (hit >= 0) {
        const cv::Vec3f& n = normal_row[u];
        const float lambert = std::max(0.0f, n[0] * kLightDirection.x() +
                                                 n[1] * kLightDirection.y() +
                                                 n[2] * kLightDirection.z());
        rgb = albedo[hit] * (kAmbient + kDiffuse * lambert);
        if (noisy) {
          const bool dropped =
              edge_dropout.at<uint8_t>(v, u) != 0 ||
              (dark[hit] && rng.Bernoulli(noise.dark_dropout_probability));
          depth_row[u] =
              dropped ? nan : NoisyDepth(depth_row[u], focal, noise, rng);
        }
        if (!std::isnan(depth_row[u])) {
          label_row[u] = label[hit];
          if (hit > 0) ++visible[hit - 1];
        }
      }
      for (int c = 0; c < 3; ++c) {
        float value = 255.0f * rgb[c];
        if (noisy) {
          value += noise.color_sigma * rng.ApproxNormal();
        }
        color_row[u][c] = ToByte(value);
      }
    }
  }

  scene.frame.name = absl::StrCat("synth-", seed);
  scene.frame.frame.color = std::move(color);
  scene.frame.frame.depth = std::move(depth);
  scene.frame.frame.intrinsics = spec.intrinsics;
  scene.frame.labels = std::move(labels);
  for (size_t k = 0; k < spec.objects.size(); ++k) {
    scene.objects.push_back(
        {ObjectLabel(static_cast<int>(k)), spec.objects[k], visible[k]});
  }

  // World plane z = 0 in the camera frame: n_c = R^T e_z, d_c = e_z . t.
  const Eigen::Matrix3f r = spec.camera_pose.linear();
  Eigen::Vector3f n = r.transpose() * Eigen::Vector3f::UnitZ();
  float d = spec.camera_pose.translation().z();
  if (d < 0.0f) {  // camera under the table: point n towards it anyway
    n = -n;
    d = -d;
  }
  scene.table_normal_camera = n;
  scene.table_d_camera = d;
  return scene;
}

SynthScene GenerateScene(uint64_t seed) {
  return RenderScene(RandomSceneSpec(seed, RandomSceneOptions{}),
                     NoiseOptions{}, seed);
}

}  // namespace fovea::synth
