#!/usr/bin/env bash
# Reproduces the laser loop-closure evaluation: models trained on one
# set of logs and tested on different ones (indoor → outdoor and back, default model → held-out
# logs, Victoria Park via GPS labels), detection at 0 / 0.1 / 1 % false alarm next to the
# published 66 % (0 % FA) and 85 % (1 % FA), the rotation split, the nearest-neighbour baseline,
# cross-validation curves and the speed bench.
#
#   bench/laser_loop/run_eval.sh [BUILD_DIR] [OUT_DIR]
#
# Needs ../shared/data (Freiburg corrected logs, Victoria Park). Takes about 4 minutes.
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD=${1:-build}
OUT=${2:-$BUILD/laser_loop_eval}
U=$BUILD/apps/urbanslam/urbanslam
D=../shared/data/freiburg_slam_benchmark/corrected_logs
VP=../shared/data/victoria_park/victoria_park_ascii.zip
mkdir -p "$OUT"
log() { echo "== $*" >&2; }

INDOOR_TRAIN="$D/intel-corrected.log.gz $D/aces-corrected.log.gz $D/csail-corrected.log.gz $D/freiburg-079-corrected.log.gz"
INDOOR_HELDOUT="$D/fhw-corrected.log.gz $D/edmonton-corrected.log.gz $D/orebro-corrected.log.gz $D/infinite-corridor-corrected.log.gz"
CAMPUS="$D/freiburg-campus-corrected.log.gz"
# Victoria Park has no reference trajectory: GPS labels (fix within 1 s either side of the scan),
# which jump by metres, so positives are within 3 m and negatives beyond 10 m.
VP_RULES="--d-pos 3 --d-neg 10 --min-travel 20"

log "train: indoor (intel, aces, csail, fr079)"
$U train-laser-loop $INDOOR_TRAIN --out "$OUT/indoor.model" --plots "$OUT/cv-indoor" --quiet --json > "$OUT/train-indoor.json"
log "train: indoor, the thesis's twenty features only (--features thesis)"
$U train-laser-loop $INDOOR_TRAIN --features thesis --out "$OUT/indoor-thesis.model" --quiet --json > "$OUT/train-indoor-thesis.json"
log "train: indoor, log-scale features (--log-features 1), measured against the plain indoor model"
$U train-laser-loop $INDOOR_TRAIN --log-features 1 --out "$OUT/indoor-log.model" --quiet --json > "$OUT/train-indoor-log.json"
log "train: indoor, virtual 360° scans from the last 5 m of odometry (--submap-window 5)"
$U train-laser-loop $INDOOR_TRAIN --submap-window 5 --out "$OUT/indoor-submap5.model" --quiet --json > "$OUT/train-indoor-submap5.json"
log "train: the five real logs of the default model, every comparison (no simulated city)"
$U train-laser-loop $INDOOR_TRAIN $CAMPUS --out "$OUT/real.model" --quiet --json > "$OUT/train-real.json"
log "train: the held-out indoor logs themselves (in-sample: what the features can tell apart there at best)"
$U train-laser-loop $INDOOR_HELDOUT --out "$OUT/heldout-in-sample.model" --quiet --json > "$OUT/train-heldout-in-sample.json"
log "train: outdoor (Freiburg campus)"
$U train-laser-loop $CAMPUS --out "$OUT/campus.model" --plots "$OUT/cv-campus" --quiet --json > "$OUT/train-campus.json"

