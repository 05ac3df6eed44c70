"""rsibr.render of a mesh under a white furnace: every covered pixel shows the albedo."""
import numpy as np

import rsibr


def write_octahedron(path):
    v = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    f = [(1, 5, 3), (3, 5, 2), (2, 5, 4), (4, 5, 1), (3, 6, 1), (2, 6, 3), (4, 6, 2), (1, 6, 4)]
    path.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in v) + "".join(f"f {a} {b} {c}\n" for a, b, c in f))


def test_a_white_furnace_render_shows_the_lambert_albedo_at_every_covered_pixel(tmp_path):
    write_octahedron(tmp_path / "octa.obj")
    mesh = rsibr.load_mesh(str(tmp_path / "octa.obj"))
    assert mesh.triangles.shape == (8, 3) and mesh.positions.shape == (6, 3)
    env = rsibr.Environment.zeros(rsibr.Layout.with_size("latlong", 32))
    env.pixels[...] = 1.0
    maps = rsibr.bake("{type: lambert, albedo: [0.7, 0.4, 0.1]}", env, "icosa", res=32, method="sh")
    camera = rsibr.frame_bounds(mesh, (0.3, -0.5, -1.0), width=64, height=48)
    for mode, lod in [("per-pixel", False), ("paper", False), ("per-pixel", True), ("paper", True)]:
        image = rsibr.render(mesh, maps, camera, mode=mode, lod=lod)  # MIP levels of a constant: the constant
        assert image.shape == (48, 64, 4)
        covered = image[..., 3] == 1
        assert covered.sum() > 150 and np.all(image[~covered & (image[..., 3] == 0)][:, :3] == 0)
        assert np.allclose(image[covered][:, :3], [0.7, 0.4, 0.1], atol=2e-3)
    renderer = rsibr.Renderer(mesh, [maps, maps], environment=env)  # two sets are summed
    image = renderer.render(rsibr.orbit(camera, (0, 0, 0), (0, 1, 0), 1, 4))
    assert np.allclose(image[image[..., 3] == 1][:, :3].max(axis=0), [1.4, 1.0, 1.0], atol=5e-3)
