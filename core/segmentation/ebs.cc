#include "core/segmentation/ebs.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"

namespace fovea {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kMinBins = 2;
constexpr int kMaxBins = 1024;
constexpr int kMaxBandPx = 16;
// BoundaryLabels' values.
constexpr uint8_t kEdge = 255;
constexpr uint8_t kNoEdge = 1;
constexpr uint8_t kLeftOut = 0;
// Largest total count a histogram may hold (keeps sums far from overflow).
constexpr int64_t kMaxTotalCount = int64_t{1} << 52;

// The bin of `value` (not NaN) under `bins`.
int BinOf(float value, const CueBins& bins) {
  const float t = std::sqrt(std::min(std::abs(value) / bins.max_value, 1.0f));
  const float x = bins.signed_cue ? 0.5f * (1.0f + (value < 0.0f ? -t : t)) : t;
  return std::min(bins.bins - 1, static_cast<int>(x * bins.bins));
}

const cv::Mat& CueMap(const EdgeMaps& maps, int cue) {
  return cue == 0 ? maps.color : cue == 1 ? maps.depth : maps.curvature;
}

// The three maps, CV_32FC1 of one size.
bool MapsAreWellFormed(const EdgeMaps& maps) {
  for (int c = 0; c < EbsModel::kCues; ++c) {
    const cv::Mat& m = CueMap(maps, c);
    if (m.type() != CV_32FC1 || m.size() != maps.depth.size()) return false;
  }
  return true;
}

// Region of a label: 1 for the table, the object id for objects, 0 none.
float RegionOf(int label) {
  if (IsTableLabel(label)) return 1.0f;
  return static_cast<float>(ObjectId(label));
}

// Pixels within `band` (Chebyshev) of a pixel of another region; the
// inputs are the regions with "none" set to +big and to -1.
cv::Mat NearOtherRegion(const cv::Mat& for_min, const cv::Mat& for_max,
                        int band) {
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_RECT, {2 * band + 1, 2 * band + 1});
  cv::Mat lo, hi;
  cv::erode(for_min, lo, kernel, {-1, -1}, 1, cv::BORDER_CONSTANT,
            cv::Scalar(std::numeric_limits<float>::max()));
  cv::dilate(for_max, hi, kernel, {-1, -1}, 1, cv::BORDER_CONSTANT,
             cv::Scalar(-1.0));
  return lo != hi;
}

absl::Status CheckFrame(const cv::Mat& labels, const OrganizedCloud& cloud) {
  if (cloud.xyz.empty() || cloud.xyz.type() != CV_32FC3 ||
      cloud.normals.type() != CV_32FC3 || cloud.color.type() != CV_8UC3 ||
      cloud.normals.size() != cloud.xyz.size() ||
      cloud.color.size() != cloud.xyz.size()) {
    return absl::InvalidArgumentError(
        "ebs: the cloud must have xyz and normals (CV_32FC3) and colour "
        "(CV_8UC3) of one size");
  }
  if (labels.type() != CV_32SC1 || labels.size() != cloud.xyz.size()) {
    return absl::InvalidArgumentError(
        "ebs: labels must be CV_32SC1 of the cloud's size");
  }
  return absl::OkStatus();
}

absl::StatusOr<OrganizedCloud> CloudOf(const LabelledFrame* frame,
                                       const NormalOptions& normals) {
  if (frame == nullptr) {
    return absl::InvalidArgumentError("ebs: a frame is null");
  }
  if (frame->frame.color.type() != CV_8UC3 ||
      frame->frame.color.size() != frame->frame.depth.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("ebs: frame ", frame->name,
                     ": colour must be CV_8UC3 of the depth's "
                     "size"));
  }
  absl::StatusOr<OrganizedCloud> cloud =
      BuildOrganizedCloud(frame->frame, normals);
  if (!cloud.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "ebs: frame ", frame->name, ": ", cloud.status().message()));
  }
  return cloud;
}

