"""Map sets and environments through files and numpy: bits and attributes survive, memory is shared."""
import numpy as np
import pytest

import rsibr
from conftest import random_map_set


def test_a_map_set_survives_a_file_round_trip_bit_for_bit(tmp_path):
    rng = np.random.default_rng(7)
    maps = random_map_set(rng, "42", size=20, captured=True)
    maps[3].warp = "normal"
    for v in maps:  # a set shares one albedo table
        v.albedo = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    maps[0].clipped = np.zeros((20, 20), np.float32)
    path = tmp_path / "maps.exr"
    rsibr.write_map_set(str(path), maps)
    assert rsibr.is_map_set_file(str(path))
    back = rsibr.read_map_set(str(path))
    assert len(back) == len(maps) == 42
    for a, b in zip(maps, back):
        assert np.array_equal(a.rgb, b.rgb)
        assert np.array_equal(a.confidence, b.confidence)
        assert a.warp == b.warp and a.source == b.source == "captured" and a.material == b.material
        assert b.attributes["note"] == "random"
        # Directions and frames are float32 on disk.
        assert np.allclose(a.view, b.view, atol=1e-7) and np.allclose(a.world_from_view, b.world_from_view, atol=1e-6)
    assert np.array_equal(np.float32(back[5].albedo), np.float32([0.1, 0.2, 0.3, 0.4, 0.5, 0.6]))  # float32
    assert back[0].clipped is not None and back[1].clipped is None
    assert back.view_set().surrounds


def test_map_view_pixels_are_shared_with_numpy_not_copied():
    rgb = np.ones((8, 8, 3), np.float32)
    view = rsibr.MapView(rgb, (0, 0, 1))
    assert np.shares_memory(view.rgb, rgb)
    rgb[2, 3] = (5, 6, 7)
    assert list(view.rgb[2, 3]) == [5, 6, 7]
    maps = rsibr.MapSet([view])
    maps[0].rgb[0, 0, 0] = 9  # a view of the set's own buffer
    assert maps[0].rgb[0, 0, 0] == 9 and rgb[0, 0, 0] == 9
    kept = maps[0].rgb
    del maps, view, rgb
    assert kept[2, 3, 1] == 6  # the buffer lives as long as an array refers to it
    # float64 or non-contiguous input is converted once (a copy).
    f64 = np.ones((8, 8, 3))
    assert not np.shares_memory(rsibr.MapView(f64, (0, 0, 1)).rgb, f64)


def test_an_environment_survives_a_file_round_trip_in_every_layout(tmp_path):
    rng = np.random.default_rng(11)
    for kind, size in [("latlong", 32), ("cube", 8), ("octahedral", 16), ("sphere", 16)]:
        layout = rsibr.Layout.with_size(kind, size)
        pixels = rng.uniform(0, 100, (layout.height, layout.width, 3)).astype(np.float32)
        env = rsibr.Environment(pixels, layout, {"origin": "test", "kind": kind})
        assert np.shares_memory(env.pixels, pixels)
        path = tmp_path / f"{kind}.exr"
        rsibr.write_environment(str(path), env)
        back = rsibr.read_environment(str(path))
        assert back.layout == layout
        assert np.array_equal(back.pixels, pixels)
        assert back.attributes["origin"] == "test" and back.attributes["kind"] == kind


def test_half_float_files_keep_three_significant_digits(tmp_path):
    pixels = np.linspace(0.01, 1000, 64 * 32 * 3, dtype=np.float32).reshape(32, 64, 3)
    env = rsibr.Environment(pixels, "latlong")
    rsibr.write_environment(str(tmp_path / "h.exr"), env, half=True)
    back = rsibr.read_environment(str(tmp_path / "h.exr")).pixels
    assert np.max(np.abs(back - pixels) / pixels) < 1e-3


def test_a_constant_environment_integrates_to_four_pi_per_channel():
    for kind in ["latlong", "cube", "octahedral", "sphere"]:
        layout = rsibr.Layout.with_size(kind, 16)
        env = rsibr.Environment.zeros(layout)
        env.pixels[...] = 1.0
        assert np.allclose(env.integral(), 4 * np.pi, rtol=1e-9)
        assert np.isclose(layout.solid_angles().sum(), 4 * np.pi, rtol=1e-12)
