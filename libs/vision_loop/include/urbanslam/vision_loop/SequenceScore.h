#pragma once
// Sequence matching (the idea of SeqSLAM, Milford & Wyeth 2012): a revisit is a run of frames
// that match a run of earlier frames in order, so a candidate is scored by how well the last
// few queries matched the frames just before it, not by one query alone. One look-alike frame
// (a copied facade, a bland corridor) makes a spike; a sequence of matches that advance together
// through the database is a place. With small or aliased images, where a single frame's score
// says little, this is what still separates the two.
//
// Score of database image j at the present query t, over a window of L queries:
//   η̄(j) = (1/L) Σ_{k=0}^{L-1} max_{i ∈ C_k(j)} η_{t-k}(i),  C_0 = {j},
//   C_k(j) = [j - 2k, j - max(1, ⌊k/2⌋)]
// where η_q(i) is query q's normalised score of image i (0 when i was not among its results).
// The cone allows the revisit to run at half to twice the speed of the first visit, but not to
// stand still, so an image that matches every frame of a stretch (a hub) gets no support from
// the sequence. η is not capped: a cap at 1 made every strong sequence score the same, and α
// could no longer rank a copied facade's run below a true revisit.
#include <deque>
#include <vector>

#include "urbanslam/vision_loop/ImageDatabase.h"

namespace urbanslam::vision_loop {

struct ScoredImage {
  ImageId image;
  float eta;  // normalised score η
};

class SequenceScore {
 public:
  // `frames`: L ≥ 1 (1: the present query's score alone).
  explicit SequenceScore(int frames);

  // η̄ of `image` with present score `eta_now`, from the last L - 1 queries pushed.
  float score(ImageId image, float eta_now) const;
  // Ends a frame: its query results (any order; empty for a frame that was not queried) become
  // the newest history entry, so that history step k is always the frame k before the present.
  void push(std::vector<ScoredImage> results);

 private:
  int frames_;
  std::deque<std::vector<ScoredImage>> history_;  // newest first, each sorted by image
};

}  // namespace urbanslam::vision_loop
