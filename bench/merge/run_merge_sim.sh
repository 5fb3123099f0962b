#!/usr/bin/env bash
# Multi-session benchmark on simulated cities: drives through the same city (other route seeds)
# that share streets with the map must be joined, at the right place; a drive that shares none,
# or goes through another city (another city seed), never.
#
#   bench/merge/run_merge_sim.sh [BUILD_DIR] [OUT_DIR]
#
# The sessions are ini/city-1km2.ini with [city] seed and [route] seed changed and a drive of
# ROUTE_KM (default 3), each mapped with `urbanslam run --simulate` (ini/default.ini) in its own
# frame. The first session (city 1, route 1) is the map; each other session is merged into it
# with `urbanslam merge`. Columns:
#   session, city       the session and its city seed
#   shared_m            the session's path that the map drove, by the truth: its keyframes within
#                       6 m and 30 degrees of one of the map's (0: it must not be joined)
#   joined              the merge joined it, or kept it apart as a separate map
#   searches            place searches made (one per probe along the session's path)
#   fixes               fixes found (place search or classifier + alignment), of them by the classifier
#   support             the session's scans supporting the join (fixes and their confirmations)
#   err_m, err_deg      for a join, the error of its transform against the truth (the simulator's
#                       poses at both sessions' first keyframes): the prior the session hangs from
#                       when it joins (its fix nearest to the session's start)
#   placed_m            for a join, the farthest any of the session's keyframes lies in the merged
#                       map (pose_graph.g2o, optimised jointly) from its true place in the map's frame
#   merge_s             wall time of `urbanslam merge`
# Environment: SAME="3 4 5" (route seeds through city 1), OTHER="2 3" (city seeds), ROUTE_KM.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
BUILD=${1:-build}
OUT=${2:-$BUILD/merge_sim_bench}
U=$BUILD/apps/urbanslam/urbanslam
KM=${ROUTE_KM:-3}
mkdir -p "$OUT"
session() {  # name city_seed route_seed
  sed -e "/^\[city\]/,/^\[/ s/^seed .*/seed = $2/" -e "s/^route_length_km .*/route_length_km = $KM/" \
      -e "s/^\[route\]/[route]\nseed = $3/" ini/city-1km2.ini > "$OUT/$1.ini"
  [ -f "$OUT/$1/stats.json" ] || "$U" run --quiet --simulate "$OUT/$1.ini" --out "$OUT/$1"
}
session map 1 1
printf "%-8s %4s %8s %-6s %8s %8s %7s %6s %7s %8s %7s\n" session city shared_m joined searches fixes support err_m err_deg placed_m merge_s
rows() {  # name city
  local rc=0 start end
  start=$(date +%s.%N)
  "$U" merge --quiet --json "$OUT/map" "$OUT/$1" --out "$OUT/merged-$1" > "$OUT/merge-$1.json" || rc=$?
  end=$(date +%s.%N)
  python3 - "$OUT" "$1" "$2" "$rc" "$(echo "$end - $start" | bc)" <<'PY'
import bisect, collections, json, math, sys
out, name, city, rc, merge_s = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), float(sys.argv[5])
j = json.load(open(f"{out}/merge-{name}.json"))
s = j["sessions"][0] if "sessions" in j else j
def tum(path):
    rows = []
    for l in open(path):
        if l[0] == "#": continue
        f = l.split()
        rows.append((float(f[0]), float(f[1]), float(f[2]), 2 * math.atan2(float(f[6]), float(f[7]))))
    return rows
def truth_at(ref, t):
    ts = [r[0] for r in ref]
    i = bisect.bisect_left(ts, t)
    return min((ref[k] for k in (i - 1, i) if 0 <= k < len(ref)), key=lambda r: abs(r[0] - t))
def truth_keyframes(run):
    ref = tum(f"{out}/{run}/reference.tum")
    return [truth_at(ref, k[0]) for k in tum(f"{out}/{run}/trajectory_keyframes.tum")]
m, q = truth_keyframes("map"), truth_keyframes(name)
shared = 0.0
if city == "1":
    cells = collections.defaultdict(list)
    for p in m: cells[(int(p[1] // 6), int(p[2] // 6))].append(p)
    for i in range(1, len(q)):
        p = q[i]
        near = (c for dx in (-1, 0, 1) for dy in (-1, 0, 1) for c in cells[(int(p[1] // 6) + dx, int(p[2] // 6) + dy)])
        if any(math.hypot(c[1] - p[1], c[2] - p[2]) < 6 and abs(math.atan2(math.sin(c[3] - p[3]), math.cos(c[3] - p[3]))) < math.radians(30) for c in near):
            shared += math.hypot(p[1] - q[i - 1][1], p[2] - q[i - 1][2])
err_m = err_deg = placed_m = "-"
if s.get("joined"):
    (_, ax, ay, ap), (_, bx, by, bp) = m[0], q[0]
    # The session's keyframes are the merged map's from its first_keyframe on, in their order.
    merged = {}
    for l in open(f"{out}/merged-{name}/pose_graph.g2o"):
        f = l.split()
        if f and f[0] == "VERTEX_SE2": merged[int(f[1])] = (float(f[2]), float(f[3]))
    c0, s0 = math.cos(ap), math.sin(ap)
    far = 0.0
    for k, p in enumerate(q):
        e = merged[s["first_keyframe"] + k]
        tx, ty = c0 * (p[1] - ax) + s0 * (p[2] - ay), -s0 * (p[1] - ax) + c0 * (p[2] - ay)
        far = max(far, math.hypot(e[0] - tx, e[1] - ty))
    placed_m = "%.2f" % far
    # truth of the session's frame in the map's: inverse(A0) * B0
    c, sn = math.cos(ap), math.sin(ap)
    tx, ty, tp = c * (bx - ax) + sn * (by - ay), -sn * (bx - ax) + c * (by - ay), bp - ap
    t = s["transform"]
    err_m = "%.2f" % math.hypot(t["x"] - tx, t["y"] - ty)
    err_deg = "%.2f" % abs(math.degrees(math.atan2(math.sin(t["phi"] - tp), math.cos(t["phi"] - tp))))
print("%-8s %4s %8.0f %-6s %8d %8s %7d %6s %7s %8s %7.1f" % (name, city, shared, "yes" if s.get("joined") else "no", s.get("place_searches", 0),
      "%d/%d" % (s.get("fixes", 0), s.get("fixes_laser", 0)), s.get("scans_agreeing", 0), err_m, err_deg, placed_m, merge_s))
PY
}
for r in ${SAME-3 4 5}; do session "route$r" 1 "$r"; rows "route$r" 1; done
for c in ${OTHER-2 3}; do session "city$c" "$c" 1; rows "city$c" "$c"; done
