#include "urbanslam/evaluation/Evaluation.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Numbers.h"
#include "urbanslam/common/RigidFit.h"

namespace urbanslam::evaluation {

using common::Pose2;

namespace {

constexpr double kRad2Deg = 180.0 / M_PI;

MeanStd meanStd(const std::vector<double>& v) {
  MeanStd r;
  if (v.empty()) return r;
  double s = 0;
  for (double x : v) s += x;
  r.mean = s / static_cast<double>(v.size());
  if (v.size() > 1) {
    double q = 0;
    for (double x : v) q += (x - r.mean) * (x - r.mean);
    r.std = std::sqrt(q / static_cast<double>(v.size() - 1));
  }
  return r;
}

std::vector<io::StampedPose> shifted(const std::vector<io::StampedPose>& t, double offset) {
  std::vector<io::StampedPose> out = t;
  for (auto& p : out) p.timestamp += offset;
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
  return out;
}

}  // namespace

std::vector<Relation> readRelations(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw common::InputError(path + ": cannot open the relations file");
  std::vector<Relation> out;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    std::istringstream is(line);
    double v[8];
    std::string tok;
    for (int k = 0; k < 8; ++k) {
      const auto x = is >> tok ? common::parseDecimal(tok) : std::nullopt;
      if (!x) throw common::InputError(path + ":" + std::to_string(n) + ": expected 't1 t2 x y z roll pitch yaw' (decimal numbers)");
      if (std::abs(*x) > (k < 2 ? common::kMaxMagnitude : common::kMaxCoordinate))
        throw common::InputError(path + ":" + std::to_string(n) + ": value " + tok + " is out of range");
      v[k] = *x;
    }
    out.push_back({v[0], v[1], {v[2], v[3], v[7]}});
  }
  if (out.empty()) throw common::InputError(path + ": no relations");
  return out;
}

bool interpolatePose(const std::vector<io::StampedPose>& traj, double t, double max_gap_s, Pose2& out) {
  if (traj.empty() || t < traj.front().timestamp || t > traj.back().timestamp) return false;
  const auto it = std::lower_bound(traj.begin(), traj.end(), t, [](const io::StampedPose& p, double x) { return p.timestamp < x; });
  if (it->timestamp == t) {
    out = it->pose;
    return true;
  }
  const auto& b = *it;
  const auto& a = *(it - 1);
  if (b.timestamp - a.timestamp > max_gap_s) return false;
  out = common::interpolate(a.pose, b.pose, (t - a.timestamp) / (b.timestamp - a.timestamp));
  return true;
}

std::vector<io::StampedPose> bridgeNodes(const std::vector<io::StampedPose>& nodes, const std::vector<io::StampedPose>& dense) {
  const auto n = shifted(nodes, 0), d = shifted(dense, 0);  // time-sorted copies
  if (n.size() < 2) return n;
  std::vector<double> times;
  for (const auto& p : n) times.push_back(p.timestamp);
  for (const auto& p : d)
    if (p.timestamp > n.front().timestamp && p.timestamp < n.back().timestamp) times.push_back(p.timestamp);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<io::StampedPose> out;
  out.reserve(times.size());
  size_t i = 0;  // n[i].timestamp <= t < n[i + 1].timestamp, or the last interval
  for (const double t : times) {
    while (i + 2 < n.size() && n[i + 1].timestamp <= t) ++i;
    const auto &a = n[i], &b = n[i + 1];
    if (t <= a.timestamp || b.timestamp <= a.timestamp) {
      out.push_back({t, a.pose});
      continue;
    }
    if (t >= b.timestamp) {
      out.push_back({t, b.pose});
      continue;
    }
    const double f = (t - a.timestamp) / (b.timestamp - a.timestamp);
    Pose2 da, db, dt;
    if (!interpolatePose(d, a.timestamp, inf, da) || !interpolatePose(d, b.timestamp, inf, db) || !interpolatePose(d, t, inf, dt)) {
      out.push_back({t, common::interpolate(a.pose, b.pose, f)});
      continue;
    }
    const Pose2 forward = common::compose(a.pose, common::between(da, dt));
    const Pose2 backward = common::compose(b.pose, common::between(db, dt));
    out.push_back({t, common::interpolate(forward, backward, f)});
  }
  return out;
}

namespace {

// Cartographer's error of one relation, (pose1⁻¹ · pose2) · expected⁻¹; false when a time falls
// outside the (shifted, sorted) trajectory.
bool relationError(const std::vector<io::StampedPose>& t, const Relation& r, double max_gap_s, Pose2& e) {
  Pose2 p1, p2;
  if (!interpolatePose(t, r.t1, max_gap_s, p1) || !interpolatePose(t, r.t2, max_gap_s, p2)) return false;
  e = common::compose(common::between(p1, p2), common::inverse(r.expected));
  return true;
}

}  // namespace

