#include "tools/eval/replay.h"

#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/fovea_client.h"
#include "client/rle.h"
#include "core/base/status_macros.h"
#include "core/eval/hungarian.h"
#include "fovea/v1/perception.pb.h"
#include "fovea/v1/track.pb.h"

namespace fovea::eval {
namespace {

namespace fs = std::filesystem;

absl::StatusOr<std::string> ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return absl::NotFoundError(absl::StrCat("cannot read ", path.string()));
  std::ostringstream data;
  data << in.rdbuf();
  return data.str();
}

absl::Status FromJson(const std::string& json,
                      google::protobuf::Message* message) {
  const auto status =
      google::protobuf::util::JsonStringToMessage(json, message);
  if (!status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("not a ", message->GetDescriptor()->full_name(), ": ",
                     std::string(status.message())));
  }
  return absl::OkStatus();
}

// The recorded frame's files put back into `frame` (compressed form).
absl::Status LoadFrame(const fs::path& record, v1::Frame& frame) {
  const fs::path jpeg = record / "color.jpg";
  absl::StatusOr<std::string> color =
      ReadFile(fs::exists(jpeg) ? jpeg : record / "color.png");
  if (!color.ok()) return color.status();
  absl::StatusOr<std::string> depth = ReadFile(record / "depth.png");
  if (!depth.ok()) return depth.status();
  frame.mutable_color()->set_compressed(*std::move(color));
  frame.mutable_depth()->set_compressed(*std::move(depth));
  return absl::OkStatus();
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

// The distance of two attention points, pixels.
double PixelDistance(const v1::AttentionPoint& a, const v1::AttentionPoint& b) {
  return std::hypot(static_cast<double>(a.u()) - static_cast<double>(b.u()),
                    static_cast<double>(a.v()) - static_cast<double>(b.v()));
}

// Attention points, recorded and now: matched one to one (nearest first,
// within point_match_px).
void ComparePoints(
    const google::protobuf::RepeatedPtrField<v1::AttentionPoint>& a,
    const google::protobuf::RepeatedPtrField<v1::AttentionPoint>& b,
    const ReplayOptions& options, ReplayResult& r) {
  r.recorded = a.size();
  r.now = b.size();
  std::vector<std::vector<double>> score(a.size(),
                                         std::vector<double>(b.size(), 0.0));
  for (int i = 0; i < a.size(); ++i) {
    for (int j = 0; j < b.size(); ++j) {
      const double d = PixelDistance(a[i], b[j]);
      // Closer scores higher; beyond the match distance, nothing.
      score[i][j] =
          d <= options.point_match_px ? options.point_match_px - d + 1.0 : 0.0;
    }
  }
  const std::vector<int> match = MaxWeightAssignment(score);
  double sum = 0.0;
  for (int i = 0; i < a.size(); ++i) {
    const int j = match.empty() ? -1 : match[i];
    if (j < 0 || score[i][j] <= 0.0) continue;
    const double d = PixelDistance(a[i], b[j]);
    ++r.matched;
    sum += d;
    r.max_shift_px = std::max(r.max_shift_px, d);
  }
  r.mean_shift_px = r.matched > 0 ? sum / r.matched : 0.0;
  r.lost = r.recorded - r.matched;
  r.found = r.now - r.matched;
}

double Iou(const client::ByteMask& a, const client::ByteMask& b) {
  if (a.width != b.width || a.height != b.height) return 0.0;
  int64_t both = 0, either = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    both += a.pixels[i] && b.pixels[i];
    either += a.pixels[i] || b.pixels[i];
  }
  return either > 0 ? static_cast<double>(both) / either : 1.0;
}

std::vector<client::ByteMask> Masks(
    const std::vector<v1::SegmentResponse>& messages) {
  std::vector<client::ByteMask> masks;
  for (const v1::SegmentResponse& m : messages) {
    if (!m.has_object()) continue;
    absl::StatusOr<client::ByteMask> mask =
        client::DecodeRle(m.object().mask());
    masks.push_back(mask.ok() ? *std::move(mask) : client::ByteMask{});
  }
  return masks;
}

