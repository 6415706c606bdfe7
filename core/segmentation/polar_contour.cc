#include "core/segmentation/polar_contour.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <new>
#include <opencv2/imgproc.hpp>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kMinAngles = 8;
constexpr int kMaxAngles = 4096;
constexpr float kMaxRadiusPx = 4096.0f;
// Fractional bits of the polygon's vertices (cv::fillPoly's shift).
constexpr int kPolygonShift = 4;

// The polar grid: angle a (row) and radius index j (column), radius
// min_radius + j * step.
struct PolarGrid {
  int angles = 0;
  int radii = 0;
  float min_radius = 0.0f;
  float step = 0.0f;
  float dtheta = 0.0f;
  float Radius(int j) const { return min_radius + j * step; }
};

// Cost of each grid sample, CV_32FC1 angles x radii.
cv::Mat SampleCosts(const cv::Mat& p, cv::Point seed, const PolarGrid& grid,
                    const PolarContourOptions& options) {
  cv::Mat map_u(grid.angles, grid.radii, CV_32FC1);
  cv::Mat map_v(grid.angles, grid.radii, CV_32FC1);
  for (int a = 0; a < grid.angles; ++a) {
    const float c = std::cos(a * grid.dtheta), s = std::sin(a * grid.dtheta);
    float* mu = map_u.ptr<float>(a);
    float* mv = map_v.ptr<float>(a);
    for (int j = 0; j < grid.radii; ++j) {
      mu[j] = seed.x + grid.Radius(j) * c;
      mv[j] = seed.y + grid.Radius(j) * s;
    }
  }
  cv::Mat samples;
  cv::remap(p, samples, map_u, map_v, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(options.outside_probability));
  const float floor_p = options.min_probability;
  for (int a = 0; a < grid.angles; ++a) {
    float* row = samples.ptr<float>(a);
    for (int j = 0; j < grid.radii; ++j) {
      // NaN (no data) and out-of-range values read as clamped edges.
      const float q =
          std::isnan(row[j]) ? 1.0f : std::clamp(row[j], 0.0f, 1.0f);
      row[j] = options.cost == PolarCost::kNegLogP
                   ? -std::log(std::max(q, floor_p))
                   : 1.0f - q;
    }
  }
  return samples;
}

// Largest radius change, in steps, of a step ending at radius index j.
std::vector<int> MaxJumps(const PolarGrid& grid,
                          const PolarContourOptions& options) {
  std::vector<int> jumps(grid.radii);
  for (int j = 0; j < grid.radii; ++j) {
    const float px = options.max_slope * grid.Radius(j) * grid.dtheta;
    jumps[j] = std::clamp(static_cast<int>(px / grid.step), 1,
                          std::max(1, grid.radii - 1));
  }
  return jumps;
}

// Length factor of a step from radius index j + d to j: its length in
// log-polar coordinates over dtheta; 1 for d = 0. Row j, column d + max.
cv::Mat LengthFactors(const PolarGrid& grid, const std::vector<int>& jumps,
                      const PolarContourOptions& options) {
  const int max_jump = *std::max_element(jumps.begin(), jumps.end());
  cv::Mat factors(grid.radii, 2 * max_jump + 1, CV_32FC1, cv::Scalar(1.0f));
  if (!options.log_polar_length) return factors;
  for (int j = 0; j < grid.radii; ++j) {
    float* row = factors.ptr<float>(j) + max_jump;
    for (int d = -jumps[j]; d <= jumps[j]; ++d) {
      const int k = std::clamp(j + d, 0, grid.radii - 1);
      const float mean_r = 0.5f * (grid.Radius(j) + grid.Radius(k));
      const float rel = (k - j) * grid.step / (mean_r * grid.dtheta);
      row[d] = std::sqrt(1.0f + rel * rel);
    }
  }
  return factors;
}