RelationMetrics relationMetrics(const std::vector<io::StampedPose>& traj, const std::vector<Relation>& rel, double time_offset_s,
                                double max_gap_s) {
  const auto t = shifted(traj, time_offset_s);
  std::vector<double> tr, tr2, rot, rot2;
  RelationMetrics m;
  m.time_offset_s = time_offset_s;
  for (const auto& r : rel) {
    Pose2 e;
    if (!relationError(t, r, max_gap_s, e)) {
      ++m.skipped;
      continue;
    }
    const double et = std::hypot(e.x, e.y), er = std::abs(e.phi) * kRad2Deg;
    tr.push_back(et);
    tr2.push_back(et * et);
    rot.push_back(er);
    rot2.push_back(er * er);
  }
  m.used = tr.size();
  m.abs_trans_m = meanStd(tr);
  m.sqr_trans_m2 = meanStd(tr2);
  m.abs_rot_deg = meanStd(rot);
  m.sqr_rot_deg2 = meanStd(rot2);
  return m;
}

RelationsByScans relationsByScans(const std::vector<io::StampedPose>& traj, const std::vector<Relation>& rel, double time_offset_s,
                                  const std::vector<double>& scan_times, double max_gap_s, double at_scan_s) {
  const auto t = shifted(traj, time_offset_s);
  std::vector<double> s = scan_times;
  for (double& x : s) x += time_offset_s;
  std::sort(s.begin(), s.end());
  const auto atScan = [&](double x) {
    const auto it = std::lower_bound(s.begin(), s.end(), x - at_scan_s);
    return it != s.end() && *it <= x + at_scan_s;
  };
  const auto oneInterval = [&](double a, double b) {
    if (a > b) std::swap(a, b);
    const auto first_after = std::upper_bound(s.begin(), s.end(), a + at_scan_s);  // no scan within at_scan_s of a ...
    return first_after != s.begin() && first_after != s.end() &&
           *(first_after - 1)<a - at_scan_s&& * first_after> b + at_scan_s;  // ... none up to b either, and one on each side
  };
  RelationsByScans out;
  size_t used = 0;
  for (const auto& r : rel) {
    Pose2 e;
    if (!relationError(t, r, max_gap_s, e)) continue;
    ++used;
    RelationClass& c = atScan(r.t1) && atScan(r.t2) ? out.at_scans : oneInterval(r.t1, r.t2) ? out.one_interval : out.other;
    ++c.n;
    c.share_m += std::hypot(e.x, e.y);  // the sum, until divided below
  }
  for (RelationClass* c : {&out.at_scans, &out.one_interval, &out.other}) {
    c->abs_trans_mean_m = c->n ? c->share_m / static_cast<double>(c->n) : 0;
    c->share_m = used ? c->share_m / static_cast<double>(used) : 0;
  }
  return out;
}

double findRelationTimeOffset(const std::vector<io::StampedPose>& reference, const std::vector<Relation>& rel,
                              const std::vector<double>& log_times) {
  if (reference.empty() || rel.empty()) return 0;
  const auto sorted = shifted(reference, 0);
  const double r0 = rel.front().t1;
  if (r0 >= sorted.front().timestamp && r0 <= sorted.back().timestamp) {
    // Same time base already when most relations fall inside the trajectory.
    if (relationMetrics(sorted, rel, 0).used > rel.size() / 2) return 0;
  }
  std::vector<Relation> sample;
  for (size_t i = 0; i < rel.size(); i += std::max<size_t>(1, rel.size() / 200)) sample.push_back(rel[i]);
  // How well the reference itself fits the relations at an offset (lower is better); offsets
  // that leave most relations outside the trajectory do not count.
  const auto misfit = [&](double off) {
    const auto m = relationMetrics(sorted, sample, off, 5.0);
    if (m.used < sample.size() * 8 / 10) return 1e300;
    return m.abs_trans_m.mean + m.abs_rot_deg.mean / 10;
  };
  // Coarse: relation times are scan times; try aligning the first relation with every reference time.
  double coarse = 0, coarse_err = 1e300;
  for (const auto& p : sorted) {
    const double off = r0 - p.timestamp, err = misfit(off);
    if (err < coarse_err) {
      coarse_err = err;
      coarse = off;
    }
  }
  // Refined by the misfit itself, 50 ms then 5 ms then 0.5 ms steps around the coarse value.
  double refined = coarse, refined_err = coarse_err, step = 0.05;
  for (int round = 0; round < 3; ++round, step /= 10) {
    const double centre = refined;
    for (int k = -10; k <= 10; ++k) {
      const double off = centre + k * step, err = misfit(off);
      if (err < refined_err) {
        refined_err = err;
        refined = off;
      }
    }
  }
  // Exact: when the relations were taken at the log's own timestamps (Intel: the raw log's
  // odometry times), the mode of (relation time - log time) near the refined value, in 1 ms bins.
  std::vector<double> times = log_times;
  for (const auto& p : sorted) times.push_back(p.timestamp);
  std::sort(times.begin(), times.end());
  std::map<long long, int> votes;
  for (const auto& r : rel)
    for (double tr : {r.t1, r.t2}) {
      const double lo = tr - refined - 1.0, hi = tr - refined + 1.0;
      for (auto it = std::lower_bound(times.begin(), times.end(), lo); it != times.end() && *it <= hi; ++it)
        ++votes[std::llround((tr - *it) * 1000.0)];
    }
  // Most votes wins; among equals (regularly sampled logs) the one nearest the refined value.
  int top = 0;
  double exact = refined;
  for (const auto& [bin, n] : votes) {
    const double off = static_cast<double>(bin) / 1000.0;
    if (n > top || (n == top && std::abs(off - refined) < std::abs(exact - refined))) {
      top = n;
      exact = off;
    }
  }
  // Without shared timestamps (FR079's corrected log is re-stamped) the mode is a chance
  // coincidence of regular sampling: it is kept only if the reference fits as well there.
  if (top >= 10 && misfit(exact) <= 1.1 * refined_err) return exact;
  return refined;
}

