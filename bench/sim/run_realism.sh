#!/usr/bin/env bash
# The simulator against a real log, and its speed.
#
#   bench/sim/run_realism.sh [BUILD_DIR] [OUT_DIR]
#
# 1. Sensor statistics (bench/sim/sensor_statistics: PL-ICP between keyframes 1 m / 15 deg of
#    odometry apart, the odometry increment's error against it, the match's residual) on
#    FR079's raw log (needs ../shared/data) and on a drive through ini/city-1km2.ini.
# 2. Simulation speed: `urbanslam simulate --json` on the 1 km2 city and on a 100 km2 city with
#    the same 3 km drive and with a 20 km drive (simulated seconds per wall-clock second, laser +
#    odometry, outputs excluded), with the peak memory of the whole command (GNU time).
# Prints one table; the JSON of every step stays in OUT_DIR.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
BUILD=${1:-build}
OUT=${2:-$BUILD/sim_eval}
U=$BUILD/apps/urbanslam/urbanslam
S=$BUILD/bench/sim/sensor_statistics
FR079=../shared/data/freiburg_slam_benchmark/raw_logs/fr079.clf.gz
mkdir -p "$OUT"

"$U" simulate --quiet --json --ini ini/city-1km2.ini --out "$OUT/city-1km2" > "$OUT/simulate-1km2.json" 2> /dev/null
"$S" "$OUT/city-1km2/city.rawlog" > "$OUT/stats-city.json"
if [ -f "$FR079" ]; then "$S" "$FR079" --laser-label FLASER > "$OUT/stats-fr079.json"; fi

# A 100 km2 city: the same ini with the area and the drive enlarged (memory must not grow with
# the area: tiles are built lazily and evicted).
sed -e 's/^area_km2 .*/area_km2 = 100/' -e 's/^route_length_km .*/route_length_km = 20/' ini/city-1km2.ini > "$OUT/city-100km2.ini"
/usr/bin/time -f '%M' -o "$OUT/rss-100km2.txt" "$U" simulate --quiet --json --ini "$OUT/city-100km2.ini" --out "$OUT/city-100km2" \
  > "$OUT/simulate-100km2.json" 2> /dev/null
sed -e 's/^area_km2 .*/area_km2 = 100/' ini/city-1km2.ini > "$OUT/city-100km2-3km.ini"
/usr/bin/time -f '%M' -o "$OUT/rss-100km2-3km.txt" "$U" simulate --quiet --json --ini "$OUT/city-100km2-3km.ini" --out "$OUT/city-100km2-3km" \
  > "$OUT/simulate-100km2-3km.json" 2> /dev/null
/usr/bin/time -f '%M' -o "$OUT/rss-1km2.txt" "$U" simulate --quiet --json --ini ini/city-1km2.ini --out "$OUT/city-1km2" \
  > "$OUT/simulate-1km2.json" 2> /dev/null

python3 - "$OUT" <<'PY'
import json, os, sys
out = sys.argv[1]
def load(name):
    p = os.path.join(out, name)
    return json.load(open(p)) if os.path.exists(p) else None
rows = [("odometry along-track error per m (median |.|)", "odometry_along_track_per_m", 1),
        ("odometry cross-track error per m (median |.|)", "odometry_cross_track_per_m", 1),
        ("odometry heading error going straight [deg/m] (median |.|)", "odometry_heading_deg_per_m_straight", 1),
        ("odometry heading error per radian turned (median |.|)", "odometry_heading_per_rad_turned", 1),
        ("PL-ICP residual between keyframes [m] (median)", "laser_residual_rms_m", 1)]
fr, city = load("stats-fr079.json"), load("stats-city.json")
print("%-62s %10s %10s" % ("statistic", "FR079 raw", "city-1km2"))
for label, key, _ in rows:
    f = "%.4f" % fr[key]["median_abs"] if fr else "-"
    print("%-62s %10s %10.4f" % (label, f, city[key]["median_abs"]))
for label, key in [("beams without a return", "laser_no_return_fraction"), ("median range [m]", "laser_median_range_m")]:
    f = "%.4f" % fr[key] if fr else "-"
    print("%-62s %10s %10.4f" % (label, f, city[key]))
print("%-62s %10s %10s" % ("keyframe pairs (well matched)", "%d (%d)" % (fr["keyframe_pairs"], fr["good_matches"]) if fr else "-",
                           "%d (%d)" % (city["keyframe_pairs"], city["good_matches"])))
print()
print("%-12s %8s %8s %8s %12s %10s %10s %8s" % ("city", "km", "scans", "tiles", "sim_s/wall_s", "sim_wall_s", "total_s", "rss_mb"))
for name in ["1km2", "100km2-3km", "100km2"]:
    j = load("simulate-%s.json" % name)
    rss = int(open(os.path.join(out, "rss-%s.txt" % name)).read().split()[-1]) / 1024
    print("%-12s %8.1f %8d %8d %12.0f %10.2f %10.2f %8.0f" % (name, j["distance_m"] / 1000, j["scans"], j["tiles_built"],
          j["simulated_s_per_wall_s"], j["simulate_wall_s"], j["total_wall_s"], rss))
PY
