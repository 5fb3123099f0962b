// Freiburg relation files (eval --relations).
#include "FuzzSupport.h"
#include "urbanslam/evaluation/Evaluation.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string path = fuzz::writeInput("input.relations", data, size);
  fuzz::expectCleanOutcome(path, [&] { evaluation::readRelations(path); });
  return 0;
}