TrajectoryMetrics trajectoryMetrics(const std::vector<io::StampedPose>& estimate, const std::vector<io::StampedPose>& reference,
                                    bool positions_only, double max_gap_s) {
  TrajectoryMetrics m;
  m.positions_only = positions_only;
  const auto est = shifted(estimate, 0);
  std::vector<Pose2> e, r;
  std::vector<double> times;
  for (const auto& ref : reference) {
    Pose2 p;
    if (!interpolatePose(est, ref.timestamp, max_gap_s, p)) continue;
    e.push_back(p);
    r.push_back(ref.pose);
    times.push_back(ref.timestamp);
  }
  m.matched = e.size();
  if (e.size() < 2) return m;
  // The estimate rigidly aligned onto the reference (the project's one closed-form fit).
  std::vector<Eigen::Vector2d> src, dst;
  for (size_t i = 0; i < e.size(); ++i) {
    src.emplace_back(e[i].x, e[i].y);
    dst.emplace_back(r[i].x, r[i].y);
  }
  Pose2 align;
  if (!common::fitRigid2D(src, dst, {}, &align)) return m;
  m.alignment = align;
  double sum2 = 0;
  for (size_t i = 0; i < e.size(); ++i) {
    const Pose2 a = common::compose(align, e[i]);
    const double d = std::hypot(a.x - r[i].x, a.y - r[i].y);
    sum2 += d * d;
    m.ate_max_m = std::max(m.ate_max_m, d);
    m.times.push_back(times[i]);
    m.errors_m.push_back(d);
    m.aligned.push_back({times[i], a});
  }
  m.ate_rmse_m = std::sqrt(sum2 / static_cast<double>(e.size()));
  double rt = 0, rr = 0;
  for (size_t i = 1; i < e.size(); ++i) {
    const Pose2 de = common::between(e[i - 1], e[i]), dr = common::between(r[i - 1], r[i]);
    if (positions_only) {
      const double d = std::hypot(de.x, de.y) - std::hypot(dr.x, dr.y);
      rt += d * d;
    } else {
      const Pose2 err = common::between(dr, de);
      rt += err.x * err.x + err.y * err.y;
      rr += err.phi * err.phi * kRad2Deg * kRad2Deg;
    }
  }
  m.rpe_trans_rmse_m = std::sqrt(rt / static_cast<double>(e.size() - 1));
  m.rpe_rot_rmse_deg = positions_only ? 0 : std::sqrt(rr / static_cast<double>(e.size() - 1));
  return m;
}

