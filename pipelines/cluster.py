"""A Dask client: a local cluster by default, or an existing one named in ``params.yaml``.

Workers fork a child per design (see ``zonegraph.isolation``) so that a hung OpenCASCADE call can
be killed; daemonic processes may not fork children, so local workers are started non-daemonic.
Workers of an existing cluster need the same setting (``DASK_DISTRIBUTED__WORKER__DAEMON=False``),
this package installed, and the data folder on a shared file system.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager

import dask
from distributed import Client, LocalCluster

from .params import DaskParams


@contextmanager
def dask_client(cfg: DaskParams) -> Iterator[Client]:
    address = cfg.scheduler
    if address:
        with Client(address) as client:
            yield client
        return
    with dask.config.set({"distributed.worker.daemon": False}):
        with (
            LocalCluster(
                n_workers=cfg.n_workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=logging.ERROR,
            ) as cluster,
            Client(cluster) as client,
        ):
            yield client
