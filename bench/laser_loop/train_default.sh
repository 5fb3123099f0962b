#!/usr/bin/env bash
# Trains the shipped laser loop-closure classifiers on the real corrected logs and on simulated
# cities that the benchmarks never evaluate on (the evaluation cities are seeds 1, 6 and 7),
# 4 km² and 5 km of driving each, from ini/city-1km2.ini:
#   share/laser_loop/default.model      any laser, the thesis's twenty features: the five Freiburg
#                                       logs (intel, aces, csail, fr079, campus) and seeds 2 and 3
#                                       with the front 180° laser;
#   share/laser_loop/default-360.model  lasers that see all around, every feature and distance:
#                                       seeds 2, 3, 4 and 5 with the 360° laser, every revisit pair
#                                       up to 10000 per city (3000 caps two of them).
# Why the general model keeps the thesis's features: share/laser_loop/README.md.
#
#   bench/laser_loop/train_default.sh [BUILD_DIR]
#
# Needs ../shared/data (Freiburg corrected logs). Takes about two minutes.
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD=${1:-build}
U=$BUILD/apps/urbanslam/urbanslam
D=../shared/data/freiburg_slam_benchmark/corrected_logs
W=$BUILD/laser_loop_train
mkdir -p "$W"

. bench/laser_loop/cities.sh

"$U" train-laser-loop "$D/intel-corrected.log.gz" "$D/aces-corrected.log.gz" "$D/csail-corrected.log.gz" \
  "$D/freiburg-079-corrected.log.gz" "$D/freiburg-campus-corrected.log.gz" "$(city "$U" "$W" 2 180)" "$(city "$U" "$W" 3 180)" \
  --features thesis --out share/laser_loop/default.model --plots share/laser_loop/default-cv --quiet --json
"$U" train-laser-loop "$(city "$U" "$W" 2 360)" "$(city "$U" "$W" 3 360)" "$(city "$U" "$W" 4 360)" "$(city "$U" "$W" 5 360)" \
  --max-positives 10000 --out share/laser_loop/default-360.model --quiet --json
