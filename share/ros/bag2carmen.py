#!/usr/bin/env python3
"""Convert a ROS 1 bag (sensor_msgs/LaserScan + odometry) into a CARMEN log for `urbanslam run`.

  bag2carmen.py [options] IN.bag OUT.clf
  urbanslam run --ini ini/ros-example.ini --out OUT_DIR OUT.clf

MRPT 2.5's rosbag2rawlog converts no LaserScan nor nav_msgs/Odometry (it reports them as
"unhandled topic"), so bags are converted here, with the standard library only.

What is read (bag format 2.0; chunks uncompressed or bz2 - for lz4 run `rosbag decompress` first):
  --scan-topic (default /scan)   sensor_msgs/LaserScan, stamped by its header
  --odom-topic (default /odom)   nav_msgs/Odometry: x, y, yaw of pose.pose
     or --odom-from-tf           the /tf transforms odom_frame -> base_frame instead
  the laser mount                base_frame -> the scan's frame_id, composed from /tf_static and /tf
                                 (taken as static), or --laser-pose X,Y,YAW when the bag has none
What is written: one ODOM line per odometry reading and one ROBOTLASER1 line per scan (its own
start angle, resolution, maximum range and mount), in the order the bag received them (as
`rosbag play` replays them), each with its header stamp printed to the microsecond. NaN and
infinite ranges become range_max: no-returns, like every range at or beyond it.
"""
import argparse
import bz2
import math
import struct
import sys

# Deserialisation below follows these layouts; a bag whose connection declares another md5sum
# holds a different message, and reading it as these would give garbage.
MD5 = {
    "sensor_msgs/LaserScan": "90c7ef2dc6895d81024acba2ac42f369",
    "nav_msgs/Odometry": "cd5e73d190d741a2f92e81eda573aca7",
    "tf2_msgs/TFMessage": "94810edda583a504dfda3829e70d7eec",
}


class Reader:
    def __init__(self, data):
        self.d, self.p = data, 0

    def take(self, fmt):
        v = struct.unpack_from(fmt, self.d, self.p)
        self.p += struct.calcsize(fmt)
        return v

    def string(self):
        (n,) = self.take("<I")
        s = self.d[self.p:self.p + n].decode("utf-8", "replace")
        self.p += n
        return s

    def header(self):
        _seq, sec, nsec = self.take("<III")
        return (sec, nsec), self.string().lstrip("/")


def yaw_of(qx, qy, qz, qw):
    return math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))


def parse_scan(data):
    r = Reader(data)
    stamp, frame = r.header()
    amin, amax, inc, _ti, _st, rmin, rmax = r.take("<7f")
    (n,) = r.take("<I")
    ranges = r.take(f"<{n}f")
    return {"stamp": stamp, "frame": frame, "angle_min": amin, "increment": inc,
            "range_min": rmin, "range_max": rmax, "ranges": ranges}


def parse_odometry(data):
    r = Reader(data)
    stamp, _frame = r.header()
    r.string()  # child_frame_id
    x, y, _z, qx, qy, qz, qw = r.take("<7d")
    return stamp, (x, y, yaw_of(qx, qy, qz, qw))


def parse_tf(data):
    r = Reader(data)
    (n,) = r.take("<I")
    out = []
    for _ in range(n):
        stamp, parent = r.header()
        child = r.string().lstrip("/")
        out.append((stamp, parent, child, r.take("<7d")))
    return out


# ---- bag format 2.0: records of header fields (name=value) and data

def read_record(buf, pos):
    (hlen,) = struct.unpack_from("<I", buf, pos)
    hdr, p = {}, pos + 4
    while p < pos + 4 + hlen:
        (flen,) = struct.unpack_from("<I", buf, p)
        name, _, value = buf[p + 4:p + 4 + flen].partition(b"=")
        hdr[name.decode()] = value
        p += 4 + flen
    (dlen,) = struct.unpack_from("<I", buf, p)
    return hdr, buf[p + 4:p + 4 + dlen], p + 4 + dlen


def connection_info(data):
    info, p = {}, 0
    while p < len(data):
        (flen,) = struct.unpack_from("<I", data, p)
        name, _, value = data[p + 4:p + 4 + flen].partition(b"=")
        info[name.decode()] = value.decode("utf-8", "replace")
        p += 4 + flen
    return info


