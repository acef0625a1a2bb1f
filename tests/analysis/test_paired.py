"""Two continuations of one state compared sample by sample (tsg_analysis.paired): the series are the
ones whose means are the window's estimates, the runs are aligned by step, and a fluctuation both
runs share cancels from the difference while the interval still covers the true offset."""
import json
import math
import shutil

import numpy as np
import pytest
from make_fixture import write_run

from tsg_analysis import systematics
from tsg_analysis.model import SOLID_FRACTION
from tsg_analysis.paired import key_series, paired_differences, paired_study, sensor_series
from tsg_analysis.run import Run
from tsg_analysis.run_files import AnalysisInputError
from tsg_analysis.uncertainty import difference

START, END = 1.3, 1.9  # s: inside the fixture's steady record (1.2-2.0 s)
ZONE = 3  # the element whose solid fraction the tests change (row 3: the second kneading element)


def test_each_series_mean_is_the_windows_estimate(periodic_run):
    path, _ = periodic_run
    run = Run(path)
    _, _, series = key_series(run, START, END)
    estimates = run.key_estimates(START, END)
    assert set(series) == {key for key in estimates if key[0] != "residence time (records)"}
    for key, values in series.items():
        assert values.mean() == pytest.approx(estimates[key].mean, rel=1e-12, abs=1e-15), key
    _, _, flows = sensor_series(run, START, END)
    sensors = run.sensor_flows(START, END)
    assert {name for _, name in flows} == set(sensors)
    for (_, name), values in flows.items():
        assert values.mean() == pytest.approx(sensors[name].mean, rel=1e-12), name


def _rewrite_solid_fraction(path, change) -> None:
    """elements.txt with row ZONE's solid fraction replaced by change(block index, old value)."""
    lines = (path / "elements.txt").read_text().splitlines()
    block = -1
    for n, line in enumerate(lines):
        fields = line.split()
        if line.startswith("#"):
            continue
        if len(fields) == 2:
            block += 1
        elif int(fields[0]) == ZONE:
            fields[1] = repr(float(change(block, float(fields[1]))))
            lines[n] = " ".join(fields)
    (path / "elements.txt").write_text("\n".join(lines) + "\n")


def _drop_first_block(path) -> None:
    lines = (path / "elements.txt").read_text().splitlines()
    header = [line for line in lines if line.startswith("#")]
    body = [line for line in lines if not line.startswith("#")]
    rows = int(body[0].split()[1]) + 1
    (path / "elements.txt").write_text("\n".join(header + body[rows:]) + "\n")


@pytest.fixture()
def two_continuations(tmp_path):
    reference, other = tmp_path / "reference", tmp_path / "setting"
    write_run(reference, kind="periodic", dumps=None, meshes=False, seed=7)
    shutil.copytree(reference, other)
    return reference, other


def test_a_shared_fluctuation_cancels_and_an_offset_is_found(two_continuations):
    """Both runs carry one large slow fluctuation (the screws' phase and the state they share), each its
    own small noise (sd 0.002), the setting an offset of +0.004 on one element: the paired interval
    covers the offset, has the width independent noise alone gives (t sd sqrt(2/n)), and is many times
    narrower than the difference of the two windows' own intervals."""
    reference, other = two_continuations
    rng = np.random.default_rng(11)
    blocks = 100
    shared = 0.05 * np.sin(2 * np.pi * np.arange(blocks) / 13.0) + np.cumsum(rng.normal(0, 0.004, blocks))
    noise = rng.normal(0, 0.002, (2, blocks))
    _rewrite_solid_fraction(reference, lambda k, value: value + shared[k] + noise[0, k])
    _rewrite_solid_fraction(other, lambda k, value: value + shared[k] + noise[1, k] + 0.004)
    _drop_first_block(other)  # aligned by step: a block only one run has is left out
    runs = Run(reference), Run(other)
    label = runs[0].zones.labels[ZONE - 1]
    paired = paired_differences(*runs, START, END)[(SOLID_FRACTION, label)]
    assert abs(paired.mean - 0.004) <= paired.half_width
    independent_only = 1.96 * 0.002 * math.sqrt(2 / paired.samples)
    assert 0.6 * independent_only < paired.half_width < 1.6 * independent_only
    unpaired = difference(runs[0].key_estimates(START, END)[(SOLID_FRACTION, label)],
                          runs[1].key_estimates(START, END)[(SOLID_FRACTION, label)])
    assert unpaired.half_width > 5 * paired.half_width
    # every other element is the same in both runs: exactly no difference
    for (quantity, scope), estimate in paired_differences(*runs, START, END).items():
        if (quantity, scope) != (SOLID_FRACTION, label) and quantity == SOLID_FRACTION:
            assert estimate.mean == 0.0 and estimate.half_width == 0.0


