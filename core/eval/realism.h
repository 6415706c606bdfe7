#ifndef FOVEA_CORE_EVAL_REALISM_H_
#define FOVEA_CORE_EVAL_REALISM_H_

#include <limits>
#include <string>
#include <vector>

#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/scene/table_scene.h"

namespace fovea {

// How far synthetic frames are from real ones: the same statistics taken
// from both, compared one distribution at a time (`fovea-eval realism`,
// docs/realism.md). A synthetic figure counts only as far as its frames
// look like the sensor's real ones; these say where they do not.
//
// Every statistic is taken from what Fovea itself sees of a frame (the
// support plane it found, its table scene), so real frames without labels
// give the label-free ones; the others need per-pixel labels (OSD
// convention, core/frame/osd_pcd.h).

// Two-sample Kolmogorov-Smirnov distance: the largest gap between the two
// empirical distribution functions, [0, 1] (0: the samples' distributions
// agree at every value; 1: every value of one lies below every value of
// the other). NaN when either sample is empty. NaNs in the samples are
// ignored.
double KolmogorovSmirnov(std::vector<double> a, std::vector<double> b);

struct RealismOptions {
  // Plane noise: square cells of this many pixels (at 640 columns; scaled
  // with the width), used when at least `cell_fill` of their pixels are on
  // the support region; each gives one sample, the residual standard
  // deviation of its points about their least-squares plane divided by
  // z^2 (1/m: the Kinect v1's is about 1.43e-3, Khoshelham & Elberink
  // 2012).
  int cell_px = 8;
  double cell_fill = 0.9;
  // Missing depth is counted inside the image-space convex hull of the
  // support region's pixels (the table as the camera sees it, objects on
  // it included), eroded by this many pixels (OSD's crop cuts at the
  // table's edge).
  int hull_erode_px = 4;
  // A hole (a 4-connected component of missing pixels) is at a depth edge
  // when the valid pixels around it differ in depth by more than
  // max(edge_jump_m, edge_jump_fraction * z): a shadow or a dropout at an
  // object's outline, not a speckle on a surface.
  double edge_jump_m = 0.03;
  double edge_jump_fraction = 0.03;
  // Dark pixels: grey level (0-255, the mean of R, G, B) below this.
  int dark_grey = 50;
  // At most this many samples per frame of the per-point statistics
  // (normals), taken evenly, so that every frame weighs alike.
  int max_point_samples = 2000;
};

// One frame's samples. Per-frame figures are one value each (NaN when the
// frame has none of what they count, e.g. no dark pixel, or no support at
// all); per-cell, per-point and per-object ones many.
struct RealismSamples {
  static constexpr double kNoSample = std::numeric_limits<double>::quiet_NaN();
  // Label-free.
  std::vector<double> plane_noise;        // per cell: sigma / z^2, 1/m
  std::vector<double> plane_noise_depth;  // per cell: its mean z, m
  double missing_fraction = kNoSample;    // missing share inside the hull
  double missing_at_edges = kNoSample;  // share of missing pixels in edge holes
  double missing_on_dark = kNoSample;   // missing share of the dark pixels
  std::vector<double> normal_angle;     // support points: normal vs plane, deg
  // Share of the table scene's pixels (TableScene::region) on the support
  // plane itself: how much of the table stays visible.
  double table_share = kNoSample;
  // With labels: per ground-truth object, the share of its pixels the
  // table scene holds (TableScene::region; 1: the whole object is in the
  // scene segmentation works on) and the share the standing test marks
  // (TableScene::standing); its lowest point above the support (the 2nd
  // percentile of its points' heights, m).
  std::vector<double> object_in_scene;
  std::vector<double> object_standing;
  std::vector<double> object_bottom;
};

// The label-free statistics of one frame (cloud with normals, the support
// found in it and the table scene prepared on it) and, when `labels` is a
// CV_32SC1 image of the cloud's size, the per-object ones. Of the cloud's
// colour (CV_8UC3, RGB or BGR) only the grey level is read.
RealismSamples CollectRealismSamples(const OrganizedCloud& cloud,
                                     const SupportPlane& plane,
                                     const TableScene& table,
                                     const cv::Mat& labels,
                                     const RealismOptions& options);

// A set of frames' samples pooled, statistic by statistic, as named by
// RealismStatisticNames(): per-frame figures one value per frame.
// Relation features (same- and different-object pairs of neighbouring
// surfaces, one vector per pair, RelationFeatureNames() order) are added
// by the caller, who builds INC's scene.
struct RealismSet {
  std::string name;
  int frames = 0;
  std::vector<std::vector<double>> statistics;  // RealismStatisticNames()
  std::vector<std::vector<double>> same_relations, different_relations;
  std::vector<double> patches_per_object;
};

// The per-frame and pooled statistics' names, in RealismSet::statistics'
// order: plane_noise, plane_noise_depth, missing_fraction,
// missing_at_edges, missing_on_dark, normal_angle, table_share,
// object_in_scene, object_standing, object_bottom.
const std::vector<std::string>& RealismStatisticNames();

// Adds one frame's samples to `set`.
void AddToSet(const RealismSamples& samples, RealismSet& set);

// One statistic compared: its medians on both sides and the KS distance
// (NaN where a side has no sample, e.g. labels on unlabelled frames).
struct RealismDistance {
  std::string statistic;
  int real_samples = 0, synthetic_samples = 0;
  double real_median = 0.0, synthetic_median = 0.0;
  double ks = 0.0;
};

// Every statistic of the two sets compared: RealismStatisticNames(), then
// patches_per_object, then each relation feature for same-object pairs
// ("same.<feature>") and different-object pairs ("different.<feature>"),
// named by `relation_names`.
std::vector<RealismDistance> CompareRealism(
    const RealismSet& real, const RealismSet& synthetic,
    const std::vector<std::string>& relation_names);

// The mean and the largest KS distance over the rows whose name starts
// with `prefix` ("" = all) and that have a number; NaN when none.
struct RealismSummary {
  double mean_ks = 0.0, max_ks = 0.0;
  std::string worst;  // the row of max_ks
  int rows = 0;
};
RealismSummary SummarizeRealism(const std::vector<RealismDistance>& rows,
                                const std::string& prefix);

}  // namespace fovea

#endif  // FOVEA_CORE_EVAL_REALISM_H_
