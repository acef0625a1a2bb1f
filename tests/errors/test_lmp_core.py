"""The LIGGGHTS core's rows of the bad-input campaign: EEPA properties, meshes, fix wall/gran/corotating."""
import pytest

import badinput
from badinput import BadInput, check, ids
from table_lmp_core import CASES

# A message that quotes the user's text ("got 'nan'") is not a NaN in the output.
badinput.NAN = badinput.re.compile(r"(?<![A-Za-z_'])[-+]?nan(?![A-Za-z_'])", badinput.re.IGNORECASE)


@pytest.mark.parametrize("case", CASES, ids=ids(CASES))
def test_bad_input(case: BadInput, tmp_path) -> None:
    check(case, tmp_path)
