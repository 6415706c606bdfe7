#include "core/frame/osd_pcd.h"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/testing/files.h"

namespace fovea {
namespace {

using ::fovea::testing::WriteFile;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

constexpr int kGrey = 128;  // colour of a pixel without colour data

uint32_t PackRgb(int r, int g, int b) {
  return (uint32_t(r) << 16) | (uint32_t(g) << 8) | uint32_t(b);
}

// A fresh, empty folder for the current test.
std::filesystem::path TestDir() {
  return ::fovea::testing::FreshTestDir("osd_pcd_test_");
}

// PCD v0.7 header for `fields` ("x y z rgb"), `types` ("F F F F") of 4 bytes.
std::string PcdHeader(const std::string& fields, const std::string& types,
                      int count, int width, int height,
                      const std::string& data) {
  const std::string sizes = count == 4 ? "4 4 4 4" : "4 4 4 4 4";
  const std::string counts = count == 4 ? "1 1 1 1" : "1 1 1 1 1";
  return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " +
         fields + "\nSIZE " + sizes.substr(0, 2 * count - 1) + "\nTYPE " +
         types + "\nCOUNT " + counts.substr(0, 2 * count - 1) + "\nWIDTH " +
         std::to_string(width) + "\nHEIGHT " + std::to_string(height) +
         "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(width * height) +
         "\nDATA " + data + "\n";
}

template <typename T>
void Append(std::string& bytes, T value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof(value));
}

// The OSD layout, organized 4 x 3, ASCII: label x y z rgba. Point (u, v)
// has label 10 v + u, z = 1 + 0.01 (u + 4 v), colour (10 u, 20 v, 77);
// (2, 1) has no data.
std::string OrganizedOsdPcd() {
  std::string pcd =
      PcdHeader("label x y z rgba", "U F F F U", 5, 4, 3, "ascii");
  for (int v = 0; v < 3; ++v) {
    for (int u = 0; u < 4; ++u) {
      const bool hole = u == 2 && v == 1;
      const float z = 1.0f + 0.01f * (u + 4 * v);
      char line[160];
      if (hole) {
        std::snprintf(line, sizeof(line), "%d nan nan nan %u\n", 10 * v + u,
                      PackRgb(10 * u, 20 * v, 77));
      } else {
        std::snprintf(line, sizeof(line), "%d %.9g %.9g %.9g %u\n", 10 * v + u,
                      0.1f * u, 0.1f * v, z, PackRgb(10 * u, 20 * v, 77));
      }
      pcd += line;
    }
  }
  return pcd;
}

TEST(OsdPcdTest, OrganizedCloudKeepsItsLayoutLabelsColourAndNaN) {
  const std::string path =
      WriteFile(TestDir() / "learn3.pcd", OrganizedOsdPcd());
  constexpr Intrinsics kIntrinsics{500.0, 510.0, 1.5, 1.0};
  // width/height arguments differ from the file's 4 x 3: the file wins.
  const absl::StatusOr<LabelledFrame> loaded =
      LoadOsdPcd(path, kIntrinsics, 640, 480);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  EXPECT_EQ(loaded->name, "learn3");
  const RgbdFrame& frame = loaded->frame;
  ASSERT_EQ(frame.width(), 4);
  ASSERT_EQ(frame.height(), 3);
  ASSERT_EQ(frame.depth.type(), CV_32FC1);
  ASSERT_EQ(frame.color.type(), CV_8UC3);
  ASSERT_EQ(loaded->labels.type(), CV_32SC1);
  ASSERT_EQ(loaded->labels.size(), frame.depth.size());
  EXPECT_EQ(frame.intrinsics.fy, 510.0);
  for (int v = 0; v < 3; ++v) {
    for (int u = 0; u < 4; ++u) {
      SCOPED_TRACE(::testing::Message() << "u=" << u << " v=" << v);
      const float z = frame.depth.at<float>(v, u);
      if (u == 2 && v == 1) {
        EXPECT_TRUE(std::isnan(z));
      } else {
        EXPECT_EQ(z, 1.0f + 0.01f * (u + 4 * v));
      }
      EXPECT_EQ(loaded->labels.at<int32_t>(v, u), 10 * v + u);
      EXPECT_EQ(frame.color.at<cv::Vec3b>(v, u), cv::Vec3b(10 * u, 20 * v, 77));
    }
  }
}

TEST(OsdPcdTest, CloudWithoutLabelOrColourGivesZeroLabelsAndGrey) {
  std::string pcd = PcdHeader("x y z intensity", "F F F F", 4, 2, 2, "binary");
  for (int i = 0; i < 4; ++i) {
    for (float value : {0.0f, 0.0f, 2.0f + i, 0.0f}) Append(pcd, value);
  }
  const std::string path = WriteFile(TestDir() / "xyz.pcd", pcd);
  const absl::StatusOr<LabelledFrame> loaded = LoadOsdPcd(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  ASSERT_EQ(loaded->frame.width(), 2);
  EXPECT_EQ(loaded->frame.depth.at<float>(1, 1), 5.0f);
  EXPECT_EQ(cv::countNonZero(loaded->labels), 0);
  EXPECT_EQ(loaded->frame.color.at<cv::Vec3b>(1, 0),
            cv::Vec3b(kGrey, kGrey, kGrey));
}

struct TestPoint {
  float x, y, z;
  uint32_t rgb;
  uint32_t label;
};

// Unorganized binary cloud "x y z rgb label", rgb stored as a float the
// way PCL writes it.
std::string UnorganizedPcd(const std::vector<TestPoint>& points) {
  std::string pcd = PcdHeader("x y z rgb label", "F F F F U", 5,
                              static_cast<int>(points.size()), 1, "binary");
  for (const TestPoint& point : points) {
    Append(pcd, point.x);
    Append(pcd, point.y);
    Append(pcd, point.z);
    float rgb;
    std::memcpy(&rgb, &point.rgb, sizeof(rgb));
    Append(pcd, rgb);
    Append(pcd, point.label);
  }
  return pcd;
}

TEST(OsdPcdTest, UnorganizedCloudIsProjectedNearestPointWinning) {
  constexpr Intrinsics kIntrinsics{10.0, 10.0, 1.5, 1.0};
  // x = (u - cx) z / fx, y = (v - cy) z / fy for a point meant for (u, v).
  auto at = [&](double u, double v, float z, uint32_t rgb, uint32_t label) {
    return TestPoint{static_cast<float>((u - kIntrinsics.cx) * z / 10.0),
                     static_cast<float>((v - kIntrinsics.cy) * z / 10.0), z,
                     rgb, label};
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<TestPoint> points = {
      at(1, 2, 2.0f, PackRgb(255, 0, 0), 5),     // (1, 2), hidden by the next
      at(1, 2, 1.0f, PackRgb(0, 255, 0), 7),     // (1, 2), nearest
      at(1, 2, 3.0f, PackRgb(9, 9, 9), 9),       // (1, 2), behind: loses
      at(3, 0, 1.5f, PackRgb(0, 0, 255), 11),    // (3, 0)
      at(2.4, 0.6, 1.0f, PackRgb(1, 2, 3), 15),  // rounds to (2, 1)
      at(0, 0, -1.0f, PackRgb(4, 4, 4), 13),     // behind the camera
      at(10, 1, 1.0f, PackRgb(5, 5, 5), 17),     // right of the image
      at(1, -0.6, 1.0f, PackRgb(6, 6, 6), 19),   // above the image
      {nan, nan, nan, PackRgb(7, 7, 7), 21},     // no data
  };
  const std::string path =
      WriteFile(TestDir() / "scattered.pcd", UnorganizedPcd(points));
  const absl::StatusOr<LabelledFrame> loaded =
      LoadOsdPcd(path, kIntrinsics, 4, 3);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  const RgbdFrame& frame = loaded->frame;
  ASSERT_EQ(frame.width(), 4);
  ASSERT_EQ(frame.height(), 3);

  EXPECT_EQ(frame.depth.at<float>(2, 1), 1.0f);
  EXPECT_EQ(loaded->labels.at<int32_t>(2, 1), 7);
  EXPECT_EQ(frame.color.at<cv::Vec3b>(2, 1), cv::Vec3b(0, 255, 0));
  EXPECT_EQ(frame.depth.at<float>(0, 3), 1.5f);
  EXPECT_EQ(loaded->labels.at<int32_t>(0, 3), 11);
  EXPECT_EQ(frame.color.at<cv::Vec3b>(0, 3), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(frame.depth.at<float>(1, 2), 1.0f);
  EXPECT_EQ(loaded->labels.at<int32_t>(1, 2), 15);

  int with_depth = 0;
  for (int v = 0; v < 3; ++v) {
    for (int u = 0; u < 4; ++u) {
      if (!std::isnan(frame.depth.at<float>(v, u))) {
        ++with_depth;
        continue;
      }
      EXPECT_EQ(loaded->labels.at<int32_t>(v, u), 0) << u << "," << v;
      EXPECT_EQ(frame.color.at<cv::Vec3b>(v, u), cv::Vec3b(kGrey, kGrey, kGrey))
          << u << "," << v;
    }
  }
  EXPECT_EQ(with_depth, 3);  // the camera-behind point did not land on (0, 0)
}

TEST(OsdPcdTest, MissingFileIsNotFound) {
  const std::string path = (TestDir() / "learn99.pcd").string();
  const absl::StatusOr<LabelledFrame> loaded = LoadOsdPcd(path);
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(loaded.status().message()), HasSubstr(path));
}

TEST(OsdPcdTest, GarbageFilesAreRefusedNotCrashedOn) {
  const std::filesystem::path dir = TestDir();
  std::mt19937 random(3);
  std::string noise;
  for (int i = 0; i < 5000; ++i) noise.push_back(static_cast<char>(random()));
  std::string short_binary =
      PcdHeader("x y z rgb", "F F F F", 4, 1000, 1, "binary");
  short_binary += std::string(10, '\0');
  std::string bad_compressed =
      PcdHeader("x y z rgb", "F F F F", 4, 640, 480, "binary_compressed");
  bad_compressed += std::string("\x10\x00\x00\x00\xff\xff\xff\x7f", 8) + noise;
  std::string no_z = PcdHeader("x y w rgb", "F F F F", 4, 1, 1, "ascii");
  no_z += "1 2 3 4\n";

  const std::vector<std::pair<std::string, std::string>> files = {
      {"noise.pcd", noise},
      {"empty.pcd", ""},
      {"short_binary.pcd", short_binary},
      {"bad_compressed.pcd", bad_compressed},
      {"no_z.pcd", no_z},
  };
  for (const auto& [name, contents] : files) {
    const absl::StatusOr<LabelledFrame> loaded =
        LoadOsdPcd(WriteFile(dir / name, contents));
    ASSERT_FALSE(loaded.ok()) << name;
    EXPECT_EQ(loaded.status().code(), absl::StatusCode::kInvalidArgument)
        << name << ": " << loaded.status();
  }
  // A folder is not a PCD file either.
  EXPECT_EQ(LoadOsdPcd(dir.string()).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// PCL's reader takes keyword lines after DATA as more header; a body that
// re-declared FIELDS made its ASCII reader read freed memory (found by
// tests/fuzz/fuzz_pcd_load). Comments and empty lines there stay harmless.
TEST(OsdPcdTest, HeaderLinesAfterDataAreRefused) {
  const std::filesystem::path dir = TestDir();
  const std::string header =
      PcdHeader("x y z rgb", "F F F F", 4, 2, 1, "ascii");
  const std::vector<std::pair<std::string, std::string>> bodies = {
      {"fields.pcd", "\nFIELDS label 11 0\n1 2 3 4\n"},
      {"comment_then_count.pcd", "# note\n\nCOUNT 1 1 1 1\n1 2 3 4\n"},
      {"prefix.pcd", "  DATAx ascii\n1 2 3 4\n"},
  };
  for (const auto& [name, body] : bodies) {
    const absl::StatusOr<LabelledFrame> loaded =
        LoadOsdPcd(WriteFile(dir / name, header + body));
    ASSERT_FALSE(loaded.ok()) << name;
    EXPECT_EQ(loaded.status().code(), absl::StatusCode::kInvalidArgument)
        << name;
    EXPECT_THAT(std::string(loaded.status().message()), HasSubstr("after DATA"))
        << name;
  }
  const absl::StatusOr<LabelledFrame> commented = LoadOsdPcd(WriteFile(
      dir / "commented.pcd", header + "# a comment\n\n0 0 1 4\n0.01 0 1 4\n"));
  ASSERT_TRUE(commented.ok()) << commented.status();
  EXPECT_EQ(commented->frame.depth.type(), CV_32FC1);
  // A binary body that happens to start with '#' (label 35) is data.
  std::string hash = PcdHeader("label x y z", "U F F F", 4, 1, 1, "binary");
  Append<uint32_t>(hash, 35);
  Append<float>(hash, 0.0f);
  Append<float>(hash, 0.0f);
  Append<float>(hash, 1.0f);
  const absl::StatusOr<LabelledFrame> binary =
      LoadOsdPcd(WriteFile(dir / "hash.pcd", hash));
  ASSERT_TRUE(binary.ok()) << binary.status();
  EXPECT_EQ(cv::countNonZero(binary->labels == 35), 1);
}

// PCL's reader ends its header at a line of only white space and then
// dereferenced a null pointer (found by tests/fuzz/fuzz_pcd_load).
TEST(OsdPcdTest, WhiteSpaceLineInTheHeaderIsRefused) {
  const std::string pcd =
      " \n" + PcdHeader("x y z rgb", "F F F F", 4, 1, 1, "ascii") + "0 0 1 4\n";
  const absl::StatusOr<LabelledFrame> loaded =
      LoadOsdPcd(WriteFile(TestDir() / "blank.pcd", pcd));
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(loaded.status().message()),
              HasSubstr("only white space"));
}

// PCL allocates POINTS x point step before reading an ASCII body: a
// 100-byte file claiming 50 million points cost it 800 MB.
TEST(OsdPcdTest, AsciiBodyTooShortForItsPointsIsRefused) {
  const std::string pcd =
      PcdHeader("x y z rgb", "F F F F", 4, 50000000, 1, "ascii") + "0 0 1 4\n";
  const absl::StatusOr<LabelledFrame> loaded =
      LoadOsdPcd(WriteFile(TestDir() / "huge_ascii.pcd", pcd));
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(loaded.status().message()),
              HasSubstr("bytes of ASCII data for 50000000 points"));
  // The shortest body that can hold its points (no final newline) loads.
  const absl::StatusOr<LabelledFrame> shortest =
      LoadOsdPcd(WriteFile(TestDir() / "short_ascii.pcd",
                           PcdHeader("x y z rgb", "F F F F", 4, 2, 1, "ascii") +
                               "0 0 1 4\n0 0 2 4"));
  EXPECT_TRUE(shortest.ok()) << shortest.status();
}

TEST(OsdPcdTest, ListPcdFilesSortsByTheNumberInTheName) {
  const std::filesystem::path dir = TestDir();
  for (const char* name :
       {"learn10.pcd", "learn2.pcd", "learn1.pcd", "learn0.pcd", "notes.txt"}) {
    WriteFile(dir / name, "");
  }
  std::filesystem::create_directory(dir / "folder.pcd");
  const absl::StatusOr<std::vector<std::string>> files =
      ListPcdFiles(dir.string());
  ASSERT_TRUE(files.ok()) << files.status();
  EXPECT_THAT(*files, ElementsAre((dir / "learn0.pcd").string(),
                                  (dir / "learn1.pcd").string(),
                                  (dir / "learn2.pcd").string(),
                                  (dir / "learn10.pcd").string()));
}

TEST(OsdPcdTest, ListPcdFilesOfAnEmptyFolderIsEmpty) {
  const absl::StatusOr<std::vector<std::string>> files =
      ListPcdFiles(TestDir().string());
  ASSERT_TRUE(files.ok()) << files.status();
  EXPECT_THAT(*files, IsEmpty());
}

TEST(OsdPcdTest, ListPcdFilesOfAMissingFolderIsNotFound) {
  const std::string dir = (TestDir() / "absent").string();
  const absl::StatusOr<std::vector<std::string>> files = ListPcdFiles(dir);
  EXPECT_EQ(files.status().code(), absl::StatusCode::kNotFound);
}

// The real OSD scene learn6 against the sensor's own depth PNG.
TEST(OsdPcdTest, Learn6MatchesItsDepthPng) {
  const char* root = std::getenv("FOVEA_OSD_DIR");
  if (root == nullptr) GTEST_SKIP() << "FOVEA_OSD_DIR is unset";
  const std::filesystem::path pcd =
      std::filesystem::path(root) / "learn" / "learn6.pcd";
  const std::filesystem::path png =
      std::filesystem::path(root) / "frames" / "learn6_depth_mm.png";
  if (!std::filesystem::exists(pcd) || !std::filesystem::exists(png)) {
    GTEST_SKIP() << "no " << pcd << " or " << png;
  }
  const auto start = std::chrono::steady_clock::now();
  const absl::StatusOr<LabelledFrame> loaded = LoadOsdPcd(pcd.string());
  const double load_ms = std::chrono::duration<double, std::milli>(
                             std::chrono::steady_clock::now() - start)
                             .count();
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  const RgbdFrame& frame = loaded->frame;
  ASSERT_EQ(frame.width(), 640);
  ASSERT_EQ(frame.height(), 480);

  std::set<int> labels;
  for (int v = 0; v < 480; ++v) {
    const int32_t* row = loaded->labels.ptr<int32_t>(v);
    labels.insert(row, row + 640);
  }
  bool has_table = false;
  bool has_object = false;
  for (int label : labels) {
    has_table |= IsTableLabel(label);
    has_object |= ObjectId(label) >= 2;
  }
  EXPECT_TRUE(has_table);
  EXPECT_TRUE(has_object);

  const cv::Mat depth_mm = cv::imread(png.string(), cv::IMREAD_ANYDEPTH);
  ASSERT_EQ(depth_mm.type(), CV_16UC1);
  ASSERT_EQ(depth_mm.size(), frame.depth.size());
  int with_depth = 0;
  int close = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const float z = frame.depth.at<float>(v, u);
      if (std::isnan(z)) continue;
      ++with_depth;
      if (std::abs(z - depth_mm.at<uint16_t>(v, u) / 1000.0f) < 0.002f) {
        ++close;
      }
    }
  }
  ASSERT_GT(with_depth, 10000);
  const double fraction = static_cast<double>(close) / with_depth;
  std::printf(
      "learn6: loaded in %.1f ms; %d pixels with depth, %.4f within 2 mm of "
      "the PNG; %zu distinct labels\n",
      load_ms, with_depth, fraction, labels.size());
  EXPECT_GT(fraction, 0.95);
}

}  // namespace
}  // namespace fovea
