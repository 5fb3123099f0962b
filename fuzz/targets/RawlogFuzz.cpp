// MRPT rawlogs, both layouts, plain or gzipped, read to the end.
#include "FuzzSupport.h"
#include "urbanslam/io/RawlogReader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string path = fuzz::writeInput("input.rawlog", data, size);
  fuzz::expectCleanOutcome(path, [&] {
    io::RawlogReader reader(path);
    io::Measurement m;
    while (reader.next(m)) {
    }
  });
  return 0;
}
