#include "core/pipeline/segment.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <new>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/base/parallel.h"
#include "core/base/stage_clock.h"
#include "core/base/status_macros.h"
#include "core/base/strings.h"

namespace fovea {
namespace {}  // namespace

namespace {

// `within`, or the whole mask when it is empty.
cv::Rect Within(const cv::Mat& mask, const cv::Rect& within) {
  return within.empty() ? cv::Rect(0, 0, mask.cols, mask.rows)
                        : within & cv::Rect(0, 0, mask.cols, mask.rows);
}

}  // namespace

double StandingShare(const TableScene& table, const cv::Mat& mask,
                     const cv::Rect& within) {
  const cv::Rect box = Within(mask, within);
  int with_depth = 0, standing = 0;
  for (int v = box.y; v < box.br().y; ++v) {
    const unsigned char* in = mask.ptr<unsigned char>(v);
    const float* h = table.height.ptr<float>(v);
    const unsigned char* c = table.standing.ptr<unsigned char>(v);
    for (int u = box.x; u < box.br().x; ++u) {
      if (in[u] == 0 || std::isnan(h[u])) continue;
      ++with_depth;
      standing += c[u] != 0;
    }
  }
  return with_depth > 0 ? static_cast<double>(standing) / with_depth : 1.0;
}

double VisibleArea(const OrganizedCloud& cloud, const cv::Mat& mask,
                   const cv::Rect& within) {
  const cv::Rect box = Within(mask, within);
  const double per_z2 = 1.0 / (cloud.intrinsics.fx * cloud.intrinsics.fy);
  double area = 0.0;
  for (int v = box.y; v < box.br().y; ++v) {
    const unsigned char* in = mask.ptr<unsigned char>(v);
    const cv::Vec3f* xyz = cloud.xyz.ptr<cv::Vec3f>(v);
    for (int u = box.x; u < box.br().x; ++u) {
      if (in[u] == 0 || std::isnan(xyz[u][2])) continue;
      area += per_z2 * xyz[u][2] * xyz[u][2];
    }
  }
  return area;
}

std::vector<AttentionPoint> PointsToInput(const FrameScale& scale,
                                          std::vector<AttentionPoint> points) {
  if (!scale.reduced()) return points;
  for (AttentionPoint& p : points) {
    const cv::Point q = scale.ToInput({p.u, p.v});
    p.u = q.x;
    p.v = q.y;
  }
  return points;
}

SupportPlane PlaneToInput(const FrameScale& scale, const SupportPlane& plane) {
  SupportPlane out = plane;
  out.inliers = scale.MaskToInput(plane.inliers);
  if (scale.reduced()) out.inlier_count = cv::countNonZero(out.inliers);
  return out;
}

void ObjectToInput(const FrameScale& scale, SegmentedObject& object) {
  if (!scale.reduced()) return;
  const cv::Point seed = scale.ToInput({object.seed.u, object.seed.v});
  object.seed.u = seed.x;
  object.seed.v = seed.y;
  object.mask = scale.MaskToInput(object.mask);
  object.area = cv::countNonZero(object.mask);
  object.box = object.area > 0 ? cv::boundingRect(object.mask) : cv::Rect();
}

void DescribeObject(const OrganizedCloud& cloud, SegmentedObject& object,
                    const cv::Rect& within) {
  const cv::Rect search = Within(object.mask, within);
  const cv::Mat part = object.mask(search);
  object.area = search.empty() ? 0 : cv::countNonZero(part);
  object.box =
      object.area > 0 ? cv::boundingRect(part) + search.tl() : cv::Rect();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Vector3f lo =
      Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  Eigen::Vector3f hi = -lo;
  int n = 0;
  for (int v = object.box.y; v < object.box.y + object.box.height; ++v) {
    const unsigned char* in = object.mask.ptr<unsigned char>(v);
    const cv::Vec3f* xyz = cloud.xyz.ptr<cv::Vec3f>(v);
    for (int u = object.box.x; u < object.box.x + object.box.width; ++u) {
      if (in[u] == 0 || std::isnan(xyz[u][2])) continue;
      const Eigen::Vector3f p(xyz[u][0], xyz[u][1], xyz[u][2]);
      sum += p.cast<double>();
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      ++n;
    }
  }
  if (n > 0) {
    object.centroid = (sum / n).cast<float>();
    object.extent = hi - lo;
  }
}

absl::Status Validate(const ObjectPointsOptions& options) {
  if (options.max_points < 0 || options.max_points > kMaxObjectPoints) {
    return absl::InvalidArgumentError(
        absl::StrCat("object_points.max_points must be in [0, ",
                     kMaxObjectPoints, "], got ", options.max_points));
  }
  return absl::OkStatus();
}

void DescribeGeometry(const OrganizedCloud& cloud, const SupportPlane& plane,
                      const BoxFitOptions& box_fit,
                      const ObjectPointsOptions& points,
                      SegmentedObject& object, const cv::Rect& within) {
  std::vector<Eigen::Vector3f> visible =
      MaskPoints(cloud, object.mask, Within(object.mask, within));
  absl::StatusOr<ObjectGeometry> geometry =
      FitSupportAlignedBox(visible, plane, box_fit);
  object.geometry.reset();
  if (geometry.ok()) object.geometry = *std::move(geometry);
  object.points.clear();
  if (points.format == ObjectPointsFormat::kXyz) {
    for (const int i :
         EvenSample(static_cast<int>(visible.size()), points.max_points)) {
      object.points.push_back(visible[i]);
    }
  }
}

void ObjectIndicesToInput(const ObjectPointsOptions& points,
                          SegmentedObject& object) {
  object.point_indices.clear();
  if (points.format == ObjectPointsFormat::kIndices) {
    object.point_indices = MaskIndices(object.mask, points.max_points);
  }
}

std::optional<cv::Point> CoverSeed(const OrganizedCloud& cloud,
                                   const cv::Mat& free, double min_area_m2,
                                   cv::Mat& piece) {
  cv::Mat labels;
  const int n = cv::connectedComponents(free, labels, 8, CV_32S);
  if (n <= 1) return std::nullopt;
  std::vector<double> area(n, 0.0);
  const double per_z2 = 1.0 / (cloud.intrinsics.fx * cloud.intrinsics.fy);
  for (int v = 0; v < labels.rows; ++v) {
    const int* l = labels.ptr<int>(v);
    const cv::Vec3f* xyz = cloud.xyz.ptr<cv::Vec3f>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (l[u] == 0 || std::isnan(xyz[u][2])) continue;
      area[l[u]] += per_z2 * xyz[u][2] * xyz[u][2];
    }
  }
  const int best = static_cast<int>(
      std::max_element(area.begin() + 1, area.end()) - area.begin());
  if (area[best] < min_area_m2 || area[best] <= 0.0) return std::nullopt;
  piece = labels == best;
  // The piece's innermost pixel; the frame's border counts as a border.
  cv::Mat framed;
  cv::copyMakeBorder(piece, framed, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::Mat distance;
  cv::distanceTransform(framed, distance, cv::DIST_L2, 3);
  cv::Point at;
  cv::minMaxLoc(distance, nullptr, nullptr, nullptr, &at);
  return cv::Point(at.x - 1, at.y - 1);
}

namespace {

// Pixels standing on the table: what scene_coverage is a fraction of.
cv::Mat ObjectRegion(const TableScene& table, float min_height) {
  cv::Mat region = table.height > min_height;  // NaN compares false
  return region;
}

}  // namespace

// One object per seed, by one method; remembers what earlier seeds took.
struct CutObject {
  cv::Mat mask;  // CV_8UC1, 255 on the object
  double score = 0.0;
};
class ObjectCutter {
 public:
  virtual ~ObjectCutter() = default;
  // nullopt: the seed yields no object.
  virtual absl::StatusOr<std::optional<CutObject>> Cut(
      cv::Point seed, const InterruptCheck& interrupt) = 0;
};

namespace {

class CosCutter final : public ObjectCutter {
 public:
  static absl::StatusOr<std::unique_ptr<ObjectCutter>> Create(
      const PreparedScene& scene, const LinearSvm& svm,
      const CosOptions& options) {
    FOVEA_ASSIGN_OR_RETURN(
        CosScene cos,
        BuildCosScene(scene.cloud, scene.plane, options, scene.table.region));
    return std::unique_ptr<ObjectCutter>(
        new CosCutter(std::move(cos), svm, options));
  }

