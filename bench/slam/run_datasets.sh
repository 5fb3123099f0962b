#!/usr/bin/env bash
# The SLAM benchmark, reproducible: urbanslam and two MRPT peers on the same logs, scored by the
# same `urbanslam eval`.
#
#   bench/slam/run_datasets.sh [BUILD_DIR] [OUT_DIR]
#
# Needs ../shared/data and the Debian package mrpt-apps (icp-slam, rbpf-slam, rawlog-edit). On the
# 2-core development machine the whole run takes about 21 minutes, half of it rbpf-slam on the
# campus (11 minutes, 9 GB of memory); urbanslam alone takes about 3 minutes.
# Environment:
#   DATASETS="intel csail"  only these datasets (names as in the table; default: all)
#   SYSTEMS="urbanslam"     only these systems: urbanslam icp-slam rbpf-slam (default: all)
#   TIME_LIMIT=1800         per-run wall-clock limit [s]; a run over it is killed (row "timeout")
#   RBPF_INI=gridmapping_intel.ini  rbpf-slam config, from /usr/share/mrpt/config_files/rbpf-slam/
#   RBPF_PARTICLES=20       rbpf-slam particle count (the shipped config's)
#   MAX_GAP=S               pass eval --max-gap S for every system (default: eval's own)
#   PEER_NICE=10            nice level of the peers (urbanslam runs at normal priority)
#   PEER_MEM_GB=16          address-space limit of a peer process [GB] (0: none); over it, the
#                           peer fails (bad_alloc) instead of swamping the machine
#
# Datasets (rows grouped by dataset):
#   intel, aces, fr079, csail  the Freiburg benchmark's RAW CARMEN logs (raw_logs/*.clf.gz: every
#                  scan, raw odometry, the relations' own time base, so eval uses --time-offset 0),
#                  scored with relations/*.relations. ATE is against the corrected log's poses,
#                  each put at the time of the same scan in the raw log (every corrected scan is
#                  found in the raw log by its ranges), so loops/false are judged on it too;
#   campus         the Freiburg campus corrected log (no raw log, no relations; ATE against its
#                  corrected poses);
#   victoria-park  the ACFR Victoria Park log (ATE against GPS positions);
#   ual            the MRPT-native UAL campus rawlog with ini/default.ini (no reference: only
#                  wall_s, rtf and urbanslam's accepted closures).
# Systems (rows):
#   urbanslam       `urbanslam run` with the dataset's ini; its relation columns are eval's
#                   "relations" block (the scans it placed, trajectory_scans.tum);
#   urbanslam@odom  eval's "relations_odometry" block (the trajectory at every odometry reading),
#                   printed only when eval writes that block; the other columns are on the row above;
#   icp-slam        MRPT 2.5 icp-slam, icp-slam_demo_classic.ini (headless), one pose per scan;
#   rbpf-slam       MRPT 2.5 rbpf-slam, gridmapping_intel.ini: a GMapping-style RBPF on an
#                   occupancy grid with optimal sampling (PF_algorithm 3), MRPT's config for the
#                   CARMEN Intel log (filter step every 0.5 m / 25 deg, 4 cm grid); headless,
#                   RBPF_PARTICLES particles, seed 1. Its trajectory: the most likely particle's
#                   final path at the filter's steps, carried to every scan by the odometry since
#                   the last step. (With 20 particles, gridmapping_optimal_sampling.ini, 1 m /
#                   40 deg steps and a 7 cm grid, scored 6.64 / 0.535 / 4.18 / 2.32 m on
#                   intel / aces / fr079 / csail, against 5.29 / 0.582 / 1.78 / 1.23 m for this
#                   one.) rbpf-slam needs odometry with every frame, so it fails on Victoria Park.
#   The peers read an action/sensory-frame rawlog written by `urbanslam convert --layout frames`.
#   MRPT pairs each frame with the first action before it and drops any further ones, so for the
#   CARMEN logs the peers get a copy of the log with one odometry reading per scan (the FLASER
#   line's own odometry; for the corrected campus log, the raw odometry chained from its ODOM
#   increments as urbanslam's reader does). Victoria Park has no odometry (speed + steering) and
#   UAL has ~4.6 odometry readings per scan, of which MRPT keeps the first. The increments carry
#   the motion model `urbanslam convert` writes (MRPT's Gaussian model, default parameters).
# Columns:
#   rel_n            relations used (of those inside the run's time span, or within MAX_GAP);
#   rel_m ±sd        absolute translational relation error, mean and std [m] (Kümmerle et al.,
#                    as Cartographer computes it);
#   sq_m2 ±sd        squared translational relation error, mean and std [m²];
#   rot_deg          absolute rotational relation error, mean [deg];
#   ate_m            ATE RMSE against the reference after a rigid 2D alignment;
#   loops / false    loop closures accepted / false against the reference (urbanslam only; on
#                    UAL, accepted from stats.json);
#   wall_s / rtf     wall-clock time of the SLAM process (not the conversion) and the real-time
#                    factor (log duration / wall). The machine is shared and the peers run niced,
#                    so these are indicative;
#   cpu_s / rtf_1cpu CPU time (user + system, every thread) of the SLAM process and the log
#                    duration over it: the real-time factor on one core;
#   status           ok, failed (exit code and the first error line of OUT_DIR/<dataset>/<system>.out),
#                    timeout, or no-eval (the run finished but eval could not score its output).
# The same table, tab-separated with empty cells for "-", is written to OUT_DIR/results.tsv.
set -euo pipefail
source "$(dirname "$0")/paths.sh" "$@"
VP=../shared/data/victoria_park/victoria_park_ascii.zip
UAL=../shared/data/mrpt_rawlogs/ual_dataset_2014_05_23_2dlaser_odo.rawlog
TIME_LIMIT=${TIME_LIMIT:-1800}
RBPF_INI=${RBPF_INI:-gridmapping_intel.ini}
RBPF_PARTICLES=${RBPF_PARTICLES:-20}
PEER_NICE=${PEER_NICE:-10}
PEER_MEM_GB=${PEER_MEM_GB:-16}
SYSTEMS=${SYSTEMS:-urbanslam icp-slam rbpf-slam}
[[ -x $U ]] || { echo "missing $U (build first)" >&2; exit 2; }
[[ -d $D ]] || { echo "missing $D (../shared/data)" >&2; exit 2; }
for tool in icp-slam rbpf-slam rawlog-edit; do
  command -v $tool >/dev/null || { echo "$tool not installed (Debian package mrpt-apps)" >&2; exit 2; }
