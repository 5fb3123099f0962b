#!/usr/bin/env bash
# Multi-session benchmark: each raw Freiburg log cut at its middle laser scan into two sessions
# mapped separately, each in its own frame (`urbanslam run` on each half), then
#   merge  the two maps joined offline (`urbanslam merge FIRST SECOND`), and
#   map    the second half mapped into the first half's map from an unknown start
#          (`urbanslam run --map FIRST second.clf`),
# both scored against the mapping run over the whole log on the log's relations (all of them:
# the two halves and the relations across).
#
#   bench/merge/run_merge.sh [BUILD_DIR] [OUT_DIR]
#
# Needs ../shared/data. Columns (RESULTS.md):
#   rel_m full / merge / map   mean absolute translational relation error [m] (eval --relations,
#                              every relation of the log); rel_deg likewise [deg];
#   joined                     whether merge joined the second map (place searches made, fixes
#                              agreeing of fixes found);
#   join_s                     `run --map`: log time from the second half's first scan to the
#                              keyframe at which it was joined;
#   merge_s                    wall time of `urbanslam merge` (loading both maps, the place
#                              searches, the joint optimisation, the outputs).
# Environment: DATASETS="intel fr079" (default: intel aces fr079 csail).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
BUILD=${1:-build}
OUT=${2:-$BUILD/merge_bench}
U=$BUILD/apps/urbanslam/urbanslam
D=../shared/data/freiburg_slam_benchmark
mkdir -p "$OUT"
declare -A LOG=([intel]=intel [aces]=aces [fr079]=fr079 [csail]=mit-csail)
printf "%-7s %6s %9s %9s %9s %8s %8s %8s %-18s %7s %8s\n" dataset rel_n rel_m_full rel_m_merge rel_m_map rel_deg_f rel_deg_mg rel_deg_mp joined join_s merge_s
for ds in ${DATASETS:-intel aces fr079 csail}; do
  W=$OUT/$ds
  mkdir -p "$W"
  src=$D/raw_logs/${LOG[$ds]}.clf.gz
  rel=$D/relations/${LOG[$ds]}.relations
  bench/localize/split_half.sh "$src" "$W"
  [ -f "$W/full/stats.json" ] || "$U" run --quiet --ini ini/$ds.ini --out "$W/full" "$src"
  "$U" run --quiet --ini ini/$ds.ini --out "$W/first" "$W/first.clf"
  "$U" run --quiet --ini ini/$ds.ini --out "$W/second" "$W/second.clf"
  start=$(date +%s.%N)
  "$U" merge --quiet --json "$W/first" "$W/second" --out "$W/merge" > "$W/merge.json" || true
  end=$(date +%s.%N)
  "$U" run --quiet --json --map "$W/first" --out "$W/map" "$W/second.clf" > "$W/map.json"
  for r in full merge map; do
    if [ -f "$W/$r/stats.json" ]; then "$U" eval "$W/$r" --relations "$rel" --json > "$W/eval_$r.json"; else echo '{}' > "$W/eval_$r.json"; fi
  done
  python3 - "$ds" "$W" "$(echo "$end - $start" | bc)" <<'PY'
import json, sys
ds, w, merge_s = sys.argv[1], sys.argv[2], float(sys.argv[3])
# The second half's first scan time (a FLASER line's timestamp is its third field from the end).
split_t = next(float(l.split()[-3]) for l in open(f"{w}/second.clf") if l.startswith("FLASER"))
def rel(r):
    j = json.load(open(f"{w}/eval_{r}.json")).get("relations")
    return (j["used"], j["abs_trans_mean_m"], j["abs_rot_mean_deg"]) if j else (0, float("nan"), float("nan"))
f, mg, mp = rel("full"), rel("merge"), rel("map")
m = json.load(open(f"{w}/merge.json"))
s = m["sessions"][0] if "sessions" in m else m
joined = "yes" if s.get("joined") else "no"
joined += " (%d, %d/%d)" % (s.get("place_searches", 0), s.get("fixes_agreeing", 0), s.get("fixes", 0))
mapj = json.load(open(f"{w}/map.json"))["sessions"][0]
join_s = "-"
if mapj.get("joined"):
    join_s = "%.1f" % (mapj["joined_at_s"] - split_t)
print("%-7s %6d %9.4f %9.4f %9.4f %8.3f %8.3f %8.3f %-18s %7s %8.1f" % (ds, f[0], f[1], mg[1], mp[1], f[2], mg[2], mp[2], joined, join_s, merge_s))
PY
done
