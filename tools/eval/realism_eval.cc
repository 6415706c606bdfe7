#include "tools/eval/realism_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/base/status_macros.h"
#include "core/pipeline/incremental.h"
#include "core/segmentation/cos.h"
#include "core/segmentation/inc.h"
#include "core/segmentation/relations.h"
#include "core/synth/room.h"
#include "core/synth/stacked_scene.h"
#include "core/synth/synth_scene.h"
#include "tools/eval/detect_eval.h"
#include "tools/eval/realsense_frames.h"

namespace fovea::eval {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Indices of plane_noise and plane_noise_depth in RealismStatisticNames().
constexpr size_t kNoiseIndex = 0, kNoiseDepthIndex = 1;
// The depth ranges of the noise table, metres.
constexpr double kRangeEdges[] = {0.4, 0.7, 0.9, 1.1, 1.4, 2.0};

double Median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

// Patches per labelled object: the non-support surfaces most of whose
// pixels carry it.
std::vector<double> PatchesPerObject(const IncScene& scene,
                                     const cv::Mat& labels) {
  const std::vector<int> object = PatchObjectIds(scene.surfaces, labels);
  std::vector<int> count;
  for (size_t k = 0; k < object.size(); ++k) {
    if (scene.surfaces.support[k] || object[k] <= 0) continue;
    if (object[k] >= static_cast<int>(count.size())) {
      count.resize(object[k] + 1, 0);
    }
    ++count[object[k]];
  }
  std::vector<double> out;
  for (const int c : count) {
    if (c > 0) out.push_back(c);
  }
  return out;
}

std::vector<NoiseAtRange> NoiseByRange(const RealismSet& real,
                                       const RealismSet& synthetic) {
  const auto sigmas = [](const RealismSet& s, double lo, double hi) {
    std::vector<double> out;
    if (s.statistics.size() <= kNoiseDepthIndex) return out;
    const std::vector<double>& k = s.statistics[kNoiseIndex];
    const std::vector<double>& z = s.statistics[kNoiseDepthIndex];
    for (size_t i = 0; i < k.size() && i < z.size(); ++i) {
      if (z[i] >= lo && z[i] < hi) out.push_back(k[i] * z[i] * z[i]);
    }
    return out;
  };
  std::vector<NoiseAtRange> rows;
  for (size_t b = 0; b + 1 < std::size(kRangeEdges); ++b) {
    NoiseAtRange row;
    row.min_z = kRangeEdges[b];
    row.max_z = kRangeEdges[b + 1];
    const std::vector<double> r = sigmas(real, row.min_z, row.max_z);
    const std::vector<double> s = sigmas(synthetic, row.min_z, row.max_z);
    row.real_cells = static_cast<int>(r.size());
    row.synthetic_cells = static_cast<int>(s.size());
    row.real_sigma = Median(r);
    row.synthetic_sigma = Median(s);
    rows.push_back(row);
  }
  return rows;
}

// The synthetic sets, by sensor.
struct SyntheticSet {
  std::string sensor, name;
  std::function<LabelledFrame(uint64_t seed)> render;
};

std::vector<SyntheticSet> SyntheticSets() {
  using synth::RoomSensor;
  return {
      {"kinect_v1", "random",
       [](uint64_t seed) { return synth::GenerateScene(seed).frame; }},
      {"kinect_v1", "piles",
       [](uint64_t seed) { return synth::GeneratePile(seed).frame; }},
      {"kinect_v1", "stacked",
       [](uint64_t seed) {
         return synth::GenerateStackedPile(seed, RoomSensor::kKinectV1)
             .scene.frame;
       }},
      {"active_stereo", "rooms",
       [](uint64_t seed) {
         synth::RoomOptions room;
         room.sensor = RoomSensor::kActiveStereo;
         return synth::GenerateRoom(seed, room).frame;
       }},
      {"active_stereo", "stacked",
       [](uint64_t seed) {
         return synth::GenerateStackedPile(seed, RoomSensor::kActiveStereo)
             .scene.frame;
       }},
  };
}

std::string Number(double x) {
  return std::isnan(x) ? "-" : absl::StrFormat("%.4g", x);
}

nlohmann::json JsonNumber(double x) {
  if (!std::isfinite(x)) return nullptr;
  return std::stod(absl::StrFormat("%.4g", x));
}

}  // namespace