done
mkdir -p "$OUT"

# name log ini relations reference
#   relations: file or "-"; reference: "corrected:FILE" (a corrected log of the same run, paired
#   with the raw log's scans), "log" (the log itself carries it), or "-".
datasets=(
  "intel $D/raw_logs/intel.clf.gz ini/intel.ini $D/relations/intel.relations corrected:$D/corrected_logs/intel-corrected.log.gz"
  "aces $D/raw_logs/aces.clf.gz ini/aces.ini $D/relations/aces.relations corrected:$D/corrected_logs/aces-corrected.log.gz"
  "fr079 $D/raw_logs/fr079.clf.gz ini/fr079.ini $D/relations/fr079.relations corrected:$D/corrected_logs/freiburg-079-corrected.log.gz"
  "csail $D/raw_logs/mit-csail.clf.gz ini/csail.ini $D/relations/mit-csail.relations corrected:$D/corrected_logs/csail-corrected.log.gz"
  "campus $D/corrected_logs/freiburg-campus-corrected.log.gz ini/freiburg-campus.ini - log"
  "victoria-park $VP ini/victoria-park.ini - log"
  "ual $UAL ini/default.ini - -"
)

# The corrected log's poses at the raw log's times: each corrected FLASER is the raw FLASER with
# the same ranges (the corrected logs keep a subset of the raw scans).
paired_reference() {  # raw.clf.gz corrected.log.gz out.tum
  python3 - "$@" <<'PY'
import gzip, math, sys
raw, corrected, out = sys.argv[1:4]
def scans(path):
    for l in gzip.open(path, 'rt'):
        f = l.split()
        if f and f[0] == 'FLASER':
            n = int(f[1])
            yield tuple(round(float(v), 2) for v in f[2:2 + n]), f[2 + n:]
times = {}
for r, rest in scans(raw):
    times.setdefault(r, []).append(rest[6])
rows, missing = [], 0
for r, rest in scans(corrected):
    t = times.get(r)
    if not t or len(t) != 1:
        missing += 1
        continue
    x, y, th = (float(v) for v in rest[:3])
    rows.append((float(t[0]), f"{t[0]} {x} {y} 0 0 0 {math.sin(th / 2):.9f} {math.cos(th / 2):.9f}\n"))
if missing:
    print(f"{corrected}: {missing} scans not found once in {raw}, left out of the reference", file=sys.stderr)
with open(out, 'w') as o:
    o.write('# timestamp x y z qx qy qz qw\n')
    o.writelines(line for _, line in sorted(rows))
PY
}

