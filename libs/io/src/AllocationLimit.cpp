#include "AllocationLimit.h"

#include <mrpt/core/aligned_allocator.h>

#include <cstdlib>
#include <new>

namespace urbanslam::io::detail {

namespace {

// Constant-initialised, so reading it costs one TLS access per allocation.
struct LimitState {
  bool active = false;
  size_t max_block = 0, max_total = 0, total = 0, refused = 0;
};
thread_local LimitState t_limit;

// True when an allocation of n bytes may go ahead on this thread.
bool admit(size_t n) {
  LimitState& s = t_limit;
  if (!s.active) return true;
  if (n > s.max_block || n > s.max_total - s.total) {
    s.refused = n;
    s.active = false;
    return false;
  }
  s.total += n;
  return true;
}

void* allocate(size_t n) {
  if (!admit(n)) throw std::bad_alloc();
  for (;;) {
    if (void* p = std::malloc(n ? n : 1)) return p;
    std::new_handler h = std::get_new_handler();
    if (!h) throw std::bad_alloc();
    h();
  }
}

void* allocateAligned(size_t n, size_t alignment) {
  if (!admit(n)) throw std::bad_alloc();
  // aligned_alloc wants a size that is a multiple of the alignment.
  const size_t size = alignment ? (n + alignment - 1) / alignment * alignment : n;
  if (void* p = std::aligned_alloc(alignment, size ? size : alignment)) return p;
  throw std::bad_alloc();
}

}  // namespace

ScopedAllocationLimit::ScopedAllocationLimit(size_t max_block, size_t max_total) { t_limit = {true, max_block, max_total, 0, 0}; }
ScopedAllocationLimit::~ScopedAllocationLimit() { end(); }
void ScopedAllocationLimit::end() { t_limit.active = false; }
size_t ScopedAllocationLimit::refusedBytes() const { return t_limit.refused; }
size_t ScopedAllocationLimit::allocatedBytes() const { return t_limit.total; }

}  // namespace urbanslam::io::detail

// Replacements of the global allocation functions (the C++ standard allows a program to
// replace them), with the matching deallocation functions: both sides go through malloc/free.
// The library's operator delete also calls free(), but AddressSanitizer's tells the two
// apart, and a pair from one place keeps new and delete matched for any runtime.
using urbanslam::io::detail::allocate;
using urbanslam::io::detail::allocateAligned;

void* operator new(size_t n) { return allocate(n); }
void* operator new[](size_t n) { return allocate(n); }
void* operator new(size_t n, const std::nothrow_t&) noexcept {
  try {
    return allocate(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](size_t n, const std::nothrow_t&) noexcept {
  try {
    return allocate(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(size_t n, std::align_val_t a) { return allocateAligned(n, static_cast<size_t>(a)); }
void* operator new[](size_t n, std::align_val_t a) { return allocateAligned(n, static_cast<size_t>(a)); }
void* operator new(size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return allocateAligned(n, static_cast<size_t>(a));
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return allocateAligned(n, static_cast<size_t>(a));
  } catch (...) {
    return nullptr;
  }
}

// MRPT's aligned containers allocate through this. libmrpt-core's own version returns null on
// failure, which the containers do not check (they write through it); this one throws
// std::bad_alloc instead, as an allocator should, and applies the limit.
void* mrpt::aligned_malloc(size_t size, size_t alignment) { return allocateAligned(size, alignment); }

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
void operator delete[](void* p, size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
