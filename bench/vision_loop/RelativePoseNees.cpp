// Consistency of the camera's planar relative pose on many simulated street-view pairs: each pair
// is two renderings of the 1 km² city from the drive, the second camera 0.5–4 m further along,
// up to 1 m nearer or further from the facades and turned by up to ±0.15 rad. The features are
// matched once; each covariance method (PlanarRelativePose.h) then estimates the pose and its
// covariance, and the errors against the renderer's true poses give the mean NEES (2 for a
// consistent 2-vector) and the share within the 95 % bound (5.99), over all pairs and without the
// gross errors (bearing off by over 20° or heading by over 5°: the wrong solution, which the
// filter's innovation gate against the odometry has to reject; their count is reported).
//
// `first_order_floor` is the first-order covariance plus a constant floor per axis (the
// options' floor_bearing_rad / floor_heading_rad: the error the residuals do not show), the
// floors given by --floor-bearing-deg / --floor-heading-deg. --calibrate prints the floors that
// make each axis's mean NEES 1 over this city's sound pairs of the first-order method
// (run_eval.sh calibrates on city seed 2 and evaluates on seed 1).
//
// --metric: the full planar pose instead (MetricRelativePose.h). Camera a's features are given
// their depth by a second rendering a2 half a second further along the drive (a keyframe later),
// whose distance from a is the truth's with an odometry error of 2 % (one sigma, drawn, and the
// sigma given); the mean NEES of (forward, left, heading) is 3 for a consistent 3-vector, gross
// errors are positions off by over 1 m or headings by over 5°, and --calibrate / --floor-*-m /
// --floor-heading-deg do for its three axes what they do for the two of the pair.
//
//   relative_pose_nees [PAIRS] [--city-seed N] [--floor-bearing-deg B --floor-heading-deg H]
//                      [--calibrate] [--json]      (default 1000 pairs, city seed 1, floors 0)
//   relative_pose_nees --metric [PAIRS] [--city-seed N] [--floor-forward-m F --floor-left-m L
//                      --floor-heading-deg H] [--calibrate] [--json]
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "urbanslam/sim/CameraRenderer.h"
#include "urbanslam/sim/CityModel.h"
#include "urbanslam/sim/Driver.h"
#include "urbanslam/vision_loop/FeatureExtractor.h"
#include "urbanslam/vision_loop/GeometricVerification.h"
#include "urbanslam/vision_loop/MetricRelativePose.h"
#include "urbanslam/vision_loop/PlanarRelativePose.h"

using namespace urbanslam;

namespace {

struct Method {
  const char* name;
  vision_loop::PoseCovariance covariance;
  int valid = 0, within95 = 0, gross = 0;
  double nees_sum = 0;
  std::vector<double> bearing_errors, heading_errors, nees, nees_sound;
};

constexpr double kGrossBearing = 20 * M_PI / 180, kGrossHeading = 5 * M_PI / 180;

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / static_cast<double>(v.size());
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

cv::Mat toMat(const io::CameraImage& im) { return cv::Mat(im.height, im.width, CV_8U, const_cast<uint8_t*>(im.pixels->data())).clone(); }

}  // namespace

