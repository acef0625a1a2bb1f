"""Write docs/bad-input.md from every row of tests/errors/table_*.py: what is refused and why.

    PYTHONPATH=tests python tests/errors/list_cases.py            # rewrite the doc
    PYTHONPATH=tests python tests/errors/list_cases.py --check    # exit 1 when the doc is out of date (test_doc.py)
"""
from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
DOC = HERE.parents[1] / "docs" / "bad-input.md"


def tables() -> dict[str, list]:
    # the table modules sit next to this file (on sys.path when it runs as a script); they import tests/tsg_harness
    found = {}
    for path in sorted(HERE.glob("table_*.py")):
        found[path.stem[len("table_"):]] = importlib.import_module(path.stem).CASES
    return found


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def render() -> str:
    areas = tables()
    total = sum(len(rows) for rows in areas.values())
    lines = ["# Bad input: what is refused and why",
             "",
             "Generated from the bad-input campaign tables (`tests/errors/table_*.py`) by",
             "`PYTHONPATH=tests python tests/errors/list_cases.py`; `ctest -R errors.doc` fails when this file is out of date.",
             "Each row is a test (`ctest -R errors.`): the run must exit non-zero (or, for rows marked",
             "handled, exit 0), print every listed word in its first message (`log.lammps` for lmp",
             "inputs), show no Python traceback, write no NaN, and leave the named earlier outputs intact.",
             "",
             f"{total} rows in {len(areas)} areas."]
    for area, rows in areas.items():
        lines += ["", f"## {area} ({len(rows)} rows)", "", "| id | refused with | why |", "|---|---|---|"]
        for row in rows:
            words = "; ".join(f"`{w}`" for w in row.words)
            handled = " (handled, exit 0)" if row.accepted else ""
            lines.append(f"| `{row.id}` | {_cell(words)}{handled} | {_cell(row.why)} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--check", action="store_true", help="only compare with the doc")
    args = parser.parse_args(argv)
    text = render()
    if args.check:
        if not DOC.is_file() or DOC.read_text() != text:
            print(f"{DOC} is out of date: run PYTHONPATH=tests python tests/errors/list_cases.py", file=sys.stderr)
            return 1
        return 0
    DOC.write_text(text)
    print(f"{DOC} written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
