"""The Micro XRCE-DDS Agent of a flight: stopped and started again mid-flight (PX4 #26022).

``run-px4.sh`` starts the agent with PX4 and says its PID on PX4's console ("agent PID N");
a flight that restarts it stops that process by its PID and starts a new agent on the same
port with the bundle's libraries, as the script does, and stops it at the end of the flight.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
from pathlib import Path

AGENT_PID = re.compile(r"run-px4\.sh: agent PID (\d+)")
PORT = 8888


class AgentError(Exception):
    """The agent could not be found or started."""


def started_pid(console: Path) -> int:
    """The PID ``run-px4.sh`` gave the agent it started (from PX4's console log)."""
    match = AGENT_PID.search(console.read_text(errors="replace"))
    if match is None:
        raise AgentError(f"{console}: run-px4.sh did not say the agent's PID")
    return int(match.group(1))


def stop(pid: int) -> None:
    """SIGTERM to the agent ``run-px4.sh`` started (by its PID, which it printed)."""
    try:
        os.kill(pid, signal.SIGTERM)
    except ProcessLookupError:
        raise AgentError(f"agent PID {pid} is not running") from None


def start(folder: Path, log: Path) -> subprocess.Popen[bytes]:
    """A new agent from ``folder`` (``MicroXRCEAgent``, ``lib/``, ``lib-debian12/``) on the
    bridge's UDP port, its output in ``log``; the caller stops it (``terminate``)."""
    binary = folder / "MicroXRCEAgent"
    if not binary.exists():
        raise AgentError(f"no agent in {folder}")
    libraries = [str(folder / "lib"), str(folder / "lib-debian12")]
    if os.environ.get("LD_LIBRARY_PATH"):
        libraries.append(os.environ["LD_LIBRARY_PATH"])
    with log.open("wb") as out:
        return subprocess.Popen(
            [str(binary), "udp4", "-p", str(PORT), "-v", "4"],
            stdout=out,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            env={**os.environ, "LD_LIBRARY_PATH": ":".join(libraries)},
        )
