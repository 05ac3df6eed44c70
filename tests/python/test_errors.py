"""C++ errors arrive as the matching Python exceptions, with the file named."""
import numpy as np
import pytest

import rsibr


def test_a_missing_file_is_a_file_not_found_error_naming_it(tmp_path):
    missing = str(tmp_path / "nowhere.exr")
    for read in [rsibr.read_map_set, rsibr.read_environment, rsibr.load_mesh, rsibr.load_brdf]:
        with pytest.raises(FileNotFoundError) as e:
            read(missing)
        assert e.value.filename == missing and missing in str(e.value)
    with pytest.raises(IsADirectoryError):
        rsibr.read_map_set(str(tmp_path))


def test_a_corrupt_map_set_is_a_runtime_error_naming_the_file(tmp_path):
    bad = tmp_path / "truncated.exr"
    maps = rsibr.MapSet([rsibr.MapView(np.ones((8, 8, 3), np.float32), (0, 0, 1))])
    rsibr.write_map_set(str(bad), maps)
    bad.write_bytes(bad.read_bytes()[:200])
    with pytest.raises(RuntimeError, match=str(bad)):
        rsibr.read_map_set(str(bad))
    text = tmp_path / "env.exr"
    text.write_text("not an image\n")
    with pytest.raises(RuntimeError, match=str(text)):
        rsibr.read_environment(str(text))


def test_non_finite_texels_are_refused_unless_sanitized(tmp_path):
    rgb = np.ones((8, 8, 3), np.float32)
    rgb[3, 4, 1] = np.nan
    path = tmp_path / "nan.exr"
    rsibr.write_map_set(str(path), rsibr.MapSet([rsibr.MapView(rgb, (0, 0, 1))]))
    with pytest.raises(RuntimeError, match="NaN"):
        rsibr.read_map_set(str(path))
    assert rsibr.read_map_set(str(path), sanitize=True)[0].rgb[3, 4, 1] == 0


def test_bad_values_are_value_errors():
    with pytest.raises(ValueError, match="brdf.roughness"):
        rsibr.parse_brdf("{type: ggx, roughness: 7, fresnel: {type: none}}")
    with pytest.raises(ValueError, match=r"\(height, width, 3\)"):
        rsibr.MapView(np.ones((8, 8, 4), np.float32), (0, 0, 1))
    with pytest.raises(ValueError):
        rsibr.ViewSet(np.zeros((3, 3)))
    maps = rsibr.MapSet([rsibr.MapView(np.ones((8, 8, 3), np.float32), (0, 0, 1))])
    with pytest.raises(ValueError, match="warp"):
        rsibr.blend(maps, (0, 0, 1), warp="curved")
    with pytest.raises(ValueError):
        rsibr.MapSet().validate()
    env = rsibr.Environment.zeros(rsibr.Layout.with_size("latlong", 16))
    with pytest.raises(ValueError, match="sh"):
        rsibr.bake("{type: ggx, roughness: 0.2, fresnel: {type: none}}", env, "tetra", res=4, method="sh")
