#include "core/pipeline/detect.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/saliency/saliency_map.h"

namespace fovea {
namespace {

// Debian 12's abseil has its own string_view (ABSL_OPTION_USE_STD_STRING_VIEW
// is 0), which StrCat and StrSplit need.
absl::string_view Abs(std::string_view s) { return {s.data(), s.size()}; }

struct NamedOp {
  SaliencyOp op;
  std::string_view name;
};
constexpr NamedOp kOps[] = {
    {SaliencyOp::kPh, "ph"},
    {SaliencyOp::kSh, "sh"},
    {SaliencyOp::kRso, "rso"},
    {SaliencyOp::kSym3d, "sym3d"},
    {SaliencyOp::kItti, "itti"},
    {SaliencyOp::kHarel, "harel"},
    {SaliencyOp::kHou, "hou"},
    {SaliencyOp::kKootstra, "kootstra"},
    {SaliencyOp::kTargetColor, "target-color"},
    {SaliencyOp::kLocationPrior, "location-prior"},
};

bool IsImplemented(SaliencyOp op) {
  return op == SaliencyOp::kPh || op == SaliencyOp::kSh ||
         op == SaliencyOp::kRso;
}

// Wall-clock stage timer that appends to the result's timings.
class StageClock {
 public:
  explicit StageClock(std::vector<StageTiming>& timings)
      : timings_(timings), start_(Clock::now()) {}
  void Lap(std::string stage) {
    const Clock::time_point now = Clock::now();
    timings_.push_back({std::move(stage),
                        std::chrono::duration<double>(now - start_).count()});
    start_ = now;
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::vector<StageTiming>& timings_;
  Clock::time_point start_;
};

absl::Status Check(const InterruptCheck& interrupt) {
  return interrupt ? interrupt() : absl::OkStatus();
}

absl::StatusOr<cv::Mat> ComputeChannel(SaliencyOp op,
                                       const OrganizedCloud& cloud,
                                       const SupportPlane& plane,
                                       const TableScene& scene,
                                       const DetectOptions& options) {
  switch (op) {
    case SaliencyOp::kPh:
      return ComputePhSaliency(scene, options.ph);
    case SaliencyOp::kSh:
      return ComputeShSaliency(cloud, plane, scene, options.sh);
    case SaliencyOp::kRso:
      return ComputeRsoSaliency(cloud, plane, scene, options.rso);
    default:
      return absl::UnimplementedError(absl::StrCat(
          "saliency '", Abs(SaliencyOpName(op)), "' is not implemented yet"));
  }
}

// Weighted sum (eq. 2.42-2.43) or maximum (eq. 2.44) of the channels.
cv::Mat Fuse(const std::vector<NamedMap>& maps,
             const std::vector<WeightedChannel>& channels, FusionKind fusion) {
  cv::Mat master = cv::Mat::zeros(maps[0].map.size(), CV_32FC1);
  double total = 0.0;
  for (const WeightedChannel& c : channels) total += c.weight;
  for (size_t i = 0; i < maps.size(); ++i) {
    if (fusion == FusionKind::kMax) {
      cv::max(master, maps[i].map, master);
    } else {
      const double w =
          total > 0.0 ? channels[i].weight / total : 1.0 / channels.size();
      cv::scaleAdd(maps[i].map, w, master, master);
    }
  }
  NormalizeLinear(master);
  return master;
}

void FillPoints(const OrganizedCloud& cloud,
                std::vector<AttentionPoint>& points) {
  for (AttentionPoint& p : points) {
    const cv::Vec3f& q = cloud.xyz.at<cv::Vec3f>(p.v, p.u);
    p.point = {q[0], q[1], q[2]};
  }
}

}  // namespace

std::string_view SaliencyOpName(SaliencyOp op) {
  for (const NamedOp& n : kOps) {
    if (n.op == op) return n.name;
  }
  return "unknown";
}

std::string_view ExtractionName(ExtractionKind kind) {
  switch (kind) {
    case ExtractionKind::kMsr:
      return "msr";
    case ExtractionKind::kWta:
      return "wta";
    case ExtractionKind::kTj:
      return "tj";
  }
  return "unknown";
}

absl::StatusOr<std::vector<SaliencyOp>> ParseSaliencyOps(
    std::string_view text) {
  std::vector<SaliencyOp> ops;
  for (absl::string_view part : absl::StrSplit(Abs(text), '+')) {
    bool found = false;
    for (const NamedOp& n : kOps) {
      if (Abs(n.name) == part) {
        ops.push_back(n.op);
        found = true;
        break;
      }
    }
    if (!found) {
      return absl::InvalidArgumentError(absl::StrCat(
          "saliency: unknown operator '", part,
          "' (known: ph sh rso sym3d itti harel hou kootstra target-color "
          "location-prior, combined with '+')"));
    }
  }
  return ops;
}

absl::StatusOr<ExtractionKind> ParseExtraction(std::string_view text) {
  if (text == "msr") return ExtractionKind::kMsr;
  if (text == "wta") return ExtractionKind::kWta;
  if (text == "tj") return ExtractionKind::kTj;
  return absl::InvalidArgumentError(absl::StrCat(
      "extract: unknown strategy '", Abs(text), "' (known: msr wta tj)"));
}

absl::Status Validate(const DetectOptions& options) {
  if (options.channels.empty()) {
    return absl::InvalidArgumentError("options.saliency: no channel given");
  }
  for (size_t i = 0; i < options.channels.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (options.channels[j].op == options.channels[i].op) {
        return absl::InvalidArgumentError(absl::StrCat(
            "options.saliency: '", Abs(SaliencyOpName(options.channels[i].op)),
            "' is given more than once; give each operator once with its "
            "weight"));
      }
    }
  }
  for (const WeightedChannel& c : options.channels) {
    if (!(c.weight >= 0.0f) || !std::isfinite(c.weight)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "options.saliency: weight of '", Abs(SaliencyOpName(c.op)),
          "' must be finite and >= 0, got ", c.weight));
    }
    if (!IsImplemented(c.op)) {
      return absl::UnimplementedError(absl::StrCat("options.saliency: '",
                                                   Abs(SaliencyOpName(c.op)),
                                                   "' is not implemented yet"));
    }
  }
  if (options.max_points < 1 || options.max_points > kMaxAttentionPoints) {
    return absl::InvalidArgumentError(
        absl::StrCat("options.max_points must be in [1, ", kMaxAttentionPoints,
                     "], got ", options.max_points));
  }
  if (options.pyramid != PyramidKind::kNone) {
    return absl::UnimplementedError(
        "options.pyramid: SIMPLE and ITTI pyramids are not implemented yet");
  }
  if (options.normalization != NormalizationKind::kLin) {
    return absl::UnimplementedError(
        "options.normalization: NMS and NLM are not implemented yet");
  }
  if (options.extraction != ExtractionKind::kMsr) {
    return absl::UnimplementedError(absl::StrCat(
        "options.extraction: '", Abs(ExtractionName(options.extraction)),
        "' is not implemented yet"));
  }
  if (absl::Status s = Validate(options.hole_filling); !s.ok()) return s;
  if (absl::Status s = Validate(options.normals); !s.ok()) return s;
  if (absl::Status s = Validate(options.support_plane); !s.ok()) return s;
  if (absl::Status s = Validate(options.table_scene); !s.ok()) return s;
  if (absl::Status s = Validate(options.ph); !s.ok()) return s;
  if (absl::Status s = Validate(options.sh); !s.ok()) return s;
  if (absl::Status s = Validate(options.rso); !s.ok()) return s;
  return Validate(options.msr);
}

