#include "urbanslam/common/AtomicFile.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>

#include "urbanslam/common/Error.h"

namespace urbanslam::common {

namespace fs = std::filesystem;

std::string temporaryPathFor(const std::string& path) {
  const fs::path p(path);
  // ".name.partial-PID.ext": hidden, obviously incomplete, but keeps the extension.
  const std::string name = "." + p.stem().string() + ".partial-" + std::to_string(::getpid()) + p.extension().string();
  return (p.parent_path() / name).string();
}

bool processAlive(long pid) { return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

void removeStaleTemporaries(const std::string& path) {
  const fs::path p(path);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const std::string prefix = "." + p.stem().string() + ".partial-", ext = p.extension().string();
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() + ext.size() || name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
      continue;
    const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - ext.size());
    if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    if (processAlive(std::stol(digits))) continue;
    std::error_code rm;
    fs::remove_all(it->path(), rm);  // best effort: a leftover only costs disk space
  }
}

AtomicFile::AtomicFile(std::string path, bool binary) : path_(std::move(path)), temp_(temporaryPathFor(path_)) {
  removeStaleTemporaries(path_);
  out_.open(temp_, binary ? std::ios::out | std::ios::binary | std::ios::trunc : std::ios::out | std::ios::trunc);
  if (!out_) throw InputError(path_ + ": cannot write (is the folder writable?)");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::remove(temp_.c_str());
  }
}

void AtomicFile::commit() {
  out_.flush();
  if (!out_) throw InputError(path_ + ": write failed (disk full?)");
  out_.close();
  if (std::rename(temp_.c_str(), path_.c_str()) != 0) throw InputError(path_ + ": cannot rename the finished file into place");
  committed_ = true;
}

void writeTextAtomically(const std::string& path, const std::string& text) {
  AtomicFile f(path);
  f.stream() << text;
  f.commit();
}

void writeAtomically(const std::string& path, const std::function<void(const std::string& tmp)>& write) {
  removeStaleTemporaries(path);
  const std::string tmp = temporaryPathFor(path);
  try {
    write(tmp);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  std::error_code ec;
  if (!fs::exists(tmp, ec)) throw InputError(path + ": the writer produced no file");
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError(path + ": cannot rename the finished file into place");
  }
}

}  // namespace urbanslam::common