absl::StatusOr<RealismSet> RealismOfFrames(
    const std::string& name, const std::vector<LabelledFrame>& frames,
    bool verbose) {
  const IncrementalOptions options;
  const DetectOptions detect = MeasuredDepthOnly(options.detect);
  const RealismOptions realism;
  RealismSet set;
  set.name = name;
  for (const LabelledFrame& f : frames) {
    absl::StatusOr<PreparedScene> scene = PrepareScene(f.frame, detect);
    if (!scene.ok()) {
      // A frame whose support is not found still counts as a frame (its
      // figures have no samples): how often that happens is part of how
      // the set looks.
      if (verbose) {
        std::fprintf(stderr, "realism %s %s: %s\n", name.c_str(),
                     f.name.c_str(), scene.status().ToString().c_str());
      }
      AddToSet(RealismSamples{}, set);
      continue;
    }
    const bool labelled =
        !f.labels.empty() && f.labels.size() == scene->cloud.xyz.size();
    AddToSet(CollectRealismSamples(scene->cloud, scene->plane, scene->table,
                                   labelled ? f.labels : cv::Mat(), realism),
             set);
    if (!labelled) continue;
    const cv::Mat flat(scene->cloud.xyz.size(), CV_32FC1, cv::Scalar(0));
    FOVEA_ASSIGN_OR_RETURN(IncScene inc,
                           BuildIncScene(scene->cloud, scene->plane, flat,
                                         options.inc, scene->table.region));
    for (SvmSample& s : IncTrainingSamples(inc, f.labels, 0)) {
      (s.label == 1 ? set.same_relations : set.different_relations)
          .push_back(std::move(s.x));
    }
    const std::vector<double> patches = PatchesPerObject(inc, f.labels);
    set.patches_per_object.insert(set.patches_per_object.end(), patches.begin(),
                                  patches.end());
    if (verbose) {
      std::fprintf(stderr, "realism %s %s: %zu patch counts\n", name.c_str(),
                   f.name.c_str(), patches.size());
    }
  }
  return set;
}

absl::StatusOr<std::vector<RealismComparison>> RunRealism(
    const RealismEvalOptions& options) {
  if (options.synthetic <= 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "realism: --synthetic must be positive, got ", options.synthetic));
  }
  struct RealSet {
    std::string sensor;
    RealismSet set;
  };
  std::vector<RealSet> reals;
  if (!options.osd_dir.empty()) {
    FOVEA_ASSIGN_OR_RETURN(std::vector<LabelledFrame> osd,
                           LoadScenes(options.osd_dir));
    FOVEA_ASSIGN_OR_RETURN(RealismSet set,
                           RealismOfFrames("osd", osd, options.verbose));
    reals.push_back({"kinect_v1", std::move(set)});
  }
  if (!options.realsense_dir.empty()) {
    std::vector<LabelledFrame> frames;
    for (RealSenseFrame& f : LoadRealSenseFrames(options.realsense_dir)) {
      frames.push_back({f.name, std::move(f.frame), cv::Mat()});
    }
    if (frames.empty()) {
      return absl::NotFoundError(absl::StrCat("realism: no RealSense frame in ",
                                              options.realsense_dir));
    }
    FOVEA_ASSIGN_OR_RETURN(
        RealismSet set, RealismOfFrames("realsense", frames, options.verbose));
    reals.push_back({"active_stereo", std::move(set)});
  }
  std::vector<RealismComparison> out;
  const std::vector<std::string>& relation_names = RelationFeatureNames();
  for (const SyntheticSet& synthetic : SyntheticSets()) {
    const RealSet* real = nullptr;
    for (const RealSet& r : reals) {
      if (r.sensor == synthetic.sensor) real = &r;
    }
    if (real == nullptr) continue;
    std::vector<LabelledFrame> frames;
    for (int k = 0; k < options.synthetic; ++k) {
      frames.push_back(synthetic.render(1 + k));
    }
    FOVEA_ASSIGN_OR_RETURN(
        RealismSet set,
        RealismOfFrames(synthetic.name, frames, options.verbose));
    RealismComparison c;
    c.sensor = synthetic.sensor;
    c.real = real->set.name;
    c.synthetic = synthetic.name;
    c.real_frames = real->set.frames;
    c.synthetic_frames = set.frames;
    c.rows = CompareRealism(real->set, set, relation_names);
    c.noise = NoiseByRange(real->set, set);
    out.push_back(std::move(c));
  }
  return out;
}

