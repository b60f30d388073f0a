#!/usr/bin/env python3
"""Seeds for the fuzz targets from the real recordings in ../shared/data (real/ and bad/).

Usage: make_seeds.py SHARED_DATA OUT_DIR. Writes OUT_DIR/<target>/<name> for the targets that
real files fit: the point clouds cut to a few points (a whole scan would make every execution
slow), the KITTI scans' values in the layouts of the data-only PCD targets (fuzz_pcd_data.cpp),
LZF blocks of real bytes, Ouster's KITTI poses, the scan pair's transform as a calib.yaml, and
the crashing PCD files of bad/ as they are. Standard library only; a missing file is skipped.
"""

from __future__ import annotations

import gzip
import struct
import sys
from pathlib import Path

#: points kept of each real cloud
SEED_POINTS = 8
#: real scans used (of the 16 KITTI scans)
SEED_SCANS = 2
#: LZF literal runs hold at most this many bytes (control byte 0..31)
LZF_MAX_LITERAL = 32
#: the fields of the data-only PCD targets: x y z intensity t (float32) sensor_id (uint8)
DATA_TARGET_RECORD = "<fffffB"


def header_and_data(raw: bytes, end_marker: bytes) -> tuple[list[bytes], bytes]:
    """The header lines up to and including the line starting with end_marker, and the rest."""
    lines, pos = [], 0
    while pos < len(raw):
        nl = raw.index(b"\n", pos)
        lines.append(raw[pos:nl])
        pos = nl + 1
        if lines[-1].startswith(end_marker):
            return lines, raw[pos:]
    raise ValueError("no end of header")


def cut_pcd(raw: bytes, points: int) -> tuple[bytes, list[tuple[float, ...]]]:
    """A binary PCD cut to `points` points, and those points' x y z intensity."""
    lines, data = header_and_data(raw, b"DATA")
    fields = sizes = counts = None
    for line in lines:
        key, *vals = line.split()
        if key == b"FIELDS":
            fields = [v.decode() for v in vals]
        elif key == b"SIZE":
            sizes = [int(v) for v in vals]
        elif key == b"COUNT":
            counts = [int(v) for v in vals]
    counts = counts or [1] * len(fields)
    record = sum(s * c for s, c in zip(sizes, counts))
    offset = {f: sum(s * c for s, c in zip(sizes[:k], counts[:k])) for k, f in enumerate(fields)}
    out = []
    for line in lines:
        key = line.split()[0] if line.split() else b""
        if key == b"HEIGHT":
            continue
        out.append(b"%s %d" % (key, points) if key in (b"WIDTH", b"POINTS") else line)
        if key == b"WIDTH":
            out.append(b"HEIGHT 1")
    body = data[: points * record]
    values = [
        tuple(struct.unpack_from("<f", body, i * record + offset[f])[0] for f in ("x", "y", "z", "intensity"))
        for i in range(points)
    ]
    return b"\n".join(out) + b"\n" + body, values


def lzf_literals(data: bytes) -> bytes:
    """LZF of `data` as literal runs only (valid, uncompressed)."""
    out = bytearray()
    for k in range(0, len(data), LZF_MAX_LITERAL):
        chunk = data[k : k + LZF_MAX_LITERAL]
        out += bytes([len(chunk) - 1]) + chunk
    return bytes(out)


def data_target_seeds(values: list[tuple[float, ...]]) -> dict[str, bytes]:
    """Inputs of the data-only PCD targets: 2-byte point count + the data section."""
    n = len(values)
    rows = [(*v, 0.001 * i, i % 2) for i, v in enumerate(values)]
    count = struct.pack("<H", n)
    binary = b"".join(struct.pack(DATA_TARGET_RECORD, *r) for r in rows)
    ascii_ = "".join(" ".join(repr(x) for x in r) + "\n" for r in rows).encode()
    soa = b"".join(b"".join(struct.pack("<" + fmt, r[k]) for r in rows) for k, fmt in enumerate(DATA_TARGET_RECORD[1:]))
    block = lzf_literals(soa)
    compressed = struct.pack("<II", len(block), len(soa)) + block
    return {"pcd_binary": count + binary, "pcd_ascii": count + ascii_, "pcd_compressed": count + compressed}


def main(shared: Path, out: Path) -> int:
    written = 0

    def put(target: str, name: str, data: bytes) -> None:
        nonlocal written
        (out / target).mkdir(parents=True, exist_ok=True)
        (out / target / name).write_bytes(data)
        written += 1

    for f in sorted((shared / "bad").glob("*.pcd")):
        put("pcd", f.name, f.read_bytes())
    for f in sorted((shared / "real" / "kitti_16_scans").glob("*.pcd.gz"))[:SEED_SCANS]:
        cut, values = cut_pcd(gzip.decompress(f.read_bytes()), SEED_POINTS)
        stem = f.name.split(".")[0]
        put("pcd", f"kitti_{stem}.pcd", cut)
        for target, data in data_target_seeds(values).items():
            put(target, f"kitti_{stem}", data)
        put("kitti_bin", f"kitti_{stem}.bin", b"".join(struct.pack("<ffff", *v) for v in values))
        put("lzf", f"kitti_{stem}", struct.pack("<I", len(cut)) + lzf_literals(cut))
    for f in sorted((shared / "real" / "scan_pair").glob("*.ply")):
        lines, data = header_and_data(f.read_bytes(), b"end_header")
        vertex_bytes = 16  # float x y z scalar_intensity
        head = [b"element vertex %d" % SEED_POINTS if x.startswith(b"element vertex") else x for x in lines]
        put("ply", f.name, b"\n".join(head) + b"\n" + data[: SEED_POINTS * vertex_bytes])
    transform = shared / "real" / "scan_pair" / "T_target_source.txt"
    if transform.exists():
        rows = [r.split() for r in transform.read_text().splitlines() if r.strip()]
        yaml = "T_imu_lidar:\n" + "".join(f"  - [{', '.join(r)}]\n" for r in rows) + "gravity: 9.81\n"
        put("calib_yaml", "scan_pair_transform.yaml", yaml.encode())
    for f in sorted((shared / "real" / "ouster").glob("*poses_kitti.txt")):
        put("kitti_poses", f.name, f.read_bytes())
    print(f"{written} seeds from {shared} in {out}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(Path(sys.argv[1]), Path(sys.argv[2])))
