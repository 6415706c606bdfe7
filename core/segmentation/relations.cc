#include "core/segmentation/relations.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "absl/strings/str_cat.h"
#include "core/base/lab.h"
#include "core/base/parallel.h"

namespace fovea {
namespace {

constexpr int kOrientations = 4;
constexpr int kFourierWindow = 16;
constexpr int kFourierBands = 4;
constexpr double kRadiansToDegrees = 180.0 / M_PI;

double Clamp01(double v) { return std::min(1.0, std::max(0.0, v)); }

// 1 - normalised L1 distance of two non-negative vectors: 1 for equal
// ones, 0 for disjoint ones; 1 when both are empty.
double ProfileSimilarity(const std::vector<double>& a,
                         const std::vector<double>& b) {
  double diff = 0.0, total = 0.0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    diff += std::abs(a[i] - b[i]);
    total += a[i] + b[i];
  }
  return total > 0.0 ? 1.0 - diff / total : 1.0;
}

// Each vector scaled to sum 1 (left as is when it sums to 0).
void Normalize(std::vector<double>& v) {
  double sum = 0.0;
  for (const double x : v) sum += x;
  if (sum <= 0.0) return;
  for (double& x : v) x /= sum;
}

// The smallest rectangle holding every pixel of `labels` whose label is in
// [0, count); empty when there is none.
cv::Rect LabelledBox(const cv::Mat& labels, int count) {
  int x0 = labels.cols, y0 = labels.rows, x1 = -1, y1 = -1;
  for (int v = 0; v < labels.rows; ++v) {
    const int* label = labels.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (label[u] < 0 || label[u] >= count) continue;
      x0 = std::min(x0, u);
      x1 = std::max(x1, u);
      y0 = std::min(y0, v);
      y1 = std::max(y1, v);
    }
  }
  return x1 < 0 ? cv::Rect() : cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
}

// Per label, the mean absolute response of each filter of a Gabor bank on
// the half-resolution grey image. Only `box` (LabelledBox of labels_half)
// is filtered: the filter reads the image around it as the whole image's
// filter would.
std::vector<std::vector<double>> GaborEnergies(const cv::Mat& grey_half,
                                               const cv::Mat& labels_half,
                                               int count,
                                               const RelationOptions& options,
                                               const cv::Rect& box) {
  const int filters =
      kOrientations * static_cast<int>(options.gabor_wavelengths_px.size());
  std::vector<std::vector<double>> energy(count,
                                          std::vector<double>(filters, 0.0));
  std::vector<int> n(count, 0);
  for (int v = box.y; v < box.br().y; ++v) {
    const int* label = labels_half.ptr<int>(v);
    for (int u = box.x; u < box.br().x; ++u) {
      if (label[u] >= 0 && label[u] < count) ++n[label[u]];
    }
  }
  // Filters run in parallel; each sums its own column, in pixel order.
  ParallelFor(box.empty() ? 0 : filters, [&](int f) {
    const float lambda = options.gabor_wavelengths_px[f / kOrientations];
    const int o = f % kOrientations;
    const int size = 2 * static_cast<int>(std::ceil(lambda)) + 1;
    const cv::Mat kernel =
        cv::getGaborKernel(cv::Size(size, size), 0.5 * lambda,
                           o * M_PI / kOrientations, lambda, 1.0, 0.0, CV_32F);
    cv::Mat response;
    cv::filter2D(grey_half(box), response, CV_32F, kernel);
    for (int v = 0; v < box.height; ++v) {
      const int* label = labels_half.ptr<int>(box.y + v) + box.x;
      const float* r = response.ptr<float>(v);
      for (int u = 0; u < box.width; ++u) {
        if (label[u] >= 0 && label[u] < count) {
          energy[label[u]][f] += std::abs(r[u]);
        }
      }
    }
  });
  for (int l = 0; l < count; ++l) {
    if (n[l] > 0) {
      for (double& e : energy[l]) e /= n[l];
    }
    Normalize(energy[l]);
  }
  return energy;
}

