// The Victoria Park folder: the input holds LASER.txt, DRS.txt and GPS.txt in that order,
// separated by lines "@@@" (a missing part is an empty file), and is read to the end.
#include <filesystem>

#include "FuzzSupport.h"
#include "urbanslam/io/VictoriaParkReader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto dir = fuzz::scratchDir() / "victoria";
  std::filesystem::create_directories(dir);
  const char* names[] = {"LASER.txt", "DRS.txt", "GPS.txt"};
  size_t at = 0;
  for (int k = 0; k < 3; ++k) {
    size_t end = k < 2 ? text.find("\n@@@\n", at) : std::string::npos;
    if (end == std::string::npos) end = text.size();
    const std::string part = at < text.size() ? text.substr(at, end - at) : std::string();
    fuzz::writeInput(std::string("victoria/") + names[k], part);
    at = std::min(text.size(), end + 5);
  }
  const std::string path = dir.string();
  fuzz::expectCleanOutcome(path, [&] {
    io::VictoriaParkReader reader(path);
    io::Measurement m;
    while (reader.next(m)) {
    }
  });
  return 0;
}
