"""rrt.render_volume and rrt.volume: numpy arrays in, images out; bad
arrays and transfer functions refused with a ValueError naming them."""

import numpy as np
import pytest

import rrt
from conftest import sphere_density


def test_a_sphere_density_renders_its_structure():
    d = sphere_density()
    img = rrt.render_volume(d, width=64, height=48)
    assert img.shape == (48, 64, 3) and img.dtype == np.uint8
    background = img[0, 0]
    covered = np.any(img != background, axis=2)
    # Both balls are in the picture, framed with room for every frame of an
    # orbit: inside the image, not filling it.
    assert 0.05 < covered.mean() < 0.8
    assert not covered[0].any() and not covered[-1].any()
    # Shaded and coloured by the default ramp: many distinct colours.
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 50
    linear = rrt.render_volume(d, width=64, height=48, float=True)
    assert linear.shape == (48, 64, 3) and linear.dtype == np.float32
    assert np.array_equal(linear[0, 0], linear[-1, -1])
    assert (linear[covered].sum(axis=1) > 0).all()


def test_every_sample_type_gives_the_same_shape():
    base = rrt.render_volume(sphere_density(dtype=np.float32), width=32, height=32)
    for dtype in (np.uint8, np.int16, np.uint16, np.float64):
        img = rrt.render_volume(sphere_density(dtype=dtype), width=32, height=32)
        covered = np.any(img != img[0, 0], axis=2)
        # The same iso-surface up to the quantisation of the samples.
        assert abs(covered.mean() - np.any(base != base[0, 0], axis=2).mean()) < 0.03, dtype


def test_transfer_functions_map_onto_the_volume_keys():
    d = sphere_density()
    red = {"iso": 0.5, "colours": [[0.0, 1, 0, 0], [1.0, 1, 0, 0]]}
    img = rrt.render_volume(d, width=48, height=48, transfer=red, float=True)
    lit = img.sum(axis=2) > img[0, 0].sum() + 0.05
    assert lit.any()
    assert (img[lit][:, 1] < 0.2 * img[lit][:, 0] + 0.05).all(), "red and its highlight only"
    # A higher iso-value shows the inner core only: fewer covered pixels.
    def cover(transfer):
        img = rrt.render_volume(d, width=48, height=48, transfer=transfer)
        return np.any(img != img[0, 0], axis=2).mean()

    assert cover({"iso": 0.8}) < cover({"iso": 0.2})
    # An opacity ramp alone decides (cut at one half today).
    assert cover({"opacity": [[0.0, 0.0], [0.4, 1.0]]}) == cover({"iso": 0.2})


def test_camera_frame_and_a_saved_volume(tmp_path):
    d = sphere_density()
    r = rrt.volume(d, spacing=(1, 1, 2), width=40, height=30)
    assert r.dims[2] > r.dims[0]
    view = r.view
    assert view.resolution == (40, 30)
    np.testing.assert_array_equal(r.render(), rrt.render_volume(d, spacing=(1, 1, 2), width=40, height=30))
    turned = rrt.render_volume(d, spacing=(1, 1, 2), width=40, height=30, frame=(1, 4))
    np.testing.assert_array_equal(turned, r.render(frame=(1, 4)))
    assert not np.array_equal(turned, r.render())
    # A camera of one's own (the light goes beside its eye).
    cam = rrt.View((20, -60, 40), (20, 20, 40), resolution=(40, 30))
    mine = rrt.render_volume(d, spacing=(1, 1, 2), camera=cam)
    assert mine.shape == (30, 40, 3)
    np.testing.assert_array_equal(mine, rrt.volume(d, spacing=(1, 1, 2), camera=cam).render())
    assert not np.array_equal(mine, r.render())
    path = tmp_path / "density.rrt"
    assert r.save(path) == path.stat().st_size
    np.testing.assert_array_equal(rrt.load(path).render(frame=(3, 4)), r.render(frame=(3, 4)))


BAD_ARRAYS = [
    (np.zeros((8, 8, 8), np.int64), "dtype int64"),
    (np.zeros((8, 8, 8), np.complex64), "dtype complex64"),
    (np.zeros((8, 8, 8), bool), "dtype bool"),
    (np.zeros((8, 8), np.float32), "3 dimensions"),
    (np.zeros((2, 8, 8, 8), np.float32), "3 dimensions"),
    (np.zeros((8, 8, 16), np.float32)[:, :, ::2], "C-contiguous"),
    (np.zeros((8, 9, 10), np.float32).T, "C-contiguous"),
    (np.zeros((0, 8, 8), np.float32), "each dimension must be 1 to"),
    (np.zeros((1, 1, 70000), np.uint8), "each dimension must be 1 to"),
    ([[[0.0, 1.0]]], "expected a numpy array, found list"),
    (np.full((8, 8, 8), 3.0, np.float32), "default transfer function"),
]


