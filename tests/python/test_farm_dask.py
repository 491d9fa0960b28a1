"""The render farm example (crates/prism-python/examples/render_farm_dask.py) on a local
dask.distributed cluster of two worker processes: the tasks and their states cross processes
pickled, and the merged image is the single render's, bit for bit."""

import importlib.util
import sys

from dask.distributed import Client, LocalCluster

import prism_renderer as pr
from conftest import ROOT, SIZE
from test_load import assert_same_image

EXAMPLE = ROOT / "crates" / "prism-python" / "examples" / "render_farm_dask.py"


def _example():
    assert EXAMPLE.is_file(), f"{EXAMPLE} is missing"
    spec = importlib.util.spec_from_file_location("render_farm_dask", EXAMPLE)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_a_dask_farm_renders_the_single_render(cornell_path):
    example = _example()
    assert example.sample_ranges(10, 4) == [(0, 2), (2, 5), (5, 7), (7, 10)]
    assert example.sample_ranges(2, 4) == [(0, 1), (1, 2)]
    defines = {"resx": str(SIZE["resx"]), "resy": str(SIZE["resy"])}
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None)
    with cluster, Client(cluster) as client:
        # The workers import the example as the client does, by name.
        client.upload_file(str(EXAMPLE))
        state = example.render_on(client, str(cornell_path), spp=5, seed=2, tasks=3,
                                  defines=defines, threads=1)
    assert state.ranges == [(0, 5)]
    scene = pr.load_file(cornell_path, **defines)
    assert_same_image(state.image(), pr.render(scene, spp=5, seed=2, progress=False))