namespace {
absl::StatusOr<DetectResult> RunDetectUnguarded(
    const RgbdFrame& frame, const DetectOptions& options,
    const InterruptCheck& interrupt);
}  // namespace

std::vector<std::string> DetectStageNames() {
  std::vector<std::string> names = {"fill_holes", "cloud", "normals",
                                    "support_plane", "fusion"};
  for (const NamedOp& n : kOps) {
    if (IsImplemented(n.op)) {
      names.push_back(absl::StrCat("saliency.", Abs(n.name)));
    }
  }
  for (ExtractionKind kind :
       {ExtractionKind::kMsr, ExtractionKind::kWta, ExtractionKind::kTj}) {
    DetectOptions probe;
    probe.extraction = kind;
    if (Validate(probe).ok()) {
      names.push_back(absl::StrCat("extract.", Abs(ExtractionName(kind))));
    }
  }
  return names;
}

absl::StatusOr<DetectResult> RunDetect(const RgbdFrame& frame,
                                       const DetectOptions& options,
                                       const InterruptCheck& interrupt) {
  // Nothing throws out of core/: OpenCV and the standard library can.
  try {
    return RunDetectUnguarded(frame, options, interrupt);
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError("detect: out of memory");
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("detect: ", e.what()));
  }
}

namespace {

// RunDetect without the exception guard.
absl::StatusOr<DetectResult> RunDetectUnguarded(
    const RgbdFrame& frame, const DetectOptions& options,
    const InterruptCheck& interrupt) {
  if (absl::Status s = Validate(options); !s.ok()) return s;
  const auto start = std::chrono::steady_clock::now();
  DetectResult result;
  StageClock clock(result.timings);

  RgbdFrame filled_frame;
  const RgbdFrame* input = &frame;
  if (options.fill_holes) {
    absl::StatusOr<FilledDepth> filled =
        FillDepthHoles(frame, options.hole_filling);
    if (!filled.ok()) return filled.status();
    filled_frame.color = frame.color;  // shares the pixels
    filled_frame.depth = std::move(filled->depth);
    filled_frame.intrinsics = frame.intrinsics;
    input = &filled_frame;
    clock.Lap("fill_holes");
  }
  OrganizedCloud cloud = BackProject(*input);
  clock.Lap("cloud");
  EstimateNormals(options.normals, cloud);
  clock.Lap("normals");
  if (absl::Status s = Check(interrupt); !s.ok()) return s;

  absl::StatusOr<SupportPlane> plane =
      FindSupportPlane(cloud, options.support_plane);
  if (!plane.ok()) return plane.status();
  const TableScene scene =
      PrepareTableScene(cloud, *plane, options.table_scene);
  clock.Lap("support_plane");
  if (absl::Status s = Check(interrupt); !s.ok()) return s;

  std::vector<NamedMap> maps;
  for (const WeightedChannel& c : options.channels) {
    absl::StatusOr<cv::Mat> map =
        ComputeChannel(c.op, cloud, *plane, scene, options);
    if (!map.ok()) return map.status();
    maps.push_back({std::string(SaliencyOpName(c.op)), *std::move(map)});
    clock.Lap(absl::StrCat("saliency.", Abs(SaliencyOpName(c.op))));
    if (absl::Status s = Check(interrupt); !s.ok()) return s;
  }
  result.master = Fuse(maps, options.channels, options.fusion);
  clock.Lap("fusion");

  absl::StatusOr<std::vector<AttentionPoint>> points =
      ExtractMsrPoints(result.master, options.max_points, options.msr);
  if (!points.ok()) return points.status();
  result.points = *std::move(points);
  FillPoints(cloud, result.points);
  clock.Lap(absl::StrCat("extract.", Abs(ExtractionName(options.extraction))));

  if (options.keep_channel_maps) result.channel_maps = std::move(maps);
  result.plane = *std::move(plane);
  result.total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return result;
}

}  // namespace

}  // namespace fovea
