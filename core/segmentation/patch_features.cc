#include "core/segmentation/patch_features.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "absl/strings/str_cat.h"
#include "core/base/parallel.h"
#include "core/segmentation/body_fit.h"

extern "C" {
#include "libqhull_r/qhull_ra.h"
}

namespace fovea {
namespace {

// Thinner point sets (standard deviation along their flattest direction,
// metres) are planar: their hull has no camera-facing face with depth.
constexpr double kFlatSigma = 1e-4;

// Where qhull writes its messages: a failed hull is an answer (0), not a
// log line. Opened once; stderr when /dev/null cannot be opened.
FILE* QhullErrorFile() {
  static FILE* const file = [] {
    FILE* f = std::fopen("/dev/null", "w");
    return f != nullptr ? f : stderr;
  }();
  return file;
}

bool IsFlat(const std::vector<Eigen::Vector3f>& points) {
  return PlaneRms(points.begin(), points.end()) < kFlatSigma;
}

// The planes (outward unit normal n, offset o: n . p + o = 0, inside < 0)
// of the hull's faces that face the origin; empty if qhull fails.
std::vector<Eigen::Vector4d> CameraFacingPlanes(
    const std::vector<Eigen::Vector3f>& points) {
  std::vector<coordT> coords;
  coords.reserve(points.size() * 3);
  for (const Eigen::Vector3f& p : points) {
    coords.push_back(p.x());
    coords.push_back(p.y());
    coords.push_back(p.z());
  }
  qhT qh_storage;
  qhT* qh = &qh_storage;
  FILE* const errors = QhullErrorFile();
  qh_zero(qh, errors);
  // QJ: joggle instead of merging, so every face is a triangle with a
  // plane; Pp: no precision warnings. The command must be writable.
  char command[] = "qhull QJ Pp";
  const int exit_code =
      qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(),
                   /*ismalloc=*/False, command, nullptr, errors);
  std::vector<Eigen::Vector4d> planes;
  if (exit_code == 0) {
    facetT* facet;
    FORALLfacets {
      if (facet->offset > 0.0) {
        planes.emplace_back(facet->normal[0], facet->normal[1],
                            facet->normal[2], facet->offset);
      }
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int still_long = 0;
  int still_total = 0;
  qh_memfreeshort(qh, &still_long, &still_total);
  return planes;
}

}  // namespace

absl::Status Validate(const PatchColorOptions& options) {
  if (options.hue_bins < 1 || options.hue_bins > 180) {
    return absl::InvalidArgumentError(
        absl::StrCat("hue_bins must be in [1, 180], got ", options.hue_bins));
  }
  if (options.saturation_bins < 1 || options.saturation_bins > 256) {
    return absl::InvalidArgumentError(absl::StrCat(
        "saturation_bins must be in [1, 256], got ", options.saturation_bins));
  }
  if (options.gray_bins < 1 || options.gray_bins > 256) {
    return absl::InvalidArgumentError(
        absl::StrCat("gray_bins must be in [1, 256], got ", options.gray_bins));
  }
  if (options.min_saturation < 0 || options.min_saturation > 255) {
    return absl::InvalidArgumentError(absl::StrCat(
        "min_saturation must be in [0, 255], got ", options.min_saturation));
  }
  if (options.min_value < 0 || options.min_value > 255) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_value must be in [0, 255], got ", options.min_value));
  }
  return absl::OkStatus();
}

int HistogramBins(const PatchColorOptions& options) {
  return options.hue_bins * options.saturation_bins + options.gray_bins;
}

std::vector<std::vector<float>> LabelColorHistograms(
    const cv::Mat& rgb, const cv::Mat& labels, int label_count,
    const PatchColorOptions& options) {
  const int bins = HistogramBins(options);
  std::vector<std::vector<float>> histograms(label_count,
                                             std::vector<float>(bins, 0.0f));
  cv::Mat hsv;
  cv::cvtColor(rgb, hsv, cv::COLOR_RGB2HSV);  // H in [0, 180)
  const int colored_bins = options.hue_bins * options.saturation_bins;
  // Rows in parallel ranges, each counting into its own histograms (counts
  // of whole pixels: the sums are exact in any order).
  const int ranges = std::max(1, std::min(labels.rows, ParallelThreads() * 4));
  std::vector<std::vector<int>> counts(ranges);
  ParallelFor(ranges, [&](int r) {
    std::vector<int>& count = counts[r];
    count.assign(static_cast<size_t>(label_count) * bins, 0);
    const int first = static_cast<int>(int64_t{labels.rows} * r / ranges);
    const int last = static_cast<int>(int64_t{labels.rows} * (r + 1) / ranges);
    for (int v = first; v < last; ++v) {
      const int* label = labels.ptr<int>(v);
      const cv::Vec3b* pixel = hsv.ptr<cv::Vec3b>(v);
      for (int u = 0; u < labels.cols; ++u) {
        const int l = label[u];
        if (l < 0 || l >= label_count) continue;
        const int h = pixel[u][0];
        const int s = pixel[u][1];
        const int value = pixel[u][2];
        int bin;
        if (s < options.min_saturation || value < options.min_value) {
          bin = colored_bins + value * options.gray_bins / 256;
        } else {
          const int hb =
              std::min(h * options.hue_bins / 180, options.hue_bins - 1);
          const int sb = s * options.saturation_bins / 256;
          bin = hb * options.saturation_bins + sb;
        }
        ++count[static_cast<size_t>(l) * bins + bin];
      }
    }
  });
  for (const std::vector<int>& count : counts) {
    for (int l = 0; l < label_count; ++l) {
      for (int b = 0; b < bins; ++b) {
        histograms[l][b] +=
            static_cast<float>(count[static_cast<size_t>(l) * bins + b]);
      }
    }
  }
  return histograms;
}

float HistogramCorrelation(const std::vector<float>& a,
                           const std::vector<float>& b) {
  const size_t n = std::min(a.size(), b.size());
  if (n == 0) return 0.0f;
  double mean_a = 0.0;
  double mean_b = 0.0;
  for (size_t i = 0; i < n; ++i) {
    mean_a += a[i];
    mean_b += b[i];
  }
  mean_a /= static_cast<double>(n);
  mean_b /= static_cast<double>(n);
  double ab = 0.0;
  double aa = 0.0;
  double bb = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double da = a[i] - mean_a;
    const double db = b[i] - mean_b;
    ab += da * db;
    aa += da * da;
    bb += db * db;
  }
  if (aa <= 0.0 || bb <= 0.0) return 0.0f;
  return static_cast<float>(ab / std::sqrt(aa * bb));
}