// Masks, recorded and now, matched one to one on IoU (at least
// same_object_iou) over one or more frames.
struct MaskTally {
  int recorded = 0, now = 0, matched = 0;
  double sum_iou = 0.0, min_iou = 1.0;

  // Adds one frame's masks; returns, for each of `a`, its match in `b`
  // (-1: none).
  std::vector<int> Add(const std::vector<client::ByteMask>& a,
                       const std::vector<client::ByteMask>& b,
                       const ReplayOptions& options) {
    recorded += static_cast<int>(a.size());
    now += static_cast<int>(b.size());
    std::vector<std::vector<double>> iou(a.size(),
                                         std::vector<double>(b.size()));
    for (size_t i = 0; i < a.size(); ++i) {
      for (size_t j = 0; j < b.size(); ++j) iou[i][j] = Iou(a[i], b[j]);
    }
    const std::vector<int> match = MaxWeightAssignment(iou);
    std::vector<int> out(a.size(), -1);
    for (size_t i = 0; i < a.size(); ++i) {
      const int j = match.empty() ? -1 : match[i];
      if (j < 0 || iou[i][j] < options.same_object_iou) continue;
      out[i] = j;
      ++matched;
      sum_iou += iou[i][j];
      min_iou = std::min(min_iou, iou[i][j]);
    }
    return out;
  }

  void Into(ReplayResult& r) const {
    r.recorded = recorded;
    r.now = now;
    r.matched = matched;
    r.mean_iou = matched > 0 ? sum_iou / matched : (recorded == 0 ? 1.0 : 0.0);
    r.min_iou = matched > 0 ? min_iou : r.mean_iou;
    r.lost = recorded - matched;
    r.found = now - matched;
  }
};

// Objects, recorded and now: matched one to one on IoU (at least
// same_object_iou).
void CompareObjects(const std::vector<v1::SegmentResponse>& before,
                    const std::vector<v1::SegmentResponse>& after,
                    const ReplayOptions& options, ReplayResult& r) {
  MaskTally tally;
  tally.Add(Masks(before), Masks(after), options);
  tally.Into(r);
}

// A Track answer's objects in view (not gone): their masks and ids.
void TrackMasks(const v1::TrackResponse& response,
                std::vector<client::ByteMask>& masks,
                std::vector<uint64_t>& ids) {
  for (const v1::TrackedObject& o : response.objects()) {
    if (o.state() == v1::TRACK_STATE_GONE || !o.object().has_mask()) continue;
    absl::StatusOr<client::ByteMask> mask =
        client::DecodeRle(o.object().mask());
    masks.push_back(mask.ok() ? *std::move(mask) : client::ByteMask{});
    ids.push_back(o.track_id());
  }
}

