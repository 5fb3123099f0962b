#!/usr/bin/env bash
# The SLAM evaluation of issue 7, reproducible: every dataset ini in ini/ run by `urbanslam run`,
# evaluated by `urbanslam eval`, next to MRPT's own `icp-slam` (the installed peer) on the same
# log in the same session.
#
#   bench/slam/run_datasets.sh [BUILD_DIR] [OUT_DIR]      (needs ../shared/data; ~5 minutes)
#
# Columns (one row per dataset and system):
#   rel_m / rel_deg  Kümmerle relation metric (mean absolute translational / rotational error, as
#                    Cartographer computes it) where a relations file exists, over rel_n relations;
#   ate_m            ATE RMSE against the log's reference (corrected-log poses; GPS for Victoria Park;
#                    CSAIL runs on the gfs log, and its reference is the corrected log's poses
#                    paired with the gfs scans by index: both hold the same 406 scans);
#   loops / false    loop closures accepted / false against the reference (urbanslam only);
#   fav_run          of the false ones, those whose two keyframe scans favour the run: PL-ICP
#                    started at the reference's relative pose ends at the run's measurement
#                    (`eval`'s weighing; details per closure in urbanslam.eval.json);
#   wall_s / rtf     wall-clock time of the process and the real-time factor (log duration / wall).
# Rows:
#   urbanslam       the trajectory at every odometry reading (what `run` writes);
#   urbanslam@scan  the keyframe trajectory alone, interpolated linearly between scans exactly as
#                   icp-slam's is (eval --max-gap 10: the corrected logs keep one scan every few
#                   seconds), so the two systems are compared on equal terms;
#   icp-slam        MRPT 2.5 icp-slam, icp-slam_demo_classic.ini (headless), one pose per scan.
set -euo pipefail
source "$(dirname "$0")/paths.sh" "$@"
VP=../shared/data/victoria_park/victoria_park_ascii.zip
[[ -x $U ]] || { echo "missing $U (build first)" >&2; exit 2; }
[[ -d $D ]] || { echo "missing $D (../shared/data)" >&2; exit 2; }
command -v icp-slam >/dev/null || { echo "icp-slam not installed (Debian package mrpt-apps)" >&2; exit 2; }
mkdir -p "$OUT"

# CSAIL's reference: the corrected log's FLASER poses at the gfs log's scan times (same scans, in
# the same order; the corrected log's own timestamps have 6 significant digits).
csail_reference() {  # gfs corrected out.tum
  python3 - "$@" <<'PY'
import gzip, math, sys
gfs, corrected, out = sys.argv[1:4]
times = [l.split()[-1] for l in gzip.open(gfs, 'rt') if l.startswith('LASER_READING ')]
poses = []
for l in gzip.open(corrected, 'rt'):
    f = l.split()
    if f and f[0] == 'FLASER':
        n = int(f[1]); poses.append([float(v) for v in f[n + 2:n + 5]])
assert len(times) == len(poses), (len(times), len(poses))
with open(out, 'w') as o:
    o.write('# timestamp x y z qx qy qz qw\n')
    for t, (x, y, th) in zip(times, poses):
        o.write(f"{t} {x} {y} 0 0 0 {math.sin(th / 2):.9f} {math.cos(th / 2):.9f}\n")
PY
}
mkdir -p "$OUT/csail"
csail_reference $D/gfs/mit-csail.corrected.gfs.gz $D/corrected_logs/csail-corrected.log.gz "$OUT/csail/reference.tum"

# name log ini relations(optional, "-": none) reference(optional; default: the log)
datasets=(
  "intel rawlogs/intel.rawlog ini/intel.ini $D/relations/intel.relations"
  "fr079 $D/corrected_logs/freiburg-079-corrected.log.gz ini/fr079.ini $D/relations/fr079.relations"
  "aces $D/corrected_logs/aces-corrected.log.gz ini/aces.ini"
  "csail $D/gfs/mit-csail.corrected.gfs.gz ini/csail.ini $D/relations/mit-csail.relations $OUT/csail/reference.tum"
  "campus $D/corrected_logs/freiburg-campus-corrected.log.gz ini/freiburg-campus.ini"
  "victoria-park $VP ini/victoria-park.ini"
)

