"""The package keeps its shape: no module grows past the size at which it stops being
read as one piece."""

from __future__ import annotations

from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "tiltlab"
MAX_LINES = 800


def test_no_module_over_800_lines():
    sizes = {
        str(p.relative_to(SRC)): len(p.read_text(encoding="utf-8").splitlines())
        for p in SRC.rglob("*.py")
    }
    too_long = {name: n for name, n in sorted(sizes.items()) if n > MAX_LINES}
    assert not too_long, (
        f"modules over {MAX_LINES} lines (split them by responsibility): {too_long}"
    )


def test_no_name_means_two_things_in_a_package():
    """Within a package, two submodules never export the same name for different
    objects (a star import would silently let one shadow the other)."""
    import importlib
    import pkgutil

    import tiltlab

    clashes = []
    for pkg in pkgutil.walk_packages(tiltlab.__path__, "tiltlab."):
        if not pkg.ispkg:
            continue
        package = importlib.import_module(pkg.name)
        seen: dict[str, tuple[str, object]] = {}
        for sub in pkgutil.iter_modules(package.__path__, pkg.name + "."):
            if sub.name.rsplit(".", 1)[1].startswith("__"):
                continue
            module = importlib.import_module(sub.name)
            for name in getattr(module, "__all__", []):
                obj = getattr(module, name, None)
                if name in seen and seen[name][1] is not obj:
                    clashes.append(f"{name}: {seen[name][0]} and {sub.name}")
                seen.setdefault(name, (sub.name, obj))
    assert not clashes, f"one name, two meanings: {clashes}"


def test_one_name_one_behaviour_across_the_package():
    """Across the whole package, a public name exported by two modules is one object
    (homonyms such as two ``gravity`` or two ``wrap_angle`` with different behaviour
    are renamed or merged; a deprecated alias of a renamed function does not count)."""
    import importlib
    import inspect
    import pkgutil

    import tiltlab

    owners: dict[str, dict[int, str]] = {}
    for info in pkgutil.walk_packages(tiltlab.__path__, "tiltlab."):
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name, None)
            if obj is None or getattr(obj, "__deprecated_alias_of__", None):
                continue
            if not (callable(obj) or name.isupper()) or inspect.ismodule(obj):
                continue
            owners.setdefault(name, {}).setdefault(id(obj), info.name)
    clashes = {n: sorted(o.values()) for n, o in owners.items() if len(o) > 1}
    assert not clashes, f"one name, two behaviours: {clashes}"
