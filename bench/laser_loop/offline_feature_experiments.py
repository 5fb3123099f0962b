#!/usr/bin/env python3
# Offline experiment (not part of the library): an independent plain-Python Algorithm 1 (stumps
# fitted by a cumulative-sum scan, written from the thesis, not from the C++ code) over the
# features that `urbanslam eval-laser-loop ... --out DIR` writes to DIR/features.csv, optionally
# with extra per-scan features computed here from the raw CARMEN ranges:
#   raw   the 20 features as the C++ code computes them
#   log   sign(f)·ln(1+|f|) of those (what --log-features 1 does)
#   hist  range histograms (ICRA 2009 style): fraction of beams per bin, bins of 1, 2.5 and 5 m
#         up to 50 m, each bin a scalar feature with its own stump (85 extra features)
# Modes combine with '+', e.g. 'raw;log;log+hist'. Pair rules as the C++ defaults: training
# positives within 1 m, ≤ 30° heading, ≥ 10 m travel, ≤ 3000 per log, balanced; test positives
# at any heading, 10 negatives per positive, at least 20000 per log. Used to cross-check the C++
# trainer (same detection rates within sampling noise) and to measure the histogram features.
#
#   D=../shared/data/freiburg_slam_benchmark/corrected_logs
#   for f in intel aces csail freiburg-079 freiburg-campus fhw edmonton orebro infinite-corridor; do
#     build/apps/urbanslam/urbanslam eval-laser-loop share/laser_loop/default.model $D/$f-corrected.log.gz \
#       --min-travel 0 --quiet --out /tmp/ll/feat-$f; done
#   bench/laser_loop/offline_feature_experiments.py /tmp/ll intel,aces,csail,freiburg-079 \
#     'freiburg-campus;fhw,edmonton,orebro,infinite-corridor' 'raw;log;log+hist' 60
import csv, gzip, itertools, math, operator, random, sys, time

FEAT_DIR = sys.argv[1]
LOGS = '../shared/data/freiburg_slam_benchmark/corrected_logs'
_cache = {}


def load(name):
    if name not in _cache:
        rows = list(csv.DictReader(open(f'{FEAT_DIR}/feat-{name}/features.csv')))
        keys = [k for k in rows[0] if k not in ('log', 'scan', 'timestamp', 'x', 'y', 'phi')][:20]  # the thesis's twenty
        F = [[float(r[k]) for k in keys] for r in rows]
        P = [(float(r['x']), float(r['y']), float(r['phi'])) for r in rows]
        R = []
        for line in gzip.open(f'{LOGS}/{name}-corrected.log.gz', 'rt'):
            if line.startswith('FLASER'):
                t = line.split()
                R.append([float(v) for v in t[2:2 + int(t[1])]])
        assert len(R) == len(F), name  # features.csv holds every FLASER scan, in order
        _cache[name] = (F, P, R)
    return _cache[name]


def histogram(r, rmax, bins):
    out = []
    for b in bins:
        h = [0] * int(math.ceil(rmax / b))
        for v in r:
            if 0 < v < rmax:
                h[min(len(h) - 1, int(v / b))] += 1
        out += [x / len(r) for x in h]
    return out


def features(name, mode):
    F, P, R = load(name)
    out = []
    for f, r in zip(F, R):
        v = []
        if 'raw' in mode: v += f
        if 'log' in mode: v += [math.copysign(math.log1p(abs(x)), x) for x in f]
        if 'hist' in mode: v += histogram(r, 50.0, (1.0, 2.5, 5.0))
        out.append(v)
    return out, P


def heading_diff(a, b):
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def pairs(P, rng, nneg_per=1.0, maxpos=3000, dpos=1.0, dneg=3.0, travel=10.0, maxh=math.pi, minneg=0):
    path = [0.0]
    for i in range(1, len(P)):
        path.append(path[-1] + math.hypot(P[i][0] - P[i - 1][0], P[i][1] - P[i - 1][1]))
    pos = []
    for i in range(len(P)):
        for j in range(i + 1, len(P)):
            if math.hypot(P[i][0] - P[j][0], P[i][1] - P[j][1]) <= dpos and path[j] - path[i] >= travel:
                h = heading_diff(P[i][2], P[j][2])
                if h <= maxh:
                    pos.append((i, j, 1, h))
    rng.shuffle(pos)
    pos = pos[:maxpos]
    neg, want, tries = set(), max(int(nneg_per * len(pos)), minneg), 0
    while len(neg) < want and tries < 50 * want + 1000:
        tries += 1
        i, j = rng.randrange(len(P)), rng.randrange(len(P))
        if i < j and math.hypot(P[i][0] - P[j][0], P[i][1] - P[j][1]) > dneg:
            neg.add((i, j, 0, -1.0))
    return pos + list(neg)


