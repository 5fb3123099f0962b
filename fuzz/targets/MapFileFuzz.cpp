// map.usmap (slam/MapFile.h). A mutation almost always breaks the payload's length or checksum,
// so the input is loaded twice: as it is, and with the header's length and checksum made right,
// which lets the fuzzer reach the sections behind them. A map that loads must encode again, and
// that encoding must load. The file's separate maps are read too.
#include <memory>
#include <vector>

#include "FuzzSupport.h"
#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/slam/MapFile.h"

namespace {

constexpr size_t kHeaderBytes = 28;  // signature 8, version 4, payload length 8, checksum 8

void load(const std::string& path) {
  using namespace urbanslam;
  fuzz::expectCleanOutcome(path, [&] {
    std::vector<std::unique_ptr<slam::Pipeline>> separate;
    const auto pipeline = slam::loadMap(path, nullptr, &separate);
    std::vector<const slam::Pipeline*> others;
    for (const auto& p : separate) others.push_back(p.get());
    const std::string again = fuzz::writeInput("again.usmap", slam::encodeMap(*pipeline, others));
    try {
      slam::loadMap(again, nullptr, &separate);
    } catch (const common::InputError& e) {
      fuzz::fail("a loaded map does not load again once encoded", e.what());
    }
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  load(fuzz::writeInput("input.usmap", data, size));
  if (size >= kHeaderBytes) {
    std::vector<uint8_t> fixed(data, data + size);
    const uint64_t length = size - kHeaderBytes;
    const uint64_t sum = common::fnv1a64(fixed.data() + kHeaderBytes, length);
    for (int b = 0; b < 8; ++b) {
      fixed[12 + b] = static_cast<uint8_t>(length >> (8 * b));
      fixed[20 + b] = static_cast<uint8_t>(sum >> (8 * b));
    }
    load(fuzz::writeInput("fixed.usmap", fixed.data(), fixed.size()));
  }
  return 0;
}
