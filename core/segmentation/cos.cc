#include "core/segmentation/cos.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/parallel.h"
#include "core/base/status_macros.h"
#include "core/frame/osd_pcd.h"

namespace fovea {
namespace {

constexpr double kMillimetresPerMetre = 1000.0;
// Compactness enters the SVM as log10(mm + this): joins measure tenths of
// a millimetre to a few, rejections a millimetre to centimetres; on a log
// scale a linear SVM separates them (cross-validated accuracy 0.70 -> ...).
constexpr double kCompactnessFloorMm = 0.1;

// Sum of the patches' histograms.
std::vector<float> ObjectHistogram(const CosScene& scene,
                                   const std::vector<int>& object) {
  std::vector<float> sum(
      scene.histograms.empty() ? 0 : scene.histograms[0].size(), 0.0f);
  for (const int p : object) {
    for (size_t b = 0; b < sum.size(); ++b) sum[b] += scene.histograms[p][b];
  }
  return sum;
}

// The patches' samples, thinned evenly to at most `max_points`.
std::vector<Eigen::Vector3f> UnionSamples(const CosScene& scene,
                                          const std::vector<int>& patches,
                                          int max_points) {
  size_t total = 0;
  for (const int p : patches) total += scene.samples[p].size();
  std::vector<Eigen::Vector3f> points;
  points.reserve(std::min<size_t>(total, max_points));
  size_t i = 0;
  for (const int p : patches) {
    for (const Eigen::Vector3f& q : scene.samples[p]) {
      // Point i is kept when floor(i * max / total) steps up.
      if (total <= static_cast<size_t>(max_points) ||
          (i + 1) * max_points / total > i * max_points / total) {
        points.push_back(q);
      }
      ++i;
    }
  }
  return points;
}

// Free, non-table neighbours of the object's patches, sorted, unique.
std::vector<int> Frontier(const CosScene& scene, const std::vector<int>& object,
                          const std::vector<int>& owner) {
  std::vector<int> frontier;
  for (const int p : object) {
    for (const int q : scene.neighbours[p]) {
      if (owner[q] < 0 && !scene.support[q]) frontier.push_back(q);
    }
  }
  std::sort(frontier.begin(), frontier.end());
  frontier.erase(std::unique(frontier.begin(), frontier.end()), frontier.end());
  std::vector<int> result;
  for (const int q : frontier) {
    if (std::find(object.begin(), object.end(), q) == object.end()) {
      result.push_back(q);
    }
  }
  return result;
}

// Gives the pixels with depth but no patch (no normal: along occluding
// edges and object rims, where normals cannot be estimated) the patch of a
// 4-neighbour with nearly the same depth, one ring per pass, `passes`
// times; the ground truth counts those pixels as the object's.
void ExtendIntoUnlabelled(const OrganizedCloud& cloud, int passes,
                          float max_depth_step_fraction, cv::Mat& labels) {
  const int w = labels.cols, h = labels.rows;
  FOVEA_CHECK(labels.isContinuous() && labels.type() == CV_32SC1);
  int* label = labels.ptr<int>();
  // The pixel's new label from the labels as they were before this pass
  // (the first 4-neighbour, right, left, down, up, with a patch and nearly
  // the same depth), or -1.
  const auto joins = [&](int u, int v) {
    const float z = cloud.xyz.ptr<cv::Vec3f>(v)[u][2];
    if (std::isnan(z)) return -1;
    constexpr int kDu[4] = {1, -1, 0, 0};
    constexpr int kDv[4] = {0, 0, 1, -1};
    for (int k = 0; k < 4; ++k) {
      const int x = u + kDu[k];
      const int y = v + kDv[k];
      if (x < 0 || y < 0 || x >= w || y >= h) continue;
      const int l = label[y * w + x];
      const float zn = cloud.xyz.ptr<cv::Vec3f>(y)[x][2];
      if (l >= 0 && std::abs(zn - z) <= max_depth_step_fraction * z) return l;
    }
    return -1;
  };
  // A pixel can join in a pass only if a neighbour joined in the one
  // before (else its neighbours are as they were when it did not): after
  // the first pass, which looks at every pixel, only the neighbours of
  // the pixels that joined are looked at.
  std::vector<std::pair<int, int>> joined;  // (pixel, its new label)
  std::vector<int> candidates;
  std::vector<int> seen_in_pass(static_cast<size_t>(w) * h, -1);
  for (int pass = 0; pass < passes; ++pass) {
    joined.clear();
    if (pass == 0) {
      // Every pixel without a patch: rows in parallel ranges, each
      // collecting its joins, concatenated in raster order.
      const int ranges = std::max(1, std::min(h, ParallelThreads() * 4));
      std::vector<std::vector<std::pair<int, int>>> found(ranges);
      ParallelFor(ranges, [&](int r) {
        const int first = static_cast<int>(int64_t{h} * r / ranges);
        const int last = static_cast<int>(int64_t{h} * (r + 1) / ranges);
        for (int v = first; v < last; ++v) {
          for (int u = 0; u < w; ++u) {
            if (label[v * w + u] >= 0) continue;
            const int l = joins(u, v);
            if (l >= 0) found[r].emplace_back(v * w + u, l);
          }
        }
      });
      for (const auto& part : found) {
        joined.insert(joined.end(), part.begin(), part.end());
      }
    } else {
      if (candidates.empty()) break;
      for (const int i : candidates) {
        const int l = joins(i % w, i / w);
        if (l >= 0) joined.emplace_back(i, l);
      }
    }
    if (joined.empty()) break;
    for (const auto& [i, l] : joined) label[i] = l;
    candidates.clear();
    for (const auto& [i, l] : joined) {
      const int u = i % w, v = i / w;
      for (const int q : {u + 1 < w ? i + 1 : -1, u > 0 ? i - 1 : -1,
                          v + 1 < h ? i + w : -1, v > 0 ? i - w : -1}) {
        if (q < 0 || label[q] >= 0 || seen_in_pass[q] == pass) continue;
        seen_in_pass[q] = pass;
        candidates.push_back(q);
      }
    }
    // Candidates in raster order (the order does not change the labels,
    // only how the pass walks memory).
    std::sort(candidates.begin(), candidates.end());
  }
}

}  // namespace

absl::Status Validate(const CosOptions& options) {
  if (options.seed_radius_px < 0 || options.seed_radius_px > 100) {
    return absl::InvalidArgumentError(absl::StrCat(
        "seed_radius_px must be in [0, 100], got ", options.seed_radius_px));
  }
  if (options.hull_points_per_patch < 4) {
    return absl::InvalidArgumentError(
        absl::StrCat("hull_points_per_patch must be at least 4, got ",
                     options.hull_points_per_patch));
  }
  if (options.max_hull_points < options.hull_points_per_patch) {
    return absl::InvalidArgumentError(absl::StrCat(
        "max_hull_points must be at least hull_points_per_patch, got ",
        options.max_hull_points));
  }
  if (options.rim_passes < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "rim_passes must not be negative, got ", options.rim_passes));
  }
  if (options.max_object_patches < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_object_patches must be positive, got ",
                     options.max_object_patches));
  }
  if (!(options.max_support_fraction >= 0.0f &&
        options.max_support_fraction <= 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_support_fraction must be in [0, 1], got ",
                     options.max_support_fraction));
  }
  if (absl::Status s = Validate(options.color); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("color.", s.message()));
  }
  if (absl::Status s = Validate(options.patches); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("patches.", s.message()));
  }
  return absl::OkStatus();
}

