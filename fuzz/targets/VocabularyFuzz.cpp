// The binary Tree of Words vocabulary. A mutation almost always breaks the checksum, so the input
// is loaded twice: as it is, and with its last 8 bytes replaced by the right checksum, which lets
// the fuzzer reach the header and tree checks behind it. A vocabulary that loads must quantize.
#include <cstring>
#include <vector>

#include "FuzzSupport.h"
#include "urbanslam/vision_loop/VocabularyFile.h"

namespace {

// The file's checksum (VocabularyFile.h): FNV-1a over 8-byte little-endian words, the tail
// zero-padded.
uint64_t checksum(const uint8_t* p, size_t n) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < n; i += 8) {
    uint8_t w[8] = {};
    std::memcpy(w, p + i, std::min<size_t>(8, n - i));
    uint64_t v = 0;
    for (int b = 7; b >= 0; --b) v = v << 8 | w[b];
    h = (h ^ v) * 0x100000001b3ull;
  }
  return h;
}

void load(const std::string& path) {
  using namespace urbanslam;
  fuzz::expectCleanOutcome(path, [&] {
    const vision_loop::Vocabulary v = vision_loop::loadVocabulary(path);
    if (v.descriptorBytes() <= 0) return;
    for (int fill : {0x00, 0x5a, 0xff}) {
      const std::vector<uint8_t> d(static_cast<size_t>(v.descriptorBytes()), static_cast<uint8_t>(fill));
      const auto w = v.quantize(d.data());
      if (w >= v.wordCount()) urbanslam::fuzz::fail("quantize gave a word outside the vocabulary", path);
    }
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  load(fuzz::writeInput("input.voc", data, size));
  if (size >= 16) {
    std::vector<uint8_t> fixed(data, data + size);
    const uint64_t sum = checksum(fixed.data(), size - 8);
    for (int b = 0; b < 8; ++b) fixed[size - 8 + b] = static_cast<uint8_t>(sum >> (8 * b));
    load(fuzz::writeInput("fixed.voc", fixed.data(), fixed.size()));
  }
  return 0;
}
