#include "core/segmentation/planar_patches.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);
// Curvature in [0, 1] is sorted into this many buckets (counting sort).
constexpr int kCurvatureBuckets = 1024;
// Label states while growing.
constexpr int kUnvisited = -2;
constexpr int kUnused = -3;   // no normal, or outside the mask
constexpr int kSupport = -4;  // on the support, labelled by its parts
constexpr int kNoise = -1;

// Least-squares plane of the points summed in `sum` and `sum_outer`,
// oriented towards the camera; false when degenerate.
bool FitPlane(const Eigen::Vector3d& sum, const Eigen::Matrix3d& sum_outer,
              int n, Eigen::Vector3f& normal, float& d) {
  if (n < 3) return false;
  const Eigen::Vector3d c = sum / n;
  const Eigen::Matrix3d cov = sum_outer / n - c * c.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  Eigen::Vector3d nrm = eig.eigenvectors().col(0);
  if (!nrm.allFinite() || nrm.norm() < 0.5) return false;
  if (nrm.dot(c) > 0.0) nrm = -nrm;
  normal = nrm.cast<float>().normalized();
  d = static_cast<float>(-nrm.dot(c));
  return true;
}

// sum_outer += p p^T: the six distinct products once each (a product is
// the same either way round, so the sum is what the full product gives).
void AddOuterProduct(const Eigen::Vector3d& p, Eigen::Matrix3d& sum_outer) {
  const double xy = p.x() * p.y(), xz = p.x() * p.z(), yz = p.y() * p.z();
  sum_outer(0, 0) += p.x() * p.x();
  sum_outer(1, 0) += xy;
  sum_outer(2, 0) += xz;
  sum_outer(0, 1) += xy;
  sum_outer(1, 1) += p.y() * p.y();
  sum_outer(2, 1) += yz;
  sum_outer(0, 2) += xz;
  sum_outer(1, 2) += yz;
  sum_outer(2, 2) += p.z() * p.z();
}

// The 4-neighbours of pixel index i = v * w + u of a w x h image; -1
// outside it.
std::array<int, 4> Neighbours4(int i, int u, int v, int w, int h) {
  return {u > 0 ? i - 1 : -1, u + 1 < w ? i + 1 : -1, v > 0 ? i - w : -1,
          v + 1 < h ? i + w : -1};
}

// A pixel in a breadth-first queue, with its coordinates (no division to
// find them again).
struct Pixel {
  int i, u, v;
};

// Point q continues the surface of its neighbour i (no depth step) and
// lies on the plane n . p + d = 0 within the depth-dependent tolerance.
bool ContinuesOntoPlane(const cv::Vec3f& q, const cv::Vec3f& i,
                        const Eigen::Vector3f& n, float d,
                        const PlanarPatchOptions& options) {
  if (std::abs(q[2] - i[2]) >
      options.max_depth_step_fraction * std::min(q[2], i[2])) {
    return false;
  }
  const float tolerance =
      options.max_plane_distance + options.distance_per_m2 * q[2] * q[2];
  return std::abs(n.x() * q[0] + n.y() * q[1] + n.z() * q[2] + d) <= tolerance;
}

// Each 4-connected part of the kSupport pixels becomes one patch (noise
// below options.min_points), its plane fitted to all its points.
void AddSupportParts(const cv::Vec3f* xyz, int w, int h,
                     const PlanarPatchOptions& options, int* label,
                     PlanarPatches& result) {
  cv::Mat on_support(h, w, CV_8UC1);
  const int n = w * h;
  for (int i = 0; i < n; ++i) on_support.data[i] = label[i] == kSupport;
  cv::Mat parts;
  const int count = cv::connectedComponents(on_support, parts, 4, CV_32S);
  std::vector<Eigen::Vector3d> sum(count, Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> sum_outer(count, Eigen::Matrix3d::Zero());
  std::vector<int> size(count, 0);
  const int* part = parts.ptr<int>();
  for (int i = 0; i < n; ++i) {
    if (part[i] == 0) continue;
    const Eigen::Vector3d p(xyz[i][0], xyz[i][1], xyz[i][2]);
    sum[part[i]] += p;
    AddOuterProduct(p, sum_outer[part[i]]);
    ++size[part[i]];
  }
  std::vector<int> id(count, kNoise);
  for (int k = 1; k < count; ++k) {
    PlanarPatch patch;
    if (size[k] < options.min_points ||
        !FitPlane(sum[k], sum_outer[k], size[k], patch.normal, patch.d)) {
      continue;
    }
    patch.centroid = (sum[k] / static_cast<double>(size[k])).cast<float>();
    id[k] = static_cast<int>(result.patches.size());
    result.patches.push_back(patch);
  }
  for (int i = 0; i < n; ++i) {
    if (part[i] != 0) label[i] = id[part[i]];
  }
}

}  // namespace

