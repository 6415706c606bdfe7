#include "core/frame/pcd_reader.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/lzf.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/frame/osd_pcd.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/testing/files.h"

namespace fovea {
namespace {

using ::fovea::testing::WriteFile;
using ::testing::HasSubstr;

// A fresh, empty folder for the current test.
std::filesystem::path TestDir() {
  return ::fovea::testing::FreshTestDir("pcd_reader_test_");
}

template <typename T>
void Append(std::string& bytes, T value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof(value));
}

template <typename T>
T At(const PcdCloud& cloud, size_t point, const std::string& name,
     size_t element = 0) {
  const PcdField* field = FindPcdField(cloud, name);
  EXPECT_NE(field, nullptr) << name;
  if (field == nullptr) return T{};
  EXPECT_EQ(PcdTypeSize(field->type), sizeof(T)) << name;
  T value;
  std::memcpy(&value,
              cloud.data.data() + point * cloud.point_step + field->offset +
                  element * sizeof(T),
              sizeof(T));
  return value;
}

// Expects `ours` to hold what pcl::PCDReader read into `theirs`, bit for
// bit.
void ExpectSameCloud(const PcdCloud& ours, const pcl::PCLPointCloud2& theirs) {
  ASSERT_EQ(ours.width, theirs.width);
  ASSERT_EQ(ours.height, theirs.height);
  ASSERT_EQ(ours.point_step, theirs.point_step);
  EXPECT_EQ(theirs.row_step, ours.width * ours.point_step);
  ASSERT_EQ(ours.fields.size(), theirs.fields.size());
  for (size_t i = 0; i < ours.fields.size(); ++i) {
    SCOPED_TRACE(theirs.fields[i].name);
    EXPECT_EQ(ours.fields[i].name, theirs.fields[i].name);
    EXPECT_EQ(ours.fields[i].offset, theirs.fields[i].offset);
    EXPECT_EQ(static_cast<int>(ours.fields[i].type),
              static_cast<int>(theirs.fields[i].datatype));
    EXPECT_EQ(ours.fields[i].count, theirs.fields[i].count);
  }
  ASSERT_EQ(ours.data.size(), theirs.data.size());
  size_t differ = 0;
  while (differ < ours.data.size() &&
         ours.data[differ] == theirs.data[differ]) {
    ++differ;
  }
  EXPECT_EQ(differ, ours.data.size()) << "first differing byte";
}

// Reads `path` with ReadPcd and with pcl::PCDReader; expects the same.
PcdCloud ExpectReadsAsPcl(const std::string& path) {
  const absl::StatusOr<PcdCloud> ours = ReadPcd(path);
  EXPECT_TRUE(ours.ok()) << ours.status();
  if (!ours.ok()) return PcdCloud();
  pcl::PCLPointCloud2 theirs;
  pcl::PCDReader reader;
  EXPECT_EQ(reader.read(path, theirs), 0) << path;
  ExpectSameCloud(*ours, theirs);
  return *ours;
}

void ExpectInvalid(const std::string& path, const std::string& part) {
  const absl::StatusOr<PcdCloud> cloud = ReadPcd(path);
  ASSERT_FALSE(cloud.ok()) << path;
  EXPECT_EQ(cloud.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(cloud.status().message()), HasSubstr(path));
  EXPECT_THAT(std::string(cloud.status().message()), HasSubstr(part));
}

bool IsHole(int u, int v) {
  return (u == 1 && v == 0) || (u == 3 && v == 2) || (u == 4 && v == 3);
}

// 5 x 4 organized XYZRGBA + label, values exact in 8 decimal digits (PCL's
// ASCII precision), three points without data (NaN).
pcl::PointCloud<pcl::PointXYZRGBL> SyntheticCloud() {
  pcl::PointCloud<pcl::PointXYZRGBL> cloud(5, 4);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < 4; ++v) {
    for (int u = 0; u < 5; ++u) {
      pcl::PointXYZRGBL& point = cloud.at(u, v);
      point.x = IsHole(u, v) ? nan : 0.125f * (u - 2);
      point.y = IsHole(u, v) ? nan : 0.25f * (v - 1);
      point.z = IsHole(u, v) ? nan : 1.0f + 0.0625f * (u + 5 * v);
      point.rgba = 0xff000000u | (40u * u) << 16 | (60u * v) << 8 | 7u;
      point.label = 10 * v + u + 1;
    }
  }
  cloud.is_dense = false;
  return cloud;
}

