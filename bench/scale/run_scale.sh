#!/usr/bin/env bash
# The pipeline at growing scale: simulated cities of 1, 10 and 100 km2 streamed from the
# simulator (no file), and the real raw logs, each with ini/default.ini.
#
#   bench/scale/run_scale.sh [BUILD_DIR] [OUT_DIR]
#
# Environment: CITIES="1 10 100" (km2), ROUTE_KM="3 10 30" (drive length per city),
# LOGS="intel aces fr079 csail" (raw Freiburg logs, needs ../shared/data; "" for none),
# PIPELINE_INI (the cities' pipeline configuration; default ini/default.ini), CHECKPOINT_EVERY=N
# (each run saves itself every N keyframes to OUT_DIR/NAME.checkpoint/; the same command run again
# after an interruption continues each run from its checkpoint).
# Per run: OUT_DIR/NAME/ holds the run's outputs, steps.csv and step_time.png (step time against
# the map's size) and progress.csv (CPU time, RSS, the heap in use, closures, full recoveries, factorisations and the filter's poses every 10,000
# keyframes; while the run goes it is OUT_DIR/NAME.progress.csv, so a run stopped early still
# tells); the cities are scored against their truth (simulate --no-rawlog writes it).
# Prints one table: keyframes, the front end's step p50/p99/max and p99 per decade of map size,
# global SLAM's latency (closure -> corrected map, p50/p99) and most keyframes waiting for it,
# peak RSS, real-time factor (wall clock, and on one core: CPU time of both threads), ATE, map
# accuracy (p95), closures accepted/false, the share of revisited scans closed (recall) and the
# revisits of at least 50 m of path that a closure joined, of all such revisits (eval's
# revisits_50m).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
BUILD=${1:-build}
OUT=${2:-$BUILD/scale_eval}
U=$BUILD/apps/urbanslam/urbanslam
B=$BUILD/bench/scale/scale_bench
CITIES=(${CITIES-1 10 100})
ROUTES=(${ROUTE_KM-3 10 30})
LOGS=${LOGS-intel aces fr079 csail}
D=../shared/data/freiburg_slam_benchmark/raw_logs
mkdir -p "$OUT"

# scale_bench's checkpoint arguments for run NAME: none, or every CHECKPOINT_EVERY keyframes,
# continuing from the run's checkpoint when an interrupted earlier call left one.
checkpointing() {
  [ -n "${CHECKPOINT_EVERY:-}" ] || return 0
  echo "--checkpoint-every $CHECKPOINT_EVERY"
  [ -f "$OUT/$1.checkpoint/checkpoint.ini" ] && echo "--continue"
  return 0
}

rows=()
for i in "${!CITIES[@]}"; do
  a=${CITIES[$i]} km=${ROUTES[$i]} name=city-${CITIES[$i]}km2
  sed -e "s/^area_km2 .*/area_km2 = $a/" -e "s/^route_length_km .*/route_length_km = $km/" ini/city-1km2.ini > "$OUT/$name.ini"
  "$U" simulate --quiet --no-rawlog --ini "$OUT/$name.ini" --out "$OUT/$name-truth" > /dev/null
  "$B" --city "$OUT/$name.ini" --ini "${PIPELINE_INI:-ini/default.ini}" --out "$OUT/$name" $(checkpointing "$name") > "$OUT/$name.json"
  "$U" eval "$OUT/$name" --truth "$OUT/$name-truth" --json > "$OUT/$name.eval.json"
  rows+=("$name")
done
declare -A FILE=([intel]=intel [aces]=aces [fr079]=fr079 [csail]=mit-csail)
for log in $LOGS; do
  f=$D/${FILE[$log]:-$log}.clf.gz
  [ -f "$f" ] || { echo "run_scale.sh: $f not found, $log skipped" >&2; continue; }
  "$B" --log "$f" --ini "ini/$log.ini" --out "$OUT/$log" $(checkpointing "$log") > "$OUT/$log.json"
  rows+=("$log")
done

python3 - "$OUT" "${rows[@]}" <<'PY'
import json, os, sys
out, names = sys.argv[1], sys.argv[2:]
print("%-14s %9s %7s %7s %7s %28s %9s %9s %7s %7s %6s %7s %7s %7s %6s %6s %6s %8s" % ("run", "keyframes", "p50_ms", "p99_ms", "max_ms",
      "p99_ms by keyframes 1e2/3/4/5/6", "lat_p50_s", "lat_p99_s", "backlog", "rss_mb", "rtf", "rtf_1cpu", "ate_m", "map_p95",
      "loops", "false", "recall", "revisits"))
for n in names:
    r = json.load(open(os.path.join(out, n + ".json")))
    t, c = r["timing"], r["counts"]
    dec = t.get("step_ms_p99_by_keyframes", {})
    by = "/".join("%.0f" % dec["1e%d" % k] if "1e%d" % k in dec else "-" for k in range(2, 7))
    e = {}
    p = os.path.join(out, n + ".eval.json")
    if os.path.exists(p): e = json.load(open(p))
    f = lambda v, fmt: fmt % v if v is not None else "-"
    rv = e.get("revisits_50m")
    revisits = "%d/%d" % (rv["closed"], rv["revisits"]) if rv else "-"
    print("%-14s %9d %7.1f %7.1f %7.1f %28s %9.1f %9.1f %7d %7.0f %6.1f %7.1f %7s %7s %6d %6s %6s %8s" % (n, r["keyframes"], t["step_ms_p50"],
          t["step_ms_p99"], t["step_ms_max"], by, t["global_latency_ms_p50"] / 1e3, t["global_latency_ms_p99"] / 1e3,
          t["global_backlog_max"], t["peak_rss_mb"], t["real_time_factor"], r["real_time_factor_one_core"], f(e.get("ate_rmse_m"), "%.2f"),
          f(e.get("map", {}).get("p95_m"), "%.2f"), c["loop_closures_accepted"], f(e.get("loops_false"), "%d"),
          f(e.get("loops_recall", {}).get("recall"), "%.2f"), revisits))
PY
