#pragma once
// What the map view draws, computed from a snapshot without any GUI toolkit: coloured map
// points, trajectory, current scan and pose with its uncertainty ellipse, loop closures
// (accepted and rejected in different colours) and the candidate set. MapCanvas turns it into
// MRPT OpenGL objects; tests check it directly.
#include <cstdint>
#include <optional>
#include <vector>

#include "MapSnapshot.h"

namespace urbanslam::gui {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb& o) const { return r == o.r && g == o.g && b == o.b; }
};

enum class PointColouring { KeyframeAge, Height };

struct Layers {
  bool map_points = true;
  bool trajectory = true;
  bool current_scan = true;
  bool uncertainty = true;
  bool closures_accepted = true;
  bool closures_rejected = true;
  bool candidates = true;
  PointColouring colouring = PointColouring::KeyframeAge;
  std::optional<size_t> selected_keyframe;  // its scan is highlighted (click to inspect)
};

struct ColouredPoint {
  float x = 0, y = 0, z = 0;
  Rgb colour;
};

struct Segment {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

struct Ellipse {
  float cx = 0, cy = 0, a = 0, b = 0, angle_rad = 0;  // semi-axes at 3 sigma
};

struct Bounds {
  float xmin = 0, xmax = 0, ymin = 0, ymax = 0;
  bool empty = true;
  void add(float x, float y);
};

// The fixed palette of the view (also used by the screenshot test).
namespace palette {
constexpr Rgb kBackground{24, 26, 30};
constexpr Rgb kTrajectory{255, 210, 60};
constexpr Rgb kCurrentScan{255, 60, 60};
constexpr Rgb kClosureAccepted{60, 230, 90};
constexpr Rgb kClosureRejected{235, 70, 200};
constexpr Rgb kCandidate{90, 200, 255};
constexpr Rgb kHeight{200, 200, 210};
constexpr Rgb kSelected{255, 255, 255};
constexpr Rgb kLocalizedTracked{40, 230, 40};  // outside the age ramp (its red and blue never drop below 64 and 51)
constexpr Rgb kLocalizedLost{255, 90, 40};
}  // namespace palette

// Colour of keyframe `i` of `n` for age colouring: old = blue, new = warm (a perceptual ramp).
Rgb ageColour(size_t i, size_t n);

struct DrawList {
  std::vector<ColouredPoint> map_points;
  std::vector<Segment> trajectory;
  std::vector<ColouredPoint> current_scan;
  std::vector<ColouredPoint> selected_scan;
  std::optional<common::Pose2> current_pose;
  std::optional<Ellipse> uncertainty;
  std::vector<Segment> closures_accepted, closures_rejected;
  // Localizing in a saved map: the vehicle's path, each segment by the state at its end.
  std::vector<Segment> localized_tracked, localized_lost;
  std::vector<common::Pose2> candidates;
  Bounds bounds;  // of everything drawn, for fit-to-map
  size_t keyframes_drawn = 0;
};

DrawList buildDrawList(const MapSnapshot& s, const Layers& layers);

// 3-sigma ellipse of the (x, y) block of a row-major 3x3 covariance; nullopt when it is zero.
std::optional<Ellipse> uncertaintyEllipse(const common::Pose2& pose, const std::array<double, 9>& cov);

// Index of the keyframe nearest to (x, y) within max_dist_m, for click-to-inspect.
std::optional<size_t> pickKeyframe(const MapSnapshot& s, double x, double y, double max_dist_m);

}  // namespace urbanslam::gui