TEST(ReadPcdTest, PclWrittenCloudReadsIdenticallyInEveryEncoding) {
  const std::filesystem::path dir = TestDir();
  const pcl::PointCloud<pcl::PointXYZRGBL> cloud = SyntheticCloud();
  const std::string ascii = (dir / "ascii.pcd").string();
  const std::string binary = (dir / "binary.pcd").string();
  const std::string compressed = (dir / "compressed.pcd").string();
  ASSERT_EQ(pcl::io::savePCDFileASCII(ascii, cloud), 0);
  ASSERT_EQ(pcl::io::savePCDFileBinary(binary, cloud), 0);
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(compressed, cloud), 0);
  for (const std::string& path : {ascii, binary, compressed}) {
    SCOPED_TRACE(path);
    const PcdCloud read = ExpectReadsAsPcl(path);
    ASSERT_EQ(read.width, 5u);
    ASSERT_EQ(read.height, 4u);
    for (int v = 0; v < 4; ++v) {
      for (int u = 0; u < 5; ++u) {
        SCOPED_TRACE(::testing::Message() << "u=" << u << " v=" << v);
        const size_t i = 5 * v + u;
        const pcl::PointXYZRGBL& point = cloud.at(u, v);
        for (const char* axis : {"x", "y", "z"}) {
          const float value = At<float>(read, i, axis);
          const float expected = axis[0] == 'x'   ? point.x
                                 : axis[0] == 'y' ? point.y
                                                  : point.z;
          if (IsHole(u, v)) {
            EXPECT_TRUE(std::isnan(value)) << axis;
          } else {
            EXPECT_EQ(value, expected) << axis;
          }
        }
        EXPECT_EQ(At<uint32_t>(read, i, "rgba"), point.rgba);
        EXPECT_EQ(At<uint32_t>(read, i, "label"), point.label);
      }
    }
  }
}

// FIELDS a b c d e f: I 1 x 3, U 2, F 8 x 2, I 8, U 4, U 1; 3 points.
constexpr char kMixedHeader[] =
    "# .PCD v0.7\nVERSION 0.7\nFIELDS a b c d e f\nSIZE 1 2 8 8 4 1\n"
    "TYPE I U F I U U\nCOUNT 3 1 2 1 1 1\nWIDTH 3\nHEIGHT 1\n"
    "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ";
constexpr char kMixedAscii[] =
    "-128 0 127 65535 nan 0.1 -1234567890123456 4294967295 255\n"
    "1 2 3 4 1e-3 -2.5e10 42 7 0\n"
    "+5 -6 7 8 inf -0 0 0 1\n";
constexpr size_t kMixedStep = 3 + 2 + 16 + 8 + 4 + 1;

std::string MixedBinaryPoints() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::string bytes;
  auto point = [&](std::vector<int8_t> a, uint16_t b, double c0, double c1,
                   int64_t d, uint32_t e, uint8_t f) {
    for (int8_t value : a) Append(bytes, value);
    Append(bytes, b);
    Append(bytes, c0);
    Append(bytes, c1);
    Append(bytes, d);
    Append(bytes, e);
    Append(bytes, f);
  };
  point({-128, 0, 127}, 65535, nan, 0.1, -1234567890123456, 4294967295u, 255);
  point({1, 2, 3}, 4, 1e-3, -2.5e10, 42, 7, 0);
  point({5, -6, 7}, 8, inf, -0.0, 0, 0, 1);
  return bytes;
}

// LZF (by PCL's compressor) of the points laid out field by field.
std::string MixedCompressedBody() {
  const std::string points = MixedBinaryPoints();
  const size_t sizes[] = {3, 2, 16, 8, 4, 1};
  std::string fields;
  size_t offset = 0;
  for (size_t size : sizes) {
    for (size_t i = 0; i < 3; ++i) {
      fields += points.substr(i * kMixedStep + offset, size);
    }
    offset += size;
  }
  std::vector<char> lzf(fields.size() * 2 + 64);
  const unsigned size =
      pcl::lzfCompress(fields.data(), static_cast<unsigned>(fields.size()),
                       lzf.data(), static_cast<unsigned>(lzf.size()));
  EXPECT_GT(size, 0u);
  std::string body;
  Append<uint32_t>(body, size);
  Append<uint32_t>(body, static_cast<uint32_t>(fields.size()));
  return body + std::string(lzf.data(), size);
}

