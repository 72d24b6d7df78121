#include "hiltwin/kernel_glue/shared_memory.h"

#include <fcntl.h>

#include <cerrno>

namespace hiltwin::kernel_glue {
namespace {

struct flock OneByteWriteLock(off_t byte) noexcept {
  struct flock lock {};
  lock.l_type = F_WRLCK;
  lock.l_whence = SEEK_SET;
  lock.l_start = byte;
  lock.l_len = 1;
  lock.l_pid = 0;  // F_OFD_* require 0
  return lock;
}

}  // namespace

int ReserveFileBytes(int fd, std::size_t size) noexcept {
  int error = 0;
  do {
    error = ::posix_fallocate(fd, 0, static_cast<off_t>(size));
  } while (error == EINTR);
  return error;
}

int TakePresence(int fd, off_t byte) noexcept {
  struct flock lock = OneByteWriteLock(byte);
  if (::fcntl(fd, F_OFD_SETLK, &lock) == 0) return 0;
  // Held elsewhere: POSIX allows EACCES as well as EAGAIN for it.
  return errno == EACCES ? EAGAIN : errno;
}

bool PresenceHeld(int fd, off_t byte) noexcept {
  struct flock lock = OneByteWriteLock(byte);
  if (::fcntl(fd, F_OFD_GETLK, &lock) != 0) return true;
  return lock.l_type != F_UNLCK;
}

}  // namespace hiltwin::kernel_glue
