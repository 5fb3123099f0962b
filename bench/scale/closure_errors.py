#!/usr/bin/env python3
# The accepted loop closures of a run on a simulated city against the simulator's truth, split by
# the two views' headings: same direction (within 90 degrees) and opposite (a front 180-degree
# laser sees a street from its two ends). Per set: the closures, the along-track error (measured
# minus true forward offset, in the earlier keyframe's frame: negative = the views put too close
# together), the position error's median, 95th percentile and maximum, and how many are off by
# more than 0.3 and 0.5 m (`urbanslam eval` counts a closure false beyond 0.5 m or 5 degrees).
# Then what the innovation gate saw of them: the median Mahalanobis^2 of the closures within
# 0.1 m along the track and of those 0.25 m or more off (the gate refuses above its threshold,
# 11.34 at the default 0.99).
#
#   bench/scale/closure_errors.py RUN_DIR TRUTH_DIR
#
# RUN_DIR: a run's outputs (loop_closures.csv); TRUTH_DIR: `urbanslam simulate --no-rawlog` of
# the same city (truth.tum).
import bisect, csv, math, statistics, sys

run, truth = sys.argv[1], sys.argv[2]
rows = [l.split() for l in open(f'{truth}/truth.tum') if not l.startswith('#')]
times = [float(r[0]) for r in rows]


def pose(t):
    i = min(bisect.bisect_left(times, t - 1e-4), len(rows) - 1)
    r = rows[i]
    return float(r[1]), float(r[2]), 2 * math.atan2(float(r[6]), float(r[7]))


def relative(a, b):
    dx, dy = b[0] - a[0], b[1] - a[1]
    c, s = math.cos(a[2]), math.sin(a[2])
    return c * dx + s * dy, -s * dx + c * dy


closures = [r for r in csv.DictReader(open(f'{run}/loop_closures.csv')) if r['accepted'] == '1' and r['bearing_only'] == '0']
print('%-9s %8s %14s %16s %9s %9s %9s %7s %7s' % ('views', 'closures', 'along_mean_m', 'along_median_m', 'median_m', 'p95_m',
                                                    'max_m', '>0.3_m', '>0.5_m'))
innovation = {}
for name, opposite in (('same', False), ('opposite', True)):
    along, error = [], []
    innovation[name] = ([], [])
    for r in closures:
        if (abs(float(r['phi'])) > math.pi / 2) != opposite:
            continue
        t = relative(pose(float(r['from_time'])), pose(float(r['to_time'])))
        dx, dy = float(r['x']) - t[0], float(r['y']) - t[1]
        along.append(dx)
        error.append(math.hypot(dx, dy))
        if abs(dx) < 0.1:
            innovation[name][0].append(float(r['mahalanobis2']))
        elif abs(dx) >= 0.25:
            innovation[name][1].append(float(r['mahalanobis2']))
    if not error:
        print('%-9s %8d' % (name, 0))
        continue
    error.sort()
    print('%-9s %8d %+14.4f %+16.4f %9.4f %9.3f %9.3f %7d %7d' % (name, len(error), statistics.mean(along), statistics.median(along),
          statistics.median(error), error[int(0.95 * (len(error) - 1))], error[-1], sum(e > 0.3 for e in error),
          sum(e > 0.5 for e in error)))

print()
print('%-9s %21s %16s %22s %16s' % ('views', 'along<0.1m_closures', 'mahalanobis2_p50', 'along>=0.25m_closures', 'mahalanobis2_p50'))
for name, (good, bad) in innovation.items():
    median = lambda v: '%16.3f' % statistics.median(v) if v else '%16s' % '-'
    print('%-9s %21d %s %22d %s' % (name, len(good), median(good), len(bad), median(bad)))
