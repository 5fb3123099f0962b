#include "urbanslam/common/MappedFile.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstddef>
#include <cstring>

#include "urbanslam/common/Error.h"

namespace urbanslam::common {

MappedFile::MappedFile(const std::string& path, size_t stretch_bytes) : stretch_(std::max<size_t>(stretch_bytes, 1)) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path + ": cannot open (" + std::strerror(errno) + ")");
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw InputError(path + ": not a regular file");
  }
  size_ = static_cast<size_t>(st.st_size);
  if (size_ > 0) {
    void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED) {
      const int e = errno;
      ::close(fd);
      throw InputError(path + ": cannot map into memory (" + std::strerror(e) + ")");
    }
    data_ = static_cast<char*>(p);
    ::madvise(p, size_, MADV_SEQUENTIAL);  // read ahead; a hint only
  }
  ::close(fd);  // the mapping keeps the file
  reader_released_ = data_;
  next = reinterpret_cast<const unsigned char*>(data_) + stretch_;
}

MappedFile::~MappedFile() {
  if (data_) ::munmap(data_, size_);
}

void MappedFile::release(const char* from, const char* to) {
  if (!data_) return;
  const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
  const size_t a = from <= data_ ? 0 : (std::min(static_cast<size_t>(from - data_), size_) + page - 1) / page * page;
  const size_t b = to <= data_ ? 0 : std::min(static_cast<size_t>(to - data_), size_) / page * page;
  // A private read-only mapping's pages are the file's: dropped, a later read faults them in
  // again from the file, so a reader going back (sections read out of order) stays correct.
  if (b > a) ::madvise(data_ + a, b - a, MADV_DONTNEED);
}

void MappedFile::reached(const unsigned char* p) {
  const char* at = reinterpret_cast<const char*>(p);
  const char* behind = at - std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(stretch_), at - data_);
  if (behind > reader_released_) {
    release(reader_released_, behind);
    reader_released_ = behind;
  }
  next = p + stretch_;
}

}  // namespace urbanslam::common
