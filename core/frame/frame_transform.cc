#include "core/frame/frame_transform.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <string>

namespace fovea {
namespace {

int Turns(int quarter_turns) { return ((quarter_turns % 4) + 4) % 4; }

}  // namespace

cv::Mat RotateImage(const cv::Mat& image, int quarter_turns) {
  cv::Mat out;
  switch (Turns(quarter_turns)) {
    case 0:
      out = image.clone();
      break;
    case 1:
      cv::rotate(image, out, cv::ROTATE_90_CLOCKWISE);
      break;
    case 2:
      cv::rotate(image, out, cv::ROTATE_180);
      break;
    default:
      cv::rotate(image, out, cv::ROTATE_90_COUNTERCLOCKWISE);
      break;
  }
  return out;
}

RgbdFrame RotateFrame(const RgbdFrame& frame, int quarter_turns) {
  RgbdFrame out;
  out.color = RotateImage(frame.color, quarter_turns);
  out.depth = RotateImage(frame.depth, quarter_turns);
  const Intrinsics& k = frame.intrinsics;
  const double w = frame.width();
  const double h = frame.height();
  switch (Turns(quarter_turns)) {
    case 0:
      out.intrinsics = k;
      break;
    case 1:  // (u, v) -> (h - 1 - v, u)
      out.intrinsics = {k.fy, k.fx, h - 1.0 - k.cy, k.cx};
      break;
    case 2:  // (u, v) -> (w - 1 - u, h - 1 - v)
      out.intrinsics = {k.fx, k.fy, w - 1.0 - k.cx, h - 1.0 - k.cy};
      break;
    default:  // (u, v) -> (v, w - 1 - u)
      out.intrinsics = {k.fy, k.fx, k.cy, w - 1.0 - k.cx};
      break;
  }
  return out;
}

RgbdFrame HalveFrame(const RgbdFrame& frame) {
  const int w = frame.width() / 2;
  const int h = frame.height() / 2;
  RgbdFrame out;
  out.depth.create(h, w, CV_32FC1);
  out.color.create(h, w, CV_8UC3);
  for (int v = 0; v < h; ++v) {
    const float* z = frame.depth.ptr<float>(2 * v);
    const cv::Vec3b* c0 = frame.color.ptr<cv::Vec3b>(2 * v);
    const cv::Vec3b* c1 = frame.color.ptr<cv::Vec3b>(2 * v + 1);
    float* zo = out.depth.ptr<float>(v);
    cv::Vec3b* co = out.color.ptr<cv::Vec3b>(v);
    for (int u = 0; u < w; ++u) {
      zo[u] = z[2 * u];
      for (int ch = 0; ch < 3; ++ch) {
        const int sum = c0[2 * u][ch] + c0[2 * u + 1][ch] + c1[2 * u][ch] +
                        c1[2 * u + 1][ch];
        co[u][ch] = static_cast<uchar>((sum + 2) / 4);
      }
    }
  }
  const Intrinsics& k = frame.intrinsics;
  out.intrinsics = {k.fx / 2.0, k.fy / 2.0, k.cx / 2.0, k.cy / 2.0};
  return out;
}

cv::Mat HalveLabels(const cv::Mat& labels) {
  const int w = labels.cols / 2;
  const int h = labels.rows / 2;
  cv::Mat out(h, w, labels.type());
  const size_t elem = labels.elemSize();
  for (int v = 0; v < h; ++v) {
    const uchar* in = labels.ptr(2 * v);
    uchar* o = out.ptr(v);
    for (int u = 0; u < w; ++u) {
      std::copy(in + 2 * u * elem, in + (2 * u + 1) * elem, o + u * elem);
    }
  }
  return out;
}

LabelledFrame RotateLabelledFrame(const LabelledFrame& frame,
                                  int quarter_turns) {
  LabelledFrame out;
  const int turns = Turns(quarter_turns);
  out.name = turns == 0 ? frame.name
                        : frame.name + "-rot" + std::to_string(90 * turns);
  out.frame = RotateFrame(frame.frame, quarter_turns);
  out.labels = RotateImage(frame.labels, quarter_turns);
  return out;
}

LabelledFrame HalveLabelledFrame(const LabelledFrame& frame) {
  LabelledFrame out;
  out.name = frame.name + "-half";
  out.frame = HalveFrame(frame.frame);
  out.labels = HalveLabels(frame.labels);
  return out;
}

}  // namespace fovea
