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


def _top_level_functions():
    """Every top-level ``def`` without a leading underscore, in every module.

    Read from the source (not ``__all__``), so helpers in private modules count too.
    """
    import ast
    from pathlib import Path

    root = Path(tiltlab.__file__).parent
    for path in sorted(root.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in tree.body:
            if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
                yield path.relative_to(root.parent).as_posix(), node


def _returns_value(node) -> bool:
    import ast

    def walk(n):
        # nested functions return for themselves
        for child in ast.iter_child_nodes(n):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
                continue
            yield child
            yield from walk(child)

    return any(
        (isinstance(n, ast.Return) and n.value is not None)
        or isinstance(n, ast.Yield | ast.YieldFrom)
        for n in walk(node)
    )


def test_every_top_level_function_documents_parameters_and_returns():
    import ast

    missing = []
    for where, node in _top_level_functions():
        doc = ast.get_docstring(node) or ""
        a = node.args
        takes = a.posonlyargs + a.args + a.kwonlyargs + [a.vararg, a.kwarg]
        if any(takes) and "\nParameters\n---" not in f"\n{doc}":
            missing.append(f"{where}:{node.name} (Parameters)")
        gives = "\nReturns\n---" in f"\n{doc}" or "\nYields\n---" in f"\n{doc}"
        if _returns_value(node) and not gives:
            missing.append(f"{where}:{node.name} (Returns)")
    assert not missing, f"{len(missing)} sections missing: {missing}"