  absl::StatusOr<std::optional<CutObject>> Cut(
      cv::Point seed, const InterruptCheck& interrupt) override {
    FOVEA_ASSIGN_OR_RETURN(std::optional<CosObject> object,
                           segmenter_.Segment(seed, interrupt));
    if (!object.has_value()) return std::nullopt;
    return CutObject{std::move(object->mask), object->score};
  }

 private:
  CosCutter(CosScene scene, const LinearSvm& svm, const CosOptions& options)
      : scene_(std::move(scene)), segmenter_(scene_, svm, options) {}

  const CosScene scene_;  // before segmenter_, which refers to it
  CosSegmenter segmenter_;
};

// Two masks overlapping by more than this intersection over union are one
// object found twice.
constexpr double kSameObjectIou = 0.5;

// Edge probability once per frame; a contour per seed.
class EbsCutter final : public ObjectCutter {
 public:
  EbsCutter(const PreparedScene& scene, const EbsModel& model,
            const PolarContourOptions& options)
      : probability_(model.EdgeProbability(scene.cloud)), options_(options) {
    // Pixels an object may cover: with depth, in the table's region, off
    // the support plane.
    allowed_ = scene.cloud.xyz.size() == probability_.size()
                   ? cv::Mat(probability_.size(), CV_8UC1, cv::Scalar(0))
                   : cv::Mat();
    const bool have_region = scene.table.region.size() == allowed_.size();
    for (int v = 0; v < allowed_.rows; ++v) {
      const cv::Vec3f* xyz = scene.cloud.xyz.ptr<cv::Vec3f>(v);
      unsigned char* out = allowed_.ptr<unsigned char>(v);
      for (int u = 0; u < allowed_.cols; ++u) {
        const bool on_plane = !scene.plane.inliers.empty() &&
                              scene.plane.inliers.at<unsigned char>(v, u) != 0;
        const bool in_region =
            !have_region || scene.table.region.at<unsigned char>(v, u) != 0;
        out[u] = !std::isnan(xyz[u][2]) && !on_plane && in_region ? 255 : 0;
      }
    }
  }

