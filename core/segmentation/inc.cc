#include "core/segmentation/inc.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <tuple>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/parallel.h"
#include "core/base/status_macros.h"
#include "core/segmentation/inc_neighbours.h"

namespace fovea {
namespace {

uint64_t PairKey(int a, int b) {
  return (static_cast<uint64_t>(std::min(a, b)) << 32) |
         static_cast<uint32_t>(std::max(a, b));
}

// A pixel of the mask nearest its centroid (a point on the object to
// report as the seed).
// The mask's pixel nearest its centroid (the first in raster order of
// those as near); `box` holds every pixel of the mask.
cv::Point CentralPixel(const cv::Mat& mask, const cv::Rect& box) {
  if (box.empty()) return {0, 0};
  const cv::Moments m = cv::moments(mask(box), true);
  if (m.m00 <= 0) return {0, 0};
  // The box's moments are of u - box.x and v - box.y, integers summed
  // exactly: these are the whole mask's, bit for bit.
  const cv::Point2d c((m.m10 + box.x * m.m00) / m.m00,
                      (m.m01 + box.y * m.m00) / m.m00);
  cv::Point best(0, 0);
  double best_d = 1e30;
  for (int v = box.y; v < box.br().y; ++v) {
    const unsigned char* row = mask.ptr<unsigned char>(v);
    for (int u = box.x; u < box.br().x; ++u) {
      if (row[u] == 0) continue;
      const double d = (u - c.x) * (u - c.x) + (v - c.y) * (v - c.y);
      if (d < best_d) {
        best_d = d;
        best = {u, v};
      }
    }
  }
  return best;
}

}  // namespace

absl::Status Validate(const IncOptions& options) {
  if (absl::Status s = Validate(options.surfaces); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("surfaces.", s.message()));
  }
  if (absl::Status s = Validate(options.relations); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("relations.", s.message()));
  }
  if (!(options.k > 0.0) || !std::isfinite(options.k)) {
    return absl::InvalidArgumentError(
        absl::StrCat("k must be positive, got ", options.k));
  }
  if (options.min_object_points < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_object_points must not be negative, got ",
                     options.min_object_points));
  }
  if (absl::Status s = Validate(options.surface_models); !s.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("surface_models.", s.message()));
  }
  const IncOptions::ConvexJoin& convex = options.convex_join;
  if (!(convex.min_touching >= 0.0 && convex.min_touching <= 1.0) ||
      !(convex.min_convexity >= 0.0 && convex.min_convexity <= 1.0) ||
      !(convex.max_sharp_concave >= 0.0 && convex.max_sharp_concave <= 1.0)) {
    return absl::InvalidArgumentError(
        "convex_join: min_touching, min_convexity and max_sharp_concave must "
        "be in [0, 1]");
  }
  if (!(convex.joined_probability > 0.5 && convex.joined_probability <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("convex_join.joined_probability must be in (0.5, 1], got ",
                     convex.joined_probability));
  }
  if (absl::Status s = Validate(options.body_join.fit); !s.ok()) {
    return s;
  }
  if (options.body_join.gap_px < 0) {
    return absl::InvalidArgumentError("body_join.gap_px must be >= 0");
  }
  const double body = options.body_join.joined_probability;
  if (!(body > 0.5 && body <= 1.0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "body_join.joined_probability must be in (0.5, 1], got ", body));
  }
  const IncOptions::PiecesWithin& piece = options.pieces_within;
  if (!(piece.min_inside >= 0.0 && piece.min_inside <= 1.0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "pieces_within.min_inside must be in [0, 1], got ", piece.min_inside));
  }
  if (!(piece.margin_m >= 0.0) || !(piece.top_m >= 0.0) ||
      !(piece.max_below_m >= 0.0)) {
    return absl::InvalidArgumentError(
        "pieces_within: margin_m, top_m and max_below_m must be >= 0");
  }
  const IncOptions::WholeObject& whole = options.whole_object;
  if (!(whole.rest_band_m >= 0.0) || !(whole.low_band_m >= 0.0) ||
      !(whole.beneath_radius_m > 0.0) || !(whole.beneath_gap_m >= 0.0) ||
      !(whole.min_resting_share >= 0.0 && whole.min_resting_share <= 1.0) ||
      !(whole.min_touching >= 0.0 && whole.min_touching <= 1.0) ||
      !(whole.min_convexity >= 0.0 && whole.min_convexity <= 1.0) ||
      !(whole.max_sharp_concave >= 0.0 && whole.max_sharp_concave <= 1.0) ||
      !(whole.max_compactness_loss_m >= 0.0) ||
      !(whole.min_inside_concavity_m >= 0.0) || !(whole.hidden_drop_m >= 0.0) ||
      !(whole.hidden_margin_m >= 0.0) ||
      !(whole.min_hidden_share >= 0.0 && whole.min_hidden_share <= 1.0)) {
    return absl::InvalidArgumentError(
        "whole_object: rest_band_m, low_band_m, beneath_gap_m, "
        "max_compactness_loss_m, hidden_drop_m, hidden_margin_m and "
        "min_inside_concavity_m must be "
        ">= 0, beneath_radius_m > 0, and min_resting_share, min_touching, "
        "min_convexity, max_sharp_concave and min_hidden_share in [0, 1]");
  }
  const IncOptions::AcrossOccluder& across = options.across_occluder;
  if (!(across.max_angle_deg >= 0.0 && across.max_angle_deg <= 90.0) ||
      !(across.plane_tolerance_m >= 0.0) || !(across.min_in_front_m >= 0.0) ||
      !(across.min_continued >= 0.0 && across.min_continued <= 1.0) ||
      across.max_gap_px < 1 || across.min_lines < 1 ||
      !(across.min_color_similarity >= 0.0 &&
        across.min_color_similarity <= 1.0) ||
      !(across.min_tilt_deg >= 0.0 && across.min_tilt_deg <= 90.0) ||
      !(across.joined_probability > 0.5 && across.joined_probability <= 1.0)) {
    return absl::InvalidArgumentError(
        "across_occluder: max_angle_deg and min_tilt_deg must be in [0, 90], "
        "plane_tolerance_m and min_in_front_m >= 0, max_gap_px and min_lines "
        ">= 1, min_continued and min_color_similarity in [0, 1] and "
        "joined_probability in (0.5, 1]");
  }
  const IncOptions::RestingOnFace& resting = options.resting_on_face;
  if (!(resting.max_tilt_deg >= 0.0 && resting.max_tilt_deg <= 90.0) ||
      !(resting.min_step_m >= 0.0) ||
      !(resting.min_inside >= 0.0 && resting.min_inside <= 1.0) ||
      !(resting.apart_probability >= 0.0 && resting.apart_probability < 0.5)) {
    return absl::InvalidArgumentError(
        "resting_on_face: max_tilt_deg must be in [0, 90], min_step_m >= 0, "
        "min_inside in [0, 1] and apart_probability in [0, 0.5)");
  }
  if (options.max_growth_steps < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "max_growth_steps must be positive, got ", options.max_growth_steps));
  }
  return absl::OkStatus();
}

