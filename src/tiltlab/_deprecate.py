"""Renamed parameters keep their old name for one release, with a warning.

The package uses one name for one thing (the Recording argument is ``rec``, the
gyroscope offset is ``gyr_offset``; see the glossary on the conventions page). Where a
public parameter was renamed, :func:`renamed` lets old calls run for one release and
says what to write instead.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable
from typing import Any, TypeVar

from ._stack import user_stacklevel

F = TypeVar("F", bound=Callable[..., Any])

__all__ = ["alias", "renamed"]


def renamed(**old_to_new: str) -> Callable[[F], F]:
    """Accept old keyword names for renamed parameters, with a ``FutureWarning``.

    Parameters
    ----------
    **old_to_new : str
        Each old keyword name mapped to the parameter's new name.

    Returns
    -------
    callable
        A decorator; the decorated function takes the new names, and the old ones
        with a ``FutureWarning`` naming the new one. Passing both is a ``TypeError``.

    Examples
    --------
    >>> import warnings
    >>> @renamed(b0="gyr_offset")
    ... def f(x, *, gyr_offset=0.0):
    ...     return x + gyr_offset
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     f(1.0, b0=2.0)
    3.0
    >>> str(caught[0].message)
    "f: 'b0' was renamed 'gyr_offset'; the old name goes in the next release"
    """

    def decorate(func: F) -> F:
        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            for old, new in old_to_new.items():
                if old in kwargs:
                    if new in kwargs:
                        raise TypeError(
                            f"{func.__name__}: pass {new!r} only ({old!r} is its "
                            "old name)"
                        )
                    warnings.warn(
                        f"{func.__name__}: {old!r} was renamed {new!r}; the old "
                        "name goes in the next release",
                        FutureWarning,
                        stacklevel=user_stacklevel(),
                    )
                    kwargs[new] = kwargs.pop(old)
            return func(*args, **kwargs)

        wrapper.__renamed__ = dict(old_to_new)  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return decorate


def alias(func: F, old_name: str) -> F:
    """Keep a renamed function's old name for one release, with a ``FutureWarning``.

    Parameters
    ----------
    func : callable
        The function under its new name.
    old_name : str
        The name it had.

    Returns
    -------
    callable
        A wrapper that warns that ``old_name`` is now ``func.__name__``, then calls
        ``func``; its ``__deprecated_alias_of__`` attribute is ``func``.

    Examples
    --------
    >>> import warnings
    >>> def load_model(path):
    ...     return path.upper()
    >>> load = alias(load_model, "load")
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     load("w.pt")
    'W.PT'
    >>> str(caught[0].message)
    'load was renamed load_model; the old name goes in the next release'
    """

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        warnings.warn(
            f"{old_name} was renamed {func.__name__}; the old name goes in the next "
            "release",
            FutureWarning,
            stacklevel=user_stacklevel(),
        )
        return func(*args, **kwargs)

    wrapper.__name__ = wrapper.__qualname__ = old_name
    wrapper.__deprecated_alias_of__ = func  # type: ignore[attr-defined]
    return wrapper  # type: ignore[return-value]
