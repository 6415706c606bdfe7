#include "core/pyramid/cloud_pyramid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/base/check.h"
#include "core/base/parallel.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The binomial kernel [1 4 6 4 1] / 16 (thesis eq. 2.20), centre at 2.
constexpr int kRadius = 2;
constexpr float kKernel[2 * kRadius + 1] = {1.0f / 16, 4.0f / 16, 6.0f / 16,
                                            4.0f / 16, 1.0f / 16};

int HalfUp(int n) { return (n + 1) / 2; }

// Masked sums are kept as 4 floats per pixel: (k m x, k m y, k m z, k m)
// summed over the taps, m = 1 for a valid pixel (third channel not NaN)
// and 0 otherwise. Zero padding of kRadius pixels on every side makes
// pixels outside the image weigh 0 and keeps the tap loops branch-free.
constexpr int kChannels = 4;

// Writes row `src_row` (w pixels of 3 floats) as masked 4-float pixels
// into `padded` (w + 2 kRadius pixels, pads already 0).
void MaskRow(const float* __restrict src_row, int w, float* __restrict padded) {
  float* __restrict out = padded + kChannels * kRadius;
  for (int j = 0; j < w; ++j) {
    const float* p = src_row + 3 * j;
    const bool valid = !std::isnan(p[2]);
    // Selects, not products with 0: NaN * 0 is NaN.
    out[kChannels * j + 0] = valid ? p[0] : 0.0f;
    out[kChannels * j + 1] = valid ? p[1] : 0.0f;
    out[kChannels * j + 2] = valid ? p[2] : 0.0f;
    out[kChannels * j + 3] = valid ? 1.0f : 0.0f;
  }
}

// Horizontal pass of one masked, padded row at the kept columns 0, 2, 4,
// ...: out[c] = sum_t k_t padded[2c + t].
void FilterRowAtKeptColumns(const float* __restrict padded, int w_out,
                            float* __restrict out) {
  for (int c = 0; c < w_out; ++c) {
    const float* in = padded + kChannels * 2 * c;
    float acc[kChannels] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int t = 0; t < 2 * kRadius + 1; ++t) {
      for (int ch = 0; ch < kChannels; ++ch) {
        acc[ch] += kKernel[t] * in[kChannels * t + ch];
      }
    }
    for (int ch = 0; ch < kChannels; ++ch) out[kChannels * c + ch] = acc[ch];
  }
}

static_assert(kRadius == 2, "FilterColumns unrolls five taps");

// Vertical pass: out[i] = sum_t k_t rows[t][i], one sweep (separate
// buffers, so the loop vectorises).
void FilterColumns(const float* const rows[2 * kRadius + 1], size_t n,
                   float* __restrict out) {
  const float* __restrict r0 = rows[0];
  const float* __restrict r1 = rows[1];
  const float* __restrict r2 = rows[2];
  const float* __restrict r3 = rows[3];
  const float* __restrict r4 = rows[4];
  for (size_t i = 0; i < n; ++i) {
    out[i] = kKernel[0] * r0[i] + kKernel[1] * r1[i] + kKernel[2] * r2[i] +
             kKernel[3] * r3[i] + kKernel[4] * r4[i];
  }
}

// Filters a CV_32FC3 image over its valid pixels and keeps every second
// row and column (eq. 2.19-2.26): separable masked sums, then the
// renormalisation by the valid weight, NaN where no valid pixel
// contributed. With `unit_length`, the result is rescaled to length 1 (NaN
// if shorter than kMinNormalLength). Output rows in parallel ranges, each
// with its own buffers.
cv::Mat FilterAndDecimate(const cv::Mat& src, bool unit_length) {
  constexpr int kTaps = 2 * kRadius + 1;
  const int h = src.rows, w = src.cols;
  const int w_out = HalfUp(w), h_out = HalfUp(h);
  const size_t row_floats = static_cast<size_t>(kChannels) * w_out;
  const size_t padded_floats =
      static_cast<size_t>(kChannels) * (w + 2 * kRadius);
  cv::Mat out(h_out, w_out, CV_32FC3);
  ParallelForRanges(h_out, [&](int first, int last) {
    // A ring of the row sums of the kTaps input rows the current output
    // row needs (cache-resident), one masked padded input row and the
    // accumulator of one output row.
    std::vector<float> scratch(kTaps * row_floats + padded_floats + row_floats);
    float* ring = scratch.data();
    float* padded = ring + kTaps * row_floats;
    float* acc = padded + padded_floats;
    std::fill(padded, padded + kChannels * kRadius, 0.0f);
    std::fill(padded + padded_floats - kChannels * kRadius,
              padded + padded_floats, 0.0f);
    // Row sums of input row v - kRadius (0 outside the image) into the
    // ring.
    const auto compute_row = [&](int padded_row) {
      float* row = ring + row_floats * (padded_row % kTaps);
      const int v = padded_row - kRadius;
      if (v < 0 || v >= h) {
        std::fill(row, row + row_floats, 0.0f);
        return;
      }
      MaskRow(src.ptr<float>(v), w, padded);
      FilterRowAtKeptColumns(padded, w_out, row);
    };
    int computed = 2 * first - 1;  // last padded row in the ring
    for (int r = first; r < last; ++r) {
      // Input rows 2r - 2 .. 2r + 2 are padded rows 2r .. 2r + 4.
      while (computed < 2 * r + 2 * kRadius) compute_row(++computed);
      const float* rows[kTaps];
      for (int t = 0; t < kTaps; ++t) {
        rows[t] = ring + row_floats * ((2 * r + t) % kTaps);
      }
      FilterColumns(rows, row_floats, acc);
      float* dst = out.ptr<float>(r);
      for (int c = 0; c < w_out; ++c) {
        const float* s = acc + kChannels * c;
        float* p = dst + 3 * c;
        if (s[3] <= 0.0f) {
          p[0] = p[1] = p[2] = kNaN;
          continue;
        }
        float scale = 1.0f / s[3];
        if (unit_length) {
          // The common factor 1 / weight cancels in the unit vector.
          const float length =
              std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) * scale;
          if (!(length >= kMinNormalLength)) {
            p[0] = p[1] = p[2] = kNaN;
            continue;
          }
          scale /= length;
        }
        p[0] = s[0] * scale;
        p[1] = s[1] * scale;
        p[2] = s[2] * scale;
      }
    }
  });
  return out;
}