absl::StatusOr<IncScene> BuildIncScene(const OrganizedCloud& cloud,
                                       const SupportPlane& plane,
                                       const cv::Mat& saliency_map,
                                       const IncOptions& options,
                                       const cv::Mat& region) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (saliency_map.type() != CV_32FC1 ||
      saliency_map.size() != cloud.xyz.size()) {
    return absl::InvalidArgumentError(
        "saliency map must be CV_32FC1 of the cloud's size");
  }
  FOVEA_ASSIGN_OR_RETURN(CosScene surfaces,
                         BuildCosScene(cloud, plane, options.surfaces, region));
  return BuildIncScene(std::move(surfaces), cloud, plane, saliency_map,
                       options);
}

absl::StatusOr<IncScene> BuildIncScene(CosScene surfaces,
                                       const OrganizedCloud& cloud,
                                       const SupportPlane& plane,
                                       const cv::Mat& saliency_map,
                                       const IncOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (saliency_map.type() != CV_32FC1 ||
      saliency_map.size() != cloud.xyz.size() ||
      surfaces.patches.labels.size() != cloud.xyz.size()) {
    return absl::InvalidArgumentError(
        "saliency map and surfaces' labels must be CV_32FC1 and CV_32SC1 of "
        "the cloud's size");
  }
  IncScene scene;
  scene.timings = surfaces.timings;
  StageClock clock(scene.timings);
  scene.surfaces = std::move(surfaces);
  const cv::Mat& labels = scene.surfaces.patches.labels;
  const int n = static_cast<int>(scene.surfaces.patches.patches.size());
  // Relations are only ever asked between object surfaces (the segmenter
  // starts with the support removed, training skips it), so the support's
  // pixels, and with them most of a frame, are left out of them.
  // Everything below looks only at the object surfaces' bounding box.
  cv::Rect box;
  for (int l = 0; l < n; ++l) {
    if (!scene.surfaces.support[l]) box |= scene.surfaces.label_boxes[l];
  }
  cv::Mat object_labels(labels.size(), CV_32SC1, cv::Scalar(-1));
  for (int v = box.y; v < box.br().y; ++v) {
    const int* from = labels.ptr<int>(v);
    int* label = object_labels.ptr<int>(v);
    for (int u = box.x; u < box.br().x; ++u) {
      if (from[u] >= 0 && !scene.surfaces.support[from[u]]) label[u] = from[u];
    }
  }
  scene.relations = std::make_unique<RelationComputer>(
      cloud, object_labels, n, plane.normal, options.relations);
  scene.up = plane.normal;
  scene.support_d = plane.d;
  scene.xyz = cloud.xyz;
  scene.intrinsics = cloud.intrinsics;
  // Eq. 3.6: a surface's saliency is the mean saliency of its points.
  std::vector<double> sum(n, 0.0);
  std::vector<int> count(n, 0);
  for (int v = box.y; v < box.br().y; ++v) {
    const int* label = object_labels.ptr<int>(v);
    const float* s = saliency_map.ptr<float>(v);
    for (int u = box.x; u < box.br().x; ++u) {
      const int l = label[u];
      if (l < 0) continue;
      sum[l] += std::isnan(s[u]) ? 0.0 : s[u];
      ++count[l];
    }
  }
  clock.Lap("relations");
  // The points of every object surface, for the surface models the
  // segmenter fits when it needs them.
  scene.points.assign(n, {});
  if (options.fuse_surfaces) {
    for (int v = box.y; v < box.br().y; ++v) {
      const int* label = object_labels.ptr<int>(v);
      const cv::Vec3f* xyz = cloud.xyz.ptr<cv::Vec3f>(v);
      for (int u = box.x; u < box.br().x; ++u) {
        const int l = label[u];
        if (l < 0 || std::isnan(xyz[u][2])) continue;
        scene.points[l].emplace_back(xyz[u][0], xyz[u][1], xyz[u][2]);
      }
    }
  }
  scene.saliency.assign(n, 0.0);
  scene.pixels = count;
  for (int l = 0; l < n; ++l) {
    if (count[l] > 0) scene.saliency[l] = sum[l] / count[l];
    if (!scene.surfaces.support[l]) scene.object_points += count[l];
  }
  scene.neighbours = scene.surfaces.neighbours;
  AddGapNeighbours(object_labels, box, cloud.intrinsics.fx, options, scene);
  AddOccludedNeighbours(object_labels, box, options, scene);
  clock.Lap("surface_points");
  return scene;
}

