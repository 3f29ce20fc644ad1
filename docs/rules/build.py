"""Write one Markdown page per rule (``docs/rules/OFB101.md`` ...) and an index, from the catalog.

Run ``.venv/bin/python docs/rules/build.py`` after editing ``rules/*.toml``; a test fails while a
page differs from what this writes. These pages are where the reports point a reader (the SARIF
``page`` property, the JUnit failure text, the HTML report's rule sections): the same text as
``fuzzoff rule CODE``, readable in the repository.
"""

from __future__ import annotations

from pathlib import Path

from fuzzoff.catalog import Rule, load_catalog, render_page

HERE = Path(__file__).resolve().parent


def index(rules: list[Rule]) -> str:
    lines = [
        "# Rules",
        "",
        "One page per rule, written from `rules/*.toml` by `docs/rules/build.py` (the same",
        "text as `fuzzoff rule CODE`). `docs/rules.md` describes the families and how severities",
        "are chosen.",
        "",
        "| code | name | severity | profiles |",
        "| --- | --- | --- | --- |",
    ]
    for r in rules:
        lines.append(
            f"| [{r.code}]({r.code}.md) | {r.name} | {r.severity.label} | {r.profiles_text()} |"
        )
    return "\n".join(lines) + "\n"


def pages() -> dict[str, str]:
    """File name -> text, for every page this folder should hold."""
    rules = list(load_catalog().values())
    out = {f"{r.code}.md": render_page(r) for r in rules}
    out["README.md"] = index(rules)
    return out


def main() -> None:
    wanted = pages()
    for stale in HERE.glob("*.md"):
        if stale.name not in wanted:
            stale.unlink()
    for name, text in wanted.items():
        (HERE / name).write_text(text, encoding="utf-8")
    print(f"wrote {len(wanted)} pages to {HERE}")


if __name__ == "__main__":
    main()
