#include "core/frame/frame_scale.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/base/check.h"

namespace fovea {
namespace {

int Clamp(long value, int size) {
  return static_cast<int>(std::clamp<long>(value, 0, size - 1));
}

}  // namespace

cv::Point FrameScale::ToProcessing(cv::Point p) const {
  if (!reduced()) return p;
  const int w =
      std::max(1, static_cast<int>(std::lround(input.width * factor)));
  const int h =
      std::max(1, static_cast<int>(std::lround(input.height * factor)));
  return {Clamp(std::lround((p.x + 0.5) * factor - 0.5), w),
          Clamp(std::lround((p.y + 0.5) * factor - 0.5), h)};
}

cv::Point FrameScale::ToInput(cv::Point q) const {
  if (!reduced()) return q;
  return {Clamp(std::lround((q.x + 0.5) / factor - 0.5), input.width),
          Clamp(std::lround((q.y + 0.5) / factor - 0.5), input.height)};
}

cv::Mat FrameScale::MaskToInput(const cv::Mat& mask) const {
  if (!reduced() || mask.empty()) return mask;
  // Each input pixel looks up the reduced pixel its centre falls in.
  std::vector<int> column(input.width);
  for (int x = 0; x < input.width; ++x) {
    column[x] =
        Clamp(static_cast<long>(std::floor((x + 0.5) * factor)), mask.cols);
  }
  cv::Mat out(input, CV_8UC1);
  for (int y = 0; y < input.height; ++y) {
    const int ry =
        Clamp(static_cast<long>(std::floor((y + 0.5) * factor)), mask.rows);
    const uint8_t* in = mask.ptr<uint8_t>(ry);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < input.width; ++x) o[x] = in[column[x]];
  }
  return out;
}

cv::Mat FrameScale::MapToInput(const cv::Mat& map) const {
  if (!reduced() || map.empty()) return map;
  cv::Mat out;
  cv::resize(map, out, input, 0, 0, cv::INTER_LINEAR);
  return out;
}

ReducedFrame ReduceForProcessing(const RgbdFrame& frame, int processing_width) {
  FOVEA_CHECK(processing_width > 0);
  ReducedFrame out;
  out.scale.input = frame.depth.size();
  if (frame.width() <= processing_width) {
    out.frame.color = frame.color;
    out.frame.depth = frame.depth;
    out.frame.intrinsics = frame.intrinsics;
    return out;
  }
  const double factor = static_cast<double>(processing_width) / frame.width();
  const cv::Size size(
      processing_width,
      std::max(1, static_cast<int>(std::lround(frame.height() * factor))));
  out.scale.factor = factor;
  cv::resize(frame.color, out.frame.color, size, 0, 0, cv::INTER_AREA);
  // Depth: the input pixel nearest the reduced pixel's centre.
  out.frame.depth.create(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y) {
    const int iy = Clamp(std::lround((y + 0.5) / factor - 0.5), frame.height());
    const float* in = frame.depth.ptr<float>(iy);
    float* o = out.frame.depth.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      o[x] = in[Clamp(std::lround((x + 0.5) / factor - 0.5), frame.width())];
    }
  }
  Intrinsics& k = out.frame.intrinsics;
  k.fx = frame.intrinsics.fx * factor;
  k.fy = frame.intrinsics.fy * factor;
  k.cx = (frame.intrinsics.cx + 0.5) * factor - 0.5;
  k.cy = (frame.intrinsics.cy + 0.5) * factor - 0.5;
  return out;
}

}  // namespace fovea
