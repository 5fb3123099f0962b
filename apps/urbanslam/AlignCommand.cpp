// `urbanslam align LOG A B`: aligns two laser scans of a log (thesis §3.3) with the same library
// call the pipeline uses, and prints the transform (pose of scan B in scan A's vehicle frame),
// its covariance, the iteration count and the time.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <variant>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/FreeSpace.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/io/DataSource.h"

namespace urbanslam::cli {

int alignCommand(const Argv& args);

namespace {

long parseIndex(const std::string& name, const std::string& text) {
  size_t pos = 0;
  long v = -1;
  try {
    v = std::stol(text, &pos);
  } catch (const std::exception&) {
    pos = 0;
  }
  if (pos != text.size() || v < 0) throw common::InputError(name + ": '" + text + "' is not a scan index (0, 1, 2, ...)");
  return v;
}

common::Pose2 parseGuess(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    size_t pos = 0;
    double d = 0;
    try {
      d = std::stod(item, &pos);
    } catch (const std::exception&) {
      pos = 0;
    }
    if (pos == 0 || pos != item.size() || !std::isfinite(d))
      throw common::InputError("--guess: '" + text + "' is not x,y,phi (metres, metres, radians)");
    v.push_back(d);
  }
  if (v.size() != 3) throw common::InputError("--guess: '" + text + "' is not x,y,phi (metres, metres, radians)");
  return {v[0], v[1], common::wrapToPi(v[2])};
}

}  // namespace