def _stamp_blocks(path, change) -> None:
    """elements.txt with each block's step replaced by change(step)."""
    lines = (path / "elements.txt").read_text().splitlines()
    (path / "elements.txt").write_text("\n".join(
        f"{change(int(line.split()[0]))} {line.split()[1]}" if not line.startswith("#") and len(line.split()) == 2
        else line for line in lines) + "\n")


def test_records_at_other_times_are_refused(two_continuations):
    """Blocks half a block later than the reference's are not samples of the same times: an error, not a
    comparison of unrelated samples. One step later (rounding of a block's stamp) still pairs."""
    reference, other = two_continuations
    _stamp_blocks(other, lambda step: step + 1)
    assert paired_differences(Run(reference), Run(other), START, END)
    _stamp_blocks(other, lambda step: step - 1 + 10000)  # blocks every 20 000 steps: half a block later
    with pytest.raises(AnalysisInputError, match="share 0 element blocks"):
        paired_differences(Run(reference), Run(other), START, END)


def test_a_run_at_another_time_step_pairs_on_its_longer_blocks(two_continuations):
    """A time-step study: the setting's run writes every N steps at twice the step, so each of its
    blocks covers two of the reference's. Written from the same underlying values (the setting's
    block: the mean of the reference's two, one offset on one element), the paired difference is that
    offset exactly, on every quantity, with the reference's pairs of blocks averaged."""
    reference, other = two_continuations
    rng = np.random.default_rng(3)
    values = 0.10 + rng.normal(0, 0.01, 100)
    _rewrite_solid_fraction(reference, lambda k, value: values[k])
    _rewrite_solid_fraction(other, lambda k, value: 0.5 * (values[k - k % 2] + values[k - k % 2 + 1]) + 0.003)
    lines = (other / "elements.txt").read_text().splitlines()
    header = [line for line in lines if line.startswith("#")]
    body = [line for line in lines if not line.startswith("#")]
    rows = int(body[0].split()[1]) + 1
    blocks = [body[k:k + rows] for k in range(0, len(body), rows)]
    (other / "elements.txt").write_text("\n".join(header + [line for block in blocks[1::2] for line in block]) + "\n")
    runs = Run(reference), Run(other)
    label = runs[0].zones.labels[ZONE - 1]
    found = paired_differences(*runs, START, END)
    assert found[(SOLID_FRACTION, label)].mean == pytest.approx(0.003, abs=1e-12)
    assert found[(SOLID_FRACTION, label)].half_width == pytest.approx(0.0, abs=1e-12)
    assert found[(SOLID_FRACTION, runs[0].zones.labels[0])].mean == pytest.approx(0.0, abs=1e-15)


def _set_variables(path, **variables) -> None:
    params = json.loads((path / "params.json").read_text())
    params["variables"].update({k: str(v) for k, v in variables.items()})
    (path / "params.json").write_text(json.dumps(params))


