"""rrt.render, rrt.voxelize, rrt.load and Raster.render against the `rrt`
command line, and the errors of scenes."""

import threading
import time

import numpy as np
import pytest

import rrt
from conftest import BALL, REPO, read_png, run_cli


def test_render_matches_the_cli_png(tmp_path):
    png = tmp_path / "ball.png"
    status, err = run_cli("render", BALL, "-o", png, "--quiet")
    assert status == 0, err
    want = read_png(png)
    got = rrt.render(BALL)
    assert got.shape == (48, 64, 3) and got.dtype == np.uint8
    np.testing.assert_array_equal(got, want)
    # Another size, a TOML scene, supersampled.
    sphere = REPO / "scenes" / "one-sphere.toml"
    status, err = run_cli("render", sphere, "-o", png, "--width", 40, "--height", 30,
                          "--supersample", 2, "--quiet")
    assert status == 0, err
    np.testing.assert_array_equal(rrt.render(sphere, width=40, height=30, supersample=2), read_png(png))


def test_min_weight_is_the_clis(tmp_path):
    png = tmp_path / "deep.png"
    for weight in (0, 0.05):
        status, err = run_cli("render", BALL, "-o", png, "--depth", 12, "--min-weight", weight,
                              "--quiet")
        assert status == 0, err
        np.testing.assert_array_equal(rrt.render(BALL, depth=12, min_weight=weight), read_png(png))
    # The default is the command line's default.
    np.testing.assert_array_equal(rrt.render(BALL, depth=12),
                                  rrt.render(BALL, depth=12, min_weight=2.0 ** -16))


def test_float_output_is_the_linear_image():
    codes = rrt.render(BALL)
    linear = rrt.render(BALL, float=True)
    assert linear.shape == codes.shape and linear.dtype == np.float32
    # The PNG's codes are the sRGB encoding of the linear values.
    v = np.clip(linear.astype(np.float64), 0.0, 1.0)
    srgb = np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)
    np.testing.assert_array_equal(np.floor(srgb * 255 + 0.5).astype(np.uint8), codes)
    assert linear.max() > 0.1


def test_a_saved_raster_renders_the_scene_image(tmp_path):
    path = tmp_path / "ball.rrt"
    raster = rrt.voxelize(BALL, path)
    assert path.exists() and raster.exact
    assert raster.view.resolution == (64, 48)
    direct = rrt.render(BALL)
    np.testing.assert_array_equal(rrt.load(path).render(), direct)
    np.testing.assert_array_equal(raster.render(), direct)
    np.testing.assert_array_equal(rrt.render(path), direct)
    # The same bytes as `rrt voxelize` writes.
    cli = tmp_path / "cli.rrt"
    status, err = run_cli("voxelize", BALL, "-o", cli, "--quiet")
    assert status == 0, err
    assert cli.read_bytes() == path.read_bytes()
    # And as the command line renders from it, from another view.
    png = tmp_path / "b.png"
    status, err = run_cli("render", path, "-o", png, "--from", "3,-2,2", "--at", "0,0,0.5",
                          "--angle", 35, "--quiet")
    assert status == 0, err
    view = rrt.View((3, -2, 2), (0, 0, 0.5), angle=35, resolution=(64, 48))
    np.testing.assert_array_equal(rrt.load(path).render(view), read_png(png))
    np.testing.assert_array_equal(rrt.render(path, view=view), read_png(png))


def test_orbit_frames_are_the_hosts_orbit(tmp_path):
    raster = rrt.voxelize(BALL, tmp_path / "ball.rrt")
    view = raster.view
    assert view.orbit(0, 8) == view and view.orbit(8, 8) == view and view.orbit(1, 8) != view
    quarter = view.orbit(2, 8)
    # A quarter turn about z through `at`: (0, -4) about (0, 0) goes to (4, 0).
    assert np.allclose(quarter.from_, (4, 0, 1.5)) and quarter.at == view.at
    frames = [raster.render(frame=(k, 8), width=32, height=24) for k in range(8)]
    np.testing.assert_array_equal(frames[0], raster.render(width=32, height=24))
    np.testing.assert_array_equal(frames[2], raster.render(quarter, width=32, height=24))
    assert len({f.tobytes() for f in frames}) == 8
    np.testing.assert_array_equal(rrt.render(BALL, frame=(2, 8)), rrt.render(BALL, view=quarter))


