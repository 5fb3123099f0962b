#include "urbanslam/evaluation/Kidnapping.h"

#include <cmath>
#include <optional>
#include <type_traits>
#include <variant>

namespace urbanslam::evaluation {

std::vector<io::Measurement> spliceKidnapping(const std::vector<io::Measurement>& log, double t1, double t2, double before_s,
                                              double after_s) {
  std::optional<common::Pose2> o1, o2;
  for (const auto& m : log) {
    const auto* od = std::get_if<io::OdometryReading>(&m);
    if (!od) continue;
    if (od->timestamp < t1) o1 = od->pose;
    if (od->timestamp >= t2 && !o2) o2 = od->pose;
  }
  if (!o1 || !o2) return {};
  const common::Pose2 to_o1 = common::compose(*o1, common::inverse(*o2));  // takes o2 to o1
  std::vector<io::Measurement> out;
  for (const auto& m : log) {
    const double t = io::timestampOf(m);
    if (t >= t1 - before_s && t < t1) out.push_back(m);
  }
  for (const auto& m : log) {
    const double t = io::timestampOf(m);
    if (t < t2 || t > t2 + after_s) continue;
    io::Measurement moved = m;
    std::visit(
        [&](auto& x) {
          using T = std::decay_t<decltype(x)>;
          x.timestamp += t1 - t2;
          if constexpr (std::is_same_v<T, io::OdometryReading>) x.pose = common::compose(to_o1, x.pose);
        },
        moved);
    out.push_back(std::move(moved));
  }
  return out;
}

std::vector<KidnapJump> pickKidnapJumps(const std::vector<io::StampedPose>& tracked, double t_first, double t_last,
                                        const KidnapSchedule& s) {
  std::vector<size_t> starts;
  for (size_t i = 0; i < tracked.size(); ++i)
    if (tracked[i].timestamp >= t_first + s.before_s && tracked[i].timestamp + s.gap_s + s.after_s <= t_last) starts.push_back(i);
  std::vector<KidnapJump> jumps;
  for (int k = 0; k < s.count && !starts.empty(); ++k) {
    const size_t a = starts[static_cast<size_t>(2 * k + 1) * starts.size() / static_cast<size_t>(2 * s.count)];
    for (size_t b = a; b < tracked.size(); ++b) {
      const common::Pose2 &p = tracked[a].pose, &q = tracked[b].pose;
      if (tracked[b].timestamp >= tracked[a].timestamp + s.gap_s && tracked[b].timestamp + s.after_s <= t_last &&
          std::hypot(q.x - p.x, q.y - p.y) >= s.min_jump_m) {
        jumps.push_back({a, b});
        break;
      }
    }
  }
  return jumps;
}

}  // namespace urbanslam::evaluation
