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
#include "core/base/status_macros.h"
#include "core/frame/osd_pcd.h"
#include "core/synth/random.h"
#include "core/synth/raycast.h"
#include "core/synth/textures.h"

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

// CV_8UC1, 255 where the second viewpoint (noise.shadow_baseline_m to the
// camera's right) does not see the surface: a pixel at column u and depth z
// lands at u - f b / z there, and is hidden when a pixel to its right lands
// at or left of it (the two crossed, the nearer one in front); with
// border_band also where it lands left of the image.
cv::Mat ShadowMask(const cv::Mat& depth, float focal_px,
                   const NoiseOptions& noise) {
  cv::Mat shadow(depth.size(), CV_8UC1, cv::Scalar(0));
  if (!(noise.shadow_baseline_m > 0.0f)) return shadow;
  const float fb = focal_px * noise.shadow_baseline_m;
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    uint8_t* out = shadow.ptr<uint8_t>(v);
    float nearest_landing = std::numeric_limits<float>::infinity();
    for (int u = depth.cols - 1; u >= 0; --u) {
      if (std::isnan(z[u])) continue;
      const float landing = static_cast<float>(u) - fb / z[u];
      if (landing >= nearest_landing || (noise.border_band && landing < 0.0f)) {
        out[u] = 255;
      }
      nearest_landing = std::min(nearest_landing, landing);
    }
  }
  return shadow;
}

// Standard normal noise per pixel, smoothed over `correlation_px` (Gaussian
// sigma) and rescaled to unit variance.
cv::Mat CorrelatedNormalField(cv::Size size, float correlation_px,
                              Random& rng) {
  cv::Mat field(size, CV_32FC1);
  for (int v = 0; v < size.height; ++v) {
    float* row = field.ptr<float>(v);
    for (int u = 0; u < size.width; ++u) row[u] = rng.ApproxNormal();
  }
  cv::GaussianBlur(field, field, cv::Size(), correlation_px, correlation_px,
                   cv::BORDER_REFLECT);
  cv::Scalar mean, stddev;
  cv::meanStdDev(field, mean, stddev);
  if (stddev[0] > 0.0) field = (field - mean[0]) / stddev[0];
  return field;
}

// Axial noise and disparity quantisation of one depth, or NaN when the
// quantised disparity is not positive (out of range). `normal` is a
// standard normal draw.
float NoisyDepth(float z, float focal_px, const NoiseOptions& noise,
                 float normal) {
  const float sigma = noise.sigma0_m + noise.sigma_per_z2 * z * z;
  const float noisy = z + sigma * normal;
  if (noise.disparity_step_px == 0.0f) {
    return noisy > 0.0f ? noisy : std::numeric_limits<float>::quiet_NaN();
  }
  const float fb = focal_px * noise.baseline_m;  // disparity = fb / z
  const float disparity = std::round(fb / noisy / noise.disparity_step_px) *
                          noise.disparity_step_px;
  if (!(disparity > 0.0f)) return std::numeric_limits<float>::quiet_NaN();
  return fb / disparity;
}

// What the sensor makes of a ray-cast depth image: its dropouts (edges,
// shadows, dark surfaces), mixed pixels and noise, pixel by pixel. Draws
// from `rng` in the order RenderScene always has: the correlated noise
// field here, then per pixel as Measure is called.
class SensorDepth {
 public:
  SensorDepth(const cv::Mat& depth, float focal, const NoiseOptions& noise,
              Random& rng)
      : focal_(focal), noise_(noise) {
    if (!noise.enabled) return;
    const cv::Mat band = EdgeDropoutMask(depth, noise);
    edge_dropout_ = band | ShadowMask(depth, focal, noise);
    // With flying pixels: the edge band (not the shadows) and how far each
    // of its pixels lies behind the nearer surface.
    if (noise.flying_pixel_probability > 0.0f) {
      flying_band_ = band;
      behind_nearest_ =
          DepthBehindNearest(depth, std::max(1, noise.edge_dropout_px));
    }
    if (noise.noise_correlation_px > 0.0f) {
      depth_noise_ =
          CorrelatedNormalField(depth.size(), noise.noise_correlation_px, rng);
    }
  }

