// Format detection by content: the input, under a name that says nothing, goes through
// io::openDataSource (the path every command takes) and is read to the end by whichever reader
// the content picks.
#include "FuzzSupport.h"
#include "urbanslam/io/DataSource.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string path = fuzz::writeInput("input", data, size);
  fuzz::expectCleanOutcome(path, [&] {
    auto source = io::openDataSource(path);
    io::Measurement m;
    while (source->next(m)) {
    }
  });
  return 0;
}
