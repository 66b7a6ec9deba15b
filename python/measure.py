"""Measures the Python package against the command line (run it in the
environment tests/run makes, with a release `rrt` built):

    cargo build --release -p rrt-host
    target/python-venv/bin/python python/measure.py [--rounds 7]

1. One render of scenes/one-sphere.toml, 256²: the `rrt render` process,
   rrt.render in a running interpreter, and a Python process that imports
   rrt and renders.
2. An orbit of 16 frames from a saved raster (the built-in 91-sphereflake,
   256²) in one process, on 1 and 2 threads: frames per second.
3. The same 16 frames as Ray tasks on a local cluster of two workers,
   against the single process (2 threads).

Medians of interleaved rounds; prints a table, or with --json one JSON
object (times in seconds) for the paper bench's Python section:

    {"rounds", "frames",
     "render": {"cli", "call", "process"},
     "orbit": {"raster", "side", "fps": {"1", "2"}},
     "ray": null (ray not installed) or
            {"workers", "ray", "process", "startup", "identical"}}"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import rrt

REPO = pathlib.Path(__file__).resolve().parents[1]
SCENE = REPO / "scenes" / "one-sphere.toml"


def timed(f):
    t = time.perf_counter()
    r = f()
    return time.perf_counter() - t, r


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--rounds", type=int, default=7)
    p.add_argument("--frames", type=int, default=16)
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    a = p.parse_args()
    say = (lambda *_: None) if a.json else print
    out = {"rounds": a.rounds, "frames": a.frames}
    cli = pathlib.Path(os.environ.get("RRT_CLI", REPO / "target" / "release" / "rrt"))
    tmp = pathlib.Path(tempfile.mkdtemp())
    png = tmp / "one.png"
    py_process = [sys.executable, "-c", f"import rrt; rrt.render({str(SCENE)!r})"]

    times = {"cli": [], "call": [], "py": []}
    for _ in range(a.rounds):
        times["cli"].append(timed(lambda: subprocess.run([str(cli), "render", str(SCENE), "-o", str(png), "-q"], check=True))[0])
        times["call"].append(timed(lambda: rrt.render(SCENE))[0])
        times["py"].append(timed(lambda: subprocess.run(py_process, check=True))[0])
    med = {k: statistics.median(v) for k, v in times.items()}
    out["render"] = {"cli": med["cli"], "call": med["call"], "process": med["py"]}
    say(f"one render, one-sphere.toml 256², medians of {a.rounds}:")
    say(f"  rrt render (process)                 {med['cli'] * 1000:8.1f} ms")
    say(f"  rrt.render (call in an interpreter)  {med['call'] * 1000:8.1f} ms")
    say(f"  python -c 'import rrt; rrt.render'   {med['py'] * 1000:8.1f} ms")

    raster_path = tmp / "balls2.rrt"
    rrt.voxelize(None, raster_path)
    raster = rrt.load(raster_path)
    n = a.frames
    fps = {1: [], 2: []}
    for _ in range(max(1, a.rounds // 2)):
        for threads in (1, 2):
            t, _ = timed(lambda: [raster.render(frame=(k, n), width=256, height=256, threads=threads) for k in range(n)])
            fps[threads].append(n / t)
    out["orbit"] = {
        "raster": list(raster.dims),
        "side": 256,
        "fps": {str(t): statistics.median(fps[t]) for t in (1, 2)},
    }
    say(f"orbit of {n} frames from a saved raster (balls2, 256²), frames per second:")
    for threads in (1, 2):
        say(f"  {threads} thread{'s' if threads > 1 else ' '}  {statistics.median(fps[threads]):6.2f} fps")

    out["ray"] = None
    try:
        import ray
    except ImportError:
        say("ray is not installed: no Ray figures")
        if a.json:
            print(json.dumps(out))
        return
    sys.path.insert(0, str(REPO / "python" / "examples"))
    import ray_orbit

    t_init, _ = timed(lambda: ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False))
    ray_times, local_times = [], []
    ray_orbit.orbit_on_ray(raster_path, 2, 32, 32)  # workers started and rrt imported
    for _ in range(max(1, a.rounds // 2)):
        t, frames = timed(lambda: ray_orbit.orbit_on_ray(raster_path, n, 256, 256))
        ray_times.append(t)
        t, local = timed(lambda: ray_orbit.orbit_in_process(raster_path, n, 256, 256, threads=2))
        local_times.append(t)
        assert all(np.array_equal(x, y) for x, y in zip(frames, local)), "Ray frames differ"
    ray.shutdown()
    r, s = statistics.median(ray_times), statistics.median(local_times)
    out["ray"] = {"workers": 2, "ray": r, "process": s, "startup": t_init, "identical": True}
    say(f"{n} frames 256² on Ray (2 workers, 1 thread each) against one process (2 threads):")
    say(f"  Ray {r:.2f} s, one process {s:.2f} s, ratio {r / s:.2f} (Ray start-up {t_init:.1f} s, not counted); frames byte-identical")
    if a.json:
        print(json.dumps(out))


if __name__ == "__main__":
    main()