IncSegmenter::IncSegmenter(const IncScene& scene, const RbfSvm& svm,
                           const IncOptions& options)
    : scene_(scene),
      svm_(svm),
      options_(options),
      removed_(scene.surfaces.patches.patches.size(), false),
      footprints_(removed_.size()),
      fitted_(removed_.size(), 0),
      models_(removed_.size()) {
  for (size_t s = 0; s < removed_.size(); ++s) {
    if (scene_.surfaces.support[s]) removed_[s] = true;
  }
}

double IncSegmenter::coverage() const {
  return scene_.object_points > 0
             ? static_cast<double>(removed_points_) / scene_.object_points
             : 1.0;
}

double IncSegmenter::SameProbability(int a, int b) {
  const uint64_t key = PairKey(a, b);
  const auto found = probability_.find(key);
  if (found != probability_.end()) return found->second;
  const std::vector<double> relation = scene_.relations->Relate(a, b);
  const IncOptions::ConvexJoin& convex = options_.convex_join;
  const bool convex_join =
      convex.enabled &&
      relation[kBorder3dFractionFeature] >= convex.min_touching &&
      relation[kBorderConvexityFeature] >= convex.min_convexity &&
      relation[kBorderSharpConcaveFeature] <= convex.max_sharp_concave;
  const double svm = svm_.Probability(relation);
  double p = convex_join ? std::max(svm, convex.joined_probability) : svm;
  const IncOptions::BodyJoin& body = options_.body_join;
  if (body.enabled && p < body.joined_probability &&
      OnOneBody(scene_.points[a], scene_.points[b], scene_.up, body.fit)) {
    p = body.joined_probability;
  }
  if (options_.across_occluder.enabled &&
      std::binary_search(scene_.across_occluder.begin(),
                         scene_.across_occluder.end(),
                         std::make_pair(std::min(a, b), std::max(a, b)))) {
    p = std::max(p, options_.across_occluder.joined_probability);
  }
  if (options_.resting_on_face.enabled && p > 0.5 &&
      (RestsOnFace(a, b) || RestsOnFace(b, a))) {
    p = std::min(p, options_.resting_on_face.apart_probability);
  }
  probability_.emplace(key, p);
  return p;
}