std::string RealismText(const std::vector<RealismComparison>& comparisons) {
  std::string text;
  for (const RealismComparison& c : comparisons) {
    absl::StrAppend(&text, "== ", c.sensor, ": ", c.real, " (", c.real_frames,
                    " frames) against synthetic ", c.synthetic, " (",
                    c.synthetic_frames, ")\n");
    for (const auto& [label, prefix] :
         std::vector<std::pair<std::string, std::string>>{
             {"all", ""},
             {"same-object relations", "same."},
             {"different-object relations", "different."}}) {
      const RealismSummary s = SummarizeRealism(c.rows, prefix);
      absl::StrAppend(&text, "  KS ", label, ": mean ", Number(s.mean_ks),
                      ", largest ", Number(s.max_ks), " (", s.worst, ")\n");
    }
    absl::StrAppend(&text,
                    "  depth noise on the support (median sigma, mm):\n"
                    "    range m     real (cells)    synthetic (cells)\n");
    for (const NoiseAtRange& n : c.noise) {
      absl::StrAppend(
          &text, absl::StrFormat(
                     "    %.1f-%.1f   %6s (%5d)    %6s (%5d)\n", n.min_z,
                     n.max_z, Number(n.real_sigma * 1000.0), n.real_cells,
                     Number(n.synthetic_sigma * 1000.0), n.synthetic_cells));
    }
    absl::StrAppend(&text,
                    "  statistic                          real median  "
                    "synthetic median   KS    (samples)\n");
    for (const RealismDistance& r : c.rows) {
      absl::StrAppend(
          &text,
          absl::StrFormat("  %-34s %11s  %16s  %5s  (%d / %d)\n", r.statistic,
                          Number(r.real_median), Number(r.synthetic_median),
                          Number(r.ks), r.real_samples, r.synthetic_samples));
    }
  }
  return text;
}

std::string RealismJson(const std::vector<RealismComparison>& comparisons) {
  nlohmann::json doc;
  doc["comparisons"] = nlohmann::json::array();
  for (const RealismComparison& c : comparisons) {
    nlohmann::json j;
    j["sensor"] = c.sensor;
    j["real"] = c.real;
    j["synthetic"] = c.synthetic;
    j["real_frames"] = c.real_frames;
    j["synthetic_frames"] = c.synthetic_frames;
    const RealismSummary all = SummarizeRealism(c.rows, "");
    j["mean_ks"] = JsonNumber(all.mean_ks);
    j["max_ks"] = JsonNumber(all.max_ks);
    j["worst"] = all.worst;
    j["noise"] = nlohmann::json::array();
    for (const NoiseAtRange& n : c.noise) {
      j["noise"].push_back(
          {{"min_z", n.min_z},
           {"max_z", n.max_z},
           {"real_cells", n.real_cells},
           {"synthetic_cells", n.synthetic_cells},
           {"real_sigma_m", JsonNumber(n.real_sigma)},
           {"synthetic_sigma_m", JsonNumber(n.synthetic_sigma)}});
    }
    j["rows"] = nlohmann::json::array();
    for (const RealismDistance& r : c.rows) {
      j["rows"].push_back({{"statistic", r.statistic},
                           {"real_samples", r.real_samples},
                           {"synthetic_samples", r.synthetic_samples},
                           {"real_median", JsonNumber(r.real_median)},
                           {"synthetic_median", JsonNumber(r.synthetic_median)},
                           {"ks", JsonNumber(r.ks)}});
    }
    doc["comparisons"].push_back(std::move(j));
  }
  return doc.dump();
}

}  // namespace fovea::eval