def bag_messages(path):
    """Yields (topic, type, md5sum, bag time, data) of every message, in file order; one chunk
    in memory at a time (bags with camera images are gigabytes)."""
    conns = {}

    def records(b, p):
        while p < len(b):
            hdr, data, p = read_record(b, p)
            yield hdr, data

    with open(path, "rb") as f:
        if f.read(13) != b"#ROSBAG V2.0\n":
            sys.exit(f"{path}: not a ROS 1 bag of format 2.0")
        while True:
            head = f.read(4)
            if len(head) < 4:
                break
            (hlen,) = struct.unpack("<I", head)
            hbytes = f.read(hlen)
            (dlen,) = struct.unpack("<I", f.read(4))
            hdr, _, _ = read_record(head + hbytes + struct.pack("<I", 0), 0)
            op = hdr.get("op")
            if op not in (b"\x05", b"\x07"):
                f.seek(dlen, 1)  # bag header, index and chunk info records: not needed in order
                continue
            data = f.read(dlen)
            if op == b"\x07":
                conns[struct.unpack("<I", hdr["conn"])[0]] = connection_info(data)
                continue
            kind = hdr["compression"].decode()
            if kind == "bz2":
                data = bz2.decompress(data)
            elif kind != "none":
                sys.exit(f"{path}: {kind}-compressed chunks; run `rosbag decompress` first")
            for h, d in records(data, 0):
                cid = struct.unpack("<I", h["conn"])[0] if "conn" in h else None
                if h.get("op") == b"\x07":
                    conns[cid] = connection_info(d)
                elif h.get("op") == b"\x02":
                    c = conns[cid]
                    yield c["topic"], c["type"], c["md5sum"], struct.unpack("<II", h["time"]), d


# ---- transforms: planar poses (x, y, yaw) plus whether the frame is upside down

