#ifndef FOVEA_CORE_ATTENTION_WTA_H_
#define FOVEA_CORE_ATTENTION_WTA_H_

#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/statusor.h"
#include "core/attention/attention_point.h"

namespace fovea {

// Constants of the integrate-and-fire Winner-Take-All (thesis section 2.5.1,
// after Itti, Koch & Niebur 1998 and Walther & Koch 2006). The neuron
// constants are the SaliencyToolbox's (defaultLeakyIntFire.m, also used by
// the thesis's own implementation in the V4R attention module), in SI units.
struct WtaOptions {
  // Pyramid level of the neuron layer: one neuron per 2^level x 2^level
  // block of map pixels, fed with the block's mean. Itti et al. 1998 put the
  // saliency map at scale 4 (1/16 of the input); range [0, 8].
  int level = 4;
  // Forward-Euler time step dt, s (SaliencyToolbox timeStep: 0.1 ms).
  float time_step_s = 1e-4f;
  // Membrane capacitance C, F (SaliencyToolbox WTA neuron: 1 nF).
  float capacitance_f = 1e-9f;
  // Leak conductance g_leak, S (SaliencyToolbox: 10 nS; with C a membrane
  // time constant C / g_leak of 100 ms). The leak reverses at 0 V (Eleak).
  float leak_conductance_s = 1e-8f;
  // Firing threshold V_th, V (SaliencyToolbox Vthresh: 1 mV).
  float threshold_v = 1e-3f;
  // Input current of a neuron whose block mean equals the map's maximum, A;
  // other neurons get it in proportion to their mean. 0.5 nA is the
  // SaliencyToolbox's steady drive of a WTA neuron at saliency 1
  // (smOutputRange 1 nA / saliency-map Gleak 100 nS * WTA Ginput 50 nS).
  float input_current_a = 5e-10f;
  // A selection gives up when no neuron fired within this simulated time,
  // s. With the defaults a neuron fires within 50 ms iff its input is above
  // g_leak V_th / (I_max (1 - exp(-T g_leak / C))) = 5.1 % of the maximum,
  // the floor MsrOptions::min_relative_saliency uses.
  float max_time_s = 0.05f;
  // Radius of the inhibition-of-return disc around the focus of attention,
  // full-resolution pixels (the thesis implementation's foaSize, 64, used
  // as a radius). The winner's own neuron is always inhibited.
  float ior_radius_px = 64.0f;
};

absl::Status Validate(const WtaOptions& options);

// Winner-Take-All with inhibition of return (thesis section 2.5.1).
//
// `map` (CV_32FC1, any size; NaN and negative values count as 0) is reduced
// to a layer of neurons, one per 2^level block (blocks at the right and
// bottom edges may be partial), input current I_i = input_current_a *
// mean_i / max_j mean_j. Each selection starts with every membrane at rest,
// V = 0, and integrates
//     C dV_i/dt = I_i - g_leak V_i                 (forward Euler, step dt)
// until some V_i reaches V_th. The first neuron over threshold wins (if
// several cross in the same step: the highest V, then the lowest row-major
// index). The focus of attention shifts to the saliency-weighted centre of
// the winner's block in `map` (rounded to a pixel), which becomes the
// point; its saliency is the winner's block mean (what made it win). All
// neurons are reset, and inhibition of return sets the input of every
// neuron whose block centre lies within ior_radius_px of the point (and of
// the winner itself) to 0 for all later selections. Repeats until
// `max_points` points or until no neuron fires within max_time_s.
//
// Points come in firing order, which is descending block mean: since all
// neurons start at rest under constant input, V_i(t) grows with I_i. Work
// is bounded by max_points * (max_time_s / dt) steps over the layer.
// Deterministic (unlike the SaliencyToolbox, no input noise).
// Fewer points come back when the map runs out; an all-zero map gives none.
// Errors: empty map or wrong type, an infinite map value, max_points < 0,
// invalid options.
absl::StatusOr<std::vector<AttentionPoint>> ExtractWtaPoints(
    const cv::Mat& map, int max_points, const WtaOptions& options);

}  // namespace fovea

#endif  // FOVEA_CORE_ATTENTION_WTA_H_
