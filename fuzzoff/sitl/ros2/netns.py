"""Run a ROS 2 flight inside a private network and mount namespace (``unshare``).

DDS finds its peers by multicast: PX4's agent and every DDS program of a flight live in a
network namespace whose only interface is loopback (with multicast routed to it), so nothing
reaches the machine's network, and a private ``/tmp`` keeps PX4's ``/tmp/px4_lock-0`` apart
from other PX4 instances on the machine. Needs root (or user namespaces) and ``unshare``/``ip``.

The flight's outputs reach the caller's folder at the same path: the namespace's ``/tmp`` hides
the caller's, so the folder is entered before ``/tmp`` is replaced and bound again at its path.

A live campaign (``fuzzoff fuzz --against sitl:R --transport ros2``) runs for minutes and keeps
its own state (Hypothesis, the bench), so it moves *itself* into a new network namespace
(``enter``: ``unshare(CLONE_NEWNET)``, loopback with multicast as ``LOOPBACK`` sets it); PX4, the
agent and the campaign's DDS participant all live there. Its files stay where they were (no
private ``/tmp``: PX4's lock file is per ``--instance``).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

LOOPBACK = (
    ("ip", "link", "set", "lo", "up"),
    ("ip", "link", "set", "lo", "multicast", "on"),
    ("ip", "route", "add", "224.0.0.0/4", "dev", "lo"),
)
"""The network a flight's namespace gets: loopback up, multicast routed to it."""
SETUP = (
    'mount -t tmpfs none /tmp && mkdir -p "$FUZZOFF_OUT"'
    ' && mount --no-canonicalize --bind . "$FUZZOFF_OUT" && cd "$FUZZOFF_OUT"'
    + "".join(f" && {' '.join(command)}" for command in LOOPBACK)
    + ' && exec "$@"'
)
"""A private /tmp; the caller's folder bound again at its own path (the shell's working
directory still reaches it under the new /tmp; ``--no-canonicalize`` keeps mount from turning
``.`` into a path, which would name the new /tmp); loopback with multicast; the flight."""
CLONE_NEWNET = 0x40000000


class NamespaceError(Exception):
    """This process could not move to a private network namespace: one line for the user."""


def enter() -> None:
    """Move this process (its calling thread, and every thread and process it starts after)
    into a new network namespace with loopback only (``LOOPBACK``). Needs root."""
    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    if libc.unshare(CLONE_NEWNET) != 0:
        errno = ctypes.get_errno()
        raise NamespaceError(f"unshare(CLONE_NEWNET): {os.strerror(errno)}")
    for command in LOOPBACK:
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            raise NamespaceError(f"{' '.join(command)}: {done.stderr.strip() or done.returncode}")


def available() -> str | None:
    """None when flights can run here, else why not (for a test's skip reason)."""
    for tool in ("unshare", "ip"):
        if shutil.which(tool) is None:
            return f"{tool} not found"
    probe = subprocess.run(
        ["unshare", "--net", "--mount", "true"], capture_output=True, text=True, check=False
    )
    if probe.returncode != 0:
        return f"unshare --net --mount: {probe.stderr.strip() or probe.returncode}"
    return None


def run_flight(
    out: Path,
    args: list[str],
    *,
    python: str | None = None,
    timeout: float = 300.0,
) -> subprocess.CompletedProcess[str]:
    """``python -m fuzzoff.sitl.ros2.flight ARGS`` in a fresh namespace, writing into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    argv = [
        "unshare",
        "--net",
        "--mount",
        "sh",
        "-c",
        SETUP,
        "sh",
        python or sys.executable,
        "-m",
        "fuzzoff.sitl.ros2.flight",
        *args,
    ]
    return subprocess.run(
        argv,
        cwd=out,
        env={**os.environ, "FUZZOFF_OUT": str(out.resolve())},
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