@pytest.mark.parametrize("array, message", BAD_ARRAYS, ids=[m for _, m in BAD_ARRAYS])
def test_bad_arrays_raise_value_error(array, message):
    with pytest.raises(ValueError, match=f"^array: .*{message}"):
        rrt.render_volume(array)


def test_absurd_sizes_are_refused_before_copying():
    try:
        # Not touched: the size is checked before a sample is read.
        huge = np.empty((1025, 2048, 2048), np.uint8)
    except MemoryError:
        pytest.skip("this machine cannot reserve 4 GiB of address space for the array")
    with pytest.raises(ValueError, match="^array: .*more than the limit of 4294967296 bytes"):
        rrt.render_volume(huge)


BAD_TRANSFERS = [
    ({"opacity": [[0.1, 0.0], [0.1, 1.0]]}, "opacity[1][0]: expected values that increase along the ramp"),
    ({"opacity": [[0.5, 0.0], [0.2, 1.0]]}, "opacity[1][0]: expected values that increase"),
    ({"opacity": [[0.0, 0.0], [0.5, 1.5]]}, "opacity[1]: expected [value, alpha] with alpha in [0, 1]"),
    ({"opacity": [[0.0, -0.1]]}, "opacity[0]: expected [value, alpha]"),
    ({"iso": 0.5, "colours": [[0.0, 1, 0, 0], [1.0, 0, 2, 0]]}, "colours[1]: expected [value, r, g, b] with channels in [0, 1]"),
    ({"iso": 0.5, "colours": [[0.0, 0, 0, 0], [0.5, 1, 1, 1], [0.4, 1, 1, 1]]}, "colours[2][0]: expected values that increase"),
    ({"iso": float("nan")}, "iso: classification: iso-value NaN is not finite"),
    ({"colours": [[0.0, 0, 0, 0]]}, "iso: missing: give an iso-value, an opacity ramp, or both"),
    ({"iso": 0.5, "opacity": [[0, 1, 2]]}, "opacity: expected a list of [value, alpha] points"),
    ({"iso": 0.5, "colors": []}, 'unknown key "colors"; expected iso, opacity, colours'),
]


@pytest.mark.parametrize("transfer, message", BAD_TRANSFERS, ids=[m.split(":")[0] for _, m in BAD_TRANSFERS])
def test_bad_transfer_functions_name_the_point(transfer, message):
    with pytest.raises(ValueError) as e:
        rrt.render_volume(sphere_density(8), transfer=transfer)
    assert str(e.value).startswith("transfer: " + message), str(e.value)


@pytest.mark.parametrize(
    "kwargs, arg",
    [
        ({"spacing": (1, 0, 1)}, "spacing"),
        ({"spacing": (1, float("inf"), 1)}, "spacing"),
        ({"background": (0, 0, 2)}, "background"),
        ({"width": 0}, "width"),
        ({"frame": (-1, 4)}, "frame"),
        ({"raster": 100000}, "raster"),
    ],
)
def test_bad_volume_arguments_name_them(kwargs, arg):
    with pytest.raises(ValueError, match=f"^{arg}: "):
        rrt.render_volume(sphere_density(8), **kwargs)


def test_a_volume_rendered_directly_renders_and_is_not_saved(tmp_path):
    d = sphere_density()
    glow = {"opacity": [[0.0, 0.0], [1.0, 0.3]], "render": "direct"}
    img = rrt.render_volume(d, width=32, height=32, transfer=glow, float=True)
    r = rrt.volume(d, width=32, height=32, transfer=glow)
    np.testing.assert_array_equal(r.render(float=True), img)
    # Through the glow the background shows, dimmed: neither the
    # background nor an opaque surface.
    centre, corner = img[16, 16], img[0, 0]
    assert not np.allclose(centre, corner)
    with pytest.raises(rrt.RrtError, match="rendered directly"):
        r.save(tmp_path / "glow.rrt")
    assert not (tmp_path / "glow.rrt").exists()
