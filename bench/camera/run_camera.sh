#!/usr/bin/env bash
# Camera + odometry mapping (no laser) against laser + odometry mapping and laser + camera +
# odometry mapping, on the same simulated 1 km² city and drive (ini/city-camera.ini is
# ini/city-1km2.ini seen by a left-looking camera; `both` has the laser and that camera):
# ATE against the simulator's truth, as metres and as a share of the distance driven, the
# closures accepted and how many of them join two views of the same place (true positions
# within 25 m; a laser closure may join scans further apart), how many of the camera's measured
# the full pose (`full_pose`: its features given depth by a neighbouring image; the others
# measured bearing and heading only, so `eval`'s whole-pose check, `eval_false`, does not apply to
# them), the false ones by what each closure measures (`false`: for the camera, accepted image
# closures at another place, or whose full pose is more than 0.5 m or 5° off the truth's, or, for
# bearing and heading only, whose bearing, times the true distance between the cameras, or
# heading is more than 0.5 m or 5° off, the camera mount read from the city ini; for the laser,
# `eval_false`), the closures the camera confirmed (`cam_confirm`: the images nearest a scan
# closure's keyframes measured the same full pose), and the real-time factor. AREA_KM2 and
# ROUTE_KM give every run another city size and drive length (default: the inis' own, 1 km² and
# 3 km).
#
#   bash bench/camera/run_camera.sh [BUILD_DIR] [OUT_DIR]
#   AREA_KM2=10 ROUTE_KM=10 bash bench/camera/run_camera.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
BUILD=${1:-build}
OUT=${2:-out/bench-camera}
U=$BUILD/apps/urbanslam/urbanslam
[[ -x $U ]] || { echo "missing $U (build first)" >&2; exit 2; }
mkdir -p "$OUT"
printf '%-8s %9s %10s %8s %7s %9s %10s %9s %10s %6s %10s %6s\n' run keyframes driven_m ate_m ate_pct accepted same_place full_pose cam_confirm false eval_false rtf
# Laser + camera: ini/city-1km2.ini with ini/city-camera.ini's camera.
awk '/^\[camera\]/{on=1} /^\[odometry\]/{on=0} on' ini/city-camera.ini > "$OUT/camera-section.ini"
awk -v cam="$OUT/camera-section.ini" '/^\[odometry\]/{while ((getline l < cam) > 0) print l} {print}' ini/city-1km2.ini > "$OUT/city-both.ini"
for spec in camera:ini/city-camera.ini laser:ini/city-1km2.ini both:$OUT/city-both.ini; do
  name=${spec%%:*}
  ini=${spec#*:}
  if [[ -n ${AREA_KM2:-} || -n ${ROUTE_KM:-} ]]; then
    sed -e "s/^area_km2 .*/area_km2 = ${AREA_KM2:-1}/" -e "s/^route_length_km .*/route_length_km = ${ROUTE_KM:-3}/" "$ini" > "$OUT/$name.ini"
    ini=$OUT/$name.ini
  fi
  "$U" run --simulate "$ini" --out "$OUT/$name" --quiet --json > "$OUT/$name.json"
  "$U" eval "$OUT/$name" --reference "$OUT/$name/reference.tum" --json > "$OUT/$name.eval.json"
  python3 - "$OUT/$name" "$name" "$ini" <<'PY'
import csv, json, math, sys
run, name, city_ini = sys.argv[1], sys.argv[2], sys.argv[3]
stats = json.load(open(run + '.json'))
ev = json.load(open(run + '.eval.json'))
ref = {}  # time -> (x, y, heading)
for l in open(run + '/reference.tum'):
    if l.startswith('#') or not l.strip(): continue
    v = [float(t) for t in l.split()]; ref[round(v[0], 6)] = (v[1], v[2], 2 * math.atan2(v[6], v[7]))
pts = [ref[k] for k in sorted(ref)]
driven = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(pts, pts[1:]))
# The camera on the vehicle ([camera] x_m, y_m, yaw_deg of the city ini).
mount, section = [0.0, 0.0, 0.0], None
for line in open(city_ini):
    line = line.split(';')[0].strip()
    if line.startswith('['):
        section = line
    elif section == '[camera]' and '=' in line:
        key, value = (t.strip() for t in line.split('=', 1))
        if key in ('x_m', 'y_m', 'yaw_deg'):
            mount[('x_m', 'y_m', 'yaw_deg').index(key)] = float(value) if key != 'yaw_deg' else math.radians(float(value))
def compose(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2])
def inverse(a):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2])
def wrap(x):
    return math.atan2(math.sin(x), math.cos(x))
accepted = same = full_pose = camera_false = cam_confirmed = 0
for r in csv.DictReader(open(run + '/loop_closures.csv')):
    if r['accepted'] != '1': continue
    accepted += 1
    ta, tb = round(float(r['from_time']), 6), round(float(r['to_time']), 6)
    a, b = ref.get(ta), ref.get(tb)
    here = a is not None and b is not None and math.hypot(a[0] - b[0], a[1] - b[1]) < 25
    same += here
    cam_confirmed += r.get('confirmed_by') == 'camera'
    if name != 'camera' or r['detector'] != 'image' or a is None or b is None: continue
    if r['bearing_only'] != '1':
        # The full pose, as eval judges it.
        full_pose += 1
        rel, z = compose(inverse(a), b), (float(r['x']), float(r['y']), float(r['phi']))
        camera_false += not here or math.hypot(rel[0] - z[0], rel[1] - z[1]) > 0.5 or abs(wrap(rel[2] - z[2])) > math.radians(5)
        continue
    # Bearing and heading: the bearing of camera j from camera i and the heading change.
    truth = compose(inverse(compose(a, mount)), compose(b, mount))
    seen = compose(compose(inverse(mount), (float(r['x']), float(r['y']), float(r['phi']))), mount)
    lateral = math.hypot(truth[0], truth[1]) * abs(math.sin(math.atan2(seen[1], seen[0]) - math.atan2(truth[1], truth[0])))
    camera_false += not here or lateral > 0.5 or abs(wrap(seen[2] - truth[2])) > math.radians(5)
false = camera_false if name == 'camera' else ev['loops_false']
print('%-8s %9d %10.0f %8.2f %6.2f%% %9d %10d %9d %10d %6d %10d %6.1f' % (name, stats['counts']['keyframes'], driven, ev['ate_rmse_m'],
      100 * ev['ate_rmse_m'] / driven, accepted, same, full_pose, cam_confirmed, false, ev['loops_false'],
      stats['timing']['real_time_factor']))
PY
done
