#include "tools/eval/track_eval.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <opencv2/core.hpp>

#include "core/base/stage_clock.h"
#include "core/base/status_macros.h"
#include "core/eval/hungarian.h"
#include "core/pipeline/incremental.h"

namespace fovea::eval {
namespace {

// The truth objects of a frame with at least `min_pixels`: id -> mask.
std::map<int, cv::Mat> TruthMasks(const synth::SequenceFrame& frame,
                                  int min_pixels) {
  std::map<int, cv::Mat> masks;
  for (size_t k = 0; k < frame.object_ids.size(); ++k) {
    const int label = 10 * (static_cast<int>(k) + 2);
    cv::Mat mask = frame.frame.labels == label;
    if (cv::countNonZero(mask) >= min_pixels) {
      masks[frame.object_ids[k]] = mask;
    }
  }
  return masks;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

IdentityCounts CountIdentities(const std::vector<FrameIdentities>& frames) {
  IdentityCounts counts;
  int64_t truth_detections = 0;
  int64_t track_detections = 0;
  std::map<std::pair<int, int>, int64_t> together;
  std::map<int, int> truth_index;
  std::map<int, int> track_index;
  std::map<int, int> last_track;
  for (const FrameIdentities& f : frames) {
    truth_detections += f.truths;
    track_detections += f.tracks;
    for (const auto& [truth, track] : f.matched) {
      ++together[{truth, track}];
      truth_index.emplace(truth, static_cast<int>(truth_index.size()));
      track_index.emplace(track, static_cast<int>(track_index.size()));
      const auto last = last_track.find(truth);
      if (last != last_track.end() && last->second != track) ++counts.switches;
      last_track[truth] = track;
    }
  }
  std::vector<std::vector<double>> score(
      truth_index.size(), std::vector<double>(track_index.size(), 0.0));
  for (const auto& [pair, n] : together) {
    score[truth_index[pair.first]][track_index[pair.second]] =
        static_cast<double>(n);
  }
  const std::vector<int> assignment = MaxWeightAssignment(score);
  for (size_t i = 0; i < assignment.size(); ++i) {
    if (assignment[i] >= 0) {
      counts.idtp += static_cast<int64_t>(score[i][assignment[i]]);
    }
  }
  counts.idfn = truth_detections - counts.idtp;
  counts.idfp = track_detections - counts.idtp;
  counts.truth_frames = truth_detections;
  return counts;
}

double Idf1(const IdentityCounts& c) {
  const double denominator = 2.0 * c.idtp + c.idfp + c.idfn;
  return denominator == 0.0 ? 1.0 : 2.0 * c.idtp / denominator;
}

IdentityCounts& operator+=(IdentityCounts& a, const IdentityCounts& b) {
  a.idtp += b.idtp;
  a.idfp += b.idfp;
  a.idfn += b.idfn;
  a.switches += b.switches;
  a.truth_frames += b.truth_frames;
  return a;
}

FrameIdentities MatchFrame(const synth::SequenceFrame& frame,
                           const std::vector<TrackedObject>& objects,
                           int min_pixels) {
  FrameIdentities out;
  const std::map<int, cv::Mat> truths = TruthMasks(frame, min_pixels);
  out.truths = static_cast<int>(truths.size());
  for (const TrackedObject& o : objects) {
    if (o.state == TrackState::kGone || o.object.mask.empty()) continue;
    ++out.tracks;
    const double area = cv::countNonZero(o.object.mask);
    for (const auto& [id, mask] : truths) {
      const double both = cv::countNonZero(mask & o.object.mask);
      const double iou = both / (area + cv::countNonZero(mask) - both);
      if (iou >= 0.5) {
        out.matched.emplace_back(id, o.track_id);
        break;
      }
    }
  }
  return out;
}

double MeanBestF(const synth::SequenceFrame& frame,
                 const std::vector<cv::Mat>& masks, int min_pixels) {
  const std::map<int, cv::Mat> truths = TruthMasks(frame, min_pixels);
  if (truths.empty()) return 1.0;
  double sum = 0.0;
  for (const auto& [id, truth] : truths) {
    const double size = cv::countNonZero(truth);
    double best = 0.0;
    for (const cv::Mat& mask : masks) {
      const double both = cv::countNonZero(mask & truth);
      best = std::max(best, 2.0 * both / (size + cv::countNonZero(mask)));
    }
    sum += best;
  }
  return sum / static_cast<double>(truths.size());
}

absl::StatusOr<TrackFigures> EvaluateTracking(synth::SequenceKind kind,
                                              const TrackEvalOptions& options,
                                              const LoadedModels& models) {
  TrackFigures figures;
  figures.kind = std::string(NameOf(synth::SequenceKinds(), kind));
  std::vector<double> track_ms;
  std::vector<double> fresh_ms;
  double f_sum = 0.0;
  double fresh_f_sum = 0.0;
  int reused = 0;
  for (int s = 0; s < options.count; ++s) {
    const synth::Sequence sequence = synth::GenerateSequence(
        kind, options.seed + static_cast<uint64_t>(s), options.frames);
    Tracker tracker(options.tracker, models.inc ? &*models.inc : nullptr);
    std::vector<FrameIdentities> identities;
    for (const synth::SequenceFrame& frame : sequence.frames) {
      std::optional<Eigen::Isometry3f> pose;
      if (options.with_pose) pose = frame.camera_to_world;
      FOVEA_ASSIGN_OR_RETURN(TrackedFrame tracked,
                             tracker.Process(frame.frame.frame, pose));
      track_ms.push_back(tracked.seconds * 1e3);
      reused += tracked.reused ? 1 : 0;
      figures.joined += tracked.joined;
      identities.push_back(MatchFrame(frame, tracked.objects));
      std::vector<cv::Mat> masks;
      for (const TrackedObject& o : tracked.objects) {
        if (o.state != TrackState::kGone) masks.push_back(o.object.mask);
      }
      f_sum += MeanBestF(frame, masks);

      std::vector<cv::Mat> fresh;
      SegmentSinks sinks;
      sinks.object = [&fresh](SegmentedObject object) {
        fresh.push_back(std::move(object.mask));
        return absl::OkStatus();
      };
      const SteadyClock::time_point start = SteadyClock::now();
      FOVEA_RETURN_IF_ERROR(
          RunSegmentIncremental(frame.frame.frame, options.tracker.segment,
                                models.inc ? &*models.inc : nullptr, sinks)
              .status());
      fresh_ms.push_back(SecondsSince(start) * 1e3);
      fresh_f_sum += MeanBestF(frame, fresh);
      ++figures.frames;
    }
    figures.identities += CountIdentities(identities);
    ++figures.sequences;
  }
  if (figures.frames > 0) {
    figures.overlap_f = f_sum / figures.frames;
    figures.single_frame_f = fresh_f_sum / figures.frames;
    figures.reused_fraction = static_cast<double>(reused) / figures.frames;
  }
  figures.median_track_ms = Median(track_ms);
  figures.median_fresh_ms = Median(fresh_ms);
  return figures;
}

}  // namespace fovea::eval
