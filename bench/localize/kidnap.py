#!/usr/bin/env python3
"""Kidnapping: the vehicle tracked in a map, then carried elsewhere without its odometry knowing.

For each of --count jumps, a CARMEN log is spliced from the second half of a benchmark log: the
--before seconds up to a time T1, then the --after seconds from a later time T2 (at least --gap s
later and --min-jump-m away, both places tracked by the uninterrupted localization), the second
piece's timestamps moved back to follow T1 and its odometry moved to continue from T1's (the
wheels felt nothing). `urbanslam localize --initial` tracks the spliced log; the jump's
relocalisation time is the log time from T1 to the first tracked pose within --tolerance-m and
--tolerance-deg of the uninterrupted run's pose of the same scan (its localization.csv, same map
frame); a jump not relocalised within the --after seconds counts as not relocalised. Writes
OUT_DIR/summary.json (jumps, relocalised, within_3s, the median relocalisation time of those
relocalised, the median time until the pose was declared lost, and each jump).

  kidnap.py URBANSLAM MAP SECOND.clf REFERENCE_LOCALIZATION.csv OUT_DIR [options]
"""
import argparse
import bisect
import csv
import json
import math
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "slam"))
from pose2 import between, compose, wrap  # noqa: E402


def fmt(v):
    return f"{v:.6f}"


class Message:
    """One CARMEN line: its fields, its ipc timestamp and where its poses are."""

    def __init__(self, line):
        self.f = line.split()
        tag = self.f[0]
        if tag == "ODOM":
            self.t_idx, self.poses = 7, [1]
        elif tag == "FLASER":
            n = int(self.f[1])
            self.t_idx, self.poses = n + 8, [n + 2, n + 5]
        else:
            raise ValueError(tag)
        self.t = float(self.f[self.t_idx])

    def odometry(self):
        return self.pose(self.poses[-1] if self.f[0] == "ODOM" else self.poses[1])

    def pose(self, i):
        return tuple(float(self.f[i + k]) for k in range(3))

    def moved(self, shift_s, transform):
        f = list(self.f)
        f[self.t_idx] = fmt(self.t + shift_s)
        f[-1] = fmt(float(f[-1]) + shift_s)  # logger timestamp
        for i in self.poses:
            p = compose(transform, self.pose(i))
            f[i], f[i + 1], f[i + 2] = fmt(p[0]), fmt(p[1]), fmt(wrap(p[2]))
        return " ".join(f)


def read_log(path):
    header, messages = [], []
    with open(path) as fh:
        for line in fh:
            tag = line.split(" ", 1)[0].strip()
            if tag in ("ODOM", "FLASER"):
                messages.append(Message(line))
            elif line.startswith("#") or tag == "PARAM":
                header.append(line.rstrip("\n"))
    return header, messages


