#ifndef FOVEA_TOOLS_EVAL_REALSENSE_FRAMES_H_
#define FOVEA_TOOLS_EVAL_REALSENSE_FRAMES_H_

// The four raw RealSense-like frames of shared/data/realsense: where the
// tests and `fovea-eval scorecard` find them, and their marked pixels; and
// the reading of any raw frame stored as `<name>_color.png` +
// `<name>_depth_mm.png` (these, the OSD folder's frames/). Header-only, so
// that tests and fovea-bench use it without linking the eval tool.

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/frame/rgbd_frame.h"

namespace fovea::eval {

// `root` ($FOVEA_REALSENSE_DIR when empty) when it holds points.json, else
// "" (tests skip).
inline std::string RealSenseDir(std::string root = "") {
  if (root.empty()) {
    const char* env = std::getenv("FOVEA_REALSENSE_DIR");
    if (env == nullptr) return "";
    root = env;
  }
  if (!std::filesystem::exists(std::filesystem::path(root) / "points.json")) {
    return "";
  }
  return root;
}

struct RealSenseFrame {
  std::string name;  // "rs0", ...
  RgbdFrame frame;
  std::vector<cv::Point> objects;    // one pixel on each object on the table
  std::vector<cv::Point> table;      // on the table's top
  std::vector<cv::Point> off_table;  // floor, chairs, other furniture
};

inline std::string ReadAll(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The numbers after `"key":` in `json` (the first occurrence).
inline double JsonNumber(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\"\\s*:\\s*([-0-9.eE+]+)");
  std::smatch m;
  return std::regex_search(json, m, re)
             ? std::stod(m[1].str())
             : std::numeric_limits<double>::quiet_NaN();
}

// [[u, v], ...] after `"key":` within `block`.
inline std::vector<cv::Point> JsonPixels(const std::string& block,
                                         const std::string& key) {
  std::vector<cv::Point> out;
  const std::regex list("\"" + key +
                        "\"\\s*:\\s*\\[((\\s*\\[[^\\]]*\\]\\s*,?)*)\\]");
  std::smatch m;
  if (!std::regex_search(block, m, list)) return out;
  const std::string inner = m[1].str();
  const std::regex pair("\\[\\s*(-?[0-9]+)\\s*,\\s*(-?[0-9]+)\\s*\\]");
  for (auto it = std::sregex_iterator(inner.begin(), inner.end(), pair);
       it != std::sregex_iterator(); ++it) {
    out.emplace_back(std::stoi((*it)[1].str()), std::stoi((*it)[2].str()));
  }
  return out;
}

// The raw frame `<name>_color.png` (8-bit colour) + `<name>_depth_mm.png`
// (16-bit millimetres, 0 = no depth) of `dir`, with intrinsics `k`;
// nullopt when either is missing or unreadable, or the depth is not 16-bit
// of the colour's size.
inline std::optional<RgbdFrame> ReadRawFrame(const std::filesystem::path& dir,
                                             const std::string& name,
                                             const Intrinsics& k) {
  const cv::Mat bgr = cv::imread((dir / (name + "_color.png")).string());
  const cv::Mat mm = cv::imread((dir / (name + "_depth_mm.png")).string(),
                                cv::IMREAD_UNCHANGED);
  if (bgr.empty() || mm.empty() || mm.type() != CV_16UC1 ||
      mm.size() != bgr.size()) {
    return std::nullopt;
  }
  RgbdFrame frame;
  cv::cvtColor(bgr, frame.color, cv::COLOR_BGR2RGB);
  mm.convertTo(frame.depth, CV_32FC1, 0.001);
  frame.depth.setTo(std::numeric_limits<float>::quiet_NaN(), mm == 0);
  frame.intrinsics = k;
  return frame;
}

// The RealSense folder's intrinsics (its camera_params.json).
inline Intrinsics RealSenseIntrinsics(const std::string& dir) {
  const std::string params =
      ReadAll(std::filesystem::path(dir) / "camera_params.json");
  return {JsonNumber(params, "fx"), JsonNumber(params, "fy"),
          JsonNumber(params, "x_offset"), JsonNumber(params, "y_offset")};
}

// The frames of `dir` (RealSenseDir()), in name order.
inline std::vector<RealSenseFrame> LoadRealSenseFrames(const std::string& dir) {
  const std::filesystem::path root(dir);
  const Intrinsics k = RealSenseIntrinsics(dir);
  const std::string points = ReadAll(root / "points.json");
  std::vector<RealSenseFrame> frames;
  const std::regex entry("\"(rs[0-9]+)\"\\s*:\\s*\\{([^}]*)\\}");
  for (auto it = std::sregex_iterator(points.begin(), points.end(), entry);
       it != std::sregex_iterator(); ++it) {
    RealSenseFrame f;
    f.name = (*it)[1].str();
    const std::string block = (*it)[2].str();
    f.objects = JsonPixels(block, "objects");
    f.table = JsonPixels(block, "table");
    f.off_table = JsonPixels(block, "off_table");
    std::optional<RgbdFrame> frame = ReadRawFrame(root, f.name, k);
    if (!frame) continue;
    f.frame = *std::move(frame);
    frames.push_back(std::move(f));
  }
  return frames;
}

}  // namespace fovea::eval

#endif  // FOVEA_TOOLS_EVAL_REALSENSE_FRAMES_H_
