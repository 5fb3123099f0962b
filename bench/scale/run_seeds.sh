#!/usr/bin/env bash
# One drive through several cities of the same settings and different seeds: what a change to
# the pipeline does to the map and its closures, judged over cities rather than on one. A single
# 12 km drive's ATE moves by tens of per cent between two builds that differ only in rounding
# (which closures a keyframe gets decides the rest of the drive); its false closures and the
# opposite views' along-track bias are what a change has to hold on every city.
#
#   bench/scale/run_seeds.sh [BUILD_DIR] [OUT_DIR]     # about 2 min per city and core
#
# Environment: SEEDS="1 2 3" (city seeds), AREA_KM2=1, ROUTE_KM=12 (the city and the drive, from
# ini/city-1km2.ini), PIPELINE_INI (default ini/default.ini), JOBS=2 (drives at once).
# Per city OUT_DIR/seedN/ holds the run's outputs, seedN-truth/ the simulation's truth,
# seedN.eval.json `urbanslam eval`, seedN.closures.txt `closure_errors.py`. Prints one row per
# city: keyframes, ATE, map p95, closures accepted and false, revisits of 50 m closed, the
# opposite views' closures with their median along-track error and those over 0.5 m, and the CPU
# time of the run; then the medians (ATE, map p95, CPU) and sums (the counts).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
BUILD=${1:-build}
OUT=${2:-$BUILD/seeds_eval}
U=$BUILD/apps/urbanslam/urbanslam
B=$BUILD/bench/scale/scale_bench
SEEDS=(${SEEDS:-1 2 3})
JOBS=${JOBS:-2}
mkdir -p "$OUT"

drive() {
  local s=$1 name=seed$1
  sed -e "s/^seed .*/seed = $s/" -e "s/^area_km2 .*/area_km2 = ${AREA_KM2:-1}/" \
      -e "s/^route_length_km .*/route_length_km = ${ROUTE_KM:-12}/" ini/city-1km2.ini > "$OUT/$name.ini"
  "$U" simulate --quiet --no-rawlog --ini "$OUT/$name.ini" --out "$OUT/$name-truth" > /dev/null
  "$B" --city "$OUT/$name.ini" --ini "${PIPELINE_INI:-ini/default.ini}" --out "$OUT/$name" > "$OUT/$name.json"
  "$U" eval "$OUT/$name" --truth "$OUT/$name-truth" --json > "$OUT/$name.eval.json"
  python3 bench/scale/closure_errors.py "$OUT/$name" "$OUT/$name-truth" > "$OUT/$name.closures.txt"
}

# At most JOBS drives at once, each waited for by name: a drive that fails stops the table
# with its seed named, whichever batch it was in.
pids=() names=()
finish() {
  wait "${pids[0]}" || { echo "run_seeds.sh: the drive of seed ${names[0]} failed (its outputs in $OUT)" >&2; exit 2; }
  pids=("${pids[@]:1}") names=("${names[@]:1}")
}
for s in "${SEEDS[@]}"; do
  drive "$s" &
  pids+=($!) names+=("$s")
  if [ "${#pids[@]}" -ge "$JOBS" ]; then finish; fi
done
while [ "${#pids[@]}" -gt 0 ]; do finish; done

python3 - "$OUT" "${SEEDS[@]}" <<'PY'
import json, os, statistics, sys
out, seeds = sys.argv[1], sys.argv[2:]
print("%-6s %9s %7s %8s %7s %6s %8s %9s %15s %9s %7s" % ("seed", "keyframes", "ate_m", "map_p95", "loops", "false", "revisits",
      "opposite", "opp_along_p50_m", "opp>0.5m", "cpu_s"))
rows = []
for s in seeds:
    name = os.path.join(out, "seed" + s)
    r, e = json.load(open(name + ".json")), json.load(open(name + ".eval.json"))
    opp = next(l.split() for l in open(name + ".closures.txt") if l.startswith("opposite"))
    opp_n = int(opp[1])
    along, over = ("%+.4f" % float(opp[3]), int(opp[8])) if opp_n else ("-", 0)
    rv = e["revisits_50m"]
    row = dict(ate=e["ate_rmse_m"], p95=e["map"]["p95_m"], loops=e["loops_accepted"], false=e["loops_false"],
               closed=rv["closed"], revisits=rv["revisits"], opp=opp_n, over=over, cpu=r["cpu_s"])
    rows.append(row)
    print("%-6s %9d %7.4f %8.4f %7d %6d %8s %9d %15s %9d %7.1f" % (s, r["keyframes"], row["ate"], row["p95"], row["loops"], row["false"],
          "%d/%d" % (row["closed"], row["revisits"]), opp_n, along, over, row["cpu"]))
med = lambda k: statistics.median(x[k] for x in rows)
tot = lambda k: sum(x[k] for x in rows)
print("%-6s %9s %7.4f %8.4f %7d %6d %8s %9d %15s %9d %7.1f" % ("all", "", med("ate"), med("p95"), tot("loops"), tot("false"),
      "%d/%d" % (tot("closed"), tot("revisits")), tot("opp"), "", tot("over"), med("cpu")))
PY
