#include "urbanslam/laser_loop/ScanFeatures.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace urbanslam::laser_loop {

namespace {

constexpr const char* kNames[kThesisFeatureCount] = {"area",
                                                     "average_range",
                                                     "mean_centroid",
                                                     "clamped_centroid",
                                                     "close_area",
                                                     "close_distance",
                                                     "circularity_residual",
                                                     "circularity_radius",
                                                     "curvature_mean",
                                                     "curvature_std",
                                                     "distance",
                                                     "far_distance",
                                                     "group_count",
                                                     "group_mean_size",
                                                     "max_range_count",
                                                     "mean_angular_difference",
                                                     "mean_deviation",
                                                     "regularity",
                                                     "size",
                                                     "std_range"};

// The beams as unit vectors plus ranges: the hot path for regular scans reuses cached cos/sin
// tables, merged scans compute them once.
struct Beams {
  size_t n = 0;
  const double* r = nullptr;  // raw ranges (only read for short beams)
  const uint8_t* valid = nullptr;
  const double* c = nullptr;  // cos(bearing)
  const double* s = nullptr;  // sin(bearing)
  double increment = 0;
  bool closed = false;
};

// Ranges are metres, far from overflow: plain sqrt is several times cheaper than std::hypot.
inline double norm2(double x, double y) { return std::sqrt(x * x + y * y); }

// Welford's running mean/variance: the textbook Σx² − n·mean² cancels catastrophically when the
// spread is small next to the mean (a regular scan), giving a noise floor instead of 0.
struct Running {
  size_t n = 0;
  double mean = 0, m2 = 0, sum = 0;
  void add(double x) {
    ++n;
    sum += x;
    const double d = x - mean;
    mean += d / static_cast<double>(n);
    m2 += d * (x - mean);
  }
  double sampleStd() const { return n < 2 ? 0.0 : std::sqrt(std::max(0.0, m2 / static_cast<double>(n - 1))); }
};

FeatureVector compute(const Beams& b, const FeatureParams& p) {
  FeatureVector f{};
  const size_t n = b.n;
  if (n == 0) return f;
  const double rmax = p.r_max_m;

  // Per-beam data in one pass: short flag, clamped point (far beams at r_max) and short point.
  thread_local std::vector<double> xs, ys;  // clamped points
  thread_local std::vector<uint8_t> sh;     // short beams
  thread_local std::vector<double> rc;      // clamped ranges
  rc.resize(n);
  xs.resize(n);
  ys.resize(n);
  sh.resize(n);
  double sum_clamped_r = 0, cx_all = 0, cy_all = 0, cx = 0, cy = 0, sum_r2 = 0;
  size_t n_short = 0;
  Running range_stats;
  for (size_t i = 0; i < n; ++i) {
    const bool is_short = b.valid[i] && b.r[i] < rmax;
    const double r = is_short ? b.r[i] : rmax;
    sh[i] = is_short;
    rc[i] = r;
    xs[i] = r * b.c[i];
    ys[i] = r * b.s[i];
    sum_clamped_r += r;
    cx_all += xs[i];
    cy_all += ys[i];
    if (is_short) {
      ++n_short;
      cx += xs[i];
      cy += ys[i];
      range_stats.add(r);
      sum_r2 += r * r;
    }
  }
  const double dn = static_cast<double>(n);
  f[int(Feature::AverageRange)] = sum_clamped_r / dn;
  const double xm = cx / dn, ym = cy / dn;  // eq. 3.8 divides by N, not by the short count
  f[int(Feature::MeanCentroid)] = std::hypot(xm, ym);
  f[int(Feature::ClampedCentroid)] = std::hypot(cx_all / dn, cy_all / dn);
  f[int(Feature::CloseArea)] = 0.5 * sum_r2 * std::sin(b.increment);
  f[int(Feature::MaxRangeCount)] = static_cast<double>(n - n_short);
  f[int(Feature::Size)] = static_cast<double>(n_short);
  f[int(Feature::StdRange)] = range_stats.sampleStd();

  // Consecutive pairs (i, i+1), wrapping on closed scans.
  const size_t n_pairs = b.closed ? n : n - 1;
  double area2 = 0, far_dist = 0, dist = 0, close_dist = 0;
  Running d_stats;
  thread_local std::vector<uint8_t> link;  // pair i is short–short and within g_max_dist
  thread_local std::vector<double> dpair;  // |p_i p_{i+1}|
  link.assign(n, 0);
  dpair.assign(n, 0.0);
  for (size_t i = 0; i < n_pairs; ++i) {
    const size_t j = i + 1 == n ? 0 : i + 1;
    area2 += xs[i] * ys[j] - xs[j] * ys[i];  // r_i r_j sin(α_j − α_i), the triangle of 3.6
    const double d = norm2(xs[j] - xs[i], ys[j] - ys[i]);
    dpair[i] = d;
    far_dist += d;
    if (sh[i] && sh[j]) {
      dist += d;
      d_stats.add(d);
      if (d < p.g_max_dist_m) {
        close_dist += d;
        link[i] = 1;
      }
    }
  }
  f[int(Feature::Area)] = 0.5 * area2;
  f[int(Feature::FarDistance)] = far_dist;
  f[int(Feature::Distance)] = dist;
  f[int(Feature::CloseDistance)] = close_dist;
  f[int(Feature::Regularity)] = d_stats.sampleStd();

  // Groups: maximal runs of short beams joined by links. On a closed scan the walk starts after
  // a broken link so that a group spanning the seam is counted once.
  {
    size_t start = 0;
    bool ring = false;
    if (b.closed) {
      size_t k = 0;
      while (k < n && link[k]) ++k;
      if (k == n)
        ring = true;
      else
        start = (k + 1) % n;
    }
    size_t groups = 0, grouped_points = 0;
    if (ring) {
      if (static_cast<int>(n) > p.g_min_size) {
        groups = 1;
        grouped_points = n;
      }
    } else {
      size_t run = 0;
      for (size_t step = 0; step < n; ++step) {
        const size_t i = (start + step) % n;
        if (sh[i]) ++run;
        const bool continues = sh[i] && link[i] && (b.closed || i + 1 < n) && step + 1 < n;
        if (!continues) {
          if (static_cast<int>(run) > p.g_min_size) {
            ++groups;
            grouped_points += run;
          }
          run = 0;
        }
      }
    }
    f[int(Feature::GroupCount)] = static_cast<double>(groups);
    f[int(Feature::GroupMeanSize)] = groups ? static_cast<double>(grouped_points) / static_cast<double>(groups) : 0.0;
  }

  // Triples (a, b, c) of consecutive short beams: curvature 3.14 and angular difference 3.19.
  {
    const size_t n_triples = b.closed ? n : (n >= 2 ? n - 2 : 0);
    double mad = 0;
    Running k_stats;
    for (size_t t = 0; t < n_triples; ++t) {
      const size_t ia = t, ib = (t + 1) % n, ic = (t + 2) % n;
      if (!(sh[ia] && sh[ib] && sh[ic])) continue;
      const double ux = xs[ib] - xs[ia], uy = ys[ib] - ys[ia];  // a→b
      const double vx = xs[ic] - xs[ib], vy = ys[ic] - ys[ib];  // b→c
      const double lu = dpair[ia], lv = dpair[ib];
      const double lw = norm2(xs[ic] - xs[ia], ys[ic] - ys[ia]);
      if (lu > 0 && lv > 0) {
        const double cosang = std::clamp((ux * vx + uy * vy) / (lu * lv), -1.0, 1.0);
        mad += std::acos(cosang);
      }
      const double denom = lu * lv * lw;
      if (denom > 1e-12) {
        const double area = 0.5 * std::fabs(ux * vy - uy * vx);
        const double k = 4.0 * area / denom;
        k_stats.add(k);
      }
    }
    f[int(Feature::CurvatureMean)] = k_stats.n ? k_stats.sum / static_cast<double>(k_stats.n) : 0.0;
    f[int(Feature::CurvatureStd)] = k_stats.sampleStd();
    f[int(Feature::MeanAngularDifference)] = mad;
  }

  // Mean deviation 3.20 (about the centroid of 3.8) and the circle fit 3.12–3.13, whose normal
  // equations decouple once the points are centred on their own mean (the algebraic residual is
  // unchanged by a translation of the points).
  {
    double dev = 0, mx = 0, my = 0;
    for (size_t i = 0; i < n; ++i)
      if (sh[i]) {
        dev += norm2(xs[i] - xm, ys[i] - ym);
        mx += xs[i];
        my += ys[i];
      }
    f[int(Feature::MeanDeviation)] = dev / dn;
    if (n_short >= 3) {
      mx /= static_cast<double>(n_short);
      my /= static_cast<double>(n_short);
      double suu = 0, svv = 0, suv = 0, suz = 0, svz = 0, sz = 0;
      for (size_t i = 0; i < n; ++i)
        if (sh[i]) {
          const double u = xs[i] - mx, v = ys[i] - my, z = u * u + v * v;
          suu += u * u;
          svv += v * v;
          suv += u * v;
          suz += u * z;
          svz += v * z;
          sz += z;
        }
      // Unknowns: centre (a, b) and c = r² − a² − b²; rows [2u 2v 1]·(a b c) = u² + v².
      const double c0 = sz / static_cast<double>(n_short);
      const double det = suu * svv - suv * suv;
      double a = 0, bb = 0;
      bool degenerate = !(det > 1e-12 * (suu + svv) * (suu + svv));
      if (!degenerate) {
        a = 0.5 * (svv * suz - suv * svz) / det;
        bb = 0.5 * (suu * svz - suv * suz) / det;
      }
      double res = 0;
      for (size_t i = 0; i < n; ++i)
        if (sh[i]) {
          const double u = xs[i] - mx, v = ys[i] - my;
          const double e = u * u + v * v - 2 * a * u - 2 * bb * v - c0;
          res += e * e;
        }
      f[int(Feature::CircularityResidual)] = res;
      // Collinear points: the circle is at infinity; 0 marks "no circle".
      f[int(Feature::CircularityRadius)] = degenerate ? 0.0 : std::sqrt(std::max(0.0, c0 + a * a + bb * bb));
    }
  }
  computeShapeFeatures(rc.data(), xs.data(), ys.data(), sh.data(), n, rmax, f.data() + kThesisFeatureCount);
  if (p.log_features)
    for (double& v : f) v = std::copysign(std::log1p(std::fabs(v)), v);
  return f;
}

bool coversCircle(size_t n, double increment) { return static_cast<double>(n) * increment >= 2 * M_PI - 0.5 * increment; }

}  // namespace

