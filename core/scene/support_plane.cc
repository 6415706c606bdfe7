// SearchSupport: candidate planes by sequential RANSAC on a grid, their
// connected parts as candidate surfaces, and the choice among them
// (support_score.cc scores them, support_region.cc grows the chosen region).

#include "core/scene/support_plane.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"
#include "core/scene/support_grid.h"

namespace fovea {
namespace {

using support_internal::Candidate;
using support_internal::Grid;
using support_internal::Plane;

constexpr float kDegToRad = static_cast<float>(M_PI / 180.0);
// Hypotheses are first scored on at most this many samples, then the best
// few are re-scored on all samples (preemptive RANSAC, Nister 2003).
constexpr int kQuickScoreSamples = 600;
constexpr int kFullScoreCandidates = 8;
// Two planes closer than this are the same one found twice.
constexpr float kDuplicateAngleDeg = 5.0f;
constexpr float kDuplicateDistance = 0.02f;  // metres
// Least-squares refinements of a RANSAC plane, at most.
constexpr int kMaxRefinements = 6;
// Fewest grid points a plane needs, whatever the fraction.
constexpr int kMinPlanePoints = 30;

void OrientTowardsCamera(Eigen::Vector3f& normal, float& d) {
  support_internal::OrientTowardsCamera(normal, d);
}

// Whether a plane's normal may belong to a support: perpendicular to
// gravity when it is known. Without gravity any plane may: the camera may be
// rolled or upside down (a wrist camera, a ceiling mount), and the side of a
// surface it sees is its top (normals are oriented towards the camera);
// which surfaces are level is decided among the candidates
// (BestLevelNormal).
bool OrientationAllowed(const Eigen::Vector3f& normal,
                        const SupportPlaneOptions& options,
                        const SupportHints& hints) {
  if (!hints.gravity.has_value()) return true;
  const Eigen::Vector3f up = -hints.gravity->normalized();
  return normal.dot(up) >=
         std::cos(options.gravity_tolerance_deg * kDegToRad) - 1e-6f;
}

int CountSupport(const Plane& plane, const Grid& grid,
                 const std::vector<int>& pool, size_t limit,
                 const SupportPlaneOptions& options, float min_cos) {
  int support = 0;
  const size_t n = std::min(limit, pool.size());
  for (size_t k = 0; k < n; ++k) {
    const int i = pool[k];
    if (support_internal::IsInlier(grid, i, plane, options, min_cos)) ++support;
  }
  return support;
}

// The plane of RANSAC's best hypothesis on `pool` (shuffled grid indices
// with normals), or nullopt when no hypothesis of an allowed orientation
// has enough support.
std::optional<Plane> RansacPlane(const Grid& grid, const std::vector<int>& pool,
                                 int min_support,
                                 const SupportPlaneOptions& options,
                                 const SupportHints& hints, float min_cos,
                                 std::mt19937& rng) {
  if (pool.size() < 3) return std::nullopt;
  std::uniform_int_distribution<size_t> pick(0, pool.size() - 1);
  struct Hypothesis {
    Plane plane;
    int support = 0;
  };
  std::vector<Hypothesis> hypotheses;
  hypotheses.reserve(options.ransac_iterations);
  for (int it = 0; it < options.ransac_iterations; ++it) {
    // One point and its (smoothed) normal make a hypothesis: a random
    // point lies on a plane with the plane's share of the points, where
    // three random points all do with its cube, so a few dozen draws find
    // planes of a few percent; the refinement corrects the normal's noise.
    const int i = pool[pick(rng)];
    Eigen::Vector3f normal = grid.n[i];
    const float norm = normal.norm();
    if (!(norm > 1e-9f)) continue;
    normal /= norm;
    float d = -normal.dot(grid.p[i]);
    OrientTowardsCamera(normal, d);
    if (!OrientationAllowed(normal, options, hints)) continue;
    Hypothesis h{{normal, d}, 0};
    h.support =
        CountSupport(h.plane, grid, pool, kQuickScoreSamples, options, min_cos);
    hypotheses.push_back(h);
  }
  if (hypotheses.empty()) return std::nullopt;
  const size_t keep = std::min<size_t>(kFullScoreCandidates, hypotheses.size());
  std::partial_sort(hypotheses.begin(), hypotheses.begin() + keep,
                    hypotheses.end(),
                    [](const Hypothesis& x, const Hypothesis& y) {
                      return x.support > y.support;
                    });
  // No plane can have enough support if the best quick score, scaled to
  // the pool, falls well short (what is left is objects and clutter).
  const size_t quick = std::min<size_t>(kQuickScoreSamples, pool.size());
  if (2.0 * hypotheses[0].support * pool.size() < 1.0 * min_support * quick) {
    return std::nullopt;
  }
  Hypothesis best{{}, -1};
  for (size_t i = 0; i < keep; ++i) {
    Hypothesis h = hypotheses[i];
    h.support =
        CountSupport(h.plane, grid, pool, pool.size(), options, min_cos);
    if (h.support > best.support) best = h;
  }
  if (best.support < min_support) return std::nullopt;
  return best.plane;
}

// Refits `plane` on the pool's inliers until their number stops growing
// (each refit can admit points the coarse plane missed; a RANSAC plane
// tilted by a degree leaves the far part of a table out of its band).
Plane Refine(const Grid& grid, const std::vector<int>& pool, Plane plane,
             const SupportPlaneOptions& options, float min_cos) {
  size_t last = 0;
  for (int round = 0; round < kMaxRefinements; ++round) {
    std::vector<int> inliers;
    for (const int i : pool) {
      if (support_internal::IsInlier(grid, i, plane, options, min_cos)) {
        inliers.push_back(i);
      }
    }
    if (round > 0 && inliers.size() <= last) break;
    last = inliers.size();
    const std::optional<Plane> refit =
        support_internal::FitPlane(grid, inliers);
    if (!refit) break;
    plane = *refit;
  }
  return plane;
}

bool SamePlane(const Plane& a, const Plane& b) {
  return a.normal.dot(b.normal) >= std::cos(kDuplicateAngleDeg * kDegToRad) &&
         std::abs(a.d - b.d) < kDuplicateDistance;
}

// Up to options.max_planes planes of allowed orientation, each found by
// RANSAC on the grid points the earlier ones did not take.
std::vector<Plane> FindPlanes(const Grid& grid,
                              const SupportPlaneOptions& options,
                              const SupportHints& hints, float min_cos) {
  std::vector<int> pool;
  int valid = 0;
  for (int i = 0; i < grid.size(); ++i) {
    if (!grid.HasPoint(i)) continue;
    ++valid;
    if (grid.HasNormal(i)) pool.push_back(i);
  }
  std::mt19937 rng(options.seed);
  std::shuffle(pool.begin(), pool.end(), rng);
  const int min_support = std::max(
      kMinPlanePoints,
      static_cast<int>(std::ceil(options.min_inlier_fraction * valid)));
  std::vector<Plane> planes;
  for (int round = 0; round < options.max_planes; ++round) {
    const std::optional<Plane> found =
        RansacPlane(grid, pool, min_support, options, hints, min_cos, rng);
    if (!found) break;
    const Plane plane = Refine(grid, pool, *found, options, min_cos);
    // Take the points of the RANSAC plane and of its refinement out, so the
    // next round finds another plane.
    std::vector<int> rest;
    rest.reserve(pool.size());
    for (const int i : pool) {
      if (!support_internal::IsInlier(grid, i, *found, options, min_cos) &&
          !support_internal::IsInlier(grid, i, plane, options, min_cos)) {
        rest.push_back(i);
      }
    }
    pool.swap(rest);
    if (!OrientationAllowed(plane.normal, options, hints)) continue;
    bool duplicate = false;
    for (const Plane& q : planes) duplicate = duplicate || SamePlane(q, plane);
    if (!duplicate) planes.push_back(plane);
  }
  return planes;
}

// The normal of the candidate with the best total before its level term
// (which every candidate would get in full as a level surface of its own).
Eigen::Vector3f BestLevelNormal(const std::vector<Candidate>& candidates) {
  float best = -std::numeric_limits<float>::infinity();
  Eigen::Vector3f up = -Eigen::Vector3f::UnitY();
  for (const Candidate& c : candidates) {
    if (c.score.total > best) {
      best = c.score.total;
      up = c.plane.normal;
    }
  }
  return up;
}

absl::Status ValidateUnit(const Eigen::Vector3f& v, std::string_view field) {
  if (!v.allFinite()) {
    return absl::InvalidArgumentError(
        absl::StrCat(AbslView(field), ": must be finite, got (", v.x(), ", ",
                     v.y(), ", ", v.z(), ")"));
  }
  const float norm = v.norm();
  if (!(std::abs(norm - 1.0f) <= 0.01f)) {
    return absl::InvalidArgumentError(absl::StrCat(
        AbslView(field), ": must be a unit vector, got length ", norm));
  }
  return absl::OkStatus();
}

}  // namespace

bool SupportPlane::ProjectsInsideHull(const Eigen::Vector3f& p,
                                      float margin) const {
  if (!p.allFinite()) return false;
  return support_internal::InsideHull(hull, ToPlane(p), margin);
}

absl::Status Validate(const SupportHints& hints) {
  if (hints.gravity.has_value()) {
    FOVEA_RETURN_IF_ERROR(ValidateUnit(*hints.gravity, "gravity"));
  }
  if (hints.plane.has_value()) {
    FOVEA_RETURN_IF_ERROR(
        ValidateUnit(hints.plane->head<3>(), "support_plane.normal"));
    if (!std::isfinite((*hints.plane)[3])) {
      return absl::InvalidArgumentError(absl::StrCat(
          "support_plane.d: must be finite, got ", (*hints.plane)[3]));
    }
  }
  return absl::OkStatus();
}

absl::Status Validate(const SupportPlaneOptions& o) {
  auto invalid = [](std::string_view field, std::string_view rule,
                    double value) {
    return absl::InvalidArgumentError(
        absl::StrCat("support_plane.", AbslView(field), " must be ",
                     AbslView(rule), ", got ", value));
  };
  if (!(o.inlier_distance > 0.0f)) {
    return invalid("inlier_distance", "> 0", o.inlier_distance);
  }
  if (!(o.inlier_sigmas >= 0.0f)) {
    return invalid("inlier_sigmas", ">= 0", o.inlier_sigmas);
  }
  if (!(o.sigma0_m >= 0.0f)) return invalid("sigma0_m", ">= 0", o.sigma0_m);
  if (!(o.sigma_per_z2 >= 0.0f)) {
    return invalid("sigma_per_z2", ">= 0", o.sigma_per_z2);
  }
  if (!(o.max_normal_angle_deg > 0.0f && o.max_normal_angle_deg <= 90.0f)) {
    return invalid("max_normal_angle_deg", "in (0, 90]",
                   o.max_normal_angle_deg);
  }
  if (o.ransac_iterations < 1) {
    return invalid("ransac_iterations", ">= 1", o.ransac_iterations);
  }
  if (o.grid_columns < 16)
    return invalid("grid_columns", ">= 16", o.grid_columns);
  if (o.max_planes < 1) return invalid("max_planes", ">= 1", o.max_planes);
  if (!(o.gravity_tolerance_deg > 0.0f && o.gravity_tolerance_deg <= 90.0f)) {
    return invalid("gravity_tolerance_deg", "in (0, 90]",
                   o.gravity_tolerance_deg);
  }
  if (!(o.max_tilt_from_estimated_up_deg > 0.0f &&
        o.max_tilt_from_estimated_up_deg <= 90.0f)) {
    return invalid("max_tilt_from_estimated_up_deg", "in (0, 90]",
                   o.max_tilt_from_estimated_up_deg);
  }
  if (!(o.min_inlier_fraction >= 0.0f && o.min_inlier_fraction < 1.0f)) {
    return invalid("min_inlier_fraction", "in [0, 1)", o.min_inlier_fraction);
  }
  const std::pair<std::string_view, float> non_negative[] = {
      {"min_candidate_area_m2", o.min_candidate_area_m2},
      {"max_contact_gap", o.max_contact_gap},
      {"min_object_area_m2", o.min_object_area_m2},
      {"object_weight", o.object_weight},
      {"area_weight", o.area_weight},
      {"near_weight", o.near_weight},
      {"view_weight", o.view_weight},
      {"level_weight", o.level_weight},
      {"under_weight", o.under_weight},
      {"under_height", o.under_height},
      {"under_reach", o.under_reach},
      {"max_occlusion_gap", o.max_occlusion_gap},
      {"max_join_color_distance", o.max_join_color_distance},
  };
  for (const auto& [field, value] : non_negative) {
    if (!(value >= 0.0f) || !std::isfinite(value)) {
      return invalid(field, "finite and >= 0", value);
    }
  }
  const std::pair<std::string_view, float> positive[] = {
      {"max_object_height", o.max_object_height},
      {"max_object_size", o.max_object_size},
      {"reference_area_m2", o.reference_area_m2},
      {"near_scale_m", o.near_scale_m},
      {"view_scale_deg", o.view_scale_deg},
  };
  for (const auto& [field, value] : positive) {
    if (!(value > 0.0f) || !std::isfinite(value)) {
      return invalid(field, "finite and > 0", value);
    }
  }
  if (o.max_counted_objects < 0) {
    return invalid("max_counted_objects", ">= 0", o.max_counted_objects);
  }
  return absl::OkStatus();
}

absl::StatusOr<SupportSearch> SearchSupport(const OrganizedCloud& cloud,
                                            const SupportPlaneOptions& options,
                                            const SupportHints& hints) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  FOVEA_RETURN_IF_ERROR(Validate(hints));
  const Grid grid = support_internal::MakeGrid(cloud, options.grid_columns);
  const float min_cos = std::cos(options.max_normal_angle_deg * kDegToRad);

