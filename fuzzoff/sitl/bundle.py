"""Start a PX4 SITL build in a private working folder and stop it, keeping its ULog.

A *bundle* is one of the ready builds in ``../shared/px4-sitl/<release>`` (``bin/px4``,
``etc/``, ``VERSION``) started by the folder's ``run-px4.sh``; a user's own PX4 tree is named by
its build folder (``build/px4_sitl_default``, which holds the same ``bin/px4`` and ``etc/``) and
started the same way. Each run gets a fresh temporary folder and its own ``PX4_INSTANCE``, so
several can run beside each other: PX4 then listens on ``14580 + N`` and sends to ``14540 + N``.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
from dataclasses import field
from pathlib import Path

from fuzzoff.lean_dataclass import dataclass

API_LISTEN_PORT = 14580
"""PX4's onboard (API) link listens here (+ instance): where a client sends."""
API_SEND_PORT = 14540
"""PX4's onboard link sends here (+ instance): where a client listens."""
SHARED_SEND_PORT = 14549
"""Where every instance above 9 sends (PX4's ``px4-rc.mavlink``, 1.14 to main): only one such
PX4 per network namespace can be talked to at a time."""
STOP_TIMEOUT_S = 10.0
RELEASE_PATTERN = re.compile(r"^\d+\.\d+\.\d+(-[0-9A-Za-z.]+)?$")


class BundleError(Exception):
    """A PX4 build that cannot be found or started: one line for the user."""


def default_root() -> Path:
    """Where the bundles are: ``$FUZZOFF_PX4_SITL`` or ``../shared/px4-sitl`` from the
    project folder (the layout the project's machines and CI have)."""
    env = os.environ.get("FUZZOFF_PX4_SITL")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[2].parent / "shared" / "px4-sitl"


def releases(root: Path | None = None) -> list[str]:
    """The bundled releases, oldest first."""
    root = root or default_root()
    if not root.is_dir():
        return []
    found = [p.name for p in root.iterdir() if (p / "bin" / "px4").exists()]
    return sorted(found, key=_release_key)


def _release_key(name: str) -> tuple[tuple[int, ...], str]:
    """The release's numbers, then the name: bundles of one release (``1.16.2``,
    ``1.16.2-ros2``) in the same order whatever order the folder lists them in."""
    return tuple(int(n) for n in re.findall(r"\d+", name)[:3]), name


@dataclass(frozen=True, slots=True)
class Build:
    """A PX4 SITL build that can be started: its folder and the release it is."""

    folder: Path
    release: str
    """``1.16.2``, or ``unknown`` for a user's build whose version could not be read."""

    @property
    def profile_release(self) -> str:
        """What ``--px4`` takes for the gate model (``1.18.0-alpha1`` -> ``1.18.0``)."""
        return self.release.split("-")[0]


def find_build(release: str | None, px4_build: Path | None, root: Path | None = None) -> Build:
    """The bundle for ``release``, or the user's build folder ``px4_build``."""
    if px4_build is not None:
        folder = px4_build.resolve()
        if not (folder / "bin" / "px4").exists() or not (folder / "etc").is_dir():
            raise BundleError(
                f"--px4-build {px4_build}: not a PX4 SITL build folder (expected bin/px4 and etc/,"
                " e.g. PX4-Autopilot/build/px4_sitl_default)"
            )
        return Build(folder, release or _read_release(folder))
    if not release:
        raise BundleError("name a release (--release 1.16.2) or a build (--px4-build DIR)")
    root = root or default_root()
    have = releases(root)
    if not have:
        raise BundleError(f"no PX4 SITL bundles in {root} (set FUZZOFF_PX4_SITL to their folder)")
    if release in have:
        # the exact name wins: "1.16.2" is the plain bundle, not "1.16.2-ros2" beside it
        return Build(root / release, release)
    matches = [r for r in have if r.startswith(release + ".")]
    matches += [r for r in have if r.startswith(release + "-") and r not in matches]
    if not matches:
        raise BundleError(f"--release {release}: no such bundle; have {', '.join(have)}")
    return Build(root / matches[-1], matches[-1])


def has_bridge(build: Build) -> bool:
    """Whether the build has PX4's ROS 2 bridge client (``uxrce_dds_client``) in its modules."""
    commands = build.folder / "bin" / "commands.txt"
    if commands.exists():
        return "uxrce_dds_client" in commands.read_text(errors="replace")
    return (build.folder / "bin" / "px4-uxrce_dds_client").exists()


def find_bridge_build(
    release: str | None, px4_build: Path | None, root: Path | None = None
) -> Build:
    """As ``find_build``, for a flight over the ROS 2 bridge: ``1.16.2`` names the bundle of
    that release with the bridge (``1.16.2-ros2``) when the exact one lacks it."""
    build = find_build(release, px4_build, root)
    if has_bridge(build) or px4_build is not None or not release:
        if not has_bridge(build):
            raise BundleError(f"{build.folder}: PX4 built without uxrce_dds_client (ROS 2 bridge)")
        return build
    root = root or default_root()
    with_bridge = [
        r
        for r in releases(root)
        if (r == release or r.startswith((release + "-", release + ".")))
        and has_bridge(Build(root / r, r))
    ]
    if not with_bridge:
        bridged = [r for r in releases(root) if has_bridge(Build(root / r, r))]
        raise BundleError(
            f"--release {release}: no bundle with the ROS 2 bridge; have {', '.join(bridged)}"
        )
    return Build(root / with_bridge[-1], with_bridge[-1])


