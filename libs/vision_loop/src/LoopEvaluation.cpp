#include "urbanslam/vision_loop/LoopEvaluation.h"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::vision_loop {

GroundTruthLoops GroundTruthLoops::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw common::InputError(path + ": cannot open ground truth");
  GroundTruthLoops gt;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const auto h = line.find('#');
    if (h != std::string::npos) line.erase(h);
    std::istringstream s(line);
    std::string query, match;
    if (!(s >> query)) continue;
    size_t count = 0;
    while (s >> match) gt.add(query, match), ++count;
    if (count == 0) throw common::InputError(path + ":" + std::to_string(n) + ": image '" + query + "' lists no matching images");
  }
  return gt;
}

bool GroundTruthLoops::isMatch(const std::string& query, const std::string& match) const {
  const auto it = matches_.find(query);
  return it != matches_.end() && it->second.count(match) > 0;
}

SweepResult sweepThresholds(const std::vector<EvaluationFrame>& frames, const GroundTruthLoops& truth,
                            std::shared_ptr<const Vocabulary> vocabulary, const FeatureOptions& features,
                            const LoopDetectorOptions& options, const std::vector<double>& thresholds) {
  SweepResult out;
  for (const auto& f : frames) out.positives += truth.closesLoop(f.name) ? 1 : 0;
  auto cache = std::make_shared<LoopDetector::VerificationCache>();
  auto run = [&](double alpha, std::vector<Detection>* detections, double* query_ms, double* verify_ms) {
    LoopDetectorOptions o = options;
    o.min_normalized_score = static_cast<float>(alpha);
    LoopDetector detector(vocabulary, features, o);
    detector.shareVerificationCache(cache);
    PrPoint p;
    p.threshold = alpha;
    double q = 0, v = 0;
    for (const auto& f : frames) {
      const LoopResult r = detector.process(f.features, f.bag);
      q += detector.lastTimings().query_ms;
      v += detector.lastTimings().verification_ms;
      if (!r.detected()) continue;
      ++p.detections;
      Detection d{f.name, frames[r.match].name, r.score, r.normalized_score, r.verification.inliers, false};
      d.correct = truth.isMatch(d.query, d.match);
      (d.correct ? p.true_positives : p.false_positives)++;
      if (detections) detections->push_back(d);
    }
    p.precision = p.detections ? double(p.true_positives) / p.detections : 1.0;
    p.recall = out.positives ? double(p.true_positives) / out.positives : 0.0;
    if (query_ms) *query_ms = frames.empty() ? 0 : q / frames.size();
    if (verify_ms) *verify_ms = frames.empty() ? 0 : v / frames.size();
    return p;
  };
  // Timings at the detector's own α, measured before the cache holds any verification.
  out.at_default = run(options.min_normalized_score, &out.detections_at_default, &out.mean_query_ms, &out.mean_verification_ms);
  for (double t : thresholds) {
    out.curve.push_back(run(t, nullptr, nullptr, nullptr));
    const PrPoint& p = out.curve.back();
    if (p.false_positives == 0 && p.recall > out.recall_at_precision_1) {
      out.recall_at_precision_1 = p.recall;
      out.threshold_at_precision_1 = t;
    }
  }
  if (out.recall_at_precision_1 > 0) run(out.threshold_at_precision_1, &out.detections_at_precision_1, nullptr, nullptr);
  return out;
}

void writePrCurveCsv(const std::vector<PrPoint>& curve, const std::string& path) {
  common::AtomicFile f(path);
  f.stream() << "threshold,detections,true_positives,false_positives,precision,recall\n" << std::setprecision(6);
  for (const auto& p : curve)
    f.stream() << p.threshold << ',' << p.detections << ',' << p.true_positives << ',' << p.false_positives << ',' << p.precision << ','
               << p.recall << '\n';
  f.commit();
}

}  // namespace urbanslam::vision_loop