// A recorded Track stream part sent again, lockstep, frame by frame: its
// objects compared frame by frame, and its identities (a matched pair of
// recorded and new track ids that differs from the pair seen before, on
// either side, counts a switch).
absl::Status ReplayTrack(const fs::path& record,
                         const std::string& options_json,
                         const std::vector<std::string>& response_lines,
                         client::FoveaClient& client, absl::Duration deadline,
                         const ReplayOptions& options, ReplayResult& r) {
  v1::TrackRequest opening;
  FOVEA_RETURN_IF_ERROR(FromJson(options_json, &opening));
  absl::StatusOr<std::string> frames_text = ReadFile(record / "frames.jsonl");
  if (!frames_text.ok()) return frames_text.status();
  const std::vector<std::string> frame_lines = Lines(*frames_text);
  if (frame_lines.size() != response_lines.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(frame_lines.size(), " frames but ", response_lines.size(),
                     " answers recorded"));
  }
  std::vector<v1::TrackFrame> frames(frame_lines.size());
  std::vector<v1::TrackResponse> before(frame_lines.size());
  for (size_t i = 0; i < frame_lines.size(); ++i) {
    v1::TrackRequest message;
    FOVEA_RETURN_IF_ERROR(FromJson(frame_lines[i], &message));
    FOVEA_RETURN_IF_ERROR(FromJson(response_lines[i], &before[i]));
    frames[i] = message.frame();
    const std::string n = std::to_string(i + 1);
    const fs::path jpeg = record / (n + "_color.jpg");
    absl::StatusOr<std::string> color =
        ReadFile(fs::exists(jpeg) ? jpeg : record / (n + "_color.png"));
    if (!color.ok()) return color.status();
    absl::StatusOr<std::string> depth = ReadFile(record / (n + "_depth.png"));
    if (!depth.ok()) return depth.status();
    v1::Frame& frame = *frames[i].mutable_frame();
    frame.mutable_color()->set_compressed(*std::move(color));
    frame.mutable_depth()->set_compressed(*std::move(depth));
  }
  std::vector<v1::TrackResponse> after;
  size_t next = 0;
  const absl::Status status = client.Track(
      opening.options(),
      [&]() -> std::optional<v1::TrackFrame> {
        if (next == frames.size()) return std::nullopt;
        return std::move(frames[next++]);
      },
      deadline,
      [&after](const v1::TrackResponse& response) {
        after.push_back(response);
      });
  MaskTally tally;
  // Recorded track id -> id now, and back: a pair that differs from the
  // one seen before, either way, is a switch.
  std::map<uint64_t, uint64_t> now_id, recorded_id;
  for (size_t i = 0; i < before.size(); ++i) {
    std::vector<client::ByteMask> a, b;
    std::vector<uint64_t> a_ids, b_ids;
    TrackMasks(before[i], a, a_ids);
    if (i < after.size()) TrackMasks(after[i], b, b_ids);
    const std::vector<int> match = tally.Add(a, b, options);
    for (size_t k = 0; k < a.size(); ++k) {
      if (match[k] < 0) continue;
      const uint64_t was = a_ids[k], now = b_ids[match[k]];
      auto [forward, new_forward] = now_id.emplace(was, now);
      auto [back, new_back] = recorded_id.emplace(now, was);
      if ((!new_forward && forward->second != now) ||
          (!new_back && back->second != was)) {
        ++r.id_switches;
      }
      forward->second = now;
      back->second = was;
    }
  }
  tally.Into(r);
  r.frames = static_cast<int>(before.size());
  r.frames_now = static_cast<int>(after.size());
  return status;
}

std::string CodeName(const absl::Status& status) {
  return absl::StatusCodeToString(status.code());
}

