#include "urbanslam/slam/Proposer.h"

namespace urbanslam::slam {

const char* proposerName(Proposer p) {
  switch (p) {
    case Proposer::Pose:
      return "pose";
    case Proposer::Laser:
      return "laser";
    case Proposer::Image:
      return "image";
    case Proposer::Place:
      return "place";
  }
  return "";
}

std::optional<Proposer> parseProposer(const std::string& name) {
  for (const Proposer p : {Proposer::Pose, Proposer::Laser, Proposer::Image, Proposer::Place})
    if (name == proposerName(p)) return p;
  return std::nullopt;
}

}  // namespace urbanslam::slam