  std::vector<Plane> planes;
  if (hints.plane.has_value()) {
    Plane given{hints.plane->head<3>().normalized(), (*hints.plane)[3]};
    OrientTowardsCamera(given.normal, given.d);
    planes.push_back(given);
  } else {
    planes = FindPlanes(grid, options, hints, min_cos);
  }
  std::vector<Candidate> candidates;
  for (const Plane& plane : planes) {
    std::vector<Candidate> parts = support_internal::SplitIntoSurfaces(
        grid, plane, options, min_cos, /*refit=*/!hints.plane.has_value());
    for (Candidate& c : parts) candidates.push_back(std::move(c));
  }
  if (candidates.empty()) {
    return absl::NotFoundError(
        hints.plane.has_value()
            ? "support plane: the given plane has no surface in view of at "
              "least support_plane.min_candidate_area_m2"
            : absl::StrCat("support plane: no surface of at least ",
                           options.min_candidate_area_m2, " m^2 in view (",
                           planes.size(), " planes found)"));
  }
  support_internal::ScoreCandidates(grid, options, candidates);
  Eigen::Vector3f up;
  if (hints.gravity.has_value()) {
    up = -hints.gravity->normalized();
  } else {
    // Which way is up is what the candidates say: the normal of the one
    // that scores best as a level surface of its own (what stands on it
    // decides, so a wall filling the view does not), and surfaces facing
    // another way than it (walls seen from above) are not supports.
    up = BestLevelNormal(candidates);
    if (!hints.plane.has_value()) {
      const float min_up =
          std::cos(options.max_tilt_from_estimated_up_deg * kDegToRad);
      candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                      [&](const Candidate& c) {
                                        return c.plane.normal.dot(up) < min_up;
                                      }),
                       candidates.end());
    }
  }
  support_internal::AddLevelTerm(up, options, candidates);
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) {
                     return a.score.total > b.score.total;
                   });

  SupportSearch search;
  for (const Candidate& c : candidates) {
    search.candidates.push_back({c.plane.normal, c.plane.d, c.centroid, c.score,
                                 static_cast<int>(c.indices.size())});
  }
  FOVEA_ASSIGN_OR_RETURN(SupportPlane chosen,
                         support_internal::MakeSupportRegion(
                             cloud, grid, candidates[0], options, min_cos));
  search.chosen = std::move(chosen);
  search.chosen.candidate_count = static_cast<int>(candidates.size());
  search.chosen.score = candidates[0].score;
  search.chosen.given = hints.plane.has_value();
  return search;
}