// Adds one cloud's pixels to per-cue counts.
void CountPixels(const EdgeMaps& maps, const cv::Mat& boundary,
                 std::array<EbsModel::Cue, EbsModel::kCues>& cues) {
  for (int c = 0; c < EbsModel::kCues; ++c) {
    const cv::Mat& map = CueMap(maps, c);
    EbsModel::Cue& cue = cues[c];
    for (int v = 0; v < map.rows; ++v) {
      const float* m = map.ptr<float>(v);
      const uint8_t* b = boundary.ptr<uint8_t>(v);
      for (int u = 0; u < map.cols; ++u) {
        if (b[u] == kLeftOut || std::isnan(m[u])) continue;
        const int bin = BinOf(m[u], cue.bins);
        ++(b[u] == kEdge ? cue.edge : cue.no_edge)[bin];
      }
    }
  }
}

void Tally(bool is_edge, bool said_edge, EdgeCounts& counts) {
  if (is_edge) {
    ++(said_edge ? counts.true_edge : counts.missed_edge);
  } else {
    ++(said_edge ? counts.false_edge : counts.true_no_edge);
  }
}

}  // namespace

// --- Options ---------------------------------------------------------------

absl::Status Validate(const CueBins& bins) {
  if (bins.bins < kMinBins || bins.bins > kMaxBins) {
    return absl::InvalidArgumentError(absl::StrCat(
        "bins must be in [", kMinBins, ", ", kMaxBins, "], got ", bins.bins));
  }
  if (!(bins.max_value > 0.0f) || !std::isfinite(bins.max_value)) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_value must be finite and > 0, got ", bins.max_value));
  }
  return absl::OkStatus();
}

absl::Status Validate(const EbsTrainOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options.edge_maps));
  FOVEA_RETURN_IF_ERROR(Validate(options.normals));
  const std::pair<const char*, const CueBins*> bins[] = {
      {"color_bins", &options.color_bins},
      {"depth_bins", &options.depth_bins},
      {"curvature_bins", &options.curvature_bins}};
  for (const auto& [name, b] : bins) {
    if (absl::Status s = Validate(*b); !s.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("ebs.", name, ".", s.message()));
    }
  }
  if (options.boundary_band_px < 1 || options.boundary_band_px > kMaxBandPx) {
    return absl::InvalidArgumentError(
        absl::StrCat("ebs.boundary_band_px must be in [1, ", kMaxBandPx,
                     "], got ", options.boundary_band_px));
  }
  if (options.ignore_band_px < 0 || options.ignore_band_px > kMaxBandPx) {
    return absl::InvalidArgumentError(
        absl::StrCat("ebs.ignore_band_px must be in [0, ", kMaxBandPx,
                     "], got ", options.ignore_band_px));
  }
  return absl::OkStatus();
}

// --- Boundary labels and counts ---------------------------------------------

