#include "io/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "floedem/io/output.hpp"

namespace floedem {

OutputLock::OutputLock(const std::string& path) : lock_path_(path + ".lock") {
  fd_ = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw OutputError(path + ": cannot create its lock " + lock_path_ + " (" + std::strerror(errno) + ")");
  // flock(2): held by the open file, released by the kernel when the process dies however it
  // dies, so a killed run's lock file never blocks the run that continues it.
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    throw OutputError(path + ": another floedem run is writing it (" + lock_path_ + " is locked" +
                      (e == EWOULDBLOCK ? "" : std::string(": ") + std::strerror(e)) +
                      "); nothing written, the other run's file untouched");
  }
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  // Removed while still held: a run that starts now creates and locks a file of its own.
  ::unlink(lock_path_.c_str());
  ::close(fd_);
}

}  // namespace floedem
