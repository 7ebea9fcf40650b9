#!/usr/bin/env python3
"""Exits 0 when two OpenEXR files hold the same image: the same header attributes (but the
line order) and,
channel by channel, the same bits in every sample (so -0 against 0 or two NaNs of different
payloads count as different). Their bytes may still differ: a file whose line order is
unspecified may hold its compressed blocks in any order (as the `exr` crate writes them
when it is told no order), so one image can be written as different bytes.

    python3 tools/dev/exr-same.py A.exr B.exr

Needs the PyPI packages OpenEXR and numpy."""
import sys

import numpy as np
import OpenEXR


def read(path):
    with OpenEXR.File(path) as f:
        # The line order says only how the blocks lie in the file, not what they hold.
        header = {k: repr(v) for k, v in f.header().items() if k != "lineOrder"}
        channels = {k: np.ascontiguousarray(v.pixels) for k, v in f.channels().items()}
    return header, channels


def main():
    (ha, ca), (hb, cb) = read(sys.argv[1]), read(sys.argv[2])
    problems = [f"header {k}: {ha.get(k)} != {hb.get(k)}" for k in sorted(set(ha) | set(hb)) if ha.get(k) != hb.get(k)]
    for name in sorted(set(ca) | set(cb)):
        a, b = ca.get(name), cb.get(name)
        if a is None or b is None or a.shape != b.shape or a.dtype != b.dtype:
            problems.append(f"channel {name}: present or shaped differently")
        elif not np.array_equal(a.view(np.uint8), b.view(np.uint8)):
            problems.append(f"channel {name}: samples differ")
    for p in problems:
        print(p)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
