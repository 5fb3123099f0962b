#!/usr/bin/env bash
# Kidnappings in simulated cities, relocalised with the scans alone and with the camera's images
# as well (city_kidnap): ini/city-1km2.ini at 0.25 km² with a 3 km drive, seen by the front 180°
# laser and ini/city-camera.ini's left-looking camera, for each seed in SEEDS. One row per city,
# each pair of figures without / with the camera: the uninterrupted second half (scans tracked,
# fixes, fixes more than 0.5 m / 10° from the truth) and the jumps relocalised within 3 s and
# in all, with the median time and the fixes away from the truth.
#
#   bash bench/localize/run_city_kidnap.sh [BUILD_DIR] [OUT_DIR]
#   SEEDS="1 2 3" AREA_KM2=0.25 ROUTE_KM=3 bash bench/localize/run_city_kidnap.sh build OUT
set -euo pipefail
BUILD=${1:-build}
OUT=${2:-out/bench-city-kidnap}
B=$BUILD/bench/localize/city_kidnap
[[ -x $B ]] || { echo "missing $B (build first)" >&2; exit 2; }
mkdir -p "$OUT"
awk '/^\[camera\]/{on=1} /^\[odometry\]/{on=0} on' ini/city-camera.ini > "$OUT/camera-section.ini"
printf '%-5s %6s %9s %7s %7s | %5s %9s %9s %9s %9s\n' seed scans tracked fixes wrong jumps within_3s relocated median_s wrong
for seed in ${SEEDS:-1 2 3}; do
  awk -v cam="$OUT/camera-section.ini" '/^\[odometry\]/{while ((getline l < cam) > 0) print l} {print}' ini/city-1km2.ini |
    sed -e "s/^seed .*/seed = $seed/" -e "s/^area_km2 .*/area_km2 = ${AREA_KM2:-0.25}/" \
        -e "s/^route_length_km .*/route_length_km = ${ROUTE_KM:-3}/" > "$OUT/city-$seed.ini"
  "$B" --city "$OUT/city-$seed.ini" > "$OUT/city-$seed.json" 2> "$OUT/city-$seed.log"
  python3 - "$OUT/city-$seed.json" "$seed" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
ul, uc, l, c = j["uninterrupted"]["laser"], j["uninterrupted"]["laser_camera"], j["laser"], j["laser_camera"]
med = lambda m: "-" if m["relocalised_s_median"] is None else f'{m["relocalised_s_median"]:.1f}'
pair = lambda a, b: f'{a}/{b}'
print(f'{sys.argv[2]:<5} {ul["scans"]:6d} {pair(ul["tracked"], uc["tracked"]):>9} {pair(ul["relocalisations"], uc["relocalisations"]):>7} '
      f'{pair(ul["wrong_fixes"], uc["wrong_fixes"]):>7} | {j["jumps"]:5d} {pair(l["within_3s"], c["within_3s"]):>9} '
      f'{pair(l["relocalised"], c["relocalised"]):>9} {pair(med(l), med(c)):>9} {pair(l["wrong_fixes"], c["wrong_fixes"]):>9}')
PY
done