const char* featureName(Feature f) {
  const int i = static_cast<int>(f);
  if (i >= 0 && i < kThesisFeatureCount) return kNames[i];
  return shapeFeatureName(i - kThesisFeatureCount);
}

int featureIndex(const std::string& name) {
  for (int i = 0; i < kFeatureCount; ++i)
    if (name == featureName(i)) return i;
  return -1;
}

bool coversFullCircle(const io::LaserScan& scan) { return scan.size() > 0 && coversCircle(scan.size(), scan.angle_increment_rad); }

PolarScan toPolar(const io::LaserScan& scan) {
  PolarScan p;
  const size_t n = scan.size();
  p.ranges.assign(scan.ranges.begin(), scan.ranges.end());
  p.valid = scan.valid;
  p.valid.resize(n, 0);
  p.bearings.resize(n);
  for (size_t i = 0; i < n; ++i) p.bearings[i] = scan.bearing(i);
  p.angle_increment_rad = scan.angle_increment_rad;
  p.closed = coversCircle(n, scan.angle_increment_rad);
  return p;
}

PolarScan mergeScans(const std::vector<io::LaserScan>& scans, double beam_increment_deg) {
  struct B {
    double bearing, range;
    uint8_t valid;
  };
  std::vector<B> beams;
  double inc = 0;
  for (const auto& s : scans) {
    size_t step = 1;
    if (beam_increment_deg > 0 && s.angle_increment_rad > 0) {
      const double k = beam_increment_deg * M_PI / 180.0 / s.angle_increment_rad;
      if (k > 1.5) step = static_cast<size_t>(std::lround(k));
    }
    const double s_inc = s.angle_increment_rad * static_cast<double>(step);
    if (s_inc > 0) inc = inc > 0 ? std::min(inc, s_inc) : s_inc;
    const double c = std::cos(s.sensor_pose.phi), sn = std::sin(s.sensor_pose.phi);
    for (size_t i = 0; i < s.size(); i += step) {
      const double a = s.bearing(i);
      if (i < s.valid.size() && s.valid[i]) {
        const double lx = s.ranges[i] * std::cos(a), ly = s.ranges[i] * std::sin(a);
        const double x = s.sensor_pose.x + c * lx - sn * ly, y = s.sensor_pose.y + sn * lx + c * ly;
        beams.push_back({std::atan2(y, x), std::hypot(x, y), 1});
      } else {
        // A no-return keeps its direction; the sensor offset is negligible at r >= r_max.
        beams.push_back({common::wrapToPi(a + s.sensor_pose.phi), 0.0, 0});
      }
    }
  }
  std::sort(beams.begin(), beams.end(), [](const B& a, const B& b) { return a.bearing < b.bearing; });
  PolarScan p;
  for (const auto& b : beams) {
    p.bearings.push_back(b.bearing);
    p.ranges.push_back(b.range);
    p.valid.push_back(b.valid);
  }
  p.angle_increment_rad = inc;
  if (beams.size() >= 2 && inc > 0) {
    double max_gap = beams.front().bearing + 2 * M_PI - beams.back().bearing;
    for (size_t i = 1; i < beams.size(); ++i) max_gap = std::max(max_gap, beams[i].bearing - beams[i - 1].bearing);
    p.closed = max_gap <= 4 * inc;
  }
  return p;
}

