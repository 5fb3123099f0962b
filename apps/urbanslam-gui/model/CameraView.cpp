#include "CameraView.h"

#include <cstdio>

namespace urbanslam::gui {

namespace {

CameraFrame keyframeFrame(const MapSnapshot& s, size_t k, const char* role) {
  CameraFrame f;
  if (k >= s.keyframes.size()) return f;
  f.image = s.keyframes[k].image;
  f.keyframe = k;
  char buf[160];
  if (f.image)
    std::snprintf(buf, sizeof buf, "%s\nkeyframe %zu, t = %.3f s", role, k, f.image->timestamp);
  else
    std::snprintf(buf, sizeof buf, "%s\nkeyframe %zu: no image", role, k);
  f.caption = buf;
  return f;
}

}  // namespace

CameraView cameraView(const MapSnapshot& s, std::optional<size_t> selected) {
  CameraView v;
  std::optional<size_t> left = selected;
  if (!left) {
    for (size_t i = s.keyframes.size(); i-- > 0;)
      if (s.keyframes[i].image) {
        left = i;
        break;
      }
  }
  if (left) {
    v.current = keyframeFrame(s, *left, selected ? "selected" : "current");
  } else if (s.last_image) {
    v.current.image = s.last_image;
    char buf[80];
    std::snprintf(buf, sizeof buf, "camera frame\nt = %.3f s", s.last_image->timestamp);
    v.current.caption = buf;
  }
  if (!left) return v;
  // The proposal to show: for a clicked keyframe, its own latest one (as either side); for the
  // running view, the newest proposal while it is recent.
  for (auto it = s.image_matches.rbegin(); it != s.image_matches.rend(); ++it) {
    const bool mine =
        selected ? (it->current == *left || it->matched == *left) : it->current <= *left && *left - it->current <= kMatchHoldKeyframes;
    if (mine) {
      v.match = *it;
      break;
    }
    if (!selected) break;  // only the newest proposal counts for the running view
  }
  if (!v.match) return v;
  const ImageMatchView& m = *v.match;
  // For a clicked keyframe that is the earlier side of the proposal, the other side is the later one.
  const size_t other = selected && m.matched == *left ? m.current : m.matched;
  if (!selected && m.current != *left) v.current = keyframeFrame(s, m.current, "proposal");
  v.matched = keyframeFrame(s, other, "matched");
  char buf[200];
  std::snprintf(buf, sizeof buf, "Tree of Words: keyframe %zu matches %zu\nscore %.2f, %s", m.current, m.matched, m.score, m.fate.c_str());
  v.match_caption = buf;
  return v;
}

}  // namespace urbanslam::gui
