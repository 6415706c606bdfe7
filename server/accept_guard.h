#ifndef FOVEA_SERVER_ACCEPT_GUARD_H_
#define FOVEA_SERVER_ACCEPT_GUARD_H_

#include <cstdint>

// Keeps the gRPC listener alive when file descriptors run short.
//
// gRPC 1.51 (Debian 12) gives up on a listening port for good when
// accept4 fails with anything but EAGAIN/EINTR/ECONNABORTED: one EMFILE
// during a flood of connections and the server never accepts again, even
// after every connection closed. This file defines accept4 for the whole
// process (the executable's definition takes precedence over libc's for
// libgrpc): it calls the next accept4 (libc's, or a sanitizer's wrapper of
// it) and
//   - while fewer than `reserve` descriptors are left under the soft limit,
//     closes each new connection at once (the client sees it reset):
//     connections stay bounded below the limit, so the rest of the process
//     (metrics, logs, health checks, model files) keeps descriptors;
//   - turns EMFILE/ENFILE into EAGAIN after a 20 ms pause, so the listener
//     survives (and does not spin) if the limit is reached anyway.
// Inactive (a plain accept4) until SetAcceptReserve is called.

namespace fovea::server {

// Descriptors kept free below the soft RLIMIT_NOFILE; 0 turns the guard
// off. The server sets it at start-up.
void SetAcceptReserve(int reserve);

// Connections the guard has closed or delayed since the process started.
int64_t AcceptsRefused();

}  // namespace fovea::server

#endif  // FOVEA_SERVER_ACCEPT_GUARD_H_