cv::Rect PatchesBox(const CosScene& scene, const std::vector<int>& patches) {
  cv::Rect box;
  for (const int p : patches) box |= scene.label_boxes[p];
  return box;
}

cv::Mat PatchesMask(const CosScene& scene, const std::vector<int>& patches) {
  std::vector<unsigned char> in(scene.patches.patches.size(), 0);
  for (const int p : patches) in[p] = 1;
  const cv::Mat& labels = scene.patches.labels;
  cv::Mat mask(labels.size(), CV_8UC1, cv::Scalar(0));
  const cv::Rect box = PatchesBox(scene, patches);
  for (int v = box.y; v < box.br().y; ++v) {
    const int* label = labels.ptr<int>(v);
    unsigned char* out = mask.ptr<unsigned char>(v);
    for (int u = box.x; u < box.br().x; ++u) {
      if (label[u] >= 0 && in[label[u]]) out[u] = 255;
    }
  }
  return mask;
}

std::vector<int> PatchObjectIds(const CosScene& scene, const cv::Mat& labels) {
  const int n = static_cast<int>(scene.patches.patches.size());
  std::vector<std::vector<std::pair<int, int>>> votes(n);  // (object, count)
  const cv::Mat& patch_labels = scene.patches.labels;
  for (int v = 0; v < labels.rows; ++v) {
    const int* gt = labels.ptr<int>(v);
    const int* patch = patch_labels.ptr<int>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (patch[u] < 0) continue;
      const int object = ObjectId(gt[u]);
      auto& list = votes[patch[u]];
      auto it = std::find_if(list.begin(), list.end(),
                             [&](const auto& e) { return e.first == object; });
      if (it == list.end()) {
        list.emplace_back(object, 1);
      } else {
        ++it->second;
      }
    }
  }
  std::vector<int> result(n, 0);
  for (int p = 0; p < n; ++p) {
    int best = 0;
    for (const auto& [object, count] : votes[p]) {
      if (count > best) {
        best = count;
        result[p] = object;
      }
    }
  }
  return result;
}

