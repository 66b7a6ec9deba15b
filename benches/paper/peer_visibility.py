#!/usr/bin/env python3
"""Who sees the right object where two renders of an NFF scene disagree.

    python3 benches/paper/peer_visibility.py SCENE.nff OURS.ppm PEER.ppm

OURS and PEER are renders of SCENE at the same size with the NFF camera
and linear 8-bit output (`rrt render SCENE -o OURS.ppm --linear`,
`embree_nff -o PEER.ppm SCENE`). For every pixel where the two differ by
more than `--threshold` levels in some channel and exactly one of them
shows the background, the pixel's primary ray is cast in double precision
against every sphere, open cone and polygon (the region its outline
bounds, by the even-odd rule, non-convex ones too), and the render that
agrees with it on whether the
ray hits anything is counted right. The PSNR of OURS against PEER is
printed as is and with those pixels of PEER replaced by OURS where the
double-precision ray sides with OURS. Needs numpy.
"""

import argparse
import math
import sys

import numpy as np


def read_ppm(path):
    with open(path, "rb") as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end : end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b"P6" or int(fields[3]) != 255:
        sys.exit(f"{path}: not an 8-bit binary PPM")
    w, h = int(fields[1]), int(fields[2])
    pixels = np.frombuffer(data[pos + 1 : pos + 1 + 3 * w * h], dtype=np.uint8)
    return pixels.reshape(h, w, 3).astype(np.int64)


def read_nff(path):
    view, spheres, cones, tris, outlines, bg = {}, [], [], [], [], (0.0, 0.0, 0.0)
    lines = open(path).read().split("\n")
    i = 0
    while i < len(lines):
        t = lines[i].split()
        i += 1
        if not t:
            continue
        k = t[0]
        if k in ("from", "at", "up"):
            view[k] = np.array([float(x) for x in t[1:4]])
        elif k == "angle":
            view["angle"] = float(t[1])
        elif k == "b":
            bg = tuple(float(x) for x in t[1:4])
        elif k == "s":
            spheres.append([float(x) for x in t[1:5]])
        elif k == "c":
            if len(t) >= 9:
                v = [float(x) for x in t[1:9]]
            else:
                v = [float(x) for x in lines[i].split()[:4] + lines[i + 1].split()[:4]]
                i += 2
            cones.append(v)
        elif k in ("p", "pp"):
            n = int(t[1])
            vs = [[float(x) for x in lines[i + j].split()[:3]] for j in range(n)]
            i += n
            if n == 3:
                tris.append(vs)
            else:
                outlines.append(np.array(vs))
    return (
        view,
        np.array(spheres).reshape(-1, 4),
        np.array(cones).reshape(-1, 8),
        np.array(tris).reshape(-1, 3, 3),
        outlines,
        bg,
    )


def meets_outline(o, d, v):
    """Whether the ray o + t d, t > 0, meets the polygon v (its plane by
    Newell's normal; inside by the even-odd rule in the plane across the
    normal's largest component)."""
    w = np.roll(v, -1, axis=0)
    n = np.array([
        ((v[:, 1] - w[:, 1]) * (v[:, 2] + w[:, 2])).sum(),
        ((v[:, 2] - w[:, 2]) * (v[:, 0] + w[:, 0])).sum(),
        ((v[:, 0] - w[:, 0]) * (v[:, 1] + w[:, 1])).sum(),
    ])
    dn = d @ n
    if dn == 0:
        return False
    t = ((v[0] - o) @ n) / dn
    if t <= 1e-9:
        return False
    k = int(np.argmax(np.abs(n)))
    i, j = [a for a in range(3) if a != k]
    p = o + t * d
    x, y = v[:, i], v[:, j]
    xn, yn = w[:, i], w[:, j]
    crosses = (y > p[j]) != (yn > p[j])
    with np.errstate(divide="ignore", invalid="ignore"):
        at = x + (p[j] - y) * (xn - x) / (yn - y)
    return bool(np.count_nonzero(crosses & (p[i] < at)) % 2)


