#!/usr/bin/env python3
# Offline experiment (not part of the library): how well the two scans of a pair themselves,
# aligned, tell a same-side revisit from another place, on logs no model was trained on. The
# score of a pair is the best overlap of its two scans over a grid of rigid motions (every 3
# degrees within +-90, every 0.2 m within +-1 m: the whole range a same-side revisit within 1 m
# can take): the share of the second scan's returns within 30 m that fall on or next to a cell
# of the first's (0.2 m cells), over the larger of the two counts. No feature, no learning, and
# the relative pose searched: evidence of the strongest kind one pair of 180-degree scans holds,
# so detection at 1 % false alarm with it bounds what a classifier on one scan each can reach.
#
# Pairs as `urbanslam eval-laser-loop` draws them by default: positives within 1 m with at least
# 10 m of path between them, kept when the headings differ by at most 90 degrees (same side);
# negatives more than 3 m apart, 20000 per log drawn at random (seed 1). The false-alarm
# threshold is pooled over the logs, as the table's held-out rows pool them.
#
#   D=../shared/data/freiburg_slam_benchmark/corrected_logs
#   for f in fhw edmonton orebro infinite-corridor; do
#     build/apps/urbanslam/urbanslam eval-laser-loop share/laser_loop/default.model $D/$f-corrected.log.gz \
#       --min-travel 0 --quiet --out /tmp/ll/feat-$f; done
#   bench/laser_loop/alignment_bound_experiment.py /tmp/ll fhw,edmonton,orebro,infinite-corridor
import csv, gzip, math, sys

import numpy as np

FEAT_DIR, NAMES = sys.argv[1], sys.argv[2].split(',')
LOGS = '../shared/data/freiburg_slam_benchmark/corrected_logs'
NEGATIVES = int(sys.argv[3]) if len(sys.argv) > 3 else 20000
CELL_M, REACH_M = 0.2, 30.0
HEADINGS = np.radians(np.arange(-90, 91, 3))
OFFSETS = np.arange(-1.0, 1.0 + 1e-9, CELL_M)
CELLS = int(2 * REACH_M / CELL_M) + 1


def load(name):
    """The corrected poses (features.csv, one row per FLASER scan) and the scans' ranges."""
    rows = list(csv.DictReader(open(f'{FEAT_DIR}/feat-{name}/features.csv')))
    poses = np.array([[float(r['x']), float(r['y']), float(r['phi'])] for r in rows])
    scans = []
    for line in gzip.open(f'{LOGS}/{name}-corrected.log.gz', 'rt'):
        if line.startswith('FLASER'):
            t = line.split()
            scans.append(np.array([float(v) for v in t[2:2 + int(t[1])]]))
    assert len(scans) == len(poses), name
    return poses, scans


def points(r):
    """The returns within REACH_M in the sensor frame, the beams spread over the front 180 degrees."""
    n = len(r)
    a = np.radians(np.linspace(-90, 90, n)) if n % 2 == 1 else np.radians(-90 + (np.arange(n) + 0.5) * 180.0 / n)
    ok = (r > 0) & (r < REACH_M)
    return np.c_[r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])]


def occupancy(p):
    """1 on the cells holding a return, 0.5 next to one."""
    g = np.zeros((CELLS + 2, CELLS + 2), np.float32)
    c = np.clip(np.floor((p + REACH_M) / CELL_M).astype(int), 0, CELLS - 1) + 1
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            g[c[:, 1] + dy, c[:, 0] + dx] = np.maximum(g[c[:, 1] + dy, c[:, 0] + dx], 0.5)
    g[c[:, 1], c[:, 0]] = 1
    return g


ROT = np.stack([np.array([[math.cos(t), math.sin(t)], [-math.sin(t), math.cos(t)]]) for t in HEADINGS])
OX, OY = [m.ravel() for m in np.meshgrid(OFFSETS, OFFSETS)]


def overlap(pa, ga, pb):
    if len(pa) < 5 or len(pb) < 5:
        return 0.0
    q = np.einsum('nk,hkj->hnj', pb, ROT)  # every heading: (headings, points, 2)
    x = np.floor((q[:, :, 0, None] + OX + REACH_M) / CELL_M).astype(int) + 1
    y = np.floor((q[:, :, 1, None] + OY + REACH_M) / CELL_M).astype(int) + 1
    inside = (x >= 0) & (x < CELLS + 2) & (y >= 0) & (y < CELLS + 2)
    v = np.where(inside, ga[np.clip(y, 0, CELLS + 1), np.clip(x, 0, CELLS + 1)], 0).sum(axis=1)
    return float(v.max()) / max(len(pa), len(pb))


def pairs(poses, rng):
    step = np.r_[0, np.hypot(np.diff(poses[:, 0]), np.diff(poses[:, 1]))]
    path = np.cumsum(step)
    pos, neg, n = [], [], len(poses)
    for i in range(n):
        d = np.hypot(poses[i + 1:, 0] - poses[i, 0], poses[i + 1:, 1] - poses[i, 1])
        dh = np.abs((poses[i + 1:, 2] - poses[i, 2] + math.pi) % (2 * math.pi) - math.pi)
        pos += [(i, i + 1 + k) for k in np.nonzero((d <= 1.0) & (path[i + 1:] - path[i] >= 10.0) & (dh <= math.pi / 2))[0]]
    while len(neg) < NEGATIVES:
        i, j = rng.integers(0, n, 2)
        if math.hypot(poses[i, 0] - poses[j, 0], poses[i, 1] - poses[j, 1]) > 3.0:
            neg.append((i, j))
    return pos, neg


def detection(ps, ns, fa):
    return float((ps > np.quantile(ns, 1 - fa)).mean()) if fa > 0 else float((ps > ns.max()).mean())


rng = np.random.default_rng(1)
all_p, all_n = [], []
print('%-18s %9s %9s %8s %8s' % ('log', 'positives', 'negatives', '@0 %', '@1 %'))
for name in NAMES:
    poses, scans = load(name)
    pos, neg = pairs(poses, rng)
    pts = [points(r) for r in scans]
    grids = {}
    score = lambda i, j: overlap(pts[i], grids.setdefault(i, occupancy(pts[i])), pts[j])
    ps = np.array([score(i, j) for i, j in pos])
    ns = np.array([score(i, j) for i, j in neg])
    grids.clear()
    print('%-18s %9d %9d %8.1f %8.1f' % (name, len(ps), len(ns), 100 * detection(ps, ns, 0), 100 * detection(ps, ns, 0.01)), flush=True)
    all_p.append(ps)
    all_n.append(ns)
ps, ns = np.concatenate(all_p), np.concatenate(all_n)
print('%-18s %9d %9d %8.1f %8.1f' % ('pooled', len(ps), len(ns), 100 * detection(ps, ns, 0), 100 * detection(ps, ns, 0.01)))