TEST(ReadPcdTest, AllTypesAndCountsReadAsPclReadsThem) {
  const std::filesystem::path dir = TestDir();
  const std::string header = kMixedHeader;
  const PcdCloud ascii = ExpectReadsAsPcl(
      WriteFile(dir / "ascii.pcd", header + "ascii\n" + kMixedAscii));
  const PcdCloud binary = ExpectReadsAsPcl(
      WriteFile(dir / "binary.pcd", header + "binary\n" + MixedBinaryPoints()));
  const PcdCloud compressed = ExpectReadsAsPcl(
      WriteFile(dir / "compressed.pcd",
                header + "binary_compressed\n" + MixedCompressedBody()));
  ASSERT_EQ(ascii.point_step, kMixedStep);
  EXPECT_EQ(ascii.data, binary.data);
  EXPECT_EQ(compressed.data, binary.data);
  EXPECT_EQ(At<int8_t>(ascii, 0, "a", 0), -128);
  EXPECT_EQ(At<int8_t>(ascii, 2, "a", 1), -6);
  EXPECT_TRUE(std::isnan(At<double>(ascii, 0, "c", 0)));
  EXPECT_EQ(At<double>(ascii, 0, "c", 1), 0.1);
  EXPECT_EQ(At<int64_t>(ascii, 0, "d"), -1234567890123456);
  EXPECT_EQ(At<uint32_t>(ascii, 0, "e"), 4294967295u);
  EXPECT_EQ(At<double>(ascii, 2, "c", 0),
            std::numeric_limits<double>::infinity());
}

// PCL reads ASCII 64-bit integers through a double (-2^53 - 1 becomes
// -2^53); ReadPcd reads them exactly.
TEST(ReadPcdTest, AsciiInt64IsExact) {
  const absl::StatusOr<PcdCloud> cloud = ReadPcd(WriteFile(
      TestDir() / "int64.pcd",
      "VERSION 0.7\nFIELDS d u\nSIZE 8 8\nTYPE I U\nCOUNT 1 1\nWIDTH 1\n"
      "HEIGHT 1\nPOINTS 1\nDATA ascii\n"
      "-9007199254740993 18446744073709551615\n"));
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(At<int64_t>(*cloud, 0, "d"), -9007199254740993);
  EXPECT_EQ(At<uint64_t>(*cloud, 0, "u"), 18446744073709551615u);
}

// PCL skips the values of a padding field "_" in ASCII and leaves it 0.
TEST(ReadPcdTest, AsciiPaddingFieldIsSkippedLikePcl) {
  const PcdCloud cloud = ExpectReadsAsPcl(WriteFile(
      TestDir() / "padding.pcd",
      "VERSION 0.7\nFIELDS x _ y\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
      "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n4 anything 6\n"));
  EXPECT_EQ(At<float>(cloud, 1, "_"), 0.0f);
  EXPECT_EQ(At<float>(cloud, 1, "y"), 6.0f);
}

std::string XyzHeader(int width, int height, const std::string& data) {
  return "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
         "WIDTH " +
         std::to_string(width) + "\nHEIGHT " + std::to_string(height) +
         "\nPOINTS " + std::to_string(width * height) + "\nDATA " + data + "\n";
}

TEST(ReadPcdTest, AsciiCommentsAndBlankLinesBetweenPointsAreSkipped) {
  const absl::StatusOr<PcdCloud> cloud = ReadPcd(WriteFile(
      TestDir() / "comments.pcd",
      XyzHeader(2, 1, "ascii") + "1 2 3\r\n# between\n\n  \r\n4 5 6\nextra\n"));
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_EQ(At<float>(*cloud, 1, "x"), 4.0f);
  EXPECT_EQ(At<float>(*cloud, 1, "z"), 6.0f);
}

