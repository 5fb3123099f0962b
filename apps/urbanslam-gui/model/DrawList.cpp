#include "DrawList.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::gui {

void Bounds::add(float x, float y) {
  if (empty) {
    xmin = xmax = x;
    ymin = ymax = y;
    empty = false;
    return;
  }
  xmin = std::min(xmin, x);
  xmax = std::max(xmax, x);
  ymin = std::min(ymin, y);
  ymax = std::max(ymax, y);
}

Rgb ageColour(size_t i, size_t n) {
  const float t = n > 1 ? static_cast<float>(i) / static_cast<float>(n - 1) : 1.f;
  // blue (old) -> cyan -> white-ish -> orange (new): readable on a dark background.
  const float r = std::clamp(-0.2f + 1.4f * t, 0.25f, 1.f);
  const float g = std::clamp(0.45f + 0.5f * std::sin(t * 3.14159f), 0.3f, 0.95f);
  const float b = std::clamp(1.1f - 1.0f * t, 0.2f, 1.f);
  return {static_cast<uint8_t>(255 * r), static_cast<uint8_t>(255 * g), static_cast<uint8_t>(255 * b)};
}

std::optional<Ellipse> uncertaintyEllipse(const common::Pose2& pose, const std::array<double, 9>& cov) {
  const double sxx = cov[0], sxy = cov[1], syy = cov[4];
  if (sxx <= 0 && syy <= 0) return std::nullopt;
  // Eigen-decomposition of the symmetric 2x2 block.
  const double tr = sxx + syy, det = sxx * syy - sxy * sxy;
  const double disc = std::sqrt(std::max(0.0, tr * tr / 4 - det));
  const double l1 = tr / 2 + disc, l2 = std::max(0.0, tr / 2 - disc);
  const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);
  return Ellipse{static_cast<float>(pose.x), static_cast<float>(pose.y), static_cast<float>(3 * std::sqrt(l1)),
                 static_cast<float>(3 * std::sqrt(l2)), static_cast<float>(angle)};
}

DrawList buildDrawList(const MapSnapshot& s, const Layers& layers) {
  DrawList d;
  const size_t n = s.keyframes.size();
  d.keyframes_drawn = n;
  for (size_t i = 0; i < n; ++i) {
    const auto& k = s.keyframes[i];
    d.bounds.add(static_cast<float>(k.pose.x), static_cast<float>(k.pose.y));
    if (!layers.map_points || !k.points) continue;
    const Rgb c = layers.colouring == PointColouring::KeyframeAge ? ageColour(i, n) : palette::kHeight;
    const double cs = std::cos(k.pose.phi), sn = std::sin(k.pose.phi);
    for (const auto& p : *k.points) {
      const float x = static_cast<float>(k.pose.x + cs * p.x - sn * p.y);
      const float y = static_cast<float>(k.pose.y + sn * p.x + cs * p.y);
      d.map_points.push_back({x, y, 0.f, c});
      d.bounds.add(x, y);
    }
  }
  if (layers.trajectory && !s.localizing)  // localizing: the path drawn is the vehicle's, below
    for (size_t i = 1; i < n; ++i)
      d.trajectory.push_back({static_cast<float>(s.keyframes[i - 1].pose.x), static_cast<float>(s.keyframes[i - 1].pose.y),
                              static_cast<float>(s.keyframes[i].pose.x), static_cast<float>(s.keyframes[i].pose.y)});
  if (s.localizing) {
    // The map stays as saved; the vehicle is the last localized pose, its path coloured by
    // whether each stretch was tracked or lost.
    if (layers.trajectory)
      for (size_t i = 1; i < s.localized.size(); ++i) {
        const auto& a = s.localized[i - 1].pose;
        const auto& b = s.localized[i].pose;
        (s.localized[i].tracking ? d.localized_tracked : d.localized_lost)
            .push_back({static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(b.x), static_cast<float>(b.y)});
      }
    if (!s.localized.empty()) {
      d.current_pose = s.localized.back().pose;
      if (layers.uncertainty) d.uncertainty = uncertaintyEllipse(*d.current_pose, s.current_covariance);
    }
  } else if (n > 0) {
    const auto& cur = s.keyframes.back();
    d.current_pose = cur.pose;
    if (layers.current_scan && cur.points) {
      const double cs = std::cos(cur.pose.phi), sn = std::sin(cur.pose.phi);
      for (const auto& p : *cur.points)
        d.current_scan.push_back({static_cast<float>(cur.pose.x + cs * p.x - sn * p.y),
                                  static_cast<float>(cur.pose.y + sn * p.x + cs * p.y), 0.05f, palette::kCurrentScan});
    }
    if (layers.uncertainty) d.uncertainty = uncertaintyEllipse(cur.pose, s.current_covariance);
  }
  if (layers.selected_keyframe && *layers.selected_keyframe < n) {
    const auto& k = s.keyframes[*layers.selected_keyframe];
    const double cs = std::cos(k.pose.phi), sn = std::sin(k.pose.phi);
    if (k.points)
      for (const auto& p : *k.points)
        d.selected_scan.push_back({static_cast<float>(k.pose.x + cs * p.x - sn * p.y), static_cast<float>(k.pose.y + sn * p.x + cs * p.y),
                                   0.07f, palette::kSelected});
  }
  for (const auto& c : s.closures) {
    if (c.from_keyframe >= n || c.to_keyframe >= n) continue;
    const auto& a = s.keyframes[c.from_keyframe].pose;
    const auto& b = s.keyframes[c.to_keyframe].pose;
    const Segment seg{static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(b.x), static_cast<float>(b.y)};
    if (c.accepted && layers.closures_accepted) d.closures_accepted.push_back(seg);
    if (!c.accepted && layers.closures_rejected) d.closures_rejected.push_back(seg);
  }
  if (layers.candidates)
    for (size_t i : s.candidates)
      if (i < n) d.candidates.push_back(s.keyframes[i].pose);
  return d;
}

std::optional<size_t> pickKeyframe(const MapSnapshot& s, double x, double y, double max_dist_m) {
  std::optional<size_t> best;
  double best_d = max_dist_m;
  for (size_t i = 0; i < s.keyframes.size(); ++i) {
    const double d = std::hypot(s.keyframes[i].pose.x - x, s.keyframes[i].pose.y - y);
    if (d <= best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

}  // namespace urbanslam::gui
