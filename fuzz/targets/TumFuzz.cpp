// TUM trajectories (eval --reference / --estimate).
#include "FuzzSupport.h"
#include "urbanslam/io/MapOutputs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string path = fuzz::writeInput("input.tum", data, size);
  fuzz::expectCleanOutcome(path, [&] { io::readTum(path); });
  return 0;
}
