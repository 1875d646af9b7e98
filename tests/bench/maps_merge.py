#!/usr/bin/env python3
"""Benchmark of `merge-maps` against the ROS multirobot_map_merge recipe.

Runs, on the same pairs of real maps (../shared/data/maps, or $SLAMLAB_DATA/maps):
  * ours: `node web/cli.mjs merge-maps A.yaml B.yaml --json` (the wasm build in web/pkg);
  * the recipe of m-explore's multirobot_map_merge: AKAZE on the grid images
    (occupancy values as grey: free 0, occupied 100, unknown 255), ratio test 0.7,
    cv2.estimateAffinePartial2D (RANSAC), confidence = inliers / (8 + 0.3 * matches),
    accepted at >= 1.0;
and prints one table row per pair: verdict and error against the truth (laser pairs:
expect.json; Halmstad KPT4A: the fit_reference.py transform), plus the time of a merge
of two 2000 x 2000 maps in node (two laser maps padded with unknown).

Needs: python3 with numpy and OpenCV 4 (pip install numpy "opencv-python-headless<5": OpenCV 5 dropped AKAZE from the wheel),
node, and ./build.sh build. Usage: python3 tests/bench/maps_merge.py [--skip-halmstad]
"""
import json
import math
import os
import subprocess
import sys
import tempfile

import cv2
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.environ.get("SLAMLAB_DATA", os.path.join(ROOT, "..", "shared", "data"))
MAPS = os.path.join(DATA, "maps")
TMP = tempfile.mkdtemp(prefix="slamlab-bench-maps-")


def read_yaml(path):
    out = {}
    for line in open(path):
        if ":" in line:
            k, v = line.split(":", 1)
            out[k.strip()] = v.strip()
    origin = [float(x) for x in out["origin"].strip("[]").split(",")]
    return out["image"], float(out["resolution"]), origin


def grid_image(yaml_path):
    """The map as multirobot_map_merge sees it: free 0, occupied 100, unknown 255."""
    image, res, origin = read_yaml(yaml_path)
    img = cv2.imread(os.path.join(os.path.dirname(yaml_path), image), cv2.IMREAD_GRAYSCALE)
    p = (255.0 - img) / 255.0
    g = np.full(img.shape, 255, np.uint8)
    g[p > 0.65] = 100
    g[p < 0.196] = 0
    return g, res, origin


def pose_compose(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    return [a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2]]


def pose_inverse(a):
    c, s = math.cos(a[2]), math.sin(a[2])
    return [-c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2]]


def akaze_merge(ya, yb):
    """The recipe; returns (accepted, pose of B's map frame in A's, confidence, ms)."""
    import time
    ga, ra, oa = grid_image(ya)
    gb, rb, ob = grid_image(yb)
    t0 = time.perf_counter()
    akaze = cv2.AKAZE_create()
    ka, da = akaze.detectAndCompute(ga, None)
    kb, db = akaze.detectAndCompute(gb, None)
    if da is None or db is None or len(ka) < 3 or len(kb) < 3:
        return False, None, 0.0, (time.perf_counter() - t0) * 1e3
    pairs = cv2.BFMatcher(cv2.NORM_HAMMING).knnMatch(db, da, k=2)
    good = [m for m, *rest in pairs if rest and m.distance < 0.7 * rest[0].distance]
    if len(good) < 3:
        return False, None, 0.0, (time.perf_counter() - t0) * 1e3
    pb = np.float32([kb[m.queryIdx].pt for m in good])
    pa = np.float32([ka[m.trainIdx].pt for m in good])
    M, inl = cv2.estimateAffinePartial2D(pb, pa, method=cv2.RANSAC)
    ms = (time.perf_counter() - t0) * 1e3
    if M is None:
        return False, None, 0.0, ms
    inliers = int(inl.sum())
    conf = inliers / (8 + 0.3 * len(good))
    # Pixel (col, row) -> image frame (x right, y up, metres).
    ha, hb = ga.shape[0], gb.shape[0]
    def to_px_b(x, y):
        return np.array([x / rb - 0.5, hb - 0.5 - y / rb])
    def from_px_a(px):
        return np.array([(px[0] + 0.5) * ra, (ha - 0.5 - px[1]) * ra])
    q0 = from_px_a(M @ np.append(to_px_b(0.0, 0.0), 1.0))
    q1 = from_px_a(M @ np.append(to_px_b(1.0, 0.0), 1.0))
    th = math.atan2(q1[1] - q0[1], q1[0] - q0[0])
    p_img = [q0[0], q0[1], th]
    pose = pose_compose(pose_compose(oa, p_img), pose_inverse(ob))
    return conf >= 1.0, pose, conf, ms


