#ifndef FOVEA_CORE_PIPELINE_SEGMENT_H_
#define FOVEA_CORE_PIPELINE_SEGMENT_H_

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/attention/attention_point.h"
#include "core/base/interrupt.h"
#include "core/frame/osd_pcd.h"
#include "core/frame/rgbd_frame.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/object_geometry.h"
#include "core/segmentation/cos.h"
#include "core/segmentation/ebs.h"
#include "core/segmentation/linear_svm.h"
#include "core/segmentation/rbf_svm.h"

namespace fovea {

// Attention-driven segmentation (thesis section 3.2): seeds from Detect or
// from the caller, one object per seed, cut out by COS or EBS.

enum class SegmentMethod { kCos, kEbs };

// The smallest object reported by default, m^2 (SegmentOptions).
inline constexpr double kMinObjectAreaM2 = 4e-4;
// Share of a mask's points with depth that must stand on the table
// (TableScene::standing: above its noise band, projecting inside its
// hull) for the mask to be reported: what rises just beyond the hull's edge
// is a wall or a chair there, what lies within the noise band a remnant of
// the table.
inline constexpr double kMinStandingShare = 0.5;

struct SegmentOptions;
struct SegmentModels;
struct PreparedScene;
class ObjectCutter;  // segment.cc: cuts one object at a seed

// The one table of segmentation methods. The server's conversion and
// capabilities (the wire value is the SegmentationMethod value whose name
// is the row's name in upper case), fovea-client's names (from the proto
// descriptor) and fovea-eval read it. Adding a method: its files in
// core/segmentation/ and their test, a SegmentMethod value, a cutter and
// one row in segment.cc, one SegmentationMethod value in segment.proto.
struct SegmentMethodRow {
  SegmentMethod method;
  std::string_view name;  // "cos": lower case, the one spelling
  // The method's cutter over a prepared scene; FAILED_PRECONDITION when its
  // model is not loaded. With a null scene only the model is checked (and
  // the cutter is null).
  absl::StatusOr<std::unique_ptr<ObjectCutter>> (*create)(
      const PreparedScene* scene, const SegmentOptions& options,
      const SegmentModels& models);
};
absl::Span<const SegmentMethodRow> SegmentMethods();
// The row of `method`; null when there is none.
const SegmentMethodRow* FindSegmentMethod(SegmentMethod method);

std::string_view SegmentMethodName(SegmentMethod method);  // "cos", "ebs"
// A row's name; INVALID_ARGUMENT naming the known ones otherwise.
absl::StatusOr<SegmentMethod> ParseSegmentMethod(std::string_view text);

// Which of an object's points come back with it.
enum class ObjectPointsFormat {
  kNone,     // none
  kIndices,  // organized indices v * width + u in the frame as sent
  kXyz,      // 3D points, metres, camera frame (pixels with depth only)
};

struct ObjectPointsOptions {
  ObjectPointsFormat format = ObjectPointsFormat::kNone;
  // At most this many, evenly spread over the object in raster order; 0:
  // all of them. [0, kMaxObjectPoints].
  int max_points = 0;
};

// Largest ObjectPointsOptions::max_points (a 1920x1080 frame's pixels).
inline constexpr int kMaxObjectPoints = 1920 * 1080;

// INVALID_ARGUMENT naming the field ("object_points.max_points").
absl::Status Validate(const ObjectPointsOptions& options);

struct SegmentOptions {
  SegmentMethod method = SegmentMethod::kCos;
  // Seeds: these pixels (x = column u, y = row v), in this order, when not
  // empty; otherwise Detect's attention points with `detect`. `detect`
  // also prepares the scene (normals, support plane) either way.
  std::vector<cv::Point> seeds;
  DetectOptions detect;
  // Objects to cut out at most; 0 = one per seed (and per cover seed).
  int max_objects = 0;
  // After the seeds, surfaces standing on the table that no mask holds yet
  // get seeds too (CoverSeed), until every one is in a mask or has yielded
  // no object, so that running to the end segments the whole scene as INC
  // does. Unset: on when the seeds come from Detect (all objects), off when
  // the caller gives them (just those objects).
  std::optional<bool> cover_scene;
  // Masks showing less than this visible area are fragments (a rim, a
  // sliver of an occluded object, sensor noise) and are not reported, m^2:
  // 4 cm^2 is a 2 x 2 cm face (VisibleArea). Nor are masks less than
  // kMinStandingShare of which stands on the table.
  double min_object_area_m2 = kMinObjectAreaM2;
  CosOptions cos;
  // EBS's contour search at each seed.
  PolarContourOptions ebs_contour;
  // Each object's box on the support (SegmentedObject::geometry).
  BoxFitOptions box_fit;
  ObjectPointsOptions object_points;
};

// INVALID_ARGUMENT naming the field: detect.*, cos.*, a negative
// max_objects, more than kMaxAttentionPoints seeds.
absl::Status Validate(const SegmentOptions& options);

// The sensor families that may have INC relation models of their own,
// trained on scenes that family sees (models/<SensorKindName>/, see
// core/pipeline/models.h); every other family's frames, the Kinect v1's
// among them, get the base model.
inline constexpr SensorKind kIncFamilies[] = {SensorKind::kActiveStereo,
                                              SensorKind::kTimeOfFlight};

// The trained models segmentation uses; not owned, may be null when the
// method does not need them.
struct SegmentModels {
  const LinearSvm* cos = nullptr;
  const EbsModel* ebs = nullptr;
  // INC's relation SVM (incremental.h): the structured-light (Kinect v1)
  // family's, and every family's that has none of its own.
  const RbfSvm* inc = nullptr;
  // INC's relation SVM of each of kIncFamilies, in its order; null: `inc`
  // serves that family's frames too.
  std::array<const RbfSvm*, std::size(kIncFamilies)> inc_family{};

