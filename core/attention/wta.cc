#include "core/attention/wta.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

// Bounds the layer's size and the work of one selection.
constexpr int kMaxLevel = 8;
constexpr double kMaxStepsPerSelection = 1e6;

// Map value as a non-negative input: NaN and negatives count as 0.
inline float Input(float s) { return s > 0.0f ? s : 0.0f; }

// The neuron layer: one cell per block of `block` x `block` map pixels.
struct Layer {
  int block = 1;
  int cols = 0, rows = 0;
  std::vector<float> mean;  // block mean of the map, row-major
};

Layer BuildLayer(const cv::Mat& map, int level) {
  Layer layer;
  layer.block = 1 << level;
  layer.cols = (map.cols + layer.block - 1) / layer.block;
  layer.rows = (map.rows + layer.block - 1) / layer.block;
  std::vector<double> sum(static_cast<size_t>(layer.cols) * layer.rows, 0.0);
  for (int v = 0; v < map.rows; ++v) {
    const float* row = map.ptr<float>(v);
    double* cell_row = &sum[static_cast<size_t>(v / layer.block) * layer.cols];
    for (int u = 0; u < map.cols; ++u) {
      cell_row[u / layer.block] += Input(row[u]);
    }
  }
  layer.mean.resize(sum.size());
  for (int r = 0; r < layer.rows; ++r) {
    const int h = std::min(layer.block, map.rows - r * layer.block);
    for (int c = 0; c < layer.cols; ++c) {
      const int w = std::min(layer.block, map.cols - c * layer.block);
      const size_t i = static_cast<size_t>(r) * layer.cols + c;
      layer.mean[i] = static_cast<float>(sum[i] / (w * h));
    }
  }
  return layer;
}

// Integrates C dV/dt = I - g_leak V from rest for every neuron that can
// reach threshold (I > g_leak V_th; the others stay below it forever, since
// forward Euler with dt g_leak / C < 1 approaches I / g_leak from below).
// Returns the first neuron to reach V_th, or -1 if none does within
// max_steps.
int RunUntilFirstSpike(const std::vector<float>& current,
                       const WtaOptions& options, int max_steps) {
  const double g = options.leak_conductance_s;
  const double v_th = options.threshold_v;
  std::vector<int> candidates;
  for (int i = 0; i < static_cast<int>(current.size()); ++i) {
    if (current[i] > g * v_th) candidates.push_back(i);
  }
  if (candidates.empty()) return -1;
  // Forward Euler: V <- V + dt / C (I - g V) = V (1 - dt g / C) + dt I / C.
  const double decay = 1.0 - options.time_step_s * g / options.capacitance_f;
  std::vector<double> drive(candidates.size()), potential(candidates.size());
  for (size_t k = 0; k < candidates.size(); ++k) {
    drive[k] = options.time_step_s * current[candidates[k]] /
               static_cast<double>(options.capacitance_f);
    potential[k] = 0.0;
  }
  for (int step = 0; step < max_steps; ++step) {
    double best = -1.0;
    int winner = -1;
    for (size_t k = 0; k < candidates.size(); ++k) {
      potential[k] = potential[k] * decay + drive[k];
      // Candidates are in row-major order: ">" keeps the lowest index on a
      // tie.
      if (potential[k] >= v_th && potential[k] > best) {
        best = potential[k];
        winner = candidates[k];
      }
    }
    if (winner >= 0) return winner;
  }
  return -1;
}

// Saliency-weighted centre of the winner's block in the map, rounded.
cv::Point BlockCentre(const cv::Mat& map, const Layer& layer, int cell) {
  const int u0 = (cell % layer.cols) * layer.block;
  const int v0 = (cell / layer.cols) * layer.block;
  const int u1 = std::min(u0 + layer.block, map.cols);
  const int v1 = std::min(v0 + layer.block, map.rows);
  double weight = 0.0, su = 0.0, sv = 0.0;
  for (int v = v0; v < v1; ++v) {
    const float* row = map.ptr<float>(v);
    for (int u = u0; u < u1; ++u) {
      const double s = Input(row[u]);
      weight += s;
      su += s * u;
      sv += s * v;
    }
  }
  if (!(weight > 0.0)) return {(u0 + u1 - 1) / 2, (v0 + v1 - 1) / 2};
  return {std::clamp(static_cast<int>(std::lround(su / weight)), u0, u1 - 1),
          std::clamp(static_cast<int>(std::lround(sv / weight)), v0, v1 - 1)};
}