# A CARMEN log with one odometry reading per scan, for the peers: ODOM (and NEFF) lines dropped,
# each FLASER carrying the odometry at its time in both pose fields. Raw logs: the FLASER's own
# odometry fields. Corrected logs (NEFF lines): the raw odometry chained from the ODOM
# increments, skipping the anchors (an ODOM right after a FLASER, at its corrected pose).
peer_log() {  # in.log.gz out.log.gz
  python3 - "$@" <<'PY'
import gzip, math, sys
src, dst = sys.argv[1:3]
corrected = any(l.startswith('NEFF') for l in gzip.open(src, 'rt'))
sys.path.insert(0, 'bench/slam')
from pose2 import wrap, compose, between
same = lambda a, b: abs(a[0] - b[0]) < 1e-9 and abs(a[1] - b[1]) < 1e-9 and abs(wrap(a[2] - b[2])) < 1e-9
raw = last = scan_pose = None
prev = None
with gzip.open(src, 'rt') as i, gzip.open(dst, 'wt') as o:
    for line in i:
        f = line.split()
        if not f or f[0].startswith('#'):
            o.write(line); continue
        tag = f[0]
        if tag == 'ODOM':
            p = (float(f[1]), float(f[2]), wrap(float(f[3])))
            if prev == 'FLASER' and scan_pose and same(p, scan_pose) and last is not None:
                last = p  # anchor: a new segment starts at the corrected pose
            else:
                raw = p if raw is None else compose(raw, between(last, p))
                last = p
        elif tag == 'FLASER':
            n = int(f[1])
            scan_pose = (float(f[n + 2]), float(f[n + 3]), wrap(float(f[n + 4])))
            if corrected:
                od = raw or (0.0, 0.0, 0.0)
            else:
                od = (float(f[n + 5]), float(f[n + 6]), float(f[n + 7]))
            pose = ['%.6f' % v for v in od]
            o.write(' '.join(f[:n + 2] + pose + pose + f[n + 8:]) + '\n')
        elif tag != 'NEFF':
            o.write(line)
        prev = tag
PY
}

# Peer output (one pose per processed frame) to TUM: trajectory_odometry.tum, the one trajectory
# of a peer's folder (eval scores a folder without trajectory_scans.tum on it).
icp_tum() {  # peer_dir timestamps.txt
  python3 - "$@" <<'PY'
import math, os, sys
p, stamps = sys.argv[1:3]
# icp-slam logs one pose per step ("step x y phi ...") without times: step k is the k-th
# sensory frame with a scan, whose time rawlog-edit lists.
times = []
for l in open(stamps):
    v = l.split()
    if len(v) >= 3 and v[2].endswith('CObservation2DRangeScan'):
        times.append(float(v[0]))
lines = []
for l in open(os.path.join(p, 'log', 'log_estimated_path.txt')):
    v = l.split()
    if not v or v[0].startswith('%'): continue
    k, x, y, phi = int(v[0]), float(v[1]), float(v[2]), float(v[3])
    if k < len(times):
        lines.append(f"{times[k]:.6f} {x:.6f} {y:.6f} 0 0 0 {math.sin(phi / 2):.9f} {math.cos(phi / 2):.9f}\n")
with open(os.path.join(p, 'trajectory_odometry.tum'), 'w') as f:
    f.write('# timestamp x y z qx qy qz qw\n'); f.writelines(lines)
PY
}