TEST(ReadPcdTest, BadAsciiValuesNameTheirByteOffset) {
  const std::filesystem::path dir = TestDir();
  const std::string header = XyzHeader(2, 1, "ascii");
  ExpectInvalid(WriteFile(dir / "word.pcd", header + "1 2 3\n4 five 6\n"),
                "ASCII value 'five' at byte " +
                    std::to_string(header.size() + 8) +
                    " is not a number of field 'y'");
  ExpectInvalid(WriteFile(dir / "suffix.pcd", header + "1 2 3\n4 5 6x\n"),
                "ASCII value '6x'");
  ExpectInvalid(WriteFile(dir / "hex.pcd", header + "1 2 3\n4 5 0x6\n"),
                "ASCII value '0x6'");
  ExpectInvalid(WriteFile(dir / "count.pcd", header + "1 2 3\n4 5 6 7\n"),
                "ASCII line at byte " + std::to_string(header.size() + 6) +
                    " has 4 values, 3 expected");
  ExpectInvalid(WriteFile(dir / "short.pcd", header + "1 2 3\n\n\n\n\n\n\n"),
                "ASCII data ends after 1 of 2 points");
  const std::string u8 =
      "VERSION 0.7\nFIELDS x y z label\nSIZE 4 4 4 1\nTYPE F F F U\n"
      "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n";
  ExpectInvalid(WriteFile(dir / "range.pcd", u8 + "1 2 3 256\n"),
                "ASCII value '256'");
  ExpectInvalid(WriteFile(dir / "negative.pcd", u8 + "1 2 3 -1\n"),
                "ASCII value '-1'");
  // Overflowing floats become infinite, as strtof has them.
  const absl::StatusOr<PcdCloud> huge =
      ReadPcd(WriteFile(dir / "huge.pcd", u8 + "1e39 -1e39 1e-50 nan\n"));
  ASSERT_TRUE(huge.ok()) << huge.status();
  EXPECT_EQ(At<float>(*huge, 0, "x"), std::numeric_limits<float>::infinity());
  EXPECT_EQ(At<float>(*huge, 0, "y"), -std::numeric_limits<float>::infinity());
  EXPECT_EQ(At<float>(*huge, 0, "z"), 0.0f);
  EXPECT_EQ(At<uint8_t>(*huge, 0, "label"), 0);  // nan in an integer field
}

std::string CompressedXyz(int width, uint32_t compressed_size,
                          uint32_t uncompressed_size,
                          const std::string& stream) {
  std::string pcd = XyzHeader(width, 1, "binary_compressed");
  Append(pcd, compressed_size);
  Append(pcd, uncompressed_size);
  return pcd + stream;
}

TEST(ReadPcdTest, CorruptLzfDataIsRefusedWithItsByteOffset) {
  const std::filesystem::path dir = TestDir();
  const size_t start = XyzHeader(2, 1, "binary_compressed").size() + 8;
  // One literal byte, then a reference 6 bytes back.
  const std::string before = std::string("\x00\x01\x20\x05", 4);
  ExpectInvalid(WriteFile(dir / "before.pcd", CompressedXyz(2, 4, 24, before)),
                "binary_compressed data at byte " + std::to_string(start) +
                    ": LZF run at compressed byte 2: back-reference 6 bytes "
                    "back from output byte 1, before the start");
  // 32 literal bytes for 24 expected.
  const std::string overrun = "\x1f" + std::string(32, 'x');
  ExpectInvalid(
      WriteFile(dir / "overrun.pcd", CompressedXyz(2, 33, 24, overrun)),
      "literal of 32 bytes at output byte 0 overruns the 24");
  // A literal of 24 bytes of which the file holds 5.
  const std::string truncated = "\x17" + std::string(5, 'x');
  ExpectInvalid(
      WriteFile(dir / "truncated.pcd", CompressedXyz(2, 6, 24, truncated)),
      "literal of 24 bytes but 5 left");
  // A stream too short to hold the data.
  ExpectInvalid(
      WriteFile(dir / "short.pcd", CompressedXyz(2, 4, 24, "\x02xyz")),
      "expands to 3 bytes, 24 expected");
}

// Found by fuzz_pcd_load: a second SIZE line after TYPE made the layout
// (from the second) disagree with the types (from the first), and
// LoadOsdPcd's FOVEA_CHECK that every field fits its point aborted.
TEST(ReadPcdTest, RepeatedHeaderLineIsRefused) {
  const std::string header =
      "FIELDS label x y z\nSIZE 4 4 4 4\nTYPE U F F F\nSIZE 2 4 4 4\n"
      "COUNT 1 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n";
  ExpectInvalid(WriteFile(TestDir() / "twice.pcd", header + "1 2 3 4\n"),
                "header line 'SIZE' appears twice");
}

