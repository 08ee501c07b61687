"""Public names imported on first use (PEP 562), for packages whose names pull in heavy modules.

``import zonegraph`` must not load the geometry kernel, ``import zonegraph.network`` not torch,
``import zonegraph.testing`` not pytest; yet each package lists its public API at the top. A
package names where each public name lives and takes its module ``__getattr__`` and ``__dir__``
from `lazy_exports`; such first uses, and the CLI's, import the kernel `uncollected`.
Like `zonegraph.errors`, this module imports nothing of the package and serves every layer.
"""

from __future__ import annotations

import gc
import importlib
import sys
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from typing import Any


def lazy_exports(
    package: str, exports: Mapping[str, str], public: Iterable[str] = ()
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of ``package``: a name of ``exports`` (name -> module)
    is imported from its module when first asked for and then kept in the package's namespace,
    so later lookups cost nothing; ``dir()`` lists the package's names and ``public`` ones."""
    listed = set(public) | set(exports)

    def __getattr__(name: str) -> Any:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        with uncollected():
            value = getattr(importlib.import_module(module), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | listed)

    return __getattr__, __dir__


@contextmanager
def uncollected() -> Iterator[None]:
    """A block run without the cyclic garbage collector, for importing the geometry kernel: OCP's
    one extension module creates about 184,000 long-lived objects (its bound classes and functions,
    none of them garbage), and the collections those allocations trigger walk them again and again,
    about a fifth of the import's CPU. The collector's earlier state is restored after the block."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