FeatureVector computeFeatures(const PolarScan& scan, const FeatureParams& params) {
  const size_t n = scan.ranges.size();
  std::vector<double> c(n), s(n);
  for (size_t i = 0; i < n; ++i) {
    c[i] = std::cos(scan.bearings[i]);
    s[i] = std::sin(scan.bearings[i]);
  }
  Beams b;
  b.n = n;
  b.r = scan.ranges.data();
  b.valid = scan.valid.data();
  b.c = c.data();
  b.s = s.data();
  b.increment = scan.angle_increment_rad;
  b.closed = scan.closed;
  return compute(b, params);
}

FeatureVector computeFeatures(const io::LaserScan& scan, const FeatureParams& params) {
  // Every feature depends on bearings only through their differences, so the beams are laid
  // out from bearing 0: the cos/sin table then depends on (N, increment) alone and is cached.
  size_t step = 1;
  if (params.beam_increment_deg > 0 && scan.angle_increment_rad > 0) {
    const double k = params.beam_increment_deg * M_PI / 180.0 / scan.angle_increment_rad;
    if (k > 1.5) step = static_cast<size_t>(std::lround(k));
  }
  const size_t n = (scan.size() + step - 1) / step;
  const double inc = scan.angle_increment_rad * static_cast<double>(step);
  thread_local size_t cached_n = 0;
  thread_local double cached_inc = 0;
  thread_local std::vector<double> cos_t, sin_t, r;
  thread_local std::vector<uint8_t> valid;
  if (n != cached_n || inc != cached_inc) {
    cos_t.resize(n);
    sin_t.resize(n);
    for (size_t i = 0; i < n; ++i) {
      cos_t[i] = std::cos(static_cast<double>(i) * inc);
      sin_t[i] = std::sin(static_cast<double>(i) * inc);
    }
    cached_n = n;
    cached_inc = inc;
  }
  r.resize(n);
  valid.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const size_t j = i * step;
    r[i] = scan.ranges[j];
    valid[i] = j < scan.valid.size() ? scan.valid[j] : 0;
  }
  Beams b;
  b.n = n;
  b.r = r.data();
  b.valid = valid.data();
  b.c = cos_t.data();
  b.s = sin_t.data();
  b.increment = inc;
  b.closed = coversCircle(n, inc);
  return compute(b, params);
}

}  // namespace urbanslam::laser_loop
