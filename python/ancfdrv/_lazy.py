"""A module imported on first use: scipy.linalg and scipy.sparse.linalg cost ~10 MB of
resident memory and ~0.1 s to import, and most runs (every dynamic run without modes, FFR
reduction or eliminated joints) never call them (issue 23: a run's peak memory).

And features a higher layer gives a lower one, loaded on first need: the package's
``__init__`` names the module (:func:`provide`) and the lower layer loads it
(:func:`load`) without importing upward (System's analyses, :mod:`ancfdrv.analyses`)."""
from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any


class LazyModule:
    """Stands for the module ``name`` and imports it when an attribute is first read."""

    def __init__(self, name: str) -> None:
        self._name = name
        self._module: ModuleType | None = None

    def __getattr__(self, attr: str) -> Any:
        if attr.startswith("__"):   # copy, pickle and introspection: no import for these
            raise AttributeError(attr)
        if self._module is None:
            self._module = importlib.import_module(self._name)
        return getattr(self._module, attr)

    def __repr__(self) -> str:
        return f"<lazy module {self._name!r}{'' if self._module is None else ' (loaded)'}>"


_PROVIDERS: dict[str, str] = {}


def provide(feature: str, module: str) -> None:
    """Name the module that registers ``feature`` when it is imported."""
    _PROVIDERS[feature] = module


def load(feature: str) -> bool:
    """Import the module that provides ``feature``; False when none was named."""
    module = _PROVIDERS.get(feature)
    if module is None:
        return False
    importlib.import_module(module)
    return True
