// fovea-eval end to end on synthetic scenes written as OSD-style PCDs.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/pipeline/models.h"
#include "core/synth/synth_scene.h"
#include "tests/core/testing/files.h"
#include "tests/core/testing/scenes.h"
#include "tests/testing/run_command.h"
#include "tools/eval/scene_kind.h"

namespace fovea {
namespace {

using ::testing::HasSubstr;

// Runs fovea-eval with `args`; stderr is appended to stdout, since the
// tests look for messages in either.
::fovea::testing::CommandRun RunEval(const std::string& args) {
  ::fovea::testing::CommandRun run =
      ::fovea::testing::RunCommand(std::string(FOVEA_EVAL_BIN) + " " + args);
  run.out += run.err;
  return run;
}

// The lines of `out` that start with '{', each parsed as JSON (a line that
// does not parse fails the test and is left out).
std::vector<nlohmann::json> JsonLines(const std::string& out) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] != '{') continue;
    nlohmann::json json = nlohmann::json::parse(line, /*cb=*/nullptr,
                                                /*allow_exceptions=*/false);
    EXPECT_TRUE(json.is_object()) << "not JSON: " << line;
    if (json.is_object()) lines.push_back(std::move(json));
  }
  return lines;
}

// The number at `key` of `json`; -1 when it is missing or not a number.
double JsonNumber(const nlohmann::json& json, const std::string& key) {
  const auto it = json.find(key);
  return it != json.end() && it->is_number() ? it->get<double>() : -1.0;
}

// Writes a synthetic scene as an organized PCD with label and rgba.
void WritePcd(const std::filesystem::path& path,
              const synth::SynthScene& scene) {
  const RgbdFrame& f = scene.frame.frame;
  pcl::PointCloud<pcl::PointXYZRGBL> cloud(f.width(), f.height());
  for (int v = 0; v < f.height(); ++v) {
    for (int u = 0; u < f.width(); ++u) {
      pcl::PointXYZRGBL& p = cloud.at(u, v);
      const float z = f.depth.at<float>(v, u);
      p.z = z;
      p.x = static_cast<float>((u - f.intrinsics.cx) * z / f.intrinsics.fx);
      p.y = static_cast<float>((v - f.intrinsics.cy) * z / f.intrinsics.fy);
      const cv::Vec3b c = f.color.at<cv::Vec3b>(v, u);
      p.r = c[0];
      p.g = c[1];
      p.b = c[2];
      p.label = static_cast<uint32_t>(scene.frame.labels.at<int>(v, u));
    }
  }
  cloud.is_dense = false;
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(path.string(), cloud), 0);
}

std::filesystem::path SyntheticDataDir() {
  const std::filesystem::path dir =
      testing::FreshTestDir("fovea_eval_test_data_");
  std::filesystem::create_directories(dir / "learn");
  for (int i = 0; i < 3; ++i) {
    WritePcd(dir / "learn" / ("learn" + std::to_string(i) + ".pcd"),
             synth::GenerateScene(i + 1));
  }
  return dir;
}

// Three scenes of two boxes side by side, touching in the first two and
// 5 cm apart in the third: every fold has patches to join and to reject.
std::filesystem::path SegmentationDataDir() {
  const std::filesystem::path dir =
      testing::FreshTestDir("fovea_segment_test_data_");
  std::filesystem::create_directories(dir / "learn");
  const float gaps[3] = {0.0f, 0.0f, 0.05f};
  for (int i = 0; i < 3; ++i) {
    WritePcd(dir / "learn" / ("learn" + std::to_string(i) + ".pcd"),
             testing::TwoBoxesOnTable(gaps[i]));
  }
  return dir;
}

