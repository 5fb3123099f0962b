#include "urbanslam/io/ScratchFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace urbanslam::io {

ScratchFile::ScratchFile(std::string owner, std::string dir) : owner_(std::move(owner)), dir_(std::move(dir)) {}

ScratchFile::~ScratchFile() {
  if (fd_ >= 0) ::close(fd_);
}

namespace {
std::runtime_error scratchError(const std::string& owner, const std::string& what, const std::string& dir) {
  return std::runtime_error(owner + ": " + what + " the spill file in " + dir + ": " + std::strerror(errno));
}
}  // namespace

std::uint64_t ScratchFile::append(const std::string& bytes) {
  if (fd_ < 0) {
    if (dir_.empty()) dir_ = std::filesystem::temp_directory_path().string();
#ifdef O_TMPFILE
    fd_ = ::open(dir_.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
#endif
    if (fd_ < 0) {
      // File systems without O_TMPFILE: a named file, unlinked as soon as it is open.
      std::string path = (std::filesystem::path(dir_) / "urbanslam-spill-XXXXXX").string();
      fd_ = ::mkostemp(path.data(), O_CLOEXEC);
      if (fd_ < 0) throw scratchError(owner_, "cannot create", dir_);
      ::unlink(path.c_str());
    }
  }
  const std::uint64_t offset = end_;
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw scratchError(owner_, "cannot write", dir_);
    done += static_cast<size_t>(n);
  }
  end_ += bytes.size();
  return offset;
}

std::string ScratchFile::read(std::uint64_t offset, size_t length) const {
  std::string bytes(length, '\0');
  if (fd_ < 0 && length > 0) errno = EBADF;  // nothing was ever appended: the error says so
  size_t done = 0;
  while (done < length) {
    const ssize_t n = fd_ < 0 ? -1 : ::pread(fd_, bytes.data() + done, length - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw scratchError(owner_, "cannot read back", dir_);
    done += static_cast<size_t>(n);
  }
  return bytes;
}

void ScratchFile::clear() {
  end_ = 0;
  if (fd_ >= 0 && ::ftruncate(fd_, 0) != 0) {
    ::close(fd_);  // a fresh file at the next append
    fd_ = -1;
  }
}

}  // namespace urbanslam::io
