#include "urbanslam/vision_loop/Descriptor.h"

#include <algorithm>
#include <cctype>
#include <cstring>

#include "urbanslam/common/Error.h"

namespace urbanslam::vision_loop {

int descriptorBytes(DescriptorType type) { return type == DescriptorType::Sift ? 128 : 32; }

std::string descriptorName(DescriptorType type) { return type == DescriptorType::Sift ? "sift" : "orb"; }

DescriptorType parseDescriptorType(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::tolower(c); });
  if (n == "sift") return DescriptorType::Sift;
  if (n == "orb") return DescriptorType::Orb;
  throw common::InputError("descriptor '" + name + "' is not one of sift|orb");
}

// Written as plain loops so that GCC vectorises them (this file is compiled with -O3). The
// target clones pick AVX2 / the POPCNT instruction at load time where the CPU has them, and
// fall back to baseline x86-64 elsewhere, so the binary stays portable.
__attribute__((target_clones("avx2", "default"))) int32_t dotProduct(const uint8_t* a, const uint8_t* b, int bytes) {
  int32_t sum = 0;
  for (int i = 0; i < bytes; ++i) sum += static_cast<int32_t>(a[i]) * static_cast<int32_t>(b[i]);
  return sum;
}

__attribute__((target_clones("popcnt", "default"))) int hammingDistance(const uint8_t* a, const uint8_t* b, int bytes) {
  int d = 0;
  for (int i = 0; i < bytes; i += 8) {
    uint64_t x, y;
    std::memcpy(&x, a + i, 8);
    std::memcpy(&y, b + i, 8);
    d += __builtin_popcountll(x ^ y);
  }
  return d;
}

}  // namespace urbanslam::vision_loop
