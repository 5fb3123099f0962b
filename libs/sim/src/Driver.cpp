#include "urbanslam/sim/Driver.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/sim/Bicycle.h"

namespace urbanslam::sim {

namespace {
constexpr double kDeg = M_PI / 180.0;
}

Driver::Driver(const StreetGrid& grid, const SimOptions& options)
    : grid_(grid),
      vehicle_(options.vehicle),
      route_(options.route),
      route_length_m_(options.route.route_length_km * 1000.0),
      planner_(grid, options.route, static_cast<uint64_t>(options.route.seed != 0 ? options.route.seed : options.city.seed)) {
  nodes_.push_back(planner_.current());
  while (path_.size() < 4) extendPath();
  const Vec2 a = path_[0].p, b = path_[1].p;
  state_.pose = {a.x, a.y, std::atan2(b.y - a.y, b.x - a.x)};
}

double Driver::clearance(NodeId n) const {
  // How far from an intersection's centre the lanes of its pieces start: past the cross street,
  // the wider crossing of an avenue, or a roundabout's ring.
  if (grid_.isRoundabout(n)) return grid_.ringOuterRadius() + 1.0;
  for (const NodeId& m : grid_.neighbours(n))
    if (grid_.pieceHalfWidth(n, m) > grid_.streetWidth() / 2) return (grid_.streetWidth() / 2 + grid_.avenueHalfWidth()) / 2;
  return grid_.streetWidth() / 2;
}

void Driver::extendPath() {
  while (nodes_.size() < 3) nodes_.push_back(planner_.advance());
  const Vec2 a = grid_.node(nodes_[0]), b = grid_.node(nodes_[1]), c = grid_.node(nodes_[2]);
  const double len = norm(b - a);
  const Vec2 d = (1.0 / len) * (b - a), e = (1.0 / norm(c - b)) * (c - b);
  const Vec2 right{d.y, -d.x};
  const double off = grid_.pieceLaneOffset(nodes_[0], nodes_[1]);
  // Short pieces (an avenue crossing next to a grid intersection) share what length they have.
  double ra = clearance(nodes_[0]), rb = clearance(nodes_[1]);
  if (ra + rb > 0.8 * len) {
    const double f = 0.8 * len / (ra + rb);
    ra *= f;
    rb *= f;
  }
  const Vec2 entry = a + ra * d + off * right, exit = b - rb * d + off * right;
  const bool roundabout = grid_.isRoundabout(nodes_[1]);
  // Turning at b: limit the speed at the lane's end and at the next lane's start.
  const bool turn = roundabout || std::fabs(cross(d, e)) > 0.5 || dot(d, e) < 0;
  const double cruise = route_.speed_mps, limit = turn ? std::min(route_.turn_speed_mps, cruise) : cruise;
  auto push = [&](Vec2 p, double lim) {
    const double s = path_.empty() ? 0.0 : path_.back().s + norm(p - path_.back().p);
    if (!path_.empty()) path_.back().speed_limit = std::min(path_.back().speed_limit, lim);
    path_.push_back({p, s, lim});
  };
  if (path_.empty())
    path_.push_back({entry, 0.0, cruise});
  else
    push(entry, path_.back().speed_limit);  // the chord across the intersection
  push(exit, limit);
  if (roundabout) {
    // Counter-clockwise round the island (right-hand traffic) on the ring lane's centre line,
    // from where the arriving lane meets it to where the leaving lane does.
    const double rc = grid_.ringRadius();
    const double off_out = grid_.pieceLaneOffset(nodes_[1], nodes_[2]);
    const Vec2 right_e{e.y, -e.x};
    const Vec2 in = -std::sqrt(rc * rc - off * off) * d + off * right;
    const Vec2 out = std::sqrt(rc * rc - off_out * off_out) * e + off_out * right_e;
    const double a0 = std::atan2(in.y, in.x);
    double sweep = std::atan2(out.y, out.x) - a0;
    while (sweep <= 0) sweep += 2 * M_PI;
    const int steps = std::max(2, static_cast<int>(std::ceil(sweep / (15.0 * M_PI / 180.0))));
    for (int k = 0; k <= steps; ++k) {
      const double ang = a0 + sweep * k / steps;
      push(b + Vec2{rc * std::cos(ang), rc * std::sin(ang)}, limit);
    }
  }
  nodes_.pop_front();
}

void Driver::control() {
  const common::Pose2& p = state_.pose;
  const Vec2 pos{p.x, p.y};
  // Progress along the path: the segment whose projection of the car lies inside it.
  while (seg_ + 2 < path_.size()) {
    const Vec2 a = path_[seg_].p, b = path_[seg_ + 1].p;
    const double len2 = dot(b - a, b - a);
    if (len2 > 0 && dot(pos - a, b - a) < len2) break;
    ++seg_;
  }
  const Vec2 a = path_[seg_].p, b = path_[seg_ + 1].p;
  const double len = norm(b - a);
  const double along = len > 0 ? std::clamp(dot(pos - a, b - a) / len, 0.0, len) : 0.0;
  const double s = path_[seg_].s + along;
  const double lookahead = std::max(route_.lookahead_min_m, route_.lookahead_s * state_.speed_mps);
  while (path_.back().s < s + lookahead + 150.0) extendPath();
  while (seg_ > 2) {
    path_.pop_front();
    --seg_;
  }

  // Pure pursuit towards the path point one look-ahead further on.
  size_t k = seg_;
  while (k + 2 < path_.size() && path_[k + 1].s < s + lookahead) ++k;
  const double f = std::clamp((s + lookahead - path_[k].s) / std::max(1e-9, path_[k + 1].s - path_[k].s), 0.0, 1.0);
  const Vec2 target = path_[k].p + f * (path_[k + 1].p - path_[k].p);
  const double dx = target.x - p.x, dy = target.y - p.y;
  const double ly = -std::sin(p.phi) * dx + std::cos(p.phi) * dy;
  const double ld2 = dx * dx + dy * dy;
  double steer = std::atan(2.0 * vehicle_.wheelbase_m * ly / std::max(ld2, 1e-6));
  const double max_steer = vehicle_.max_steering_deg * kDeg, max_rate = vehicle_.max_steering_rate_deg_s * kDeg;
  steer = std::clamp(steer, -max_steer, max_steer);
  state_.steering_rad += std::clamp(steer - state_.steering_rad, -max_rate * route_.step_s, max_rate * route_.step_s);

  // Speed: cruise, but slow enough to brake to every speed limit ahead.
  double v = route_.speed_mps;
  for (size_t i = seg_ + 1; i < path_.size() && path_[i].s - s < 150.0; ++i)
    v = std::min(v, std::sqrt(path_[i].speed_limit * path_[i].speed_limit + 1.6 * vehicle_.max_decel_mps2 * std::max(0.0, path_[i].s - s)));
  state_.speed_mps += std::clamp(v - state_.speed_mps, -vehicle_.max_decel_mps2 * route_.step_s, vehicle_.max_accel_mps2 * route_.step_s);
}

void Driver::advanceTo(double t) {
  while (state_.time_s < t - 1e-12) {
    if (state_.time_s >= next_control_s_ - 1e-12) {
      control();
      next_control_s_ += route_.step_s;
    }
    const double dt = std::min(next_control_s_, t) - state_.time_s;
    if (dt <= 0) continue;
    state_.pose = stepBicycle(state_.pose, state_.speed_mps, state_.steering_rad, dt, vehicle_.wheelbase_m);
    state_.odometer_m += state_.speed_mps * dt;
    state_.time_s = std::min(next_control_s_, t);
  }
}

}  // namespace urbanslam::sim
