"""Shared fixtures of the Python module's tests (run by ctest as python.pytest).

The module comes from PYTHONPATH (build/<preset>/python); the command line from $RSIBR_CLI
(build/<preset>/rsibr), for the tests that check the module against the verbs.
"""
import os
import pathlib
import subprocess

import numpy as np
import pytest

import rsibr

ROOT = pathlib.Path(__file__).resolve().parents[2]
HDRI = ROOT / "cache" / "assets" / "hdri"


@pytest.fixture(scope="session")
def cli():
    """Runs the rsibr command; skips when $RSIBR_CLI is not set."""
    path = os.environ.get("RSIBR_CLI")
    if not path:
        pytest.skip("RSIBR_CLI is not set (ctest sets it)")

    def run(*args):
        return subprocess.run([path, *map(str, args)], check=True, capture_output=True, text=True)

    return run


def real_environment(name):
    """One of the CC0 environments of cache/ (skips without it)."""
    path = HDRI / f"{name}.exr"
    if not path.exists():
        pytest.skip(f"{path} is missing (scripts/fetch-assets.sh fetches it)")
    return path


def random_map_set(rng, views="icosa", size=24, captured=False):
    """A map set of random positive maps for the given view set (the blend does not care what they show)."""
    vs = rsibr.ViewSet.named(views)
    out = rsibr.MapSet()
    for v in vs.views:
        rgb = rng.uniform(0.05, 4.0, (size, size, 3)).astype(np.float32)
        conf = rng.uniform(0.2, 1.0, (size, size)).astype(np.float32) if captured else None
        out.append(rsibr.MapView(rgb, v, source="captured" if captured else "computed",
                                 confidence=conf, material="{type: none}", attributes={"note": "random"}))
    return out
