"""Run every benchmark module (``bench/bench_*.py``), or those named on the command line."""

from __future__ import annotations

import pkgutil
import subprocess
import sys
from pathlib import Path


def main() -> None:
    wanted = set(sys.argv[1:])
    here = Path(__file__).parent
    for module in sorted(pkgutil.iter_modules([str(here)]), key=lambda m: m.name):
        if not module.name.startswith("bench_"):
            continue
        if wanted and module.name.removeprefix("bench_") not in wanted:
            continue
        print(f"== {module.name}", flush=True)
        # each benchmark in its own process: one's generated data must not weigh on the next
        subprocess.run(
            [sys.executable, "-c", f"import bench.{module.name} as m; m.main()"],
            cwd=here.parent,
            check=False,
        )


if __name__ == "__main__":
    main()
