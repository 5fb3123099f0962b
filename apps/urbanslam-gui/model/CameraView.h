#pragma once
// What the camera panel shows, decided without wx: the current keyframe's frame (or the clicked
// keyframe's) on the left and, when Tree of Words proposed a closure for it, the matched earlier
// frame on the right with the score and the proposal's fate.
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "MapSnapshot.h"

namespace urbanslam::gui {

struct CameraFrame {
  std::shared_ptr<const io::CameraImage> image;  // null: nothing to show
  std::optional<size_t> keyframe;                // the keyframe it belongs to, if any
  std::string caption;
};

struct CameraView {
  CameraFrame current, matched;
  std::optional<ImageMatchView> match;  // the proposal behind `matched`
  std::string match_caption;            // e.g. "Tree of Words: keyframe 41 matches 3\nscore 0.74, accepted"
};

// A proposal stays on screen this many keyframes after it was made, so a short-lived match is
// visible while the run goes on (a later proposal replaces it).
constexpr size_t kMatchHoldKeyframes = 5;

// `selected`: the keyframe clicked in the map (its image and its latest proposal), else the
// newest keyframe with an image (or the latest camera frame when no keyframe has one yet).
CameraView cameraView(const MapSnapshot& s, std::optional<size_t> selected = std::nullopt);

}  // namespace urbanslam::gui
