"""Point warnings at the user's line, however deep inside tiltlab they are raised.

A warning's ``stacklevel`` counted by hand goes stale whenever a call path changes (a
decorator such as :func:`tiltlab._deprecate.renamed` adds a frame); :func:`user_stacklevel`
counts the frames at the moment of the warning instead.
"""

from __future__ import annotations

import os
import sys

__all__ = ["user_stacklevel"]

_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def user_stacklevel() -> int:
    """Return the ``stacklevel`` that names the first caller outside tiltlab.

    Returns
    -------
    int
        For ``warnings.warn(..., stacklevel=user_stacklevel())`` called in a tiltlab
        function: the number of frames from that function to the first frame whose
        code is not in the package (the user's script, notebook cell or test).

    Examples
    --------
    >>> import warnings
    >>> from tiltlab._stack import user_stacklevel
    >>> def f():
    ...     return user_stacklevel()
    >>> f()  # called from outside tiltlab: the caller of f
    1
    """
    frame = sys._getframe(1)
    level = 1
    while frame.f_back is not None and os.path.abspath(
        frame.f_code.co_filename
    ).startswith(_PACKAGE):
        frame = frame.f_back
        level += 1
    return level