void IncSegmenter::DecideFusions(const std::vector<int>& selection) {
  if (!options_.fuse_surfaces) return;
  // Pairs that share a border in the labels image (the relations').
  const std::vector<std::pair<int, int>>& bordering =
      scene_.relations->adjacent_pairs();
  std::vector<int> to_fit;
  std::vector<std::pair<int, int>> to_decide;
  for (const int a : selection) {
    if (!fitted_[a]) to_fit.push_back(a);
    for (const int b : scene_.neighbours[a]) {
      if (a < b && std::binary_search(selection.begin(), selection.end(), b) &&
          fused_.count(PairKey(a, b)) == 0 &&
          std::binary_search(bordering.begin(), bordering.end(),
                             std::make_pair(a, b))) {
        to_decide.emplace_back(a, b);
      }
    }
  }
  // Every item writes only its own slot.
  ParallelFor(static_cast<int>(to_fit.size()), [&](int i) {
    const int l = to_fit[i];
    if (scene_.surfaces.support[l] || scene_.points[l].size() < 3) return;
    absl::StatusOr<SurfaceModel> model =
        FitSurface(scene_.points[l], options_.surface_models);
    if (model.ok()) models_[l] = *std::move(model);  // else: no fusion
  });
  for (const int l : to_fit) fitted_[l] = 1;
  std::vector<char> fuse(to_decide.size(), 0);
  ParallelFor(static_cast<int>(to_decide.size()), [&](int i) {
    const auto [a, b] = to_decide[i];
    if (!models_[a] || !models_[b]) return;
    absl::StatusOr<FusionVerdict> verdict =
        ShouldFuse(scene_.points[a], *models_[a], scene_.points[b], *models_[b],
                   options_.surface_models);
    fuse[i] = verdict.ok() && verdict->fuse &&
              verdict->fused.kind == SurfaceKind::kBSpline;
  });
  for (size_t i = 0; i < to_decide.size(); ++i) {
    fused_[PairKey(to_decide[i].first, to_decide[i].second)] = fuse[i] != 0;
  }
}

