#pragma once
// Which source proposed a loop-closure pair: the estimate (the nearest keyframes; alignment and
// gating verify), the laser classifier, the Tree of Words, or a place search joining a session
// to a map (SessionJoin.h). Closure records, observer events and session fixes carry it.
#include <cstdint>
#include <optional>
#include <string>

namespace urbanslam::slam {

enum class Proposer : std::uint8_t { Pose, Laser, Image, Place };
// Its name in loop_closures.csv, map.usmap and the GUI: "pose", "laser", "image", "place".
const char* proposerName(Proposer p);
// The proposer of that name, if any.
std::optional<Proposer> parseProposer(const std::string& name);

}  // namespace urbanslam::slam
