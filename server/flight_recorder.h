#ifndef FOVEA_SERVER_FLIGHT_RECORDER_H_
#define FOVEA_SERVER_FLIGHT_RECORDER_H_

#include <google/protobuf/message.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace fovea::server {

// The flight recorder: a bounded ring, on disk, of the calls the server
// served (requests with their frames, and what it answered), so that a
// robot's bad day can be sent again to a new server (fovea-eval replay)
// and turned into a regression test.
//
// Each recorded call is a folder DIR/<sequence, 8 digits>-<method>/:
//   meta.json        method, sequence, time, request id, code, seconds
//   request.json     the request (proto JSON) without its image bytes,
//                    its colour and depth described as the files below
//   color.png        the colour image (8-bit RGB; or color.jpg, as sent)
//   depth.png        the depth image, 16-bit grey in request.json's
//                    frame.depth_scale metres per unit (raw 16UC1 frames
//                    keep their units exactly; 32FC1 ones are stored at
//                    0.1 mm)
//   responses.jsonl  what the server sent, one proto JSON message a line
//
// A Track stream is handed over a message at a time (its opening, each
// frame answered, its end) and written as it goes, in parts of at most
// config.track_part_frames frames, so that no stream is ever held whole: each
// part is a folder <sequence>-Track/ whose request.json is the stream's
// options message, frames.jsonl the frames answered (TrackRequest, one a
// line, without their image bytes), <n>_color.png and <n>_depth.png their
// images, n counted from 1 in each part (the layout `fovea-client track
// --frames` reads), and responses.jsonl the answer to each frame, line for
// line. meta.json adds "part" (from 0), "frames", "frames_dropped" (frames
// answered but not recorded: the queue was full) and "continues" (the
// stream went on in the next part). A part appears when it is complete.
//
// Calls are handed over when they end (Submit) and written by one thread
// of the recorder's own: never on a call's path, and never blocking one (a
// call that finds the queue full is not recorded, and counted). The
// folder's files never take more than max_bytes: before a record is
// written, the oldest are deleted until it fits (a record larger than the
// whole budget is not written). Records appear whole (written under a
// temporary name, then renamed). A recorder started on a folder that
// holds records goes on after the last one, within the same budget.

struct RecorderConfig {
  std::string dir;                       // created if missing
  int64_t max_bytes = int64_t{1} << 30;  // the files' total, > 0
  // The share of calls recorded, (0, 1]: every 1/sample-th call, evenly.
  double sample = 1.0;
  // Calls waiting to be written, at most; past either, new ones are
  // dropped (fovea_recorder_records_total{outcome="queue_full"}).
  int max_pending = 8;
  int64_t max_pending_bytes = int64_t{128} << 20;
  // A stream's record holds at most this many frames; the stream goes on
  // in a new record (its next part).
  int track_part_frames = 64;
};

// INVALID_ARGUMENT naming the flag (record_dir, record_max_mb,
// record_sample).
absl::Status Validate(const RecorderConfig& config);

// One finished call, as handed to the recorder.
struct RecordedCall {
  // "Detect", "Segment", "SegmentIncremental", "Track"
  std::string method;
  // The request (a DetectRequest, SegmentRequest or
  // SegmentIncrementalRequest; a Track stream's options message) and the
  // messages sent, in order. The recorder owns the requests: it moves the
  // frames' pixels out of them into the record's image files instead of
  // copying them.
  std::unique_ptr<google::protobuf::Message> request;
  std::vector<std::unique_ptr<const google::protobuf::Message>> responses;
  // A stream's message (FlightRecorder::NewStream's id; 0 for a whole
  // call): its opening carries `request`; a frame carries `frame` and its
  // answer in `responses`; the end (stream_end) carries code and seconds.
  uint64_t stream = 0;
  std::unique_ptr<google::protobuf::Message> frame;
  bool stream_end = false;
  std::string code;         // the gRPC status code's name, "OK", ...
  double seconds = 0.0;     // the call's time on the server
  int64_t unix_micros = 0;  // when it ended
};

// A call that ends now with `code`, `seconds` after it started: its
// record, with the code's name and the time stamp filled in.
RecordedCall EndedCall(
    std::string method, std::unique_ptr<google::protobuf::Message> request,
    std::vector<std::unique_ptr<const google::protobuf::Message>> responses,
    absl::StatusCode code, double seconds);

class FlightRecorder {
 public:
  // Creates the folder, takes stock of the records in it (deleting
  // half-written ones) and starts the writer. Errors: Validate's; the
  // folder cannot be made or read (naming it).
  static absl::StatusOr<std::unique_ptr<FlightRecorder>> Start(
      const RecorderConfig& config);
  // Writes what is queued, then stops.
  ~FlightRecorder();
  FlightRecorder(const FlightRecorder&) = delete;
  FlightRecorder& operator=(const FlightRecorder&) = delete;

  // Whether the call starting now is one to record (config.sample of
  // them, evenly). Thread-safe and lock-free.
  bool ShouldRecord();

  // Hands a finished call, or a stream's message, over; returns at once.
  // Dropped (and counted) when the queue is full; a stream's opening and
  // end, which carry no frame, never are.
  void Submit(RecordedCall call);

  // An id for a stream to be recorded (RecordedCall::stream), > 0.
  uint64_t NewStream();

  // Blocks until every call submitted so far has been written or dropped
  // (tests, and shutdown).
  void Flush();

  // The files' total size now, bytes (<= config.max_bytes).
  int64_t bytes() const;

  // Test hook: runs on the writer thread before each record is written.
  void set_before_write_for_test(std::function<void()> hook);

 private:
  struct Record {
    int64_t sequence = 0;
    std::string path;
    int64_t bytes = 0;
  };
  explicit FlightRecorder(const RecorderConfig& config);
  absl::Status TakeStock();
  void Write();
  // A stream's part being written, in a temporary folder.
  struct OpenPart {
    int64_t sequence = 0;
    std::string method, path, request_json;
    int part = 0, frames = 0, dropped = 0;
    int64_t bytes = 0;
  };
  void WriteOne(RecordedCall call);
  void WriteStreamMessage(RecordedCall call);
  // Deletes the oldest records until `bytes` more fit; false when they
  // cannot.
  bool MakeRoom(int64_t bytes);
  // Opens the next part of `stream` (its folder and request.json).
  bool OpenNextPart(OpenPart& part);
  // Writes meta.json and publishes the part under its final name.
  void ClosePart(OpenPart& part, const std::string& code, double seconds,
                 bool continues);

  const RecorderConfig config_;
  std::atomic<uint64_t> calls_seen_{0};
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<RecordedCall> queue_;      // guarded by mutex_
  int64_t queued_bytes_ = 0;            // guarded by mutex_
  int writing_ = 0;                     // guarded by mutex_: 1 while writing
  bool stopping_ = false;               // guarded by mutex_
  std::function<void()> before_write_;  // guarded by mutex_
  // The writer's own (read by bytes() under mutex_).
  std::deque<Record> records_;
  int64_t total_bytes_ = 0;  // guarded by mutex_ (written by the writer)
  int64_t next_sequence_ = 1;
  std::atomic<uint64_t> next_stream_{1};
  std::map<uint64_t, OpenPart> open_parts_;  // the writer's own
  std::map<uint64_t, int> dropped_frames_;   // guarded by mutex_
  std::thread writer_;
};

}  // namespace fovea::server

#endif  // FOVEA_SERVER_FLIGHT_RECORDER_H_
