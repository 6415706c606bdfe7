#include "core/saliency/sym3d.h"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/parallel.h"
#include "core/base/status_macros.h"
#include "core/saliency/saliency_map.h"

namespace fovea {
namespace {

constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);

// The patch around one pixel, relative to its centre point.
struct Patch {
  std::vector<Eigen::Vector3f> offsets;  // q_i - p
  std::vector<Eigen::Vector3f> normals;  // m_i
  float mean_radius = 0.0f;              // r = mean |q_i - p|
};

void GatherPatch(const OrganizedCloud& cloud, int u, int v, int half,
                 float max_distance, Patch& patch) {
  patch.offsets.clear();
  patch.normals.clear();
  const cv::Vec3f& c = cloud.xyz.at<cv::Vec3f>(v, u);
  const Eigen::Vector3f p(c[0], c[1], c[2]);
  const float max_d2 = max_distance * max_distance;
  float radius_sum = 0.0f;
  for (int dv = -half; dv <= half; ++dv) {
    const int y = v + dv;
    if (y < 0 || y >= cloud.height()) continue;
    const cv::Vec3f* row = cloud.xyz.ptr<cv::Vec3f>(y);
    const cv::Vec3f* nrow = cloud.normals.ptr<cv::Vec3f>(y);
    for (int du = -half; du <= half; ++du) {
      const int x = u + du;
      if (x < 0 || x >= cloud.width()) continue;
      if (std::isnan(row[x][2]) || std::isnan(nrow[x][2])) continue;
      const Eigen::Vector3f d =
          Eigen::Vector3f(row[x][0], row[x][1], row[x][2]) - p;
      const float d2 = d.squaredNorm();
      if (d2 > max_d2) continue;
      patch.offsets.push_back(d);
      patch.normals.emplace_back(nrow[x][0], nrow[x][1], nrow[x][2]);
      radius_sum += std::sqrt(d2);
    }
  }
  if (!patch.offsets.empty()) {
    patch.mean_radius = radius_sum / patch.offsets.size();
  }
}

// Principal axes of the normals (the extended Gaussian image), as columns.
Eigen::Matrix3f NormalAxes(const Patch& patch) {
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& m : patch.normals) mean += m;
  mean /= static_cast<float>(patch.normals.size());
  Eigen::Matrix3f cov = Eigen::Matrix3f::Zero();
  for (const Eigen::Vector3f& m : patch.normals) {
    const Eigen::Vector3f d = m - mean;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eig;
  eig.computeDirect(cov);
  return eig.eigenvectors();
}

// Omega_j for the plane through the patch centre with unit normal `n`.
float PlaneSymmetry(const Patch& patch, const Eigen::Vector3f& n, float band,
                    const Sym3dOptions& options, float curved_rad) {
  Eigen::Vector3f sum_p[2] = {Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero()};
  Eigen::Vector3f sum_m[2] = {Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero()};
  int count[2] = {0, 0};
  for (size_t i = 0; i < patch.offsets.size(); ++i) {
    const float s = n.dot(patch.offsets[i]);
    if (std::abs(s) <= band) continue;
    const int side = s > 0.0f ? 0 : 1;
    sum_p[side] += patch.offsets[i];
    sum_m[side] += patch.normals[i];
    ++count[side];
  }
  if (count[0] < options.min_side_points ||
      count[1] < options.min_side_points) {
    return 0.0f;
  }
  const Eigen::Vector3f p_plus = sum_p[0] / count[0];
  const Eigen::Vector3f p_minus = sum_p[1] / count[1];
  const Eigen::Vector3f m_plus = sum_m[0].normalized();
  const Eigen::Vector3f m_minus = sum_m[1].normalized();
  // Concave across the plane (eq. 2.18): normals converge.
  if ((m_plus - m_minus).dot(n) <= 0.0f) return 0.0f;
  // Reflections in the plane through the origin (the patch centre).
  const Eigen::Vector3f rp = p_plus - 2.0f * n.dot(p_plus) * n;
  const Eigen::Vector3f rm = m_plus - 2.0f * n.dot(m_plus) * n;
  const float dD = (rp - p_minus).norm() / patch.mean_radius;
  const float dd = (rm - m_minus).norm();
  const float w1 = static_cast<float>(std::min(count[0], count[1])) /
                   static_cast<float>(std::max(count[0], count[1]));
  const float angle = std::acos(std::clamp(m_plus.dot(m_minus), -1.0f, 1.0f));
  const float w2 = std::min(1.0f, angle / curved_rad);
  return std::exp(-dD) * std::exp(-dd) * w1 * w2;
}

}  // namespace

