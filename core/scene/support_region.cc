// The support region of SearchSupport's chosen candidate
// (support_grid.h): the other parts of its plane that join it (inside its
// hull, or hidden from it only by what stands in front, and of its
// colour), the refitted plane and its full-resolution inliers and hull.

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "core/base/lab.h"
#include "core/base/parallel.h"
#include "core/scene/support_grid.h"

namespace fovea::support_internal {
namespace {

// A part of the plane joins the region when this share of its points
// projects inside the region's hull.
constexpr float kInsideShare = 0.5f;
// The seen-through test: samples along the gap every this many metres, at
// most kMaxGapSamples; the gap is seen empty when more than this share of
// the samples that could be judged see beyond the plane.
constexpr float kGapSampleStep = 0.01f;
constexpr int kMaxGapSamples = 60;
constexpr float kSeenThroughShare = 0.1f;
constexpr int kMaxRegionPairPoints = 200;  // subsamples for the nearest pair
constexpr int kMaxPartPairPoints = 60;
// Parts of the plane with fewer grid points are specks, not table.
constexpr int kMinPartPoints = 4;
// Weight of lightness in a part's colour distance from the region.
constexpr float kLightnessWeight = 0.5f;

// Whether the plane between a and b (points on it) is seen empty: the
// cloud shows, along the rays to points of the segment, something beyond
// the plane (the floor through a gap) rather than something in front of it
// (an object hiding it) or the plane itself.
bool GapSeenEmpty(const OrganizedCloud& cloud, const Eigen::Vector3f& a,
                  const Eigen::Vector3f& b,
                  const SupportPlaneOptions& options) {
  const float length = (b - a).norm();
  const int steps =
      std::clamp(static_cast<int>(length / kGapSampleStep), 2, kMaxGapSamples);
  const Intrinsics& k = cloud.intrinsics;
  int beyond = 0, judged = 0;
  for (int s = 1; s < steps; ++s) {
    const Eigen::Vector3f q = a + (b - a) * (static_cast<float>(s) / steps);
    if (!(q.z() > 0.0f)) continue;
    const int u = static_cast<int>(std::lround(k.fx * q.x() / q.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * q.y() / q.z() + k.cy));
    if (u < 0 || v < 0 || u >= cloud.width() || v >= cloud.height()) continue;
    const float seen = cloud.xyz.at<cv::Vec3f>(v, u)[2];
    if (std::isnan(seen)) continue;  // a hole says nothing
    ++judged;
    const float tolerance = 1.5f * InlierDistance(q.z(), options);
    if (seen > q.z() + tolerance) ++beyond;
  }
  return beyond >= 2 && beyond > kSeenThroughShare * judged;
}

// Every `step`-th element, so that at most about `max` remain.
std::vector<int> Thin(const std::vector<int>& indices, int max) {
  const size_t step = std::max<size_t>(1, indices.size() / max);
  std::vector<int> out;
  for (size_t i = 0; i < indices.size(); i += step) out.push_back(indices[i]);
  return out;
}

// The closest pair between two point sets in plane coordinates (thinned).
std::pair<int, int> NearestPair(const Grid& grid, const SupportPlane& frame,
                                const std::vector<int>& a,
                                const std::vector<int>& b, float* distance) {
  const std::vector<int> ta = Thin(a, kMaxRegionPairPoints);
  const std::vector<int> tb = Thin(b, kMaxPartPairPoints);
  std::pair<int, int> best{ta[0], tb[0]};
  float best_d2 = std::numeric_limits<float>::infinity();
  for (const int i : ta) {
    const Eigen::Vector2f qi = frame.ToPlane(grid.p[i]);
    for (const int j : tb) {
      const float d2 = (frame.ToPlane(grid.p[j]) - qi).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best = {i, j};
      }
    }
  }
  *distance = std::sqrt(best_d2);
  return best;
}

// Mean CIE Lab colour (L in [0, 100]) of the grid points' pixels.
cv::Vec3f MeanLab(const OrganizedCloud& cloud, const Grid& grid,
                  const std::vector<int>& indices) {
  cv::Vec3d sum(0, 0, 0);
  for (const int i : indices) {
    const cv::Vec3b& c = cloud.color.at<cv::Vec3b>(
        (i / grid.cols) * grid.stride, (i % grid.cols) * grid.stride);
    sum += cv::Vec3d(c[0], c[1], c[2]);
  }
  const double n = std::max<size_t>(1, indices.size());
  cv::Mat rgb(
      1, 1, CV_32FC3,
      cv::Scalar(sum[0] / n / 255.0, sum[1] / n / 255.0, sum[2] / n / 255.0));
  cv::Mat lab;
  RgbToLab(rgb, &lab);
  return lab.at<cv::Vec3f>(0, 0);
}

// Distance of the part's mean colour from `reference` (Lab), lightness
// weighted by kLightnessWeight: shading and shadows change lightness
// across one table far more than its hue.
float ColorDistance(const OrganizedCloud& cloud, const Grid& grid,
                    const cv::Vec3f& reference, const std::vector<int>& part) {
  if (cloud.color.empty() || cloud.color.size() != cloud.xyz.size())
    return 0.0f;
  const cv::Vec3f c = MeanLab(cloud, grid, part);
  const float dl = kLightnessWeight * (c[0] - reference[0]);
  const float da = c[1] - reference[1], db = c[2] - reference[2];
  return std::sqrt(dl * dl + da * da + db * db);
}

}  // namespace

