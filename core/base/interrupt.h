#ifndef FOVEA_CORE_BASE_INTERRUPT_H_
#define FOVEA_CORE_BASE_INTERRUPT_H_

#include <functional>

#include "absl/status/status.h"

namespace fovea {

// Asked between stages and inside long loops; a non-OK status (e.g.
// DEADLINE_EXCEEDED, CANCELLED) stops the work and is returned as is. An
// empty function never interrupts. The same alias as the one in
// core/pipeline/detect.h (redeclaring an alias of the same type is
// allowed), here so that libraries below the pipeline can take one.
using InterruptCheck = std::function<absl::Status()>;

// OK when `interrupt` is empty, else what it returns.
inline absl::Status CheckInterrupt(const InterruptCheck& interrupt) {
  return interrupt ? interrupt() : absl::OkStatus();
}

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_INTERRUPT_H_
