// `urbanslam eval-image-loop`: precision–recall of Tree of Words loop detection on an image
// sequence with ground-truth loops (recall at 100 % precision as DBoW2 reports it), timings.
#include <filesystem>
#include <cstdio>
#include <iostream>
#include <set>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Progress.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/vision_loop/ImageSequence.h"
#include "urbanslam/vision_loop/LoopEvaluation.h"
#include "urbanslam/vision_loop/VocabularyFile.h"

namespace urbanslam::cli {

int evalImageLoopCommand(const Argv& args) {
  using namespace vision_loop;
  ArgParser ap("urbanslam eval-image-loop VOCAB SEQUENCE --gt GT [--out DIR] [--alpha A] [--json] [--quiet]",
               "Runs image loop-closure detection over SEQUENCE (a folder of images in natural name order, an\n"
               "image list or a rawlog) and scores it against GT (one line per loop-closing image: its name\n"
               "without extension, then the names of the earlier images it matches; # comments). The detection\n"
               "threshold α (normalised score) is swept for the precision-recall curve.");
  ap.addPositional("VOCAB", "vocabulary file (build-vocabulary)");
  ap.addPositional("SEQUENCE", "folder of images, image list or rawlog");
  ap.addOption("gt", "GT", "ground-truth loops");
  ap.addOption("out", "DIR", "writes pr_curve.csv, pr_curve.png, detections.csv here", "out/eval-image-loop");
  ap.addOption("max-features", "N", "features per image", "500");
  ap.addOption("max-image-side", "PX", "larger images are downscaled to this longer side (0: never)", "1024");
  ap.addOption("min-image-side", "PX",
               "smaller images (after any downscaling) are upscaled to this longer side before detection (0: never)", "320");
  ap.addOption("alpha", "A", "detector threshold on the normalised score (reported point)", "0.3");
  ap.addOption("exclude-recent", "N", "the last N frames are never loop candidates", "10");
  ap.addOption("consistency", "K", "earlier consecutive queries whose islands must agree (DBoW2 k)", "0");
  ap.addOption("sequence", "L", "sequence matching over the last L queries (1: off)", "3");
  ap.addOption("min-inliers", "N", "geometric verification: minimum fundamental-matrix inliers", "20");
  ap.addOption("ransac-px", "PX", "geometric verification: max distance to the epipolar line", "3");
  ap.addFlag("no-verification", "skip geometric verification");
  ap.addFlag("quiet", "no progress bar");
  ap.addFlag("json", "print the results as one JSON object");
  if (!ap.parse(args)) return 0;
  if (!ap.has("gt")) throw common::InputError("--gt GT is required");

  common::Stopwatch sw;
  auto vocabulary = std::make_shared<const Vocabulary>(loadVocabulary(ap.positional("VOCAB")));
  const double load_ms = sw.milliseconds();
  const GroundTruthLoops truth = GroundTruthLoops::load(ap.option("gt"));

  FeatureOptions fo;
  fo.type = vocabulary->descriptorType();
  fo.max_features = static_cast<int>(ap.optionInt("max-features"));
  fo.max_image_side_px = static_cast<int>(ap.optionInt("max-image-side"));
  fo.min_image_side_px = static_cast<int>(ap.optionInt("min-image-side"));
  LoopDetectorOptions lo;
  lo.min_normalized_score = static_cast<float>(ap.optionDouble("alpha"));
  lo.exclude_recent_frames = static_cast<int>(ap.optionInt("exclude-recent"));
  lo.temporal_consistency = static_cast<int>(ap.optionInt("consistency"));
  lo.sequence_frames = static_cast<int>(ap.optionInt("sequence"));
  if (lo.sequence_frames < 1 || lo.sequence_frames > 100) throw common::InputError("--sequence: L must be 1..100");
  lo.verification.min_inliers = static_cast<int>(ap.optionInt("min-inliers"));
  lo.verification.ransac_threshold_px = ap.optionDouble("ransac-px");
  lo.geometric_verification = !ap.flag("no-verification");

  // Features and words once (they do not depend on α); timed per frame.
  FeatureExtractor extractor(fo);
  std::vector<EvaluationFrame> frames;
  auto sequence = openImageSequence(ap.positional("SEQUENCE"));
  {
    common::ProgressBar bar("features", sequence->sizeHint(), !ap.flag("quiet"));
    NamedImage img;
    while (sequence->next(img)) {
      EvaluationFrame f;
      f.name = img.name;
      sw.restart();
      f.features = extractor.extract(img.gray);
      f.extraction_ms = sw.milliseconds();
      sw.restart();
      f.bag = vocabulary->transform(f.features.descriptors);
      f.quantization_ms = sw.milliseconds();
      frames.push_back(std::move(f));
      bar.update(frames.size());
    }
    bar.finish();
  }
  if (frames.empty()) throw common::InputError(ap.positional("SEQUENCE") + ": no images");
  size_t gt_missing = 0;
  {
    std::set<std::string> names;
    for (const auto& f : frames) names.insert(f.name);
    for (const auto& [q, ms] : truth.all()) gt_missing += names.count(q) ? 0 : 1;
  }

  std::vector<double> thresholds;
  for (int i = 0; i <= 100; ++i) thresholds.push_back(i / 100.0);
  for (int i = 1; i <= 40; ++i) thresholds.push_back(1.0 + i * 0.05);
  const SweepResult sweep = sweepThresholds(frames, truth, vocabulary, fo, lo, thresholds);

  double extraction = 0, quantization = 0, features = 0;
  for (const auto& f : frames) extraction += f.extraction_ms, quantization += f.quantization_ms, features += f.features.size();
  extraction /= frames.size();
  quantization /= frames.size();
  features /= frames.size();
  const double per_image = extraction + quantization + sweep.mean_query_ms + sweep.mean_verification_ms;

  const std::filesystem::path out(ap.option("out"));
  std::filesystem::create_directories(out);
  writePrCurveCsv(sweep.curve, (out / "pr_curve.csv").string());
  char title[200];
  std::snprintf(title, sizeof title, "%s, %zu frames: recall %.1f %% at 100 %% precision",
                std::filesystem::path(ap.positional("SEQUENCE")).filename().c_str(), frames.size(), 100 * sweep.recall_at_precision_1);
  writePrCurvePng(sweep.curve, title, (out / "pr_curve.png").string());
  {
    common::AtomicFile f((out / "detections.csv").string());
    f.stream() << "alpha,query,match,score,normalized_score,inliers,correct\n";
    for (const auto& d : sweep.detections_at_default)
      f.stream() << lo.min_normalized_score << ',' << d.query << ',' << d.match << ',' << d.score << ',' << d.normalized_score << ','
                 << d.inliers << ',' << (d.correct ? 1 : 0) << '\n';
    for (const auto& d : sweep.detections_at_precision_1)
      f.stream() << sweep.threshold_at_precision_1 << ',' << d.query << ',' << d.match << ',' << d.score << ',' << d.normalized_score << ','
                 << d.inliers << ',' << (d.correct ? 1 : 0) << '\n';
    f.commit();
  }

  common::Json j = common::Json::object();
  j["vocabulary"] = vocabulary->summary();
  j["vocabulary_load_ms"] = load_ms;
  j["sequence"] = ap.positional("SEQUENCE");
  j["frames"] = frames.size();
  j["loop_frames"] = sweep.positives;
  j["ground_truth_images_not_in_sequence"] = gt_missing;
  j["mean_features_per_image"] = features;
  j["recall_at_precision_1"] = sweep.recall_at_precision_1;
  j["alpha_at_precision_1"] = sweep.threshold_at_precision_1;
  common::Json d = common::Json::object();
  d["alpha"] = static_cast<double>(lo.min_normalized_score);
  d["precision"] = sweep.at_default.precision;
  d["recall"] = sweep.at_default.recall;
  d["true_positives"] = sweep.at_default.true_positives;
  d["false_positives"] = sweep.at_default.false_positives;
  j["at_alpha"] = d;
  j["mean_ms_per_image"] = per_image;
  j["mean_extraction_ms"] = extraction;
  j["mean_quantization_ms"] = quantization;
  j["mean_query_ms"] = sweep.mean_query_ms;
  j["mean_verification_ms"] = sweep.mean_verification_ms;
  j["geometric_verification"] = lo.geometric_verification;
  j["temporal_consistency"] = lo.temporal_consistency;
  j["sequence_frames"] = lo.sequence_frames;
  j["pr_curve_csv"] = (out / "pr_curve.csv").string();
  j["pr_curve_png"] = (out / "pr_curve.png").string();
  if (ap.flag("json")) {
    std::cout << j.dump() << "\n";
  } else {
    std::printf("%s\n%zu frames (%zu close loops), %.0f features/image\n", vocabulary->summary().c_str(), frames.size(), sweep.positives,
                features);
    std::printf("recall at 100%% precision: %.1f %% (alpha %.2f)\n", 100 * sweep.recall_at_precision_1, sweep.threshold_at_precision_1);
    std::printf("at alpha %.2f: precision %.1f %%, recall %.1f %% (%zu TP, %zu FP)\n", lo.min_normalized_score,
                100 * sweep.at_default.precision, 100 * sweep.at_default.recall, sweep.at_default.true_positives,
                sweep.at_default.false_positives);
    std::printf("per image: %.2f ms (extraction %.2f, quantisation %.2f, query %.3f, verification %.2f)\n", per_image, extraction,
                quantization, sweep.mean_query_ms, sweep.mean_verification_ms);
    std::printf("PR curve: %s, %s\n", (out / "pr_curve.csv").c_str(), (out / "pr_curve.png").c_str());
  }
  return 0;
}

}  // namespace urbanslam::cli