absl::StatusOr<SupportPlane> MakeSupportRegion(
    const OrganizedCloud& cloud, const Grid& grid, const Candidate& chosen,
    const SupportPlaneOptions& options, float min_cos) {
  // Every part of the chosen plane, the chosen one among them.
  std::vector<int> labels;
  const std::vector<std::vector<int>> parts =
      PlaneParts(grid, chosen.plane, options, min_cos, chosen.indices, &labels);
  const int n = static_cast<int>(parts.size());
  const int own = labels[chosen.indices[0]];
  std::vector<bool> joined(n, false);
  joined[own] = true;
  std::vector<int> region = parts[own];
  SupportPlane frame = chosen.frame;
  const cv::Vec3f region_color = MeanLab(cloud, grid, region);
  // Two passes: a part that joins widens the hull for the next.
  for (int pass = 0; pass < 2; ++pass) {
    frame.hull = HullOfIndices(grid, frame, region);
    bool grew = false;
    for (int l = 1; l < n; ++l) {
      if (joined[l] || static_cast<int>(parts[l].size()) < kMinPartPoints) {
        continue;
      }
      // Smaller parts are the insides of what stands on the table (a
      // bowl's bottom) as often as the table between objects; left out, the
      // segmentation treats both as what they touch.
      float area = 0.0f;
      for (const int i : parts[l]) area += grid.Area(i, chosen.plane.normal);
      if (area < options.min_candidate_area_m2) continue;
      int inside = 0;
      for (const int i : parts[l]) {
        inside += InsideHull(frame.hull, frame.ToPlane(grid.p[i]), 0.0f);
      }
      // A part of another colour than the region is the inside of
      // something standing on it (a bowl's bottom), not the table.
      if (ColorDistance(cloud, grid, region_color, parts[l]) >
          options.max_join_color_distance) {
        continue;
      }
      bool join = inside >= kInsideShare * parts[l].size();
      if (!join) {
        float gap = 0.0f;
        const auto [a, b] = NearestPair(grid, frame, region, parts[l], &gap);
        if (gap <= options.max_occlusion_gap) {
          // The two ends, dropped onto the plane.
          const Eigen::Vector3f pa =
              grid.p[a] - chosen.plane.normal * chosen.plane.Height(grid.p[a]);
          const Eigen::Vector3f pb =
              grid.p[b] - chosen.plane.normal * chosen.plane.Height(grid.p[b]);
          join = !GapSeenEmpty(cloud, pa, pb, options);
        }
      }
      if (join) {
        joined[l] = true;
        region.insert(region.end(), parts[l].begin(), parts[l].end());
        grew = true;
      }
    }
    if (!grew) break;
  }

  SupportPlane plane;
  const std::optional<Plane> fit = FitPlane(grid, region);
  const Plane best = fit && fit->normal.dot(chosen.plane.normal) >=
                                 std::cos(kMaxRefitAngleDeg * kDegToRad)
                         ? *fit
                         : chosen.plane;
  plane.normal = best.normal;
  plane.d = best.d;
  SetAxes(plane);

  // Full resolution: pixels on the plane whose grid cell (or a neighbour of
  // it) belongs to the region.
  cv::Mat member(grid.rows, grid.cols, CV_8UC1, cv::Scalar(0));
  for (const int i : region)
    member.at<uint8_t>(i / grid.cols, i % grid.cols) = 255;
  // Cells of no point (holes, edges) take their neighbours' membership;
  // cells of another surface do not.
  cv::Mat grown;
  cv::dilate(member, grown, cv::Mat());
  for (int i = 0; i < grid.size(); ++i) {
    if (!grid.HasPoint(i)) {
      member.at<uint8_t>(i / grid.cols, i % grid.cols) =
          grown.at<uint8_t>(i / grid.cols, i % grid.cols);
    }
  }
  const float min_cos_full = min_cos;
  plane.inliers =
      cv::Mat(cloud.height(), cloud.width(), CV_8UC1, cv::Scalar(0));
  int count = 0;
  // Only the pixels of the member cells' bounding box can be inliers.
  const cv::Rect cells = cv::boundingRect(member);
  const int u_begin = std::max(0, cells.x * grid.stride - grid.stride);
  const int u_end = std::min(
      cloud.width(), (cells.x + cells.width) * grid.stride + grid.stride);
  const int v_begin = std::max(0, cells.y * grid.stride - grid.stride);
  const int v_end = std::min(
      cloud.height(), (cells.y + cells.height) * grid.stride + grid.stride);
  // Rows in parallel ranges, each counting its own inliers.
  std::vector<int> row_count(std::max(0, v_end - v_begin), 0);
  ParallelForRanges(v_end - v_begin, [&](int first, int last) {
    for (int v = v_begin + first; v < v_begin + last; ++v) {
      const cv::Vec3f* p = cloud.xyz.ptr<cv::Vec3f>(v);
      const cv::Vec3f* nrm = cloud.normals.ptr<cv::Vec3f>(v);
      const uint8_t* m = member.ptr<uint8_t>(
          std::min(grid.rows - 1, (v + grid.stride / 2) / grid.stride));
      uint8_t* out = plane.inliers.ptr<uint8_t>(v);
      for (int u = u_begin; u < u_end; ++u) {
        if (std::isnan(p[u][2])) continue;
        if (!m[std::min(grid.cols - 1, (u + grid.stride / 2) / grid.stride)]) {
          continue;
        }
        const Eigen::Vector3f q(p[u][0], p[u][1], p[u][2]);
        if (!(std::abs(best.Height(q)) <= InlierDistance(q.z(), options))) {
          continue;
        }
        if (!std::isnan(nrm[u][2]) &&
            std::abs(best.normal.dot(Eigen::Vector3f(
                nrm[u][0], nrm[u][1], nrm[u][2]))) < min_cos_full) {
          continue;
        }
        out[u] = 255;
        ++row_count[v - v_begin];
      }
    }
  });
  for (const int c : row_count) count += c;
  plane.inlier_count = count;
  plane.hull = HullOfMask(cloud, plane.inliers, plane);
  if (plane.hull.size() < 3) {
    return absl::NotFoundError("support plane: the region has no 2D extent");
  }
  return plane;
}

}  // namespace fovea::support_internal
