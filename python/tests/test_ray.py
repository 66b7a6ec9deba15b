"""The Ray example: an orbit's frames as Ray tasks on a local cluster of
two workers, each loading the same saved raster, byte-identical to the
frames of one process."""

import pathlib
import sys

import numpy as np
import pytest

ray = pytest.importorskip("ray", reason="ray is not installed (pip install ray): the Ray example is not tested")

import rrt  # noqa: E402
from conftest import BALL  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "examples"))
import ray_orbit  # noqa: E402


@pytest.fixture(scope="module")
def cluster():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def test_orbit_frames_on_ray_equal_one_process(cluster, tmp_path):
    path = tmp_path / "ball.rrt"
    rrt.voxelize(BALL, path)
    frames = ray_orbit.orbit_on_ray(path, 6, 48, 36)
    local = ray_orbit.orbit_in_process(path, 6, 48, 36)
    assert len(frames) == 6
    for k, (a, b) in enumerate(zip(frames, local)):
        assert a.shape == (36, 48, 3) and a.dtype == np.uint8
        np.testing.assert_array_equal(a, b, err_msg=f"frame {k}")
    assert len({f.tobytes() for f in frames}) == 6
    # Two workers took part.
    nodes = ray.nodes()
    assert sum(n["Resources"].get("CPU", 0) for n in nodes if n["Alive"]) == 2
