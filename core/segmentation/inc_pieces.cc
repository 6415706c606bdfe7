// INC's pieces within an object's footprint (IncOptions::PiecesWithin): when
// an object is final, the surfaces still in the scene that no border joins
// to it, that lie within its footprint seen along the support's normal and
// reach its top, join it.

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/segmentation/inc.h"

namespace fovea {
namespace {

// Footprints are taken from an even sample of at most about this many
// points: an object's (whose convex hull is taken at every object) and a
// surface's (once per scene).
constexpr size_t kObjectFootprintPoints = 2048;
constexpr size_t kSurfaceFootprintPoints = 512;

}  // namespace

IncSegmenter::Footprint IncSegmenter::FootprintOf(
    const std::vector<int>& surfaces, size_t max_points) const {
  // Plane coordinates (x, y) and height along the support's normal.
  const Eigen::Vector3f up = scene_.up.normalized();
  const Eigen::Vector3f x_axis = up.unitOrthogonal();
  const Eigen::Vector3f y_axis = up.cross(x_axis);
  size_t total = 0;
  for (const int s : surfaces) total += scene_.points[s].size();
  // Every stride-th point of each surface: at most about max_points.
  const size_t stride =
      std::max<size_t>(1, (total + max_points - 1) / max_points);
  Footprint f;
  std::vector<float> heights;
  for (const int s : surfaces) {
    const std::vector<Eigen::Vector3f>& points = scene_.points[s];
    for (size_t i = 0; i < points.size(); i += stride) {
      f.flat.emplace_back(x_axis.dot(points[i]), y_axis.dot(points[i]));
      heights.push_back(up.dot(points[i]));
    }
  }
  if (f.flat.empty()) return f;
  const auto at = [&heights](double q) {
    const auto it =
        heights.begin() +
        static_cast<ptrdiff_t>(q * static_cast<double>(heights.size() - 1));
    std::nth_element(heights.begin(), it, heights.end());
    return *it;
  };
  f.top = at(0.99);
  f.bottom = at(0.01);
  cv::Point2f lo = f.flat[0];
  cv::Point2f hi = f.flat[0];
  for (const cv::Point2f& p : f.flat) {
    lo.x = std::min(lo.x, p.x);
    lo.y = std::min(lo.y, p.y);
    hi.x = std::max(hi.x, p.x);
    hi.y = std::max(hi.y, p.y);
  }
  f.box = cv::Rect2f(lo, hi);
  return f;
}

int IncSegmenter::AddPiecesWithin(std::vector<int>& group) {
  const IncOptions::PiecesWithin& options = options_.pieces_within;
  if (!options.enabled) return 0;
  const Footprint object = FootprintOf(group, kObjectFootprintPoints);
  if (object.flat.size() < 3) return 0;  // no points kept: nothing to tell
  std::vector<cv::Point2f> hull;
  cv::convexHull(object.flat, hull);
  const float margin = static_cast<float>(options.margin_m);
  const cv::Rect2f grown(object.box.x - margin, object.box.y - margin,
                         object.box.width + 2 * margin,
                         object.box.height + 2 * margin);
  const auto in_box = [&grown](const cv::Point2f& p) {
    return p.x >= grown.x && p.x <= grown.x + grown.width && p.y >= grown.y &&
           p.y <= grown.y + grown.height;
  };
  const auto borders_object = [&](size_t s) {
    return std::any_of(
        scene_.neighbours[s].begin(), scene_.neighbours[s].end(), [&](int t) {
          return std::binary_search(group.begin(), group.end(), t);
        });
  };
  std::vector<int> joined;
  int pixels = 0;
  for (size_t s = 0; s < removed_.size(); ++s) {
    if (removed_[s] || scene_.points[s].empty()) continue;
    // Where a border joins them the grouping has decided already.
    if (borders_object(s)) continue;
    if (!footprints_[s]) {
      footprints_[s] =
          FootprintOf({static_cast<int>(s)}, kSurfaceFootprintPoints);
    }
    const Footprint& piece = *footprints_[s];
    if (std::abs(piece.top - object.top) > options.top_m ||
        piece.bottom < object.bottom - options.max_below_m ||
        (grown & piece.box).area() <= 0.0f) {
      continue;
    }
    const int needed = static_cast<int>(
        std::ceil(options.min_inside * static_cast<double>(piece.flat.size())));
    int inside = 0;
    int left = static_cast<int>(piece.flat.size());
    for (const cv::Point2f& p : piece.flat) {
      if (in_box(p) && cv::pointPolygonTest(hull, p, true) >= -margin) {
        ++inside;
      }
      --left;
      if (inside >= needed || inside + left < needed) break;
    }
    if (inside >= needed) {
      joined.push_back(static_cast<int>(s));
      removed_[s] = true;
      pixels += scene_.pixels[s];
    }
  }
  group.insert(group.end(), joined.begin(), joined.end());
  std::sort(group.begin(), group.end());
  return pixels;
}

}  // namespace fovea
