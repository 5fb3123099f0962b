#!/usr/bin/env python3
"""Write a ROS 1 bag (format 2.0, uncompressed chunks) from a CARMEN log's FLASER and ODOM lines.

There is no ROS here, so the bag for the ROS path's test is generated from a shipped CARMEN
excerpt: the same scans and the same odometry, so a run on the bag can be checked against a run
on the CARMEN log itself. Standard library only.

  make_bag.py LOG.clf[.gz] OUT.bag

Topics (the layout of a typical 2D robot recording):
  /scan        sensor_msgs/LaserScan   frame 'laser', one per FLASER line
  /odom        nav_msgs/Odometry       frame 'odom', child 'base_link', one per ODOM line
  /tf          tf2_msgs/TFMessage      odom -> base_link, one per ODOM line
  /tf_static   tf2_msgs/TFMessage      base_link -> laser (PARAM robot_frontlaser_offset), latched
Headers carry the stamp of the line; the bag time is the logger's time of receipt.
"""
import gzip
import hashlib
import math
import struct
import sys

# Message definitions as ROS 1 ships them (comments dropped; md5sums depend only on these lines).
DEFS = {
    "std_msgs/Header": "uint32 seq\ntime stamp\nstring frame_id",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Quaternion": "float64 x\nfloat64 y\nfloat64 z\nfloat64 w",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Pose": "Point position\nQuaternion orientation",
    "geometry_msgs/PoseWithCovariance": "Pose pose\nfloat64[36] covariance",
    "geometry_msgs/Twist": "Vector3 linear\nVector3 angular",
    "geometry_msgs/TwistWithCovariance": "Twist twist\nfloat64[36] covariance",
    "geometry_msgs/Transform": "Vector3 translation\nQuaternion rotation",
    "geometry_msgs/TransformStamped": "Header header\nstring child_frame_id\nTransform transform",
    "sensor_msgs/LaserScan": (
        "Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n"
        "float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\n"
        "float32[] ranges\nfloat32[] intensities"),
    "nav_msgs/Odometry": (
        "Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
        "geometry_msgs/TwistWithCovariance twist"),
    "tf2_msgs/TFMessage": "geometry_msgs/TransformStamped[] transforms",
}
# The md5sums roslib publishes for these types: the computed ones must match, or rosbag's
# instantiate<T>() in a reader refuses the messages.
KNOWN_MD5 = {
    "std_msgs/Header": "2176decaecbce78abc3b96ef049fabed",
    "sensor_msgs/LaserScan": "90c7ef2dc6895d81024acba2ac42f369",
    "nav_msgs/Odometry": "cd5e73d190d741a2f92e81eda573aca7",
    "tf2_msgs/TFMessage": "94810edda583a504dfda3829e70d7eec",
}
BUILTIN = {"bool", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
           "float32", "float64", "string", "time", "duration", "byte", "char"}


def resolve(pkg, base):
    """Full name of a field type used inside package pkg (Header is std_msgs' by convention)."""
    if base == "Header":
        return "std_msgs/Header"
    return base if "/" in base else pkg + "/" + base


def fields(name):
    for line in DEFS[name].splitlines():
        ftype, fname = line.split()
        base = ftype.split("[")[0]
        yield ftype, base, fname


def md5sum(name):
    """roslib's md5: the definition with every nested type replaced by its own md5sum."""
    pkg = name.split("/")[0]
    lines = []
    for ftype, base, fname in fields(name):
        if base in BUILTIN:
            lines.append(f"{ftype} {fname}")
        else:
            lines.append(f"{md5sum(resolve(pkg, base))} {fname}")
    return hashlib.md5("\n".join(lines).encode()).hexdigest()


def full_definition(name):
    """The connection header's message_definition: the type, then each nested type once."""
    order = []

    def visit(n):
        pkg = n.split("/")[0]
        for _, base, _ in fields(n):
            if base not in BUILTIN:
                dep = resolve(pkg, base)
                if dep not in order:
                    order.append(dep)
                    visit(dep)
    visit(name)
    text = DEFS[name] + "\n"
    for dep in order:
        text += "=" * 80 + f"\nMSG: {dep}\n" + DEFS[dep] + "\n"
    return text


# ---- ROS 1 serialisation (little-endian; strings and variable arrays carry a uint32 length)

def ser_string(s):
    b = s.encode()
    return struct.pack("<I", len(b)) + b


def ser_header(seq, stamp, frame):
    return struct.pack("<III", seq, stamp[0], stamp[1]) + ser_string(frame)


