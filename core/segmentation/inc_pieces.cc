// INC's pieces within an object's footprint (IncOptions::PiecesWithin): when
// an object is final, the surfaces still in the scene that no border joins
// to it, that lie within its footprint seen along the support's normal and
// reach its top, join it. An object on one upright cylinder or cone, or on
// one sphere, has its body's widest cross-section in its footprint too, and
// a surface bordering such a body and nothing else joins it.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "core/segmentation/inc.h"
#include "core/segmentation/patch_features.h"

namespace fovea {
namespace {

// Footprints are taken from an even sample of at most about this many
// points: an object's (whose convex hull is taken at every object) and a
// surface's (once per scene).
constexpr size_t kObjectFootprintPoints = 2048;
constexpr size_t kSurfaceFootprintPoints = 512;
// An object's body is taken when the object spans at least this share of
// its diameter on the support's plane.
constexpr float kSeenAcross = 0.75f;

// The support's plane's axes, the footprints' coordinates: (x, y) on it,
// and up along its unit normal.
struct PlaneAxes {
  explicit PlaneAxes(const Eigen::Vector3f& normal)
      : up(normal.normalized()), x(up.unitOrthogonal()), y(up.cross(x)) {}
  cv::Point2f Flat(const Eigen::Vector3f& p) const {
    return {x.dot(p), y.dot(p)};
  }
  Eigen::Vector3f up, x, y;
};

// Every stride-th point of each of `surfaces` (of `points`, per surface),
// the stride such that at most about `max_points` are kept: an even
// sample.
using SurfacePoints = std::vector<std::vector<Eigen::Vector3f>>;

// The stride of that sample and the surfaces' points in all.
size_t EvenStride(const SurfacePoints& points, const std::vector<int>& surfaces,
                  size_t max_points, size_t* total_points = nullptr) {
  size_t total = 0;
  for (const int s : surfaces) total += points[s].size();
  if (total_points != nullptr) *total_points = total;
  return std::max<size_t>(1, (total + max_points - 1) / max_points);
}

std::vector<Eigen::Vector3f> EvenSample(const SurfacePoints& points,
                                        const std::vector<int>& surfaces,
                                        size_t max_points) {
  size_t total = 0;
  const size_t stride = EvenStride(points, surfaces, max_points, &total);
  std::vector<Eigen::Vector3f> sample;
  sample.reserve(total / stride + surfaces.size());
  for (const int s : surfaces) {
    for (size_t i = 0; i < points[s].size(); i += stride) {
      sample.push_back(points[s][i]);
    }
  }
  return sample;
}

// IncSegmenter::flat_grid_'s cells: a coordinate's cell of `size`, and a
// cell's key.
int64_t FlatCell(float v, float size) {
  return static_cast<int64_t>(std::floor(v / size));
}
uint64_t FlatCellKey(int64_t x, int64_t y) {
  return (static_cast<uint64_t>(x) << 32) ^ static_cast<uint32_t>(y);
}

// A disc on the support's plane (PlaneAxes::Flat), metres.
struct Disc {
  cv::Point2f center;
  float radius = 0.0f;
};

// The median of `off` over `points`.
template <typename Off>
float MedianOff(const std::vector<Eigen::Vector3f>& points, const Off& off) {
  std::vector<float> distances;
  distances.reserve(points.size());
  for (const Eigen::Vector3f& p : points) distances.push_back(off(p));
  const auto median =
      distances.begin() + static_cast<ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), median, distances.end());
  return *median;
}