  absl::StatusOr<std::optional<CutObject>> Cut(
      cv::Point seed, const InterruptCheck& interrupt) override {
    if (allowed_.at<unsigned char>(seed) == 0) return std::nullopt;
    FOVEA_ASSIGN_OR_RETURN(
        PolarContour contour,
        FindPolarContour(probability_, seed, options_, interrupt));
    CutObject object;
    object.mask = FillPolarContour(contour, probability_.size()) & allowed_;
    const int area = cv::countNonZero(object.mask);
    if (area == 0) return std::nullopt;
    for (const cv::Mat& earlier : masks_) {
      const int both = cv::countNonZero(earlier & object.mask);
      const int either = area + cv::countNonZero(earlier) - both;
      if (both > kSameObjectIou * either) return std::nullopt;
    }
    masks_.push_back(object.mask);
    object.score = MeanAlongContour(contour);
    return object;
  }

 private:
  // The edge probability under the contour, [0, 1]: how clearly edges
  // bound the object.
  double MeanAlongContour(const PolarContour& contour) const {
    double sum = 0.0;
    int n = 0;
    const size_t angles = contour.radii.size();
    for (size_t i = 0; i < angles; ++i) {
      const double a = 2.0 * M_PI * i / angles;
      const cv::Point p(static_cast<int>(std::lround(
                            contour.seed.x + contour.radii[i] * std::cos(a))),
                        static_cast<int>(std::lround(
                            contour.seed.y + contour.radii[i] * std::sin(a))));
      if (p.x < 0 || p.y < 0 || p.x >= probability_.cols ||
          p.y >= probability_.rows) {
        continue;
      }
      const float q = probability_.at<float>(p);
      if (std::isnan(q)) continue;
      sum += q;
      ++n;
    }
    return n > 0 ? sum / n : 0.0;
  }