ReplayResult ReplayOne(const fs::path& record, client::FoveaClient& client,
                       const ReplayOptions& options) {
  ReplayResult r;
  r.record = record.filename().string();
  absl::StatusOr<std::string> meta_text = ReadFile(record / "meta.json");
  absl::StatusOr<std::string> request_text = ReadFile(record / "request.json");
  absl::StatusOr<std::string> responses_text =
      ReadFile(record / "responses.jsonl");
  if (!meta_text.ok() || !request_text.ok() || !responses_text.ok()) {
    r.error = "incomplete record";
    return r;
  }
  const nlohmann::json meta = nlohmann::json::parse(*meta_text, nullptr, false);
  if (meta.is_discarded() || !meta.contains("method")) {
    r.error = "meta.json is not JSON";
    return r;
  }
  r.method = meta.value("method", "");
  r.recorded_code = meta.value("code", "");
  r.recorded_ms = 1e3 * meta.value("seconds", 0.0);
  if (meta.value("frame", "") != "recorded") {
    r.error = "its frame was not recorded";
    return r;
  }
  const std::vector<std::string> lines = Lines(*responses_text);
  const absl::Duration deadline = absl::Seconds(options.deadline_s);
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed_ms = [&start] {
    return std::chrono::duration<double, std::milli>(
               std::chrono::steady_clock::now() - start)
        .count();
  };
  absl::Status status;
  if (r.method == "Detect") {
    v1::DetectRequest request;
    v1::DetectResponse before;
    status = FromJson(*request_text, &request);
    if (status.ok() && !lines.empty()) status = FromJson(lines[0], &before);
    if (status.ok()) status = LoadFrame(record, *request.mutable_frame());
    if (!status.ok()) {
      r.error = std::string(status.message());
      return r;
    }
    absl::StatusOr<v1::DetectResponse> after = client.Detect(request, deadline);
    r.now_ms = elapsed_ms();
    r.code = CodeName(after.status());
    ComparePoints(before.points(),
                  after.ok() ? after->points() : v1::DetectResponse().points(),
                  options, r);
  } else if (r.method == "Segment" || r.method == "SegmentIncremental") {
    std::vector<v1::SegmentResponse> before, after;
    for (const std::string& line : lines) {
      before.emplace_back();
      status.Update(FromJson(line, &before.back()));
    }
    const client::SegmentCallback collect =
        [&after](const v1::SegmentResponse& m) { after.push_back(m); };
    if (r.method == "Segment") {
      v1::SegmentRequest request;
      status.Update(FromJson(*request_text, &request));
      if (status.ok()) status = LoadFrame(record, *request.mutable_frame());
      if (status.ok())
        status = client.Segment(request, deadline, collect);
      else
        r.error = std::string(status.message());
    } else {
      v1::SegmentIncrementalRequest request;
      status.Update(FromJson(*request_text, &request));
      if (status.ok()) status = LoadFrame(record, *request.mutable_frame());
      if (status.ok()) {
        status = client.SegmentIncremental(request, deadline, collect);
      } else {
        r.error = std::string(status.message());
      }
    }
    if (!r.error.empty()) return r;
    r.now_ms = elapsed_ms();
    r.code = CodeName(status);
    CompareObjects(before, after, options, r);
  } else if (r.method == "Track") {
    status =
        ReplayTrack(record, *request_text, lines, client, deadline, options, r);
    if (status.code() == absl::StatusCode::kInvalidArgument ||
        status.code() == absl::StatusCode::kNotFound) {
      if (r.frames == 0) {  // the record, not the call, is at fault
        r.error = std::string(status.message());
        return r;
      }
    }
    r.now_ms = elapsed_ms();
    r.code = CodeName(status);
  } else {
    r.error = absl::StrCat("unknown method '", r.method, "'");
    return r;
  }
  r.changed = r.code != r.recorded_code || r.lost > 0 || r.found > 0 ||
              r.id_switches > 0 || r.frames_now != r.frames ||
              r.max_shift_px > options.changed_point_px ||
              r.min_iou < options.changed_iou;
  return r;
}

}  // namespace

absl::StatusOr<std::vector<ReplayResult>> ReplayRecords(
    const std::string& dir, const ReplayOptions& options) {
  std::error_code error;
  if (!fs::is_directory(dir, error)) {
    return absl::InvalidArgumentError(
        absl::StrCat("replay: ", dir, " is not a folder"));
  }
  static const std::regex kRecord(R"(^\d{8}-[A-Za-z]+$)");
  std::vector<fs::path> records;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, error)) {
    if (e.is_directory() &&
        std::regex_match(e.path().filename().string(), kRecord)) {
      records.push_back(e.path());
    }
  }
  std::sort(records.begin(), records.end());
  client::ClientOptions client_options;
  client_options.wait_for_ready = true;
  absl::StatusOr<std::unique_ptr<client::FoveaClient>> client =
      client::FoveaClient::Connect(options.server, client_options);
  if (!client.ok()) return client.status();
  std::vector<ReplayResult> results;
  for (const fs::path& record : records) {
    results.push_back(ReplayOne(record, **client, options));
  }
  return results;
}

