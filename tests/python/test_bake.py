"""rsibr.bake against analytic answers and against `rsibr bake`."""
import numpy as np
import pytest

import rsibr
from conftest import real_environment


def white_furnace(layout="latlong", size=64):
    env = rsibr.Environment.zeros(rsibr.Layout.with_size(layout, size))
    env.pixels[...] = 1.0
    return env


@pytest.mark.parametrize("spec", [
    "{type: lambert, albedo: [0.8, 0.5, 0.2]}",
    "{type: ggx, roughness: 0.5, fresnel: {type: schlick, f0: [0.95, 0.64, 0.54]}}",
    "{type: phong, albedo: [0.6, 0.6, 0.6], exponent: 20}",
])
def test_a_white_furnace_bake_gives_the_directional_albedo_at_every_texel(spec):
    # Under L_i = 1 a texel holds int f_r cos dw = albedo(wo), wo = (sin, 0, cos) with cos = n.v = g_normal z.
    brdf = rsibr.parse_brdf(spec)
    size = 16
    maps = rsibr.bake(brdf, white_furnace(), "tetra", res=size, method="mis", samples=256, seed=3)
    normals, inside = rsibr.sphere_map.normals(size, size)
    expected = np.zeros((size, size, 3))
    for r, c in zip(*np.nonzero(inside)):
        z = normals[r, c, 2]
        expected[r, c] = brdf.albedo((np.sqrt(max(0.0, 1 - z * z)), 0.0, z))
    rim = inside & (normals[..., 2] > 0.2)  # grazing texels are noisier
    for view in maps:
        got = view.rgb.astype(np.float64)
        assert np.all(got[~inside] == 0)
        assert np.max(np.abs(got[rim] - expected[rim])) < 0.03
        assert abs(got[rim].mean() - expected[rim].mean()) < 2e-3


def test_a_bake_has_the_attributes_of_a_computed_map_set():
    brdf = rsibr.parse_brdf("{type: lambert, albedo: [0.5, 0.5, 0.5]}")
    maps = rsibr.bake(brdf, white_furnace(), rsibr.ViewSet.octahedron(), res=8, method="sh", environment_name="furnace")
    maps.validate()
    assert len(maps) == 6 and maps.width == 8
    for v, d in zip(maps, rsibr.ViewSet.octahedron().views):
        assert np.allclose(v.view, d) and v.warp == "normal" and v.source == "computed"
        assert rsibr.parse_brdf(v.material).spec == brdf.spec
        assert v.attributes["method"] == "sh" and v.attributes["environment"] == "furnace"


def test_a_bake_equals_the_command_line_bake_bit_for_bit(tmp_path, cli):
    env_path = real_environment("sunset")
    spec = "{type: ggx, roughness: 0.3, fresnel: {type: dielectric, ior: 1.5}}"
    (tmp_path / "b.yaml").write_text(spec + "\n")
    cli("bake", "--env", env_path, "--brdf", tmp_path / "b.yaml", "--views", "tetra", "--res", 24,
        "--method", "fis", "--samples", 16, "--seed", 9, "--normalise", "albedo", "-q", tmp_path / "cli.exr")
    theirs = rsibr.read_map_set(str(tmp_path / "cli.exr"))
    ours = rsibr.bake(spec, rsibr.read_environment(str(env_path)), "tetra", res=24, method="fis", samples=16,
                      seed=9, normalise_albedo=True, environment_name=env_path.name)
    for a, b in zip(ours, theirs):
        assert np.array_equal(a.rgb, b.rgb)
        assert a.attributes == b.attributes and a.material == b.material
        assert np.array_equal(np.float32(a.albedo), np.float32(b.albedo))
