#include "urbanslam/laser_loop/TrainingPairs.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <unordered_set>

#include "urbanslam/common/Error.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/laser_loop/SubmapScan.h"

namespace urbanslam::laser_loop {

namespace {

struct TimedScan {
  double t;
  FeatureVector f;
  long stream_ref;  // index of the reference pose read since the previous scan, or −1
};
struct TimedRef {
  double t;
  common::Pose2 pose;
};
struct TimedGps {
  double t, x, y;
};

}  // namespace

ScanSet loadLabelledScans(const std::string& path, const ScanLoadOptions& opt) {
  auto source = io::openDataSource(path);
  ScanSet set;
  set.source = path;
  set.format = source->format();
  std::vector<TimedScan> scans;
  std::vector<TimedRef> refs;
  std::vector<TimedGps> gps;
  io::Measurement m;
  size_t count = 0;
  long since_last_scan = -1;
  // Scans of several lasers taken at the same instant (front + rear, distinct labels) are one
  // observation of the place: they are merged about the vehicle origin before the features.
  std::vector<io::LaserScan> group;
  long group_ref = -1;
  // Odometry for the submap window: the last reading before the scan (identity until the first).
  common::Pose2 odom, group_odom;  // latest reading; the reading when the group's first scan came
  bool have_odom = false;
  std::unique_ptr<SubmapScanBuilder> submap;
  if (opt.submap_window_m > 0)
    submap = std::make_unique<SubmapScanBuilder>(
        opt.submap_window_m, opt.params.beam_increment_deg > 0 ? opt.params.beam_increment_deg : 1.0, opt.params.r_max_m);
  auto flush = [&] {
    if (group.empty()) return;
    const FeatureVector f = submap              ? computeFeatures(submap->add(group_odom, group), opt.params)
                            : group.size() == 1 ? computeFeatures(group[0], opt.params)
                                                : computeFeatures(mergeScans(group, opt.params.beam_increment_deg), opt.params);
    scans.push_back({group[0].timestamp, f, group_ref});
    group.clear();
  };
  while (source->next(m)) {
    if (auto* s = std::get_if<io::LaserScan>(&m)) {
      bool same_instant = !group.empty() && s->timestamp == group[0].timestamp;
      for (const auto& g : group) same_instant = same_instant && g.label != s->label;
      if (!same_instant) {
        flush();
        group_ref = since_last_scan;
        since_last_scan = -1;
        // flush() runs when the next instant's scan arrives, after that instant's odometry.
        group_odom = odom;
      }
      group.push_back(std::move(*s));
    } else if (const auto* r = std::get_if<io::ReferencePose>(&m)) {
      since_last_scan = static_cast<long>(refs.size());
      refs.push_back({r->timestamp, r->pose});
    } else if (const auto* g = std::get_if<io::GpsFix>(&m)) {
      gps.push_back({g->timestamp, g->x_m, g->y_m});
    } else if (const auto* o = std::get_if<io::OdometryReading>(&m)) {
      odom = o->pose;
      have_odom = true;
    }
    if (opt.progress && (++count & 1023) == 0) opt.progress(source->progress());
  }
  flush();
  if (submap && !have_odom)
    throw common::InputError(path + ": the submap window (" + std::to_string(opt.submap_window_m) +
                             " m) needs odometry, and this log has none");
  set.scans_read = scans.size();
  if (refs.empty() && gps.empty())
    throw common::InputError(path + ": no reference trajectory (neither reference poses nor GPS) to label scan pairs");
  auto by_t = [](const auto& a, const auto& b) { return a.t < b.t; };
  // A reference pose read right before its scan (corrected CARMEN logs) is that scan's pose even
  // when the log's timestamps are too coarse to tell scans apart (csail: 6 significant digits).
  std::vector<TimedRef> stream_refs = refs;
  std::stable_sort(refs.begin(), refs.end(), by_t);
  std::stable_sort(gps.begin(), gps.end(), by_t);
  set.reference_kind =
      refs.empty() ? "GPS (interpolated between fixes within " + std::to_string(opt.gps_max_gap_s) + " s)" : "reference poses";
  bool have_prev = false;
  common::Pose2 prev;
  double path_m = 0;
  for (const auto& s : scans) {
    LabelledScan ls;
    ls.features = s.f;
    ls.timestamp = s.t;
    bool ok = false;
    if (s.stream_ref >= 0 && std::fabs(stream_refs[static_cast<size_t>(s.stream_ref)].t - s.t) <= opt.ref_max_gap_s) {
      ls.pose = stream_refs[static_cast<size_t>(s.stream_ref)].pose;
      ok = true;
    } else if (!refs.empty()) {
      auto it = std::lower_bound(refs.begin(), refs.end(), s.t, [](const TimedRef& r, double t) { return r.t < t; });
      const TimedRef* best = nullptr;
      if (it != refs.end()) best = &*it;
      if (it != refs.begin() && (!best || s.t - std::prev(it)->t < best->t - s.t)) best = &*std::prev(it);
      if (best && std::fabs(best->t - s.t) <= opt.ref_max_gap_s) {
        ls.pose = best->pose;
        ok = true;
      }
    } else {
      auto it = std::lower_bound(gps.begin(), gps.end(), s.t, [](const TimedGps& g, double t) { return g.t < t; });
      if (it != gps.end() && it != gps.begin()) {
        const TimedGps& a = *std::prev(it);
        const TimedGps& b = *it;
        if (s.t - a.t <= opt.gps_max_gap_s && b.t - s.t <= opt.gps_max_gap_s) {
          const double f = b.t > a.t ? (s.t - a.t) / (b.t - a.t) : 0.0;
          ls.pose.x = a.x + f * (b.x - a.x);
          ls.pose.y = a.y + f * (b.y - a.y);
          ls.has_heading = std::hypot(b.x - a.x, b.y - a.y) >= 0.5;
          ls.pose.phi = ls.has_heading ? std::atan2(b.y - a.y, b.x - a.x) : 0.0;
          ok = true;
        }
      } else if (it != gps.end() && it->t == s.t) {
        ls.pose.x = it->x;
        ls.pose.y = it->y;
        ls.has_heading = false;
        ok = true;
      }
    }
    if (!ok) {
      ++set.scans_without_reference;
      continue;
    }
    if (have_prev) path_m += std::hypot(ls.pose.x - prev.x, ls.pose.y - prev.y);
    ls.path_m = path_m;
    prev = ls.pose;
    have_prev = true;
    set.scans.push_back(ls);
  }
  return set;
}

std::vector<LabelledPair> samplePairs(const ScanSet& set, uint32_t set_index, const PairRules& rules) {
  if (!(rules.d_pos_m > 0) || !(rules.d_neg_m >= rules.d_pos_m))
    throw common::InputError("pair rules: need 0 < d_pos_m <= d_neg_m (got " + std::to_string(rules.d_pos_m) + ", " +
                             std::to_string(rules.d_neg_m) + ")");
  const auto& s = set.scans;
  const size_t n = s.size();
  auto make = [&](uint32_t a, uint32_t b, bool match) {
    LabelledPair p;
    p.set = set_index;
    p.a = a;
    p.b = b;
    p.match = match;
    p.distance_m = std::hypot(s[a].pose.x - s[b].pose.x, s[a].pose.y - s[b].pose.y);
    if (s[a].has_heading && s[b].has_heading) p.heading_diff_rad = std::fabs(common::wrapToPi(s[a].pose.phi - s[b].pose.phi));
    return p;
  };
  std::mt19937_64 rng(rules.seed);
  std::vector<LabelledPair> pos;
  const double d2 = rules.d_pos_m * rules.d_pos_m;
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t j = i + 1; j < n; ++j) {
      const double dx = s[i].pose.x - s[j].pose.x, dy = s[i].pose.y - s[j].pose.y;
      if (dx * dx + dy * dy <= d2 && std::fabs(s[j].path_m - s[i].path_m) >= rules.min_travel_m) {
        LabelledPair p = make(i, j, true);
        if (p.heading_diff_rad <= rules.max_heading_diff_rad) pos.push_back(p);
      }
    }
  std::shuffle(pos.begin(), pos.end(), rng);
  if (pos.size() > rules.max_positives) pos.resize(rules.max_positives);

