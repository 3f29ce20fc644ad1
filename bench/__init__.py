"""Benchmarks run by ``make bench``: each ``bench/bench_*.py`` has ``main() -> None``."""
