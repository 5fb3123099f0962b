#pragma once
// Outputs are written to a temporary name beside the target and renamed when complete, so an
// interrupted run never leaves a half-written file that looks complete (rename is atomic on
// POSIX within one file system).
#include <fstream>
#include <functional>
#include <string>

namespace urbanslam::common {

// Writes through a std::ofstream; commit() renames, the destructor removes an uncommitted file.
class AtomicFile {
 public:
  explicit AtomicFile(std::string path, bool binary = false);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return out_; }
  const std::string& tempPath() const { return temp_; }
  // Flushes, checks for write errors and renames into place. Throws InputError on failure.
  void commit();

 private:
  std::string path_, temp_;
  std::ofstream out_;
  bool committed_ = false;
};

// `text` written to `path` through an AtomicFile (stats.json and the like).
void writeTextAtomically(const std::string& path, const std::string& text);

// For writers that insist on a filename (MRPT's savers): `write` gets the temporary path.
// The extension is kept so writers that infer a format from it still work.
void writeAtomically(const std::string& path, const std::function<void(const std::string& tmp)>& write);

// Temporary name for `path`: same folder, same extension, unique per process.
std::string temporaryPathFor(const std::string& path);

// Removes the temporaries that killed processes left for `path` (".name.partial-PID.ext" whose
// process no longer exists; folders too). Those of live processes are left alone.
void removeStaleTemporaries(const std::string& path);

// True while a process with this id exists.
bool processAlive(long pid);

}  // namespace urbanslam::common
