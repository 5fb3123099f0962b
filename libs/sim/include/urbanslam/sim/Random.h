#pragma once
// Deterministic randomness for the simulator. Everything the city contains is a pure function of
// (seed, what, indices) through hash64(), so any part of the city can be built on its own, in any
// order, with the same result. Rng is a small, fast generator whose sequence is fixed by this
// code (std:: distributions are implementation-defined, so they would not give byte-identical
// outputs across standard libraries).
#include <cmath>
#include <cstdint>

namespace urbanslam::sim {

// SplitMix64 finaliser: a well-mixed 64-bit value from any 64-bit input.
inline uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Hash of a seed, a tag naming what is generated (so different features never share draws) and
// up to three signed indices.
inline uint64_t hash64(uint64_t seed, uint64_t tag, int64_t a = 0, int64_t b = 0, int64_t c = 0) {
  uint64_t h = mix64(seed ^ mix64(tag));
  h = mix64(h ^ static_cast<uint64_t>(a));
  h = mix64(h ^ (static_cast<uint64_t>(b) * 0x9e3779b97f4a7c15ULL));
  h = mix64(h ^ (static_cast<uint64_t>(c) * 0xc2b2ae3d27d4eb4fULL));
  return h;
}

// Uniform in [0,1) from a hash.
inline double unitFromHash(uint64_t h) { return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0); }

class Rng {
 public:
  explicit Rng(uint64_t state) : state_(state) {}
  uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return unitFromHash(next()); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Integer in [lo, hi] inclusive.
  int uniformInt(int lo, int hi) { return lo + static_cast<int>(uniform() * (hi - lo + 1)); }
  bool chance(double p) { return uniform() < p; }
  // Standard normal by Box-Muller (one value per call; simple and reproducible).
  double normal() {
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
  double normal(double sigma) { return sigma * normal(); }

 private:
  uint64_t state_;
};

}  // namespace urbanslam::sim
