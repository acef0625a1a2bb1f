"""docs/bad-input.md lists every row of every table (tests/errors/list_cases.py)."""
from list_cases import DOC, render, tables


def test_doc_is_up_to_date() -> None:
    assert DOC.read_text() == render(), "docs/bad-input.md is out of date: run PYTHONPATH=tests python tests/errors/list_cases.py"


def test_every_row_says_why() -> None:
    missing = [row.id for rows in tables().values() for row in rows if not row.why.strip()]
    assert not missing, f"rows without a `why` for the doc: {missing}"