// The floor f that makes the mean of e_i^2 / (v_i + f^2) equal 1 (bisection: the mean falls as f
// grows); 0 when the variances alone already explain the errors.
double calibrateFloor(const std::vector<double>& e2, const std::vector<double>& v) {
  const auto meanNees = [&](double f) {
    double s = 0;
    for (size_t i = 0; i < e2.size(); ++i) s += e2[i] / (v[i] + f * f);
    return s / static_cast<double>(e2.size());
  };
  if (e2.empty() || meanNees(0) <= 1) return 0;
  double lo = 0, hi = 1.0;  // rad
  for (int it = 0; it < 200; ++it) (meanNees(0.5 * (lo + hi)) > 1 ? lo : hi) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

// The 1 km² city, its camera and a drive through it, and the draws of the second camera.
struct Scene {
  sim::SimOptions so;
  sim::CityModel city;
  sim::CameraRenderer cam;
  vision_loop::PinholeCamera k;
  vision_loop::FeatureExtractor sift;
  sim::Driver driver;
  std::mt19937 rng{2026};
  std::uniform_real_distribution<double> forward{0.5, 4.0}, across{-1.0, 1.0}, turn{-0.15, 0.15};
  const common::Pose2 mount{1.0, 0.0, M_PI / 2};  // looking left, as ini/city-camera.ini
  explicit Scene(unsigned seed)
      : so(options(seed)), city(so.city), cam(cameraOptions(), city, 1), k(pinhole(cam)), driver(city.streets(), so) {}
  static sim::SimOptions options(unsigned seed) {
    sim::SimOptions o;
    o.city.seed = seed;
    o.city.area_km2 = 1.0;
    return o;
  }
  static sim::CameraOptions cameraOptions() {
    sim::CameraOptions c;
    c.enabled = true;
    return c;
  }
  static vision_loop::PinholeCamera pinhole(const sim::CameraRenderer& c) {
    vision_loop::PinholeCamera k;
    k.fx = c.fx(), k.fy = c.fy(), k.cx = c.cx(), k.cy = c.cy();
    return k;
  }
};

// --metric: the full planar pose of each pair, given a's depths by a second image a2.
int runMetric(Scene& scene, int pairs, unsigned city_seed, bool json, bool calibrate, const Eigen::Vector3d& floors) {
  constexpr double kOdometrySigma = 0.02;  // relative error of the a-a2 distance
  std::normal_distribution<double> odometry(0.0, kOdometrySigma);
  vision_loop::MetricRelativePoseOptions o;
  o.floor_forward_m = floors(0), o.floor_left_m = floors(1), o.floor_heading_rad = floors(2);
  int valid = 0, within95 = 0, gross = 0, triangulated = 0;
  std::vector<double> nees, nees_sound, err_forward, err_left, err_heading;
  std::array<std::vector<double>, 3> e2, var;  // sound pairs, per axis: for --calibrate
  uint64_t index = 0;
  for (int i = 0; i < pairs; ++i) {
    const double t = 5.0 + 1.5 * i;
    scene.driver.advanceTo(t);
    const common::Pose2 v = scene.driver.state().pose;
    const double f = scene.forward(scene.rng), l = scene.across(scene.rng), h = scene.turn(scene.rng);
    scene.driver.advanceTo(t + 0.5);
    const common::Pose2 a = common::compose(v, scene.mount), a2 = common::compose(scene.driver.state().pose, scene.mount);
    const common::Pose2 b =
        common::compose(common::compose({v.x + f * std::cos(v.phi), v.y + f * std::sin(v.phi), v.phi}, scene.mount), {l, 0.0, h});
    const auto fa = scene.sift.extract(toMat(scene.cam.render(index++, 0, a)));
    const auto fa2 = scene.sift.extract(toMat(scene.cam.render(index++, 0, a2)));
    const auto fb = scene.sift.extract(toMat(scene.cam.render(index++, 0, b)));
    const double baseline = std::hypot(a2.x - a.x, a2.y - a.y);
    const auto stereo = vision_loop::triangulateWithSecondImage(fa, fa2, scene.sift.options().type, scene.k,
                                                                baseline * (1 + odometry(scene.rng)), kOdometrySigma * baseline, o);
    triangulated += !stereo.x.empty();
    const auto r = vision_loop::metricRelativePose(stereo, fa, fb, scene.sift.options().type, scene.k, o);
    if (!json && (i + 1) % 100 == 0) std::fprintf(stderr, "%d / %d pairs\n", i + 1, pairs);
    if (!r.valid) continue;
    const common::Pose2 truth = common::between(a, b);
    const Eigen::Vector3d d(r.pose.x - truth.x, r.pose.y - truth.y, common::wrapToPi(r.pose.phi - truth.phi));
    const double n = d.dot(r.cov.inverse() * d);
    ++valid;
    nees.push_back(n);
    within95 += n < 7.815;
    err_forward.push_back(std::abs(d(0))), err_left.push_back(std::abs(d(1))), err_heading.push_back(std::abs(d(2)) * 180 / M_PI);
    if (std::hypot(d(0), d(1)) > 1.0 || std::abs(d(2)) > kGrossHeading) {
      ++gross;
      continue;
    }
    nees_sound.push_back(n);
    for (int axis = 0; axis < 3; ++axis) e2[axis].push_back(d(axis) * d(axis)), var[axis].push_back(r.cov(axis, axis));
  }
  if (calibrate) {
    // The floors are calibrated on the covariance without floors: run it so (the defaults).
    std::printf(
        "floors making each axis's mean NEES 1 (%zu sound pairs of city seed %u): --floor-forward-m %.4f --floor-left-m %.4f "
        "--floor-heading-deg %.4f\n",
        e2[0].size(), city_seed, calibrateFloor(e2[0], var[0]), calibrateFloor(e2[1], var[1]), calibrateFloor(e2[2], var[2]) * 180 / M_PI);
    return 0;
  }
  const double mean_nees = mean(nees), within = valid ? static_cast<double>(within95) / valid : 0.0;
  if (json) {
    std::printf(
        "{\"pairs\":%d,\"city_seed\":%u,\"floor_forward_m\":%.4f,\"floor_left_m\":%.4f,\"floor_heading_deg\":%.4f,\"triangulated\":%d,"
        "\"valid\":%d,\"mean_nees\":%.4f,\"median_nees\":%.4f,\"within_95\":%.4f,\"median_forward_err_m\":%.4f,"
        "\"median_left_err_m\":%.4f,\"median_heading_err_deg\":%.4f,\"gross_errors\":%d,\"mean_nees_without_gross\":%.4f}\n",
        pairs, city_seed, floors(0), floors(1), floors(2) * 180 / M_PI, triangulated, valid, mean_nees, median(nees), within,
        median(err_forward), median(err_left), median(err_heading), gross, mean(nees_sound));
    return 0;
  }
  std::printf("%d pairs of city seed %u, %d with a triangulated first image; floors %.4f m (forward), %.4f m (left), %.4f° (heading)\n",
              pairs, city_seed, triangulated, floors(0), floors(1), floors(2) * 180 / M_PI);
  std::printf("%-14s %6s %10s %12s %10s %12s %12s %14s %6s %16s\n", "pose", "valid", "mean NEES", "median NEES", "within 95%",
              "forward err", "left err", "heading err°", "gross", "NEES w/o gross");
  std::printf("%-14s %6d %10.2f %12.2f %9.1f%% %12.3f %12.3f %14.3f %6d %16.2f\n", "metric_3dof", valid, mean_nees, median(nees),
              100 * within, median(err_forward), median(err_left), median(err_heading), gross, mean(nees_sound));
  return 0;
}

int main(int argc, char** argv) {
  int pairs = 1000;
  unsigned city_seed = 1;
  bool json = false, calibrate = false, metric = false;
  double floor_bearing = 0, floor_heading = 0;
  Eigen::Vector3d metric_floors = Eigen::Vector3d::Zero();  // forward m, left m, heading rad
  for (int i = 1; i < argc; ++i) {
    const auto value = [&](const char* name) {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "relative_pose_nees: %s needs a value\n", name);
        std::exit(2);
      }
      char* end = nullptr;
      const double x = std::strtod(argv[++i], &end);
      if (*end || !(x >= 0)) {
        std::fprintf(stderr, "relative_pose_nees: %s must be a number >= 0, got '%s'\n", name, argv[i]);
        std::exit(2);
      }
      return x;
    };
    if (!std::strcmp(argv[i], "--json")) {
      json = true;
    } else if (!std::strcmp(argv[i], "--metric")) {
      metric = true;
    } else if (!std::strcmp(argv[i], "--floor-forward-m")) {
      metric_floors(0) = value("--floor-forward-m");
    } else if (!std::strcmp(argv[i], "--floor-left-m")) {
      metric_floors(1) = value("--floor-left-m");
    } else if (!std::strcmp(argv[i], "--calibrate")) {
      calibrate = true;
    } else if (!std::strcmp(argv[i], "--city-seed")) {
      city_seed = static_cast<unsigned>(value("--city-seed"));
    } else if (!std::strcmp(argv[i], "--floor-bearing-deg")) {
      floor_bearing = value("--floor-bearing-deg") * M_PI / 180;
    } else if (!std::strcmp(argv[i], "--floor-heading-deg")) {
      floor_heading = metric_floors(2) = value("--floor-heading-deg") * M_PI / 180;
    } else if (!std::strcmp(argv[i], "--help")) {
      std::printf(
          "usage: relative_pose_nees [PAIRS] [--city-seed N] [--floor-bearing-deg B --floor-heading-deg H] [--calibrate] [--json]\n"
          "       relative_pose_nees --metric [PAIRS] [--city-seed N] [--floor-forward-m F --floor-left-m L --floor-heading-deg H] "
          "[--calibrate] [--json]\n");
      return 0;
    } else {
      pairs = std::atoi(argv[i]);
      if (pairs < 1) {
        std::fprintf(stderr, "relative_pose_nees: PAIRS must be a positive number, got '%s'\n", argv[i]);
        return 2;
      }
    }
  }
  Scene scene(city_seed);
  if (metric) return runMetric(scene, pairs, city_seed, json, calibrate, metric_floors);
  const auto& cam = scene.cam;
  const auto& k = scene.k;
  const auto& sift = scene.sift;
  auto& driver = scene.driver;
  auto& rng = scene.rng;
  auto& forward = scene.forward;
  auto& across = scene.across;
  auto& turn = scene.turn;
  const common::Pose2 mount = scene.mount;

  std::vector<Method> methods = {{"five_point_bootstrap", vision_loop::PoseCovariance::FivePointBootstrap},
                                 {"planar_bootstrap", vision_loop::PoseCovariance::PlanarBootstrap},
                                 {"first_order", vision_loop::PoseCovariance::FirstOrder},
                                 {"first_order_floor", vision_loop::PoseCovariance::FirstOrder}};
  std::vector<double> e2_bearing, e2_heading, v_bearing, v_heading;  // first order, sound pairs: for --calibrate
  int matched = 0;
  uint64_t index = 0;
  for (int i = 0; i < pairs; ++i) {
    driver.advanceTo(5.0 + 1.5 * i);
    const common::Pose2 v = driver.state().pose;
    const double f = forward(rng);
    const common::Pose2 a = common::compose(v, mount);
    const common::Pose2 b = common::compose(common::compose({v.x + f * std::cos(v.phi), v.y + f * std::sin(v.phi), v.phi}, mount),
                                            {across(rng), 0.0, turn(rng)});
    const auto fa = sift.extract(toMat(cam.render(index++, 0, a)));
    const auto fb = sift.extract(toMat(cam.render(index++, 0, b)));
    const vision_loop::PointMatches m = vision_loop::matchFeatures(fa, fb, sift.options().type, 0.8);
    const common::Pose2 truth = common::between(a, b);
    bool any = false;
    for (Method& method : methods) {
      vision_loop::PlanarRelativePoseOptions o;
      o.covariance = method.covariance;
      const bool floored = !std::strcmp(method.name, "first_order_floor");
      o.floor_bearing_rad = floored ? floor_bearing : 0.0;
      o.floor_heading_rad = floored ? floor_heading : 0.0;
      const auto r = vision_loop::planarRelativePose(m.a, m.b, k, o);
      if (!r.valid) continue;
      any = true;
      const Eigen::Vector2d d(common::wrapToPi(r.bearing_rad - std::atan2(truth.y, truth.x)), common::wrapToPi(r.heading_rad - truth.phi));
      const double nees = d.dot(r.cov.inverse() * d);
      ++method.valid;
      method.nees_sum += nees;
      method.nees.push_back(nees);
      method.within95 += nees < 5.991;
      method.bearing_errors.push_back(std::abs(d(0)) * 180 / M_PI);
      method.heading_errors.push_back(std::abs(d(1)) * 180 / M_PI);
      // A wrong mode (a planar facade's second solution, a copied facade): no covariance of the
      // right mode explains it; the filter's innovation gate against the odometry must.
      if (std::abs(d(0)) > kGrossBearing || std::abs(d(1)) > kGrossHeading) {
        ++method.gross;
      } else {
        method.nees_sound.push_back(nees);
        if (method.covariance == vision_loop::PoseCovariance::FirstOrder && !floored) {
          e2_bearing.push_back(d(0) * d(0)), v_bearing.push_back(r.cov(0, 0));
          e2_heading.push_back(d(1) * d(1)), v_heading.push_back(r.cov(1, 1));
        }
      }
    }
    matched += any;
    if (!json && (i + 1) % 100 == 0) std::fprintf(stderr, "%d / %d pairs\n", i + 1, pairs);
  }
  if (calibrate) {
    std::printf(
        "floors making each axis's mean NEES 1 (first order, %zu sound pairs of city seed %u): --floor-bearing-deg %.4f "
        "--floor-heading-deg %.4f\n",
        e2_bearing.size(), city_seed, calibrateFloor(e2_bearing, v_bearing) * 180 / M_PI,
        calibrateFloor(e2_heading, v_heading) * 180 / M_PI);
    return 0;
  }
  if (json) {
    std::printf("{\"pairs\":%d,\"city_seed\":%u,\"floor_bearing_deg\":%.4f,\"floor_heading_deg\":%.4f,\"methods\":{", pairs, city_seed,
                floor_bearing * 180 / M_PI, floor_heading * 180 / M_PI);
    for (size_t i = 0; i < methods.size(); ++i) {
      const Method& m = methods[i];
      std::printf(
          "%s\"%s\":{\"valid\":%d,\"mean_nees\":%.4f,\"median_nees\":%.4f,\"within_95\":%.4f,\"median_bearing_err_deg\":%.4f,"
          "\"median_heading_err_deg\":%.4f,\"gross_errors\":%d,\"mean_nees_without_gross\":%.4f}",
          i ? "," : "", m.name, m.valid, m.valid ? m.nees_sum / m.valid : 0.0, median(m.nees), m.valid ? double(m.within95) / m.valid : 0.0,
          median(m.bearing_errors), median(m.heading_errors), m.gross, mean(m.nees_sound));
    }
    std::printf("}}\n");
  } else {
    std::printf("%d pairs of city seed %u, %d with a pose from some method; floors %.4f° (bearing), %.4f° (heading)\n", pairs, city_seed,
                matched, floor_bearing * 180 / M_PI, floor_heading * 180 / M_PI);
    std::printf("%-22s %6s %10s %12s %10s %14s %14s %6s %16s\n", "covariance", "valid", "mean NEES", "median NEES", "within 95%",
                "bearing err°", "heading err°", "gross", "NEES w/o gross");
    for (const Method& m : methods)
      std::printf("%-22s %6d %10.2f %12.2f %9.1f%% %14.3f %14.3f %6d %16.2f\n", m.name, m.valid, m.valid ? m.nees_sum / m.valid : 0.0,
                  median(m.nees), m.valid ? 100.0 * m.within95 / m.valid : 0.0, median(m.bearing_errors), median(m.heading_errors), m.gross,
                  mean(m.nees_sound));
  }
  return 0;
}