  // Replaces the true depth `z` of pixel (v, u), on a dark surface or not,
  // with what the sensor measures there (NaN for none). Whether the pixel
  // keeps its label: a dark surface's dropped pixels do, as a labeller
  // marks a black mug whole; an edge's do not (OSD labels points, and
  // there is no point there, or a mixed one).
  bool Measure(int v, int u, bool dark, Random& rng, float& z) const {
    const bool edge = edge_dropout_.at<uint8_t>(v, u) != 0;
    const bool dropped =
        edge || (dark && rng.Bernoulli(noise_.dark_dropout_probability));
    if (!dropped) {
      const float normal = depth_noise_.empty()
                               ? static_cast<float>(rng.Normal())
                               : depth_noise_.at<float>(v, u);
      z = NoisyDepth(z, focal_, noise_, normal);
      return true;
    }
    const float true_z = z;
    z = std::numeric_limits<float>::quiet_NaN();
    if (edge && !flying_band_.empty() && flying_band_.at<uint8_t>(v, u) != 0 &&
        rng.Bernoulli(noise_.flying_pixel_probability)) {
      const float mixed =
          true_z - rng.Uniform(0.2f, 0.8f) * behind_nearest_.at<float>(v, u);
      z = NoisyDepth(mixed, focal_, noise_, static_cast<float>(rng.Normal()));
    }
    return !edge;
  }

 private:
  const float focal_;
  const NoiseOptions& noise_;
  cv::Mat edge_dropout_;
  cv::Mat flying_band_;
  cv::Mat behind_nearest_;
  cv::Mat depth_noise_;
};

// OK, or INVALID_ARGUMENT naming `field` (the primitive's place in the
// SceneSpec): see Validate(const SceneSpec&).
absl::Status ValidatePrimitive(const Primitive& p, const std::string& field) {
  if (!IsRotation(p.pose.linear())) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".pose must be a rigid transform"));
  }
  if (!IsUnitRgb(p.rgb)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".rgb must be in [0, 1]"));
  }
  if (!IsUnitRgb(p.print_rgb)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".print_rgb must be in [0, 1]"));
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
  const bool hollow = p.shape == Shape::kBowl || p.shape == Shape::kCup;
  if (hollow && !(p.thickness > 0.0f && p.thickness < p.radius &&
                  p.thickness < 2.0f * p.half_extents.z())) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ".thickness must be > 0 and below the radius and height"));
  }
  if (p.shape == Shape::kBowl && !(2.0f * p.half_extents.z() < p.radius)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field,
                     ": a bowl's depth (2 half_extents.z) must be "
                     "below its radius"));
  }
  if (p.shape == Shape::kBowl &&
      !(p.floor_height >= 0.0f && p.floor_height < 2.0f * p.half_extents.z())) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".floor_height must be in [0, the bowl's depth)"));
  }
  if (p.shape == Shape::kBowl && !(p.floor_radius >= 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".floor_radius must be >= 0"));
  }
  if (p.shape == Shape::kBowl && p.floor_radius > 0.0f) {
    const float h = p.half_extents.z();
    const float rim = p.radius - p.thickness;
    const float depth = 2.0f * h - std::max(p.thickness, p.floor_height);
    const float foot = std::sqrt(p.radius * p.radius - 4.0f * h * h);
    if (!(p.floor_radius * p.floor_radius <= rim * rim - depth * depth) ||
        !(p.floor_radius < foot)) {
      return absl::InvalidArgumentError(absl::StrCat(
          field,
          ".floor_radius must be at most sqrt((radius - thickness)^2 - "
          "depth^2) and below the foot's radius"));
    }
  }
  return absl::OkStatus();
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
    FOVEA_RETURN_IF_ERROR(ValidatePrimitive(
        spec.objects[k], absl::StrCat("SceneSpec.objects[", k, "]")));
  }
  for (size_t i = 0; i < spec.object_parts.size(); ++i) {
    const ObjectPart& part = spec.object_parts[i];
    const std::string field = absl::StrCat("SceneSpec.object_parts[", i, "]");
    if (part.object < 0 ||
        part.object >= static_cast<int>(spec.objects.size())) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".object must index SceneSpec.objects, got ", part.object));
    }
    FOVEA_RETURN_IF_ERROR(
        ValidatePrimitive(part.primitive, absl::StrCat(field, ".primitive")));
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
  if (!(options.disparity_step_px >= 0.0f)) {
    return absl::InvalidArgumentError(
        "NoiseOptions.disparity_step_px must be >= 0");
  }
  if (!IsUnit(options.flying_pixel_probability)) {
    return absl::InvalidArgumentError(
        "NoiseOptions.flying_pixel_probability must be in [0, 1]");
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
  if (!(options.sigma0_m >= 0.0f) || !(options.noise_correlation_px >= 0.0f) ||
      !(options.shadow_baseline_m >= 0.0f)) {
    return absl::InvalidArgumentError(
        "NoiseOptions.sigma0_m, noise_correlation_px and shadow_baseline_m "
        "must be >= 0");
  }
  return absl::OkStatus();
}