rbpf_tum() {  # peer_dir console_output
  python3 - "$@" <<'PY'
import math, os, re, sys
p, out = sys.argv[1:3]
log = os.path.join(p, 'log')
sys.path.insert(0, 'bench/slam')
from pose2 import wrap, compose, between
def rows(name):
    for l in open(os.path.join(log, name)):
        v = l.split()
        if v and not v[0].startswith('%'): yield v
# Per step: its time and the filter's mean (log_estimated_path: step x y z yaw pitch roll t),
# the odometry (log_odometry_path: step x y z yaw ...).
est = {int(v[0]): (float(v[7]), (float(v[1]), float(v[2]), float(v[4]))) for v in rows('log_estimated_path.txt')}
odo = {int(v[0]): (float(v[1]), float(v[2]), float(v[4])) for v in rows('log_odometry_path.txt')}
# The steps at which the particle filter ran ("New pose=" in the step's console output; step k's
# output ends with "STEP k+1"); the most likely path has the start pose and one pose per run.
pf, step = [], 0
for l in open(out, errors='replace'):
    m = re.search(r'------------- STEP (\d+) -', l)
    if m: step = int(m.group(1))
    elif 'New pose=' in l: pf.append(step)
path = [tuple(float(x) for x in v[:3]) for v in rows('most_likely_path.txt')]
lines = []
if len(path) == len(pf) + 1:
    j = -1
    for k in sorted(est):
        while j + 1 < len(pf) and pf[j + 1] <= k: j += 1
        if j < 0: continue
        s = pf[j]
        x, y, th = compose(path[j + 1], between(odo[s], odo[k]))
        lines.append((est[k][0], x, y, th))
else:  # cannot pair the path with the steps: the filter's running mean instead
    print(f"{p}: {len(path)} path poses for {len(pf)} filter steps; using log_estimated_path", file=sys.stderr)
    lines = [(t, *pose) for t, pose in (est[k] for k in sorted(est))]
with open(os.path.join(p, 'trajectory_odometry.tum'), 'w') as f:
    f.write('# timestamp x y z qx qy qz qw\n')
    for t, x, y, th in lines:
        f.write(f"{t:.6f} {x:.6f} {y:.6f} 0 0 0 {math.sin(th / 2):.9f} {math.cos(th / 2):.9f}\n")
PY
}

# One row of the table (stdout) and of results.tsv.
TSV=$OUT/results.tsv
COLS=(dataset system rel_n rel_m rel_sd sq_m2 sq_sd rot_deg ate_m loops false wall_s rtf cpu_s rtf_1cpu status)
row() {  # dataset system status wall cpu duration eval.json|- block stats.json|-
  python3 - "$TSV" "$@" <<'PY'
import json, os, sys
tsv, name, system, status, wall, cpu, dur, ev, block, stats = sys.argv[1:11]
j = json.load(open(ev)) if ev != '-' and os.path.exists(ev) else {}
r = j.get(block, {})
main = system in ('urbanslam', 'icp-slam', 'rbpf-slam')
ate = j.get('ate_rmse_m') if main and j.get('matched', 0) > 1 else None
loops = false = None
if system == 'urbanslam':
    loops, false = j.get('loops_accepted'), j.get('loops_false')
    if loops is None and stats != '-' and os.path.exists(stats):
        loops = json.load(open(stats)).get('counts', {}).get('loop_closures_accepted')
num = lambda v: float(v) if v not in ('', '-', None) else None
wall, cpu, dur = num(wall), num(cpu), num(dur)
rtf = dur / wall if wall and dur and main and status == 'ok' else None
rtf1 = dur / cpu if cpu and dur and main and status == 'ok' else None
vals = [r.get('used'), r.get('abs_trans_mean_m'), r.get('abs_trans_std_m'), r.get('sqr_trans_mean_m2'),
        r.get('sqr_trans_std_m2'), r.get('abs_rot_mean_deg'), ate, loops, false, wall if main else None, rtf,
        cpu if main else None, rtf1]
fmts = ['%d', '%.4f', '%.4f', '%.5f', '%.5f', '%.3f', '%.3f', '%d', '%d', '%.1f', '%.1f', '%.1f', '%.1f']
cells = [(f % v) if v is not None else '-' for f, v in zip(fmts, vals)]
widths = [6, 8, 7, 9, 8, 8, 8, 6, 6, 8, 7, 7, 8]
print(f"{name:14s} {system:15s} " + ' '.join(c.rjust(w) for c, w in zip(cells, widths)) + f"  {status}")
with open(tsv, 'a') as o:
    o.write('\t'.join([name, system] + [c if c != '-' else '' for c in cells] + [status]) + '\n')
PY
}

