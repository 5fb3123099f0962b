// The laser loop-closure classifier's model file.
#include "FuzzSupport.h"
#include "urbanslam/laser_loop/ClassifierModel.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string name = "input.model";
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::expectCleanOutcome(name, [&] {
    const laser_loop::ClassifierModel m = laser_loop::parseModel(text, name);
    // A model that loads writes back to one that loads the same.
    const laser_loop::ClassifierModel again = laser_loop::parseModel(laser_loop::modelToText(m), name);
    const std::string first = laser_loop::modelToText(m), second = laser_loop::modelToText(again);
    if (first != second) {
      // The first line that differs, for the report.
      size_t at = 0;
      while (at < first.size() && at < second.size() && first[at] == second[at]) ++at;
      const size_t line = first.rfind('\n', at) == std::string::npos ? 0 : first.rfind('\n', at) + 1;
      fuzz::fail("model does not round-trip",
                 first.substr(line, first.find('\n', at) - line) + " | " + second.substr(line, second.find('\n', at) - line));
    }
  });
  return 0;
}
