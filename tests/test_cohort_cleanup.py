"""A cohort run killed with SIGKILL leaves no worker behind: the process pool's workers
(and with them the multiprocessing resource tracker) end with their parent."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(
    not Path("/proc").is_dir(), reason="reads the process table from /proc (Linux)"
)

SCRIPT = textwrap.dedent(
    """
    import os, sys, time
    from tiltlab.cohort.schedulers import backend

    if __name__ == "__main__":
        b = backend(sys.argv[1], 2)
        pids = sorted({b.submit(os.getpid).result() for _ in range(8)})
        print(" ".join(map(str, pids)), flush=True)
        b.submit(time.sleep, 120)  # a worker busy when its parent is killed
        time.sleep(120)
    """
)


def _alive(pid: int) -> bool:
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return False
    return "State:\tZ" not in status  # a zombie has ended


def _descendants(root: int) -> list[int]:
    children = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                ppid = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry.name))
    out, todo = [], [root]
    while todo:
        for child in children.get(todo.pop(), []):
            out.append(child)
            todo.append(child)
    return out


@pytest.mark.parametrize("scheduler", ["processes", "dask"])
def test_workers_end_with_a_killed_parent(tmp_path, scheduler):
    script = tmp_path / "run.py"
    script.write_text(SCRIPT)
    proc = subprocess.Popen(
        [sys.executable, str(script), scheduler], stdout=subprocess.PIPE, text=True
    )
    try:
        workers = [int(p) for p in proc.stdout.readline().split()]
        family = _descendants(proc.pid)
        assert workers and set(workers) <= set(family)
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    deadline = time.monotonic() + 15.0
    while time.monotonic() < deadline and any(_alive(p) for p in family):
        time.sleep(0.25)
    left = [p for p in family if _alive(p)]
    for p in left:  # do not leave them to the next test either
        os.kill(p, signal.SIGKILL)
    assert not left, f"{scheduler}: processes {left} outlived their killed parent"
