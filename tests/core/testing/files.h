#ifndef FOVEA_TESTS_CORE_TESTING_FILES_H_
#define FOVEA_TESTS_CORE_TESTING_FILES_H_

#include <filesystem>
#include <fstream>
#include <string>

#include "gtest/gtest.h"

namespace fovea::testing {

// A fresh, empty folder for the current test: TempDir()/<prefix><test name>.
inline std::filesystem::path FreshTestDir(const std::string& prefix) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) /
      (prefix +
       ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Writes `contents` to `path` byte for byte; returns the path as a string.
inline std::string WriteFile(const std::filesystem::path& path,
                             const std::string& contents) {
  std::ofstream out(path, std::ios::binary);
  out << contents;
  return path.string();
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_TESTING_FILES_H_