absl::Status ValidateCloud(const OrganizedCloud& cloud) {
  if (cloud.xyz.empty() || cloud.xyz.type() != CV_32FC3) {
    return absl::InvalidArgumentError(
        "cloud.xyz must be a non-empty CV_32FC3 image");
  }
  const cv::Size size = cloud.xyz.size();
  if (!cloud.normals.empty() &&
      (cloud.normals.type() != CV_32FC3 || cloud.normals.size() != size)) {
    return absl::InvalidArgumentError(
        "cloud.normals must be empty or CV_32FC3 of the size of cloud.xyz");
  }
  if (!cloud.color.empty() &&
      (cloud.color.type() != CV_8UC3 || cloud.color.size() != size)) {
    return absl::InvalidArgumentError(
        "cloud.color must be empty or CV_8UC3 of the size of cloud.xyz");
  }
  return absl::OkStatus();
}

OrganizedCloud Downsample(const OrganizedCloud& cloud) {
  OrganizedCloud out;
  out.xyz = FilterAndDecimate(cloud.xyz, /*unit_length=*/false);
  if (!cloud.normals.empty()) {
    out.normals = FilterAndDecimate(cloud.normals, /*unit_length=*/true);
  }
  if (!cloud.color.empty()) {
    // cv::pyrDown: the same kernel centred on the kept pixel 2u, and the
    // same ceil(w / 2) x ceil(h / 2) size.
    cv::pyrDown(cloud.color, out.color);
    FOVEA_CHECK(out.color.size() == out.xyz.size());
  }
  out.intrinsics = DownsampleIntrinsics(cloud.intrinsics);
  return out;
}

}  // namespace

absl::Status Validate(const CloudPyramidOptions& options) {
  if (options.max_levels < 1 || options.max_levels > 16) {
    return absl::InvalidArgumentError(absl::StrCat(
        "pyramid.max_levels must be in [1, 16], got ", options.max_levels));
  }
  if (options.min_size < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("pyramid.min_size must be >= 1, got ", options.min_size));
  }
  return absl::OkStatus();
}

Intrinsics DownsampleIntrinsics(const Intrinsics& intrinsics) {
  return {intrinsics.fx / 2.0, intrinsics.fy / 2.0, intrinsics.cx / 2.0,
          intrinsics.cy / 2.0};
}

absl::StatusOr<OrganizedCloud> DownsampleCloud(const OrganizedCloud& cloud) {
  FOVEA_RETURN_IF_ERROR(ValidateCloud(cloud));
  return Downsample(cloud);
}

absl::StatusOr<CloudPyramid> BuildCloudPyramid(
    const OrganizedCloud& cloud, const CloudPyramidOptions& options) {
  FOVEA_RETURN_IF_ERROR(Validate(options));
  FOVEA_RETURN_IF_ERROR(ValidateCloud(cloud));
  CloudPyramid pyramid;
  pyramid.levels.reserve(options.max_levels);
  pyramid.levels.push_back(cloud);  // cv::Mat headers: shares the pixels
  while (pyramid.size() < options.max_levels) {
    const OrganizedCloud& last = pyramid.levels.back();
    if (HalfUp(last.width()) < options.min_size ||
        HalfUp(last.height()) < options.min_size) {
      break;
    }
    OrganizedCloud next = Downsample(last);
    pyramid.levels.push_back(std::move(next));
  }
  return pyramid;
}

}  // namespace fovea