  const cv::Mat probability_;
  const PolarContourOptions options_;
  cv::Mat allowed_;
  std::vector<cv::Mat> masks_;  // of the objects cut so far
};

// The rows' cutters. Without a scene (null), only the model is checked.
absl::StatusOr<std::unique_ptr<ObjectCutter>> MakeCosCutter(
    const PreparedScene* scene, const SegmentOptions& options,
    const SegmentModels& models) {
  if (models.cos == nullptr) {
    return absl::FailedPreconditionError("segment: no COS model is loaded");
  }
  if (scene == nullptr) return nullptr;
  return CosCutter::Create(*scene, *models.cos, options.cos);
}

absl::StatusOr<std::unique_ptr<ObjectCutter>> MakeEbsCutter(
    const PreparedScene* scene, const SegmentOptions& options,
    const SegmentModels& models) {
  if (models.ebs == nullptr) {
    return absl::FailedPreconditionError("segment: no EBS model is loaded");
  }
  if (scene == nullptr) return nullptr;
  return std::unique_ptr<ObjectCutter>(
      std::make_unique<EbsCutter>(*scene, *models.ebs, options.ebs_contour));
}

constexpr SegmentMethodRow kSegmentMethods[] = {
    {SegmentMethod::kCos, "cos", &MakeCosCutter},
    {SegmentMethod::kEbs, "ebs", &MakeEbsCutter},
};

// The seeds in the scene's (processing) pixels: the given ones mapped
// there, or Detect's.
absl::StatusOr<std::vector<AttentionPoint>> TakeSeeds(
    const PreparedScene& scene, const SegmentOptions& options,
    const InterruptCheck& interrupt, std::vector<StageTiming>& timings) {
  std::vector<AttentionPoint> seeds;
  if (!options.seeds.empty()) {
    for (const cv::Point& given : options.seeds) {
      const cv::Point p = scene.scale.ToProcessing(given);
      AttentionPoint a;
      a.u = p.x;
      a.v = p.y;
      const cv::Vec3f& q = scene.cloud.xyz.at<cv::Vec3f>(p.y, p.x);
      a.point = {q[0], q[1], q[2]};
      seeds.push_back(a);
    }
    return seeds;
  }
  FOVEA_ASSIGN_OR_RETURN(DetectResult detect,
                         DetectOnScene(scene, options.detect, interrupt));
  timings.insert(timings.end(), detect.timings.begin(), detect.timings.end());
  return std::move(detect.points);
}

}  // namespace

const RbfSvm* SegmentModels::IncFor(SensorKind noise_kind) const {
  for (size_t i = 0; i < std::size(kIncFamilies); ++i) {
    if (kIncFamilies[i] == noise_kind && inc_family[i] != nullptr) {
      return inc_family[i];
    }
  }
  return inc;
}

const RbfSvm* SegmentModels::IncFor(const RgbdFrame& frame,
                                    const SceneOptions& scene) const {
  return IncFor(NoiseKind(scene.sensor, frame.intrinsics));
}

absl::Span<const SegmentMethodRow> SegmentMethods() { return kSegmentMethods; }

const SegmentMethodRow* FindSegmentMethod(SegmentMethod method) {
  for (const SegmentMethodRow& row : kSegmentMethods) {
    if (row.method == method) return &row;
  }
  return nullptr;
}

std::string_view SegmentMethodName(SegmentMethod method) {
  const SegmentMethodRow* row = FindSegmentMethod(method);
  return row != nullptr ? row->name : "unknown";
}

absl::StatusOr<SegmentMethod> ParseSegmentMethod(std::string_view text) {
  std::vector<absl::string_view> known;
  for (const SegmentMethodRow& row : kSegmentMethods) {
    if (row.name == text) return row.method;
    known.push_back(AbslView(row.name));
  }
  return absl::InvalidArgumentError(
      absl::StrCat("unknown segmentation method '", AbslView(text),
                   "' (known: ", absl::StrJoin(known, ", "), ")"));
}

absl::Status Validate(const SegmentOptions& options) {
  if (absl::Status s = Validate(options.detect); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("detect: ", s.message()));
  }
  if (absl::Status s = Validate(options.cos); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("cos.", s.message()));
  }
  if (absl::Status s = Validate(options.ebs_contour); !s.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("ebs_contour.", s.message()));
  }
  if (options.max_objects < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "max_objects must not be negative, got ", options.max_objects));
  }
  if (!(options.min_object_area_m2 >= 0.0) ||
      !std::isfinite(options.min_object_area_m2)) {
    return absl::InvalidArgumentError(
        absl::StrCat("min_object_area_m2 must be finite and >= 0, got ",
                     options.min_object_area_m2));
  }
  if (options.seeds.size() > static_cast<size_t>(kMaxAttentionPoints)) {
    return absl::InvalidArgumentError(
        absl::StrCat("seeds: ", options.seeds.size(), " given, at most ",
                     kMaxAttentionPoints, " allowed"));
  }
  FOVEA_RETURN_IF_ERROR(Validate(options.box_fit));
  return Validate(options.object_points);
}