std::vector<std::vector<Eigen::Vector3f>> SampleLabelPoints(
    const OrganizedCloud& cloud, const cv::Mat& labels, int label_count,
    int per_label) {
  std::vector<int> counts(label_count, 0);
  for (int v = 0; v < labels.rows; ++v) {
    const int* label = labels.ptr<int>(v);
    const cv::Vec3f* xyz = cloud.xyz.ptr<cv::Vec3f>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (label[u] >= 0 && label[u] < label_count && !std::isnan(xyz[u][2])) {
        ++counts[label[u]];
      }
    }
  }
  std::vector<std::vector<Eigen::Vector3f>> samples(label_count);
  std::vector<int> seen(label_count, 0);
  for (int v = 0; v < labels.rows; ++v) {
    const int* label = labels.ptr<int>(v);
    const cv::Vec3f* xyz = cloud.xyz.ptr<cv::Vec3f>(v);
    for (int u = 0; u < labels.cols; ++u) {
      const int l = label[u];
      if (l < 0 || l >= label_count || std::isnan(xyz[u][2])) continue;
      // Pixel i is taken when floor(i * per_label / count) steps up: all
      // of a label with at most per_label pixels, else per_label evenly.
      const int64_t i = seen[l]++;
      if ((i + 1) * per_label / counts[l] > i * per_label / counts[l]) {
        samples[l].emplace_back(xyz[u][0], xyz[u][1], xyz[u][2]);
      }
    }
  }
  return samples;
}

std::vector<float> CameraFacingHullDistances(
    const std::vector<Eigen::Vector3f>& points) {
  std::vector<float> distances(points.size(), 0.0f);
  if (points.size() < 4 || IsFlat(points)) return distances;
  const std::vector<Eigen::Vector4d> planes = CameraFacingPlanes(points);
  if (planes.empty()) return distances;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector4d q(points[i].x(), points[i].y(), points[i].z(), 1.0);
    double nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector4d& plane : planes) {
      nearest = std::min(nearest, -plane.dot(q));
    }
    distances[i] = static_cast<float>(std::max(0.0, nearest));
  }
  return distances;
}

float CameraFacingHullDistance(const std::vector<Eigen::Vector3f>& points) {
  const std::vector<float> distances = CameraFacingHullDistances(points);
  if (distances.empty()) return 0.0f;
  double sum = 0.0;
  for (const float d : distances) sum += d;
  return static_cast<float>(sum / static_cast<double>(distances.size()));
}

}  // namespace fovea
