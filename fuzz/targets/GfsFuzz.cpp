// GMapping gfs logs, read to the end.
#include "FuzzSupport.h"
#include "urbanslam/io/GfsReader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string path = fuzz::writeInput("input.gfs", data, size);
  fuzz::expectCleanOutcome(path, [&] {
    io::GfsReader reader(path);
    io::Measurement m;
    while (reader.next(m)) {
    }
  });
  return 0;
}
