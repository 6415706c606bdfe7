#include "core/track/region.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/track/object_ops.h"

namespace fovea {

std::optional<cv::Rect> RegionToSegment(const cv::Mat& changed,
                                        const std::vector<cv::Rect>& held,
                                        const RegionOptions& options) {
  if (changed.empty() || cv::countNonZero(changed) == 0) return std::nullopt;
  const cv::Rect frame(0, 0, changed.cols, changed.rows);
  const double scale = changed.cols / 640.0;
  const int margin = static_cast<int>(std::lround(options.margin_px * scale));
  cv::Rect region = Grown(cv::boundingRect(changed), margin) & frame;
  // At least the smallest size, grown about its centre and kept within the
  // frame.
  const int min_w = std::min(
      frame.width, static_cast<int>(std::ceil(options.min_size.width * scale)));
  const int min_h =
      std::min(frame.height,
               static_cast<int>(std::ceil(options.min_size.height * scale)));
  if (region.width < min_w) {
    const int x = std::clamp(region.x + region.width / 2 - min_w / 2, 0,
                             frame.width - min_w);
    region.x = x;
    region.width = min_w;
  }
  if (region.height < min_h) {
    const int y = std::clamp(region.y + region.height / 2 - min_h / 2, 0,
                             frame.height - min_h);
    region.y = y;
    region.height = min_h;
  }
  // Every held object it overlaps comes in whole (each addition can reach
  // another: until nothing is added).
  for (bool grew = true; grew;) {
    grew = false;
    for (const cv::Rect& box : held) {
      if ((box & region).empty()) continue;
      const cv::Rect with = (region | Grown(box, margin)) & frame;
      if (with != region) {
        region = with;
        grew = true;
      }
    }
  }
  if (static_cast<double>(region.area()) >
      options.max_fraction * static_cast<double>(frame.area())) {
    return std::nullopt;
  }
  return region;
}

RgbdFrame CropFrame(const RgbdFrame& frame, const cv::Rect& region) {
  RgbdFrame crop;
  crop.depth = frame.depth(region).clone();
  if (!frame.color.empty()) crop.color = frame.color(region).clone();
  crop.intrinsics = frame.intrinsics;
  crop.intrinsics.cx -= region.x;
  crop.intrinsics.cy -= region.y;
  return crop;
}

bool ReachesInnerBorder(const cv::Rect& box, const cv::Rect& region,
                        cv::Size frame_size) {
  return (box.x <= 0 && region.x > 0) || (box.y <= 0 && region.y > 0) ||
         (box.x + box.width >= region.width &&
          region.x + region.width < frame_size.width) ||
         (box.y + box.height >= region.height &&
          region.y + region.height < frame_size.height);
}

void ObjectToFrame(const cv::Rect& region, cv::Size frame_size,
                   SegmentedObject& object) {
  cv::Mat mask(frame_size, CV_8UC1, cv::Scalar(0));
  if (object.mask.size() == region.size()) object.mask.copyTo(mask(region));
  object.mask = mask;
  object.box += region.tl();
  object.seed.u += region.x;
  object.seed.v += region.y;
  object.point_indices.clear();
}

}  // namespace fovea
