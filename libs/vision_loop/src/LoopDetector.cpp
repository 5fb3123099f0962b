#include "urbanslam/vision_loop/LoopDetector.h"

#include <algorithm>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Timing.h"

namespace urbanslam::vision_loop {

const char* loopStatusName(LoopStatus s) {
  switch (s) {
    case LoopStatus::Detected:
      return "detected";
    case LoopStatus::NoFeatures:
      return "no_features";
    case LoopStatus::DatabaseTooSmall:
      return "database_too_small";
    case LoopStatus::LowPriorScore:
      return "low_prior_score";
    case LoopStatus::NoCandidates:
      return "no_candidates";
    case LoopStatus::NotConsistent:
      return "not_consistent";
    case LoopStatus::VerificationFailed:
      return "verification_failed";
  }
  return "?";
}

LoopDetector::LoopDetector(std::shared_ptr<const Vocabulary> vocabulary, const FeatureOptions& features, const LoopDetectorOptions& options)
    : vocabulary_(std::move(vocabulary)),
      extractor_([&] {
        if (!vocabulary_ || vocabulary_->empty()) throw common::InputError("loop detector needs a vocabulary");
        if (features.type != vocabulary_->descriptorType())
          throw common::InputError("features are " + descriptorName(features.type) + " but the vocabulary is " +
                                   descriptorName(vocabulary_->descriptorType()));
        return features;
      }()),
      options_(options),
      database_(vocabulary_->wordCount()),
      sequence_(options.sequence_frames) {}

LoopResult LoopDetector::process(const cv::Mat& image, const std::vector<ImageId>* candidates) {
  common::Stopwatch sw;
  ImageFeatures f = extractor_.extract(image);
  const double extraction = sw.milliseconds();
  sw.restart();
  BagOfWords bag = vocabulary_->transform(f.descriptors);
  const double quantization = sw.milliseconds();
  LoopResult r = process(std::move(f), std::move(bag), candidates);
  timings_.extraction_ms = extraction;
  timings_.quantization_ms = quantization;
  return r;
}

bool LoopDetector::consistentWithPrevious(const Island& island, ImageId query) {
  bool agree = false;
  if (window_open_ && query - window_query_ <= static_cast<ImageId>(options_.max_query_gap_frames)) {
    const Island& p = window_island_;
    const bool overlap = (p.first <= island.first && island.first <= p.last) || (island.first <= p.first && p.first <= island.last);
    long gap = 0;
    if (!overlap) gap = std::min(std::labs(long(p.first) - long(island.last)), std::labs(long(island.first) - long(p.last)));
    agree = gap <= options_.max_island_distance_frames;
  }
  window_count_ = agree ? window_count_ + 1 : 1;
  window_open_ = true;
  window_query_ = query;
  window_island_ = island;
  return window_count_ > options_.temporal_consistency;
}

LoopResult LoopDetector::process(ImageFeatures features, BagOfWords bag, const std::vector<ImageId>* candidates) {
  timings_ = {};
  LoopResult r;
  r.query = static_cast<ImageId>(database_.size());
  common::Stopwatch sw;
  // Whatever happens below, the frame joins the database and becomes the "previous" frame.
  struct AddOnExit {
    LoopDetector& d;
    ImageFeatures& f;
    BagOfWords& b;
    ~AddOnExit() {
      d.database_.add(b);
      d.frames_.push_back(std::move(f));
      d.previous_bag_ = std::move(b);
      d.sequence_.push(std::move(d.query_results_));
      d.query_results_.clear();
    }
  } add_on_exit{*this, features, bag};

  if (bag.empty()) {
    r.status = LoopStatus::NoFeatures;
    return r;
  }
  const long limit = long(r.query) - options_.exclude_recent_frames;
  if (limit <= 0) {
    r.status = LoopStatus::DatabaseTooSmall;
    return r;
  }
  const float prior = previous_bag_.empty() ? 0.f : l1Score(bag, previous_bag_);
  if (prior < options_.min_prior_score) {
    r.status = LoopStatus::LowPriorScore;
    return r;
  }
  const bool sequence = options_.sequence_frames > 1;
  QueryOptions q;
  q.max_results = options_.max_query_results;
  q.max_image = static_cast<ImageId>(limit);
  q.candidates = candidates;
  // η ≥ α; with sequences every result is kept, since a weak match now may support a strong
  // sequence later.
  q.min_score = sequence ? 0.f : options_.min_normalized_score * prior;
  const std::vector<QueryResult> raw = database_.query(bag, q);
  // The ranked results: score = η̄ · prior, so that islands and α work on η̄ as they do on η.
  std::vector<QueryResult> hits;
  if (!sequence) {
    hits = raw;
  } else {
    for (const auto& h : raw) {
      query_results_.push_back({h.image, h.score / prior});
      const float ranked = sequence_.score(h.image, h.score / prior);
      if (ranked >= options_.min_normalized_score) hits.push_back({h.image, ranked * prior});
    }
  }
  timings_.query_ms = sw.milliseconds();
  if (hits.empty()) {
    r.status = LoopStatus::NoCandidates;
    return r;
  }

  // Islands: runs of images close in time, scored by their summed similarity.
  std::sort(hits.begin(), hits.end(), [](const QueryResult& a, const QueryResult& b) { return a.image < b.image; });
  std::vector<Island> islands;
  for (const auto& h : hits) {
    if (islands.empty() || h.image - islands.back().last > static_cast<ImageId>(options_.island_gap_frames)) {
      islands.push_back({h.image, h.image, 0.f, {}});
    }
    Island& is = islands.back();
    is.last = h.image;
    is.score += h.score;
    is.members.push_back(h);
  }
  const Island& best =
      *std::max_element(islands.begin(), islands.end(), [](const Island& a, const Island& b) { return a.score < b.score; });
  std::vector<QueryResult> members = best.members;
  std::sort(members.begin(), members.end(),
            [](const QueryResult& a, const QueryResult& b) { return a.score > b.score || (a.score == b.score && a.image < b.image); });
  auto report = [&](const QueryResult& m) {
    r.match = m.image;
    r.score = std::find_if(raw.begin(), raw.end(), [&](const QueryResult& h) { return h.image == m.image; })->score;
    r.normalized_score = r.score / prior;
    r.sequence_score = m.score / prior;
  };
  report(members.front());

  if (!consistentWithPrevious(best, r.query)) {
    r.status = LoopStatus::NotConsistent;
    return r;
  }
  if (!options_.geometric_verification) {
    r.status = LoopStatus::Detected;
    return r;
  }
  sw.restart();
  r.status = LoopStatus::VerificationFailed;
  const int tries = std::min<int>(options_.verify_candidates, static_cast<int>(members.size()));
  for (int i = 0; i < tries; ++i) {
    const ImageId m = members[i].image;
    VerificationResult v;
    const auto key = std::make_pair(r.query, m);
    if (cache_ && cache_->count(key)) {
      v = cache_->at(key);
    } else {
      v = verifyPair(features, frames_[m], vocabulary_->descriptorType(), options_.verification);
      if (cache_) (*cache_)[key] = v;
    }
    if (i == 0 || v.accepted) {
      r.verification = v;
      report(members[i]);
    }
    if (v.accepted) {
      r.status = LoopStatus::Detected;
      break;
    }
  }
  if (r.status != LoopStatus::Detected) report(members.front());
  timings_.verification_ms = sw.milliseconds();
  return r;
}

}  // namespace urbanslam::vision_loop
