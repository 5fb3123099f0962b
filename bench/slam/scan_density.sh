#!/usr/bin/env bash
# How much the relation metric depends on how many of the log's scans there are, on FR079's raw
# log (4934 scans). The Freiburg corrected logs keep fewer scans than the raw ones (Intel's: 910
# of 13631, 1 in 15), and Cartographer's Table II figures come from the raw logs. Two
# measurements, each for keeping 1 scan in k:
#   same poses  urbanslam's own scan poses of the full run, every k-th kept, the gaps bridged
#               with the odometry exactly as `run` bridges them (forward from the earlier scan,
#               backward from the later one, blended by time) at every odometry time, scored
#               by `urbanslam eval`: the effect of density alone;
#   rerun       `urbanslam run` on the log with the other scans relabelled RLASER, which the ini
#               does not use (the odometry is untouched): what the system makes of it, scored
#               three ways: rerun_m, eval's main figure, on its nodes bridged along its
#               trajectory at odometry times (as same_poses bridges them); rerun_lin_m on its
#               nodes interpolated linearly at the relation times (Cartographer's interpolation:
#               with nodes seconds apart it cuts the turns, and the full run's own poses at one
#               scan in 15 score about 0.146 m so); rerun_odo_m on its trajectory at odometry
#               times itself; ATE against run_datasets.sh's reference (the corrected log's poses
#               at the raw log's times).
#
#   bench/slam/scan_density.sh [BUILD_DIR] [OUT_DIR]
# OUT_DIR must hold run_datasets.sh's and relation_breakdown.sh's output (the full FR079 run and
# its dead-reckoning run are reused); ~2 minutes more.
set -euo pipefail
source "$(dirname "$0")/paths.sh" "$@"
[[ -x $U ]] || { echo "missing $U (build first)" >&2; exit 2; }
LOG=$D/raw_logs/fr079.clf.gz
REL=$D/relations/fr079.relations
run=$OUT/fr079/urbanslam
dr=$OUT/fr079/dead-reckoning/run
REF=$OUT/fr079/reference.tum
for f in "$run/trajectory_scans.tum" "$dr/trajectory_odometry.tum" "$OUT/fr079/urbanslam.eval.json" "$REF"; do
  [[ -f $f ]] || { echo "missing $f (run run_datasets.sh, then relation_breakdown.sh)" >&2; exit 2; }
done
off=0  # the raw log is in the relations' time base
KS=(1 2 3 5 10 15)

# A run folder holding the run's scan poses thinned to every k-th, bridged by the odometry at
# every odometry time between them (for `urbanslam eval`); prints the number of scans kept.
same_poses() {  # scans.tum odometry.tum k out_dir
  python3 - "$@" <<'PY'
import bisect, math, os, sys
scans, odom, k, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
def tum(path):
    t, p = [], []
    for l in open(path):
        if l.startswith('#') or not l.strip(): continue
        v = [float(x) for x in l.split()]
        t.append(v[0]); p.append((v[1], v[2], 2 * math.atan2(v[6], v[7])))
    return t, p
wrap = lambda a: math.atan2(math.sin(a), math.cos(a))
def compose(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2])
def between(a, b):
    c, s = math.cos(a[2]), math.sin(a[2]); dx, dy = b[0] - a[0], b[1] - a[1]
    return (c * dx + s * dy, -s * dx + c * dy, wrap(b[2] - a[2]))
def lerp(p, q, f):
    return (p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1]), p[2] + f * wrap(q[2] - p[2]))
def at(t_, p_, t):  # linear interpolation in a time-sorted trajectory
    i = min(max(bisect.bisect_left(t_, t), 1), len(t_) - 1)
    f = (t - t_[i - 1]) / (t_[i] - t_[i - 1]) if t_[i] > t_[i - 1] else 0.0
    return lerp(p_[i - 1], p_[i], min(max(f, 0.0), 1.0))
st, sp = tum(scans); ot, op = tum(odom)
st, sp = st[::k], sp[::k]
so = [at(ot, op, t) for t in st]
def pose(t):  # forward from the scan before, backward from the one after, blended by time
    i = min(bisect.bisect_right(st, t) - 1, len(st) - 2)
    o = at(ot, op, t)
    return lerp(compose(sp[i], between(so[i], o)), compose(sp[i + 1], between(so[i + 1], o)),
                (t - st[i]) / (st[i + 1] - st[i]))
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, 'trajectory_odometry.tum'), 'w') as f:
    f.write('# timestamp x y z qx qy qz qw\n')
    for t in sorted(set(st) | {t for t in ot if st[0] <= t <= st[-1]}):
        x, y, th = pose(t)
        f.write(f"{t:.6f} {x:.6f} {y:.6f} 0 0 0 {math.sin(th / 2):.9f} {math.cos(th / 2):.9f}\n")
print(len(st))
PY
}

# The log with all but every k-th FLASER line relabelled RLASER.
thin_log() {  # in out k
  python3 - "$@" <<'PY'
import gzip, sys
src, dst, k = sys.argv[1], sys.argv[2], int(sys.argv[3])
n = 0
with gzip.open(src, 'rt') as i, gzip.open(dst, 'wt') as o:
    for line in i:
        if line.startswith('FLASER '):
            if n % k: line = 'RLASER ' + line[7:]
            n += 1
        o.write(line)
PY
}

mkdir -p "$OUT/fr079/density"
echo "FR079 raw log, keeping 1 scan in k (Intel's corrected log: 1 in 15 of the raw log's)"
echo " k  scans  relations  same_poses_m  rerun_m  rerun_lin_m  rerun_odo_m  rerun_ate_m  rerun_loops"
for k in "${KS[@]}"; do
  sp=$OUT/fr079/density/same$k
  n=$(same_poses "$run/trajectory_scans.tum" "$dr/trajectory_odometry.tum" "$k" "$sp")
  $U eval "$sp" --relations "$REL" --time-offset "$off" --json > "$sp/eval.json"
  if [[ $k == 1 ]]; then
    j=$OUT/fr079/urbanslam.eval.json  # the full run itself
  else
    d=$OUT/fr079/density/k$k
    mkdir -p "$d"
    thin_log "$LOG" "$d/log.gz" "$k"
    $U run --quiet --ini ini/fr079.ini --out "$d/run" "$d/log.gz"
    j=$d/eval.json
    $U eval "$d/run" --relations "$REL" --time-offset "$off" --reference "$REF" --json > "$j"
  fi
  python3 - "$k" "$n" "$sp/eval.json" "$j" <<'PY'
import json, sys
k, n, same_ev, ev = sys.argv[1:5]
s = json.load(open(same_ev))['relations']; used, same = s['used'], s['abs_trans_mean_m']
j = json.load(open(ev)); r = j['relations']; ro = j.get('relations_odometry', r); rl = j.get('relations_linear', r)
ate = j.get('ate_rmse_m'); loops = j.get('loops_accepted')
print(f"{int(k):2d} {int(n):6d} {int(used):10d} {float(same):13.4f} {r['abs_trans_mean_m']:8.4f} {rl['abs_trans_mean_m']:12.4f} "
      f"{ro['abs_trans_mean_m']:12.4f} "
      f"{(f'{ate:12.3f}' if ate is not None else '           -')} {(f'{loops:12d}' if loops is not None else '           -')}")
PY
done
