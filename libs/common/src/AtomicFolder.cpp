#include "urbanslam/common/AtomicFolder.h"

#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::common {

namespace fs = std::filesystem;

namespace {

// Where the earlier folder waits for deletion when the file system cannot exchange two names.
std::string asidePathFor(const std::string& path) {
  const fs::path p(path);
  return (p.parent_path() / ("." + p.filename().string() + ".old-" + std::to_string(::getpid()))).string();
}

// A process killed between the two renames of the fallback left the target missing and the
// earlier folder aside: put it back, so the target again holds a complete folder.
void restoreAsideFolders(const std::string& path) {
  const fs::path p(path);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const std::string prefix = "." + p.filename().string() + ".old-";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    if (processAlive(std::stol(digits))) continue;
    std::error_code e2;
    if (!fs::exists(path, e2))
      fs::rename(it->path(), path, e2);
    else
      fs::remove_all(it->path(), e2);
  }
}

}  // namespace

AtomicFolder::AtomicFolder(std::string path, const std::function<bool(const std::string&)>& replaceable) : path_(std::move(path)) {
  while (path_.size() > 1 && path_.back() == '/') path_.pop_back();  // "out/" names the folder "out"
  const fs::path p(path_);
  const std::string leaf = p.filename().string();
  if (leaf.empty() || leaf == "." || leaf == "..") throw InputError(path_ + ": give the output folder by its name (not . or ..)");
  std::error_code ec;
  if (!p.parent_path().empty()) fs::create_directories(p.parent_path(), ec);
  restoreAsideFolders(path_);
  removeStaleTemporaries(path_);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) throw InputError(path_ + ": exists and is not a folder");
    if (!replaceable(path_)) throw InputError(path_ + ": exists and is not an output folder of this kind (choose a new or empty folder)");
  }
  staging_ = temporaryPathFor(path_);
  fs::remove_all(staging_, ec);
  if (!fs::create_directory(staging_, ec) || ec) throw InputError(path_ + ": cannot create the output folder (is its parent writable?)");
}

AtomicFolder::~AtomicFolder() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

void AtomicFolder::commit() {
  std::error_code ec;
  if (!fs::exists(path_, ec)) {
    if (std::rename(staging_.c_str(), path_.c_str()) != 0)
      throw InputError(path_ + ": cannot move the finished outputs into place (" + std::strerror(errno) + ")");
  } else if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, path_.c_str(), RENAME_EXCHANGE) == 0) {
    fs::remove_all(staging_, ec);  // now the earlier folder
  } else if (errno == EINVAL || errno == ENOSYS) {
    // No exchange on this file system: move the earlier folder aside, then the new one in. A kill
    // between the two leaves the target missing for a moment; the next run restores it.
    const std::string aside = asidePathFor(path_);
    fs::remove_all(aside, ec);
    if (std::rename(path_.c_str(), aside.c_str()) != 0)
      throw InputError(path_ + ": cannot replace the earlier outputs (" + std::strerror(errno) + ")");
    if (std::rename(staging_.c_str(), path_.c_str()) != 0) {
      const int err = errno;
      std::rename(aside.c_str(), path_.c_str());
      throw InputError(path_ + ": cannot move the finished outputs into place (" + std::strerror(err) + ")");
    }
    fs::remove_all(aside, ec);
  } else {
    throw InputError(path_ + ": cannot replace the earlier outputs (" + std::strerror(errno) + ")");
  }
  committed_ = true;
}

bool isReplaceableOutputFolder(const std::string& dir, const std::string& marker_file,
                               const std::function<bool(const std::string& first_line)>& is_marker) {
  std::error_code ec;
  if (fs::is_empty(dir, ec) && !ec) return true;
  std::ifstream marker(fs::path(dir) / marker_file);
  std::string first;
  if (marker && std::getline(marker, first) && is_marker(first)) return true;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name != ".urbanslam-write-test" && (name.empty() || name[0] != '.' || name.find(".partial-") == std::string::npos)) return false;
  }
  return !ec;
}

}  // namespace urbanslam::common