absl::StatusOr<cv::Mat> BoundaryLabels(const cv::Mat& labels,
                                       const cv::Mat& xyz, int boundary_band_px,
                                       int ignore_band_px) {
  if (labels.empty() || labels.type() != CV_32SC1) {
    return absl::InvalidArgumentError(
        "ebs: labels must be a non-empty CV_32SC1 image");
  }
  if (!xyz.empty() && (xyz.type() != CV_32FC3 || xyz.size() != labels.size())) {
    return absl::InvalidArgumentError(
        "ebs: xyz must be empty or CV_32FC3 of the labels' size");
  }
  if (boundary_band_px < 1 || boundary_band_px > kMaxBandPx ||
      ignore_band_px < 0 || ignore_band_px > kMaxBandPx) {
    return absl::InvalidArgumentError(
        absl::StrCat("ebs: boundary_band_px must be in [1, ", kMaxBandPx,
                     "] and ignore_band_px in [0, ", kMaxBandPx, "], got ",
                     boundary_band_px, " and ", ignore_band_px));
  }
  const int h = labels.rows, w = labels.cols;
  cv::Mat for_min(h, w, CV_32FC1), for_max(h, w, CV_32FC1);
  cv::Mat out(h, w, CV_8UC1);
  for (int v = 0; v < h; ++v) {
    const int* l = labels.ptr<int>(v);
    const cv::Vec3f* p = xyz.empty() ? nullptr : xyz.ptr<cv::Vec3f>(v);
    float* lo = for_min.ptr<float>(v);
    float* hi = for_max.ptr<float>(v);
    uint8_t* o = out.ptr<uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      const float region = RegionOf(l[u]);
      const bool has_region = region > 0.0f;
      lo[u] = has_region ? region : std::numeric_limits<float>::max();
      hi[u] = has_region ? region : -1.0f;
      const bool usable = has_region && (p == nullptr || !std::isnan(p[u][2]));
      o[u] = usable ? kNoEdge : kLeftOut;
    }
  }
  const cv::Mat edge = NearOtherRegion(for_min, for_max, boundary_band_px);
  const cv::Mat near =
      ignore_band_px > 0
          ? NearOtherRegion(for_min, for_max, boundary_band_px + ignore_band_px)
          : edge;
  for (int v = 0; v < h; ++v) {
    const uint8_t* e = edge.ptr<uint8_t>(v);
    const uint8_t* n = near.ptr<uint8_t>(v);
    uint8_t* o = out.ptr<uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      if (o[u] == kLeftOut) continue;
      o[u] = e[u] ? kEdge : n[u] ? kLeftOut : kNoEdge;
    }
  }
  return out;
}

double EdgeCounts::Accuracy() const {
  const int64_t all = true_edge + missed_edge + true_no_edge + false_edge;
  return all > 0 ? static_cast<double>(true_edge + true_no_edge) / all : 0.0;
}

double EdgeCounts::BalancedAccuracy() const {
  const int64_t edges = true_edge + missed_edge;
  const int64_t others = true_no_edge + false_edge;
  if (edges == 0 || others == 0) return 0.0;
  return 0.5 * (static_cast<double>(true_edge) / edges +
                static_cast<double>(true_no_edge) / others);
}

// --- Trainer -----------------------------------------------------------------

EbsTrainer::EbsTrainer(const EbsTrainOptions& options) : options_(options) {
  const CueBins* bins[] = {&options.color_bins, &options.depth_bins,
                           &options.curvature_bins};
  for (int c = 0; c < EbsModel::kCues; ++c) {
    cues_[c].bins = *bins[c];
    cues_[c].edge.assign(bins[c]->bins, 0);
    cues_[c].no_edge.assign(bins[c]->bins, 0);
  }
}

absl::StatusOr<EbsTrainer> EbsTrainer::Create(const EbsTrainOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  return EbsTrainer(options);
}

absl::Status EbsTrainer::Add(const LabelledFrame& frame) {
  FOVEA_ASSIGN_OR_RETURN(OrganizedCloud cloud,
                         CloudOf(&frame, options_.normals));
  return Add(cloud, frame.labels);
}

absl::Status EbsTrainer::Add(const OrganizedCloud& cloud,
                             const cv::Mat& labels) {
  FOVEA_RETURN_IF_ERROR(CheckFrame(labels, cloud));
  FOVEA_ASSIGN_OR_RETURN(
      cv::Mat boundary,
      BoundaryLabels(labels, cloud.xyz, options_.boundary_band_px,
                     options_.ignore_band_px));
  const EdgeMaps maps = ComputeEdgeMaps(cloud, options_.edge_maps);
  CountPixels(maps, boundary, cues_);
  return absl::OkStatus();
}

