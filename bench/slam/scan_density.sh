#!/usr/bin/env bash
# How much the relation metric depends on how many of the log's scans there are, on FR079 (the one
# log with relations whose corrected log keeps every scan: 4791). Intel's corrected log, the only
# Intel log here, keeps 910 of the raw log's 13631 scans (1 in 15), and Cartographer's Table II
# figure comes from the raw log. Two measurements, each for keeping 1 scan in k:
#   same poses  urbanslam's own scan poses of the full run, every k-th kept, the gaps bridged
#               with the odometry exactly as `run` bridges them (forward from the earlier scan,
#               backward from the later one, blended by time): the effect of density alone;
#   rerun       `urbanslam run` on the log with the other scans relabelled RLASER, which the ini
#               does not use (the reader still sees them, so the corrected log's odometry
#               re-anchoring at each scan is read as before): what the system makes of it.
#
#   bench/slam/scan_density.sh [BUILD_DIR] [OUT_DIR]
# OUT_DIR must hold run_datasets.sh's and relation_breakdown.sh's output (the full FR079 run and
# its dead-reckoning run are reused); ~2 minutes more.
set -euo pipefail
source "$(dirname "$0")/paths.sh" "$@"
[[ -x $U ]] || { echo "missing $U (build first)" >&2; exit 2; }
LOG=$D/corrected_logs/freiburg-079-corrected.log.gz
REL=$D/relations/fr079.relations
run=$OUT/fr079/urbanslam
dr=$OUT/fr079/dead-reckoning/run
for f in "$run/trajectory_scans.tum" "$dr/trajectory_odometry.tum" "$OUT/fr079/urbanslam.eval.json"; do
  [[ -f $f ]] || { echo "missing $f (run run_datasets.sh, then relation_breakdown.sh)" >&2; exit 2; }
done
off=$(python3 -c "import json; print(json.load(open('$OUT/fr079/urbanslam.eval.json'))['relations']['time_offset_s'])")
KS=(1 2 3 5 10 15)

# Relation error (Kümmerle, as eval computes it) of the run's scan poses thinned to every k-th.
same_poses() {  # scans.tum odometry.tum relations offset k
  python3 - "$@" <<'PY'
import bisect, math, sys
scans, odom, relf, off, k = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]), int(sys.argv[5])
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
def pose(t):
    i = bisect.bisect_right(st, t) - 1
    if i < 0 or i + 1 >= len(st): return None
    o = at(ot, op, t)
    return lerp(compose(sp[i], between(so[i], o)), compose(sp[i + 1], between(so[i + 1], o)),
                (t - st[i]) / (st[i + 1] - st[i]))
errors = []
for l in open(relf):
    v = l.split()
    if len(v) < 8: continue
    p, q = pose(float(v[0]) - off), pose(float(v[1]) - off)  # off: added to run times
    if p is None or q is None: continue
    d = between(p, q); e = (float(v[2]), float(v[3]), float(v[7]))
    c, s = math.cos(d[2] - e[2]), math.sin(d[2] - e[2])
    errors.append(math.hypot(d[0] - (c * e[0] - s * e[1]), d[1] - (s * e[0] + c * e[1])))
print(len(st), len(errors), f"{sum(errors) / len(errors):.4f}")
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
echo "FR079, keeping 1 scan in k (Intel's corrected log: 1 in 15 of the raw log's)"
echo " k  scans  relations  same_poses_m  rerun_m  rerun_ate_m  rerun_loops"
for k in "${KS[@]}"; do
  read -r n used same < <(same_poses "$run/trajectory_scans.tum" "$dr/trajectory_odometry.tum" "$REL" "$off" "$k")
  if [[ $k == 1 ]]; then
    j=$OUT/fr079/urbanslam.eval.json  # the full run itself
  else
    d=$OUT/fr079/density/k$k
    mkdir -p "$d"
    thin_log "$LOG" "$d/log.gz" "$k"
    $U run --quiet --ini ini/fr079.ini --out "$d/run" "$d/log.gz"
    j=$d/eval.json
    $U eval "$d/run" --relations "$REL" --time-offset "$off" --reference "$LOG" --json > "$j"
  fi
  python3 - "$k" "$n" "$used" "$same" "$j" <<'PY'
import json, sys
k, n, used, same, ev = sys.argv[1:6]
j = json.load(open(ev)); r = j['relations']
ate = j.get('ate_rmse_m'); loops = j.get('loops_accepted')
print(f"{int(k):2d} {int(n):6d} {int(used):10d} {float(same):13.4f} {r['abs_trans_mean_m']:8.4f} "
      f"{(f'{ate:12.3f}' if ate is not None else '           -')} {(f'{loops:12d}' if loops is not None else '           -')}")
PY
done