NoiseOptions KinectV1Noise() {
  NoiseOptions noise;
  noise.shadow_baseline_m = 0.075f;
  noise.noise_correlation_px = 2.0f;
  return noise;
}

NoiseOptions IndependentKinectV1Noise() {
  NoiseOptions noise = KinectV1Noise();
  noise.noise_correlation_px = 0.0f;
  return noise;
}

NoiseOptions ActiveStereoNoise() {
  NoiseOptions noise;
  noise.sigma0_m = 0.0005f;
  noise.sigma_per_z2 = 1.25e-3f;
  noise.noise_correlation_px = 3.0f;
  noise.baseline_m = 0.05f;
  noise.disparity_step_px = 0.05f;
  noise.edge_dropout_px = 1;
  noise.shadow_baseline_m = 0.05f;
  noise.border_band = true;
  noise.dark_albedo = 0.15f;
  noise.dark_dropout_probability = 0.7f;
  noise.color_sigma = 2.5f;
  return noise;
}

NoiseOptions TimeOfFlightNoise() {
  NoiseOptions noise;
  noise.sigma0_m = 0.001f;
  noise.sigma_per_z2 = 0.5e-3f;
  noise.noise_correlation_px = 1.0f;  // the lens's blur, little else
  noise.disparity_step_px = 0.0f;
  noise.edge_dropout_px = 2;
  noise.flying_pixel_probability = 0.3f;
  noise.shadow_baseline_m = 0.0f;
  noise.dark_albedo = 0.1f;
  noise.dark_dropout_probability = 0.5f;
  noise.color_sigma = 2.5f;
  return noise;
}

