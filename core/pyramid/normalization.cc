#include "core/pyramid/normalization.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

constexpr uint8_t kCandidate = 255;

// 255 where the pixel is > min_value and >= each of its 8 neighbours.
cv::Mat MarkCandidates(const cv::Mat& map, float min_value) {
  const int h = map.rows, w = map.cols;
  cv::Mat mask(h, w, CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < h; ++v) {
    const float* up = map.ptr<float>(std::max(v - 1, 0));
    const float* row = map.ptr<float>(v);
    const float* down = map.ptr<float>(std::min(v + 1, h - 1));
    uint8_t* out = mask.ptr<uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      const float x = row[u];
      if (!(x > min_value)) continue;
      const int l = std::max(u - 1, 0), r = std::min(u + 1, w - 1);
      // Clamped indices revisit the pixel itself at the border, which
      // never fails x >= x.
      const bool is_max = x >= up[l] && x >= up[u] && x >= up[r] &&
                          x >= row[l] && x >= row[r] && x >= down[l] &&
                          x >= down[u] && x >= down[r];
      if (is_max) out[u] = kCandidate;
    }
  }
  return mask;
}

// True if a candidate pixel touches a pixel of equal value that is not a
// candidate: its plateau continues to a pixel with a higher neighbour, so
// the plateau is not a maximum.
bool PlateauLeaks(const cv::Mat& map, const cv::Mat& mask, int u, int v) {
  const float x = map.at<float>(v, u);
  for (int dv = -1; dv <= 1; ++dv) {
    const int y = v + dv;
    if (y < 0 || y >= map.rows) continue;
    const float* row = map.ptr<float>(y);
    const uint8_t* m = mask.ptr<uint8_t>(y);
    for (int du = -1; du <= 1; ++du) {
      const int c = u + du;
      if (c < 0 || c >= map.cols) continue;
      if (m[c] != kCandidate && row[c] == x) return true;
    }
  }
  return false;
}

// INVALID_ARGUMENT naming the first negative or non-finite pixel, or OK.
absl::Status CheckValues(const cv::Mat& map) {
  for (int v = 0; v < map.rows; ++v) {
    const float* row = map.ptr<float>(v);
    for (int u = 0; u < map.cols; ++u) {
      if (!(row[u] >= 0.0f) || !std::isfinite(row[u])) {
        return absl::InvalidArgumentError(
            absl::StrCat("map value at (", u, ", ", v, ") is ", row[u],
                         "; must be finite and >= 0"));
      }
    }
  }
  return absl::OkStatus();
}

// (global max - mean of the maxima but the first)^2 (the global max is 1
// up to rounding); 1 when there is no other maximum.
float NmsFactor(const std::vector<LocalMaximum>& maxima) {
  if (maxima.size() < 2) return 1.0f;
  double sum = 0.0;
  for (size_t i = 1; i < maxima.size(); ++i) sum += maxima[i].value;
  const double mean = sum / static_cast<double>(maxima.size() - 1);
  const double d = maxima.front().value - mean;
  return static_cast<float>(d * d);
}

// 1 / sqrt(number of maxima >= (1 - range) * global max); the global
// maximum counts.
float NlmFactor(const std::vector<LocalMaximum>& maxima, float range) {
  if (maxima.empty()) return 1.0f;
  const float threshold = (1.0f - range) * maxima.front().value;
  int n = 0;
  for (const LocalMaximum& m : maxima) {
    if (m.value >= threshold) ++n;
  }
  return 1.0f / std::sqrt(static_cast<float>(std::max(n, 1)));
}

}  // namespace

absl::Status Validate(const NormalizationOptions& options) {
  if (!(options.min_peak >= 0.0f && options.min_peak < 1.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "normalization.min_peak must be in [0, 1), got ", options.min_peak));
  }
  if (!(options.min_peak_distance >= 0.0f) ||
      !std::isfinite(options.min_peak_distance)) {
    return absl::InvalidArgumentError(
        absl::StrCat("normalization.min_peak_distance must be >= 0, got ",
                     options.min_peak_distance));
  }
  if (!(options.nlm_range >= 0.0f && options.nlm_range <= 1.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "normalization.nlm_range must be in [0, 1], got ", options.nlm_range));
  }
  return absl::OkStatus();
}

std::vector<LocalMaximum> FindLocalMaxima(const cv::Mat& map, float min_value,
                                          float min_distance) {
  std::vector<LocalMaximum> maxima;
  if (map.empty()) return maxima;
  FOVEA_CHECK(map.type() == CV_32FC1);
  const cv::Mat mask = MarkCandidates(map, min_value);
  cv::Mat labels;
  const int count = cv::connectedComponents(mask, labels, 8, CV_32S);
  // Label 0 is the background. Per plateau: its first pixel, or a leak.
  std::vector<cv::Point> first(count, cv::Point(-1, -1));
  std::vector<bool> leaks(count, false);
  for (int v = 0; v < map.rows; ++v) {
    const int* row = labels.ptr<int>(v);
    for (int u = 0; u < map.cols; ++u) {
      const int label = row[u];
      if (label == 0 || leaks[label]) continue;
      if (first[label].x < 0) first[label] = {u, v};
      if (PlateauLeaks(map, mask, u, v)) leaks[label] = true;
    }
  }
  for (int label = 1; label < count; ++label) {
    if (leaks[label]) continue;
    maxima.push_back({first[label], map.at<float>(first[label])});
  }
  // Labels follow scan order, so a stable sort keeps ties in scan order.
  std::stable_sort(maxima.begin(), maxima.end(),
                   [](const LocalMaximum& a, const LocalMaximum& b) {
                     return a.value > b.value;
                   });
  if (min_distance <= 0.0f) return maxima;
  const float min_distance2 = min_distance * min_distance;
  std::vector<LocalMaximum> kept;
  for (const LocalMaximum& m : maxima) {
    const bool too_close =
        std::any_of(kept.begin(), kept.end(), [&](const LocalMaximum& k) {
          const cv::Point d = m.pixel - k.pixel;
          return static_cast<float>(d.dot(d)) < min_distance2;
        });
    if (!too_close) kept.push_back(m);
  }
  return kept;
}

absl::StatusOr<cv::Mat> NormalizeMap(const cv::Mat& map, MapNormalization kind,
                                     const NormalizationOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (map.empty()) return cv::Mat();
  if (map.type() != CV_32FC1) {
    return absl::InvalidArgumentError("map must be CV_32FC1");
  }
  FOVEA_RETURN_IF_ERROR(CheckValues(map));
  double max_value = 0.0;
  cv::minMaxLoc(map, nullptr, &max_value);
  if (max_value <= 0.0) return cv::Mat(cv::Mat::zeros(map.size(), CV_32FC1));
  cv::Mat scaled;
  map.convertTo(scaled, CV_32FC1, 1.0 / max_value);
  if (kind == MapNormalization::kLin) return scaled;
  const std::vector<LocalMaximum> maxima =
      FindLocalMaxima(scaled, options.min_peak, options.min_peak_distance);
  const float factor = kind == MapNormalization::kNms
                           ? NmsFactor(maxima)
                           : NlmFactor(maxima, options.nlm_range);
  scaled *= factor;
  return scaled;
}

}  // namespace fovea
