// flock(2)-based folder lock (folder_lock.h).
#include "spherekit/formats/folder_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace spherekit::formats {
namespace {

Status lock_impl(const std::string& dir, const char* lock_file, bool wait, int& fd_out) {
  const std::string path = (std::filesystem::path(dir) / lock_file).string();
  for (;;) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) return Status(ErrorCode::IoError, path + ": cannot open the lock file (" + std::strerror(errno) + ")");
    int r;
    do {
      r = ::flock(fd, wait ? LOCK_EX : LOCK_EX | LOCK_NB);
    } while (r != 0 && errno == EINTR);
    if (r != 0) {
      const int err = errno;
      ::close(fd);
      if (!wait && err == EWOULDBLOCK) {
        fd_out = -1;
        return Status();
      }
      return Status(ErrorCode::IoError, path + ": cannot lock (" + std::strerror(err) + ")");
    }
    // The folder may have been replaced while we waited: then the path names another file
    // (the new folder's lock), and holding the old one protects nothing.
    struct stat held {}, named {};
    if (::fstat(fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino) {
      fd_out = fd;
      return Status();
    }
    ::close(fd);
  }
}

}  // namespace

FolderLock& FolderLock::operator=(FolderLock&& o) noexcept {
  if (this != &o) {
    release();
    fd_ = o.fd_;
    o.fd_ = -1;
  }
  return *this;
}

void FolderLock::release() noexcept {
  if (fd_ >= 0) ::close(fd_);  // closing the last descriptor releases the flock
  fd_ = -1;
}

Result<FolderLock> FolderLock::acquire(const std::string& dir, const char* lock_file) {
  int fd = -1;
  SPHEREKIT_RETURN_IF_ERROR(lock_impl(dir, lock_file, true, fd));
  return FolderLock(fd);
}

Result<FolderLock> FolderLock::try_acquire(const std::string& dir, const char* lock_file) {
  int fd = -1;
  SPHEREKIT_RETURN_IF_ERROR(lock_impl(dir, lock_file, false, fd));
  return FolderLock(fd);
}

}  // namespace spherekit::formats