int RunReplay(const std::string& dir, const ReplayOptions& options, bool json,
              bool fail_on_change) {
  if (dir.empty() || options.server.empty()) {
    std::fprintf(stderr,
                 "usage: fovea-eval replay DIR --server HOST:PORT [--json] "
                 "[--fail_on_change]\n");
    return 2;
  }
  absl::StatusOr<std::vector<ReplayResult>> results =
      ReplayRecords(dir, options);
  if (!results.ok()) {
    std::fprintf(stderr, "fovea-eval replay: %s\n",
                 results.status().ToString().c_str());
    return results.status().code() == absl::StatusCode::kInvalidArgument ? 2
                                                                         : 1;
  }
  int failed = 0, changed = 0, replayed = 0;
  if (!json) {
    std::printf("%-28s %-9s %-9s %11s %9s %12s %11s %15s\n", "record", "code",
                "(was)", "recorded/now", "lost/found", "shift px", "IoU",
                "ms (was/now)");
  }
  for (const ReplayResult& r : *results) {
    if (!r.error.empty()) {
      ++failed;
      if (json) {
        nlohmann::json line = {{"record", r.record}, {"error", r.error}};
        std::printf("%s\n", line.dump().c_str());
      } else {
        std::printf("%-28s not replayed: %s\n", r.record.c_str(),
                    r.error.c_str());
      }
      continue;
    }
    ++replayed;
    changed += r.changed;
    if (r.code != "OK" && r.recorded_code == "OK") ++failed;
    if (json) {
      nlohmann::json line = {{"record", r.record},
                             {"method", r.method},
                             {"code", r.code},
                             {"recorded_code", r.recorded_code},
                             {"recorded", r.recorded},
                             {"now", r.now},
                             {"matched", r.matched},
                             {"lost", r.lost},
                             {"found", r.found},
                             {"mean_shift_px", r.mean_shift_px},
                             {"max_shift_px", r.max_shift_px},
                             {"mean_iou", r.mean_iou},
                             {"min_iou", r.min_iou},
                             {"frames", r.frames},
                             {"frames_now", r.frames_now},
                             {"id_switches", r.id_switches},
                             {"recorded_ms", r.recorded_ms},
                             {"now_ms", r.now_ms},
                             {"changed", r.changed}};
      std::printf("%s\n", line.dump().c_str());
    } else {
      const bool points = r.method == "Detect";
      std::printf(
          "%-28s %-9s %-9s %5d / %-5d %4d / %-4d %12s %11s %7.1f / %-7.1f%s\n",
          r.record.c_str(), r.code.c_str(), r.recorded_code.c_str(), r.recorded,
          r.now, r.lost, r.found,
          points ? absl::StrFormat("%.1f (max %.1f)", r.mean_shift_px,
                                   r.max_shift_px)
                       .c_str()
                 : (r.method == "Track"
                        ? absl::StrFormat("%d id sw", r.id_switches).c_str()
                        : "-"),
          points
              ? "-"
              : absl::StrFormat("%.3f (%.2f)", r.mean_iou, r.min_iou).c_str(),
          r.recorded_ms, r.now_ms, r.changed ? "  CHANGED" : "");
    }
  }
  if (json) {
    nlohmann::json summary = {{"records", results->size()},
                              {"replayed", replayed},
                              {"changed", changed},
                              {"failed", failed}};
    std::printf("%s\n", summary.dump().c_str());
  } else {
    std::printf(
        "%zu records: %d replayed, %d changed, %d failed or not "
        "replayed\n",
        results->size(), replayed, changed, failed);
  }
  if (failed > 0) return 1;
  return fail_on_change && changed > 0 ? 3 : 0;
}

}  // namespace fovea::eval
