#ifndef FOVEA_SERVER_RECORD_FILES_H_
#define FOVEA_SERVER_RECORD_FILES_H_

#include <google/protobuf/message.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace fovea::server {

// The files of a flight record (server/flight_recorder.h): what a request's
// frame becomes on disk, the JSON of its messages and meta.json.

// The files of one record, names and contents, or why the frame could not
// be kept.
struct RecordFiles {
  std::vector<std::pair<std::string, std::string>> files;
  std::string frame_problem;
  int64_t bytes() const {
    int64_t total = 0;
    for (const auto& [name, data] : files) total += data.size();
    return total;
  }
};

// `message` as proto JSON with the proto's field names ("{}" when it
// cannot be printed).
std::string ToJson(const google::protobuf::Message& message);

// The image files of the frame `request` carries (its `frame` field, or a
// TrackRequest's frame.frame), named `prefix` + color.png / color.jpg /
// depth.png: the colour as sent when compressed, else an RGB PNG; the depth
// a 16-bit PNG (16UC1 in its own units, 32FC1 at 0.1 mm), the request's
// depth_scale set to match. The pixels go out of the request into the
// files. False, with out.frame_problem set and the pixels dropped, when they
// cannot be kept; true, adding nothing, when the request has no frame.
bool FrameFiles(google::protobuf::Message& request, const std::string& prefix,
                RecordFiles& out);

// meta.json: method, sequence, unix_micros, code, seconds and frame
// ("recorded" or "unreadable"), then `more` (",\"key\":value..." or empty).
std::string MetaJson(const std::string& method, int64_t sequence,
                     int64_t unix_micros, const std::string& code,
                     double seconds, const std::string& frame,
                     const std::string& more);

// Writes `data` to `path` (appending with `append`); false on failure.
bool WriteFile(const std::filesystem::path& path, const std::string& data,
               bool append);

}  // namespace fovea::server

#endif  // FOVEA_SERVER_RECORD_FILES_H_
