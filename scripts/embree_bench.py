#!/usr/bin/env python3
"""Embree's side of `fxrt bench --against-embree` (docs/PERFORMANCE.md).

fxrt writes into DIR, little-endian:
  triangles.f32   T x 3 x 3 float32: the scene's triangles in world coordinates, file order
  origins.f64     N x 3 float64: each pixel ray's origin (Camera::pixel_rays)
  directions.f64  N x 3 float64: each pixel ray's unit direction
This script builds an Embree 4 scene of the triangles (embreex, float32 like Embree itself),
traces every ray for its closest hit (rtcIntersect1, in embreex's loop that releases the GIL)
with each thread count asked for, best of --repeat, and prints one JSON line:
  {"embree": "4.x.y", "embreex": "...", "rays": N, "hits": H,
   "runs": [{"threads": 1, "seconds": s, "mrays_per_s": x}, ...]}
Exit 3 with one line on stderr when embreex cannot be imported (fxrt says what to install).
"""

import argparse
import itertools
import json
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor

try:
    import numpy as np
    import embreex
    from embreex import rtcore, rtcore_scene
    from embreex.mesh_construction import TriangleMesh
except ImportError as e:
    print(f"embree_bench: embreex is not installed ({e})", file=sys.stderr)
    sys.exit(3)

# Rows of pixels a thread takes at a time, from a shared queue (as rayon's work stealing
# does for fxrt, so a thread slowed by other work on the machine holds no one up): small enough
# to share the frame's costly middle evenly, large enough that each `run` call's own overhead
# (its argument checks and result arrays) stays near 1 %.
ROWS_PER_BLOCK = 16


def load(folder):
    tris = np.fromfile(os.path.join(folder, "triangles.f32"), dtype="<f4").reshape(-1, 3, 3)
    # The same float64 rays the golden model traced, rounded to Embree's float32 here.
    org = np.fromfile(os.path.join(folder, "origins.f64"), dtype="<f8").reshape(-1, 3)
    dirs = np.fromfile(os.path.join(folder, "directions.f64"), dtype="<f8").reshape(-1, 3)
    if len(org) != len(dirs):
        raise SystemExit(f"embree_bench: {len(org)} origins but {len(dirs)} directions")
    return np.ascontiguousarray(tris), org.astype(np.float32), dirs.astype(np.float32)


def scene_of(tris):
    # Embree's default build quality and flags (robust=False: not RTC_SCENE_FLAG_ROBUST, the
    # library's default, its fastest traversal).
    scene = rtcore_scene.EmbreeScene(rtcore.EmbreeDevice(), robust=False)
    TriangleMesh(scene, tris)
    return scene


def blocks(org, dirs, width):
    """The frame in blocks of ROWS_PER_BLOCK rows: contiguous slices, no copies."""
    step = max(1, ROWS_PER_BLOCK * width)
    return [(org[s : s + step], dirs[s : s + step]) for s in range(0, len(org), step)]


def hits_of(ids):
    return int((ids >= 0).sum())


def trace(scene, org, dirs, parts, threads, pool):
    """Closest hit of every ray; returns the number of hits. One thread: one `run` over all
    rays. Several: each takes the next block until none is left (embreex's loop runs without
    the GIL, so they trace at once)."""
    if threads == 1:
        return hits_of(scene.run(org, dirs))
    queue = itertools.count()  # next() is atomic under the GIL

    def worker():
        hits = 0
        while (k := next(queue)) < len(parts):
            hits += hits_of(scene.run(*parts[k]))
        return hits

    return sum(f.result() for f in [pool.submit(worker) for _ in range(threads)])


def measure(scene, org, dirs, threads, repeat, width):
    parts = blocks(org, dirs, width)
    with ThreadPoolExecutor(max_workers=threads) as pool:
        hits = trace(scene, org, dirs, parts, threads, pool)  # warm-up: caches, pool threads
        best = float("inf")
        for _ in range(repeat):
            start = time.perf_counter()
            again = trace(scene, org, dirs, parts, threads, pool)
            best = min(best, time.perf_counter() - start)
            if again != hits:
                raise SystemExit(f"embree_bench: {again} hits, then {hits}")
    return hits, best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", help="folder with triangles.f32, origins.f64, directions.f64")
    ap.add_argument("--threads", default="1", help="thread counts, comma-separated (default 1)")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per thread count; the best counts")
    ap.add_argument("--width", type=int, default=1, help="image width: rays per row (the blocks are rows)")
    a = ap.parse_args()
    tris, org, dirs = load(a.dir)
    scene = scene_of(tris)
    # The first query commits the scene (builds the BVH): not part of any timed run.
    scene.run(org[:1], dirs[:1])
    runs, hits = [], None
    for t in [int(x) for x in a.threads.split(",")]:
        h, seconds = measure(scene, org, dirs, t, max(1, a.repeat), a.width)
        if hits is not None and h != hits:
            raise SystemExit(f"embree_bench: {h} hits with {t} threads, {hits} before")
        hits = h
        runs.append({"threads": t, "seconds": seconds, "mrays_per_s": len(org) / seconds / 1e6})
    print(json.dumps({
        "embree": repr(rtcore.EmbreeDevice()).split(":")[-1].strip(),
        "embreex": getattr(embreex, "__version__", "unknown"),
        "rays": len(org),
        "triangles": len(tris),
        "hits": hits,
        "runs": runs,
    }))


if __name__ == "__main__":
    main()