def hits(o, d, spheres, cones, tris, outlines):
    """Whether the ray o + t d, t > 0, meets any primitive."""
    if len(spheres):
        oc = o - spheres[:, :3]
        b = oc @ d
        perp = oc - np.outer(b, d)
        disc = spheres[:, 3] ** 2 - (perp * perp).sum(1)
        ok = disc >= 0
        far = -b + np.sqrt(np.where(ok, disc, 0))
        if np.any(ok & (far > 1e-9)):
            return True
    if len(cones):
        base, rb, apex, ra = cones[:, :3], cones[:, 3], cones[:, 4:7], cones[:, 7]
        axis = apex - base
        length = np.linalg.norm(axis, axis=1)
        w = axis / length[:, None]
        k = (ra - rb) / length
        q0 = o - base
        dw, qw = w @ d, (q0 * w).sum(1)
        dp, qp = d - dw[:, None] * w, q0 - qw[:, None] * w
        a = (dp * dp).sum(1) - k * k * dw * dw
        bb = 2 * ((dp * qp).sum(1) - k * dw * (rb + k * qw))
        c = (qp * qp).sum(1) - (rb + k * qw) ** 2
        disc = bb * bb - 4 * a * c
        ok = (disc >= 0) & (a != 0)
        s = np.sqrt(np.where(ok, disc, 0))
        with np.errstate(divide="ignore", invalid="ignore"):
            for t in ((-bb - s) / (2 * a), (-bb + s) / (2 * a)):
                h = qw + t * dw
                if np.any(ok & (t > 1e-9) & (h >= 0) & (h <= length)):
                    return True
    if len(tris):
        a0, e1, e2 = tris[:, 0], tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
        p = np.cross(d, e2)
        det = (e1 * p).sum(1)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1 / det
            s = o - a0
            u = (s * p).sum(1) * inv
            q = np.cross(s, e1)
            v = (q @ d) * inv
            t = (q * e2).sum(1) * inv
        if np.any((det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-9)):
            return True
    return any(meets_outline(o, d, v) for v in outlines)


def psnr(a, b):
    mse = ((a - b) ** 2).mean()
    return math.inf if mse == 0 else 10 * math.log10(255**2 / mse)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("ours")
    ap.add_argument("peer")
    ap.add_argument("--threshold", type=int, default=8)
    args = ap.parse_args()
    view, spheres, cones, tris, outlines, bg = read_nff(args.scene)
    ours, peer = read_ppm(args.ours), read_ppm(args.peer)
    if ours.shape != peer.shape:
        sys.exit("the two images differ in size")
    h, w, _ = ours.shape
    o = view["from"]
    fwd = view["at"] - o
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, view["up"])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    pitch = 2 * math.tan(math.radians(view["angle"]) / 2) / (max(h, 2) - 1)
    background = np.array([round(255 * min(max(c, 0.0), 1.0)) for c in bg])
    is_bg = lambda px: np.abs(px - background).max() <= 2
    fixed = peer.copy()
    counts = {"ours": 0, "peer": 0, "both hit": 0}
    for y, x in zip(*np.nonzero(np.abs(ours - peer).max(axis=2) > args.threshold)):
        a, b = is_bg(ours[y, x]), is_bg(peer[y, x])
        if a == b:
            counts["both hit"] += not a
            continue
        d = fwd + right * ((x - (w - 1) * 0.5) * pitch) + up * (((h - 1) * 0.5 - y) * pitch)
        hit = hits(o, d / np.linalg.norm(d), spheres, cones, tris, outlines)
        if hit != a:
            counts["ours"] += 1
            fixed[y, x] = ours[y, x]
        else:
            counts["peer"] += 1
    print(
        f"pixels differing by more than {args.threshold}, one of them background: "
        f"ours right {counts['ours']}, peer right {counts['peer']}; "
        f"both a hit: {counts['both hit']}"
    )
    print(f"PSNR {psnr(ours, peer):.2f} dB; with the peer's pixels the double-precision ray refutes replaced: {psnr(ours, fixed):.2f} dB")


if __name__ == "__main__":
    main()