evaluate() {  # name model rules... data...
  local name=$1 model=$2; shift 2
  log "eval: $name"
  $U eval-laser-loop "$model" "$@" --out "$OUT/$name" --quiet --json > "$OUT/$name.json"
}
evaluate indoor-on-campus "$OUT/indoor.model" $CAMPUS
evaluate indoor-log-on-campus "$OUT/indoor-log.model" $CAMPUS
evaluate indoor-log-on-heldout-indoor "$OUT/indoor-log.model" $INDOOR_HELDOUT
evaluate indoor-log-on-victoria-park "$OUT/indoor-log.model" $VP_RULES $VP
# Victoria Park has speed + steering, not odometry poses, so the submap model is not run on it.
evaluate indoor-submap5-on-campus "$OUT/indoor-submap5.model" $CAMPUS
evaluate indoor-submap5-on-heldout-indoor "$OUT/indoor-submap5.model" $INDOOR_HELDOUT
evaluate indoor-on-campus-heading30 "$OUT/indoor.model" --max-heading-diff 30 $CAMPUS
evaluate indoor-on-heldout-indoor "$OUT/indoor.model" $INDOOR_HELDOUT
evaluate indoor-thesis-on-campus "$OUT/indoor-thesis.model" $CAMPUS
evaluate indoor-thesis-on-heldout-indoor "$OUT/indoor-thesis.model" $INDOOR_HELDOUT
evaluate indoor-on-victoria-park "$OUT/indoor.model" $VP_RULES $VP
evaluate campus-on-indoor "$OUT/campus.model" $INDOOR_TRAIN
evaluate campus-on-indoor-heading30 "$OUT/campus.model" --max-heading-diff 30 $INDOOR_TRAIN
evaluate campus-on-victoria-park "$OUT/campus.model" $VP_RULES $VP
evaluate default-on-heldout-indoor share/laser_loop/default.model $INDOOR_HELDOUT
evaluate default-on-heldout-indoor-heading30 share/laser_loop/default.model --max-heading-diff 30 $INDOOR_HELDOUT
evaluate default-on-victoria-park share/laser_loop/default.model $VP_RULES $VP
evaluate real-on-heldout-indoor "$OUT/real.model" $INDOOR_HELDOUT
evaluate real-on-victoria-park "$OUT/real.model" $VP_RULES $VP
evaluate in-sample-on-heldout-indoor "$OUT/heldout-in-sample.model" $INDOOR_HELDOUT
# The evaluation city of bench/scale (seed 1, never trained on), 4 km² and 5 km of driving, with
# the front 180° laser and with the 360° one; two more held-out cities (seeds 6 and 7) with the
# 360° laser for the 360° model.
. bench/laser_loop/cities.sh
for fov in 180 360; do
  evaluate default-on-city-fov$fov share/laser_loop/default.model "$(city "$U" "$OUT" 1 $fov)"
  evaluate default-360-on-city-fov$fov share/laser_loop/default-360.model "$(city "$U" "$OUT" 1 $fov)"
  evaluate real-on-city-fov$fov "$OUT/real.model" "$(city "$U" "$OUT" 1 $fov)"
done
for seed in 6 7; do
  evaluate default-360-on-city-seed$seed-fov360 share/laser_loop/default-360.model "$(city "$U" "$OUT" $seed 360)"
done
# Close-pair protocol (positives within 1 m with no minimum travel, so consecutive scans count —
# the "scans very close together" positives attributed to the ICRA 2009 paper), any heading and
# same direction.
CLOSE="--min-travel 0"
evaluate close-default-on-heldout-indoor share/laser_loop/default.model $CLOSE $INDOOR_HELDOUT
evaluate close-default-on-heldout-indoor-heading30 share/laser_loop/default.model $CLOSE --max-heading-diff 30 $INDOOR_HELDOUT
evaluate close-indoor-on-campus "$OUT/indoor.model" $CLOSE $CAMPUS
evaluate close-indoor-on-campus-heading30 "$OUT/indoor.model" $CLOSE --max-heading-diff 30 $CAMPUS

python3 - "$OUT" <<'PY'
import json, sys, os
out = sys.argv[1]
print(f"{'evaluation':42s} {'pos':>6s} {'neg':>6s} | {'det@0%':>7s} {'det@0.1%':>8s} {'det@1%':>7s} | {'NN@0%':>6s} {'NN@1%':>6s} | {'same@0%':>7s} {'same@1%':>7s} | {'>90deg':>7s} {'<30deg':>7s}  (published: 66 % @0 %, 85 % @1 %)")
for f in sorted(os.listdir(out)):
    if not f.endswith('.json') or f.startswith('train-'): continue
    d = json.load(open(os.path.join(out, f)))
    r = d['rotation_at_fa_0.01']
    p = lambda v: f"{100*v:6.1f}%"
    print(f"{f[:-5]:42s} {d['positives']:6d} {d['negatives']:6d} | {p(d['detection_at_fa_0'])} {p(d['detection_at_fa_0.001']):>8s} {p(d['detection_at_fa_0.01'])} | "
          f"{p(d['baseline_detection_at_fa_0'])} {p(d['baseline_detection_at_fa_0.01'])} | "
          f"{p(d['same_side'].get('detection_at_fa_0', 0))} {p(d['same_side'].get('detection_at_fa_0.01', 0))} | {p(r['detection_heading_gt_90'])} {p(r['detection_heading_lt_30'])}  ({r['pairs_heading_gt_90']}/{r['pairs_heading_lt_30']})")
for f in ('train-indoor.json', 'train-indoor-thesis.json', 'train-real.json', 'train-indoor-log.json', 'train-indoor-submap5.json', 'train-campus.json',
          'train-heldout-in-sample.json'):
    d = json.load(open(os.path.join(out, f)))
    print(f"{f}: T={d['T']} (CV chose {d['cv_chosen_T']}), CV FA {d['cv_fa_rate']:.3f} MD {d['cv_md_rate']:.3f} total {d['cv_total_rate']:.3f} on {d['positives']}+{d['negatives']} pairs")
PY

if [ -x "$BUILD/bench/laser_loop/laser_loop_bench" ]; then
  log "bench"
  "$BUILD/bench/laser_loop/laser_loop_bench" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true | tee "$OUT/bench.txt"
fi
