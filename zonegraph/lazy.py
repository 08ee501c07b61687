"""Public names imported on first use (PEP 562), for packages whose names pull in heavy modules.

``import zonegraph`` must not load the geometry kernel, ``import zonegraph.network`` not torch,
``import zonegraph.testing`` not pytest; yet each package lists its public API at the top. A
package names where each public name lives and takes its module ``__getattr__`` and ``__dir__``
from :func:`lazy_exports`. Like :mod:`zonegraph.errors`, this module imports nothing of the
package and serves every layer.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Iterable, Mapping
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
        value = getattr(importlib.import_module(module), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | listed)

    return __getattr__, __dir__
