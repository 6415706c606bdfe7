#ifndef FOVEA_CORE_BASE_INTERRUPT_H_
#define FOVEA_CORE_BASE_INTERRUPT_H_

#include <functional>

#include "absl/status/status.h"

namespace fovea {

// Asked between stages and inside long loops; a non-OK status (e.g.
// DEADLINE_EXCEEDED, CANCELLED) stops the work and is returned as is. An
// empty function never interrupts.
using InterruptCheck = std::function<absl::Status()>;

inline absl::Status CheckInterrupt(const InterruptCheck& interrupt) {
  return interrupt ? interrupt() : absl::OkStatus();
}

}  // namespace fovea

#endif  // FOVEA_CORE_BASE_INTERRUPT_H_