absl::Status Validate(const PlanarPatchOptions& options) {
  if (!(options.max_plane_distance > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("planar_patches.max_plane_distance must be > 0, got ",
                     options.max_plane_distance));
  }
  if (!(options.distance_per_m2 >= 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("planar_patches.distance_per_m2 must be >= 0, got ",
                     options.distance_per_m2));
  }
  if (!(options.max_normal_angle_deg > 0.0f &&
        options.max_normal_angle_deg < 90.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("planar_patches.max_normal_angle_deg must be in (0, 90), "
                     "got ",
                     options.max_normal_angle_deg));
  }
  if (!(options.max_depth_step_fraction > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("planar_patches.max_depth_step_fraction must be > 0, got ",
                     options.max_depth_step_fraction));
  }
  if (!(options.refit_growth == 0.0f || options.refit_growth > 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("planar_patches.refit_growth must be 0 or > 1, got ",
                     options.refit_growth));
  }
  if (options.min_points < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "planar_patches.min_points must be >= 1, got ", options.min_points));
  }
  return absl::OkStatus();
}

absl::StatusOr<PlanarPatches> FindPlanarPatches(
    const OrganizedCloud& cloud, const cv::Mat& mask,
    const PlanarPatchOptions& options, const cv::Mat& support) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  const int w = cloud.width(), h = cloud.height();
  if (!mask.empty() &&
      (mask.type() != CV_8UC1 || mask.rows != h || mask.cols != w)) {
    return absl::InvalidArgumentError(
        "planar_patches: mask must be CV_8UC1 of the cloud's size");
  }
  if (!support.empty() && (support.type() != CV_8UC1 || support.rows != h ||
                           support.cols != w || !support.isContinuous())) {
    return absl::InvalidArgumentError(
        "planar_patches: support must be a continuous CV_8UC1 of the cloud's "
        "size");
  }
  if (!cloud.xyz.isContinuous() || !cloud.normals.isContinuous() ||
      (!mask.empty() && !mask.isContinuous())) {
    return absl::InvalidArgumentError(
        "planar_patches: cloud and mask must be continuous matrices");
  }
  const int n = w * h;
  const auto* xyz = reinterpret_cast<const cv::Vec3f*>(cloud.xyz.data);
  const auto* nrm = reinterpret_cast<const cv::Vec3f*>(cloud.normals.data);
  PlanarPatches result;
  result.labels.create(h, w, CV_32SC1);
  int* label = result.labels.ptr<int>();
  for (int i = 0; i < n; ++i) {
    const bool use = !std::isnan(nrm[i][2]) && !std::isnan(xyz[i][2]) &&
                     (mask.empty() || mask.data[i] != 0);
    label[i] = !use                                       ? kUnused
               : !support.empty() && support.data[i] != 0 ? kSupport
                                                          : kUnvisited;
  }

  // Curvature, counting-sorted into seed order.
  // Read only where label[i] == kUnvisited, written there first.
  std::unique_ptr<uint16_t[]> bucket(new uint16_t[n]);
  std::vector<int> count(kCurvatureBuckets + 1, 0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int i = v * w + u;
      if (label[i] != kUnvisited) continue;
      cv::Vec3f m(0, 0, 0);
      for (int dv = -1; dv <= 1; ++dv) {
        const int y = v + dv;
        if (y < 0 || y >= h) continue;
        for (int du = -1; du <= 1; ++du) {
          const int x = u + du;
          if (x < 0 || x >= w || label[y * w + x] == kUnused) continue;
          m += nrm[y * w + x];
        }
      }
      const float len = std::sqrt(m.dot(m));
      const float curvature =
          len > 0.0f
              ? std::clamp(1.0f - std::abs(nrm[i].dot(m)) / len, 0.0f, 1.0f)
              : 1.0f;
      bucket[i] = static_cast<uint16_t>(
          std::min(kCurvatureBuckets - 1,
                   static_cast<int>(curvature * kCurvatureBuckets)));
      ++count[bucket[i] + 1];
    }
  }
  for (int b = 0; b < kCurvatureBuckets; ++b) count[b + 1] += count[b];
  std::vector<int> order(count[kCurvatureBuckets]);
  for (int i = 0; i < n; ++i) {
    if (label[i] == kUnvisited) order[count[bucket[i]]++] = i;
  }

  const float min_cos = std::cos(options.max_normal_angle_deg * kDegToRad);
  std::vector<Pixel> members;
  members.reserve(n);
  for (const int seed : order) {
    if (label[seed] != kUnvisited) continue;
    const int id = static_cast<int>(result.patches.size());
    Eigen::Vector3f normal(nrm[seed][0], nrm[seed][1], nrm[seed][2]);
    const Eigen::Vector3f p0(xyz[seed][0], xyz[seed][1], xyz[seed][2]);
    float d = -normal.dot(p0);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();
    int next_fit = 3;
    members.clear();
    members.push_back({seed, seed % w, seed / w});
    label[seed] = id;
    for (size_t head = 0; head < members.size(); ++head) {
      const Pixel m = members[head];
      const int i = m.i;
      const Eigen::Vector3d p(xyz[i][0], xyz[i][1], xyz[i][2]);
      sum += p;
      AddOuterProduct(p, sum_outer);
      const int size = static_cast<int>(head) + 1;
      if (options.refit_growth > 0.0f && size >= next_fit) {
        FitPlane(sum, sum_outer, size, normal, d);
        next_fit = static_cast<int>(std::ceil(size * options.refit_growth));
      }
      const std::array<int, 4> next = Neighbours4(i, m.u, m.v, w, h);
      const Pixel at[4] = {{next[0], m.u - 1, m.v},
                           {next[1], m.u + 1, m.v},
                           {next[2], m.u, m.v - 1},
                           {next[3], m.u, m.v + 1}};
      for (const Pixel& q : at) {
        if (q.i < 0 || label[q.i] != kUnvisited) continue;
        if (!ContinuesOntoPlane(xyz[q.i], xyz[i], normal, d, options)) continue;
        const Eigen::Vector3f nq(nrm[q.i][0], nrm[q.i][1], nrm[q.i][2]);
        if (normal.dot(nq) < min_cos) continue;
        label[q.i] = id;
        members.push_back(q);
      }
    }
    if (static_cast<int>(members.size()) < options.min_points) {
      for (const Pixel& m : members) label[m.i] = kNoise;
      continue;
    }
    PlanarPatch patch;
    FitPlane(sum, sum_outer, static_cast<int>(members.size()), normal, d);
    patch.normal = normal;
    patch.d = d;
    patch.centroid = (sum / static_cast<double>(members.size())).cast<float>();
    result.patches.push_back(patch);
  }
  if (!support.empty()) AddSupportParts(xyz, w, h, options, label, result);
  // Points near a fold have normals smoothed across it, which no patch
  // accepts; they join a neighbouring patch whose plane they lie on
  // (distance test only), growing out from the patches breadth first.
  // A patch's pixel none of whose 4-neighbours is left over now never
  // has one later (labels only go from left over to a patch), so the
  // search starts from those that have one: the same joins, in the same
  // order, as from every patch pixel.
  const auto left_over = [label](int q) {
    return q >= 0 && (label[q] == kNoise || label[q] == kUnvisited);
  };
  std::vector<Pixel> frontier;
  for (int v = 0, i = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u, ++i) {
      if (label[i] < 0) continue;
      const std::array<int, 4> next = Neighbours4(i, u, v, w, h);
      if (left_over(next[0]) || left_over(next[1]) || left_over(next[2]) ||
          left_over(next[3])) {
        frontier.push_back({i, u, v});
      }
    }
  }
  for (size_t head = 0; head < frontier.size(); ++head) {
    const Pixel m = frontier[head];
    const int i = m.i;
    const PlanarPatch& patch = result.patches[label[i]];
    const std::array<int, 4> next = Neighbours4(i, m.u, m.v, w, h);
    const Pixel at[4] = {{next[0], m.u - 1, m.v},
                         {next[1], m.u + 1, m.v},
                         {next[2], m.u, m.v - 1},
                         {next[3], m.u, m.v + 1}};
    for (const Pixel& q : at) {
      if (q.i < 0 || (label[q.i] != kNoise && label[q.i] != kUnvisited)) {
        continue;
      }
      if (!ContinuesOntoPlane(xyz[q.i], xyz[i], patch.normal, patch.d,
                              options)) {
        continue;
      }
      label[q.i] = label[i];
      frontier.push_back(q);
    }
  }
  for (int i = 0; i < n; ++i) {
    if (label[i] < 0) label[i] = kNoise;
  }
  // Sizes and boxes with the joined points.
  for (PlanarPatch& patch : result.patches) {
    patch.points = 0;
    patch.box = cv::Rect();
  }
  // Sizes, boxes and 4-adjacency in one pass.
  std::vector<cv::Vec4i> extent(result.patches.size(), cv::Vec4i(w, h, -1, -1));
  for (int v = 0, i = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u, ++i) {
      const int a = label[i];
      if (a < 0) continue;
      ++result.patches[a].points;
      cv::Vec4i& e = extent[a];
      e[0] = std::min(e[0], u);
      e[1] = std::min(e[1], v);
      e[2] = std::max(e[2], u);
      e[3] = std::max(e[3], v);
      if (u + 1 < w) {
        const int b = label[i + 1];
        if (b >= 0 && b != a) {
          result.adjacency.emplace_back(std::min(a, b), std::max(a, b));
        }
      }
      if (v + 1 < h) {
        const int b = label[i + w];
        if (b >= 0 && b != a) {
          result.adjacency.emplace_back(std::min(a, b), std::max(a, b));
        }
      }
    }
  }
  for (size_t k = 0; k < extent.size(); ++k) {
    const cv::Vec4i& e = extent[k];
    result.patches[k].box =
        cv::Rect(e[0], e[1], e[2] - e[0] + 1, e[3] - e[1] + 1);
  }
  std::sort(result.adjacency.begin(), result.adjacency.end());
  result.adjacency.erase(
      std::unique(result.adjacency.begin(), result.adjacency.end()),
      result.adjacency.end());
  return result;
}

}  // namespace fovea
