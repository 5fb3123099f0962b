#!/usr/bin/env bash
# Camera + odometry mapping (no laser) against laser + odometry mapping, on the same simulated
# 1 km² city and drive (ini/city-camera.ini is ini/city-1km2.ini seen by a left-looking camera):
# ATE against the simulator's truth, as metres and as a share of the distance driven, the
# closures accepted and how many of them join two views of the same place (true positions
# within 25 m: a camera closure measures bearing and heading, so `eval`'s whole-pose check,
# `eval_false`, does not apply to it; a laser closure may join scans further apart), and the
# real-time factor. AREA_KM2 and ROUTE_KM give both runs another city size and drive length
# (default: the inis' own, 1 km² and 3 km).
#
#   bash bench/camera/run_camera.sh [BUILD_DIR] [OUT_DIR]
#   AREA_KM2=10 ROUTE_KM=10 bash bench/camera/run_camera.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
BUILD=${1:-build}
OUT=${2:-out/bench-camera}
U=$BUILD/apps/urbanslam/urbanslam
[[ -x $U ]] || { echo "missing $U (build first)" >&2; exit 2; }
mkdir -p "$OUT"
printf '%-8s %9s %10s %8s %7s %9s %10s %10s %6s\n' run keyframes driven_m ate_m ate_pct accepted same_place eval_false rtf
for spec in camera:ini/city-camera.ini laser:ini/city-1km2.ini; do
  name=${spec%%:*}
  ini=${spec#*:}
  if [[ -n ${AREA_KM2:-} || -n ${ROUTE_KM:-} ]]; then
    sed -e "s/^area_km2 .*/area_km2 = ${AREA_KM2:-1}/" -e "s/^route_length_km .*/route_length_km = ${ROUTE_KM:-3}/" "$ini" > "$OUT/$name.ini"
    ini=$OUT/$name.ini
  fi
  "$U" run --simulate "$ini" --out "$OUT/$name" --quiet --json > "$OUT/$name.json"
  "$U" eval "$OUT/$name" --reference "$OUT/$name/reference.tum" --json > "$OUT/$name.eval.json"
  python3 - "$OUT/$name" "$name" <<'PY'
import csv, json, math, sys
run, name = sys.argv[1], sys.argv[2]
stats = json.load(open(run + '.json'))
ev = json.load(open(run + '.eval.json'))
ref = {}
for l in open(run + '/reference.tum'):
    if l.startswith('#') or not l.strip(): continue
    v = l.split(); ref[round(float(v[0]), 6)] = (float(v[1]), float(v[2]))
pts = [ref[k] for k in sorted(ref)]
driven = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(pts, pts[1:]))
accepted = same = 0
for r in csv.DictReader(open(run + '/loop_closures.csv')):
    if r['accepted'] != '1': continue
    accepted += 1
    a, b = ref.get(round(float(r['from_time']), 6)), ref.get(round(float(r['to_time']), 6))
    same += a is not None and b is not None and math.hypot(a[0] - b[0], a[1] - b[1]) < 25
print('%-8s %9d %10.0f %8.2f %6.2f%% %9d %10d %10d %6.1f' % (name, stats['counts']['keyframes'], driven, ev['ate_rmse_m'],
      100 * ev['ate_rmse_m'] / driven, accepted, same, ev['loops_false'], stats['timing']['real_time_factor']))
PY
done