def matrix(t):
    x, y, z, qx, qy, qz, qw = t
    return ([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
             [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
             [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]],
            [x, y, z])


def compose(a, b):
    (ra, ta), (rb, tb) = a, b
    r = [[sum(ra[i][k] * rb[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    t = [ta[i] + sum(ra[i][k] * tb[k] for k in range(3)) for i in range(3)]
    return r, t


def mount_from_tf(static, base, laser):
    """base -> laser through the tree of static transforms (child -> (parent, transform))."""
    chain, frame = [], laser
    while frame != base:
        if frame not in static:
            return None
        parent, t = static[frame]
        chain.append(t)
        frame = parent
        if len(chain) > 32:
            return None
    m = ([[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0, 0, 0])
    for t in reversed(chain):
        m = compose(m, matrix(t))
    (r, t) = m
    # A laser mounted upside down sweeps clockwise as seen from above.
    return t[0], t[1], math.atan2(r[1][0], r[0][0]), r[2][2] < 0


def interpolate(odom, t):
    """Odometry pose at time t (linear between the readings around it, held outside them)."""
    lo, hi = 0, len(odom)
    while lo < hi:
        mid = (lo + hi) // 2
        if odom[mid][0] < t:
            lo = mid + 1
        else:
            hi = mid
    if lo == 0:
        return odom[0][1]
    if lo == len(odom):
        return odom[-1][1]
    (t0, p0), (t1, p1) = odom[lo - 1], odom[lo]
    a = (t - t0) / (t1 - t0) if t1 > t0 else 1.0
    dth = math.atan2(math.sin(p1[2] - p0[2]), math.cos(p1[2] - p0[2]))
    return p0[0] + a * (p1[0] - p0[0]), p0[1] + a * (p1[1] - p0[1]), p0[2] + a * dth


def f32(v):
    """Shortest decimal that reads back as the same float32 (ROS ranges are float32)."""
    for digits in range(6, 10):
        s = f"{v:.{digits}g}"
        if "e" not in s and struct.unpack("<f", struct.pack("<f", float(s)))[0] == v:
            return s
    return f"{v:.9f}"  # tiny or huge: plain fixed point, never an exponent


def stamp_text(stamp):
    # Microseconds: CARMEN's precision; truncating keeps a time printed from CARMEN unchanged.
    return f"{stamp[0]}.{stamp[1] // 1000:06d}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("bag")
    ap.add_argument("out")
    ap.add_argument("--scan-topic", default="/scan")
    ap.add_argument("--odom-topic", default="/odom")
    ap.add_argument("--odom-from-tf", action="store_true", help="odometry from /tf odom_frame -> base_frame")
    ap.add_argument("--odom-frame", default="odom")
    ap.add_argument("--base-frame", default="base_link")
    ap.add_argument("--laser-pose", help="X,Y,YAW of the laser in base_frame [m, m, rad], instead of /tf")
    a = ap.parse_args()
    odom_frame, base = a.odom_frame.lstrip("/"), a.base_frame.lstrip("/")

    # Readings are kept with their bag time (receipt) to be written in the order they were received.
    scans, odom, odom_tf, static = [], [], [], {}
    for topic, mtype, md5, received, data in bag_messages(a.bag):
        if mtype in MD5 and md5 != MD5[mtype]:
            sys.exit(f"{a.bag}: {topic} declares md5sum {md5}, not {mtype}'s {MD5[mtype]}")
        if topic == a.scan_topic and mtype == "sensor_msgs/LaserScan":
            scans.append(dict(parse_scan(data), received=received))
        elif topic == a.odom_topic and mtype == "nav_msgs/Odometry" and not a.odom_from_tf:
            odom.append(parse_odometry(data) + (received,))
        elif topic in ("/tf", "/tf_static") and mtype == "tf2_msgs/TFMessage":
            for stamp, parent, child, t in parse_tf(data):
                if parent == odom_frame and child == base:
                    x, y, _z, qx, qy, qz, qw = t
                    odom_tf.append((stamp, (x, y, yaw_of(qx, qy, qz, qw)), received))
                elif child not in static:
                    static[child] = (parent, t)
    if a.odom_from_tf:
        odom = odom_tf
    if not scans:
        sys.exit(f"{a.bag}: no sensor_msgs/LaserScan on {a.scan_topic}")
    if not odom:
        src = f"/tf {odom_frame} -> {base}" if a.odom_from_tf else f"nav_msgs/Odometry on {a.odom_topic}"
        sys.exit(f"{a.bag}: no odometry ({src})")

    if a.laser_pose:
        x, y, yaw = (float(v) for v in a.laser_pose.split(","))
        mount = (x, y, yaw, False)
    else:
        mount = mount_from_tf(static, base, scans[0]["frame"])
        if mount is None:
            sys.exit(f"{a.bag}: no transform {base} -> {scans[0]['frame']} in /tf_static or /tf; "
                     "give --laser-pose X,Y,YAW")

    odom_times = sorted((st[0] + st[1] * 1e-9, pose) for st, pose, _ in odom)
    # The order of receipt (rosbag play's): the pipeline pairs a scan with the odometry received
    # before it, as a live robot would. Python's sort is stable: ties keep the file's order.
    timed = [(r, 0, i) for i, (_, _, r) in enumerate(odom)] + [(s["received"], 1, i) for i, s in enumerate(scans)]
    timed.sort(key=lambda e: e[0])
    with open(a.out, "w") as out:
        out.write(f"# CARMEN log converted from {a.bag} by bag2carmen.py\n"
                  "# message formats defined: ODOM ROBOTLASER1\n")
        for _, kind, idx in timed:
            stamp = odom[idx][0] if kind == 0 else scans[idx]["stamp"]
            ts = stamp_text(stamp)
            if kind == 0:
                x, y, th = odom[idx][1]
                out.write(f"ODOM {x:.6f} {y:.6f} {th:.6f} 0 0 0 {ts} bag {ts}\n")
                continue
            s = scans[idx]
            ranges, amin, inc = list(s["ranges"]), s["angle_min"], s["increment"]
            if inc < 0:  # beams listed clockwise: CARMEN's go counter-clockwise
                ranges.reverse()
                amin, inc = amin + inc * (len(ranges) - 1), -inc
            mx, my, myaw, flipped = mount
            if flipped:
                # Seen from above, beam i of an upside-down laser is at -angle: reverse the beams.
                ranges.reverse()
                amin = -(amin + inc * (len(ranges) - 1))
            rmax = s["range_max"]
            cells = []
            for r in ranges:
                if not math.isfinite(r):
                    cells.append(f32(rmax))  # no return; a finite value beyond the maximum is kept
                elif r < s["range_min"] or r <= 0:
                    cells.append("0")
                else:
                    cells.append(f32(r))
            rx, ry, rth = interpolate(odom_times, stamp[0] + stamp[1] * 1e-9)
            lx = rx + mx * math.cos(rth) - my * math.sin(rth)
            ly = ry + mx * math.sin(rth) + my * math.cos(rth)
            lth = rth + myaw
            fov = inc * (len(ranges) - 1)
            out.write(f"ROBOTLASER1 0 {amin:.9f} {fov:.9f} {inc:.9f} {f32(rmax)} 0.01 0 {len(ranges)} "
                      + " ".join(cells)
                      + f" 0 {lx:.9f} {ly:.9f} {lth:.9f} {rx:.9f} {ry:.9f} {rth:.9f} 0 0 0 0 0 {ts} bag {ts}\n")
    print(f"{a.out}: {len(scans)} scans, {len(odom)} odometry readings, laser at "
          f"({mount[0]:.3f}, {mount[1]:.3f}, {math.degrees(mount[2]):.1f} deg){' upside down' if mount[3] else ''}")


if __name__ == "__main__":
    main()
