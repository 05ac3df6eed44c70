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