// One dynamic-programming pass over `steps` angle steps starting at angle
// `first` with the start costs `start` (inf: not a start). Fills `from`
// (steps x radii, the predecessor's radius index of each node) and returns
// the costs at the last angle.
absl::StatusOr<std::vector<float>> RunPass(
    const cv::Mat& costs, const PolarGrid& grid, const std::vector<int>& jumps,
    const cv::Mat& factors, int first, int steps, std::vector<float> start,
    std::vector<int16_t>& from, const PolarContourOptions& options,
    const InterruptCheck& interrupt) {
  const int n = grid.radii;
  const int max_jump = (factors.cols - 1) / 2;
  std::vector<float> prev = std::move(start), next(n);
  from.assign(static_cast<size_t>(steps) * n, 0);
  for (int s = 0; s < steps; ++s) {
    if (s % options.interrupt_every_angles == 0) {
      FOVEA_RETURN_IF_ERROR(CheckInterrupt(interrupt));
    }
    const float* cost = costs.ptr<float>((first + s + 1) % grid.angles);
    int16_t* back = from.data() + static_cast<size_t>(s) * n;
    for (int j = 0; j < n; ++j) {
      const float* f = factors.ptr<float>(j) + max_jump;
      const int lo = std::max(0, j - jumps[j]);
      const int hi = std::min(n - 1, j + jumps[j]);
      float best = kInf;
      int best_k = j;
      for (int k = lo; k <= hi; ++k) {
        const float c = prev[k] + cost[j] * f[k - j];
        if (c < best) {
          best = c;
          best_k = k;
        }
      }
      next[j] = best;
      back[j] = static_cast<int16_t>(best_k);
    }
    std::swap(prev, next);
  }
  return prev;
}

// Radius indices of the path ending at radius index `end` after `steps`
// steps: entry s is the node at step s (entry 0 the start).
std::vector<int> Backtrack(const std::vector<int16_t>& from, int n, int steps,
                           int end) {
  std::vector<int> path(steps + 1);
  path[steps] = end;
  for (int s = steps; s > 0; --s) {
    path[s - 1] = from[static_cast<size_t>(s - 1) * n + path[s]];
  }
  return path;
}

// FindPolarContour on checked arguments: both passes and the result.
absl::StatusOr<PolarContour> SolveClosedContour(
    const cv::Mat& edge_probability, cv::Point seed,
    const PolarContourOptions& options, const InterruptCheck& interrupt) {
  PolarGrid grid;
  grid.angles = options.angles;
  grid.min_radius = options.min_radius_px;
  grid.step = options.radial_step_px;
  grid.radii =
      1 + static_cast<int>((options.max_radius_px - options.min_radius_px) /
                           options.radial_step_px);
  grid.dtheta = static_cast<float>(2.0 * M_PI / options.angles);
  FOVEA_CHECK(grid.radii >= 1 && grid.radii <= 32767);
  FOVEA_RETURN_IF_ERROR(CheckInterrupt(interrupt));
  const cv::Mat costs = SampleCosts(edge_probability, seed, grid, options);
  const std::vector<int> jumps = MaxJumps(grid, options);
  const cv::Mat factors = LengthFactors(grid, jumps, options);
  const int n = grid.radii, a_count = grid.angles;

  // Pass 1: open contour from angle 0 (any radius) to angle a_count - 1.
  std::vector<int16_t> from;
  const float* first_costs = costs.ptr<float>(0);
  absl::StatusOr<std::vector<float>> end =
      RunPass(costs, grid, jumps, factors, 0, a_count - 1,
              std::vector<float>(first_costs, first_costs + n), from, options,
              interrupt);
  if (!end.ok()) return end.status();
  const int open_end = static_cast<int>(
      std::min_element(end->begin(), end->end()) - end->begin());
  const std::vector<int> open = Backtrack(from, n, a_count - 1, open_end);
  // Pass 2: closed, through the open contour's node opposite angle 0.
  const int anchor_angle = a_count / 2;
  const int anchor = open[anchor_angle];
  std::vector<float> start(n, kInf);
  start[anchor] = 0.0f;
  end = RunPass(costs, grid, jumps, factors, anchor_angle, a_count,
                std::move(start), from, options, interrupt);
  if (!end.ok()) return end.status();
  const std::vector<int> closed = Backtrack(from, n, a_count, anchor);

  PolarContour contour;
  contour.seed = seed;
  contour.cost = (*end)[anchor];
  contour.radii.resize(a_count);
  for (int s = 0; s < a_count; ++s) {
    contour.radii[(anchor_angle + s) % a_count] = grid.Radius(closed[s]);
  }
  return contour;
}

}  // namespace

