"""The relations whose two times both fall within a TUM trajectory, between poses at most
MAX_GAP seconds apart (the localizer's tracked stretches).

    relations_within.py RELATIONS TUM MAX_GAP > subset
"""
import bisect
import sys

rel_path, tum_path, max_gap = sys.argv[1], sys.argv[2], float(sys.argv[3])
times = sorted(float(l.split()[0]) for l in open(tum_path) if l.strip() and not l.startswith("#"))


def covered(t):
    i = bisect.bisect_left(times, t)
    if i < len(times) and times[i] == t:
        return True
    return 0 < i < len(times) and times[i] - times[i - 1] <= max_gap


for line in open(rel_path):
    f = line.split()
    if len(f) >= 2 and covered(float(f[0])) and covered(float(f[1])):
        sys.stdout.write(line)
