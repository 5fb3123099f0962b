#!/usr/bin/env bash
# Trains the shipped laser loop-closure classifier (share/laser_loop/default.model) on the real
# corrected logs and on simulated cities that the benchmarks never evaluate on (the evaluation
# city is seed 1): seeds 2 and 3, with the front 180° laser, 4 km² and 5 km of driving each,
# from ini/city-1km2.ini.
#
#   bench/laser_loop/train_default.sh [BUILD_DIR]
#
# Needs ../shared/data (Freiburg corrected logs). Takes about a minute.
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD=${1:-build}
U=$BUILD/apps/urbanslam/urbanslam
D=../shared/data/freiburg_slam_benchmark/corrected_logs
W=$BUILD/laser_loop_train
mkdir -p "$W"

cities=()
for seed in 2 3; do
  name=city-seed$seed-fov180  # ini/city-1km2.ini's front 180° laser
  sed -e "s/^seed .*/seed = $seed/" -e "s/^area_km2 .*/area_km2 = 4/" -e "s/^route_length_km .*/route_length_km = 5/" \
    ini/city-1km2.ini > "$W/$name.ini"
  [ -f "$W/$name/city.rawlog" ] || "$U" simulate --quiet --ini "$W/$name.ini" --out "$W/$name" > /dev/null
  cities+=("$W/$name/city.rawlog")
done
"$U" train-laser-loop "$D/intel-corrected.log.gz" "$D/aces-corrected.log.gz" "$D/csail-corrected.log.gz" \
  "$D/freiburg-079-corrected.log.gz" "$D/freiburg-campus-corrected.log.gz" "${cities[@]}" \
  --out share/laser_loop/default.model --plots share/laser_loop/default-cv --quiet --json
