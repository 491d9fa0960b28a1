"""Renders a scene on a dask.distributed cluster, split by sample index (docs/render-farm.md).

Every task loads the scene and renders the samples start <= i < end of every pixel; the tasks'
render states come back to the client, which merges them into the image one machine would
render with all the samples, bit for bit. The scene's files must be readable at the same path
on every worker (a shared file system).

    python render_farm_dask.py scene.xml --spp 1024 --tasks 16 -o final.exr
    python render_farm_dask.py scene.xml --scheduler tcp://head:8786 ...   # an existing cluster

Without ``--scheduler`` it starts a local cluster of worker processes.
"""

from __future__ import annotations

import argparse
from typing import Dict, List, Optional, Tuple

import prism_renderer as pr


def render_part(
    path: str,
    defines: Dict[str, str],
    spp: int,
    seed: int,
    sample_range: Tuple[int, int],
    threads: Optional[int] = None,
) -> pr.RenderState:
    """One task: the scene at ``path`` rendered over ``sample_range``, as its state."""
    scene = pr.load_file(path, **defines)
    return pr.render(
        scene, spp=spp, seed=seed, threads=threads, sample_range=sample_range, progress=False
    )


def sample_ranges(spp: int, tasks: int) -> List[Tuple[int, int]]:
    """``spp`` samples split into ``tasks`` contiguous ranges of sizes differing by one at
    most (fewer when there are fewer samples than tasks)."""
    tasks = max(1, min(tasks, spp))
    bounds = [spp * i // tasks for i in range(tasks + 1)]
    return list(zip(bounds[:-1], bounds[1:]))


def render_on(
    client,
    path: str,
    spp: int,
    seed: int,
    tasks: int,
    defines: Optional[Dict[str, str]] = None,
    threads: Optional[int] = None,
) -> pr.RenderState:
    """The merged state of the scene at ``path`` rendered by ``tasks`` tasks on ``client``'s
    cluster."""
    futures = [
        client.submit(render_part, path, defines or {}, spp, seed, part, threads, pure=False)
        for part in sample_ranges(spp, tasks)
    ]
    return pr.merge(client.gather(futures))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--spp", type=int, required=True)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--tasks", type=int, default=8)
    parser.add_argument("-D", dest="defines", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--scheduler", help="address of a running dask scheduler")
    parser.add_argument("--workers", type=int, default=2, help="local cluster's processes")
    parser.add_argument("-o", "--output", default="final.exr")
    args = parser.parse_args()
    defines = dict(define.split("=", 1) for define in args.defines)

    from dask.distributed import Client, LocalCluster

    if args.scheduler:
        client = Client(args.scheduler)
    else:
        client = Client(LocalCluster(n_workers=args.workers, threads_per_worker=1))
    with client:
        state = render_on(client, args.scene, args.spp, args.seed, args.tasks, defines)
    state.image().write(args.output)
    print(f"{state!r} -> {args.output}")


if __name__ == "__main__":
    main()