// The widest cross-section, on the support's plane (PlaneAxes::Flat), of
// the upright cylinder or cone, or else the sphere (a bowl, a ball), that
// the points of `surfaces` lie on, between the heights `bottom` and `top`
// (IncOptions::PiecesWithin::body_footprint); `hull` is their convex hull
// on the plane. nullopt: no body holds them.
std::optional<Disc> BodyDisc(const IncScene& scene, const BodyFitOptions& fit,
                             const std::vector<int>& surfaces, float bottom,
                             float top, const std::vector<cv::Point2f>& hull) {
  const std::vector<Eigen::Vector3f> sample =
      EvenSample(scene.points, surfaces, kObjectFootprintPoints);
  if (static_cast<int>(sample.size()) < fit.min_points) return std::nullopt;
  float z = 0.0f;
  for (const Eigen::Vector3f& p : sample) z += p.z();
  z /= static_cast<float>(sample.size());
  // Within the sensor's noise and half a wall of the body, by the median
  // distance (a handle or a rim's lip is off it), of the radii allowed,
  // and seen across most of its width, as the front of a can or the inside
  // of a pot or a bowl is: a flat face is on a wide enough cylinder, a
  // box's corner near a cone, and a body fitted to a narrow strip is a
  // guess.
  const float allowed =
      std::hypot(fit.wall_m, fit.sigma0_m + fit.sigma_per_z2 * z * z);
  float width = 0.0f;
  for (size_t i = 0; i < hull.size(); ++i) {
    for (size_t k = i + 1; k < hull.size(); ++k) {
      const cv::Point2f d = hull[i] - hull[k];
      width = std::max(width, d.dot(d));
    }
  }
  width = std::sqrt(width);
  const auto holds = [&](float median, float widest) {
    return median <= allowed && widest >= fit.min_radius_m &&
           widest <= fit.max_radius_m && width >= kSeenAcross * 2.0f * widest;
  };
  const PlaneAxes axes(scene.up);
  const std::optional<BodyFit> upright =
      fit.max_taper > 0.0f ? FitUprightCone(sample, axes.up)
                           : FitUprightCylinder(sample, axes.up);
  if (upright.has_value() && std::abs(upright->taper) <= fit.max_taper) {
    const BodyFit& body = *upright;
    // The radius at a height along up above the body's centre.
    const auto radius_at = [&body](float height) {
      return body.radius + body.taper * height;
    };
    const float median = MedianOff(sample, [&](const Eigen::Vector3f& p) {
      const Eigen::Vector3f d = p - body.center;
      const float height = axes.up.dot(d);
      return std::abs((d - axes.up * height).norm() - radius_at(height));
    });
    const float center = axes.up.dot(body.center);
    const float widest =
        std::max(radius_at(bottom - center), radius_at(top - center));
    if (holds(median, widest)) return Disc{axes.Flat(body.center), widest};
  }
  const std::optional<BodyFit> sphere = FitSphere(sample);
  if (sphere.has_value()) {
    const BodyFit& body = *sphere;
    const float median = MedianOff(sample, [&](const Eigen::Vector3f& p) {
      return std::abs((p - body.center).norm() - body.radius);
    });
    // Its widest cross-section between bottom and top: the equator's,
    // or the one at the end nearer it.
    const float center = axes.up.dot(body.center);
    const float off_equator = center < bottom
                                  ? bottom - center
                                  : (center > top ? center - top : 0.0f);
    const float widest = std::sqrt(
        std::max(0.0f, body.radius * body.radius - off_equator * off_equator));
    if (holds(median, widest)) return Disc{axes.Flat(body.center), widest};
  }
  return std::nullopt;
}

}  // namespace

