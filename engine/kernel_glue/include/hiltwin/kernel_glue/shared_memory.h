#pragma once
/// File operations on a shared-memory segment (a file on tmpfs, /dev/shm) that two processes
/// map: reserving its pages before they are touched, and a process's presence that the kernel
/// ends at the process's death. Used by the wire (io/wire_bus.h).

#include <sys/types.h>

#include <cstddef>

namespace hiltwin::kernel_glue {

/// Reserves the first `size` bytes of the file behind `fd` (posix_fallocate), extending it to
/// `size` when shorter. A tmpfs file that was only sized (ftruncate) is sparse: a write into a
/// page that the full or too small file system cannot supply then kills the writer with SIGBUS.
/// Returns 0, or the errno value (ENOSPC: no room). Bytes already there are kept.
[[nodiscard]] int ReserveFileBytes(int fd, std::size_t size) noexcept;

/// Presence: a write lock on byte `byte` of the file behind `fd`, held by that open file
/// description (F_OFD_SETLK). The kernel drops it when the description is closed, which a
/// process's death does before the process becomes a zombie, so a process killed but not yet
/// reaped (which kill(pid, 0) still finds) holds none. Unlike a classic POSIX lock it also
/// excludes another description in the same process. Advisory: the bytes stay writable.
/// Returns 0 once held, EAGAIN when another description holds it, else the errno value.
[[nodiscard]] int TakePresence(int fd, off_t byte) noexcept;

/// Whether another open file description holds the presence lock on `byte` now
/// (F_OFD_GETLK); one system call, no allocation. True when the kernel cannot say (never for
/// a valid descriptor): callers then fall back on what else they know, e.g. a heartbeat.
[[nodiscard]] bool PresenceHeld(int fd, off_t byte) noexcept;

}  // namespace hiltwin::kernel_glue