TEST(FoveaEvalTest, DetectPrintsATableAndAJsonLastLine) {
  const std::filesystem::path dir = SyntheticDataDir();
  const ::fovea::testing::CommandRun run =
      RunEval("detect --data " + dir.string() + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_THAT(run.out, HasSubstr("boxes"));  // learn0-2 are box scenes
  const std::string last =
      run.out.substr(run.out.rfind('\n', run.out.size() - 2) + 1);
  const std::vector<nlohmann::json> lines = JsonLines(last);
  ASSERT_EQ(lines.size(), 1u) << run.out;
  const nlohmann::json& json = lines[0];
  EXPECT_EQ(JsonNumber(json, "scenes"), 3.0) << last;
  for (const char* key : {"distance_to_center", "detect_ms_median"}) {
    EXPECT_GE(JsonNumber(json, key), 0.0) << key << " in " << last;
  }
  // Ten HR(N) values, HR(1) first.
  ASSERT_TRUE(json["hit_ratio_at"].is_array()) << last;
  EXPECT_EQ(json["hit_ratio_at"].size(), 10u) << last;
  // Synthetic objects on a clean table: most are found.
  EXPECT_GE(JsonNumber(json, "hit_ratio"), 0.6) << last;
}

TEST(FoveaEvalTest, SweepWritesTheGridAsMarkdownAndCsv) {
  const std::filesystem::path dir = SyntheticDataDir();
  const std::filesystem::path out = testing::FreshTestDir("fovea_eval_sweep_");
  const ::fovea::testing::CommandRun run =
      RunEval("sweep --data " + dir.string() + " --out " + out.string() +
              " --filter rso/none/-/lin/wta/");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  std::ifstream md(out / "sweep.md");
  std::string header, rule, row1, row2, extra;
  std::getline(md, header);
  std::getline(md, rule);
  std::getline(md, row1);
  std::getline(md, row2);
  EXPECT_THAT(header, HasSubstr("| variant | HR | DC | DC (thesis) |"));
  // rso with WTA as the thesis has it and with Fovea's defaults, then the
  // two ph+sh+rso rows the substring filter also matches.
  EXPECT_THAT(row1, HasSubstr("| rso | none | - | lin | wta | thesis |"));
  EXPECT_THAT(row2, HasSubstr("| rso | none | - | lin | wta | fovea |"));
  ASSERT_TRUE(std::getline(md, extra));
  EXPECT_THAT(extra,
              HasSubstr("| ph+sh+rso | none | - | lin | wta | thesis |"));
  std::ifstream csv(out / "sweep.csv");
  std::string line;
  int lines = 0;
  while (std::getline(csv, line)) ++lines;
  EXPECT_EQ(lines, 5);  // header and four rows
}

TEST(FoveaEvalTest, SegmentCrossValidatesBothMethodsWithAJsonLastLine) {
  const std::filesystem::path dir = SegmentationDataDir();
  for (const char* method : {"cos", "ebs"}) {
    const ::fovea::testing::CommandRun run =
        RunEval(std::string("segment --method ") + method + " --data " +
                dir.string() + " --folds 3 --json");
    ASSERT_EQ(run.exit_code, 0) << run.out;
    EXPECT_THAT(run.out, HasSubstr("3-fold cross-validated"));
    const std::string last =
        run.out.substr(run.out.rfind('\n', run.out.size() - 2) + 1);
    const std::vector<nlohmann::json> lines = JsonLines(last);
    ASSERT_EQ(lines.size(), 1u) << run.out;
    const nlohmann::json& json = lines[0];
    EXPECT_EQ(json.value("method", ""), method) << last;
    EXPECT_EQ(json.value("evaluation", ""), "cross-validated") << last;
    EXPECT_EQ(JsonNumber(json, "folds"), 3.0) << last;
    for (const char* key :
         {"f_all", "f_best", "f_first", "object_recall", "false_masks",
          "first_mask_ms_median", "all_masks_ms_median"}) {
      EXPECT_GE(JsonNumber(json, key), 0.0) << key << " in " << last;
    }
    EXPECT_EQ(JsonNumber(json, "scenes"), 3.0);
    // Two noise-free boxes on a clean table: both are cut out.
    EXPECT_GT(JsonNumber(json, "f_all"), 0.6) << method << ": " << last;
    EXPECT_GT(JsonNumber(json, "object_recall"), 0.6) << method << ": " << last;
  }
}

TEST(FoveaEvalTest, SegmentScoresTheShippedModelsAndPeersSideBySide) {
  // Without --folds: the models of models/ as the server loads them, every
  // method on the same two synthetic piles, one JSON line each.
  const ::fovea::testing::CommandRun run =
      RunEval("segment --method inc,cos,pcl-lccp --piles 2 --seed 5 --json");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_THAT(run.out, HasSubstr("as shipped"));
  std::vector<std::string> methods;
  for (const nlohmann::json& line : JsonLines(run.out)) {
    methods.push_back(line.value("method", ""));
    EXPECT_EQ(line.value("evaluation", ""), "held-out") << line;
    for (const char* key : {"overlap_p", "overlap_r", "overlap_f", "boundary_f",
                            "objects_075", "whole_scene_f", "f_all"}) {
      const double value = JsonNumber(line, key);
      EXPECT_GE(value, 0.0) << key << " in " << line;
      EXPECT_LE(value, 1.0) << key << " in " << line;
    }
    EXPECT_EQ(JsonNumber(line, "scenes"), 2.0);
    // Piles of 8-16 objects on a clean table: much of them is found.
    EXPECT_GT(JsonNumber(line, "overlap_f"), 0.4) << line;
  }
  EXPECT_THAT(methods, ::testing::ElementsAre("inc", "cos", "pcl-lccp"));
  // --folds 1 is neither held out nor cross-validated.
  EXPECT_EQ(RunEval("segment --method cos --piles 1 --folds 1").exit_code, 64);
}

TEST(FoveaTrainTest, WritesModelsTheServerLoads) {
  const std::filesystem::path dir = SegmentationDataDir();
  const std::filesystem::path models =
      testing::FreshTestDir("fovea_train_models_");
  std::filesystem::create_directories(models);
  for (const auto& [command, file] :
       {std::pair<std::string, std::string>{"cos", kCosModelFile},
        {"ebs", kEbsModelFile},
        {"inc", kIncModelFile}}) {
    const ::fovea::testing::CommandRun run = ::fovea::testing::RunCommand(
        std::string(FOVEA_TRAIN_BIN) + " " + command + " --data " +
        dir.string() + " --folds 3 --out " + (models / file).string());
    ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
    EXPECT_THAT(run.out, HasSubstr("3-fold cross-validated"));
  }
  const absl::StatusOr<LoadedModels> loaded = LoadModels(models.string());
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  EXPECT_EQ(loaded->versions.size(), 3u);
  const ::fovea::testing::CommandRun usage = ::fovea::testing::RunCommand(
      std::string(FOVEA_TRAIN_BIN) + " cos --data " + dir.string());
  EXPECT_EQ(usage.exit_code, 64);
  EXPECT_THAT(usage.err, HasSubstr("--out"));
}

TEST(FoveaEvalTest, UnknownSaliencyIsAUsageErrorNamingIt) {
  const ::fovea::testing::CommandRun run =
      RunEval("detect --data /nonexistent --saliency ph+bogus");
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.out, HasSubstr("bogus"));
}