absl::Status Validate(const PolarContourOptions& options) {
  if (options.angles < kMinAngles || options.angles > kMaxAngles) {
    return absl::InvalidArgumentError(
        absl::StrCat("polar_contour.angles must be in [", kMinAngles, ", ",
                     kMaxAngles, "], got ", options.angles));
  }
  if (!(options.radial_step_px >= 0.25f && options.radial_step_px <= 16.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("polar_contour.radial_step_px must be in [0.25, 16], got ",
                     options.radial_step_px));
  }
  if (!(options.min_radius_px > 0.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("polar_contour.min_radius_px must be > 0, got ",
                     options.min_radius_px));
  }
  if (!(options.max_radius_px > options.min_radius_px &&
        options.max_radius_px <= kMaxRadiusPx)) {
    return absl::InvalidArgumentError(
        absl::StrCat("polar_contour.max_radius_px must be in (min_radius_px, ",
                     kMaxRadiusPx, "], got ", options.max_radius_px));
  }
  if (!(options.max_slope > 0.0f && options.max_slope <= 1000.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("polar_contour.max_slope must be in (0, 1000], got ",
                     options.max_slope));
  }
  if (!(options.outside_probability >= 0.0f &&
        options.outside_probability <= 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("polar_contour.outside_probability must be in [0, 1], "
                     "got ",
                     options.outside_probability));
  }
  if (!(options.min_probability > 0.0f && options.min_probability < 1.0f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("polar_contour.min_probability must be in (0, 1), got ",
                     options.min_probability));
  }
  if (options.cost != PolarCost::kOneMinusP &&
      options.cost != PolarCost::kNegLogP) {
    return absl::InvalidArgumentError("polar_contour.cost is not a PolarCost");
  }
  if (options.interrupt_every_angles < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("polar_contour.interrupt_every_angles must be >= 1, got ",
                     options.interrupt_every_angles));
  }
  return absl::OkStatus();
}

absl::StatusOr<PolarContour> FindPolarContour(
    const cv::Mat& edge_probability, cv::Point seed,
    const PolarContourOptions& options, const InterruptCheck& interrupt) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (edge_probability.empty() || edge_probability.type() != CV_32FC1) {
    return absl::InvalidArgumentError(
        "polar_contour: edge_probability must be a non-empty CV_32FC1 map");
  }
  if (seed.x < 0 || seed.y < 0 || seed.x >= edge_probability.cols ||
      seed.y >= edge_probability.rows) {
    return absl::InvalidArgumentError(absl::StrCat(
        "polar_contour: seed (", seed.x, ", ", seed.y, ") is outside the ",
        edge_probability.cols, " x ", edge_probability.rows, " map"));
  }
  return SolveClosedContour(edge_probability, seed, options, interrupt);
}

cv::Mat FillPolarContour(const PolarContour& contour, cv::Size size) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
  const int a_count = static_cast<int>(contour.radii.size());
  if (a_count < 3) return mask;
  const double scale = 1 << kPolygonShift;
  std::vector<cv::Point> polygon(a_count);
  for (int a = 0; a < a_count; ++a) {
    const double theta = 2.0 * M_PI * a / a_count;
    polygon[a] = cv::Point(
        static_cast<int>(std::lround(
            (contour.seed.x + contour.radii[a] * std::cos(theta)) * scale)),
        static_cast<int>(std::lround(
            (contour.seed.y + contour.radii[a] * std::sin(theta)) * scale)));
  }
  cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{polygon},
               cv::Scalar(255), cv::LINE_8, kPolygonShift);
  return mask;
}

absl::StatusOr<cv::Mat> SegmentAtFixation(const cv::Mat& edge_probability,
                                          cv::Point seed,
                                          const PolarContourOptions& options,
                                          const InterruptCheck& interrupt) {
  FOVEA_ASSIGN_OR_RETURN(
      PolarContour contour,
      FindPolarContour(edge_probability, seed, options, interrupt));
  return FillPolarContour(contour, edge_probability.size());
}

}  // namespace fovea
