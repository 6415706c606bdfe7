#ifndef FOVEA_TESTS_CORE_TESTING_OSD_H_
#define FOVEA_TESTS_CORE_TESTING_OSD_H_

// Where the tests that need the OSD data find it.

#include <cstdlib>
#include <filesystem>
#include <string>

namespace fovea::testing {

// $FOVEA_OSD_DIR when it holds a learn/ folder, else "" (tests then skip).
inline std::string OsdDir() {
  const char* root = std::getenv("FOVEA_OSD_DIR");
  if (root == nullptr) return "";
  if (!std::filesystem::is_directory(std::filesystem::path(root) / "learn")) {
    return "";
  }
  return root;
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_TESTING_OSD_H_
