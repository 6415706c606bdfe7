#include "client/cli_frame.h"

#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "client/frame_builder.h"
#include "core/base/status_macros.h"
#include "core/frame/image_codec.h"
#include "core/frame/osd_pcd.h"
#include "core/frame/rgbd_frame.h"
#include "core/synth/synth_scene.h"

namespace fovea::client {
namespace {

// Largest side of a colour file decoded for the overlays, pixels: the
// server takes no larger frame (FrameLimits is at most 1 << 15).
constexpr uint32_t kMaxOverlaySide = 1u << 15;

// The source's intrinsics: each flag given wins over `fallback`.
Intrinsics ChooseIntrinsics(const FrameSource& source,
                            const Intrinsics& fallback) {
  Intrinsics intrinsics = fallback;
  if (source.fx) intrinsics.fx = *source.fx;
  if (source.fy) intrinsics.fy = *source.fy;
  if (source.cx) intrinsics.cx = *source.cx;
  if (source.cy) intrinsics.cy = *source.cy;
  return intrinsics;
}

fovea::v1::Intrinsics ToProto(const Intrinsics& intrinsics) {
  return MakeIntrinsics(intrinsics.fx, intrinsics.fy, intrinsics.cx,
                        intrinsics.cy);
}

// A raw image over any cv::Mat (continuous or not); the data is copied.
absl::StatusOr<fovea::v1::Image> ImageFromMat(const cv::Mat& mat,
                                              const std::string& encoding) {
  if (mat.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("empty ", encoding, " image"));
  }
  const size_t size = mat.step[0] * (mat.rows - 1) + mat.cols * mat.elemSize();
  return MakeRawImage(mat.data, size, mat.cols, mat.rows, encoding,
                      mat.step[0]);
}

// Sends an RgbdFrame (RGB colour, float metres depth) raw.
absl::StatusOr<LoadedFrame> FromRgbdFrame(const RgbdFrame& rgbd,
                                          const FrameSource& source,
                                          std::string description) {
  FOVEA_ASSIGN_OR_RETURN(fovea::v1::Image color,
                         ImageFromMat(rgbd.color, "rgb8"));
  FOVEA_ASSIGN_OR_RETURN(fovea::v1::Image depth,
                         ImageFromMat(rgbd.depth, "32FC1"));
  LoadedFrame loaded;
  loaded.frame =
      MakeFrame(std::move(color), std::move(depth),
                ToProto(ChooseIntrinsics(source, rgbd.intrinsics)), 0.0);
  cv::cvtColor(rgbd.color, loaded.color_bgr, cv::COLOR_RGB2BGR);
  loaded.description = std::move(description);
  return loaded;
}

absl::StatusOr<LoadedFrame> FromFiles(const FrameSource& source) {
  FOVEA_ASSIGN_OR_RETURN(std::string color_bytes,
                         ReadFileBytes(source.color_path));
  FOVEA_ASSIGN_OR_RETURN(std::string depth_bytes,
                         ReadFileBytes(source.depth_path));

  LoadedFrame loaded;
  ImageDecodeOptions options;
  options.mode = ImageDecodeMode::kColor;
  options.max_width = kMaxOverlaySide;
  options.max_height = kMaxOverlaySide;
  absl::StatusOr<cv::Mat> color_bgr =
      DecodeImage(color_bytes, options, "--color");
  // Left empty when undecodable: the server will say what is wrong.
  if (color_bgr.ok()) loaded.color_bgr = *std::move(color_bgr);
  absl::StatusOr<fovea::v1::Image> color =
      MakeCompressedImage(std::move(color_bytes));
  if (!color.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--color ", source.color_path, ": ", color.status().message()));
  }
  absl::StatusOr<fovea::v1::Image> depth =
      MakeCompressedImage(std::move(depth_bytes));
  if (!depth.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--depth ", source.depth_path, ": ", depth.status().message()));
  }
  loaded.description =
      absl::StrCat(source.color_path, " + ", source.depth_path, " (",
                   color->width(), "x", color->height(), ", compressed)");
  loaded.frame =
      MakeFrame(*std::move(color), *std::move(depth),
                ToProto(ChooseIntrinsics(source, kKinectV1Intrinsics)),
                source.depth_scale);
  return loaded;
}

}  // namespace

absl::StatusOr<LoadedFrame> LoadFrame(const FrameSource& source) {
  const bool files = !source.color_path.empty() || !source.depth_path.empty();
  const bool pcd = !source.pcd_path.empty();
  const bool synthetic = source.synthetic_seed.has_value();
  if (int{files} + int{pcd} + int{synthetic} != 1) {
    return absl::InvalidArgumentError(
        "give exactly one frame source: --color C.png --depth D.png, "
        "--pcd scene.pcd or --synthetic SEED");
  }
  absl::StatusOr<LoadedFrame> loaded;
  if (files) {
    if (source.color_path.empty() || source.depth_path.empty()) {
      return absl::InvalidArgumentError(
          "--color and --depth go together: give both");
    }
    loaded = FromFiles(source);
  } else if (pcd) {
    FOVEA_ASSIGN_OR_RETURN(
        LabelledFrame labelled,
        LoadOsdPcd(source.pcd_path,
                   ChooseIntrinsics(source, kKinectV1Intrinsics)));
    loaded = FromRgbdFrame(
        labelled.frame, source,
        absl::StrCat(source.pcd_path, " (", labelled.frame.width(), "x",
                     labelled.frame.height(), ", raw rgb8 + 32FC1)"));
  } else {
    synth::SynthScene scene = synth::GenerateScene(*source.synthetic_seed);
    loaded = FromRgbdFrame(
        scene.frame.frame, source,
        absl::StrCat("synthetic scene ", *source.synthetic_seed, " (",
                     scene.frame.frame.width(), "x", scene.frame.frame.height(),
                     ", ", scene.objects.size(),
                     " objects, raw rgb8 + 32FC1)"));
  }
  if (!loaded.ok()) return loaded;
  loaded->frame.set_frame_id(source.frame_id);
  const fovea::v1::Intrinsics& k = loaded->frame.intrinsics();
  absl::StrAppend(&loaded->description, ", fx ", k.fx(), " fy ", k.fy(), " cx ",
                  k.cx(), " cy ", k.cy());
  if (files && !(source.fx && source.fy && source.cx && source.cy)) {
    absl::StrAppend(&loaded->description,
                    " (unset ones: OSD Kinect v1 defaults)");
  }
  return loaded;
}

}  // namespace fovea::client