now() { date +%s.%N; }
# Runs "$@" under the time limit; sets RC (0 ok, 124 timeout), WALL and CPU (user + system time
# of the process and its children: what one core would need).
timed() {
  local t0 t1
  t0=$(now)
  RC=0
  timeout --kill-after=30 "$TIME_LIMIT" /usr/bin/time -f "%U %S" -o "$OUT/.cpu" "$@" || RC=$?
  t1=$(now)
  WALL=$(python3 -c "print($t1 - $t0)")
  CPU=$(awk 'NF == 2 && $1 ~ /^[0-9.]+$/ { c = $1 + $2 } END { if (c != "") print c; else print "-" }' "$OUT/.cpu" 2>/dev/null || echo -)
}
status_of() {  # exit_code console_output (after timed: WALL)
  case $1 in
    0) echo ok ;;
    124) echo timeout ;;
    137) [[ ${WALL%.*} -ge $TIME_LIMIT ]] && echo timeout || echo "failed (rc 137: killed)" ;;
    *) echo "failed (rc $1: $(awk '/exception ====$/ { getline; sub(/^Message: */, ""); print; exit }
                                  /[Ee]rror/ { print; exit }' "$2" | cut -c1-80))" ;;
  esac
}
want() { [[ " $2 " == *" $1 "* ]]; }
# A peer, niced and with its address space limited.
peer() {
  local limit=unlimited
  [[ $PEER_MEM_GB != 0 ]] && limit=$((PEER_MEM_GB * 1024 * 1024))
  timed bash -c 'ulimit -v "$1"; n=$2; shift 2; exec nice -n "$n" "$@"' peer "$limit" "$PEER_NICE" "$@"
}

(IFS=$'\t'; echo "${COLS[*]}") > "$TSV"
printf "%-14s %-15s %6s %8s %7s %9s %8s %8s %8s %6s %6s %8s %7s %7s %8s  %s\n" dataset system rel_n rel_m ±sd sq_m2 ±sd rot_deg ate_m loops false wall_s rtf cpu_s rtf_1cpu status
# A peer on the dataset's peer rawlog with its ini (FOLDER/NAME.ini), its trajectory made into
# FOLDER/trajectory_odometry.tum by TUM_FN FOLDER TUM_ARG, scored, and its row printed. Uses the
# loop's $o, $name, $dur and $can_eval.
run_peer() {  # name folder tum_fn tum_arg
  local sys=$1 p=$2 tum_fn=$3 tum_arg=$4 st ev=-
  peer "$sys" "$p/$sys.ini" "$o/peer.rawlog" </dev/null > "$o/$sys.out" 2>&1
  st=$(status_of $RC "$o/$sys.out")
  if [[ $RC == 0 ]]; then
    "$tum_fn" "$p" "$tum_arg"
    if evaluate "$p" "$o/$sys.eval.json"; then ev=$o/$sys.eval.json
    elif [[ $can_eval == 1 ]]; then st=no-eval; fi
  fi
  row "$name" "$sys" "$st" "$WALL" "$CPU" "$dur" "$ev" relations -
}