// Per label, DFT magnitude energy in 4 radial bands (DC left out) of up to
// options.fourier_windows 16x16 windows lying mostly on the label. The
// windows sit on a grid of half a window from the image's corner; only
// those centred in `box` (LabelledBox of labels_half) can count.
std::vector<std::vector<double>> FourierEnergies(const cv::Mat& grey_half,
                                                 const cv::Mat& labels_half,
                                                 int count,
                                                 const RelationOptions& options,
                                                 const cv::Rect& box) {
  std::vector<std::vector<double>> bands(
      count, std::vector<double>(kFourierBands, 0.0));
  std::vector<int> windows(count, 0);
  const int step = kFourierWindow / 2;
  // The first grid line whose window's centre (+ step) can be in the box.
  auto first = [step](int box_start) {
    return (std::max(0, box_start - step) + step - 1) / step * step;
  };
  for (int v = first(box.y);
       v + kFourierWindow <= labels_half.rows && v + step < box.br().y;
       v += step) {
    for (int u = first(box.x);
         u + kFourierWindow <= labels_half.cols && u + step < box.br().x;
         u += step) {
      const int l = labels_half.at<int>(v + step, u + step);
      if (l < 0 || l >= count || windows[l] >= options.fourier_windows) {
        continue;
      }
      const cv::Rect window(u, v, kFourierWindow, kFourierWindow);
      if (cv::countNonZero(labels_half(window) == l) <
          kFourierWindow * kFourierWindow * 3 / 4) {
        continue;
      }
      cv::Mat patch;
      grey_half(window).convertTo(patch, CV_32F);
      patch -= cv::mean(patch)[0];
      cv::Mat spectrum;
      cv::dft(patch, spectrum, cv::DFT_COMPLEX_OUTPUT);
      for (int y = 0; y < kFourierWindow; ++y) {
        for (int x = 0; x < kFourierWindow; ++x) {
          const int fy = std::min(y, kFourierWindow - y);
          const int fx = std::min(x, kFourierWindow - x);
          const double r = std::hypot(fx, fy);
          if (r < 1.0) continue;
          const int band = std::min(
              kFourierBands - 1,
              static_cast<int>(r * kFourierBands / (kFourierWindow / 2 + 1)));
          const cv::Vec2f c = spectrum.at<cv::Vec2f>(y, x);
          bands[l][band] += std::hypot(c[0], c[1]);
        }
      }
      ++windows[l];
    }
  }
  for (std::vector<double>& b : bands) Normalize(b);
  return bands;
}

}  // namespace

absl::Status Validate(const RelationOptions& options) {
  if (absl::Status s = Validate(options.color); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("color.", s.message()));
  }
  if (options.gabor_wavelengths_px.empty()) {
    return absl::InvalidArgumentError("gabor_wavelengths_px must not be empty");
  }
  for (const float w : options.gabor_wavelengths_px) {
    if (!(w >= 2.0f && w <= 32.0f)) {
      return absl::InvalidArgumentError(
          absl::StrCat("gabor_wavelengths_px must be in [2, 32], got ", w));
    }
  }
  if (options.fourier_windows < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "fourier_windows must not be negative, got ", options.fourier_windows));
  }
  if (!(options.color_scale > 0) || !(options.depth_scale > 0) ||
      !(options.angle_scale_deg > 0)) {
    return absl::InvalidArgumentError(
        "color_scale, depth_scale and angle_scale_deg must be positive");
  }
  if (!(options.touch_depth_fraction > 0)) {
    return absl::InvalidArgumentError("touch_depth_fraction must be positive");
  }
  if (options.convexity_offset_px < 1 || options.convexity_offset_px > 32) {
    return absl::InvalidArgumentError(
        absl::StrCat("convexity_offset_px must be in [1, 32], got ",
                     options.convexity_offset_px));
  }
  if (!(options.sharp_concave > 0.0f && options.sharp_concave <= 2.0f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "sharp_concave must be in (0, 2], got ", options.sharp_concave));
  }
  return absl::OkStatus();
}

const std::vector<std::string>& RelationFeatureNames() {
  static const std::vector<std::string>* const names =
      new std::vector<std::string>{
          "color_similarity",      "gabor_similarity",
          "fourier_similarity",    "relative_size",
          "border_color_mean",     "border_color_variation",
          "border_depth_mean",     "border_depth_variation",
          "border_angle_mean",     "border_angle_variation",
          "border_3d_fraction",    "curvature_similarity",
          "border_convexity",      "border_sharp_concave_fraction",
          "uprightness_difference"};
  return *names;
}

uint64_t RelationComputer::Key(int a, int b) {
  return (static_cast<uint64_t>(std::min(a, b)) << 32) |
         static_cast<uint32_t>(std::max(a, b));
}

