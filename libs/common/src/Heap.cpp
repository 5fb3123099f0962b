#include "urbanslam/common/Heap.h"

#include <malloc.h>

namespace urbanslam::common {

void keepFreedBuffers() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
}

}  // namespace urbanslam::common