int alignCommand(const Argv& args) {
  ArgParser ap("urbanslam align LOG A B [--method M] [--guess x,y,phi] [--covariance C] [--json]",
               "Aligns laser scan B of LOG onto laser scan A (0-based indices among the log's laser scans,\n"
               "in file order) and prints the pose of B in A's vehicle frame (x, y in metres, phi in\n"
               "radians), its 3x3 covariance (x, y, phi), the iterations and the time.");
  ap.addPositional("LOG", "any supported log (MRPT rawlog, CARMEN log, GMapping gfs log, Victoria Park folder/zip)");
  ap.addPositional("A", "index of the reference scan");
  ap.addPositional("B", "index of the scan to align onto A");
  ap.addOption("method", "M",
               "prior (the guess as a prior: correlative search + point-to-line with the prior, local SLAM's matcher) | icp | plicp | crf "
               "| crf+icp (CRF-match coarse, ICP refine)",
               "prior");
  ap.addOption("prior-sigma", "M,DEG", "method prior: how far off the guess may be (1 sigma: metres on x and y, degrees)", "0.5,15");
  ap.addOption("guess", "x,y,phi", "initial guess of B in A (metres, metres, radians)", "0,0,0");
  ap.addOption("covariance", "C", "line (line variance, thesis) | hessian | sampling (methods other than prior, which gives its posterior)",
               "line");
  ap.addFlag("json", "print one JSON object: x, y, phi, cov, iterations, time_ms, converged, ...");
  ap.addEpilog("Exit code 0 also when the alignment fails (converged: false, with a reason); 2 for bad input.");
  if (!ap.parse(args)) return 0;

  const std::string log = ap.positional("LOG");
  const long ia = parseIndex("A", ap.positional("A"));
  const long ib = parseIndex("B", ap.positional("B"));
  alignment::AlignerOptions options;
  try {
    options.method = alignment::parseMethod(ap.option("method"));
    options.covariance.method = alignment::parseCovarianceMethod(ap.option("covariance"));
  } catch (const std::invalid_argument& e) {
    throw common::InputError(e.what());
  }
  const common::Pose2 guess = parseGuess(ap.option("guess"));
  {
    std::stringstream ss(ap.option("prior-sigma"));
    std::string a, b;
    double m = 0, d = 0;
    size_t pa = 0, pb = 0;
    bool ok = std::getline(ss, a, ',') && std::getline(ss, b, ',') && ss.peek() == EOF;
    try {
      if (ok) m = std::stod(a, &pa), d = std::stod(b, &pb);
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok || pa != a.size() || pb != b.size() || !(m > 0) || !(d > 0) || !std::isfinite(m) || !std::isfinite(d))
      throw common::InputError("--prior-sigma: '" + ap.option("prior-sigma") + "' is not M,DEG (two positive numbers)");
    options.prior_sigma_m = m;
    options.prior_sigma_deg = d;
  }

  auto source = io::openDataSource(log);
  io::Measurement m;
  io::LaserScan sa, sb;
  bool have_a = false, have_b = false;
  // Reference poses (corrected logs) come right before their scan; reported when both exist.
  bool have_ref = false, ref_a = false, ref_b = false;
  io::ReferencePose last_ref;
  common::Pose2 pose_a, pose_b;
  long index = 0;
  const long last = std::max(ia, ib);
  while (index <= last && source->next(m)) {
    if (auto* r = std::get_if<io::ReferencePose>(&m)) {
      last_ref = *r;
      have_ref = true;
      continue;
    }
    auto* s = std::get_if<io::LaserScan>(&m);
    if (!s) continue;
    const bool ref_ok = have_ref && std::abs(last_ref.timestamp - s->timestamp) < 1e-6;
    have_ref = false;
    if (index == ia) {
      sa = *s;
      have_a = true;
      ref_a = ref_ok;
      pose_a = last_ref.pose;
    }
    if (index == ib) {
      sb = *s;
      have_b = true;
      ref_b = ref_ok;
      pose_b = last_ref.pose;
    }
    ++index;
  }
  if (!have_a || !have_b) {
    std::ostringstream os;
    os << "scan index " << (!have_a ? ia : ib) << " is out of range: " << log << " has " << index << " laser scans";
    throw common::InputError(os.str());
  }

  const alignment::AlignmentResult r = alignment::align(sa, sb, guess, options);
  // Negative evidence next to the positive (matches): the share of points in the other scan's
  // free space, as the loop closer tests it (default options).
  const double conflict = alignment::mutualFreeSpaceConflict(sa, sb, r.transform);

  if (ap.flag("json")) {
    common::Json j = common::Json::object();
    j["x"] = r.transform.x;
    j["y"] = r.transform.y;
    j["phi"] = r.transform.phi;
    common::Json cov = common::Json::array();
    for (int i = 0; i < 3; ++i) {
      common::Json row = common::Json::array();
      for (int k = 0; k < 3; ++k) row.push(r.cov(i, k));
      cov.push(row);
    }
    j["cov"] = cov;
    j["iterations"] = r.iterations;
    j["time_ms"] = r.time_ms;
    j["converged"] = r.converged;
    j["failure_reason"] = r.failure_reason;
    j["method"] = alignment::methodName(options.method);
    j["covariance_method"] = alignment::covarianceMethodName(options.covariance.method);
    j["matches"] = r.matches;
    j["rms_residual_m"] = r.rms_residual_m;
    j["points_a"] = r.points_a;
    j["points_b"] = r.points_b;
    j["free_space_conflict"] = conflict;
    if (ref_a && ref_b) {
      const common::Pose2 rel = common::between(pose_a, pose_b);
      common::Json ref = common::Json::object();
      ref["x"] = rel.x;
      ref["y"] = rel.y;
      ref["phi"] = rel.phi;
      ref["free_space_conflict"] = alignment::mutualFreeSpaceConflict(sa, sb, rel);
      j["reference"] = ref;
    }
    std::cout << j.dump() << "\n";
    return 0;
  }
  char line[256];
  std::printf("scans %ld -> %ld of %s (%d / %d points), method %s\n", ia, ib, log.c_str(), r.points_a, r.points_b,
              alignment::methodName(options.method).c_str());
  std::snprintf(line, sizeof line, "transform: x %.4f m  y %.4f m  phi %.5f rad (%.3f deg)\n", r.transform.x, r.transform.y,
                r.transform.phi, r.transform.phi * 180.0 / M_PI);
  std::cout << line;
  std::cout << "covariance (" << alignment::covarianceMethodName(options.covariance.method) << "; x, y, phi):\n";
  for (int i = 0; i < 3; ++i) {
    std::snprintf(line, sizeof line, "  % .4e % .4e % .4e\n", r.cov(i, 0), r.cov(i, 1), r.cov(i, 2));
    std::cout << line;
  }
  std::snprintf(line, sizeof line, "std: x %.4f m  y %.4f m  phi %.4f deg\n", std::sqrt(r.cov(0, 0)), std::sqrt(r.cov(1, 1)),
                std::sqrt(r.cov(2, 2)) * 180.0 / M_PI);
  std::cout << line;
  std::printf("iterations %d, time %.2f ms, %d matches, rms residual %.3f m\n", r.iterations, r.time_ms, r.matches, r.rms_residual_m);
  std::printf("free-space conflict %.3f (share of points where the other scan saw through)\n", conflict);
  if (r.converged)
    std::printf("converged\n");
  else
    std::printf("NOT converged: %s\n", r.failure_reason.c_str());
  if (ref_a && ref_b) {
    const common::Pose2 rel = common::between(pose_a, pose_b);
    std::printf("reference (log's corrected poses): x %.4f m  y %.4f m  phi %.5f rad, free-space conflict %.3f\n", rel.x, rel.y, rel.phi,
                alignment::mutualFreeSpaceConflict(sa, sb, rel));
  }
  return 0;
}

}  // namespace urbanslam::cli