def ours(ya, yb):
    r = subprocess.run(["node", os.path.join(ROOT, "web", "cli.mjs"), "merge-maps", ya, yb, "--json"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"merge-maps failed ({r.returncode}): {r.stderr}")
    rep = json.loads(r.stdout)
    m = rep["merge"]
    pose = m["pairs"][0]["pose"]
    return m["status"] == "merged", pose, m["confidence"], rep["timings_ms"]["merge"]


def err(pose, truth):
    if pose is None:
        return float("nan"), float("nan")
    d = math.hypot(pose[0] - truth[0], pose[1] - truth[1])
    a = abs((pose[2] - truth[2] + math.pi) % (2 * math.pi) - math.pi)
    return d, math.degrees(a)


def verdict(accepted, d, a, wrong_m, wrong_deg, expect_merge):
    if not accepted:
        return "no_merge" if expect_merge else "no_merge (right)"
    if not expect_merge:
        return "WRONG (different buildings)"
    return "WRONG" if (d > wrong_m or a > wrong_deg) else "merged"


def row(name, truth, ya, yb, wrong_m, wrong_deg, expect_merge=True):
    cells = [name]
    for f in (ours, akaze_merge):
        acc, pose, conf, ms = f(ya, yb)
        d, a = err(pose, truth) if truth else (float("nan"), float("nan"))
        v = verdict(acc, d, a, wrong_m, wrong_deg, expect_merge)
        cells += [v, f"{d:.3f}" if truth else "-", f"{a:.2f}" if truth else "-", f"{conf:.2f}", f"{ms:.0f}"]
    print("| " + " | ".join(cells) + " |", flush=True)


def halmstad_yaml(name):
    floor = name.split("_")[0]
    y = os.path.join(TMP, f"{name}.yaml")
    with open(y, "w") as f:
        f.write(f"image: {os.path.join(MAPS, 'halmstad', floor, name + '.png')}\nresolution: 0.05\n"
                "origin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return y


def padded(yaml_path, size):
    """The map padded with unknown to size x size, same frame."""
    image, res, origin = read_yaml(yaml_path)
    img = cv2.imread(os.path.join(os.path.dirname(yaml_path), image), cv2.IMREAD_GRAYSCALE)
    out = np.full((size, size), 205, np.uint8)
    out[size - img.shape[0]:, :img.shape[1]] = img  # keep the lower-left corner
    base = os.path.join(TMP, "pad-" + os.path.basename(yaml_path)[:-5])
    cv2.imwrite(base + ".pgm", out)
    with open(base + ".yaml", "w") as f:
        f.write(f"image: {os.path.basename(base)}.pgm\nresolution: {res}\norigin: [{origin[0]}, {origin[1]}, {origin[2]}]\n"
                "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return base + ".yaml"


def main():
    sys.path.insert(0, os.path.join(MAPS, "halmstad"))
    lp = os.path.join(MAPS, "laser-pairs")
    expect = json.load(open(os.path.join(lp, "expect.json")))
    print("| pair | ours | err m | err deg | conf | ms | AKAZE recipe | err m | err deg | conf | ms |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, c in expect.items():
        row(name, c["pose_b_in_a"], os.path.join(lp, c["a"]), os.path.join(lp, c["b"]), 0.5, 3.0)
    bs = ["intel", "aces", "csail", "freiburg-079"]
    for a in bs:
        for b in bs:
            if a != b:
                row(f"{a}-half-a + {b}-half-b", None, os.path.join(lp, f"{a}-half-a.yaml"),
                    os.path.join(lp, f"{b}-half-b.yaml"), 0, 0, expect_merge=False)
    if "--skip-halmstad" not in sys.argv:
        from fit_reference import reference
        names = [f"KPT4A_0{k}" for k in range(1, 5)]
        for i in range(4):
            for j in range(i + 1, 4):
                ref = reference(names[i], names[j], os.path.join(MAPS, "halmstad"))
                truth = [ref["t_m"][0], ref["t_m"][1], ref["theta_rad"]]
                tol = 2.0 + 2 * ref["rms_px"] * 0.05
                row(f"{names[i]} + {names[j]} (ref rms {ref['rms_px'] * 0.05:.2f} m)", truth,
                    halmstad_yaml(names[i]), halmstad_yaml(names[j]), tol, 5.0)
    ya, yb = padded(os.path.join(lp, "intel-half-a.yaml"), 2000), padded(os.path.join(lp, "intel-half-b.yaml"), 2000)
    times = []
    for _ in range(3):
        acc, pose, conf, ms = ours(ya, yb)
        times.append(ms)
    d, a = err(pose, expect["intel-half"]["pose_b_in_a"])
    print(f"\n2000 x 2000 pair (intel-half padded): merge {min(times):.0f} / {sorted(times)[1]:.0f} ms (min / median of 3), "
          f"{'merged' if acc else 'no_merge'}, off by {d:.3f} m {a:.2f} deg")


if __name__ == "__main__":
    main()