def adaboost(C, y, T):
    """Algorithm 1: C[k][i] = |Δf_k| of pair i, y[i] in {0, 1}."""
    n, npos = len(y), sum(y)
    w = [1 / (2 * npos) if yi else 1 / (2 * (n - npos)) for yi in y]
    prep = []
    for ck in C:
        o = sorted(range(n), key=ck.__getitem__)
        v = [ck[i] for i in o]
        cuts = [0] + [c for c in range(1, n) if v[c - 1] < v[c]] + [n]  # only between distinct values
        prep.append((o, v, cuts))
    H = []
    for _ in range(T):
        s = sum(w)
        w = [x / s for x in w]
        d = [(-x if yi else x) for x, yi in zip(w, y)]  # error(+1, cut c) = W_pos + Σ_{first c} d
        wp = sum(x for x, yi in zip(w, y) if yi)
        best = (2.0, None)
        for k, (o, v, cuts) in enumerate(prep):
            cum = [0.0] + list(itertools.accumulate(operator.itemgetter(*o)(d)))
            at = operator.itemgetter(*cuts)(cum)
            for e, target, pol in ((wp + min(at), min(at), 1), (1 - (wp + max(at)), max(at), -1)):
                if e < best[0]:
                    c = cuts[at.index(target)]
                    thr = v[0] - 1 if c == 0 else (v[-1] + 1 if c == n else 0.5 * (v[c - 1] + v[c]))
                    best = (e, (k, thr, pol))
        e, (k, thr, pol) = best
        if e >= 0.5:
            break
        beta = max(e, 1e-10) / (1 - max(e, 1e-10))
        for i, c in enumerate(C[k]):
            if (c < thr if pol > 0 else c > thr) == bool(y[i]):
                w[i] *= beta
        H.append((k, thr, pol, math.log(1 / beta)))
    return H


def score(H, F, i, j):
    vote = sum(a for k, thr, pol, a in H if ((abs(F[i][k] - F[j][k]) < thr) if pol > 0 else (abs(F[i][k] - F[j][k]) > thr)))
    return vote / sum(a for *_, a in H)


def detection_at(ps, ns, fa):
    ns = sorted(ns, reverse=True)
    k = int(math.floor(fa * len(ns) + 1e-9))
    bar = ns[k] if k < len(ns) else -math.inf  # match iff score > bar: at most k false alarms
    return sum(s > bar for s in ps) / len(ps)


def main():
    train = sys.argv[2].split(',')
    tests = [t.split(',') for t in sys.argv[3].split(';')]
    modes = sys.argv[4].split(';')
    T = int(sys.argv[5]) if len(sys.argv) > 5 else 60
    for mode in modes:
        t0, rng, C, y = time.time(), random.Random(1), None, []
        for name in train:
            F, P = features(name, mode)
            prs = pairs(P, rng, maxh=math.radians(30))
            c = [[abs(F[i][k] - F[j][k]) for i, j, *_ in prs] for k in range(len(F[0]))]
            C = c if C is None else [a + b for a, b in zip(C, c)]
            y += [p[2] for p in prs]
        H = adaboost(C, y, T)
        for test in tests:
            rng, ps, ns = random.Random(2), [], []
            for name in test:
                F, P = features(name, mode)
                for i, j, label, _ in pairs(P, rng, nneg_per=10, maxpos=20000, minneg=20000):
                    (ps if label else ns).append(score(H, F, i, j))
            print(f'{mode:10s} {"+".join(test):40s} pos {len(ps):5d} neg {len(ns):6d} | det@0% {detection_at(ps, ns, 0):.3f} '
                  f'@0.1% {detection_at(ps, ns, 0.001):.3f} @1% {detection_at(ps, ns, 0.01):.3f}  ({time.time() - t0:.0f} s)', flush=True)


main()