const std::vector<std::string>& CosFeatureNames() {
  static const std::vector<std::string>* const names =
      new std::vector<std::string>{"color_similarity", "log10_compactness_mm"};
  return *names;
}

absl::StatusOr<CosScene> BuildCosScene(const OrganizedCloud& cloud,
                                       const SupportPlane& plane,
                                       const CosOptions& options,
                                       const cv::Mat& region) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  CosScene scene;
  StageClock clock(scene.timings);
  const bool have_inliers = plane.inliers.size() == cloud.xyz.size();
  FOVEA_ASSIGN_OR_RETURN(
      PlanarPatches patches,
      FindPlanarPatches(cloud, region, options.patches,
                        options.support_from_inliers && have_inliers
                            ? plane.inliers
                            : cv::Mat()));
  scene.patches = std::move(patches);
  clock.Lap("patches");
  const int n = static_cast<int>(scene.patches.patches.size());
  // The patches as grown, before the rims join them, for the features.
  const cv::Mat grown = scene.patches.labels.clone();
  ExtendIntoUnlabelled(cloud, options.rim_passes,
                       options.patches.max_depth_step_fraction,
                       scene.patches.labels);
  scene.neighbours.assign(n, {});
  for (const auto& [a, b] : scene.patches.adjacency) {
    scene.neighbours[a].push_back(b);
    scene.neighbours[b].push_back(a);
  }
  for (std::vector<int>& list : scene.neighbours) {
    std::sort(list.begin(), list.end());
  }
  // Per patch: its pixels, those on the support plane, its box. Rows in
  // parallel ranges, each counting into its own tallies, then summed.
  struct Tally {
    std::vector<int> on_plane, size;
    std::vector<cv::Vec4i> extent;
  };
  const int rows = scene.patches.labels.rows;
  const int ranges = std::max(1, std::min(rows, ParallelThreads() * 4));
  std::vector<Tally> tallies(ranges);
  const cv::Vec4i no_extent(cloud.width(), cloud.height(), -1, -1);
  ParallelFor(ranges, [&](int r) {
    Tally& t = tallies[r];
    t.on_plane.assign(n, 0);
    t.size.assign(n, 0);
    t.extent.assign(n, no_extent);
    const int first = static_cast<int>(int64_t{rows} * r / ranges);
    const int last = static_cast<int>(int64_t{rows} * (r + 1) / ranges);
    for (int v = first; v < last; ++v) {
      const int* label = scene.patches.labels.ptr<int>(v);
      const uint8_t* inlier =
          have_inliers ? plane.inliers.ptr<uint8_t>(v) : nullptr;
      for (int u = 0; u < scene.patches.labels.cols; ++u) {
        const int l = label[u];
        if (l < 0) continue;
        ++t.size[l];
        if (inlier != nullptr && inlier[u] != 0) ++t.on_plane[l];
        cv::Vec4i& e = t.extent[l];
        e[0] = std::min(e[0], u);
        e[1] = std::min(e[1], v);
        e[2] = std::max(e[2], u);
        e[3] = std::max(e[3], v);
      }
    }
  });
  std::vector<int> on_plane(n, 0);
  std::vector<int> size(n, 0);
  std::vector<cv::Vec4i> extent(n, no_extent);
  for (const Tally& t : tallies) {
    for (int p = 0; p < n; ++p) {
      on_plane[p] += t.on_plane[p];
      size[p] += t.size[p];
      for (int k = 0; k < 2; ++k) {
        extent[p][k] = std::min(extent[p][k], t.extent[p][k]);
        extent[p][k + 2] = std::max(extent[p][k + 2], t.extent[p][k + 2]);
      }
    }
  }
  scene.label_boxes.assign(n, cv::Rect());
  for (int p = 0; p < n; ++p) {
    const cv::Vec4i& e = extent[p];
    if (e[2] >= 0) {
      scene.label_boxes[p] =
          cv::Rect(e[0], e[1], e[2] - e[0] + 1, e[3] - e[1] + 1);
    }
  }
  scene.support.assign(n, false);
  for (int p = 0; p < n; ++p) {
    const float height = plane.Height(scene.patches.patches[p].centroid);
    scene.support[p] =
        size[p] > 0 && (on_plane[p] > options.max_support_fraction * size[p] ||
                        (have_inliers && height < options.min_patch_height));
  }
  // Colour histograms and hull samples of the patches that can be part of
  // an object (the support's are never read), on their bounding box.
  cv::Rect box;
  for (int p = 0; p < n; ++p) {
    if (!scene.support[p]) box |= scene.patches.patches[p].box;
  }
  cv::Mat feature_labels(box.size(), CV_32SC1);
  for (int v = 0; v < box.height; ++v) {
    const int* from = grown.ptr<int>(box.y + v) + box.x;
    int* to = feature_labels.ptr<int>(v);
    for (int u = 0; u < box.width; ++u) {
      to[u] = from[u] >= 0 && !scene.support[from[u]] ? from[u] : -1;
    }
  }
  OrganizedCloud box_cloud;
  box_cloud.intrinsics = cloud.intrinsics;
  box_cloud.xyz = box.empty() ? cv::Mat() : cloud.xyz(box);
  scene.histograms =
      box.empty()
          ? std::vector<std::vector<float>>(
                n, std::vector<float>(HistogramBins(options.color), 0.0f))
          : LabelColorHistograms(cloud.color(box), feature_labels, n,
                                 options.color);
  scene.samples = box.empty()
                      ? std::vector<std::vector<Eigen::Vector3f>>(n)
                      : SampleLabelPoints(box_cloud, feature_labels, n,
                                          options.hull_points_per_patch);
  // Each sample onto its patch's plane: the sensor's noise (1-2 mm at a
  // metre) would otherwise push the hull's faces out by its peaks, as far
  // as the concavities compactness is to measure.
  for (int p = 0; p < n; ++p) {
    const PlanarPatch& patch = scene.patches.patches[p];
    for (Eigen::Vector3f& q : scene.samples[p]) {
      q -= (patch.normal.dot(q) + patch.d) * patch.normal;
    }
  }
  clock.Lap("patch_features");
  return scene;
}

