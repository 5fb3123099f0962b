// Victoria Park as its published zip (victoria_park_ascii.zip with LASER.txt, DRS.txt and
// GPS.txt inside): the input is the archive, read to the end through libzip.
#include "FuzzSupport.h"
#include "urbanslam/io/VictoriaParkReader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string path = fuzz::writeInput("victoria_park_ascii.zip", data, size);
  // An error about an entry names "ARCHIVE:ENTRY", which contains the archive's path.
  fuzz::expectCleanOutcome(path, [&] {
    io::VictoriaParkReader reader(path);
    io::Measurement m;
    while (reader.next(m)) {
    }
  });
  return 0;
}