absl::Status Validate(const Sym3dOptions& options) {
  if (options.kernel_size < 3 || options.kernel_size % 2 == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "sym3d.kernel_size must be odd and >= 3, got ", options.kernel_size));
  }
  if (!(options.max_distance_factor > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("sym3d.max_distance_factor must be > 0, got ",
                     options.max_distance_factor));
  }
  if (options.min_side_points < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "sym3d.min_side_points must be >= 1, got ", options.min_side_points));
  }
  if (!(options.plane_band_fraction >= 0.0f &&
        options.plane_band_fraction < 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("sym3d.plane_band_fraction must be in [0, 1), got ",
                     options.plane_band_fraction));
  }
  if (!(options.curved_angle_deg > 0.0f &&
        options.curved_angle_deg <= 180.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("sym3d.curved_angle_deg must be in (0, 180], got ",
                     options.curved_angle_deg));
  }
  return absl::OkStatus();
}

absl::StatusOr<cv::Mat> ComputeSym3dSaliency(const OrganizedCloud& cloud,
                                             const TableScene& scene,
                                             const Sym3dOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (scene.candidate.size() != cloud.xyz.size()) {
    return absl::InvalidArgumentError(
        "sym3d: table scene and cloud differ in size");
  }
  const int w = cloud.width(), h = cloud.height();
  cv::Mat map(h, w, CV_32FC1, cv::Scalar(0));
  const int half = options.kernel_size / 2;
  const float inv_fx = static_cast<float>(1.0 / cloud.intrinsics.fx);
  const float curved_rad = options.curved_angle_deg * kDegToRad;
  // Rows in parallel, each range with its own patch buffers; each pixel
  // writes only its own output.
  ParallelForRanges(h, [&](int begin, int end) {
    Patch patch;
    patch.offsets.reserve(options.kernel_size * options.kernel_size);
    patch.normals.reserve(options.kernel_size * options.kernel_size);
    for (int v = begin; v < end; ++v) {
      const uint8_t* cand = scene.candidate.ptr<uint8_t>(v);
      const cv::Vec3f* row = cloud.xyz.ptr<cv::Vec3f>(v);
      const cv::Vec3f* nrow = cloud.normals.ptr<cv::Vec3f>(v);
      float* out = map.ptr<float>(v);
      for (int u = 0; u < w; ++u) {
        if (!cand[u] || std::isnan(nrow[u][2])) continue;
        const float half_width = half * row[u][2] * inv_fx;  // metres
        GatherPatch(cloud, u, v, half, options.max_distance_factor * half_width,
                    patch);
        if (patch.offsets.size() < 2u * options.min_side_points ||
            !(patch.mean_radius > 0.0f)) {
          continue;
        }
        const Eigen::Matrix3f axes = NormalAxes(patch);
        const float band = options.plane_band_fraction * half_width;
        float best = 0.0f;
        for (int j = 0; j < 3; ++j) {
          best = std::max(best, PlaneSymmetry(patch, axes.col(j), band, options,
                                              curved_rad));
        }
        out[u] = best;
      }
    }
  });
  NormalizeLinear(map);
  return map;
}

}  // namespace fovea
