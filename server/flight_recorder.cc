#include "server/flight_recorder.h"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <system_error>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "server/log.h"
#include "server/metrics.h"
#include "server/record_files.h"

namespace fovea::server {
namespace {

namespace fs = std::filesystem;

// The writer thread's nice value: the lowest priority there is.
constexpr int kWriterNice = 19;

// A record's folder name: the sequence on 8 digits, a dash, the method.
const std::regex& RecordName() {
  static const std::regex* const name =
      new std::regex(R"(^(\d{8})-([A-Za-z]+)$)");
  return *name;
}

// Everything a whole call's record holds, in memory.
RecordFiles MakeFiles(RecordedCall& call, int64_t sequence) {
  RecordFiles out;
  FrameFiles(*call.request, "", out);
  out.files.emplace_back("request.json", ToJson(*call.request) + "\n");
  std::string responses;
  for (const auto& response : call.responses) {
    absl::StrAppend(&responses, ToJson(*response), "\n");
  }
  out.files.emplace_back("responses.jsonl", std::move(responses));
  out.files.emplace_back(
      "meta.json",
      MetaJson(call.method, sequence, call.unix_micros, call.code, call.seconds,
               out.frame_problem.empty() ? "recorded" : "unreadable", ""));
  return out;
}

// Bytes of the files in a folder (not recursing).
int64_t FolderBytes(const fs::path& folder) {
  int64_t total = 0;
  std::error_code error;
  for (const fs::directory_entry& entry :
       fs::directory_iterator(folder, error)) {
    if (entry.is_regular_file(error)) total += entry.file_size(error);
  }
  return total;
}

int64_t ApproximateBytes(const RecordedCall& call) {
  int64_t bytes = call.request ? call.request->ByteSizeLong() : 0;
  if (call.frame) bytes += call.frame->ByteSizeLong();
  for (const auto& response : call.responses) bytes += response->ByteSizeLong();
  return bytes;
}

}  // namespace

absl::Status Validate(const RecorderConfig& config) {
  if (config.dir.empty()) {
    return absl::InvalidArgumentError("record_dir: empty");
  }
  if (config.max_bytes <= 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "record_max_mb: must be > 0, got ", config.max_bytes >> 20));
  }
  if (!(config.sample > 0.0 && config.sample <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("record_sample: must be in (0, 1], got ", config.sample));
  }
  if (config.track_part_frames < 1) {
    return absl::InvalidArgumentError("record: track_part_frames must be >= 1");
  }
  if (config.max_pending < 1 || config.max_pending_bytes < 1) {
    return absl::InvalidArgumentError(
        "record queue: max_pending and max_pending_bytes must be >= 1");
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<FlightRecorder>> FlightRecorder::Start(
    const RecorderConfig& config) {
  if (absl::Status s = Validate(config); !s.ok()) return s;
  std::unique_ptr<FlightRecorder> recorder(new FlightRecorder(config));
  if (absl::Status s = recorder->TakeStock(); !s.ok()) return s;
  recorder->writer_ = std::thread([r = recorder.get()] { r->Write(); });
  return recorder;
}

FlightRecorder::FlightRecorder(const RecorderConfig& config)
    : config_(config) {}

FlightRecorder::~FlightRecorder() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (writer_.joinable()) writer_.join();
}

absl::Status FlightRecorder::TakeStock() {
  std::error_code error;
  fs::create_directories(config_.dir, error);
  if (error) {
    return absl::InvalidArgumentError(absl::StrCat(
        "record_dir: cannot make ", config_.dir, ": ", error.message()));
  }
  std::vector<Record> found;
  for (const fs::directory_entry& entry :
       fs::directory_iterator(config_.dir, error)) {
    const std::string name = entry.path().filename().string();
    std::smatch match;
    if (!entry.is_directory(error)) continue;
    if (name.rfind(".tmp-", 0) == 0) {  // a record cut off half-written
      fs::remove_all(entry.path(), error);
      continue;
    }
    if (!std::regex_match(name, match, RecordName())) continue;
    found.push_back({std::stoll(match[1].str()), entry.path().string(),
                     FolderBytes(entry.path())});
  }
  if (error) {
    return absl::InvalidArgumentError(absl::StrCat(
        "record_dir: cannot read ", config_.dir, ": ", error.message()));
  }
  std::sort(found.begin(), found.end(), [](const Record& a, const Record& b) {
    return a.sequence < b.sequence;
  });
  std::lock_guard<std::mutex> lock(mutex_);
  for (Record& record : found) {
    total_bytes_ += record.bytes;
    next_sequence_ = record.sequence + 1;
    records_.push_back(std::move(record));
  }
  // Within this run's budget, which may be smaller than the last one's.
  while (!records_.empty() && total_bytes_ > config_.max_bytes) {
    fs::remove_all(records_.front().path, error);
    total_bytes_ -= records_.front().bytes;
    records_.pop_front();
  }
  SetRecorderBytes(total_bytes_);
  return absl::OkStatus();
}

