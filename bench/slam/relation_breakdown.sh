#!/usr/bin/env bash
# Where the relation error comes from, for the raw logs with relations (Intel, ACES, FR079, CSAIL):
# each relation by where its two times fall among the scans urbanslam placed (eval's by_scans, of
# the trajectory at every odometry reading: the relations_odometry block, or relations where eval
# has no such block), for urbanslam and for dead reckoning (the same ini with scan matching and
# loop closing off) on the same classes:
#   at      both ends at a scan (within 2 ms);
#   inside  both ends inside one interval between two consecutive scans: the run knows only the
#           odometry there;
#   other   the rest.
# share = the class's error sum over all relations, so the three shares add up to rel_m. The raw
# logs are in the relations' time base (time offset 0).
#
#   bench/slam/relation_breakdown.sh [BUILD_DIR] [OUT_DIR]
# OUT_DIR must hold run_datasets.sh's output (its urbanslam runs are reused); a few seconds more.
set -euo pipefail
source "$(dirname "$0")/paths.sh" "$@"
[[ -x $U ]] || { echo "missing $U (build first)" >&2; exit 2; }

# The dataset's ini with [local] scan_matching and [loop_closure] enabled set to false (keys the
# ini leaves to the defaults are added).
dead_reckoning_ini() {  # in out
  python3 - "$@" <<'PY'
import re, sys
src, dst = sys.argv[1:3]
off = {('local', 'scan_matching'), ('loop_closure', 'enabled')}
sec, out, heads = None, [], {}
for line in open(src):
    m = re.match(r'\s*\[(\w+)\]', line)
    if m:
        sec = m.group(1); heads.setdefault(sec, len(out))
    m = re.match(r'(\s*)(\w+)(\s*=\s*)(\S*)(.*)', line)
    if m and (sec, m.group(2)) in off:
        line = f"{m.group(1)}{m.group(2)}{m.group(3)}false{m.group(5)}\n"
        off.discard((sec, m.group(2)))
    out.append(line)
for sec, key in sorted(off, key=lambda k: -heads.get(k[0], -1)):  # from the last section up
    if sec in heads:
        out.insert(heads[sec] + 1, f"{key} = false\n")
    else:
        out.append(f"\n[{sec}]\n{key} = false\n")
open(dst, 'w').write(''.join(out))
PY
}

row() {  # dataset system eval.json
  python3 - "$@" <<'PY'
import json, sys
name, system, ev = sys.argv[1:4]
j = json.load(open(ev)); r = j.get('relations_odometry', j['relations']); b = r['by_scans']
cells = ''.join(f"{b[k]['n']:6d} {b[k]['abs_trans_mean_m']:7.4f} {b[k]['share_m']:7.4f}  " for k in ('at_scans', 'one_interval', 'other'))
print(f"{name:8s} {system:16s} {cells}{r['abs_trans_mean_m']:7.4f}")
PY
}

echo "                          ------- at -------  ----- inside -----  ------ other -----"
echo "dataset  system                n  mean_m share_m       n  mean_m share_m       n  mean_m share_m    rel_m"
for spec in "intel $D/raw_logs/intel.clf.gz ini/intel.ini intel.relations" \
            "aces $D/raw_logs/aces.clf.gz ini/aces.ini aces.relations" \
            "fr079 $D/raw_logs/fr079.clf.gz ini/fr079.ini fr079.relations" \
            "csail $D/raw_logs/mit-csail.clf.gz ini/csail.ini mit-csail.relations"; do
  read -r name log ini rel <<<"$spec"
  run=$OUT/$name/urbanslam
  [[ -f $run/trajectory_scans.tum ]] || { echo "$run: no trajectory_scans.tum (run run_datasets.sh first)" >&2; exit 2; }
  $U eval "$run" --relations "$D/relations/$rel" --time-offset 0 --json > "$OUT/$name/breakdown.urbanslam.json"
  row "$name" urbanslam "$OUT/$name/breakdown.urbanslam.json"
  dr=$OUT/$name/dead-reckoning
  mkdir -p "$dr"
  dead_reckoning_ini "$ini" "$dr/dr.ini"
  $U run --quiet --ini "$dr/dr.ini" --out "$dr/run" "$log"
  # The same scans as the urbanslam run's.
  $U eval "$dr/run" --relations "$D/relations/$rel" --time-offset 0 --scans "$run/trajectory_scans.tum" --json > "$dr/eval.json"
  row "$name" dead-reckoning "$dr/eval.json"
done