def read_reference(path):
    rows = []
    with open(path) as fh:
        for r in csv.DictReader(fh):
            rows.append((float(r["time"]), float(r["x"]), float(r["y"]), float(r["phi"]), r["state"] == "tracking"))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("urbanslam")
    ap.add_argument("map")
    ap.add_argument("log")
    ap.add_argument("reference")
    ap.add_argument("out")
    ap.add_argument("--count", type=int, default=5)
    ap.add_argument("--before", type=float, default=10.0)
    ap.add_argument("--after", type=float, default=20.0)
    ap.add_argument("--gap", type=float, default=30.0)
    ap.add_argument("--min-jump-m", type=float, default=5.0)
    ap.add_argument("--tolerance-m", type=float, default=0.5)
    ap.add_argument("--tolerance-deg", type=float, default=10.0)
    a = ap.parse_args()

    header, msgs = read_log(a.log)
    ref = read_reference(a.reference)
    ref_t = [r[0] for r in ref]
    tracked = [r for r in ref if r[4]]

    def ref_at(t):
        i = bisect.bisect_left(ref_t, t - 1e-4)
        return ref[i] if i < len(ref) and abs(ref[i][0] - t) < 1e-3 else None

    t_first, t_last = msgs[0].t, msgs[-1].t
    # The jumps' starts spread evenly over the tracked scans with enough log on both sides.
    starts = [r for r in tracked if r[0] >= t_first + a.before and r[0] + a.gap + a.after <= t_last]
    jumps = []
    for k in range(a.count):
        if not starts:
            break
        s = starts[(2 * k + 1) * len(starts) // (2 * a.count)]
        for r in tracked:
            if r[0] >= s[0] + a.gap and r[0] + a.after <= t_last and math.hypot(r[1] - s[1], r[2] - s[2]) >= a.min_jump_m:
                jumps.append((s, r))
                break

    os.makedirs(a.out, exist_ok=True)
    results = []
    for k, (s, d) in enumerate(jumps):
        t1, t2 = s[0], d[0]
        before = [m for m in msgs if t1 - a.before <= m.t < t1]
        after = [m for m in msgs if t2 <= m.t <= t2 + a.after]
        # The odometry: ODOM lines, or the laser lines' own fields in logs without them.
        kind = "ODOM" if any(m.f[0] == "ODOM" for m in msgs) else "FLASER"
        o1 = next(m for m in reversed(before) if m.f[0] == kind).odometry()
        o2 = next(m for m in after if m.f[0] == kind).odometry()
        transform = compose(o1, between(o2, (0.0, 0.0, 0.0)))  # o1 ⊕ ⊖o2: takes o2 to o1
        log = os.path.join(a.out, f"jump{k}.clf")
        with open(log, "w") as fh:
            fh.write("\n".join(header) + "\n")
            for m in before:
                fh.write(" ".join(m.f) + "\n")
            for m in after:
                fh.write(m.moved(t1 - t2, transform) + "\n")
        first = next(r for r in ref if r[0] >= before[0].t)
        out = os.path.join(a.out, f"jump{k}")
        subprocess.run([a.urbanslam, "localize", "--quiet", "--map", a.map, "--initial", f"{first[1]},{first[2]},{first[3]}",
                        "--out", out, log], check=True)
        reloc, lost = math.inf, math.inf
        with open(os.path.join(out, "localization.csv")) as fh:
            for r in csv.DictReader(fh):
                t = float(r["time"])
                if t < t1:
                    continue
                if r["state"] != "tracking":
                    lost = min(lost, t - t1)
                    continue
                truth = ref_at(t + t2 - t1)
                if truth is None or not truth[4]:
                    continue
                dxy = math.hypot(float(r["x"]) - truth[1], float(r["y"]) - truth[2])
                dphi = abs(wrap(float(r["phi"]) - truth[3]))
                if dxy <= a.tolerance_m and math.degrees(dphi) <= a.tolerance_deg:
                    reloc = t - t1
                    break
        results.append((t1, t2, reloc, lost))
        print(f"jump {k}: {t1:.2f} -> {t2:.2f} ({math.hypot(d[1] - s[1], d[2] - s[2]):.1f} m): lost after {lost:.2f} s, "
              f"relocalised after {reloc:.2f} s", file=sys.stderr)

    found = [r[2] for r in results if math.isfinite(r[2])]
    lost = [r[3] for r in results if math.isfinite(r[3])]
    summary = {
        "jumps": len(results),
        "relocalised": len(found),
        "within_3s": sum(1 for r in found if r <= 3.0),
        "relocalised_s_median": statistics.median(found) if found else None,
        "lost_s_median": statistics.median(lost) if lost else None,
        "list": [{"t1": r[0], "t2": r[1], "relocalised_s": r[2] if math.isfinite(r[2]) else None,
                  "lost_s": r[3] if math.isfinite(r[3]) else None} for r in results],
    }
    with open(os.path.join(a.out, "summary.json"), "w") as fh:
        json.dump(summary, fh, indent=1)
    print(json.dumps({k: v for k, v in summary.items() if k != "list"}))


if __name__ == "__main__":
    main()
