#pragma once
// The process's heap policy, set once at the start of a program.

namespace urbanslam::common {

// Local SLAM builds a likelihood grid of its submap at every keyframe: megabytes that glibc
// would map fresh and hand back each time (its default above 128 KiB), so every build faulted
// its pages in again (7 % of a run on the UAL rawlog). This keeps blocks up to 32 MiB in the
// heap and holds back up to 64 MiB of free memory for the next build.
void keepFreedBuffers();

}  // namespace urbanslam::common
