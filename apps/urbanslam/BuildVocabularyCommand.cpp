// `urbanslam build-vocabulary`: offline training of the Tree of Words vocabulary (thesis §4.2.2)
// from images unrelated to the runs it will serve.
#include <atomic>
#include <iostream>
#include <thread>

#include "ArgParser.h"
#include "Commands.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Progress.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/vision_loop/FeatureExtractor.h"
#include "urbanslam/vision_loop/ImageSequence.h"
#include "urbanslam/vision_loop/VocabularyFile.h"
#include "urbanslam/vision_loop/VocabularyTrainer.h"

namespace urbanslam::cli {

int buildVocabularyCommand(const Argv& args) {
  using namespace vision_loop;
  ArgParser ap(
      "urbanslam build-vocabulary IMAGES... --out FILE [--descriptor sift|orb] [--k 10] [--levels 6] "
      "[--max-features 500] [--threads N] [--quiet] [--json]",
      "Trains a vocabulary tree by hierarchical k-means (k-means++ seeding) on the local features of\n"
      "IMAGES and writes it in the binary vocabulary format. IMAGES: folders (their image files), image\n"
      "lists (.txt: one path per line, relative to the list), image files or rawlogs. Use images that\n"
      "are NOT in the sequences the vocabulary will be evaluated on.");
  ap.addPositional("IMAGES", "folders, image lists, images or rawlogs", true, true);
  ap.addOption("out", "FILE", "output vocabulary file");
  ap.addOption("descriptor", "D", "sift (128-D, angle) or orb (256-bit, Hamming)", "sift");
  ap.addOption("k", "K", "branching factor", "10");
  ap.addOption("levels", "L", "depth: up to K^L words", "6");
  ap.addOption("max-features", "N", "features kept per image (strongest)", "500");
  ap.addOption("max-image-side", "PX", "larger images are downscaled to this longer side (0: never)", "1024");
  ap.addOption("iterations", "N", "k-means iterations per node", "10");
  ap.addOption("seed", "S", "random seed (same seed and images: same vocabulary)", "1");
  ap.addOption("every", "N", "use every N-th image of each input (1: all)", "1");
  ap.addOption("threads", "N", "worker threads (0: all cores)", "0");
  ap.addFlag("quiet", "no progress bar");
  ap.addFlag("json", "print a summary as one JSON object");
  if (!ap.parse(args)) return 0;
  if (!ap.has("out")) throw common::InputError("--out FILE is required");

  FeatureOptions fo;
  fo.type = parseDescriptorType(ap.option("descriptor"));
  fo.max_features = static_cast<int>(ap.optionInt("max-features"));
  fo.max_image_side_px = static_cast<int>(ap.optionInt("max-image-side"));
  KMeansOptions ko;
  const long k = ap.optionInt("k"), levels = ap.optionInt("levels");
  if (k < 2 || k > 1000) throw common::InputError("--k must be in [2, 1000]");
  if (levels < 1 || levels > 12) throw common::InputError("--levels must be in [1, 12]");
  ko.branching = static_cast<uint32_t>(k);
  ko.depth = static_cast<uint32_t>(levels);
  ko.max_iterations = static_cast<int>(ap.optionInt("iterations"));
  ko.seed = static_cast<uint64_t>(ap.optionInt("seed"));
  const long every = ap.optionInt("every");
  if (every < 1) throw common::InputError("--every must be >= 1");
  int threads = static_cast<int>(ap.optionInt("threads"));
  if (threads <= 0) threads = std::max(1u, std::thread::hardware_concurrency());
  ko.threads = threads;
  const bool show = !ap.flag("quiet");

  // 1. Features, extracted in parallel batches (images are read in order on this thread).
  common::Stopwatch total;
  std::vector<cv::Mat> descriptors;
  size_t images = 0;
  {
    common::ProgressBar bar("features", 0, show);
    std::vector<FeatureExtractor> extractors;
    for (int t = 0; t < threads; ++t) extractors.emplace_back(fo);
    std::vector<cv::Mat> batch;
    auto flush = [&] {
      std::vector<cv::Mat> out(batch.size());
      std::atomic<size_t> cursor{0};
      std::vector<std::thread> pool;
      for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
          for (size_t i; (i = cursor++) < batch.size();) out[i] = extractors[t].extract(batch[i]).descriptors;
        });
      for (auto& th : pool) th.join();
      for (auto& d : out)
        if (!d.empty()) descriptors.push_back(d);
      batch.clear();
    };
    for (const std::string& input : ap.positionals("IMAGES")) {
      auto seq = openImageSequence(input);
      NamedImage img;
      long index = 0;
      while (seq->next(img)) {
        if (index++ % every != 0) continue;
        batch.push_back(img.gray);
        ++images;
        if (batch.size() >= static_cast<size_t>(4 * threads)) flush();
        bar.update(images, std::to_string(images) + " images");
      }
    }
    flush();
    bar.finish();
  }
  size_t count = 0;
  for (const auto& d : descriptors) count += d.rows;
  const double feature_s = total.seconds();
  if (show)
    std::cerr << images << " images, " << descriptors.size() << " with features, " << count << " " << descriptorName(fo.type)
              << " descriptors (" << feature_s << " s)\n";

  // 2. Tree and IDF.
  common::Stopwatch train;
  Vocabulary vocabulary;
  {
    common::ProgressBar bar("k-means", 1000, show);
    vocabulary =
        trainVocabulary(descriptors, fo.type, ko, [&](double f, const std::string& s) { bar.update(static_cast<uint64_t>(f * 1000), s); });
    bar.finish();
  }
  const double train_s = train.seconds();
  saveVocabulary(vocabulary, ap.option("out"));

  common::Json j = common::Json::object();
  j["out"] = ap.option("out");
  j["descriptor"] = descriptorName(fo.type);
  j["k"] = static_cast<long>(ko.branching);
  j["levels"] = static_cast<long>(ko.depth);
  j["words"] = vocabulary.wordCount();
  j["nodes"] = vocabulary.nodeCount();
  j["images"] = images;
  j["training_images"] = static_cast<unsigned long long>(vocabulary.data().training_images);
  j["descriptors"] = count;
  j["feature_seconds"] = feature_s;
  j["training_seconds"] = train_s;
  j["threads"] = threads;
  if (ap.flag("json"))
    std::cout << j.dump() << "\n";
  else
    std::cout << "wrote " << ap.option("out") << ": " << vocabulary.summary() << " in " << feature_s + train_s << " s\n";
  return 0;
}

}  // namespace urbanslam::cli