IncSegmenter::Footprint IncSegmenter::FootprintOf(
    const std::vector<int>& surfaces, size_t max_points) const {
  const PlaneAxes axes(scene_.up);
  Footprint f;
  for (const Eigen::Vector3f& p :
       EvenSample(scene_.points, surfaces, max_points)) {
    f.flat.push_back(axes.Flat(p));
    f.heights.push_back(axes.up.dot(p));
  }
  if (f.flat.empty()) return f;
  std::vector<float> heights = f.heights;
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

const IncSegmenter::Footprint& IncSegmenter::SurfaceFootprint(int surface) {
  if (!footprints_[surface]) {
    footprints_[surface] = FootprintOf({surface}, kSurfaceFootprintPoints);
  }
  return *footprints_[surface];
}

bool IncSegmenter::RestsOnFace(int piece, int face) {
  const IncOptions::RestingOnFace& options = options_.resting_on_face;
  const std::vector<PlanarPatch>& patches = scene_.surfaces.patches.patches;
  const float level = static_cast<float>(
      std::cos(options.max_tilt_deg * std::numbers::pi / 180.0));
  if (std::abs(patches[piece].normal.dot(scene_.up)) < level ||
      std::abs(patches[face].normal.dot(scene_.up)) < level ||
      patches[piece].points >= patches[face].points) {
    return false;
  }
  const Footprint& upper = SurfaceFootprint(piece);
  const Footprint& lower = SurfaceFootprint(face);
  if (upper.flat.empty() || lower.flat.size() < 3) return false;
  const auto median = [](std::vector<float> heights) {
    const auto mid =
        heights.begin() + static_cast<ptrdiff_t>(heights.size() / 2);
    std::nth_element(heights.begin(), mid, heights.end());
    return *mid;
  };
  if (median(upper.heights) - median(lower.heights) < options.min_step_m) {
    return false;
  }
  std::vector<cv::Point2f> hull;
  cv::convexHull(lower.flat, hull);
  int inside = 0;
  for (const cv::Point2f& p : upper.flat) {
    inside += cv::pointPolygonTest(hull, p, false) >= 0 ? 1 : 0;
  }
  return inside >= options.min_inside * static_cast<double>(upper.flat.size());
}

int IncSegmenter::AddPiecesWithin(std::vector<int>& group) {
  const IncOptions::PiecesWithin& options = options_.pieces_within;
  if (!options.enabled) return 0;
  const Footprint object = FootprintOf(group, kObjectFootprintPoints);
  if (object.flat.size() < 3) return 0;  // no points kept: nothing to tell
  std::vector<cv::Point2f> hull;
  cv::convexHull(object.flat, hull);
  const float margin = static_cast<float>(options.margin_m);
  // The footprint's box and the body's disc grown by the margin (reach 0:
  // no body), fitted only once a surface needs them: most objects have no
  // piece of the right height.
  struct Extent {
    cv::Rect2f grown;
    cv::Point2f center;
    float reach = 0.0f;
  };
  std::optional<Extent> extent;
  const auto extent_of_object = [&]() -> const Extent& {
    if (extent) return *extent;
    extent.emplace();
    extent->grown = cv::Rect2f(object.box.x - margin, object.box.y - margin,
                               object.box.width + 2 * margin,
                               object.box.height + 2 * margin);
    const std::optional<Disc> disc =
        options.body_footprint ? BodyDisc(scene_, options_.body_join.fit, group,
                                          object.bottom, object.top, hull)
                               : std::nullopt;
    if (disc) {
      extent->center = disc->center;
      extent->reach = disc->radius + margin;
      const float r = extent->reach;
      extent->grown |=
          cv::Rect2f(disc->center.x - r, disc->center.y - r, 2 * r, 2 * r);
    }
    return *extent;
  };
  const auto inside = [&](const Extent& e, const cv::Point2f& p) {
    if (p.x < e.grown.x || p.x > e.grown.x + e.grown.width || p.y < e.grown.y ||
        p.y > e.grown.y + e.grown.height) {
      return false;
    }
    const cv::Point2f d = p - e.center;
    if (e.reach > 0.0f && d.dot(d) <= e.reach * e.reach) return true;
    return cv::pointPolygonTest(hull, p, true) >= -margin;
  };
  const auto borders_object = [&](size_t s) {
    return std::any_of(
        scene_.neighbours[s].begin(), scene_.neighbours[s].end(), [&](int t) {
          return std::binary_search(group.begin(), group.end(), t);
        });
  };
  const auto borders_others = [&](size_t s) {
    return std::any_of(scene_.neighbours[s].begin(), scene_.neighbours[s].end(),
                       [&](int t) { return !removed_[t]; });
  };
  std::vector<int> joined;
  int pixels = 0;
  for (size_t s = 0; s < removed_.size(); ++s) {
    if (removed_[s] || scene_.points[s].empty()) continue;
    // Where a border joins them the grouping has decided already; but a
    // surface that borders a body and nothing else still in the scene (a
    // sliver of a bowl's rim) would be an object of its own.
    const bool bordering = borders_object(s);
    if (bordering && borders_others(s)) continue;
    const Footprint& piece = SurfaceFootprint(static_cast<int>(s));
    if (std::abs(piece.top - object.top) > options.top_m ||
        piece.bottom < object.bottom - options.max_below_m) {
      continue;
    }
    const Extent& e = extent_of_object();
    if ((bordering && e.reach <= 0.0f) ||
        (e.grown & piece.box).area() <= 0.0f) {
      continue;
    }
    const int needed = static_cast<int>(
        std::ceil(options.min_inside * static_cast<double>(piece.flat.size())));
    int within = 0;
    int left = static_cast<int>(piece.flat.size());
    for (const cv::Point2f& p : piece.flat) {
      if (inside(e, p)) ++within;
      --left;
      if (within >= needed || within + left < needed) break;
    }
    if (within >= needed) {
      joined.push_back(static_cast<int>(s));
      removed_[s] = true;
      pixels += scene_.pixels[s];
    }
  }
  group.insert(group.end(), joined.begin(), joined.end());
  std::sort(group.begin(), group.end());
  return pixels;
}

void IncSegmenter::BuildFlatGrid() {
  const PlaneAxes axes(scene_.up);
  const float cell = static_cast<float>(options_.whole_object.beneath_radius_m);
  std::vector<int> all;
  for (size_t s = 0; s < scene_.points.size(); ++s) {
    if (!scene_.surfaces.support[s]) all.push_back(static_cast<int>(s));
  }
  const size_t stride =
      EvenStride(scene_.points, all, 4 * kObjectFootprintPoints);
  constexpr float kCos30 = 0.866f;
  for (const int s : all) {
    const bool horizontal =
        std::abs(scene_.surfaces.patches.patches[s].normal.dot(axes.up)) >=
        kCos30;
    const std::vector<Eigen::Vector3f>& points = scene_.points[s];
    for (size_t i = 0; i < points.size(); i += stride) {
      const cv::Point2f f = axes.Flat(points[i]);
      flat_grid_[FlatCellKey(FlatCell(f.x, cell), FlatCell(f.y, cell))]
          .push_back({f.x, f.y, axes.up.dot(points[i]) + scene_.support_d, s,
                      horizontal});
    }
  }
  flat_grid_built_ = true;
}

bool IncSegmenter::RestsOnSomething(const std::vector<int>& group) {
  const IncOptions::WholeObject& options = options_.whole_object;
  const Footprint footprint = FootprintOf(group, kObjectFootprintPoints);
  if (footprint.flat.empty()) return true;  // nothing to tell: as it was
  const float bottom = footprint.bottom + scene_.support_d;
  if (bottom <= options.rest_band_m) return true;  // on the support
  if (!flat_grid_built_) BuildFlatGrid();
  const float cell = static_cast<float>(options.beneath_radius_m);
  const float low = bottom + static_cast<float>(options.low_band_m);
  const float r2 = cell * cell;
  const float gap = static_cast<float>(options.beneath_gap_m);
  constexpr float kAbove = 0.005f;  // a support's top a little above: noise
  int lows = 0;
  int resting = 0;
  for (size_t i = 0; i < footprint.flat.size(); ++i) {
    const float height = footprint.heights[i] + scene_.support_d;
    if (height > low) continue;
    ++lows;
    const cv::Point2f& f = footprint.flat[i];
    const int64_t cx = FlatCell(f.x, cell);
    const int64_t cy = FlatCell(f.y, cell);
    bool beneath = false;
    for (int64_t dx = -1; dx <= 1 && !beneath; ++dx) {
      for (int64_t dy = -1; dy <= 1 && !beneath; ++dy) {
        const auto found = flat_grid_.find(FlatCellKey(cx + dx, cy + dy));
        if (found == flat_grid_.end()) continue;
        for (const FlatPoint& q : found->second) {
          if (!q.horizontal ||
              std::binary_search(group.begin(), group.end(), q.surface)) {
            continue;
          }
          const float ddx = q.x - f.x;
          const float ddy = q.y - f.y;
          if (ddx * ddx + ddy * ddy <= r2 && q.height <= height + kAbove &&
              q.height >= height - gap) {
            beneath = true;
            break;
          }
        }
      }
    }
    if (beneath) ++resting;
  }
  return lows == 0 ||
         resting >= options.min_resting_share * static_cast<double>(lows);
}

bool IncSegmenter::HangsFrom(const std::vector<int>& piece,
                             const std::vector<int>& object) {
  if (!TouchesIn3d(piece, object)) return false;
  // The union as good an object as its parts (eq. 3.3-3.4): neither
  // part's points lie farther from the union's camera-facing hull than
  // from their own. A cylinder standing flush on a box's front face
  // continues it as a wall cut across would, but the box's top beside it
  // lies below the union's hull; a can beside a bowl lies below the hull
  // spanning it and the bowl's rim.
  constexpr size_t kHullPoints = 600;
  const std::vector<Eigen::Vector3f> a =
      EvenSample(scene_.surfaces.samples, piece, kHullPoints);
  const std::vector<Eigen::Vector3f> b =
      EvenSample(scene_.surfaces.samples, object, kHullPoints);
  if (a.empty() || b.empty()) return false;  // nothing to tell: apart
  const float own = CameraFacingHullDistance(a);
  std::vector<Eigen::Vector3f> both = a;
  both.insert(both.end(), b.begin(), b.end());
  // Each part's mean distance to the union's hull against its own hull
  // (the thesis takes each side's mean apart too, CosJoinFeatures).
  const std::vector<float> distances = CameraFacingHullDistances(both);
  double piece_sum = 0.0;
  double object_sum = 0.0;
  for (size_t i = 0; i < distances.size(); ++i) {
    (i < a.size() ? piece_sum : object_sum) += distances[i];
  }
  const double loss = options_.whole_object.max_compactness_loss_m;
  if (piece_sum / static_cast<double>(a.size()) > own + loss ||
      object_sum / static_cast<double>(b.size()) >
          CameraFacingHullDistance(b) + loss) {
    return false;
  }
  // A foot hidden behind another object may stand on what is hidden (a cup
  // in an open box, a can in a bowl), unless the piece is a vessel's inside
  // (concave: far from its own hull), whose foot its front wall hides.
  return own >= options_.whole_object.min_inside_concavity_m ||
         !FootHidden(FootprintOf(piece, kObjectFootprintPoints), piece);
}

bool IncSegmenter::FootHidden(const Footprint& footprint,
                              const std::vector<int>& group) const {
  const IncOptions::WholeObject& options = options_.whole_object;
  if (scene_.xyz.empty()) return false;
  const PlaneAxes axes(scene_.up);
  const Intrinsics& k = scene_.intrinsics;
  const float drop = static_cast<float>(options.hidden_drop_m);
  const float margin = static_cast<float>(options.hidden_margin_m);
  const cv::Mat& labels = scene_.surfaces.patches.labels;
  // Of the points whose drop the camera would see off the piece (its lower
  // outline), those where another object's surface is nearer.
  int outline = 0;
  int hidden = 0;
  for (size_t i = 0; i < footprint.flat.size(); ++i) {
    const cv::Point2f& f = footprint.flat[i];
    const Eigen::Vector3f q =
        axes.x * f.x + axes.y * f.y + axes.up * (footprint.heights[i] - drop);
    if (!(q.z() > 0.0f)) continue;
    const int u = static_cast<int>(std::lround(k.fx * q.x() / q.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * q.y() / q.z() + k.cy));
    if (u < 0 || v < 0 || u >= labels.cols || v >= labels.rows) continue;
    const int l = labels.at<int>(v, u);
    if (l >= 0 && std::binary_search(group.begin(), group.end(), l)) {
      continue;  // the piece's own
    }
    ++outline;
    const float seen = scene_.xyz.at<cv::Vec3f>(v, u)[2];
    if (l >= 0 && !scene_.surfaces.support[l] && !std::isnan(seen) &&
        seen < q.z() - margin) {
      ++hidden;
    }
  }
  return outline > 0 &&
         hidden >= options.min_hidden_share * static_cast<double>(outline);
}

bool IncSegmenter::TouchesIn3d(const std::vector<int>& piece,
                               const std::vector<int>& object) {
  const IncOptions::WholeObject& whole = options_.whole_object;
  const std::vector<std::pair<int, int>>& bordering =
      scene_.relations->adjacent_pairs();
  bool touching = false;
  for (const int p : piece) {
    for (const int o : scene_.neighbours[p]) {
      if (!std::binary_search(object.begin(), object.end(), o)) continue;
      if (std::binary_search(bordering.begin(), bordering.end(),
                             std::make_pair(std::min(p, o), std::max(p, o)))) {
        const std::vector<double> relation = scene_.relations->Relate(p, o);
        // A sharply concave fold anywhere along the contact: two objects
        // meet there.
        if (relation[kBorderSharpConcaveFeature] > whole.max_sharp_concave) {
          return false;
        }
        // Depth continuous along the border, and the surfaces continue
        // each other there or fold away (a wall cut across, a handle's
        // root), as one object's parts do.
        touching = touching ||
                   (relation[kBorder3dFractionFeature] >= whole.min_touching &&
                    relation[kBorderConvexityFeature] >= whole.min_convexity);
      } else if (!touching && options_.body_join.enabled) {
        touching = OnOneBody(scene_.points[p], scene_.points[o], scene_.up,
                             options_.body_join.fit);  // across a gap
      }
    }
  }
  return touching;
}

std::vector<int> IncSegmenter::GroupAround(int s) {
  std::set<int> near = {s};
  for (int step = 0; step < 2; ++step) {
    const std::vector<int> ring(near.begin(), near.end());
    for (const int r : ring) {
      for (const int t : scene_.neighbours[r]) {
        if (!removed_[t]) near.insert(t);
      }
    }
  }
  return GroupOf(std::vector<int>(near.begin(), near.end()), s, nullptr);
}

int IncSegmenter::TakeHangingNeighbours(IncObject& object) {
  int pixels = 0;
  std::vector<int> around;
  for (const int s : object.surfaces) {
    for (const int t : scene_.neighbours[s]) {
      if (!removed_[t]) around.push_back(t);
    }
  }
  std::sort(around.begin(), around.end());
  around.erase(std::unique(around.begin(), around.end()), around.end());
  for (const int s : around) {
    if (removed_[s]) continue;  // taken with an earlier one
    const std::vector<int> piece = GroupAround(s);
    if (RestsOnSomething(piece) || !HangsFrom(piece, object.surfaces)) {
      continue;
    }
    for (const int t : piece) {
      removed_[t] = true;
      pixels += scene_.pixels[t];
    }
    object.surfaces.insert(object.surfaces.end(), piece.begin(), piece.end());
    std::sort(object.surfaces.begin(), object.surfaces.end());
  }
  return pixels;
}

}  // namespace fovea