def _read_release(folder: Path) -> str:
    version = folder / "VERSION"
    if version.exists():
        m = re.search(r"tag:\s*v?(\S+)", version.read_text(errors="replace"))
        if m:
            return m.group(1)
    return "unknown"


def run_script(build: Build) -> Path:
    """``run-px4.sh`` beside the bundles, which also starts a user's build folder."""
    script = build.folder.parent / "run-px4.sh"
    if script.exists():
        return script
    script = default_root() / "run-px4.sh"
    if not script.exists():
        raise BundleError(f"run-px4.sh not found beside {build.folder} or in {default_root()}")
    return script


@dataclass(slots=True)
class Px4Process:
    """A running PX4: its process, working folder, instance and ports."""

    build: Build
    instance: int
    workdir: Path
    process: subprocess.Popen[bytes]
    console: Path
    started: float = field(default_factory=time.monotonic)
    ulog: Path | None = None

    @property
    def listen_port(self) -> int:
        return API_LISTEN_PORT + self.instance

    @property
    def send_port(self) -> int:
        return send_port(self.instance)

    @property
    def sysid(self) -> int:
        return self.instance + 1

    def alive(self) -> bool:
        return self.process.poll() is None

    def console_tail(self, lines: int = 5) -> str:
        try:
            text = self.console.read_text(errors="replace").splitlines()
        except OSError:
            return ""
        return " | ".join(line.strip() for line in text[-lines:])

    def command(self, module: str, *args: str, timeout: float = 10.0) -> str:
        """Run a PX4 shell command in this instance (``px4-logger on``); its output."""
        exe = self.workdir / "bin" / f"px4-{module}"
        try:
            done = subprocess.run(
                [str(exe), "--instance", str(self.instance), *args],
                capture_output=True,
                text=True,
                timeout=timeout,
                cwd=self.workdir,
            )
        except (OSError, subprocess.TimeoutExpired) as exc:
            raise BundleError(f"px4-{module} {' '.join(args)}: {exc}") from None
        if done.returncode != 0:
            raise BundleError(
                f"px4-{module} {' '.join(args)} failed: {(done.stdout + done.stderr).strip()}"
            )
        return done.stdout + done.stderr

    def ulogs(self) -> list[Path]:
        return sorted((self.workdir / "log").rglob("*.ulg"), key=lambda p: p.stat().st_mtime)

    def stop(self) -> Path | None:
        """SIGINT (PX4 closes its ULog and exits); the newest ULog in the working folder."""
        if self.alive():
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        logs = self.ulogs()
        self.ulog = logs[-1] if logs else None
        return self.ulog

    def cleanup(self) -> None:
        """Remove the private folder (PX4's working folder and its console log)."""
        shutil.rmtree(self.workdir.parent, ignore_errors=True)


PR_SET_PDEATHSIG = 1
MAX_INSTANCE = 99
"""PX4_INSTANCE shifts PX4's ports (14580+N, 18570+N) and its system id (N+1); above 9 PX4 sends
to 14549 whatever the instance (``send_port``)."""


def send_port(instance: int) -> int:
    """Where PX4 instance ``instance`` sends on its onboard link: where a client listens."""
    return SHARED_SEND_PORT if instance > 9 else API_SEND_PORT + instance


def _stop_with_parent() -> None:  # pragma: no cover (runs in the child before exec)
    """Linux: PX4 gets SIGINT when the process that started it dies, so that a run killed
    from outside (a CI timeout, an interrupted test worker) leaves no PX4 holding its instance."""
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGINT)


def start(
    build: Build,
    instance: int,
    env: dict[str, str] | None = None,
    keep_dir: Path | None = None,
) -> Px4Process:
    """Start PX4 headless in a new private folder (under ``keep_dir`` when given); ``env``
    adds ``PX4_*`` variables such as ``PX4_SIM_SPEED_FACTOR``. The logger is started and stopped
    per run with ``logger on``/``off`` (``Px4Process.command``): ``PX4_PARAM_SDLOG_MODE`` is
    ignored by 1.14 and 1.15, and their default log closes at disarm."""
    if not 0 <= instance <= MAX_INSTANCE:
        raise BundleError(f"instance {instance}: expected 0 to {MAX_INSTANCE}")
    parent = keep_dir
    if parent is not None:
        parent.mkdir(parents=True, exist_ok=True)
    base = Path(tempfile.mkdtemp(prefix=f"fuzzoff-px4-{instance}-", dir=parent))
    workdir = base / "px4"
    console = base / "console.log"
    extra = dict(env or {})
    argv = [
        str(run_script(build)),
        str(build.folder),
        str(workdir),
        *(["--", *(f"{k}={v}" for k, v in sorted(extra.items()))] if extra else []),
    ]
    proc_env = {**os.environ, "PX4_INSTANCE": str(instance)}
    with console.open("wb") as out:
        process = subprocess.Popen(
            argv,
            stdout=out,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            env=proc_env,
            preexec_fn=_stop_with_parent if os.name == "posix" else None,
        )
    return Px4Process(build, instance, workdir, process, console)
