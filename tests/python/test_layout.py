"""Layouts, sphere-map coordinates and view sets as the C++ defines them."""
import numpy as np

import rsibr

sm = rsibr.sphere_map


def test_the_mirror_inverse_undoes_the_mirror_inside_the_disc():
    rng = np.random.default_rng(4)
    for _ in range(200):
        xy = rng.uniform(-0.7, 0.7, 2)
        assert np.allclose(sm.g_mirror_inv(sm.g_mirror(xy)), xy, atol=1e-12)
        assert np.isclose(np.linalg.norm(sm.g_mirror(xy)), 1)


def test_the_sphere_layout_looks_up_the_mirror_directions_of_its_texel_centres():
    size = 12
    dirs, has = rsibr.Layout.with_size("sphere", size).texel_directions()
    mirrors, inside = sm.mirror_directions(size, size)
    assert np.all(has[inside])
    assert np.allclose(dirs[inside], mirrors[inside], atol=1e-12)
    assert inside.sum() == sum(1 for r in range(size) for c in range(size)
                               if np.linalg.norm(sm.disc_from_pixel((c, r), size, size)) < 1)


def test_located_weights_sum_to_one_and_point_at_the_direction():
    vs = rsibr.ViewSet.named("42")
    rng = np.random.default_rng(8)
    for _ in range(50):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        w = vs.locate(d)
        assert w.inside and w.count == 3 and np.isclose(sum(w.weights), 1)
        p = sum(wi * vs.views[i] for i, wi in zip(w.views, w.weights))
        assert np.allclose(p / np.linalg.norm(p), d, atol=0.2)
    assert len(vs) == 42 and vs.surrounds and vs.triangles.shape == (80, 3)


def test_a_view_frame_is_a_rotation_whose_z_is_the_view():
    v = np.array([0.3, -0.4, 0.8])
    t = rsibr.world_from_view_for(v)
    assert np.allclose(t.T @ t, np.eye(3)) and np.isclose(np.linalg.det(t), 1)
    assert np.allclose(t[:, 2], v / np.linalg.norm(v))


def test_a_cell_centred_latlong_holds_the_environment_at_its_texel_centres():
    # Values linear in rsibr's column and row: the cell-centred texel (i, j) is rsibr's pixel
    # ((i + 1/2)(W - 1)/W, (j + 1/2)(H - 1)/H), interpolated exactly.
    w, h = 16, 8
    pixels = np.zeros((h, w, 3), np.float32)
    pixels[..., 0] = np.arange(w)[None, :]
    pixels[..., 1] = np.arange(h)[:, None]
    pixels[..., 2] = 1
    out = rsibr.to_cell_centred_latlong(rsibr.Environment(pixels), w, h)
    assert out.layout.width == w and out.layout.height == h
    got = np.asarray(out.pixels)
    assert np.allclose(got[..., 0], ((np.arange(w) + 0.5) * (w - 1) / w)[None, :], atol=2e-4)
    assert np.allclose(got[..., 1], ((np.arange(h) + 0.5) * (h - 1) / h)[:, None], atol=2e-4)
    assert np.allclose(got[..., 2], 1)
    # The image's centre looks at +Z (longitude 0, latitude 0).
    d = rsibr.cell_centred_latlong_direction(w / 2 - 0.5, h / 2 - 0.5, w, h)
    assert np.allclose(d, [0, 0, 1], atol=1e-12)