RelationComputer::RelationComputer(const OrganizedCloud& cloud,
                                   const cv::Mat& labels, int count,
                                   const Eigen::Vector3f& up,
                                   const RelationOptions& options)
    : options_(options),
      points_(count, 0),
      curvature_(count, 0.0),
      uprightness_(count, 0.0) {
  // Everything below looks only at the surfaces' pixels: their bounding
  // box, at full and at half resolution (a frame's support and background
  // are often most of it, and callers leave them out).
  const cv::Rect box = LabelledBox(labels, count);
  const cv::Rect colour_box =
      box.empty() ? cv::Rect(0, 0, labels.cols, labels.rows) : box;
  histograms_ = LabelColorHistograms(cloud.color(colour_box),
                                     labels(colour_box), count, options.color);
  cv::Mat grey, grey_half, labels_half;
  cv::cvtColor(cloud.color, grey, cv::COLOR_RGB2GRAY);
  cv::resize(grey, grey_half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  cv::resize(labels, labels_half, grey_half.size(), 0, 0, cv::INTER_NEAREST);
  const cv::Rect half_box = LabelledBox(labels_half, count);
  cv::Mat grey_float;
  grey_half.convertTo(grey_float, CV_32F, 1.0 / 255.0);
  gabor_ = GaborEnergies(grey_float, labels_half, count, options, half_box);
  fourier_ = FourierEnergies(grey_half, labels_half, count, options, half_box);

  cv::Mat lab;  // of the box
  if (!box.empty()) {
    cv::Mat color_float;
    cloud.color(box).convertTo(color_float, CV_32FC3, 1.0 / 255.0);
    RgbToLab(color_float, &lab);
  }
  // Mean normals, then each surface's mean deviation from it.
  std::vector<Eigen::Vector3d> mean_normal(count, Eigen::Vector3d::Zero());
  for (int v = box.y; v < box.br().y; ++v) {
    for (int u = box.x; u < box.br().x; ++u) {
      const int l = labels.at<int>(v, u);
      if (l < 0 || l >= count) continue;
      ++points_[l];
      const cv::Vec3f& n = cloud.normals.at<cv::Vec3f>(v, u);
      if (!std::isnan(n[2]))
        mean_normal[l] += Eigen::Vector3d(n[0], n[1], n[2]);
    }
  }
  std::vector<int> with_normal(count, 0);
  for (int v = box.y; v < box.br().y; ++v) {
    for (int u = box.x; u < box.br().x; ++u) {
      const int l = labels.at<int>(v, u);
      if (l < 0 || l >= count) continue;
      const cv::Vec3f& n = cloud.normals.at<cv::Vec3f>(v, u);
      if (std::isnan(n[2]) || mean_normal[l].norm() == 0.0) continue;
      curvature_[l] += 1.0 - std::abs(Eigen::Vector3d(n[0], n[1], n[2])
                                          .dot(mean_normal[l].normalized()));
      ++with_normal[l];
    }
  }
  const Eigen::Vector3d up_d = up.cast<double>().normalized();
  for (int l = 0; l < count; ++l) {
    if (with_normal[l] > 0) curvature_[l] /= with_normal[l];
    if (mean_normal[l].norm() > 0.0) {
      uprightness_[l] = std::abs(mean_normal[l].normalized().dot(up_d));
    }
  }
  const int offset = options.convexity_offset_px;

  // Borders: every 4-adjacent pixel pair of two surfaces (both in the box).
  for (int v = box.y; v < box.br().y; ++v) {
    for (int u = box.x; u < box.br().x; ++u) {
      const int a = labels.at<int>(v, u);
      if (a < 0 || a >= count) continue;
      for (const cv::Point d : {cv::Point(1, 0), cv::Point(0, 1)}) {
        const int x = u + d.x;
        const int y = v + d.y;
        if (x >= labels.cols || y >= labels.rows) continue;
        const int b = labels.at<int>(y, x);
        if (b < 0 || b >= count || b == a) continue;
        Border& border = borders_[Key(a, b)];
        ++border.pixels;
        const float za = cloud.xyz.at<cv::Vec3f>(v, u)[2];
        const float zb = cloud.xyz.at<cv::Vec3f>(y, x)[2];
        if (!std::isnan(za) && !std::isnan(zb)) {
          const double step = std::abs(za - zb) / std::max(za, zb);
          border.depth_sum += step;
          border.depth_sq += step * step;
          if (step <= options.touch_depth_fraction) ++border.touching;
        }
        const bool touching = !std::isnan(za) && !std::isnan(zb) &&
                              std::abs(za - zb) / std::max(za, zb) <=
                                  options.touch_depth_fraction;
        const cv::Vec3f& la = lab.at<cv::Vec3f>(v - box.y, u - box.x);
        const cv::Vec3f& lb = lab.at<cv::Vec3f>(y - box.y, x - box.x);
        const double color = cv::norm(la - lb);
        border.color_sum += color;
        border.color_sq += color * color;
        const cv::Vec3f& na = cloud.normals.at<cv::Vec3f>(v, u);
        const cv::Vec3f& nb = cloud.normals.at<cv::Vec3f>(y, x);
        if (!std::isnan(na[2]) && !std::isnan(nb[2])) {
          const double angle =
              std::acos(
                  std::min(1.0, std::abs(static_cast<double>(na.dot(nb))))) *
              kRadiansToDegrees;
          border.angle_sum += angle;
          border.angle_sq += angle * angle;
        }
        // Convexity from points `offset` pixels inside either surface,
        // where the two touch (across a depth jump they need not meet).
        if (!touching) continue;
        const int pu = u - offset * d.x, pv = v - offset * d.y;
        const int qu = x + offset * d.x, qv = y + offset * d.y;
        if (pu < 0 || pv < 0 || qu >= labels.cols || qv >= labels.rows ||
            labels.at<int>(pv, pu) != a || labels.at<int>(qv, qu) != b) {
          continue;
        }
        const cv::Vec3f& pp = cloud.xyz.at<cv::Vec3f>(pv, pu);
        const cv::Vec3f& qq = cloud.xyz.at<cv::Vec3f>(qv, qu);
        const cv::Vec3f& np = cloud.normals.at<cv::Vec3f>(pv, pu);
        const cv::Vec3f& nq = cloud.normals.at<cv::Vec3f>(qv, qu);
        if (std::isnan(pp[2]) || std::isnan(qq[2]) || std::isnan(np[2]) ||
            std::isnan(nq[2])) {
          continue;
        }
        const cv::Vec3f pq = qq - pp;
        const double length = cv::norm(pq);
        if (length <= 0.0) continue;
        const double convexity = (nq - np).dot(pq) / length;
        ++border.folds;
        border.convexity_sum += convexity;
        border.sharp_concave += convexity < -options.sharp_concave;
      }
    }
  }
  for (const auto& [key, border] : borders_) {
    pairs_.emplace_back(static_cast<int>(key >> 32),
                        static_cast<int>(key & 0xffffffffu));
  }
  std::sort(pairs_.begin(), pairs_.end());
}

std::vector<double> RelationComputer::Relate(int a, int b) const {
  std::vector<double> f(RelationFeatureNames().size(), 0.0);
  f[0] = 0.5 * (1.0 + HistogramCorrelation(histograms_[a], histograms_[b]));
  f[1] = ProfileSimilarity(gabor_[a], gabor_[b]);
  f[2] = ProfileSimilarity(fourier_[a], fourier_[b]);
  f[3] = points_[a] > 0 && points_[b] > 0
             ? static_cast<double>(std::min(points_[a], points_[b])) /
                   std::max(points_[a], points_[b])
             : 0.0;
  const auto found = borders_.find(Key(a, b));
  if (found != borders_.end() && found->second.pixels > 0) {
    const Border& border = found->second;
    const double n = border.pixels;
    auto mean_std = [n](double sum, double sq, double scale) {
      const double mean = sum / n;
      const double var = std::max(0.0, sq / n - mean * mean);
      return std::pair<double, double>(Clamp01(mean / scale),
                                       Clamp01(std::sqrt(var) / scale));
    };
    std::tie(f[4], f[5]) =
        mean_std(border.color_sum, border.color_sq, options_.color_scale);
    std::tie(f[6], f[7]) =
        mean_std(border.depth_sum, border.depth_sq, options_.depth_scale);
    std::tie(f[8], f[9]) =
        mean_std(border.angle_sum, border.angle_sq, options_.angle_scale_deg);
    f[10] = border.touching / n;
  }
  f[11] = Clamp01(1.0 - std::abs(curvature_[a] - curvature_[b]) * 10.0);
  if (found != borders_.end() && found->second.folds > 0) {
    const Border& border = found->second;
    // Mean convexity, in [-2, 2], mapped to [0, 1]: 0.5 is flat.
    f[12] = Clamp01(0.5 + 0.25 * border.convexity_sum / border.folds);
    f[13] = static_cast<double>(border.sharp_concave) / border.folds;
  } else {
    f[12] = 0.5;
  }
  f[14] = std::abs(uprightness_[a] - uprightness_[b]);
  return f;
}

}  // namespace fovea