SynthScene RenderScene(const SceneSpec& spec, const NoiseOptions& noise,
                       uint64_t seed) {
  FOVEA_CHECK(Validate(spec).ok());
  FOVEA_CHECK(Validate(noise).ok());
  RaycastImage ray = RaycastScene(spec);
  Random rng(seed ^ kNoiseStream);
  const bool noisy = noise.enabled;
  const float focal = static_cast<float>(spec.intrinsics.fx);
  const SensorDepth sensor(ray.depth, focal, noise, rng);

  // Albedo, texture, label, object (or -1) and darkness of each hit index
  // (0 table, k + 1 object, then the background parts, then the object
  // parts).
  std::vector<Eigen::Vector3f> albedo = {spec.table_rgb};
  std::vector<Texture> texture = {spec.table_texture};
  // kPrint's colour and the world-to-primitive transform of each hit index.
  std::vector<Eigen::Vector3f> print_rgb = {spec.table_rgb};
  std::vector<Eigen::Isometry3f> world_to_local = {
      Eigen::Isometry3f::Identity()};
  const auto add_print = [&](const Primitive& p) {
    print_rgb.push_back(p.print_rgb);
    world_to_local.push_back(p.pose.inverse());
  };
  std::vector<int> label = {kTableLabel};
  std::vector<int> object_of_hit = {-1};
  for (size_t k = 0; k < spec.objects.size(); ++k) {
    albedo.push_back(spec.objects[k].rgb);
    add_print(spec.objects[k]);
    texture.push_back(spec.objects[k].texture);
    label.push_back(ObjectLabel(static_cast<int>(k)));
    object_of_hit.push_back(static_cast<int>(k));
  }
  for (const BackgroundPart& part : spec.background) {
    albedo.push_back(part.primitive.rgb);
    add_print(part.primitive);
    texture.push_back(part.primitive.texture);
    label.push_back(part.label);
    object_of_hit.push_back(-1);
  }
  for (const ObjectPart& part : spec.object_parts) {
    albedo.push_back(part.primitive.rgb);
    add_print(part.primitive);
    texture.push_back(part.primitive.texture);
    label.push_back(ObjectLabel(part.object));
    object_of_hit.push_back(part.object);
  }
  const Eigen::Matrix3f cam_to_world = spec.camera_pose.linear();
  const Eigen::Vector3f eye = spec.camera_pose.translation();
  const float fx = static_cast<float>(spec.intrinsics.fx);
  const float fy = static_cast<float>(spec.intrinsics.fy);
  const float cx = static_cast<float>(spec.intrinsics.cx);
  const float cy = static_cast<float>(spec.intrinsics.cy);
  std::vector<bool> dark;
  for (const Eigen::Vector3f& rgb : albedo) {
    dark.push_back(Luminance(rgb) < noise.dark_albedo);
  }

  SynthScene scene;
  cv::Mat depth = std::move(ray.depth);
  cv::Mat color(spec.height, spec.width, CV_8UC3);
  cv::Mat labels(spec.height, spec.width, CV_32SC1);
  std::vector<int> visible(spec.objects.size(), 0);
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
        float shade = kAmbient + kDiffuse * lambert;
        Eigen::Vector3f surface = albedo[hit];
        if (texture[hit] != Texture::kFlat) {
          const float z = depth_row[u];
          const Eigen::Vector3f world =
              eye + cam_to_world * Eigen::Vector3f((u - cx) / fx * z,
                                                   (v - cy) / fy * z, z);
          if (texture[hit] == Texture::kPrint) {
            const float w = PrintWeight(world_to_local[hit] * world);
            surface = (1.0f - w) * surface + w * print_rgb[hit];
          } else {
            shade *= TextureFactor(texture[hit], world);
          }
        }
        rgb = (surface * shade).cwiseMin(1.0f);
        const bool labelled =
            !noisy || sensor.Measure(v, u, dark[hit], rng, depth_row[u]);
        if (labelled) {
          label_row[u] = label[hit];
          if (object_of_hit[hit] >= 0) ++visible[object_of_hit[hit]];
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

RandomSceneOptions PileOptions() {
  RandomSceneOptions o;
  o.min_objects = 8;
  o.max_objects = 16;
  o.household = true;
  o.stack_probability = 0.25f;
  o.touch_probability = 0.4f;
  o.occlude_probability = 0.1f;
  o.lean_probability = 0.1f;
  o.work_area_scale = 0.75f;
  o.camera_height = 0.7f;
  o.camera_distance = 0.65f;
  return o;
}

SynthScene GeneratePile(uint64_t seed) {
  SceneSpec spec = RandomSceneSpec(seed, PileOptions());
  AddPrints(seed, kPrintedObjectShare, spec);
  SynthScene scene = RenderScene(spec, KinectV1Noise(), seed);
  scene.frame.name = absl::StrCat("pile-", seed);
  return scene;
}

}  // namespace fovea::synth
