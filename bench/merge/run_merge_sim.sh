#!/usr/bin/env bash
# Multi-session benchmark on simulated cities: drives through the same city (another route seed)
# must be joined, at the right place; a drive through another city (another city seed) never.
#
#   bench/merge/run_merge_sim.sh [BUILD_DIR] [OUT_DIR]
#
# The sessions are ini/city-1km2.ini with [city] seed and [route] seed changed and a drive of
# ROUTE_KM (default 2), each mapped with `urbanslam run --simulate` (ini/default.ini) in its own
# frame. The first session (city 1, route 1) is the map; each other session is merged into it
# with `urbanslam merge`. Columns: the session, whether it is the same city, joined (exit 0) or
# not (exit 1, the reason), place searches, fixes agreeing / found, and for a join the error of
# its transform against the truth (the simulator's poses at both sessions' first keyframes).
# Environment: SAME="2 3 4" (route seeds through city 1), OTHER="2 3" (city seeds).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
BUILD=${1:-build}
OUT=${2:-$BUILD/merge_sim_bench}
U=$BUILD/apps/urbanslam/urbanslam
KM=${ROUTE_KM:-2}
mkdir -p "$OUT"
session() {  # name city_seed route_seed
  sed -e "/^\[city\]/,/^\[/ s/^seed .*/seed = $2/" -e "s/^route_length_km .*/route_length_km = $KM/" \
      -e "s/^\[route\]/[route]\nseed = $3/" ini/city-1km2.ini > "$OUT/$1.ini"
  [ -f "$OUT/$1/stats.json" ] || "$U" run --quiet --simulate "$OUT/$1.ini" --out "$OUT/$1"
}
session map 1 1
printf "%-16s %-5s %-7s %8s %9s %9s %9s  %s\n" session same joined searches agreeing err_m err_deg reason
rows() {  # name same
  local rc=0
  "$U" merge --quiet --json "$OUT/map" "$OUT/$1" --out "$OUT/merged-$1" > "$OUT/merge-$1.json" || rc=$?
  python3 - "$OUT" "$1" "$2" "$rc" <<'PY'
import json, math, sys
out, name, same, rc = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
j = json.load(open(f"{out}/merge-{name}.json"))
s = j["sessions"][0] if "sessions" in j else j
def first_truth(run):
    t0 = float(next(l for l in open(f"{out}/{run}/trajectory_keyframes.tum") if l[0] != "#").split()[0])
    best = None
    for l in open(f"{out}/{run}/reference.tum"):
        if l[0] == "#": continue
        f = l.split()
        if best is None or abs(float(f[0]) - t0) < abs(best[0] - t0):
            best = (float(f[0]), float(f[1]), float(f[2]), 2 * math.atan2(float(f[6]), float(f[7])))
    return best[1:]
err_m = err_deg = "-"
if s.get("joined"):
    (ax, ay, ap), (bx, by, bp) = first_truth("map"), first_truth(name)
    # truth of the session's frame in the map's: inverse(A0) * B0
    c, sn = math.cos(ap), math.sin(ap)
    tx, ty, tp = c * (bx - ax) + sn * (by - ay), -sn * (bx - ax) + c * (by - ay), bp - ap
    t = s["transform"]
    err_m = "%.2f" % math.hypot(t["x"] - tx, t["y"] - ty)
    err_deg = "%.2f" % abs(math.degrees(math.atan2(math.sin(t["phi"] - tp), math.cos(t["phi"] - tp))))
print("%-16s %-5s %-7s %8d %9s %9s %9s  %s" % (name, same, "yes" if rc == 0 else "no", s.get("place_searches", 0),
      "%d/%d" % (s.get("fixes_agreeing", 0), s.get("fixes", 0)), err_m, err_deg, s.get("reason", "")))
PY
}
for r in ${SAME-2 3 4}; do session "route$r" 1 "$r"; rows "route$r" yes; done
for c in ${OTHER-2 3}; do session "city$c" "$c" 1; rows "city$c" no; done
