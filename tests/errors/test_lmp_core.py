"""The LIGGGHTS core's rows of the bad-input campaign: EEPA properties, meshes, fix wall/gran/corotating."""
import pytest

from badinput import BadInput, check, ids
from table_lmp_core import CASES


@pytest.mark.parametrize("case", CASES, ids=ids(CASES))
def test_bad_input(case: BadInput, tmp_path) -> None:
    check(case, tmp_path)
