#include "core/attention/msr.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

struct Region {
  std::vector<int> pixels;    // v * width + u
  double weight = 0.0;        // sum of saliency
  double su = 0.0, sv = 0.0;  // saliency-weighted sums of u and v
};

// Grows an 8-connected region from `seed` over pixels with saliency >=
// `threshold` that are not yet in `visited`; marks them visited.
Region GrowRegion(const cv::Mat& map, int seed, float threshold,
                  std::vector<uint8_t>& visited, std::vector<int>& stack) {
  const int w = map.cols, h = map.rows;
  const float* s = map.ptr<float>(0);
  Region region;
  stack.clear();
  stack.push_back(seed);
  visited[seed] = 1;
  while (!stack.empty()) {
    const int p = stack.back();
    stack.pop_back();
    region.pixels.push_back(p);
    const int u = p % w, v = p / w;
    region.weight += s[p];
    region.su += static_cast<double>(s[p]) * u;
    region.sv += static_cast<double>(s[p]) * v;
    for (int dv = -1; dv <= 1; ++dv) {
      const int nv = v + dv;
      if (nv < 0 || nv >= h) continue;
      for (int du = -1; du <= 1; ++du) {
        const int nu = u + du;
        if (nu < 0 || nu >= w || (du == 0 && dv == 0)) continue;
        const int q = nv * w + nu;
        if (visited[q] || !(s[q] >= threshold)) continue;
        visited[q] = 1;
        stack.push_back(q);
      }
    }
  }
  return region;
}

// Marks as visited the pixels reachable from `region` by never climbing:
// each step goes to a neighbour with saliency in (0, that of the pixel it
// comes from].
void InhibitSlope(const cv::Mat& map, const Region& region,
                  std::vector<uint8_t>& visited, std::vector<int>& stack) {
  const int w = map.cols, h = map.rows;
  const float* s = map.ptr<float>(0);
  stack.assign(region.pixels.begin(), region.pixels.end());
  while (!stack.empty()) {
    const int p = stack.back();
    stack.pop_back();
    const int u = p % w, v = p / w;
    for (int dv = -1; dv <= 1; ++dv) {
      const int nv = v + dv;
      if (nv < 0 || nv >= h) continue;
      for (int du = -1; du <= 1; ++du) {
        const int nu = u + du;
        if (nu < 0 || nu >= w || (du == 0 && dv == 0)) continue;
        const int q = nv * w + nu;
        if (visited[q] || !(s[q] > 0.0f) || s[q] > s[p]) continue;
        visited[q] = 1;
        stack.push_back(q);
      }
    }
  }
}

// The region pixel nearest to the region's saliency-weighted centroid.
int CentralPixel(const Region& region, int width) {
  const double cu = region.su / region.weight;
  const double cv = region.sv / region.weight;
  int best = region.pixels.front();
  double best_d2 = std::numeric_limits<double>::max();
  for (int p : region.pixels) {
    const double du = p % width - cu, dv = p / width - cv;
    const double d2 = du * du + dv * dv;
    if (d2 < best_d2) {
      best_d2 = d2;
      best = p;
    }
  }
  return best;
}

}  // namespace

absl::Status Validate(const MsrOptions& options) {
  if (!(options.region_tolerance >= 0.0f && options.region_tolerance < 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("msr.region_tolerance must be in [0, 1), got ",
                     options.region_tolerance));
  }
  if (!(options.min_relative_saliency >= 0.0f &&
        options.min_relative_saliency < 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("msr.min_relative_saliency must be in [0, 1), got ",
                     options.min_relative_saliency));
  }
  if (options.min_region_pixels < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "msr.min_region_pixels must be >= 1, got ", options.min_region_pixels));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<AttentionPoint>> ExtractMsrPoints(
    const cv::Mat& map, int max_points, const MsrOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (map.empty() || map.type() != CV_32FC1) {
    return absl::InvalidArgumentError("msr: map must be a non-empty CV_32FC1");
  }
  if (max_points < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("msr: max_points must be >= 0, got ", max_points));
  }
  const cv::Mat work = map.clone();  // continuous
  const int w = work.cols;
  const int n = work.rows * w;
  const float* s = work.ptr<float>(0);
  double global_max = 0.0;
  cv::minMaxLoc(work, nullptr, &global_max);
  const float floor =
      static_cast<float>(global_max) * options.min_relative_saliency;
  // Pixels in descending saliency order, so the next seed is found by
  // advancing a cursor past inhibited pixels instead of a full scan.
  std::vector<int> order;
  order.reserve(n);
  for (int p = 0; p < n; ++p) {
    if (s[p] > floor && s[p] > 0.0f) order.push_back(p);
  }
  std::sort(order.begin(), order.end(), [s](int a, int b) {
    return s[a] > s[b] || (s[a] == s[b] && a < b);
  });
  std::vector<uint8_t> visited(n, 0);
  std::vector<int> stack;
  std::vector<AttentionPoint> points;
  size_t cursor = 0;
  while (static_cast<int>(points.size()) < max_points) {
    while (cursor < order.size() && visited[order[cursor]]) ++cursor;
    if (cursor >= order.size()) break;
    const int seed = order[cursor];
    const float seed_value = s[seed];
    const float threshold = (1.0f - options.region_tolerance) * seed_value;
    const Region region = GrowRegion(work, seed, threshold, visited, stack);
    if (options.inhibit_slope) InhibitSlope(work, region, visited, stack);
    // Inhibition of the region: its pixels are visited and never seed or
    // join again.
    if (static_cast<int>(region.pixels.size()) < options.min_region_pixels ||
        !(region.weight > 0.0)) {
      continue;
    }
    const int p = CentralPixel(region, w);
    AttentionPoint point;
    point.u = p % w;
    point.v = p / w;
    point.saliency = seed_value;
    points.push_back(point);
  }
  return points;
}

}  // namespace fovea
