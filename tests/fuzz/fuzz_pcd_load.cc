// libFuzzer target: LoadOsdPcd on hostile PCD files.
//
// The input is written to a per-process file in the temporary folder and
// loaded with LoadOsdPcd, which reads it with ReadPcd (core/frame/
// pcd_reader: header, ASCII, binary and LZF-compressed bodies). Inputs
// above 1 MiB are refused by the target: LoadOsdPcd's header
// check, not the input size, must keep memory bounded, and a small body with
// a header claiming billions of points is the case that matters. Unorganized
// clouds are re-organized into 64 x 48 (Kinect intrinsics scaled by 1/10) to
// keep each run cheap. A loaded frame is checked against the header's
// contract; a breach aborts, which libFuzzer reports as a crash. With
// FOVEA_FUZZ_VERBOSE set, each input's outcome is printed.

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/frame/osd_pcd.h"

namespace {

constexpr size_t kMaxInputBytes = 1 << 20;
constexpr int kWidth = 64;
constexpr int kHeight = 48;
constexpr fovea::Intrinsics kIntrinsics{52.5, 52.5, 31.5, 23.5};

void Require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "fuzz_pcd_load: contract broken: %s\n", what);
    std::abort();
  }
}

const std::string& TempPath() {
  static const std::string* path = new std::string(
      (std::filesystem::temp_directory_path() /
       ("fovea_fuzz_pcd_load." + std::to_string(getpid()) + ".pcd"))
          .string());
  return *path;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  // The temporary file goes at a normal exit (not after a crash: it is the
  // crashing input, which libFuzzer also saves).
  std::atexit([] { std::remove(TempPath().c_str()); });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > kMaxInputBytes) return -1;
  const std::string& path = TempPath();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data),
              static_cast<std::streamsize>(size));
    Require(out.good(), "the temporary file is writable");
  }
  absl::StatusOr<fovea::LabelledFrame> loaded =
      fovea::LoadOsdPcd(path, kIntrinsics, kWidth, kHeight);
  if (std::getenv("FOVEA_FUZZ_VERBOSE") != nullptr) {
    std::fprintf(stderr, "fuzz_pcd_load: %s\n",
                 loaded.ok() ? "loaded" : loaded.status().ToString().c_str());
  }
  if (!loaded.ok()) {
    Require(loaded.status().code() == absl::StatusCode::kInvalidArgument ||
                loaded.status().code() == absl::StatusCode::kResourceExhausted,
            "errors are INVALID_ARGUMENT (or out of memory)");
    return 0;
  }
  const fovea::LabelledFrame& frame = *loaded;
  Require(frame.frame.depth.type() == CV_32FC1, "depth is CV_32FC1");
  Require(frame.frame.color.type() == CV_8UC3, "colour is CV_8UC3");
  Require(frame.labels.type() == CV_32SC1, "labels are CV_32SC1");
  Require(frame.frame.depth.size() == frame.frame.color.size() &&
              frame.frame.depth.size() == frame.labels.size(),
          "depth, colour and labels of one size");
  Require(!frame.frame.depth.empty(), "a non-empty frame");
  for (int v = 0; v < frame.frame.depth.rows; ++v) {
    const float* row = frame.frame.depth.ptr<float>(v);
    for (int u = 0; u < frame.frame.depth.cols; ++u) {
      Require(std::isnan(row[u]) || (row[u] > 0.0f && std::isfinite(row[u])),
              "depth is NaN or positive and finite");
    }
  }
  return 0;
}
