#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "core/base/parallel.h"
#include "core/frame/frame_decode.h"
#include "core/pipeline/detect.h"
#include "core/pipeline/incremental.h"
#include "core/pipeline/models.h"
#include "core/pipeline/object_geometry.h"
#include "core/pipeline/segment.h"
#include "tools/bench/bench_inputs.h"
#include "tools/bench/stages.h"

namespace fovea::bench {
namespace {

// FNV-1a, 64 bits: a change in any byte changes the digest.
class Digest {
 public:
  void Bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
      hash_ ^= p[i];
      hash_ *= 1099511628211ull;
    }
  }
  template <typename T>
  void Value(const T& value) {
    Bytes(&value, sizeof value);
  }
  void Mat(const cv::Mat& m) {
    Value(m.rows);
    Value(m.cols);
    Value(m.type());
    for (int r = 0; r < m.rows; ++r) {
      Bytes(m.ptr(r), m.cols * m.elemSize());
    }
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 14695981039346656037ull;
};

void AddPoint(const AttentionPoint& p, Digest& d) {
  d.Value(p.u);
  d.Value(p.v);
  d.Value(p.saliency);
}

void AddBox(const OrientedBox& box, Digest& d) {
  d.Value(box.center);
  d.Value(box.orientation.coeffs());
  d.Value(box.size);
}

void AddObject(const SegmentedObject& o, Digest& d) {
  AddPoint(o.seed, d);
  d.Mat(o.mask);
  d.Value(o.score);
  d.Value(o.geometry.has_value());
  if (o.geometry.has_value()) {
    const ObjectGeometry& g = *o.geometry;
    AddBox(g.box, d);
    d.Value(g.support_origin);
    d.Value(g.support_orientation.coeffs());
    AddBox(g.box_in_support, d);
    d.Value(g.height_above_support);
    d.Value(g.footprint_area_m2);
  }
}

struct DigestFlags {
  std::string set = "osd";
  int scenes = 0;
  int threads = 1;
};

}  // namespace

int RunDigestCommand(int argc, char** argv) {
  DigestFlags flags;
  for (int i = 2; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--set" && i + 1 < argc) {
      flags.set = argv[++i];
    } else if ((arg == "--scenes" || arg == "--threads") && i + 1 < argc) {
      int value = 0;
      if (!absl::SimpleAtoi(argv[++i], &value) || value < 1) {
        std::fprintf(stderr, "fovea-bench digest: %s: expected N >= 1\n",
                     std::string(arg).c_str());
        return 2;
      }
      (arg == "--scenes" ? flags.scenes : flags.threads) = value;
    } else {
      std::fprintf(stderr,
                   "usage: fovea-bench digest [--set osd|pile-15|"
                   "room-640x480|room-1920x1080] [--scenes N] [--threads N]\n");
      return 2;
    }
  }
  SceneList scenes;
  if (absl::Status s = LoadSceneSet(flags.set, flags.scenes, scenes); !s.ok()) {
    std::fprintf(stderr, "fovea-bench digest: %s\n", s.ToString().c_str());
    return 2;
  }
  const absl::StatusOr<LoadedModels> models =
      LoadModels(FOVEA_BENCH_MODELS_DIR);
  if (!models.ok()) {
    std::fprintf(stderr, "fovea-bench digest: %s\n",
                 models.status().ToString().c_str());
    return 1;
  }
  ThreadPool pool(flags.threads - 1);
  const ParallelScope scope(&pool, flags.threads);
  Digest all;
  for (const auto& scene : scenes) {
    const absl::StatusOr<RgbdFrame> frame =
        DecodeFrame(scene->raw_wire, BenchFrameLimits());
    if (!frame.ok()) {
      std::fprintf(stderr, "fovea-bench digest: %s: %s\n", scene->name.c_str(),
                   frame.status().ToString().c_str());
      return 1;
    }
    Digest detect, cos, inc;
    int objects[2] = {0, 0};
    const absl::StatusOr<DetectResult> result =
        RunDetect(*frame, DetectOptions{});
    if (result.ok()) {
      for (const AttentionPoint& p : result->points) AddPoint(p, detect);
      detect.Mat(result->master);
      detect.Value(result->plane.normal);
      detect.Value(result->plane.d);
      detect.Mat(result->plane.inliers);
    }
    for (int method = 0; method < 2; ++method) {
      Digest& d = method == 0 ? cos : inc;
      SegmentSinks sinks;
      sinks.object = [&](SegmentedObject object) {
        AddObject(object, d);
        ++objects[method];
        return absl::OkStatus();
      };
      const absl::StatusOr<SegmentSummary> summary =
          method == 0
              ? RunSegment(*frame, SegmentOptions{}, models->View(), sinks)
              : RunSegmentIncremental(
                    *frame, IncrementalOptions{},
                    models->View().IncFor(*frame, SceneOptions{}), sinks);
      d.Value(summary.ok());
    }
    const int points =
        result.ok() ? static_cast<int>(result->points.size()) : -1;
    std::printf(
        "%-24s detect %016llx (%2d points)  cos %016llx (%2d)  "
        "inc %016llx (%2d)\n",
        scene->name.c_str(), static_cast<unsigned long long>(detect.value()),
        points, static_cast<unsigned long long>(cos.value()), objects[0],
        static_cast<unsigned long long>(inc.value()), objects[1]);
    all.Value(detect.value());
    all.Value(cos.value());
    all.Value(inc.value());
  }
  std::printf("all %zu %s scenes: %016llx\n", scenes.size(), flags.set.c_str(),
              static_cast<unsigned long long>(all.value()));
  return 0;
}

}  // namespace fovea::bench