  // INC's model for a frame whose depth noise is `noise_kind`'s (NoiseKind
  // in core/frame/sensor_model.h; kGeneric is taken as the Kinect v1).
  const RbfSvm* IncFor(SensorKind noise_kind) const;
  // INC's model for `frame` as `scene` declares its sensor: kGeneric is
  // chosen from the frame's intrinsics, as the noise model is.
  const RbfSvm* IncFor(const RgbdFrame& frame, const SceneOptions& scene) const;
};

struct SegmentedObject {
  int index = 0;        // 0 = first object emitted
  AttentionPoint seed;  // the seed that started it (3D filled in)
  cv::Mat mask;         // CV_8UC1, 255 on the object
  cv::Rect box;         // the mask's bounding box, pixels
  int area = 0;         // mask pixels
  double score = 0.0;   // [0, 1], the method's confidence
  // Of the mask's pixels with depth, metres, camera frame: the mean point
  // and the axis-aligned size.
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  Eigen::Vector3f extent = Eigen::Vector3f::Zero();
  // The box standing on the support that holds the object's points
  // (FitSupportAlignedBox); none when it has fewer than 3 with depth.
  std::optional<ObjectGeometry> geometry;
  // As ObjectPointsOptions asked: organized indices into the frame as sent,
  // or 3D points (metres, camera frame); empty otherwise.
  std::vector<int> point_indices;
  std::vector<Eigen::Vector3f> points;
  double seconds_since_start = 0.0;  // since RunSegment's `start`
};

// Fills the object's box, area, centroid and extent from its mask and the
// cloud's points under it. `within`, when not empty, holds every pixel of
// the mask (only it is looked at: the same result, sooner).
void DescribeObject(const OrganizedCloud& cloud, SegmentedObject& object,
                    const cv::Rect& within = cv::Rect());

// Fills the object's geometry (its box on `plane`) and, for
// ObjectPointsFormat::kXyz, its points, from the mask (at the cloud's
// size) and the cloud's points under it; `within` as DescribeObject's.
// Indices are taken later, from the mask at the frame's size
// (ObjectIndicesToInput).
void DescribeGeometry(const OrganizedCloud& cloud, const SupportPlane& plane,
                      const BoxFitOptions& box_fit,
                      const ObjectPointsOptions& points,
                      SegmentedObject& object,
                      const cv::Rect& within = cv::Rect());

// For ObjectPointsFormat::kIndices, the object's organized indices from its
// mask as sent (after ObjectToInput).
void ObjectIndicesToInput(const ObjectPointsOptions& points,
                          SegmentedObject& object);

// The share of the mask's pixels with depth that stand on `table`
// (TableScene::standing), [0, 1] (1 for a mask without depth). `within`
// as DescribeObject's.
double StandingShare(const TableScene& table, const cv::Mat& mask,
                     const cv::Rect& within = cv::Rect());

// Where to seed the next object of a scene whose `covered` pixels are in
// masks already: on the largest piece (by VisibleArea) of `free` (pixels
// standing on the table, off surface edges, not covered, not tried) of at
// least `min_area_m2`, the pixel farthest from the piece's border. nullopt
// when there is none. `piece` receives the piece's pixels (CV_8UC1, 255).
std::optional<cv::Point> CoverSeed(const OrganizedCloud& cloud,
                                   const cv::Mat& free, double min_area_m2,
                                   cv::Mat& piece);

// The area the mask's points show the camera, m^2: each pixel with depth z
// covers z^2 / (fx fy) facing the camera (a lower bound of the surface's
// area, exact for a face seen head-on).
// `within` as DescribeObject's.
double VisibleArea(const OrganizedCloud& cloud, const cv::Mat& mask,
                   const cv::Rect& within = cv::Rect());

// Results in the scene's (processing) pixels mapped to the frame as sent:
// points' pixels; an object's seed, mask, box and area (its centroid and
// extent are metric and stay).
std::vector<AttentionPoint> PointsToInput(const FrameScale& scale,
                                          std::vector<AttentionPoint> points);
void ObjectToInput(const FrameScale& scale, SegmentedObject& object);
// The plane with its inliers (and their count) at the input size.
SupportPlane PlaneToInput(const FrameScale& scale, const SupportPlane& plane);

enum class SegmentStop {
  kDone,        // every seed was used
  kMaxObjects,  // options.max_objects objects were emitted
  kTimeBudget,  // the request's time budget ran out (incremental only)
};

struct SegmentSummary {
  SegmentStop stop = SegmentStop::kDone;
  int objects = 0;
  // Fraction of the pixels standing on the table (height above
  // detect.table_scene.min_object_height) inside an emitted mask, [0, 1].
  double scene_coverage = 0.0;
  // "cloud", "normals", "support_plane", Detect's stages when it ran,
  // "segment.prepare" (the method's per-frame work), one
  // "segment.object" per seed and one "segment.cover" per cover seed.
  std::vector<StageTiming> timings;
  double total_seconds = 0.0;
};

// Where the results go as they are made. A non-OK status from a sink
// stops the work and is returned (the caller's client has gone).
struct SegmentSinks {
  // The support the scene was prepared on (its inliers at the frame's
  // size), once, first (may be empty).
  std::function<absl::Status(const SupportPlane&)> support;
  // The seeds, once, before the first object (may be empty).
  std::function<absl::Status(const std::vector<AttentionPoint>&)> points;
  std::function<absl::Status(SegmentedObject)> object;
};

// Prepares the scene, takes the seeds, and for each seed in order cuts out
// its object and hands it to `sinks.object` at once; then, with
// cover_scene, the same for each cover seed (its object less what earlier
// masks hold). A seed whose object
// was already cut out, or that lies on the table or on nothing, yields no
// object. COS: see CosSegmenter (objects are disjoint patch sets). EBS:
// the inside of the minimum-cost contour around the seed on the model's
// edge probability map, less the pixels without depth or on the support
// plane; a contour is independent of earlier ones (a seed on a box that an
// earlier, too large contour also covered still gets its own mask), and a
// mask overlapping an earlier one by more than half (IoU) is that object
// found again and yields none. `interrupt` is checked between stages,
// between objects and inside the methods' loops; its status is returned as
// is. Errors: Validate's; FAILED_PRECONDITION when the method's model is
// null; NOT_FOUND without a support plane; RESOURCE_EXHAUSTED / INTERNAL
// for what throws underneath.
absl::StatusOr<SegmentSummary> RunSegment(
    const RgbdFrame& frame, const SegmentOptions& options,
    const SegmentModels& models, const SegmentSinks& sinks,
    const InterruptCheck& interrupt = {},
    std::chrono::steady_clock::time_point start =
        std::chrono::steady_clock::now());

// COS training examples of one labelled frame (CosTrainingSamples on the
// scene `detect` prepares from measured depth: MeasuredDepthOnly), tagged
// with `group`.
absl::StatusOr<std::vector<SvmSample>> CollectCosSamples(
    const LabelledFrame& frame, int group, const DetectOptions& detect,
    const CosOptions& cos);

}  // namespace fovea

#endif  // FOVEA_CORE_PIPELINE_SEGMENT_H_