def test_the_image_does_not_depend_on_threads(tmp_path):
    raster = rrt.voxelize(BALL, tmp_path / "ball.rrt", threads=2)
    one = raster.render(frame=(3, 7), threads=1)
    np.testing.assert_array_equal(one, raster.render(frame=(3, 7), threads=2))
    np.testing.assert_array_equal(rrt.voxelize(BALL, tmp_path / "one.rrt", threads=1).render(frame=(3, 7)), one)
    assert (tmp_path / "one.rrt").read_bytes() == (tmp_path / "ball.rrt").read_bytes()


def test_scene_errors_carry_the_cli_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        "[camera]\nfrom = [0, -4, 1]\nat = [0, 0, 0]\nangle = 40\nresolution = [8, 8]\n"
        "[material.m]\ncolour = [1, 0, 0]\n"
        "[[object]]\nmaterial = \"m\"\nsphere = { centre = [0, 0, 0], radius = -1 }\n"
    )
    status, err = run_cli("render", bad, "-o", tmp_path / "x.png", "--quiet")
    assert status != 0
    with pytest.raises(rrt.RrtError) as e:
        rrt.render(bad)
    assert "rrt: " + str(e.value) == err.strip()
    assert "bad.toml:10:" in str(e.value) and "radius" in str(e.value)
    with pytest.raises(rrt.RrtError, match="nothing.nff"):
        rrt.render(tmp_path / "nothing.nff")
    with pytest.raises(rrt.RrtError, match="not-a-raster.rrt"):
        (tmp_path / "not-a-raster.rrt").write_bytes(b"RRTRASTR" + bytes(40))
        rrt.load(tmp_path / "not-a-raster.rrt")


@pytest.mark.parametrize(
    "kwargs, arg",
    [
        ({"width": 0}, "width"),
        ({"height": -3}, "height"),
        ({"width": 40000}, "width"),
        ({"supersample": 0}, "supersample"),
        ({"depth": 65}, "depth"),
        ({"min_weight": 2.0}, "min_weight"),
        ({"min_weight": -0.5}, "min_weight"),
        ({"min_weight": float("nan")}, "min_weight"),
        ({"threads": -1}, "threads"),
        ({"frame": (-1, 2)}, "frame"),
        ({"frame": (0, 0)}, "frame"),
        ({"mode": "fast"}, "mode"),
        ({"connectivity": "eight"}, "connectivity"),
        ({"raster": 2}, "raster"),
    ],
)
def test_bad_arguments_raise_value_error_naming_them(kwargs, arg):
    with pytest.raises(ValueError, match=f"^{arg}: "):
        rrt.render(BALL, **kwargs)


def test_bad_views_and_outputs(tmp_path):
    with pytest.raises(ValueError, match="camera: `from` and `at`"):
        rrt.View((1, 2, 3), (1, 2, 3))
    with pytest.raises(ValueError, match="camera: `up`"):
        rrt.View((0, -4, 0), (0, 0, 0), up=(0, 1, 0))
    with pytest.raises(ValueError, match="camera: angle"):
        rrt.View((0, -4, 0), (0, 0, 0), angle=180)
    with pytest.raises(ValueError, match="^from_: "):
        rrt.View((0, float("nan"), 0), (0, 0, 0))
    with pytest.raises(ValueError, match="^resolution: "):
        rrt.View((0, -4, 0), (0, 0, 0), resolution=(0, 10))
    with pytest.raises(ValueError, match=r"--output: .*\.rrt"):
        rrt.voxelize(BALL, tmp_path / "ball.png")
    raster = rrt.voxelize(BALL, tmp_path / "ball.rrt")
    with pytest.raises(ValueError, match=r"^path: .*\.rrt"):
        raster.save(tmp_path / "ball.png")
    with pytest.raises(ValueError, match="^--raster: "):
        rrt.render(tmp_path / "ball.rrt", raster=64)


def test_the_gil_is_released_while_rendering(tmp_path):
    raster = rrt.voxelize(BALL, tmp_path / "ball.rrt")
    ticks, done = [], threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())

    t = threading.Thread(target=count)
    t.start()
    try:
        time.sleep(0.01)
        start = time.perf_counter()
        raster.render(width=256, height=192, supersample=2, threads=1)
        end = time.perf_counter()
    finally:
        done.set()
        t.join()
    during = sum(start < x < end for x in ticks)
    # Held, the GIL would let the counter run only at the switch interval
    # boundaries around the call (at most a handful of ticks).
    assert end - start > 0.02
    assert during > 1000, f"{during} ticks in {end - start:.3f} s"
