"""The inputs-as-typed rows of the bad-input campaign (tests/errors/README.md)."""
import pytest

from badinput import BadInput, check, ids
from table_typed import CASES


@pytest.mark.parametrize("case", CASES, ids=ids(CASES))
def test_bad_input(case: BadInput, tmp_path) -> None:
    check(case, tmp_path)