std::vector<int> IncSegmenter::GroupOf(const std::vector<int>& selection,
                                       int seed, double* score) {
  // Components by index into `selection`; union by the merge criterion.
  const int n = static_cast<int>(selection.size());
  std::map<int, int> index;
  for (int i = 0; i < n; ++i) index[selection[i]] = i;
  const std::vector<PlanarPatch>& patches = scene_.surfaces.patches.patches;

  std::vector<int> parent(n), members(n, 1), version(n, 0);
  std::vector<double> internal(n, 0.0);
  for (int i = 0; i < n; ++i) parent[i] = i;
  auto find = [&parent](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  // Eq. 3.7: the weight between two groups is the mean of their surface
  // pairs' weights, each weighted by the pair's points; kept as sums.
  struct EdgeSums {
    double weighted = 0.0;
    double weights = 0.0;
    double Weight() const { return weighted / weights; }
  };
  std::vector<std::map<int, EdgeSums>> edges(n);
  DecideFusions(selection);
  for (int i = 0; i < n; ++i) {
    for (const int neighbour : scene_.neighbours[selection[i]]) {
      const auto j = index.find(neighbour);
      if (j == index.end() || j->second <= i) continue;
      const auto fused = fused_.find(PairKey(selection[i], neighbour));
      const double w = fused != fused_.end() && fused->second
                           ? 0.0
                           : 1.0 - SameProbability(selection[i], neighbour);
      const double points =
          patches[selection[i]].points + patches[neighbour].points;
      EdgeSums sums{points * w, points};
      edges[i][j->second] = sums;
      edges[j->second][i] = sums;
    }
  }
  // Edges in increasing weight; an entry is stale once either end's
  // version changed.
  std::set<std::tuple<double, int, int, int, int>> queue;
  for (int i = 0; i < n; ++i) {
    for (const auto& [j, sums] : edges[i]) {
      if (i < j) queue.emplace(sums.Weight(), i, j, 0, 0);
    }
  }
  double merged_p_sum = 0.0;
  int merged = 0;
  while (!queue.empty()) {
    const auto [w, a, b, va, vb] = *queue.begin();
    queue.erase(queue.begin());
    if (find(a) != a || find(b) != b || version[a] != va || version[b] != vb) {
      continue;
    }
    const double threshold = std::min(internal[a] + options_.k / members[a],
                                      internal[b] + options_.k / members[b]);
    if (w > threshold) continue;
    // Merge b into a; its edges join a's, summed where both had one.
    parent[b] = a;
    members[a] += members[b];
    internal[a] = std::max({internal[a], internal[b], w});
    merged_p_sum += 1.0 - w;
    ++merged;
    edges[a].erase(b);
    for (const auto& [c, sums] : edges[b]) {
      if (c == a) continue;
      EdgeSums& ac = edges[a][c];
      ac.weighted += sums.weighted;
      ac.weights += sums.weights;
      edges[c].erase(b);
      edges[c][a] = ac;
    }
    edges[b].clear();
    // The order is kept right after the merge: a's edges re-enter with
    // their new weights.
    ++version[a];
    for (const auto& [c, sums] : edges[a]) {
      queue.emplace(sums.Weight(), std::min(a, c), std::max(a, c),
                    version[std::min(a, c)], version[std::max(a, c)]);
    }
  }
  const int root = find(index.at(seed));
  std::vector<int> group;
  for (int i = 0; i < n; ++i) {
    if (find(i) == root) group.push_back(selection[i]);
  }
  std::sort(group.begin(), group.end());
  if (score != nullptr) *score = merged > 0 ? merged_p_sum / merged : 1.0;
  return group;
}

absl::StatusOr<std::optional<IncObject>> IncSegmenter::Next(
    const InterruptCheck& interrupt) {
  const std::vector<PlanarPatch>& patches = scene_.surfaces.patches.patches;
  while (true) {
    int seed = -1;
    for (size_t s = 0; s < patches.size(); ++s) {
      if (removed_[s]) continue;
      if (seed < 0 || scene_.saliency[s] > scene_.saliency[seed] ||
          (scene_.saliency[s] == scene_.saliency[seed] &&
           patches[s].points > patches[seed].points)) {
        seed = static_cast<int>(s);
      }
    }
    if (seed < 0) {
      // What no later object took is an object after all.
      if (held_.empty()) return std::nullopt;
      IncObject object = std::move(held_.front());
      held_.erase(held_.begin());
      Finish(object);
      return object;
    }

    IncObject object;
    object.seed_surface = seed;
    object.saliency = scene_.saliency[seed];
    std::vector<int> selection = {seed};
    std::vector<int> group = {seed};
    for (int step = 0; step < options_.max_growth_steps; ++step) {
      FOVEA_RETURN_IF_ERROR(CheckInterrupt(interrupt));
      std::set<int> grown(selection.begin(), selection.end());
      for (const int s : selection) {
        for (const int t : scene_.neighbours[s]) {
          if (!removed_[t]) grown.insert(t);
        }
      }
      if (grown.size() == selection.size()) break;  // nothing new around
      selection.assign(grown.begin(), grown.end());
      double score = 1.0;
      std::vector<int> next = GroupOf(selection, seed, &score);
      object.growth_steps = step + 1;
      object.score = score;
      const bool stable = next == group && step > 0;
      group = std::move(next);
      if (stable) break;
    }
    int points = 0;
    for (const int s : group) {
      removed_[s] = true;
      points += scene_.pixels[s];
    }
    if (points >= options_.min_object_points) {
      points += AddPiecesWithin(group);
    }
    object.surfaces = group;
    removed_points_ += points;
    if (points < options_.min_object_points) continue;  // noise: next
    if (options_.whole_object.enabled) {
      TakeHeldNeighbours(object);
      if (!RestsOnSomething(object.surfaces)) {
        held_.push_back(std::move(object));
        continue;
      }
    }
    if (options_.whole_object.enabled) {
      removed_points_ += TakeHangingNeighbours(object);
    }
    Finish(object);
    return object;
  }
}

void IncSegmenter::Finish(IncObject& object) const {
  object.mask = PatchesMask(scene_.surfaces, object.surfaces);
  object.box = PatchesBox(scene_.surfaces, object.surfaces);
  object.seed = CentralPixel(object.mask, object.box);
}

void IncSegmenter::TakeHeldNeighbours(IncObject& object) {
  // A held piece that borders only a piece taken before it is taken too.
  bool took = true;
  while (took) {
    took = false;
    for (auto it = held_.begin(); it != held_.end();) {
      if (!HangsFrom(it->surfaces, object.surfaces)) {
        ++it;
        continue;
      }
      object.surfaces.insert(object.surfaces.end(), it->surfaces.begin(),
                             it->surfaces.end());
      std::sort(object.surfaces.begin(), object.surfaces.end());
      it = held_.erase(it);
      took = true;
    }
  }
}

std::vector<SvmSample> IncTrainingSamples(const IncScene& scene,
                                          const cv::Mat& labels, int group) {
  const std::vector<int> object = PatchObjectIds(scene.surfaces, labels);
  std::vector<SvmSample> samples;
  for (const auto& [a, b] : scene.relations->adjacent_pairs()) {
    if (scene.surfaces.support[a] || scene.surfaces.support[b]) continue;
    if (object[a] == 0 && object[b] == 0) continue;
    SvmSample sample;
    sample.x = scene.relations->Relate(a, b);
    sample.label = object[a] == object[b] ? 1 : -1;
    sample.group = group;
    samples.push_back(std::move(sample));
  }
  return samples;
}

}  // namespace fovea
