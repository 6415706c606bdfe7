#ifndef FOVEA_SERVER_DESCRIPTORS_H_
#define FOVEA_SERVER_DESCRIPTORS_H_

#include <optional>
#include <string>

// The process's file descriptors: every connection takes one, and a
// server that runs out cannot accept.

namespace fovea::server {

struct DescriptorUse {
  int open = 0;   // descriptors open now (entries of /proc/self/fd)
  int limit = 0;  // the soft RLIMIT_NOFILE
};

// nullopt when /proc/self/fd cannot be read (not Linux, no /proc).
std::optional<DescriptorUse> CountDescriptors();

// Raises the soft RLIMIT_NOFILE to the hard one (containers often start
// with 1024 of a larger hard limit). Returns a line for the log saying
// what it did, or why not.
std::string RaiseDescriptorLimit();

}  // namespace fovea::server

#endif  // FOVEA_SERVER_DESCRIPTORS_H_