std::vector<LoopRow> readLoopClosuresCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw common::InputError(path + ": cannot open");
  std::vector<LoopRow> out;
  std::string line;
  std::getline(in, line);  // header
  int n = 1;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) f.push_back(cell);
    if (f.size() < 11) throw common::InputError(path + ":" + std::to_string(n) + ": expected 14 columns");
    const auto whole = [&](const std::string& c) {
      const auto v = common::parseWholeNumber(c);
      if (!v || *v < 0) throw common::InputError(path + ":" + std::to_string(n) + ": malformed keyframe index '" + c + "'");
      return *v;
    };
    const auto number = [&](const std::string& c, double max_abs) {
      const auto v = common::parseDecimal(c);
      if (!v || std::abs(*v) > max_abs)
        throw common::InputError(path + ":" + std::to_string(n) + ": malformed or out-of-range number '" + c + "'");
      return *v;
    };
    out.push_back({whole(f[0]),
                   whole(f[1]),
                   number(f[2], common::kMaxMagnitude),
                   number(f[3], common::kMaxMagnitude),
                   f[6] == "1",
                   {number(f[8], common::kMaxCoordinate), number(f[9], common::kMaxCoordinate), number(f[10], common::kMaxCoordinate)}});
  }
  return out;
}

LoopMetrics classifyLoopClosures(const std::vector<LoopRow>& loops, const std::vector<io::StampedPose>& reference, bool positions_only,
                                 double tol_m, double tol_deg) {
  LoopMetrics m;
  const auto ref = shifted(reference, 0);
  for (const auto& l : loops) {
    if (!l.accepted) continue;
    ++m.accepted;
    Pose2 a, b;
    // GPS drops out: allow longer gaps for a position-only reference.
    const double gap = positions_only ? 5.0 : 1.0;
    if (!interpolatePose(ref, l.from_time, gap, a) || !interpolatePose(ref, l.to_time, gap, b)) {
      ++m.unverifiable;
      continue;
    }
    bool ok;
    double err_m = 0, err_deg = 0;
    const Pose2 rel = common::between(a, b);
    if (positions_only) {
      // GPS alone has no heading, and Victoria Park's fixes jump by metres: compare distances
      // only, with 2 m of slack for the fixes themselves.
      err_m = std::abs(std::hypot(b.x - a.x, b.y - a.y) - std::hypot(l.measurement.x, l.measurement.y));
      ok = err_m <= tol_m + 2.0;
    } else {
      const Pose2 err = common::between(rel, l.measurement);
      err_m = std::hypot(err.x, err.y);
      err_deg = std::abs(err.phi) * kRad2Deg;
      ok = err_m <= tol_m && err_deg <= tol_deg;
    }
    ++(ok ? m.true_positive : m.false_positive);
    if (!ok) m.false_closures.push_back({l.from_keyframe, l.to_keyframe, l.from_time, l.to_time, err_m, err_deg, l.measurement, rel});
  }
  return m;
}

RelationLoopCheck checkLoopsWithRelations(const std::vector<LoopRow>& loops, const std::vector<io::StampedPose>& nodes,
                                          const std::vector<Relation>& rel, double time_offset_s, double bridge_s, double tol_m,
                                          double tol_deg) {
  RelationLoopCheck c;
  const auto t = shifted(nodes, time_offset_s);
  // Relations by their first time, each in both directions.
  std::vector<Relation> both;
  both.reserve(2 * rel.size());
  for (const auto& r : rel) {
    both.push_back(r);
    both.push_back({r.t2, r.t1, common::inverse(r.expected)});
  }
  std::sort(both.begin(), both.end(), [](const Relation& a, const Relation& b) { return a.t1 < b.t1; });
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& l : loops) {
    if (!l.accepted) continue;
    ++c.accepted;
    const Relation* best = nullptr;
    double best_d = inf;
    auto it = std::lower_bound(both.begin(), both.end(), l.from_time - bridge_s, [](const Relation& r, double x) { return r.t1 < x; });
    for (; it != both.end() && it->t1 <= l.from_time + bridge_s; ++it) {
      const double d = std::abs(it->t1 - l.from_time) + std::abs(it->t2 - l.to_time);
      if (std::abs(it->t2 - l.to_time) <= bridge_s && d < best_d) best = &*it, best_d = d;
    }
    Pose2 a, r1, r2, b;
    if (!best || !interpolatePose(t, l.from_time, inf, a) || !interpolatePose(t, best->t1, inf, r1) ||
        !interpolatePose(t, best->t2, inf, r2) || !interpolatePose(t, l.to_time, inf, b))
      continue;
    ++c.checked;
    const Pose2 expected = common::compose(common::compose(common::between(a, r1), best->expected), common::between(r2, b));
    const Pose2 err = common::between(expected, l.measurement);
    const double err_m = std::hypot(err.x, err.y), err_deg = std::abs(err.phi) * kRad2Deg;
    if (err_m > tol_m || err_deg > tol_deg) {
      ++c.contradicted;
      c.contradictions.push_back({l.from_keyframe, l.to_keyframe, l.from_time, l.to_time, err_m, err_deg, l.measurement, expected});
    }
  }
  return c;
}

}  // namespace urbanslam::evaluation
