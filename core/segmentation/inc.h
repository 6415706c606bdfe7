#ifndef FOVEA_CORE_SEGMENTATION_INC_H_
#define FOVEA_CORE_SEGMENTATION_INC_H_

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "absl/status/statusor.h"
#include "core/base/interrupt.h"
#include "core/frame/organized_cloud.h"
#include "core/scene/support_plane.h"
#include "core/segmentation/body_fit.h"
#include "core/segmentation/cos.h"
#include "core/segmentation/rbf_svm.h"
#include "core/segmentation/relations.h"
#include "core/segmentation/surface_model.h"

namespace fovea {

// INC, incremental attention-driven segmentation (thesis section 3.3,
// Algorithm 1): the most salient surface starts an object; the surfaces
// around it are grouped by a graph-based segmentation whose edge weights
// come from an SVM on surface relations; the selection grows by its
// neighbours until the object stops changing; the object is emitted, its
// surfaces leave the scene, and the next most salient surface starts the
// next object.

struct IncOptions {
  // Low-level surfaces: COS's planar patches with their rims and support
  // flags (adaptive clustering by normals: a point joins when its normal
  // deviation and plane distance are below thresholds, the distance one
  // growing with depth as the Kinect's noise, z^2).
  CosOptions surfaces;
  RelationOptions relations;
  // Graph-based segmentation (Felzenszwalb and Huttenlocher 2004): two
  // groups merge when the edge between them weighs at most
  // min(Int(A) + k / |A|, Int(B) + k / |B|), |.| in surfaces, weights
  // 1 - p(same object). k = 1: a lone surface always joins its most likely
  // neighbour (lone surfaces are fragments more often than objects); two
  // groups of two merge when p(same) exceeds 1/2 - Int. Learn scenes:
  // whole-scene F 0.889 / 0.914 / 0.917 / 0.919 / 0.859 for k = 0.5 / 0.75
  // / 1 / 1.25 / 2.
  double k = 1.0;
  // Surface models (plane or B-spline by MDL); two neighbouring surfaces
  // whose union is better explained by one B-spline are one surface for
  // the grouping (their edge weighs 0).
  bool fuse_surfaces = true;
  SurfaceModelOptions surface_models;
  // LCCP's criterion (Stein et al. 2014) beside the SVM: two surfaces that
  // touch in 3D along most of their border, fold away from each other
  // there (convex) and show almost no sharp concave fold are likely parts
  // of one object (a can's lid and side, a mug's inside and outside at the
  // rim, a box's faces); objects meet at concave folds (a can on a box, a
  // cup in a bowl) or depth jumps. Such a pair's p(same) is at least
  // `joined_probability`: the SVM, trained on one sensor's noise, is
  // overruled where it doubts, and the grouping still decides. On the OSD
  // learn scenes and 100 training piles, 97 % of the neighbouring pairs
  // the criterion takes are of one object (all 864 on OSD); a hard join
  // (p = 1) cost the synthetic piles 0.013 overlap F, 0.75 leaves them
  // within 0.001 (docs/scorecard.md).
  struct ConvexJoin {
    bool enabled = true;
    double min_touching = 0.5;         // border_3d_fraction, [0, 1]
    double min_convexity = 0.55;       // border_convexity, [0, 1], 0.5 flat
    double max_sharp_concave = 0.1;    // border_sharp_concave_fraction
    double joined_probability = 0.75;  // (0.5, 1]
  };
  ConvexJoin convex_join;
  // What rests on a face is another object: a horizontal surface that
  // lies within a larger horizontal surface's outline (on the support's
  // plane) and stands at least `min_step_m` above it is the top of a thin
  // object lying on it (a pen or a small part on a book, a coaster on a
  // tray), whatever the SVM says: their p(same) is at most
  // `apart_probability`. The SVM, trained on frames where a small surface
  // touching a large one is mostly a piece of the same object, joined them
  // (p 0.53-0.69 on the stacked-above piles' parts on books: colour
  // similarity 0.47-0.51 and a step of 1-1.5 cm notwithstanding).
  // Scorecard: stacked-above Kinect INC recall 0.918 -> 0.938, every other
  // row identical (docs/scorecard.md).
  struct RestingOnFace {
    bool enabled = true;
    // Both surfaces' planes within this of the support's, degrees.
    double max_tilt_deg = 30.0;
    // The upper surface's median height above the lower's median, m (the
    // least height an object has, 1 cm, less a sigma of noise) ...
    double min_step_m = 0.008;
    // ... and this share of its points over the lower's outline.
    double min_inside = 0.9;
    double apart_probability = 0.2;  // [0, 0.5)
  };
  RestingOnFace resting_on_face;
  // One face seen on both sides of what stands in front of it: two upright
  // planar surfaces on one plane (normals within `max_angle_deg` of each
  // other and at least `min_tilt_deg` from the support's), whose image
  // regions are separated only by nearer points (an occluder; pixels
  // without depth count too, at most `max_gap_px` at a 525 px focal
  // length, scaled with fx) along at least `min_lines` rows or columns,
  // where the far side's pixels lie on the near side's plane (within
  // `plane_tolerance_m`, each on the other's), the face continued across
  // (`min_continued`), and whose colours are alike (colour similarity
  // at least `min_color_similarity`), become neighbours with p(same) at
  // least `joined_probability`: a box behind a can (OSD's occluded kind).
  // Scorecard: OSD occluded INC overlap F 0.870 -> 0.896, all 0.939 ->
  // 0.944, stacked active stereo 0.789 -> 0.791, nothing lower; the plane
  // tolerance, the upright faces only and the continued share keep apart
  // two boxes that happen to share a plane, and a box top split by what
  // lies on it (which changed the grouping: docs/scorecard.md).
  struct AcrossOccluder {
    bool enabled = true;
    double max_angle_deg = 10.0;
    double plane_tolerance_m = 0.004;
    // Occluder points lie at least this much nearer than the plane, m.
    double min_in_front_m = 0.02;
    int max_gap_px = 120;
    // Rows (or columns) met on: at least this many, and this share of the
    // smaller surface's height (width).
    int min_lines = 5;
    double min_continued = 0.4;
    double min_color_similarity = 0.8;
    double min_tilt_deg = 45.0;
    double joined_probability = 0.75;  // (0.5, 1]
  };
  AcrossOccluder across_occluder;
  // One curved body (body_fit.h) beside the SVM: two neighbouring surfaces
  // whose points lie together on one sphere, upright cylinder or cone (a
  // bowl's or a mug's inside and outside, seen across a depth jump at the
  // rim; a can's side cut in strips) have p(same) at least
  // `joined_probability`. Reads the surfaces' points, which the scene
  // keeps when fuse_surfaces is on.
  struct BodyJoin {
    bool enabled = true;
    BodyFitOptions fit;
    double joined_probability = 0.75;  // (0.5, 1]
    // Surfaces at most this many pixels apart (at a 525 px focal length,
    // scaled by fx / 525) that are not neighbours become neighbours when
    // they lie on one body, within the Kinect's noise whatever the sensor
    // (no border speaks for them): a thin rim seen edge-on leaves a gap of
    // pixels without a surface between a bowl's inside and outside. 0:
    // none. Scorecard: 3 px, or the sensor's own noise, cost active-stereo
    // rooms 0.018 objects above 0.75 F; 2 px within the Kinect's does not.
    int gap_px = 2;
  };
  BodyJoin body_join;
  // Pieces within an object's footprint: when an object is final, the
  // surfaces still in the scene that no border joins to it, whose points
  // lie, seen along the support's normal, within its footprint and that
  // reach its top, join it: a box's top face or a tin's lid cut from its
  // sides, a bowl's rim from its body, by a ring of pixels no surface took
  // (otherwise each comes out later as an object of its own). An object
  // resting on another rises above its top, one beside another stands
  // outside its footprint and one in an open box stays below the box's
  // rim: they are kept apart. Reads the surfaces' points, which the scene
  // keeps when fuse_surfaces is on. Scorecard (docs/scorecard.md): masks
  // per object on the synthetic piles 1.148 -> 1.102, stacked scenes
  // 1.437 -> 1.344 and rooms 1.119 -> 1.084, OSD within 0.001 overlap F;
  // tracking (30 sequences of each kind) IDF1 up on every kind.
  struct PiecesWithin {
    bool enabled = true;
    // Share of a surface's points within the footprint, [0, 1].
    double min_inside = 0.9;
    // The footprint (the convex hull of the object's points on the
    // support's plane) grown by this, m.
    double margin_m = 0.01;
    // The surface's top (the 99th percentile of its points' heights above
    // the support) within this of the object's, and its bottom (the 1st)
    // at most `max_below_m` below the object's, m.
    double top_m = 0.005;
    double max_below_m = 0.015;
    // An object whose points lie on one upright cylinder or cone, or else
    // on one sphere (within body_join.fit's radii, taper and noise, by
    // their median distance to it), seen across at least 3/4 of its
    // diameter, has the body's cross-section in its footprint too, at its
    // widest between its bottom and top: a pot's front wall seen from
    // outside stands for the whole pot, its inside wall beyond the floor
    // (which the support takes) within it, though the front wall's own
    // hull is a thin crescent. A surface bordering such a body and nothing
    // else still in the scene (a sliver of a bowl's rim) joins it too.
    // Scorecard: OSD cylindric overlap F 0.912 -> 0.929, nothing lower
    // (docs/scorecard.md).
    bool body_footprint = true;
  };
  PiecesWithin pieces_within;
  // Each object checked as a whole before it is reported: a piece that
  // rests on nothing is part of the object it hangs from. A piece rests on
  // nothing when its lowest points are above the support's noise band and
  // no horizontal face of another surface (a normal within 30 degrees of
  // the support's) lies beneath them: the upper half of a mug's wall cut
  // from its lower half, a drill's top on its handle, a bottle's cap. It
  // hangs from an object when (1) it touches it: a border with depth
  // continuous, the surfaces continuing each other or folding away, and
  // no border of the two sharply concave (there two objects meet: LCCP);
  // (2) their union is as compact as its parts (eq. 3.3-3.4: neither
  // part's points lie farther from the union's hull than from their own;
  // a cylinder standing flush on a box's front face continues it as a
  // wall would, but the box's top beside it falls below the union's
  // hull); and (3)
  // its foot is not hidden behind another object (a cup in an open box, a
  // can in a bowl may stand on what is hidden), unless it is concave (a
  // mug's inside seen across its rim, whose foot the mug's front wall
  // hides). A can on a tin rests on the tin's top face and stays apart. Both
  // orders: a piece made before its object is held back until an object
  // it hangs from takes it (what nothing took is reported after the
  // rest); an object made first takes the groups around it that hang from
  // it before it is reported. Scorecard (docs/scorecard.md): OSD INC
  // overlap F 0.934 -> 0.939, rolled 90 degrees 0.919 -> 0.933, RealSense
  // masks per object 1.85 -> 1.78, no row lower; frame streams held.
  struct WholeObject {
    bool enabled = true;
    // Bottom (1st percentile of heights) at most this above the support:
    // it stands on it, m.
    double rest_band_m = 0.015;
    // The lowest points: within this of the bottom, m.
    double low_band_m = 0.01;
    // A horizontal face is beneath a low point when one of its points lies
    // within this on the support's plane ...
    double beneath_radius_m = 0.015;
    // ... and at most this below it (or 5 mm above), m.
    double beneath_gap_m = 0.03;
    // Resting: at least this share of the low points have a face beneath,
    // [0, 1].
    double min_resting_share = 0.1;
    // (1) Touching: a border with depth continuous along at least this
    // share of it (border_3d_fraction) ...
    double min_touching = 0.5;
    // ... whose surfaces continue each other or fold away from each other
    // (border_convexity, 0.5 flat) ...
    double min_convexity = 0.5;
    // ... and no border of the two that folds sharply concave along more
    // than this share of it, [0, 1]. Scorecard: 0.5 joined a stacked OSD
    // box to its neighbour (recall 1.0 -> 0.95), 0.1 does not.
    double max_sharp_concave = 0.1;
    // (2) Each part's mean distance to the union's camera-facing hull at
    // most this above its distance to its own, m.
    double max_compactness_loss_m = 0.0008;
    // (3) A hidden foot: of the piece's points whose drop by
    // `hidden_drop_m` the camera would see off the piece (its lower
    // outline), at least `min_hidden_share` have another object's surface
    // nearer than the dropped point by `hidden_margin_m` there.
    double hidden_drop_m = 0.02;
    double hidden_margin_m = 0.01;
    double min_hidden_share = 0.5;
    // ... unless the piece's own mean distance to its camera-facing hull
    // is at least this, m: a vessel's inside (RealSense mugs 2.7 and 9 mm;
    // a can in a bowl, cylinders in and behind open boxes 0-1.1 mm).
    double min_inside_concavity_m = 0.002;
  };
  WholeObject whole_object;
  // Objects of fewer points leave the scene without being emitted (noise
  // surfaces), pixels.
  int min_object_points = 150;
  // The selection grows by its neighbours at most this many times per
  // object.
  int max_growth_steps = 12;
};

absl::Status Validate(const IncOptions& options);

// What INC computes once per frame.
struct IncScene {
  CosScene surfaces;
  std::unique_ptr<RelationComputer> relations;
  // Per surface, eq. 3.6: the mean of the map over its pixels (0 for the
  // support's, which never start or join an object).
  std::vector<double> saliency;
  std::vector<int> pixels;  // per surface, in the labels image (0: support)
  // Per surface, its points (none for support ones), for the surface models
  // (options.fuse_surfaces), which the segmenter fits only for the
  // surfaces an object's growth reaches, when it first reaches them.
  std::vector<std::vector<Eigen::Vector3f>> points;
  int object_points = 0;  // pixels of non-support surfaces
  Eigen::Vector3f up = Eigen::Vector3f::UnitZ();  // the support's normal
  float support_d = 0.0f;  // height above the support: up . p + support_d
  // The cloud's points (CV_32FC3, shared with it) and intrinsics: what the
  // camera sees below a piece (IncOptions::WholeObject).
  cv::Mat xyz;
  Intrinsics intrinsics;
  // Per surface, sorted: its neighbours (CosScene::neighbours) and the
  // surfaces across a gap on one body with it (IncOptions::body_join).
  std::vector<std::vector<int>> neighbours;
  // The pairs (a < b) on one plane across an occluder
  // (IncOptions::across_occluder), sorted; they are neighbours too.
  std::vector<std::pair<int, int>> across_occluder;
  // The surfaces' stages, then "relations" and "surface_points".
  std::vector<StageTiming> timings;
};

// Surfaces (of the points in `region`, as BuildCosScene), their
// relations' statistics and saliency from `saliency_map`
// (CV_32FC1 of the cloud's size, [0, 1]; NaN read as 0). Errors: invalid
// options, a map of another size or type.
absl::StatusOr<IncScene> BuildIncScene(const OrganizedCloud& cloud,
                                       const SupportPlane& plane,
                                       const cv::Mat& saliency_map,
                                       const IncOptions& options,
                                       const cv::Mat& region = cv::Mat());

// The same from `surfaces`, which BuildCosScene made of the same cloud and
// plane with options.surfaces (so that a caller can build them while it
// computes the saliency map).
absl::StatusOr<IncScene> BuildIncScene(CosScene surfaces,
                                       const OrganizedCloud& cloud,
                                       const SupportPlane& plane,
                                       const cv::Mat& saliency_map,
                                       const IncOptions& options);

struct IncObject {
  cv::Mat mask;               // CV_8UC1, 255 on the object
  cv::Rect box;               // the mask's bounding box
  std::vector<int> surfaces;  // its surfaces
  int seed_surface = -1;      // the most salient one, which started it
  cv::Point seed;             // a pixel of it near its centroid
  double saliency = 0.0;      // the seed surface's
  double score = 0.0;         // mean p(same) of the object's merged edges
  int growth_steps = 0;
};

// Runs Algorithm 1 object by object on one scene.
class IncSegmenter {
 public:
  // Not owned; all must outlive the segmenter.
  IncSegmenter(const IncScene& scene, const RbfSvm& svm,
               const IncOptions& options);

