"""rsibr.blend is the blend of `rsibr blend`: the same bytes for the same inputs."""
import numpy as np
import pytest

import rsibr
from conftest import random_map_set


@pytest.mark.parametrize("warp", ["precomputed", "exact", "tessellated", "double-indirection"])
def test_a_blend_equals_the_command_line_blend_bit_for_bit(tmp_path, cli, warp):
    rng = np.random.default_rng({"precomputed": 1, "exact": 2, "tessellated": 3, "double-indirection": 4}[warp])
    maps = random_map_set(rng, "icosa", size=32, captured=warp == "exact")
    path = tmp_path / "maps.exr"
    rsibr.write_map_set(str(path), maps)
    for k in range(3):
        view = rng.normal(size=3)
        view /= np.linalg.norm(view)
        out = tmp_path / f"novel{k}.exr"
        cli("blend", path, out, "--view", *view, "--warp", warp, "--size", 40)
        ours = rsibr.blend(rsibr.read_map_set(str(path)), view, warp=warp, size=40)
        theirs = rsibr.read_map_set(str(out))[0]
        assert ours.rgb.shape == (40, 40, 3)
        assert np.array_equal(ours.rgb, theirs.rgb)
        assert np.array_equal(ours.weight, theirs.confidence)
        assert np.allclose(ours.world_from_view, theirs.world_from_view, atol=1e-6)


def test_a_blend_at_a_source_view_reproduces_that_source():
    rng = np.random.default_rng(5)
    maps = random_map_set(rng, "octa", size=16)
    r = rsibr.blend(maps, maps[2].view, up=maps[2].world_from_view[:, 1])
    assert r.located.views[np.argmax(r.located.weights)] == 2 and max(r.located.weights) == 1.0
    _, inside = rsibr.sphere_map.normals(16, 16)
    # Exact up to the per-texel renormalisation (float32 rounding).
    assert np.allclose(r.rgb[inside], maps[2].rgb[inside], rtol=1e-5)
    assert np.all(r.rgb[~inside] == 0)


def test_an_engine_gives_blends_bytes_for_every_view_of_a_turntable():
    rng = np.random.default_rng(7)
    maps = random_map_set(rng, "icosa", size=24)
    engine = rsibr.BlendEngine(maps)
    for k in range(4):
        a = 2 * np.pi * k / 4
        view = np.array([np.cos(a), 0.3, np.sin(a)])
        view /= np.linalg.norm(view)
        ours = engine.map(view, size=20)
        theirs = rsibr.blend(maps, view, size=20)
        assert np.array_equal(ours.rgb, theirs.rgb)
        assert np.array_equal(ours.weight, theirs.weight)


def test_engine_radiance_at_a_destination_view_equals_the_destination_map():
    rng = np.random.default_rng(8)
    maps = random_map_set(rng, "icosa", size=24)
    engine = rsibr.BlendEngine(maps)
    view = np.array([0.3, 0.5, 0.8]) / np.linalg.norm([0.3, 0.5, 0.8])
    r = engine.map(view, warp="exact")
    normals, inside = rsibr.sphere_map.normals(24, 24)
    n = normals[inside] @ r.world_from_view.T
    v = np.tile(view, (n.shape[0], 1))
    L, w = engine.radiance(v, n)
    assert L.shape == (n.shape[0], 3) and w.shape == (n.shape[0],)
    assert np.all(np.isfinite(L)) and np.all((w >= 0) & (w <= 1))
    # The map warps in float, radiance() in double: equal to float rounding of the disc point.
    assert np.allclose(L, r.rgb[inside], rtol=1e-4, atol=1e-5)
    assert np.allclose(w, r.weight[inside], atol=1e-4)


def test_engine_radiance_rejects_mismatched_rows():
    rng = np.random.default_rng(9)
    engine = rsibr.BlendEngine(random_map_set(rng, "icosa", size=8))
    with pytest.raises(ValueError):
        engine.radiance(np.zeros((3, 3)) + [0, 0, 1], np.zeros((2, 3)) + [0, 0, 1])


def test_engine_radiance_at_a_zero_footprint_is_the_point_lookup_and_a_wide_one_smooths():
    rng = np.random.default_rng(10)
    maps = random_map_set(rng, "icosa", size=32)  # noise per texel
    engine = rsibr.BlendEngine(maps)
    n = rng.normal(size=(400, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = n + 0.3 * rng.normal(size=(400, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    L, w = engine.radiance(v, n)
    zero = np.zeros_like(n)
    L0, w0 = engine.radiance(v, n, dn_dx=zero, dn_dy=zero)
    assert np.array_equal(L0, L) and np.array_equal(w0, w)
    # A footprint of about a quarter of the disc: the noise averages out towards each map's mean.
    a = np.cross(n, [0.0, 1.0, 0.0]) + 1e-3
    b = np.cross(n, a)
    a *= 0.5 / np.linalg.norm(a, axis=1, keepdims=True)
    b *= 0.5 / np.linalg.norm(b, axis=1, keepdims=True)
    Lw, ww = engine.radiance(v, n, dn_dx=a, dn_dy=b)
    assert np.all(np.isfinite(Lw)) and np.all((ww >= 0) & (ww <= 1))
    assert Lw.var(axis=0).sum() < 0.5 * L.var(axis=0).sum()


def test_engine_radiance_rejects_half_or_mismatched_footprints():
    rng = np.random.default_rng(11)
    engine = rsibr.BlendEngine(random_map_set(rng, "icosa", size=8))
    v = np.zeros((3, 3)) + [0, 0, 1]
    with pytest.raises(ValueError):
        engine.radiance(v, v, dn_dx=np.zeros((3, 3)))
    with pytest.raises(ValueError):
        engine.radiance(v, v, dn_dx=np.zeros((2, 3)), dn_dy=np.zeros((2, 3)))
    with pytest.raises(ValueError):
        engine.radiance(v, v, dn_dx=np.full((3, 3), np.nan), dn_dy=np.zeros((3, 3)))