absl::StatusOr<SegmentSummary> RunSegment(const RgbdFrame& frame,
                                          const SegmentOptions& options,
                                          const SegmentModels& models,
                                          const SegmentSinks& sinks,
                                          const InterruptCheck& interrupt,
                                          SteadyClock::time_point start) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  for (const cv::Point& p : options.seeds) {
    if (p.x < 0 || p.y < 0 || p.x >= frame.width() || p.y >= frame.height()) {
      return absl::InvalidArgumentError(
          absl::StrCat("seeds: (", p.x, ", ", p.y, ") lies outside the ",
                       frame.width(), "x", frame.height(), " frame"));
    }
  }
  const SegmentMethodRow* method = FindSegmentMethod(options.method);
  if (method == nullptr) {
    return absl::InvalidArgumentError("segment: unknown method");
  }
  FOVEA_RETURN_IF_ERROR(method->create(nullptr, options, models).status());
  SegmentSummary summary;
  FOVEA_ASSIGN_OR_RETURN(PreparedScene scene,
                         PrepareScene(frame, options.detect, interrupt));
  summary.timings = scene.timings;
  if (sinks.support) {
    FOVEA_RETURN_IF_ERROR(
        sinks.support(PlaneToInput(scene.scale, scene.plane)));
  }

  // The cutter's scene does not depend on the seeds: with two threads it
  // is built while Detect runs (its time overlaps Detect's stages).
  absl::StatusOr<std::vector<AttentionPoint>> seeds;
  absl::StatusOr<std::unique_ptr<ObjectCutter>> cutter;
  double prepare_seconds = 0.0;
  ParallelInvoke(
      [&] { seeds = TakeSeeds(scene, options, interrupt, summary.timings); },
      [&] {
        const SteadyClock::time_point lap = SteadyClock::now();
        cutter = method->create(&scene, options, models);
        prepare_seconds = SecondsSince(lap);
      });
  FOVEA_RETURN_IF_ERROR(seeds.status());
  if (sinks.points) {
    FOVEA_RETURN_IF_ERROR(sinks.points(PointsToInput(scene.scale, *seeds)));
  }
  FOVEA_RETURN_IF_ERROR(CheckInterrupt(interrupt));
  FOVEA_RETURN_IF_ERROR(cutter.status());
  summary.timings.push_back({"segment.prepare", prepare_seconds});

  const cv::Mat region =
      ObjectRegion(scene.table, options.detect.table_scene.min_object_height);
  cv::Mat covered(region.size(), CV_8UC1, cv::Scalar(0));
  // Cuts the object at `seed`; false when it yields none to report. A cover
  // seed's object is what no earlier mask holds.
  const auto cut_and_send = [&](const AttentionPoint& seed, bool cover,
                                const char* stage) -> absl::StatusOr<bool> {
    const SteadyClock::time_point at = SteadyClock::now();
    FOVEA_ASSIGN_OR_RETURN(std::optional<CutObject> cut,
                           (*cutter)->Cut({seed.u, seed.v}, interrupt));
    summary.timings.push_back({stage, SecondsSince(at)});
    if (!cut.has_value()) return false;
    if (cover) cut->mask.setTo(0, covered);
    if (VisibleArea(scene.cloud, cut->mask) < options.min_object_area_m2 ||
        StandingShare(scene.table, cut->mask) < kMinStandingShare) {
      return false;  // a fragment, or not on the table
    }
    SegmentedObject object;
    object.seed = seed;
    object.mask = std::move(cut->mask);
    object.score = cut->score;
    DescribeObject(scene.cloud, object);
    DescribeGeometry(scene.cloud, scene.plane, options.box_fit,
                     options.object_points, object, object.box);
    covered.setTo(255, object.mask);
    ObjectToInput(scene.scale, object);
    ObjectIndicesToInput(options.object_points, object);
    object.index = summary.objects++;
    object.seconds_since_start = SecondsSince(start);
    if (sinks.object) {
      FOVEA_RETURN_IF_ERROR(sinks.object(std::move(object)));
    }
    return true;
  };
  const auto full = [&] {
    return options.max_objects > 0 && summary.objects >= options.max_objects;
  };
  for (const AttentionPoint& seed : *seeds) {
    if (full()) break;
    FOVEA_RETURN_IF_ERROR(CheckInterrupt(interrupt));
    if (absl::StatusOr<bool> sent = cut_and_send(seed, false, "segment.object");
        !sent.ok()) {
      return sent.status();
    }
  }
  if (options.cover_scene.value_or(options.seeds.empty())) {
    // Standing pixels off surface edges; each cover seed's piece is tried
    // once, so this ends after at most one seed per piece.
    cv::Mat tried =
        scene.surface_edges.empty()
            ? FindSurfaceEdges(scene.cloud, options.detect.surface_edges)
            : scene.surface_edges.clone();
    tried.setTo(255, scene.table.standing == 0);
    int cover_seeds = 0;
    while (!full() && cover_seeds < kMaxAttentionPoints) {
      FOVEA_RETURN_IF_ERROR(CheckInterrupt(interrupt));
      cv::Mat piece;
      const std::optional<cv::Point> at = CoverSeed(
          scene.cloud, ~(tried | covered), options.min_object_area_m2, piece);
      if (!at.has_value()) break;
      ++cover_seeds;
      tried.setTo(255, piece);
      AttentionPoint seed;
      seed.u = at->x;
      seed.v = at->y;
      const cv::Vec3f& q = scene.cloud.xyz.at<cv::Vec3f>(*at);
      seed.point = {q[0], q[1], q[2]};
      if (absl::StatusOr<bool> sent = cut_and_send(seed, true, "segment.cover");
          !sent.ok()) {
        return sent.status();
      }
    }
  }
  if (full()) summary.stop = SegmentStop::kMaxObjects;
  const int region_pixels = cv::countNonZero(region);
  summary.scene_coverage =
      region_pixels > 0
          ? static_cast<double>(cv::countNonZero(covered & region)) /
                region_pixels
          : 0.0;
  summary.total_seconds = SecondsSince(start);
  return summary;
}

absl::StatusOr<std::vector<SvmSample>> CollectCosSamples(
    const LabelledFrame& frame, int group, const DetectOptions& detect,
    const CosOptions& cos) {
  FOVEA_ASSIGN_OR_RETURN(PreparedScene scene,
                         PrepareScene(frame.frame, MeasuredDepthOnly(detect)));
  FOVEA_ASSIGN_OR_RETURN(
      CosScene cos_scene,
      BuildCosScene(scene.cloud, scene.plane, cos, scene.table.region));
  return CosTrainingSamples(cos_scene, frame.labels, group, cos);
}

}  // namespace fovea