absl::StatusOr<EbsModel> EbsTrainer::Finish() const {
  for (int c = 0; c < EbsModel::kCues; ++c) {
    const auto sum = [](const std::vector<int64_t>& v) {
      int64_t s = 0;
      for (const int64_t x : v) s += x;
      return s;
    };
    if (sum(cues_[c].edge) == 0 || sum(cues_[c].no_edge) == 0) {
      return absl::FailedPreconditionError(absl::StrCat(
          "ebs: no ", sum(cues_[c].edge) == 0 ? "edge" : "non-edge",
          " pixel with a ", EbsModel::kCueNames[c],
          " value has been counted; add labelled frames with "
          "objects on a table"));
    }
  }
  return EbsModel::FromCounts(options_, cues_);
}

// --- Model -------------------------------------------------------------------

absl::StatusOr<EbsModel> EbsModel::Train(
    const std::vector<const LabelledFrame*>& frames,
    const EbsTrainOptions& options) {
  FOVEA_ASSIGN_OR_RETURN(EbsTrainer trainer, EbsTrainer::Create(options));
  for (const LabelledFrame* frame : frames) {
    if (frame == nullptr) {
      return absl::InvalidArgumentError("ebs: a frame is null");
    }
    FOVEA_RETURN_IF_ERROR(trainer.Add(*frame));
  }
  return trainer.Finish();
}

absl::StatusOr<EbsModel> EbsModel::Train(
    const std::vector<const LabelledFrame*>& frames,
    const EdgeMapOptions& edge_maps, const NormalOptions& normals) {
  EbsTrainOptions options;
  options.edge_maps = edge_maps;
  options.normals = normals;
  return Train(frames, options);
}

absl::StatusOr<EbsModel> EbsModel::FromCounts(
    const EbsTrainOptions& options, const std::array<Cue, kCues>& cues) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  EbsModel model;
  model.options_ = options;
  model.cues_ = cues;
  for (int c = 0; c < kCues; ++c) {
    const Cue& cue = cues[c];
    const std::string name =
        absl::StrCat("ebs: cue ", EbsModel::kCueNames[c], ": ");
    if (absl::Status s = Validate(cue.bins); !s.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(name, s.message()));
    }
    const size_t n = static_cast<size_t>(cue.bins.bins);
    if (cue.edge.size() != n || cue.no_edge.size() != n) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, "histograms must have ", n, " bins, have ",
                       cue.edge.size(), " and ", cue.no_edge.size()));
    }
    int64_t edge_total = 0, no_edge_total = 0;
    for (size_t i = 0; i < n; ++i) {
      if (cue.edge[i] < 0 || cue.no_edge[i] < 0) {
        return absl::InvalidArgumentError(
            absl::StrCat(name, "negative count in bin ", i));
      }
      if (cue.edge[i] > kMaxTotalCount - edge_total ||
          cue.no_edge[i] > kMaxTotalCount - no_edge_total) {
        return absl::InvalidArgumentError(
            absl::StrCat(name, "counts sum past 2^52"));
      }
      edge_total += cue.edge[i];
      no_edge_total += cue.no_edge[i];
    }
    if (edge_total == 0 || no_edge_total == 0) {
      return absl::InvalidArgumentError(absl::StrCat(
          name, "no ", edge_total == 0 ? "edge" : "non-edge", " counts"));
    }
    // Laplace smoothing: one extra count in every bin.
    std::vector<float>& ratio = model.log_ratio_[c];
    ratio.resize(n);
    const double edge_norm = static_cast<double>(edge_total) + n;
    const double no_edge_norm = static_cast<double>(no_edge_total) + n;
    model.inverse_ratio_[c].resize(n);
    for (size_t i = 0; i < n; ++i) {
      const double log_ratio = std::log((cue.edge[i] + 1.0) / edge_norm) -
                               std::log((cue.no_edge[i] + 1.0) / no_edge_norm);
      ratio[i] = static_cast<float>(log_ratio);
      model.inverse_ratio_[c][i] = static_cast<float>(std::exp(-log_ratio));
    }
  }
  return model;
}

