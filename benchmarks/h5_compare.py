#!/usr/bin/env python3
"""Bitwise comparison of ancfdrv HDF5 results (the lean-output gate, issue 23 item 4):
every dataset and attribute of the files except /timing, wall times (and the phase times
``time_<phase>_s`` of /modal and /buckling), the git commit, the command line and the
creation/finish stamps.

    python benchmarks/h5_compare.py DIR_BEFORE DIR_AFTER boom_ffr.h5 boom_cable.h5 ...

    python benchmarks/h5_compare.py --rtol 1e-12 DIR_BEFORE DIR_AFTER boom_ffr.h5 ...

Exit status 0 when every named file is the same in both directories. With --rtol R, float
datasets and attributes may differ by R times the dataset's largest magnitude (NaN where
the other has NaN): the gate of output computed in another arithmetic order."""
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
    return {k: v for k, v in obj.attrs.items() if k not in SKIP_ATTRS and "wall" not in k
            and "time_s" not in k and not (k.startswith("time_") and k.endswith("_s"))}
RTOL = None
if len(sys.argv) > 2 and sys.argv[1] == "--rtol":
    RTOL = float(sys.argv[2])
    del sys.argv[1:3]
WORST = [0.0, ""]
def same(a, b, name=""):
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind in "fc":
        if RTOL is None or a.tobytes() == b.tobytes():
            return a.tobytes() == b.tobytes()
        if not np.array_equal(np.isnan(a), np.isnan(b)):
            return False
        fa, fb = a[~np.isnan(a)], b[~np.isnan(b)]
        scale = np.abs(fa).max(initial=0.0)
        diff = np.abs(fa - fb).max(initial=0.0)
        rel = diff / scale if scale > 0 else (0.0 if diff == 0 else np.inf)
        if rel > WORST[0]:
            WORST[:] = [rel, name]
        return rel <= RTOL
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
                if not same(x[()], y[()], f"{name}:{k}"):
                    bad += 1
                    if bad < 8: print(name, "dataset differs:", k)
            ax, ay = attrs(x), attrs(y)
            if set(ax) != set(ay):
                print(name, k, "attrs differ:", set(ax) ^ set(ay)); bad += 1
            for a in set(ax) & set(ay):
                if not same(ax[a], ay[a]):
                    print(name, k, "attr differs:", a, ax[a], ay[a]); bad += 1
        print(name, ndat, "datasets compared")
if RTOL is not None:
    print(f"largest relative difference {WORST[0]:.3g} ({WORST[1] or '-'})")
print(("IDENTICAL" if RTOL is None else f"SAME WITHIN {RTOL:g}") if not bad
      else f"{bad} DIFFERENCES")
sys.exit(1 if bad else 0)
