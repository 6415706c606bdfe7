#ifndef FOVEA_CORE_FRAME_PCD_READER_H_
#define FOVEA_CORE_FRAME_PCD_READER_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace fovea {

// Storage of one scalar of a PCD field: its TYPE letter and SIZE in bytes.
// Numbered as PCL's pcl::PCLPointField::PointFieldTypes, so a PcdField
// compares directly with what PCL reads.
enum class PcdType : uint8_t {
  kInt8 = 1,     // I 1
  kUint8 = 2,    // U 1
  kInt16 = 3,    // I 2
  kUint16 = 4,   // U 2
  kInt32 = 5,    // I 4
  kUint32 = 6,   // U 4
  kFloat32 = 7,  // F 4
  kFloat64 = 8,  // F 8
  kInt64 = 9,    // I 8
  kUint64 = 10,  // U 8
};

// Bytes of one scalar of `type`: 1, 2, 4 or 8.
size_t PcdTypeSize(PcdType type);

// One named field of every point (FIELDS, with its TYPE, SIZE and COUNT).
struct PcdField {
  std::string name;
  PcdType type = PcdType::kFloat32;
  uint32_t offset = 0;  // bytes from the start of a point to its first scalar
  uint32_t count = 1;   // scalars per point (COUNT), >= 1
};

// A point cloud as a PCD file stores it: points of `point_step` bytes, the
// fields packed in header order (each offset is the sum of size x count of
// the fields before it), points in row-major order: point (u, v) of an
// organized cloud starts at byte (v * width + u) * point_step.
struct PcdCloud {
  std::vector<PcdField> fields;
  uint32_t width = 0;       // points per row (WIDTH), >= 1
  uint32_t height = 0;      // rows (HEIGHT), >= 1; 1 = unorganized
  uint32_t point_step = 0;  // bytes per point, sum of size x count
  // width * height * point_step bytes, little-endian as in the file.
  std::vector<uint8_t> data;
};

// The first field named `name`, or null.
const PcdField* FindPcdField(const PcdCloud& cloud, absl::string_view name);

// Reads a PCD v0.7 file, as pcl::PCDReader would read it into a
// pcl::PCLPointCloud2 (same fields, offsets and bytes), without PCL.
//
// Header: lines VERSION (ignored), FIELDS, SIZE (1, 2, 4 or 8), TYPE (F of
// 4 or 8 bytes; I or U of 1, 2, 4 or 8 bytes), COUNT (optional, default
// 1), WIDTH, HEIGHT (optional, default 1), VIEWPOINT (ignored), POINTS =
// WIDTH x HEIGHT, and last DATA ascii | binary | binary_compressed; empty
// lines and lines starting with '#' anywhere before DATA are skipped.
// Body:
//   ascii              one line of COUNT-summed values per point, numbers
//                      as strtod reads them (no hex), "nan" (any case) for
//                      NaN (0 in an integer field); values of a field named
//                      "_" (padding) are skipped and left 0, as PCL does.
//                      Empty lines and '#' comment lines are skipped;
//                      lines after the last point are ignored.
//   binary             POINTS x point_step bytes, as they are in memory.
//   binary_compressed  uint32 compressed size, uint32 uncompressed size
//                      (= POINTS x point_step), then that many bytes of LZF
//                      (LzfDecompress) holding the fields one after the
//                      other, each for all points (structure of arrays).
//
// Refused, as INVALID_ARGUMENT naming the file and the header key or the
// byte offset: anything else in the header; a line of only white space in
// the header; a header line (FIELDS, COUNT, ...) after DATA, which PCL
// would take as more header; more than 1024 fields or COUNT above 2^20;
// more than 1 GiB of point data; a body too short for the POINTS the
// header claims (checked before anything is allocated); an unparsable or
// out-of-range ASCII value, or a line with the wrong number of values;
// corrupt LZF data. NOT_FOUND for a missing file. Running out of memory
// throws std::bad_alloc (see core/base/guarded.h). Assumes a little-endian
// machine.
absl::StatusOr<PcdCloud> ReadPcd(const std::string& path);

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_PCD_READER_H_
