"""Readers of urbanslam's map exports as the ROS tools read them (standard library only).

map_server (ROS 1) loads grid.yaml + grid.png; PCL's PCDReader loads map.pcd; RViz, PCL and
every mesh viewer load map.ply. Each reader here checks what those tools check and fails with
the reason otherwise.
"""
import struct
import zlib


class FormatError(Exception):
    pass


def read_map_yaml(path):
    """grid.yaml as map_server reads it: required keys, their types, origin [x, y, yaw]."""
    values = {}
    with open(path) as f:
        for line in f:
            line = line.split("#")[0].strip()
            if line:
                key, sep, value = line.partition(":")
                if not sep:
                    raise FormatError(f"{path}: not a 'key: value' line: {line}")
                values[key.strip()] = value.strip()
    for key in ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh"):
        if key not in values:
            raise FormatError(f"{path}: map_server needs '{key}'")
    origin = values["origin"]
    if not (origin.startswith("[") and origin.endswith("]")):
        raise FormatError(f"{path}: origin must be a list [x, y, yaw]")
    out = {
        "image": values["image"],
        "resolution": float(values["resolution"]),
        "origin": [float(v) for v in origin[1:-1].split(",")],
        "negate": int(values["negate"]),
        "occupied_thresh": float(values["occupied_thresh"]),
        "free_thresh": float(values["free_thresh"]),
        "mode": values.get("mode", "trinary"),
    }
    if len(out["origin"]) != 3:
        raise FormatError(f"{path}: origin has {len(out['origin'])} values, map_server needs 3")
    if out["resolution"] <= 0 or out["negate"] not in (0, 1):
        raise FormatError(f"{path}: resolution must be > 0 and negate 0 or 1")
    if not 0 <= out["free_thresh"] < out["occupied_thresh"] <= 1:
        raise FormatError(f"{path}: thresholds must satisfy 0 <= free < occupied <= 1")
    if out["mode"] not in ("trinary", "scale", "raw"):
        raise FormatError(f"{path}: unknown mode {out['mode']}")
    return out


def read_png_gray(path):
    """8-bit grayscale (or RGB/RGBA, averaged as map_server does) PNG: (width, height, rows)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise FormatError(f"{path}: not a PNG")
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, color, _, _, interlace = ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(color)
    if depth != 8 or channels is None or interlace:
        raise FormatError(f"{path}: only 8-bit non-interlaced gray/RGB(A) PNGs are decoded here")
    raw, stride, bpp = zlib.decompress(idat), w * channels, channels
    rows, prev, p = [], bytearray(stride), 0
    for _ in range(h):
        ftype, line = raw[p], bytearray(raw[p + 1:p + 1 + stride])
        p += 1 + stride
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], (prev[i - bpp] if i >= bpp else 0)
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ftype == 4:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line) if channels == 1 else
                    bytes(sum(line[j:j + min(channels, 3)]) // min(channels, 3) for j in range(0, stride, channels)))
        prev = line
    return w, h, rows


def map_server_class(value, meta):
    """map_server's trinary reading of one pixel: 'occupied', 'free' or 'unknown'."""
    occ = value / 255.0 if meta["negate"] else (255 - value) / 255.0
    if occ > meta["occupied_thresh"]:
        return "occupied"
    if occ < meta["free_thresh"]:
        return "free"
    return "unknown"


def read_pcd_header(path):
    """PCD header as PCL's reader checks it: the fields in order, sizes agreeing, data kind."""
    order = ["VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT", "POINTS", "DATA"]
    with open(path, "rb") as f:
        head, seen = {}, []
        while len(seen) < len(order):
            line = f.readline().decode("ascii").strip()
            if not line:
                raise FormatError(f"{path}: header ends before DATA")
            if line.startswith("#"):
                continue
            key, _, rest = line.partition(" ")
            seen.append(key)
            head[key] = rest.split()
        body = f.read()
    if seen != order:
        raise FormatError(f"{path}: header fields {seen}, PCL expects {order}")
    if head["VERSION"][0] not in ("0.7", ".7"):
        raise FormatError(f"{path}: VERSION {head['VERSION']}")
    n = len(head["FIELDS"])
    if not all(len(head[k]) == n for k in ("SIZE", "TYPE", "COUNT")):
        raise FormatError(f"{path}: FIELDS, SIZE, TYPE and COUNT disagree in length")
    width, height, points = int(head["WIDTH"][0]), int(head["HEIGHT"][0]), int(head["POINTS"][0])
    if width * height != points:
        raise FormatError(f"{path}: WIDTH*HEIGHT {width * height} != POINTS {points}")
    kind = head["DATA"][0]
    if kind == "ascii":
        lines = [l for l in body.decode("ascii").splitlines() if l.strip()]
        if len(lines) != points or any(len(l.split()) != n for l in lines):
            raise FormatError(f"{path}: {len(lines)} data lines of {n} values expected {points}")
    elif kind == "binary":
        if len(body) != points * sum(int(s) * int(c) for s, c in zip(head["SIZE"], head["COUNT"])):
            raise FormatError(f"{path}: binary body of {len(body)} bytes for {points} points")
    else:
        raise FormatError(f"{path}: DATA {kind}")
    return {"fields": head["FIELDS"], "points": points, "data": kind}


def read_ply_header(path):
    """PLY header: magic, format, the vertex element with float x y z, and the body's size."""
    with open(path, "rb") as f:
        if f.readline() != b"ply\n":
            raise FormatError(f"{path}: no 'ply' magic line")
        fmt, vertices, props = None, None, []
        while True:
            line = f.readline().decode("ascii").strip()
            if line == "end_header":
                break
            if not line:
                raise FormatError(f"{path}: header without end_header")
            w = line.split()
            if w[0] == "format":
                fmt = w[1]
            elif w[0] == "element":
                if w[1] != "vertex" or vertices is not None:
                    raise FormatError(f"{path}: unexpected element {line}")
                vertices = int(w[2])
            elif w[0] == "property":
                props.append((w[1], w[2]))
        body = f.read()
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian") or vertices is None:
        raise FormatError(f"{path}: format {fmt}, vertices {vertices}")
    if [p[1] for p in props[:3]] != ["x", "y", "z"]:
        raise FormatError(f"{path}: vertex properties {props}")
    if fmt == "binary_little_endian":
        size = {"float": 4, "float32": 4, "double": 8, "float64": 8}
        if len(body) != vertices * sum(size[t] for t, _ in props):
            raise FormatError(f"{path}: {len(body)} body bytes for {vertices} vertices")
        points = [struct.unpack_from("<3f", body, i * 12) for i in range(vertices)] if all(
            t in ("float", "float32") for t, _ in props) and len(props) == 3 else []
    else:
        points = [tuple(float(v) for v in l.split()[:3]) for l in body.decode("ascii").splitlines()[:vertices]]
    return {"format": fmt, "vertices": vertices, "points": points}