absl::StatusOr<SupportPlane> FindSupportPlane(
    const OrganizedCloud& cloud, const SupportPlaneOptions& options,
    const SupportHints& hints) {
  FOVEA_ASSIGN_OR_RETURN(SupportSearch search,
                         SearchSupport(cloud, options, hints));
  return std::move(search.chosen);
}

absl::StatusOr<SupportPlane> SupportPlaneFromInliers(
    const OrganizedCloud& cloud, const Eigen::Vector3f& normal, float d,
    const cv::Mat& inliers) {
  const float norm = normal.norm();
  if (!(norm > 0.0f) || !std::isfinite(norm) || !std::isfinite(d)) {
    return absl::InvalidArgumentError(
        "support plane: the normal must be finite and non-zero");
  }
  if (inliers.type() != CV_8UC1 || inliers.rows != cloud.height() ||
      inliers.cols != cloud.width()) {
    return absl::InvalidArgumentError(
        "support plane: inliers must be CV_8UC1 of the cloud's size");
  }
  SupportPlane plane;
  plane.normal = normal / norm;
  plane.d = d / norm;
  OrientTowardsCamera(plane.normal, plane.d);
  plane.inliers = inliers;
  plane.inlier_count = cv::countNonZero(inliers);
  support_internal::SetAxes(plane);
  plane.hull = support_internal::HullOfMask(cloud, plane.inliers, plane);
  if (plane.hull.size() < 3) {
    return absl::NotFoundError("support plane: inliers have no 2D extent");
  }
  return plane;
}

}  // namespace fovea