  // The next object, most salient first; nullopt once no surface is left.
  // Checks `interrupt` at every growth step.
  absl::StatusOr<std::optional<IncObject>> Next(
      const InterruptCheck& interrupt = {});

  // Fraction of the non-support surface pixels that left the scene.
  double coverage() const;

 private:
  // Points seen along the support's normal (IncOptions::PiecesWithin): on
  // its plane, the box around them there, and their heights' 1st and 99th
  // percentiles (none: no points kept), of an even sample of at most about
  // `max_points` of the surfaces' points.
  struct Footprint {
    std::vector<cv::Point2f> flat;
    std::vector<float> heights;  // per flat point, up . p
    cv::Rect2f box;
    float bottom = 0.0f;
    float top = 0.0f;
  };
  Footprint FootprintOf(const std::vector<int>& surfaces,
                        size_t max_points) const;
  // Adds to `group` (sorted, and kept so) the surfaces still in the scene
  // that no border joins to it, that lie within its footprint and reach
  // its top (IncOptions::PiecesWithin; inc_pieces.cc); they leave the
  // scene. Their pixels.
  int AddPiecesWithin(std::vector<int>& group);
  // Whether the surfaces `group` rest on the support or on a horizontal
  // face of another surface (IncOptions::WholeObject; inc_pieces.cc).
  bool RestsOnSomething(const std::vector<int>& group);
  // Whether a surface of `piece` borders one of `object` (sorted) with
  // depth continuous along the border, or lies on one body with it.
  bool TouchesIn3d(const std::vector<int>& piece,
                   const std::vector<int>& object);
  // Whether `piece` (resting on nothing) is part of `object`: it touches
  // it in 3D, and its foot is not hidden behind another object unless the
  // two lie on one body.
  bool HangsFrom(const std::vector<int>& piece, const std::vector<int>& object);
  // Whether surface `piece` lies on surface `face`'s horizontal face, at
  // least a step above it (IncOptions::RestingOnFace).
  bool RestsOnFace(int piece, int face);
  // The footprint of one surface (kept in footprints_).
  const Footprint& SurfaceFootprint(int surface);
  // Takes into `object` every held object that hangs from it (their pixels
  // left the scene when they were made).
  void TakeHeldNeighbours(IncObject& object);
  // Fills flat_grid_.
  void BuildFlatGrid();
  // Whether the foot of `group` (sorted; `footprint` its points) is
  // hidden: for most of the points whose drop by hidden_drop_m the camera
  // would see off the group, another object's surface is nearer there
  // (IncOptions::WholeObject).
  bool FootHidden(const Footprint& footprint,
                  const std::vector<int>& group) const;
  // Takes into `object` the groups of surfaces still in the scene around
  // it that hang from it; their pixels.
  int TakeHangingNeighbours(IncObject& object);
  // The group INC would grow from surface `s` within two steps, of the
  // surfaces still in the scene.
  std::vector<int> GroupAround(int s);
  // The mask, box and seed pixel of `object`'s surfaces.
  void Finish(IncObject& object) const;
  // p(same object) of two neighbouring surfaces: the SVM's, raised to
  // convex_join.joined_probability or body_join.joined_probability where
  // that criterion holds; cached.
  double SameProbability(int a, int b);
  // Fits the surface models of `selection`'s surfaces and decides for each
  // neighbouring pair of them whether one B-spline explains both (then
  // their edge weighs 0), where not done before; in parallel.
  void DecideFusions(const std::vector<int>& selection);
  // Groups of `selection` by the graph-based segmentation; the group of
  // `seed`.
  std::vector<int> GroupOf(const std::vector<int>& selection, int seed,
                           double* score);

