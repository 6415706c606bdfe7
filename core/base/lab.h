#ifndef FOVEA_CORE_BASE_LAB_H_
#define FOVEA_CORE_BASE_LAB_H_

#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace fovea {

// cv::cvtColor(rgb, *lab, cv::COLOR_RGB2Lab), for CV_8UC3 or CV_32FC3
// `rgb` (OpenCV's Lab scaling for each depth).
//
// Why not call cvtColor directly: OpenCV 4.6 (Debian 12) builds its Lab
// lookup tables lazily on the first conversion, without a lock. When two
// threads make their first conversion at once, both build the tables and
// one set is never freed (about 1.2 MB, once per process; valgrind and
// LeakSanitizer report it, and it is a data race). Every Lab conversion in
// core/ goes through here, which builds the tables once, on one thread.
inline void RgbToLab(const cv::Mat& rgb, cv::Mat* lab) {
  static std::once_flag tables_built;
  std::call_once(tables_built, [] {
    cv::Mat out;
    cv::cvtColor(cv::Mat(1, 1, CV_8UC3, cv::Scalar(1, 2, 3)), out,
                 cv::COLOR_RGB2Lab);
    cv::cvtColor(cv::Mat(1, 1, CV_32FC3, cv::Scalar(0.1, 0.2, 0.3)), out,
                 cv::COLOR_RGB2Lab);
  });
  cv::cvtColor(rgb, *lab, cv::COLOR_RGB2Lab);
}

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_LAB_H_
