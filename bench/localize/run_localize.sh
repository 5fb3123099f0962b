#!/usr/bin/env bash
# Localization benchmark: for each raw Freiburg log, map its first half (`urbanslam run` on the
# log cut at its middle laser scan), localize the second half in that map (`urbanslam localize`),
# and compare with the mapping run over the whole log on the same relations.
#
#   bench/localize/run_localize.sh [BUILD_DIR] [OUT_DIR]
#
# Needs ../shared/data. Rows (RESULTS.md):
#   rel_m loc / onl / full
#                      mean absolute translational relation error [m] of the localized second
#                      half (trajectory_scans.tum: smoothed), of its poses as tracked at each scan
#                      (trajectory_online.tum) and of the full mapping run, on the relations whose
#                      two ends are both tracked by the localizer (eval --max-gap 1 on a relations
#                      file restricted to those, see relations_within.py); rel_deg likewise [deg];
#   tracked            share of the second half's scans tracked (the rest: lost, e.g. rooms the first
#                      half never entered);
#   reloc              relocalisations (place searches that found the pose) in the run with --initial;
#   fix_s              started lost: the second half localized with no initial pose, log time from its
#                      first scan to the first tracked one;
#   fix_err_m          that first fix against the full run's pose at the same scan (map frames agree:
#                      both runs start at the same first scan);
#   rtf                log duration / wall time of `urbanslam localize` with --initial (map loading
#                      included); rtf_onl the same with --no-smoothing (no local SLAM trajectory);
#                      rtf_lost the run started lost (smoothed);
#   jumps              kidnapping (kidnap.py): five times the vehicle tracked for 10 s, then carried
#                      to a place at least 5 m away and 30 s later in the log, its odometry
#                      unaware; relocalised within 20 s / within 3 s / jumps;
#   jump_s             the median log time from the jump to the first pose within 0.5 m and 10° of
#                      the uninterrupted run's (of the jumps relocalised).
# Environment: DATASETS="intel fr079" (default: intel aces fr079 csail).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
BUILD=${1:-build}
OUT=${2:-$BUILD/localize_bench}
U=$BUILD/apps/urbanslam/urbanslam
D=../shared/data/freiburg_slam_benchmark
HERE=bench/localize
mkdir -p "$OUT"
declare -A LOG=([intel]=intel [aces]=aces [fr079]=fr079 [csail]=mit-csail)
declare -A REL=([intel]=intel [aces]=aces [fr079]=fr079 [csail]=mit-csail)
printf "%-7s %6s %8s %8s %8s %8s %8s %8s %8s %6s %7s %9s %8s %8s %8s %7s %7s\n" dataset rel_n rel_m_loc rel_m_onl rel_m_full rel_deg_loc \
  rel_deg_onl rel_deg_full tracked reloc fix_s fix_err_m rtf rtf_onl rtf_lost jumps jump_s
for ds in ${DATASETS:-intel aces fr079 csail}; do
  W=$OUT/$ds
  mkdir -p "$W"
  src=$D/raw_logs/${LOG[$ds]}.clf.gz
  $HERE/split_half.sh "$src" "$W"
  [ -f "$W/full/stats.json" ] || "$U" run --quiet --ini ini/$ds.ini --out "$W/full" "$src"
  "$U" run --quiet --ini ini/$ds.ini --out "$W/map" "$W/first.clf"
  initial=$(python3 $HERE/last_pose.py "$W/map/trajectory_scans.tum")
  "$U" localize --quiet --map "$W/map" --initial "$initial" --out "$W/loc" "$W/second.clf"
  "$U" localize --quiet --no-smoothing --map "$W/map" --initial "$initial" --out "$W/loc_fast" "$W/second.clf"
  # The online poses as a folder eval reads.
  rm -rf "$W/loc_online" && mkdir -p "$W/loc_online"
  cp "$W/loc/stats.json" "$W/loc_online/"
  cp "$W/loc/trajectory_online.tum" "$W/loc_online/trajectory_scans.tum"
  cp "$W/loc/trajectory_online.tum" "$W/loc_online/trajectory_odometry.tum"
  "$U" localize --quiet --map "$W/map" --out "$W/start_lost" "$W/second.clf"
  python3 $HERE/kidnap.py "$U" "$W/map" "$W/second.clf" "$W/loc/localization.csv" "$W/jumps" > /dev/null 2>&1
  python3 $HERE/relations_within.py "$D/relations/${REL[$ds]}.relations" "$W/loc/trajectory_scans.tum" 1.0 > "$W/relations_tracked"
  "$U" eval "$W/loc" --relations "$W/relations_tracked" --time-offset 0 --max-gap 1 --json > "$W/eval_loc.json"
  "$U" eval "$W/loc_online" --relations "$W/relations_tracked" --time-offset 0 --max-gap 1 --json > "$W/eval_online.json"
  "$U" eval "$W/full" --relations "$W/relations_tracked" --time-offset 0 --max-gap 1 --json > "$W/eval_full.json"
  python3 $HERE/row.py "$ds" "$W"
done