def yaw_quat(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def ser_laser_scan(seq, stamp, frame, angle_min, increment, range_max, ranges):
    angle_max = angle_min + increment * (len(ranges) - 1)
    return (ser_header(seq, stamp, frame)
            + struct.pack("<7f", angle_min, angle_max, increment, 0.0, 0.0, 0.0, range_max)
            + struct.pack(f"<I{len(ranges)}f", len(ranges), *ranges)
            + struct.pack("<I", 0))


def ser_odometry(seq, stamp, frame, child, x, y, yaw):
    cov = [0.0] * 36
    return (ser_header(seq, stamp, frame) + ser_string(child)
            + struct.pack("<7d", x, y, 0.0, *yaw_quat(yaw)) + struct.pack("<36d", *cov)
            + struct.pack("<6d", 0, 0, 0, 0, 0, 0) + struct.pack("<36d", *cov))


def ser_tf(transforms):
    out = struct.pack("<I", len(transforms))
    for seq, stamp, parent, child, x, y, yaw in transforms:
        out += (ser_header(seq, stamp, parent) + ser_string(child)
                + struct.pack("<7d", x, y, 0.0, *yaw_quat(yaw)))
    return out


# ---- Bag format 2.0 records: header (name=value fields) + data

def record(fields_, data):
    h = b""
    for k, v in fields_.items():
        f = k.encode() + b"=" + v
        h += struct.pack("<I", len(f)) + f
    return struct.pack("<I", len(h)) + h + struct.pack("<I", len(data)) + data


def u32(v):
    return struct.pack("<I", v)


def t64(stamp):
    return struct.pack("<II", *stamp)


class BagWriter:
    """Everything in one uncompressed chunk per CHUNK_MESSAGES messages, indexed per connection."""
    CHUNK_MESSAGES = 500

    def __init__(self, path):
        self.f = open(path, "wb")
        self.f.write(b"#ROSBAG V2.0\n")
        self.header_pos = self.f.tell()
        self._write_bag_header(0, 0, 0)
        self.conns = {}        # topic -> (id, connection record fields, connection header data)
        self.chunk = []        # (conn id, stamp, record bytes)
        self.chunk_infos = []  # (chunk pos, start, end, {conn: count})

    def _write_bag_header(self, index_pos, n_conns, n_chunks):
        # The bag header record is padded to 4096 bytes so it can be rewritten in place at close.
        fields_ = {"op": b"\x03", "index_pos": struct.pack("<Q", index_pos),
                   "conn_count": u32(n_conns), "chunk_count": u32(n_chunks)}
        h = record(fields_, b"")
        pad = 4096 - len(h)
        self.f.seek(self.header_pos)
        self.f.write(record(fields_, b" " * pad))

    def add_connection(self, topic, msg_type, latching=False):
        cid = len(self.conns)
        hdr = {"topic": topic.encode(), "type": msg_type.encode(), "md5sum": md5sum(msg_type).encode(),
               "message_definition": full_definition(msg_type).encode(), "callerid": b"/make_bag"}
        if latching:
            hdr["latching"] = b"1"
        data = b"".join(u32(len(k) + 1 + len(v)) + k.encode() + b"=" + v for k, v in hdr.items())
        self.conns[topic] = (cid, {"op": b"\x07", "conn": u32(cid), "topic": topic.encode()}, data)

    def write(self, topic, received, data):
        """received: the bag time, when the recorder got the message (the header has the stamp)."""
        cid = self.conns[topic][0]
        self.chunk.append((cid, received, record({"op": b"\x02", "conn": u32(cid), "time": t64(received)}, data)))
        if len(self.chunk) >= self.CHUNK_MESSAGES:
            self._flush()

    def _flush(self):
        if not self.chunk:
            return
        # A connection record precedes the first message of each connection in every chunk.
        body, offsets, seen = b"", {}, set()
        for cid, stamp, rec in self.chunk:
            if cid not in seen:
                seen.add(cid)
                _, cfields, cdata = next(c for c in self.conns.values() if c[0] == cid)
                body += record(cfields, cdata)
            offsets.setdefault(cid, []).append((stamp, len(body)))
            body += rec
        stamps = [s for _, s, _ in self.chunk]
        pos = self.f.seek(0, 2)
        self.f.write(record({"op": b"\x05", "compression": b"none", "size": u32(len(body))}, body))
        for cid, entries in sorted(offsets.items()):
            data = b"".join(t64(s) + u32(o) for s, o in entries)
            self.f.write(record({"op": b"\x04", "ver": u32(1), "conn": u32(cid), "count": u32(len(entries))}, data))
        self.chunk_infos.append((pos, min(stamps), max(stamps), {c: len(e) for c, e in offsets.items()}))
        self.chunk = []

    def close(self):
        self._flush()
        index_pos = self.f.seek(0, 2)
        for _, cfields, cdata in sorted(self.conns.values(), key=lambda c: c[0]):
            self.f.write(record(cfields, cdata))
        for pos, start, end, counts in self.chunk_infos:
            data = b"".join(u32(c) + u32(n) for c, n in sorted(counts.items()))
            self.f.write(record({"op": b"\x06", "ver": u32(1), "chunk_pos": struct.pack("<Q", pos),
                                 "start_time": t64(start), "end_time": t64(end), "count": u32(len(counts))}, data))
        self._write_bag_header(index_pos, len(self.conns), len(self.chunk_infos))
        self.f.close()


# ---- CARMEN input

def stamp_of(token):
    """CARMEN times are decimal seconds: split them exactly into (sec, nsec), no float rounding."""
    sec, _, frac = token.partition(".")
    return int(sec), int((frac + "000000000")[:9])


def resolution_for_beams(n):
    # The beam spacing CARMEN implies by the count over its 180° field of view (SICK LMS modes),
    # the same rule as the CARMEN reader's.
    deg = math.pi / 180
    return {180: deg, 181: deg, 360: deg / 2, 361: deg / 2, 720: deg / 4, 721: deg / 4}.get(
        n, math.pi / (n - 1) if n > 1 else math.pi)


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    for name, md5 in KNOWN_MD5.items():
        assert md5sum(name) == md5, f"{name}: md5sum {md5sum(name)} != {md5}"
    opener = gzip.open if argv[1].endswith(".gz") else open
    with opener(argv[1], "rt") as f:
        lines = [l.split() for l in f if l.strip() and not l.startswith("#")]
    params = {l[1]: l[2] for l in lines if l[0] == "PARAM" and len(l) >= 3}
    offset = float(params.get("robot_frontlaser_offset", "0"))
    range_max = float(params.get("robot_front_laser_max", "81.9"))

    bag = BagWriter(argv[2])
    bag.add_connection("/tf_static", "tf2_msgs/TFMessage", latching=True)
    bag.add_connection("/scan", "sensor_msgs/LaserScan")
    bag.add_connection("/odom", "nav_msgs/Odometry")
    bag.add_connection("/tf", "tf2_msgs/TFMessage")
    def line_stamp(l):
        return stamp_of(l[7]) if l[0] == "ODOM" else stamp_of(l[int(l[1]) + 8])

    data = [l for l in lines if l[0] in ("ODOM", "FLASER")]
    if not data:
        sys.exit(f"{argv[1]}: no FLASER or ODOM lines")
    # Bag time is the time of receipt, as rosbag record stores it: CARMEN's logger timestamp
    # (the line's last field, seconds since the logger started), moved to the stamps' time base.
    # It keeps the log's order, in which a scan arrives after odometry newer than its stamp.
    start = line_stamp(data[0])
    base = start[0] + start[1] * 1e-9 - float(data[0][-1])

    def received(l):
        return divmod(int(round((base + float(l[-1])) * 1e9)), 1000000000)

    # The mount is static: written first, before any message that needs it.
    bag.write("/tf_static", received(data[0]), ser_tf([(0, start, "base_link", "laser", offset, 0.0, 0.0)]))
    n_scan = n_odom = 0
    for l in data:
        stamp, recv = line_stamp(l), received(l)
        if l[0] == "ODOM":
            x, y, th = float(l[1]), float(l[2]), float(l[3])
            bag.write("/odom", recv, ser_odometry(n_odom, stamp, "odom", "base_link", x, y, th))
            bag.write("/tf", recv, ser_tf([(n_odom, stamp, "odom", "base_link", x, y, th)]))
            n_odom += 1
        else:
            n = int(l[1])
            ranges = [float(r) for r in l[2:2 + n]]
            bag.write("/scan", recv, ser_laser_scan(n_scan, stamp, "laser", -math.pi / 2,
                                                     resolution_for_beams(n), range_max, ranges))
            n_scan += 1
    bag.close()
    print(f"{argv[2]}: {n_scan} scans, {n_odom} odometry readings")


if __name__ == "__main__":
    main(sys.argv)
