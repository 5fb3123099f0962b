// The run's ini file: syntax (IniFile) and every key, type and range of the pipeline's options
// schema, as `run --ini` and `check-ini` load it, and the resolved configuration printed back.
#include "FuzzSupport.h"
#include "urbanslam/slam/PipelineOptions.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string path = fuzz::writeInput("input.ini", data, size);
  fuzz::expectCleanOutcome(path, [&] {
    std::string resolved;
    slam::loadPipelineOptions(path, &resolved);
    // What check-ini prints loads again.
    const std::string again_path = fuzz::writeInput("resolved.ini", resolved);
    try {
      slam::loadPipelineOptions(again_path);
    } catch (const common::InputError& e) {
      fuzz::fail("the resolved configuration does not load", e.what());
    }
  });
  return 0;
}
