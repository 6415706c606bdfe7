#include "core/frame/hole_filling.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

constexpr int kNeighbours = 8;
constexpr int kDu[kNeighbours] = {-1, 0, 1, -1, 1, -1, 0, 1};
constexpr int kDv[kNeighbours] = {-1, -1, -1, 0, 0, 1, 1, 1};
// Colour distance^2 beyond which the weight is below exp(-18): treated 0.
constexpr float kMaxSigmas2 = 36.0f;

// Table of exp(-d2 / (2 sigma^2)) for squared RGB distances, quantised.
class ColorWeight {
 public:
  explicit ColorWeight(float sigma) : inv_two_sigma2_(0.5f / (sigma * sigma)) {}
  float operator()(const cv::Vec3b& a, const cv::Vec3b& b) const {
    const float d0 = static_cast<float>(a[0]) - b[0];
    const float d1 = static_cast<float>(a[1]) - b[1];
    const float d2 = static_cast<float>(a[2]) - b[2];
    const float x = (d0 * d0 + d1 * d1 + d2 * d2) * inv_two_sigma2_;
    return x > kMaxSigmas2 * 0.5f ? 0.0f : std::exp(-x);
  }

 private:
  float inv_two_sigma2_;
};

// Weighted average of the neighbours of (u, v) that have depth. False when
// none has (or all weights vanish).
bool Average(const cv::Mat& depth, const cv::Mat& color, const ColorWeight& wf,
             int u, int v, float& out) {
  const cv::Vec3b& c = color.at<cv::Vec3b>(v, u);
  float sum = 0.0f, weight = 0.0f;
  for (int k = 0; k < kNeighbours; ++k) {
    const int x = u + kDu[k], y = v + kDv[k];
    if (x < 0 || y < 0 || x >= depth.cols || y >= depth.rows) continue;
    const float d = depth.at<float>(y, x);
    if (std::isnan(d)) continue;
    const float w = wf(c, color.at<cv::Vec3b>(y, x));
    sum += w * d;
    weight += w;
  }
  if (!(weight > 1e-12f)) return false;
  out = sum / weight;
  return true;
}

}  // namespace

absl::Status Validate(const HoleFillingOptions& options) {
  if (options.max_hole_pixels < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("hole_filling.max_hole_pixels must be >= 0, got ",
                     options.max_hole_pixels));
  }
  if (!(options.color_sigma > 0.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "hole_filling.color_sigma must be > 0, got ", options.color_sigma));
  }
  if (options.diffusion_iterations < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("hole_filling.diffusion_iterations must be >= 0, got ",
                     options.diffusion_iterations));
  }
  return absl::OkStatus();
}

absl::StatusOr<FilledDepth> FillDepthHoles(const RgbdFrame& frame,
                                           const HoleFillingOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (frame.depth.type() != CV_32FC1 || frame.color.type() != CV_8UC3 ||
      frame.depth.size() != frame.color.size()) {
    return absl::InvalidArgumentError(
        "hole_filling: expected CV_32FC1 depth and CV_8UC3 colour of one size");
  }
  FilledDepth result;
  result.depth = frame.depth.clone();
  result.filled = cv::Mat(frame.depth.size(), CV_8UC1, cv::Scalar(0));
  // Holes small enough to fill.
  cv::Mat missing(frame.depth.size(), CV_8UC1);
  for (int v = 0; v < missing.rows; ++v) {
    const float* d = frame.depth.ptr<float>(v);
    uint8_t* m = missing.ptr<uint8_t>(v);
    for (int u = 0; u < missing.cols; ++u) m[u] = std::isnan(d[u]) ? 255 : 0;
  }
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(missing, labels, stats,
                                                 centroids, 8, CV_32S);
  std::vector<uint8_t> fillable(n, 0);
  for (int i = 1; i < n; ++i) {
    fillable[i] = stats.at<int>(i, cv::CC_STAT_AREA) <= options.max_hole_pixels;
  }
  std::vector<cv::Point> hole;
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (l[u] > 0 && fillable[l[u]]) hole.emplace_back(u, v);
    }
  }
  if (hole.empty()) return result;
  const ColorWeight weight(options.color_sigma);
  // Front propagation: each round fills the hole pixels that touch depth,
  // from the values known at the start of the round.
  std::vector<cv::Point> pending = hole, next;
  std::vector<float> values;
  while (!pending.empty()) {
    next.clear();
    values.clear();
    std::vector<cv::Point> reached;
    for (const cv::Point& p : pending) {
      float d;
      if (Average(result.depth, frame.color, weight, p.x, p.y, d)) {
        reached.push_back(p);
        values.push_back(d);
      } else {
        next.push_back(p);
      }
    }
    if (reached.empty()) break;  // the rest has no path of similar colour
    for (size_t i = 0; i < reached.size(); ++i) {
      result.depth.at<float>(reached[i]) = values[i];
      result.filled.at<uint8_t>(reached[i]) = 255;
    }
    pending.swap(next);
  }
  // Anisotropic diffusion sweeps over the filled pixels.
  std::vector<cv::Point> filled;
  for (const cv::Point& p : hole) {
    if (result.filled.at<uint8_t>(p)) filled.push_back(p);
  }
  for (int it = 0; it < options.diffusion_iterations; ++it) {
    values.assign(filled.size(), 0.0f);
    for (size_t i = 0; i < filled.size(); ++i) {
      if (!Average(result.depth, frame.color, weight, filled[i].x, filled[i].y,
                   values[i])) {
        values[i] = result.depth.at<float>(filled[i]);
      }
    }
    for (size_t i = 0; i < filled.size(); ++i) {
      result.depth.at<float>(filled[i]) = values[i];
    }
  }
  result.filled_pixels = static_cast<int>(filled.size());
  return result;
}

}  // namespace fovea
