"""alpha=True: (H, W, 4) images whose fourth channel is the coverage (1 −
the transmittance of the pixel's rays to the background) and whose colour
is straight, for scenes, saved rasters and volumes rendered directly."""

import numpy as np

import rrt
from conftest import BALL, sphere_density

# The background of ball.nff (`b 0.1 0.1 0.15`).
BALL_BACKGROUND = np.array([0.1, 0.1, 0.15], np.float32)


def srgb_codes(linear):
    """The 8-bit sRGB codes of linear values, as rrt encodes them."""
    v = np.clip(np.asarray(linear, np.float64), 0.0, 1.0)
    e = np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)
    return np.floor(e * 255 + 0.5).astype(np.uint8)


def assert_over_background_is_the_image(rgba, rgb, background):
    """Linear straight colour over the background is the 3-channel image."""
    a = rgba[..., 3:].astype(np.float64)
    over = rgba[..., :3] * a + background * (1 - a)
    np.testing.assert_allclose(over, rgb, rtol=0, atol=2e-5)


def test_geometry_is_covered_and_the_background_is_not():
    rgb = rrt.render(BALL)
    img = rrt.render(BALL, alpha=True)
    assert img.shape == (48, 64, 4) and img.dtype == np.uint8
    a = img[..., 3]
    # One ray per pixel: each pixel is covered or not.
    assert set(np.unique(a)) == {0, 255}
    # The image centre looks at a point inside the opaque sphere; the top
    # rows look over the floor into the background.
    assert a[24, 32] == 255 and a[0].max() == 0
    assert 0.3 < (a == 255).mean() < 0.95
    # The colour channels are the 3-channel image, the background's colour
    # where nothing is covered.
    np.testing.assert_array_equal(img[..., :3], rgb)
    assert (img[a == 0][:, :3] == srgb_codes(BALL_BACKGROUND)).all()
    # In floats: coverage 0 or 1, the colour the linear image.
    f = rrt.render(BALL, alpha=True, float=True)
    assert f.shape == (48, 64, 4) and f.dtype == np.float32
    np.testing.assert_array_equal(f[..., :3], rrt.render(BALL, float=True))
    np.testing.assert_array_equal(f[..., 3], a / 255)
    # The codes are the floats' sRGB codes and their linear coverage.
    np.testing.assert_array_equal(img[..., :3], srgb_codes(f[..., :3]))


def test_supersampled_edges_are_partly_covered_the_same_on_any_thread_count(tmp_path):
    rgb = rrt.render(BALL, supersample=2, float=True)
    one = rrt.render(BALL, supersample=2, alpha=True, threads=1)
    two = rrt.render(BALL, supersample=2, alpha=True, threads=2)
    assert one.tobytes() == two.tobytes()
    f1 = rrt.render(BALL, supersample=2, alpha=True, float=True, threads=1)
    f2 = rrt.render(BALL, supersample=2, alpha=True, float=True, threads=2)
    assert f1.tobytes() == f2.tobytes()
    # Four rays per pixel: a quarter of a pixel at a time, some on edges.
    assert set(np.unique(f1[..., 3])) == {0.0, 0.25, 0.5, 0.75, 1.0}
    assert set(np.unique(one[..., 3])) == {0, 64, 128, 191, 255}
    edge = (f1[..., 3] > 0) & (f1[..., 3] < 1)
    assert edge.sum() > 10
    # Where a pixel is wholly covered or wholly background the colour is
    # the 3-channel image's; on the edges, straight colour over the
    # background gives it.
    whole = ~edge
    np.testing.assert_array_equal(f1[..., :3][whole], rgb[whole])
    np.testing.assert_array_equal(one[..., :3][whole], rrt.render(BALL, supersample=2)[whole])
    assert_over_background_is_the_image(f1, rgb, BALL_BACKGROUND)
    # A saved raster gives the same RGBA.
    raster = rrt.voxelize(BALL, tmp_path / "ball.rrt")
    assert raster.render(supersample=2, alpha=True).tobytes() == one.tobytes()


def test_a_translucent_volume_is_partly_covered():
    d = sphere_density()
    faint = {"opacity": [[0.0, 0.0], [1.0, 0.05]], "render": "direct"}
    bg = (0.2, 0.3, 0.4)
    kwargs = dict(width=48, height=48, transfer=faint, background=bg)
    rgb = rrt.render_volume(d, float=True, **kwargs)
    f = rrt.render_volume(d, alpha=True, float=True, threads=1, **kwargs)
    assert f.shape == (48, 48, 4)
    a = f[..., 3]
    # Beside the volume nothing; through it the opacity composited, never
    # opaque at 5 % per sample spacing.
    assert a[0, 0] == 0 and a[-1, -1] == 0
    assert 0.2 < a.max() < 0.99
    assert ((a > 0) & (a < 1)).mean() > 0.1
    assert_over_background_is_the_image(f, rgb, np.array(bg, np.float32))
    # The same bytes on two threads, in floats and in codes.
    assert rrt.render_volume(d, alpha=True, float=True, threads=2, **kwargs).tobytes() == f.tobytes()
    codes = rrt.render_volume(d, alpha=True, threads=1, **kwargs)
    assert codes.tobytes() == rrt.render_volume(d, alpha=True, threads=2, **kwargs).tobytes()
    np.testing.assert_array_equal(codes[..., 3], np.floor(a.astype(np.float64) * 255 + 0.5))
    # Opaque enough in the core: compositing ends there, the pixel covered.
    dense = {"opacity": [[0.0, 0.0], [0.5, 0.3], [0.9, 1.0]], "render": "direct"}
    a = rrt.render_volume(d, alpha=True, float=True, width=48, height=48, transfer=dense)[..., 3]
    assert a.max() == 1.0 and a[0, 0] == 0
