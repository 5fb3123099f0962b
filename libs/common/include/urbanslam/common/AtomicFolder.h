#pragma once
// A folder of outputs that appears complete or not at all: everything is written into a fresh
// staging folder beside the target (".name.partial-PID") and commit() swaps it into place in one
// atomic step (renameat2 RENAME_EXCHANGE), then deletes the earlier folder. A process killed at
// any moment leaves either the earlier complete folder or the new complete one at the target;
// the staging folders of killed processes are removed by the next AtomicFolder of that target.
#include <functional>
#include <string>

namespace urbanslam::common {

class AtomicFolder {
 public:
  // `replaceable(path)` says whether an existing folder at the target may be replaced (for a run
  // folder: it is one); when it says no, the constructor throws InputError.
  AtomicFolder(std::string path, const std::function<bool(const std::string&)>& replaceable);
  ~AtomicFolder();
  AtomicFolder(const AtomicFolder&) = delete;
  AtomicFolder& operator=(const AtomicFolder&) = delete;

  // Where to write the outputs until commit().
  const std::string& stagingPath() const { return staging_; }
  // Swaps the staging folder into place and removes the earlier one. Throws InputError.
  void commit();

 private:
  std::string path_, staging_;
  bool committed_ = false;
};

// Whether an existing folder may be replaced by a writer's outputs: it is empty, or its
// `marker_file` has a first line that `is_marker` accepts (an earlier output of that writer), or
// it holds only the hidden temporaries an interrupted writer left. Anything else may be a
// user's folder, and is never deleted.
bool isReplaceableOutputFolder(const std::string& dir, const std::string& marker_file,
                               const std::function<bool(const std::string& first_line)>& is_marker);

}  // namespace urbanslam::common
