"""A turntable on Ray: the frames of an orbit around a saved raster, each
rendered as a Ray task that loads the same raster file.

    python python/examples/ray_orbit.py SCENE_OR_RASTER [--frames 16] [--size 256x256]
        [--address auto|ray://HOST:10001] [--out orbit.npy]

Without --address it starts a local Ray instance on this machine's cores.
A scene (NFF or TOML) is voxelized once to a raster beside --out first; on
a real cluster the raster path must be readable by every worker (a shared
file system). The frames are byte-identical to a single-process render of
the same views (`Raster.render(frame=(k, n))`), whatever the cluster.
"""

import argparse
import pathlib
import time

import numpy as np
import ray

import rrt


@ray.remote(num_cpus=1)
def render_frame(raster_path, k, n, width, height):
    """Frame k of an n-frame orbit of the raster's own view, on one thread
    (Ray schedules one task per core)."""
    return rrt.load(raster_path).render(frame=(k, n), width=width, height=height, threads=1)


def orbit_on_ray(raster_path, frames, width, height):
    """The orbit's frames, rendered as Ray tasks (ray.init must have been
    called), in frame order."""
    path = str(pathlib.Path(raster_path).resolve())
    tasks = [render_frame.remote(path, k, frames, width, height) for k in range(frames)]
    return ray.get(tasks)


def orbit_in_process(raster_path, frames, width, height, threads=0):
    """The same frames in this process."""
    raster = rrt.load(raster_path)
    return [raster.render(frame=(k, frames), width=width, height=height, threads=threads)
            for k in range(frames)]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", help="an NFF or TOML scene, or a raster saved by rrt voxelize (.rrt)")
    p.add_argument("--frames", type=int, default=16)
    p.add_argument("--size", default="256x256", help="WIDTHxHEIGHT")
    p.add_argument("--address", default=None, help="a Ray cluster (auto, ray://host:10001); default: a local one")
    p.add_argument("--out", default="orbit.npy", help="the frames as one (N, H, W, 3) uint8 array")
    p.add_argument("--check", action="store_true", help="render in this process too and compare the bytes")
    a = p.parse_args()
    width, height = (int(v) for v in a.size.lower().split("x"))
    out = pathlib.Path(a.out)
    raster = pathlib.Path(a.scene)
    if raster.suffix.lower() != ".rrt":
        raster = out.with_suffix(".rrt")
        rrt.voxelize(a.scene, raster)
    ray.init(address=a.address)
    t = time.perf_counter()
    frames = orbit_on_ray(raster, a.frames, width, height)
    print(f"{a.frames} frames {width}×{height} on Ray: {time.perf_counter() - t:.2f} s")
    np.save(out, np.stack(frames))
    if a.check:
        t = time.perf_counter()
        local = orbit_in_process(raster, a.frames, width, height)
        print(f"in this process: {time.perf_counter() - t:.2f} s")
        same = all(np.array_equal(x, y) for x, y in zip(frames, local))
        print("byte-identical" if same else "DIFFERENT")
        if not same:
            raise SystemExit(1)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