TEST(ReadPcdTest, HeaderSizesAreCheckedBeforeAllocating) {
  const std::filesystem::path dir = TestDir();
  // 100000 points (1.2 MB) from 3 bytes of LZF: at most 264 bytes.
  ExpectInvalid(WriteFile(dir / "expansion.pcd",
                          CompressedXyz(100000, 3, 1200000,
                                        std::string("\xe0\xff\x00", 3))),
                "compressed data of 3 -> 1200000 bytes");
  // A compressed size beyond the end of the file.
  ExpectInvalid(
      WriteFile(dir / "beyond.pcd", CompressedXyz(2, 4000, 24, "\x02xyz")),
      "24 expected from 4 available");
  // An uncompressed size other than POINTS x point size.
  ExpectInvalid(
      WriteFile(dir / "mismatch.pcd", CompressedXyz(2, 4, 25, "\x02xyz")),
      "compressed data of 4 -> 25 bytes; 24 expected");
  // 2^60 points: the product fits 64 bits but not the data limit.
  ExpectInvalid(
      WriteFile(dir / "points.pcd",
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1073741824\n"
                "HEIGHT 1073741824\nPOINTS 1152921504606846976\nDATA binary\n"),
      "exceed the limit");
  // WIDTH x HEIGHT overflowing 64 bits.
  ExpectInvalid(
      WriteFile(dir / "overflow.pcd",
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4294967296\n"
                "HEIGHT 4294967296\nPOINTS 0\nDATA binary\n"),
      "is not POINTS 0");
  ExpectInvalid(WriteFile(dir / "binary.pcd",
                          XyzHeader(1000, 1, "binary") + std::string(100, 0)),
                "100 bytes of binary data, 12000 expected");
  ExpectInvalid(WriteFile(dir / "type.pcd",
                          "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nWIDTH 1\n"
                          "POINTS 1\nDATA ascii\n1 2 3\n"),
                "unsupported TYPE 'F' and SIZE 2 of field 'z'");
  ExpectInvalid(WriteFile(dir / "keyword.pcd",
                          "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\n"
                          "POINTS 1\nROWS 1\nDATA ascii\n1 2 3\n"),
                "unknown header line 'ROWS'");
}

TEST(ReadPcdTest, MissingFileIsNotFound) {
  const std::string path = (TestDir() / "absent.pcd").string();
  EXPECT_EQ(ReadPcd(path).status().code(), absl::StatusCode::kNotFound);
}

// Every real OSD scene: ReadPcd gives PCL's cloud bit for bit. Prints the
// time each reader takes.
TEST(ReadPcdTest, AllOsdScenesReadAsPclReadsThem) {
  const char* root = std::getenv("FOVEA_OSD_DIR");
  if (root == nullptr) GTEST_SKIP() << "FOVEA_OSD_DIR is unset";
  const absl::StatusOr<std::vector<std::string>> files =
      ListPcdFiles((std::filesystem::path(root) / "learn").string());
  if (!files.ok() || files->empty()) GTEST_SKIP() << "no scenes in " << root;
  using Clock = std::chrono::steady_clock;
  double ours_ms = 0.0;
  double pcl_ms = 0.0;
  for (const std::string& path : *files) {
    SCOPED_TRACE(path);
    const Clock::time_point start = Clock::now();
    const absl::StatusOr<PcdCloud> ours = ReadPcd(path);
    const Clock::time_point middle = Clock::now();
    pcl::PCLPointCloud2 theirs;
    pcl::PCDReader reader;
    ASSERT_EQ(reader.read(path, theirs), 0);
    const Clock::time_point end = Clock::now();
    ours_ms +=
        std::chrono::duration<double, std::milli>(middle - start).count();
    pcl_ms += std::chrono::duration<double, std::milli>(end - middle).count();
    ASSERT_TRUE(ours.ok()) << ours.status();
    ASSERT_EQ(ours->width * ours->height, 640u * 480u);
    ExpectSameCloud(*ours, theirs);
  }
  std::printf(
      "%zu OSD scenes identical to pcl::PCDReader; per scene: ReadPcd %.2f "
      "ms, pcl::PCDReader %.2f ms\n",
      files->size(), ours_ms / files->size(), pcl_ms / files->size());
}

}  // namespace
}  // namespace fovea
