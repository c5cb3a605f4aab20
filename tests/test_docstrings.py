"""Every public function says what it takes and gives: a numpydoc Parameters section
(the package's entry points are read through ``help()`` and the rendered API)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import tiltlab


def _public_functions():
    for info in pkgutil.walk_packages(tiltlab.__path__, "tiltlab."):
        if info.name.rsplit(".", 1)[1].startswith("_") and not info.ispkg:
            continue
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name, None)
            if inspect.isfunction(obj) and obj.__module__ == module.__name__:
                yield module.__name__, name, obj


def test_every_public_function_documents_its_parameters():
    missing = [
        f"{module}.{name}"
        for module, name, obj in _public_functions()
        if inspect.signature(obj).parameters
        and "Parameters" not in (inspect.getdoc(obj) or "")
    ]
    assert not missing, f"{len(missing)} public functions without Parameters: {missing}"
