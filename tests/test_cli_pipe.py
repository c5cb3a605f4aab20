"""The command line stops quietly when its reader closes the pipe (``… | head``)."""

from __future__ import annotations

import subprocess
import sys

import pytest


@pytest.mark.parametrize("args", [["info", "broad:2"], ["cohort", "--help"]])
def test_closed_pipe_is_quiet(args, data_mirror):
    code = (
        "import os, sys\n"
        "r, w = os.pipe(); os.close(r); os.dup2(w, 1)  # nobody reads stdout\n"
        "from tiltlab.cli import main\n"
        f"sys.exit(main({args!r}))\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert "Traceback" not in run.stderr and "BrokenPipe" not in run.stderr, run.stderr
    assert run.returncode == 0