bool FlightRecorder::ShouldRecord() {
  // Call i is recorded when floor(i * sample) steps up: exactly that
  // share, evenly spread.
  const uint64_t i = calls_seen_.fetch_add(1, std::memory_order_relaxed) + 1;
  return std::floor(i * config_.sample) > std::floor((i - 1) * config_.sample);
}

RecordedCall EndedCall(
    std::string method, std::unique_ptr<google::protobuf::Message> request,
    std::vector<std::unique_ptr<const google::protobuf::Message>> responses,
    absl::StatusCode code, double seconds) {
  RecordedCall call;
  call.method = std::move(method);
  call.request = std::move(request);
  call.responses = std::move(responses);
  call.code = absl::StatusCodeToString(code);
  call.seconds = seconds;
  call.unix_micros = absl::ToUnixMicros(absl::Now());
  return call;
}

void FlightRecorder::Submit(RecordedCall call) {
  const int64_t bytes = ApproximateBytes(call);
  // A stream's opening and end are small, and the part needs both.
  const bool always = call.stream != 0 && call.frame == nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_ ||
        (!always && (static_cast<int>(queue_.size()) >= config_.max_pending ||
                     (!queue_.empty() &&
                      queued_bytes_ + bytes > config_.max_pending_bytes)))) {
      RecordRecorderOutcome("queue_full");
      if (call.stream != 0) ++dropped_frames_[call.stream];
      return;
    }
    queued_bytes_ += bytes;
    queue_.push_back(std::move(call));
  }
  changed_.notify_all();
}

uint64_t FlightRecorder::NewStream() {
  return next_stream_.fetch_add(1, std::memory_order_relaxed);
}

void FlightRecorder::Flush() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return queue_.empty() && writing_ == 0; });
}

int64_t FlightRecorder::bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return total_bytes_;
}

void FlightRecorder::set_before_write_for_test(std::function<void()> hook) {
  std::lock_guard<std::mutex> lock(mutex_);
  before_write_ = std::move(hook);
}

void FlightRecorder::Write() {
  // The writer yields to the calls: a call never waits for the CPU behind
  // a record's PNG compression. (Linux keeps the nice value per thread;
  // raising it needs no privilege.) Under load the queue fills and calls
  // go unrecorded, counted, rather than slower.
  pthread_setname_np(pthread_self(), "fovea-recorder");
  if (setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)),
                  kWriterNice) != 0) {
    LogWarn("flight recorder: could not lower the writer's priority");
  }
  while (true) {
    RecordedCall call;
    std::function<void()> hook;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, nothing left
      call = std::move(queue_.front());
      queue_.pop_front();
      queued_bytes_ -= std::min(queued_bytes_, ApproximateBytes(call));
      writing_ = 1;
      hook = before_write_;
    }
    if (hook) hook();
    WriteOne(std::move(call));
    {
      std::lock_guard<std::mutex> lock(mutex_);
      writing_ = 0;
    }
    changed_.notify_all();
  }
}

bool FlightRecorder::MakeRoom(int64_t bytes) {
  std::error_code error;
  while (true) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (total_bytes_ + bytes <= config_.max_bytes) return true;
    }
    if (records_.empty()) return false;  // only open parts hold the rest
    fs::remove_all(records_.front().path, error);
    std::lock_guard<std::mutex> lock(mutex_);
    total_bytes_ -= records_.front().bytes;
    records_.pop_front();
    SetRecorderBytes(total_bytes_);
  }
}

void FlightRecorder::WriteOne(RecordedCall call) {
  if (call.stream != 0) {
    WriteStreamMessage(std::move(call));
    return;
  }
  const int64_t sequence = next_sequence_;
  const RecordFiles files = MakeFiles(call, sequence);
  const int64_t bytes = files.bytes();
  if (bytes > config_.max_bytes || !MakeRoom(bytes)) {
    RecordRecorderOutcome("too_large");
    return;
  }
  std::error_code error;
  const std::string name = absl::StrFormat("%08d-%s", sequence, call.method);
  const fs::path temporary = fs::path(config_.dir) / (".tmp-" + name);
  const fs::path final_path = fs::path(config_.dir) / name;
  fs::create_directories(temporary, error);
  bool ok = !error;
  for (const auto& [file, data] : files.files) {
    if (!ok) break;
    ok = WriteFile(temporary / file, data, false);
  }
  if (ok) fs::rename(temporary, final_path, error);
  if (!ok || error) {
    fs::remove_all(temporary, error);
    RecordRecorderOutcome("error");
    LogWarn(absl::StrCat("flight recorder: could not write ",
                         final_path.string(), "; call not recorded"));
    return;
  }
  next_sequence_ = sequence + 1;
  records_.push_back({sequence, final_path.string(), bytes});
  {
    std::lock_guard<std::mutex> lock(mutex_);
    total_bytes_ += bytes;
    SetRecorderBytes(total_bytes_);
  }
  RecordRecorderOutcome(files.frame_problem.empty() ? "written"
                                                    : "written_without_frame");
}

