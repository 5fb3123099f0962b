"""The last pose of a TUM trajectory as x,y,phi (for localize --initial)."""
import math
import sys

last = [l.split() for l in open(sys.argv[1]) if l.strip() and not l.startswith("#")][-1]
x, y, qz, qw = float(last[1]), float(last[2]), float(last[6]), float(last[7])
print(f"{x:.6f},{y:.6f},{2 * math.atan2(qz, qw):.6f}")