std::vector<double> CosJoinFeatures(const CosScene& scene,
                                    const std::vector<int>& object,
                                    int candidate, const CosOptions& options) {
  const std::vector<float> hist = ObjectHistogram(scene, object);
  // The object's samples, then the candidate's.
  std::vector<Eigen::Vector3f> points = UnionSamples(
      scene, object, options.max_hull_points - options.hull_points_per_patch);
  const size_t object_points = points.size();
  points.insert(points.end(), scene.samples[candidate].begin(),
                scene.samples[candidate].end());
  const std::vector<float> distances = CameraFacingHullDistances(points);
  double object_sum = 0.0;
  double candidate_sum = 0.0;
  for (size_t i = 0; i < distances.size(); ++i) {
    (i < object_points ? object_sum : candidate_sum) += distances[i];
  }
  const double compactness = std::max(
      object_sum / std::max<size_t>(object_points, 1),
      candidate_sum / std::max<size_t>(points.size() - object_points, 1));
  return {HistogramCorrelation(hist, scene.histograms[candidate]),
          std::log10(compactness * kMillimetresPerMetre + kCompactnessFloorMm)};
}

CosSegmenter::CosSegmenter(const CosScene& scene, const LinearSvm& svm,
                           const CosOptions& options)
    : scene_(scene),
      svm_(svm),
      options_(options),
      owner_(scene.patches.patches.size(), -1) {}

void CosSegmenter::AbsorbEnclosedSmallPatches(std::vector<int>& object) const {
  for (const int q : Frontier(scene_, object, owner_)) {
    if (scene_.patches.patches[q].points > options_.small_patch_points)
      continue;
    bool enclosed = true;
    for (const int r : scene_.neighbours[q]) {
      const bool in_object =
          std::find(object.begin(), object.end(), r) != object.end();
      if (!in_object && !scene_.support[r]) enclosed = false;
    }
    if (enclosed) object.push_back(q);
  }
}