cv::Mat EbsModel::EdgeProbability(const EdgeMaps& maps) const {
  if (maps.depth.empty()) return cv::Mat();
  FOVEA_CHECK(MapsAreWellFormed(maps));
  const int h = maps.depth.rows, w = maps.depth.cols;
  cv::Mat out(h, w, CV_32FC1);
  for (int v = 0; v < h; ++v) {
    const float* m[kCues] = {maps.color.ptr<float>(v), maps.depth.ptr<float>(v),
                             maps.curvature.ptr<float>(v)};
    float* o = out.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      if (std::isnan(m[1][u])) {
        o[u] = 1.0f;
        continue;
      }
      // p = 1 / (1 + prod_c p(x_c | ~E) / p(x_c | E)); the prior 0.5
      // cancels.
      float odds_against = 1.0f;
      for (int c = 0; c < kCues; ++c) {
        if (!std::isnan(m[c][u])) {
          odds_against *= inverse_ratio_[c][BinOf(m[c][u], cues_[c].bins)];
        }
      }
      o[u] = 1.0f / (1.0f + odds_against);
    }
  }
  return out;
}

cv::Mat EbsModel::EdgeProbability(const OrganizedCloud& cloud) const {
  return EdgeProbability(ComputeEdgeMaps(cloud, options_.edge_maps));
}

absl::StatusOr<EbsEvaluation> EbsModel::Evaluate(const OrganizedCloud& cloud,
                                                 const cv::Mat& labels) const {
  FOVEA_RETURN_IF_ERROR(CheckFrame(labels, cloud));
  FOVEA_ASSIGN_OR_RETURN(
      cv::Mat boundary,
      BoundaryLabels(labels, cloud.xyz, options_.boundary_band_px,
                     options_.ignore_band_px));
  const EdgeMaps maps = ComputeEdgeMaps(cloud, options_.edge_maps);
  const cv::Mat p = EdgeProbability(maps);
  EbsEvaluation result;
  EdgeCounts* per_cue[kCues] = {&result.color, &result.depth,
                                &result.curvature};
  for (int v = 0; v < p.rows; ++v) {
    const uint8_t* b = boundary.ptr<uint8_t>(v);
    const float* fused = p.ptr<float>(v);
    for (int u = 0; u < p.cols; ++u) {
      if (b[u] == kLeftOut) continue;
      const bool is_edge = b[u] == kEdge;
      Tally(is_edge, fused[u] > 0.5f, result.fused);
      for (int c = 0; c < kCues; ++c) {
        const float x = CueMap(maps, c).ptr<float>(v)[u];
        if (std::isnan(x)) continue;
        Tally(is_edge, log_ratio_[c][BinOf(x, cues_[c].bins)] > 0.0f,
              *per_cue[c]);
      }
    }
  }
  return result;
}

absl::StatusOr<EbsEvaluation> EbsModel::Evaluate(
    const std::vector<const LabelledFrame*>& frames) const {
  EbsEvaluation total;
  for (const LabelledFrame* frame : frames) {
    FOVEA_ASSIGN_OR_RETURN(OrganizedCloud cloud,
                           CloudOf(frame, options_.normals));
    FOVEA_ASSIGN_OR_RETURN(EbsEvaluation one, Evaluate(cloud, frame->labels));
    EdgeCounts* sums[] = {&total.color, &total.depth, &total.curvature,
                          &total.fused};
    const EdgeCounts* parts[] = {&one.color, &one.depth, &one.curvature,
                                 &one.fused};
    for (int i = 0; i < 4; ++i) {
      sums[i]->true_edge += parts[i]->true_edge;
      sums[i]->missed_edge += parts[i]->missed_edge;
      sums[i]->true_no_edge += parts[i]->true_no_edge;
      sums[i]->false_edge += parts[i]->false_edge;
    }
  }
  return total;
}

}  // namespace fovea
