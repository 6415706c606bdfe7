#include "core/segmentation/inc_neighbours.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <utility>
#include <vector>

#include "core/segmentation/body_fit.h"
#include "core/segmentation/planar_patches.h"
#include "core/segmentation/relations.h"

namespace fovea {

void AddGapNeighbours(const cv::Mat& labels, const cv::Rect& box, float fx,
                      const IncOptions& options, IncScene& scene) {
  const IncOptions::BodyJoin& body = options.body_join;
  const int gap =
      static_cast<int>(std::lround(body.gap_px * std::max(fx, 1.0f) / 525.0f));
  if (!body.enabled || gap <= 0 || !options.fuse_surfaces) return;
  std::set<std::pair<int, int>> near;
  for (int v = box.y; v < box.br().y; ++v) {
    const int* row = labels.ptr<int>(v);
    for (int u = box.x; u < box.br().x; ++u) {
      const int a = row[u];
      if (a < 0) continue;
      // Right and down, across pixels without a surface only.
      for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{0, 1}}) {
        for (int step = 1; step <= gap + 1; ++step) {
          const int x = u + du * step;
          const int y = v + dv * step;
          if (x >= box.br().x || y >= box.br().y) break;
          const int b = labels.at<int>(y, x);
          if (b == a) break;
          if (b < 0) continue;
          if (step > 1) near.emplace(std::min(a, b), std::max(a, b));
          break;
        }
      }
    }
  }
  // Across a gap there is no border to speak for the pair: the fit must be
  // as tight as the Kinect's noise allows, even for a noisier sensor.
  BodyFitOptions fit = body.fit;
  const BodyFitOptions kinect;
  fit.sigma0_m = std::min(fit.sigma0_m, kinect.sigma0_m);
  fit.sigma_per_z2 = std::min(fit.sigma_per_z2, kinect.sigma_per_z2);
  for (const auto& [a, b] : near) {
    std::vector<int>& na = scene.neighbours[a];
    if (std::binary_search(na.begin(), na.end(), b)) continue;
    if (!OnOneBody(scene.points[a], scene.points[b], scene.up, fit)) {
      continue;
    }
    na.insert(std::lower_bound(na.begin(), na.end(), b), b);
    std::vector<int>& nb = scene.neighbours[b];
    nb.insert(std::lower_bound(nb.begin(), nb.end(), a), a);
  }
}

void AddOccludedNeighbours(const cv::Mat& labels, const cv::Rect& box,
                           const IncOptions& options, IncScene& scene) {
  const IncOptions::AcrossOccluder& o = options.across_occluder;
  if (!o.enabled || box.empty()) return;
  const std::vector<PlanarPatch>& patches = scene.surfaces.patches.patches;
  const Intrinsics& k = scene.intrinsics;
  const int max_gap =
      std::max(1, static_cast<int>(std::lround(o.max_gap_px * k.fx / 525.0)));
  // Rows and columns on which each pair was met.
  std::map<std::pair<int, int>, std::pair<int, int>> lines;
  // The depth at which pixel `p`'s ray meets surface `s`'s plane, or a
  // negative value where it does not (in front of the camera).
  const auto plane_depth = [&](int s, cv::Point p) {
    const Eigen::Vector3f ray((p.x - k.cx) / k.fx, (p.y - k.cy) / k.fy, 1.0);
    const float facing = patches[s].normal.dot(ray);
    return std::abs(facing) > 1e-3f ? -patches[s].d / facing : -1.0f;
  };
  const auto scan = [&](cv::Point start, cv::Point step, int length) {
    std::set<std::pair<int, int>> met;
    int near = -1;        // the last surface pixel's label
    cv::Point near_at;    // ... where it was
    float near_z = 0.0f;  // ... and its depth
    int occluding = 0;    // pixels in front of its plane since
    int gap = 0;          // pixels since it
    for (int i = 0; i < length; ++i) {
      const cv::Point p = start + step * i;
      const int l = labels.at<int>(p);
      const float z = scene.xyz.at<cv::Vec3f>(p)[2];
      if (near >= 0 && l != near) {
        ++gap;
        const float on_plane = plane_depth(near, p);
        if (gap > max_gap || !(on_plane > 0.0f)) {
          near = -1;
        } else if (std::isnan(z)) {
          continue;  // without depth: neither in front nor behind
        } else if (z < on_plane - o.min_in_front_m) {
          ++occluding;
          continue;
        } else if (l >= 0 && occluding > 0 &&
                   std::abs(z - on_plane) <= o.plane_tolerance_m &&
                   std::abs(near_z - plane_depth(l, near_at)) <=
                       o.plane_tolerance_m) {
          // Each side on the other's plane.
          met.emplace(std::min(near, l), std::max(near, l));
        } else if (l < 0) {
          near = -1;  // behind or beside the plane: no occluder
        }
      }
      if (l >= 0 && !scene.points[l].empty() && !std::isnan(z)) {
        near = l;
        near_at = p;
        near_z = z;
        occluding = 0;
        gap = 0;
      }
    }
    for (const auto& pair : met) {
      (step.x != 0 ? lines[pair].first : lines[pair].second) += 1;
    }
  };
  for (int v = box.y; v < box.br().y; ++v) {
    scan({box.x, v}, {1, 0}, box.width);
  }
  for (int u = box.x; u < box.br().x; ++u) {
    scan({u, box.y}, {0, 1}, box.height);
  }
  const double min_dot = std::cos(o.max_angle_deg * std::numbers::pi / 180.0);
  const double max_up = std::cos(o.min_tilt_deg * std::numbers::pi / 180.0);
  const std::vector<cv::Rect>& extent = scene.surfaces.label_boxes;
  for (const auto& [pair, count] : lines) {  // sorted: so is across_occluder
    const auto [a, b] = pair;
    // Across the occluder along most of the smaller side's extent: a face
    // continued, not two faces that happen to share a plane somewhere.
    const auto continued = [&](int met, int extent_a, int extent_b) {
      return met >= o.min_lines &&
             met >= o.min_continued * std::min(extent_a, extent_b);
    };
    if (!continued(count.first, extent[a].height, extent[b].height) &&
        !continued(count.second, extent[a].width, extent[b].width)) {
      continue;
    }
    std::vector<int>& na = scene.neighbours[a];
    if (std::binary_search(na.begin(), na.end(), b)) continue;
    if (std::abs(patches[a].normal.dot(patches[b].normal)) < min_dot ||
        std::abs(patches[a].normal.dot(scene.up)) > max_up) {
      continue;
    }
    if (scene.relations->Relate(a, b)[0] < o.min_color_similarity) continue;
    na.insert(std::lower_bound(na.begin(), na.end(), b), b);
    std::vector<int>& nb = scene.neighbours[b];
    nb.insert(std::lower_bound(nb.begin(), nb.end(), a), a);
    scene.across_occluder.push_back(pair);
  }
}

}  // namespace fovea
