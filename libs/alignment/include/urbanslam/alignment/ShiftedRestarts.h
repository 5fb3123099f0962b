#pragma once
// Is an alignment the best explanation of two point sets, or one of several? A wrong alignment is
// usually a wrong local minimum that the start happened to lie in: a corridor's repeated doors, a
// facade, a street of one building design. PL-ICP restarted from the result shifted along x and
// y, by a first shift, then twice, four times that, ..., finds the other minima within that reach;
// one that matches enough points, compared with the result's, is another explanation. The loop
// closer asks it of two scans (another minimum matching clearly more points), and of the two
// visits' path submaps (another matching nearly as many).
#include <limits>

#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/IndexedReference.h"

namespace urbanslam::alignment {

struct ShiftedRestarts {
  double first_shift_m = 0.75;
  double last_shift_m = 6.0;      // shifts double from the first while they are at most this
  double same_minimum_m = 0.2;    // a restart that ends this close to the result found the same minimum
  double min_match_ratio = 1.05;  // another minimum counts when it matches this many times the result's points ...
  double max_rms_m = std::numeric_limits<double>::infinity();  // ... with its residual at most this
};

// Whether a restart of `result` (b aligned onto a, `options` but by PL-ICP) finds another minimum.
// A restart that cannot reach min_match_ratio times the result's matches is given up once settled
// near the final gate (IcpOptions::abandon_below_fraction), a rule, not a proof: on the tested
// scans and the 1, 10 and 100 km² cities it gave the answer of restarts run in full.
bool findsOtherMinimum(const IndexedReference& a, const PointSet& b, const AlignmentResult& result, AlignerOptions options,
                       const ShiftedRestarts& restarts);

}  // namespace urbanslam::alignment
