#pragma once
// A bound on what one thread may allocate while it deserialises untrusted data.
//
// MRPT's deserialisation reads a count from the file and allocates (and zero-fills) that many
// elements before it reads them, so a corrupt count in a 2 MB rawlog asks for gigabytes: the
// zero-filling alone takes them, or the allocation fails inside an allocator that returns null
// and the fill segfaults. There is no size prefix to check the objects against beforehand, so
// the bound is placed where the count takes effect: while a ScopedAllocationLimit is alive, an
// allocation on its thread through operator new or mrpt::aligned_malloc (MRPT's aligned vectors:
// scan ranges, point clouds) that is larger than `max_block` bytes, or that brings the total
// allocated in the scope beyond `max_total`, throws std::bad_alloc. The first refusal ends the
// limit, so the error handling that follows can allocate as usual.
#include <cstddef>

namespace urbanslam::io::detail {

class ScopedAllocationLimit {
 public:
  ScopedAllocationLimit(size_t max_block, size_t max_total);
  ~ScopedAllocationLimit();
  ScopedAllocationLimit(const ScopedAllocationLimit&) = delete;
  ScopedAllocationLimit& operator=(const ScopedAllocationLimit&) = delete;

  // Lifts the limit before the scope ends.
  void end();
  // Size of the refused request, 0 when nothing was refused.
  size_t refusedBytes() const;
  // Bytes allocated in the scope so far.
  size_t allocatedBytes() const;
};

}  // namespace urbanslam::io::detail