def test_a_study_over_states_and_its_registry_entries(tmp_path):
    """Three states: each run carries the reference's shared fluctuation, its own noise and the same
    offset +0.004 on one element. The study combines the three paired differences (Student's t, 2
    degrees of freedom) and finds the offset within its interval; the registry entry for solid fraction
    names that element as the worst scope, the setting's two values and its bound."""
    reference = tmp_path / "reference"
    write_run(reference, kind="periodic", dumps=None, meshes=False, seed=7)
    rng = np.random.default_rng(5)
    shared = 0.03 * np.sin(np.arange(100) / 3.0)
    _rewrite_solid_fraction(reference, lambda k, value: value + shared[k])
    _set_variables(reference, dt_fraction=0.1)
    runs = []
    for state in range(3):
        run = tmp_path / f"state-{state}"
        shutil.copytree(reference, run)
        noise = rng.normal(0, 0.002, 100)
        _rewrite_solid_fraction(run, lambda k, value, noise=noise: value + noise[k] + 0.004)
        _set_variables(run, dt_fraction=0.2, t_startup=START)
        runs.append(Run(run))
    rows = paired_study(Run(reference), runs, END - START)
    label = runs[0].zones.labels[ZONE - 1]
    row = next(r for r in rows if r.key == (SOLID_FRACTION, label))
    assert row.difference.replicas == 3 and row.difference.method == "replica means"
    assert abs(row.difference.mean - 0.004) <= row.difference.half_width
    assert row.bound == pytest.approx((abs(row.difference.mean) + row.difference.half_width) / abs(row.reference))
    assert len(row.per_state) == 3
    # each state's own interval: the offset 0.004 against noise of 0.002 per block, over 100 blocks the
    # half-width is about 2 x 0.002 / 10: every state resolves the offset on its own
    assert all(d.mean == pytest.approx(0.004, abs=0.0015) for d in row.per_state)
    assert 0 < row.state_half_width < 0.002
    assert row.states_differing == 3
    untouched = next(r for r in rows if r.key == (SOLID_FRACTION, runs[0].zones.labels[0]))
    assert untouched.states_differing == 0  # an element no run changed: no state differs
    entries = systematics.from_paired(rows, Run(reference).parameters, "test-study", "studies/x", "3 states x 0.6 s",
                                      "dt_fraction", "0.2")
    solid = next(e for e in entries if e.quantity == SOLID_FRACTION)
    assert (solid.scope, solid.reference, solid.value, solid.setting) == (label, "0.1", "0.2", "dt_fraction")
    assert solid.relative_bound == pytest.approx(row.bound)
    assert {e.quantity for e in entries} == {r.key[0] for r in rows}
    with pytest.raises(AnalysisInputError, match="'rpm' is not allowed"):
        systematics.from_paired(rows, Run(reference).parameters, "x", "y", "z", "rpm", "1")


def test_a_study_compared_after_a_skip_leaves_out_the_start(tmp_path):
    """An offset present only in the window's first half: over the whole window the study finds about half of
    it, compared from the middle on it finds none; a skip outside [0, window) is refused by name."""
    reference = tmp_path / "reference"
    write_run(reference, kind="periodic", dumps=None, meshes=False, seed=7)
    ends = Run(reference).block_times[1]
    middle = START + (END - START) / 2
    runs = []
    for state in range(3):
        run = tmp_path / f"state-{state}"
        shutil.copytree(reference, run)
        _rewrite_solid_fraction(run, lambda k, value: value + (0.004 if ends[k] <= middle else 0.0))
        _set_variables(run, t_startup=START)
        runs.append(Run(run))
    label = runs[0].zones.labels[ZONE - 1]
    whole = next(r for r in paired_study(Run(reference), runs, END - START) if r.key == (SOLID_FRACTION, label))
    later = next(r for r in paired_study(Run(reference), runs, END - START, skip=middle - START)
                 if r.key == (SOLID_FRACTION, label))
    assert 0.001 < whole.difference.mean < 0.003
    assert later.difference.mean == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(AnalysisInputError, match="skip = 0.6 s is not allowed"):
        paired_study(Run(reference), runs, END - START, skip=END - START)
