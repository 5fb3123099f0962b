# Sourced by train_default.sh and run_eval.sh: the laser-loop benchmarks' simulated cities.
#
#   city URBANSLAM DIR SEED FOV
#
# simulates ini/city-1km2.ini with that seed and laser field of view (180 or 360), 4 km² and
# 5 km of driving, into DIR/city-seedSEED-fovFOV (once: an existing rawlog is reused) and prints
# the rawlog's path. Run from the repository root.
city() {
  local u=$1 dir=$2 name=city-seed$3-fov$4
  sed -e "s/^seed .*/seed = $3/" -e "s/^area_km2 .*/area_km2 = 4/" -e "s/^route_length_km .*/route_length_km = 5/" \
    -e "s/^fov_deg .*/fov_deg = $4/" ini/city-1km2.ini > "$dir/$name.ini"
  [ -f "$dir/$name/city.rawlog" ] || "$u" simulate --quiet --ini "$dir/$name.ini" --out "$dir/$name" > /dev/null
  echo "$dir/$name/city.rawlog"
}
