#!/usr/bin/env python3
"""Where a frame's device time goes: sums Nsight Compute's per-launch kernel durations
(`ncu --metrics gpu__time_duration.sum --csv --page raw`) per kernel and per frame.

  python3 scripts/gpu_kernel_table.py ncu.csv FRAMES

Kernels are named by the function that launches them (a CudaExecutor lambda: its enclosing
function and lambda number) or by their own name (CUB). Run by scripts/gpu_check.sh (NCU=1).
"""

from __future__ import annotations

import csv
import re
import sys
from collections import defaultdict

UNIT_TO_US = {"nsecond": 1e-3, "usecond": 1.0, "msecond": 1e3, "second": 1e6}
METRIC = "gpu__time_duration.sum"


def short_name(name: str) -> str:
    """The launching function and lambda instance of an executor kernel, else the kernel's name."""
    lam = re.search(
        r"([A-Za-z_][\w:]*)\((?:[^()]|\([^()]*\))*\)(?: const)?::\[lambda\(unsigned long\) \(instance (\d+)\)\]", name
    )
    kind = "reduce" if "reduce" in name.split("<")[0] else "for_each"
    if lam:
        function = re.sub(r"^(farlio::)?(cuda::)?", "", lam.group(1))
        return f"{function} lambda {lam.group(2)} ({kind})"
    head = re.split(r"[<(]", name.replace("void ", "", 1))[0]
    return head.split("::")[-1] or name[:60]


def main() -> int:
    path, frames = sys.argv[1], int(sys.argv[2])
    rows = list(csv.reader(open(path, newline="")))
    header = next(i for i, r in enumerate(rows) if "Kernel Name" in r)
    cols = rows[header]
    name_col, value_col = cols.index("Kernel Name"), cols.index(METRIC)
    scale = 1e-3  # ncu's default unit for the duration: ns
    totals: dict[str, float] = defaultdict(float)
    launches: dict[str, int] = defaultdict(int)
    for r in rows[header + 1 :]:
        if len(r) <= value_col:
            continue
        value = r[value_col].replace(",", "")
        if value in UNIT_TO_US:  # the units row
            scale = UNIT_TO_US[value]
            continue
        try:
            us = float(value) * scale
        except ValueError:
            continue
        key = short_name(r[name_col])
        totals[key] += us
        launches[key] += 1
    total = sum(totals.values())
    if not totals:
        print(f"{path}: no kernel durations", file=sys.stderr)
        return 1
    print(f"{'kernel (launching function)':<60} {'launches/frame':>15} {'us/frame':>10} {'share':>7}")
    for key, us in sorted(totals.items(), key=lambda kv: -kv[1]):
        print(f"{key[:60]:<60} {launches[key] / frames:>15.1f} {us / frames:>10.1f} {100 * us / total:>6.1f}%")
    print(f"{'all kernels':<60} {sum(launches.values()) / frames:>15.1f} {total / frames:>10.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