  size_t want_neg = static_cast<size_t>(std::llround(rules.negatives_per_positive * static_cast<double>(pos.size())));
  want_neg = std::max(want_neg, rules.min_negatives);
  std::vector<LabelledPair> out = pos;
  if (n >= 2 && want_neg > 0) {
    std::uniform_int_distribution<uint32_t> pick(0, static_cast<uint32_t>(n - 1));
    std::unordered_set<uint64_t> seen;
    const double dn2 = rules.d_neg_m * rules.d_neg_m;
    // Rejection sampling; the attempt cap ends it on logs where few pairs are far enough apart.
    const size_t max_attempts = 50 * want_neg + 1000;
    size_t got = 0;
    for (size_t attempt = 0; attempt < max_attempts && got < want_neg; ++attempt) {
      uint32_t a = pick(rng), b = pick(rng);
      if (a == b) continue;
      if (a > b) std::swap(a, b);
      const double dx = s[a].pose.x - s[b].pose.x, dy = s[a].pose.y - s[b].pose.y;
      if (dx * dx + dy * dy <= dn2) continue;
      if (!seen.insert((static_cast<uint64_t>(a) << 32) | b).second) continue;
      out.push_back(make(a, b, false));
      ++got;
    }
  }
  std::shuffle(out.begin(), out.end(), rng);
  return out;
}

PairTable makePairTable(const std::vector<ScanSet>& sets, const std::vector<LabelledPair>& pairs, int comparisons) {
  PairTable t;
  t.comparisons = comparisons;
  for (int k = 0; k < comparisons; ++k) t.c[k].reserve(pairs.size());
  t.y.reserve(pairs.size());
  for (const auto& p : pairs) t.add(sets[p.set].scans[p.a].features, sets[p.set].scans[p.b].features, p.match);
  return t;
}

}  // namespace urbanslam::laser_loop
