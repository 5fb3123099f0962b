"""One row of the localization benchmark's table from a dataset's folder (run_localize.sh)."""
import bisect
import json
import math
import os
import sys

ds, w = sys.argv[1], sys.argv[2]


def load(p):
    return json.load(open(os.path.join(w, p)))


def tum(p):
    out = []
    for l in open(os.path.join(w, p)):
        if l.strip() and not l.startswith("#"):
            v = [float(x) for x in l.split()]
            out.append((v[0], v[1], v[2], 2 * math.atan2(v[6], v[7])))
    return out


loc, full = load("eval_loc.json")["relations"], load("eval_full.json")["relations"]
onl = load("eval_online.json")["relations"]
s, k, fast = load("loc/stats.json"), load("start_lost/stats.json"), load("loc_fast/stats.json")
j = load("jumps/summary.json")
jump_s = j["relocalised_s_median"] if j["relocalised_s_median"] is not None else float("nan")
fix = k["localization"]["first_fix_s"]
fix_err = float("nan")
kt = tum("start_lost/trajectory_online.tum")  # the first fix as found
ft = tum("full/trajectory_scans.tum")
if kt:
    times = [p[0] for p in ft]
    i = bisect.bisect_left(times, kt[0][0])
    if i < len(ft) and abs(ft[i][0] - kt[0][0]) < 1e-3:
        fix_err = math.hypot(ft[i][1] - kt[0][1], ft[i][2] - kt[0][2])
print(f"{ds:<7} {loc['used']:6d} {loc['abs_trans_mean_m']:8.4f} {onl['abs_trans_mean_m']:8.4f} {full['abs_trans_mean_m']:8.4f} "
      f"{loc['abs_rot_mean_deg']:8.3f} {onl['abs_rot_mean_deg']:8.3f} {full['abs_rot_mean_deg']:8.3f} "
      f"{s['localization']['tracking_fraction']:8.3f} {s['counts']['relocalisations']:6d} "
      f"{fix if fix is not None else float('nan'):7.2f} {fix_err:9.3f} {s['timing']['real_time_factor']:8.1f} "
      f"{fast['timing']['real_time_factor']:8.1f} {k['timing']['real_time_factor']:8.1f} "
      f"{j['relocalised']}/{j['within_3s']}/{j['jumps']:<3} {jump_s:7.2f}")
