#ifndef FOVEA_TESTS_CORE_TESTING_MODELS_H_
#define FOVEA_TESTS_CORE_TESTING_MODELS_H_

#include <cstdlib>
#include <filesystem>
#include <utility>

#include "core/pipeline/models.h"

namespace fovea::testing {

// The models in the source tree's models/ (FOVEA_SOURCE_DIR, set for every
// test by CMake), loaded once as the server loads them; null when they do
// not load.
inline const LoadedModels* ShippedModels() {
  static const LoadedModels* models = [] {
    const char* source = std::getenv("FOVEA_SOURCE_DIR");
    absl::StatusOr<LoadedModels> loaded = LoadModels(
        (std::filesystem::path(source ? source : ".") / "models").string());
    return loaded.ok() ? new LoadedModels(*std::move(loaded)) : nullptr;
  }();
  return models;
}

}  // namespace fovea::testing

#endif  // FOVEA_TESTS_CORE_TESTING_MODELS_H_
