// g2o and TORO pose graphs, parsed, then written and parsed again in both formats (what the
// graph command does with a file it read).
#include "FuzzSupport.h"
#include "urbanslam/esdf/PoseGraphIO.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const std::string name = "input.g2o";
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::expectCleanOutcome(name, [&] {
    const esdf::PoseGraph g = esdf::parsePoseGraph(text, name);
    for (auto format : {esdf::PoseGraphFormat::G2o, esdf::PoseGraphFormat::Toro}) {
      const esdf::PoseGraph again = esdf::parsePoseGraph(esdf::formatPoseGraph(g, format), name);
      if (again.vertices.size() != g.vertices.size() || again.edges.size() != g.edges.size())
        fuzz::fail("written graph reads back differently", name);
    }
  });
  return 0;
}