bool FlightRecorder::OpenNextPart(OpenPart& part) {
  part.sequence = next_sequence_++;
  part.frames = 0;
  part.dropped = 0;
  part.bytes = 0;
  part.path = (fs::path(config_.dir) /
               absl::StrFormat(".tmp-%08d-%s", part.sequence, part.method))
                  .string();
  std::error_code error;
  fs::create_directories(part.path, error);
  const std::string request = part.request_json + "\n";
  if (error || !MakeRoom(static_cast<int64_t>(request.size())) ||
      !WriteFile(fs::path(part.path) / "request.json", request, false)) {
    fs::remove_all(part.path, error);
    return false;
  }
  part.bytes = static_cast<int64_t>(request.size());
  std::lock_guard<std::mutex> lock(mutex_);
  total_bytes_ += part.bytes;
  SetRecorderBytes(total_bytes_);
  return true;
}

void FlightRecorder::ClosePart(OpenPart& part, const std::string& code,
                               double seconds, bool continues) {
  const std::string meta = MetaJson(
      part.method, part.sequence, absl::ToUnixMicros(absl::Now()), code,
      seconds, "recorded",
      absl::StrFormat(",\"part\":%d,\"frames\":%d,\"frames_dropped\":%d,"
                      "\"continues\":%s",
                      part.part, part.frames, part.dropped,
                      continues ? "true" : "false"));
  const fs::path temporary(part.path);
  const fs::path final_path =
      fs::path(config_.dir) /
      absl::StrFormat("%08d-%s", part.sequence, part.method);
  std::error_code error;
  bool ok = WriteFile(temporary / "meta.json", meta, false);
  // Both .jsonl files exist even when no frame was answered.
  ok = ok && WriteFile(temporary / "frames.jsonl", "", true) &&
       WriteFile(temporary / "responses.jsonl", "", true);
  if (ok) fs::rename(temporary, final_path, error);
  const int64_t written = part.bytes + static_cast<int64_t>(meta.size());
  std::lock_guard<std::mutex> lock(mutex_);
  if (!ok || error) {
    fs::remove_all(temporary, error);
    total_bytes_ -= part.bytes;
    SetRecorderBytes(total_bytes_);
    RecordRecorderOutcome("error");
    return;
  }
  total_bytes_ += static_cast<int64_t>(meta.size());
  SetRecorderBytes(total_bytes_);
  records_.push_back({part.sequence, final_path.string(), written});
  RecordRecorderOutcome("written");
}

void FlightRecorder::WriteStreamMessage(RecordedCall call) {
  auto found = open_parts_.find(call.stream);
  if (call.request) {  // the opening
    OpenPart part;
    part.method = call.method;
    part.request_json = ToJson(*call.request);
    if (OpenNextPart(part)) open_parts_[call.stream] = std::move(part);
    return;
  }
  if (found == open_parts_.end()) return;  // its opening was not written
  OpenPart& part = found->second;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto dropped = dropped_frames_.find(call.stream);
    if (dropped != dropped_frames_.end()) {
      part.dropped += dropped->second;
      dropped_frames_.erase(dropped);
    }
  }
  if (call.stream_end) {
    ClosePart(part, call.code, call.seconds, false);
    open_parts_.erase(found);
    return;
  }
  if (!call.frame) return;
  if (part.frames >= config_.track_part_frames) {
    ClosePart(part, "OK", 0.0, true);
    ++part.part;
    if (!OpenNextPart(part)) {
      open_parts_.erase(found);
      RecordRecorderOutcome("error");
      return;
    }
  }
  RecordFiles files;
  const int n = part.frames + 1;
  if (!FrameFiles(*call.frame, absl::StrCat(n, "_"), files)) {
    ++part.dropped;
    RecordRecorderOutcome("written_without_frame");
    return;
  }
  const std::string frame_line = ToJson(*call.frame) + "\n";
  const std::string response_line =
      call.responses.empty() ? "{}\n" : ToJson(*call.responses[0]) + "\n";
  const int64_t bytes = files.bytes() +
                        static_cast<int64_t>(frame_line.size()) +
                        static_cast<int64_t>(response_line.size());
  if (!MakeRoom(bytes)) {
    ++part.dropped;
    RecordRecorderOutcome("too_large");
    return;
  }
  const fs::path folder(part.path);
  bool ok = true;
  for (const auto& [file, data] : files.files) {
    ok = ok && WriteFile(folder / file, data, false);
  }
  ok = ok && WriteFile(folder / "frames.jsonl", frame_line, true) &&
       WriteFile(folder / "responses.jsonl", response_line, true);
  if (!ok) {
    ++part.dropped;
    RecordRecorderOutcome("error");
    return;
  }
  ++part.frames;
  part.bytes += bytes;
  std::lock_guard<std::mutex> lock(mutex_);
  total_bytes_ += bytes;
  SetRecorderBytes(total_bytes_);
}

}  // namespace fovea::server
