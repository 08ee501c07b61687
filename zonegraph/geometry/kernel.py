"""OpenCASCADE's thread pool, kept to the calling thread so that forked children can use it.

build123d runs every Boolean with ``SetRunParallel(True)``, on OCCT's default thread pool (OCP's
OCCT is built without TBB, so the pool is OCCT's own). A process forked after that pool started a
worker thread inherits the pool but not the thread, and its first parallel Boolean waits for the
thread forever. Each job of `zonegraph.isolation` runs in such a child: a synthetic design
replayed in a child after its parent had replayed it hung until its timeout, every time. The pool
is created here with no worker thread, before any Boolean of ours, and parallelism comes from
processes instead (Dask workers, a batch's children), as it does on every other path.

Every module of the package that imports OCP or build123d at module level imports this one
(``tests/test_architecture.py`` checks it), so the pool is held before the first Boolean runs.
Code that ran a parallel Boolean before importing `zonegraph` has a started pool already:
`fork_safe` says so, and `zonegraph.isolation.run_isolated` warns once.
"""

from __future__ import annotations

from OCP.OSD import OSD_ThreadPool

# One thread in all: the caller's (OCCT starts n - 1 workers for a pool of n threads).
POOL = OSD_ThreadPool.DefaultPool_s(1)


def fork_safe() -> bool:
    """Whether a forked child can run parallel Booleans: the default pool has no worker thread."""
    return not POOL.HasThreads()