TEST(FoveaEvalTest, MissingDataIsAnErrorNotACrash) {
  const ::fovea::testing::CommandRun run =
      RunEval("detect --data /nonexistent/osd");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_THAT(run.out, HasSubstr("/nonexistent/osd"));
}

TEST(SceneKindTest, FollowsTheOsdLearnNumbering) {
  EXPECT_EQ(eval::SceneKind("learn0"), "boxes");
  EXPECT_EQ(eval::SceneKind("learn16"), "boxes");
  EXPECT_EQ(eval::SceneKind("learn17"), "stacked");
  EXPECT_EQ(eval::SceneKind("learn32"), "occluded");
  EXPECT_EQ(eval::SceneKind("learn44"), "cylindric");
  EXPECT_EQ(eval::SceneKind("learn45"), "other");
  EXPECT_EQ(eval::SceneKind("learnx"), "other");
}

TEST(SceneKindTest, KnowsTheOsdTestNumberingPilesAndAKindsFile) {
  EXPECT_EQ(eval::SceneKind("test15"), "boxes");
  EXPECT_EQ(eval::SceneKind("test16"), "stacked");
  EXPECT_EQ(eval::SceneKind("test30"), "occluded");
  EXPECT_EQ(eval::SceneKind("test42"), "cylindric");
  EXPECT_EQ(eval::SceneKind("test54"), "mixed");
  EXPECT_EQ(eval::SceneKind("test64"), "complex");
  EXPECT_EQ(eval::SceneKind("test65"), "other");
  EXPECT_EQ(eval::SceneKind("pile-17"), "pile");
  const std::filesystem::path file =
      std::filesystem::path(::testing::TempDir()) / "kinds.txt";
  {
    std::ofstream out(file);
    out << "# my scenes\nshelf 0-4 shelves\nshelf 5-9 drawers  # at the back\n";
  }
  ASSERT_TRUE(eval::LoadKinds(file.string()).ok());
  EXPECT_EQ(eval::SceneKind("shelf3"), "shelves");
  EXPECT_EQ(eval::SceneKind("shelf9"), "drawers");
  {
    std::ofstream out(file);
    out << "shelf 4-2 backwards\n";
  }
  const absl::Status bad = eval::LoadKinds(file.string());
  EXPECT_EQ(bad.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(bad.message()), HasSubstr("kinds.txt:1"));
}

}  // namespace
}  // namespace fovea