now() { date +%s.%N; }
row() {  # system dataset evaljson wall duration
  python3 - "$@" <<'PY'
import json, sys
system, name, ev, wall, dur = sys.argv[1:6]
j = json.load(open(ev)); r = j.get('relations', {})
# Closures exist (loop_closures.csv) only in urbanslam's own run folder.
loops, false = (j.get('loops_accepted'), j.get('loops_false')) if system == 'urbanslam' else (None, None)
# False closures whose two scans, aligned from the reference's relative pose, end at the run's.
fav = j.get('loops_false_scans_favour_run', 0 if false == 0 else None) if system == 'urbanslam' else None
f = lambda v, fmt: (fmt % v) if v is not None else '-'
ate = j.get('ate_rmse_m') if j.get('matched', 0) > 0 else None
print(f"{name:14s} {system:15s} {f(r.get('used'), '%5d'):>5s} {f(r.get('abs_trans_mean_m'), '%8.4f'):>8s} {f(r.get('abs_rot_mean_deg'), '%7.3f'):>7s} "
      f"{f(ate, '%7.3f'):>7s} {f(loops, '%5d'):>5s} {f(false, '%5d'):>5s} {f(fav, '%7d'):>7s} {float(wall):8.2f} {float(dur) / float(wall):8.1f}")
PY
}
printf "%-14s %-15s %5s %8s %7s %7s %5s %5s %7s %8s %8s\n" dataset system rel_n rel_m rel_deg ate_m loops false fav_run wall_s rtf
for d in "${datasets[@]}"; do
  read -r name log ini rel ref <<<"$d"
  [[ -e $log ]] || { echo "$name: $log absent, skipped" >&2; continue; }
  o=$OUT/$name
  R=(); [[ -n ${rel:-} && $rel != - ]] && R=(--relations "$rel")
  ref=${ref:-$log}
  # urbanslam
  t0=$(now); $U run --quiet --ini "$ini" --out "$o/urbanslam" "$log" > /dev/null; t1=$(now)
  dur=$(python3 -c "import json; s=json.load(open('$o/urbanslam/stats.json')); print(s['timing']['log_duration_s'])")
  $U eval "$o/urbanslam" "${R[@]}" --reference "$ref" --json > "$o/urbanslam.eval.json"
  row urbanslam "$name" "$o/urbanslam.eval.json" "$(python3 -c "print($t1 - $t0)")" "$dur"
  # urbanslam at scan rate (keyframes only)
  mkdir -p "$o/urbanslam-scan"
  cp "$o/urbanslam/trajectory_keyframes.tum" "$o/urbanslam-scan/trajectory_odometry.tum"
  [[ -f $o/urbanslam/reference.tum ]] && cp "$o/urbanslam/reference.tum" "$o/urbanslam-scan/"
  $U eval "$o/urbanslam-scan" "${R[@]}" --max-gap 10 --reference "$ref" --json > "$o/urbanslam-scan.eval.json"
  row urbanslam@scan "$name" "$o/urbanslam-scan.eval.json" "$(python3 -c "print($t1 - $t0)")" "$dur"
  # icp-slam on the same log, as an action/sensory-frame rawlog
  p=$o/icp-slam; mkdir -p "$p"
  $U convert "$log" "$p/log.rawlog" --layout frames --quiet > /dev/null
  sed -e 's/^SHOW_PROGRESS_3D_REAL_TIME=1/SHOW_PROGRESS_3D_REAL_TIME=0/' -e 's/^SAVE_3D_SCENE=1/SAVE_3D_SCENE=0/' \
      -e 's/^LOG_FREQUENCY=50/LOG_FREQUENCY=1000000/' -e "s#^logOutput_dir=.*#logOutput_dir=$p/log#" \
      /usr/share/mrpt/config_files/icp-slam/icp-slam_demo_classic.ini > "$p/icp-slam.ini"
  t0=$(now); icp-slam "$p/icp-slam.ini" "$p/log.rawlog" </dev/null > "$p/icp-slam.out" 2>&1 || { echo "$name: icp-slam failed, see $p/icp-slam.out" >&2; continue; }; t1=$(now)
  # icp-slam logs one pose per step ("step x y phi") without times: step k is the k-th sensory
  # frame with a scan, whose time rawlog-edit lists.
  rawlog-edit --list-timestamps -i "$p/log.rawlog" --text-file-output "$p/timestamps.txt" -q > /dev/null 2>&1
  python3 - "$p" <<'PY'
import math, sys
p = sys.argv[1]
times = []
for l in open(p + '/timestamps.txt'):
    v = l.split()
    if len(v) >= 3 and v[2].endswith('CObservation2DRangeScan') and (not times or float(v[0]) != times[-1]):
        times.append(float(v[0]))
with open(p + '/trajectory_odometry.tum', 'w') as f:
    f.write('# timestamp x y z qx qy qz qw\n')
    for l in open(p + '/log/log_estimated_path.txt'):
        k, x, y, phi = l.split()[:4]; k = int(k)
        if k < len(times):
            phi = float(phi)
            f.write(f"{times[k]:.6f} {x} {y} 0 0 0 {math.sin(phi / 2):.9f} {math.cos(phi / 2):.9f}\n")
PY
  [[ -f $o/urbanslam/reference.tum ]] && cp "$o/urbanslam/reference.tum" "$p/"
  $U eval "$p" "${R[@]}" --max-gap 10 --reference "$ref" --json > "$o/icp-slam.eval.json"
  row icp-slam "$name" "$o/icp-slam.eval.json" "$(python3 -c "print($t1 - $t0)")" "$dur"
done