// Inhibition of return: zero the input of the winner and of every neuron
// whose block centre is within `radius` pixels of the focus of attention.
void InhibitDisc(const Layer& layer, cv::Point focus, float radius, int winner,
                 std::vector<float>& current) {
  current[winner] = 0.0f;
  const double r2 = static_cast<double>(radius) * radius;
  for (int r = 0; r < layer.rows; ++r) {
    const double dv = (r + 0.5) * layer.block - 0.5 - focus.y;
    for (int c = 0; c < layer.cols; ++c) {
      const double du = (c + 0.5) * layer.block - 0.5 - focus.x;
      if (du * du + dv * dv <= r2) current[r * layer.cols + c] = 0.0f;
    }
  }
}

}  // namespace

absl::Status Validate(const WtaOptions& options) {
  if (options.level < 0 || options.level > kMaxLevel) {
    return absl::InvalidArgumentError(absl::StrCat(
        "wta.level must be in [0, ", kMaxLevel, "], got ", options.level));
  }
  if (!(options.time_step_s > 0.0f) || !std::isfinite(options.time_step_s)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "wta.time_step_s must be finite and > 0, got ", options.time_step_s));
  }
  if (!(options.capacitance_f > 0.0f) ||
      !std::isfinite(options.capacitance_f)) {
    return absl::InvalidArgumentError(
        absl::StrCat("wta.capacitance_f must be finite and > 0, got ",
                     options.capacitance_f));
  }
  if (!(options.leak_conductance_s >= 0.0f) ||
      !std::isfinite(options.leak_conductance_s)) {
    return absl::InvalidArgumentError(
        absl::StrCat("wta.leak_conductance_s must be finite and >= 0, got ",
                     options.leak_conductance_s));
  }
  if (!(static_cast<double>(options.time_step_s) * options.leak_conductance_s /
            options.capacitance_f <
        1.0)) {
    return absl::InvalidArgumentError(
        "wta.time_step_s * wta.leak_conductance_s / wta.capacitance_f must "
        "be < 1 (forward Euler stability)");
  }
  if (!(options.threshold_v > 0.0f) || !std::isfinite(options.threshold_v)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "wta.threshold_v must be finite and > 0, got ", options.threshold_v));
  }
  if (!(options.input_current_a > 0.0f) ||
      !std::isfinite(options.input_current_a)) {
    return absl::InvalidArgumentError(
        absl::StrCat("wta.input_current_a must be finite and > 0, got ",
                     options.input_current_a));
  }
  if (!(options.max_time_s > 0.0f) ||
      !(static_cast<double>(options.max_time_s) / options.time_step_s <=
        kMaxStepsPerSelection)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "wta.max_time_s must be > 0 and at most ", kMaxStepsPerSelection,
        " time steps (wta.time_step_s), got ", options.max_time_s));
  }
  if (!(options.ior_radius_px >= 0.0f) ||
      !std::isfinite(options.ior_radius_px)) {
    return absl::InvalidArgumentError(
        absl::StrCat("wta.ior_radius_px must be finite and >= 0, got ",
                     options.ior_radius_px));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<AttentionPoint>> ExtractWtaPoints(
    const cv::Mat& map, int max_points, const WtaOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  if (map.empty() || map.type() != CV_32FC1) {
    return absl::InvalidArgumentError("wta: map must be a non-empty CV_32FC1");
  }
  if (max_points < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("wta: max_points must be >= 0, got ", max_points));
  }
  std::vector<AttentionPoint> points;
  if (max_points == 0) return points;
  const Layer layer = BuildLayer(map, options.level);
  const float max_mean =
      *std::max_element(layer.mean.begin(), layer.mean.end());
  if (!std::isfinite(max_mean)) {
    return absl::InvalidArgumentError("wta: map has an infinite value");
  }
  if (!(max_mean > 0.0f)) return points;
  std::vector<float> current(layer.mean.size());
  for (size_t i = 0; i < current.size(); ++i) {
    current[i] = static_cast<float>(static_cast<double>(layer.mean[i]) /
                                    max_mean * options.input_current_a);
  }
  const int max_steps = static_cast<int>(
      std::ceil(static_cast<double>(options.max_time_s) / options.time_step_s));
  while (static_cast<int>(points.size()) < max_points) {
    const int winner = RunUntilFirstSpike(current, options, max_steps);
    if (winner < 0) break;
    const cv::Point focus = BlockCentre(map, layer, winner);
    AttentionPoint point;
    point.u = focus.x;
    point.v = focus.y;
    point.saliency = layer.mean[winner];
    points.push_back(point);
    InhibitDisc(layer, focus, options.ior_radius_px, winner, current);
  }
  return points;
}

}  // namespace fovea