std::vector<int> CosSegmenter::InitialPatches(cv::Point seed) const {
  const cv::Mat& labels = scene_.patches.labels;
  const int r = options_.seed_radius_px;
  std::vector<int> initial;
  for (int v = std::max(0, seed.y - r);
       v <= std::min(labels.rows - 1, seed.y + r); ++v) {
    for (int u = std::max(0, seed.x - r);
         u <= std::min(labels.cols - 1, seed.x + r); ++u) {
      const int du = u - seed.x;
      const int dv = v - seed.y;
      if (du * du + dv * dv > r * r) continue;
      const int p = labels.at<int>(v, u);
      if (p >= 0 && owner_[p] < 0 && !scene_.support[p]) initial.push_back(p);
    }
  }
  std::sort(initial.begin(), initial.end());
  initial.erase(std::unique(initial.begin(), initial.end()), initial.end());
  return initial;
}

absl::StatusOr<std::optional<CosObject>> CosSegmenter::Segment(
    cv::Point seed, const InterruptCheck& interrupt) {
  const cv::Mat& labels = scene_.patches.labels;
  if (seed.x < 0 || seed.y < 0 || seed.x >= labels.cols ||
      seed.y >= labels.rows) {
    return absl::InvalidArgumentError(
        absl::StrCat("seed (", seed.x, ", ", seed.y, ") lies outside the ",
                     labels.cols, "x", labels.rows, " image"));
  }
  const int own = labels.at<int>(seed.y, seed.x);
  if (own >= 0 && owner_[own] >= 0) return std::nullopt;
  std::vector<int> object = InitialPatches(seed);
  if (object.empty()) return std::nullopt;
  double min_margin = std::numeric_limits<double>::infinity();
  while (static_cast<int>(object.size()) < options_.max_object_patches) {
    FOVEA_RETURN_IF_ERROR(CheckInterrupt(interrupt));
    int best = -1;
    double best_margin = options_.min_decision;
    for (const int q : Frontier(scene_, object, owner_)) {
      const double margin =
          svm_.Decision(CosJoinFeatures(scene_, object, q, options_));
      if (margin > best_margin) {
        best_margin = margin;
        best = q;
      }
    }
    if (best < 0) break;
    object.push_back(best);
    min_margin = std::min(min_margin, best_margin);
  }
  AbsorbEnclosedSmallPatches(object);
  for (const int p : object) owner_[p] = objects_;
  ++objects_;
  CosObject result;
  result.mask = PatchesMask(scene_, object);
  result.patches = std::move(object);
  result.score =
      std::isinf(min_margin) ? 1.0 : 1.0 / (1.0 + std::exp(-min_margin));
  return result;
}

std::vector<SvmSample> CosTrainingSamples(const CosScene& scene,
                                          const cv::Mat& labels, int group,
                                          const CosOptions& options) {
  const std::vector<int> patch_object = PatchObjectIds(scene, labels);
  const int n = static_cast<int>(patch_object.size());
  const std::vector<int> owner(n, -1);
  std::vector<SvmSample> samples;
  std::vector<int> objects;
  for (int p = 0; p < n; ++p) {
    if (patch_object[p] > 0 && !scene.support[p]) {
      objects.push_back(patch_object[p]);
    }
  }
  std::sort(objects.begin(), objects.end());
  objects.erase(std::unique(objects.begin(), objects.end()), objects.end());
  for (const int k : objects) {
    int start = -1;
    for (int p = 0; p < n; ++p) {
      if (patch_object[p] == k && !scene.support[p] &&
          (start < 0 || scene.patches.patches[p].points >
                            scene.patches.patches[start].points)) {
        start = p;
      }
    }
    std::vector<int> object = {start};
    while (static_cast<int>(object.size()) < options.max_object_patches) {
      int next = -1;
      for (const int q : Frontier(scene, object, owner)) {
        SvmSample sample;
        sample.x = CosJoinFeatures(scene, object, q, options);
        sample.label = patch_object[q] == k ? 1 : -1;
        sample.group = group;
        samples.push_back(std::move(sample));
        if (patch_object[q] == k &&
            (next < 0 || scene.patches.patches[q].points >
                             scene.patches.patches[next].points)) {
          next = q;
        }
      }
      if (next < 0) break;
      object.push_back(next);
    }
  }
  return samples;
}

}  // namespace fovea