  const IncScene& scene_;
  const RbfSvm& svm_;
  const IncOptions options_;
  std::vector<bool> removed_;
  int removed_points_ = 0;
  // Per surface, its footprint (pieces_within), when first needed.
  std::vector<std::optional<Footprint>> footprints_;
  std::unordered_map<uint64_t, double> probability_;  // pair -> p(same)
  // Per surface: fitted yet, and its model (none: support, too few points
  // or degenerate).
  std::vector<char> fitted_;
  std::vector<std::optional<SurfaceModel>> models_;
  std::unordered_map<uint64_t, bool> fused_;  // pair -> one B-spline
  // Objects held back (IncOptions::WholeObject), in the order they were
  // made; reported after every other object when no later one took them.
  std::vector<IncObject> held_;
  // Every object surface's points seen along the support's normal (an even
  // sample): per grid cell of beneath_radius_m, (x, y, height, surface);
  // built when first needed.
  struct FlatPoint {
    float x, y, height;
    int surface;
    bool horizontal;  // its surface's normal within 30 degrees of up
  };
  std::unordered_map<uint64_t, std::vector<FlatPoint>> flat_grid_;
  bool flat_grid_built_ = false;
};

// Relation SVM training examples of one labelled frame: every pair of
// neighbouring non-support surfaces, +1 when most of both belong to one
// ground-truth object, -1 when to different ones (or one to the table).
// Pairs of two table surfaces are left out. `group` tags the samples.
std::vector<SvmSample> IncTrainingSamples(const IncScene& scene,
                                          const cv::Mat& labels, int group);

}  // namespace fovea

#endif  // FOVEA_CORE_SEGMENTATION_INC_H_