for d in "${datasets[@]}"; do
  read -r name log ini rel refspec <<<"$d"
  [[ -z ${DATASETS:-} ]] || want "$name" "$DATASETS" || continue
  [[ -e $log ]] || { echo "$name: $log absent, skipped" >&2; continue; }
  o=$OUT/$name
  rm -rf "$o"; mkdir -p "$o"
  E=()
  [[ -n ${MAX_GAP:-} ]] && E+=(--max-gap "$MAX_GAP")
  [[ $rel != - ]] && E+=(--relations "$rel")
  case $refspec in
    corrected:*) paired_reference "$log" "${refspec#corrected:}" "$o/reference.tum"
                 E+=(--reference "$o/reference.tum" --time-offset 0) ;;  # raw log: the relations' time base
    log) E+=(--reference "$log") ;;
  esac
  can_eval=0; [[ $rel != - || $refspec != - ]] && can_eval=1
  evaluate() {  # run_dir out.json -> 0 when scored
    [[ $can_eval == 1 && -s $1/trajectory_odometry.tum ]] || return 1
    $U eval "$1" "${E[@]}" --json > "$2" 2> "$2.err" || { echo "$name: eval of $1 failed: $(tail -1 "$2.err")" >&2; return 1; }
  }
  dur=-
  # urbanslam
  if want urbanslam "$SYSTEMS"; then
    timed "$U" run --quiet --ini "$ini" --out "$o/urbanslam" "$log" > "$o/urbanslam.out" 2>&1
    st=$(status_of $RC "$o/urbanslam.out")
    [[ -f $o/urbanslam/stats.json ]] && dur=$(python3 -c "import json; print(json.load(open('$o/urbanslam/stats.json'))['timing']['log_duration_s'])")
    ev=-
    if [[ $RC == 0 ]]; then
      if evaluate "$o/urbanslam" "$o/urbanslam.eval.json"; then ev=$o/urbanslam.eval.json
      elif [[ $can_eval == 1 ]]; then st=no-eval; fi
    fi
    row "$name" urbanslam "$st" "$WALL" "$CPU" "$dur" "$ev" relations "$o/urbanslam/stats.json"
    if [[ $ev != - ]] && python3 -c "import json,sys; sys.exit('relations_odometry' not in json.load(open('$ev')))"; then
      row "$name" urbanslam@odom "$st" "$WALL" "$CPU" "$dur" "$ev" relations_odometry -
    fi
  fi
  want icp-slam "$SYSTEMS" || want rbpf-slam "$SYSTEMS" || continue
  # The peers' input: an action/sensory-frame rawlog, one odometry reading per scan where the
  # log allows it (see the header), and the time of every scan in it.
  case $log in
    *.clf.gz|*.log.gz) peer_log "$log" "$o/peer.log.gz"; src=$o/peer.log.gz ;;
    *) src=$log ;;
  esac
  if ! $U convert "$src" "$o/peer.rawlog" --layout frames --quiet > "$o/convert.out" 2>&1 ||
     ! rawlog-edit --list-timestamps -i "$o/peer.rawlog" --text-file-output "$o/peer.timestamps.txt" -q > /dev/null 2>&1; then
    for s in icp-slam rbpf-slam; do
      want $s "$SYSTEMS" && row "$name" $s "failed (no peer rawlog: $(tail -1 "$o/convert.out" | cut -c1-60))" - - - - relations -
    done
    continue
  fi
  if [[ $dur == - ]]; then  # no urbanslam run: the scans' time span
    dur=$(python3 -c "
t=[float(l.split()[0]) for l in open('$o/peer.timestamps.txt') if len(l.split()) >= 3 and l.split()[2].endswith('CObservation2DRangeScan')]
print(max(t) - min(t))")
  fi
  # icp-slam
  if want icp-slam "$SYSTEMS"; then
    p=$o/icp-slam; mkdir -p "$p"
    sed -e 's/^SHOW_PROGRESS_3D_REAL_TIME=1/SHOW_PROGRESS_3D_REAL_TIME=0/' -e 's/^SAVE_3D_SCENE=1/SAVE_3D_SCENE=0/' \
        -e 's/^LOG_FREQUENCY=50/LOG_FREQUENCY=1000000/' -e "s#^logOutput_dir=.*#logOutput_dir=$p/log#" \
        /usr/share/mrpt/config_files/icp-slam/icp-slam_demo_classic.ini > "$p/icp-slam.ini"
    run_peer icp-slam "$p" icp_tum "$o/peer.timestamps.txt"
  fi
  # rbpf-slam: the first frame has no odometry action (the first reading has no increment), and
  # rbpf-slam needs one with every frame: rawlog_offset=3 skips that pair (MRPT counts objects).
  if want rbpf-slam "$SYSTEMS"; then
    p=$o/rbpf-slam; mkdir -p "$p"
    sed -e 's/^SHOW_PROGRESS_IN_WINDOW=.*/SHOW_PROGRESS_IN_WINDOW=0/' -e 's/^SAVE_3D_SCENE=.*/SAVE_3D_SCENE=0/' \
        -e 's/^SAVE_MAP_IMAGES=.*/SAVE_MAP_IMAGES=0/' -e 's/^LOG_FREQUENCY=[0-9]*/LOG_FREQUENCY=1000000/' \
        -e "s#^logOutput_dir=.*#logOutput_dir=$p/log#" -e 's/^rawlog_offset=.*/rawlog_offset=3\nRANDOM_SEED=1/' \
        -e 's/^verbosity_level *= *DEBUG/verbosity_level = INFO/' -e "s/^sampleSize=[0-9]*/sampleSize=$RBPF_PARTICLES/" \
        "/usr/share/mrpt/config_files/rbpf-slam/$RBPF_INI" > "$p/rbpf-slam.ini"
    run_peer rbpf-slam "$p" rbpf_tum "$o/rbpf-slam.out"
  fi
done
