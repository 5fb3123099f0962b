// CARMEN logs, raw and Freiburg-corrected (the reader tells them apart), read to the end.
#include "FuzzSupport.h"
#include "urbanslam/io/CarmenReader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string path = fuzz::writeInput("input.log", data, size);
  fuzz::expectCleanOutcome(path, [&] {
    io::CarmenReader reader(path);
    io::Measurement m;
    while (reader.next(m)) {
    }
  });
  return 0;
}
