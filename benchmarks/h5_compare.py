#!/usr/bin/env python3
"""Bitwise comparison of ancfdrv HDF5 results (the lean-output gate, issue 23 item 4):
every dataset and attribute of the files except /timing, wall times, the git commit, the
command line and the creation/finish stamps.

    python benchmarks/h5_compare.py DIR_BEFORE DIR_AFTER boom_ffr.h5 boom_cable.h5 ...

Exit status 0 when every named file is the same in both directories."""
import sys, h5py, numpy as np
SKIP_ATTRS = {"wall_time_s", "git_commit", "command", "created", "finished"}
def walk(f):
    items = {}
    def visit(name, obj):
        if name.startswith("timing"):
            return
        items[name] = obj
    f.visititems(visit)
    return items
def attrs(obj):
    return {k: v for k, v in obj.attrs.items() if k not in SKIP_ATTRS and "wall" not in k and "time_s" not in k}
def same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind in "fc":
        return a.tobytes() == b.tobytes()
    return np.array_equal(a, b)
bad = 0
for name in sys.argv[3:]:
    with h5py.File(f"{sys.argv[1]}/{name}", "r") as A, h5py.File(f"{sys.argv[2]}/{name}", "r") as B:
        ia, ib = walk(A), walk(B)
        ia[""] = A; ib[""] = B
        if set(ia) != set(ib):
            print(name, "members differ:", set(ia) ^ set(ib)); bad += 1
        ndat = 0
        for k in sorted(set(ia) & set(ib)):
            x, y = ia[k], ib[k]
            if isinstance(x, h5py.Dataset):
                ndat += 1
                if not same(x[()], y[()]):
                    bad += 1
                    if bad < 8: print(name, "dataset differs:", k)
            ax, ay = attrs(x), attrs(y)
            if set(ax) != set(ay):
                print(name, k, "attrs differ:", set(ax) ^ set(ay)); bad += 1
            for a in set(ax) & set(ay):
                if not same(ax[a], ay[a]):
                    print(name, k, "attr differs:", a, ax[a], ay[a]); bad += 1
        print(name, ndat, "datasets compared")
print("IDENTICAL" if not bad else f"{bad} DIFFERENCES")
sys.exit(1 if bad else 0)
