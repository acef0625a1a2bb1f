"""The pure parts of the accuracy-cost study (tsg_analysis.accuracy) against hand-computed cases:
error and interval of a point, verdict against a tolerance, the cheapest setting, the cost read from
a log, zones of another domain aligned on the reference's."""
import math
from pathlib import Path

import numpy as np
import pytest

from tsg_analysis.accuracy import (
    FAILS,
    MEETS,
    TOO_SHORT,
    UNDECIDED,
    PointError,
    RunCost,
    Tolerance,
    cheapest,
    family_factor,
    point_errors,
    quantity_verdict,
    recommend,
    resolved_scopes,
    run_cost,
    sampling_ends,
    verdict,
)
from tsg_analysis.run import Run
from tsg_analysis.run_files import Zones
from tsg_analysis.uncertainty import Difference, Estimate


def estimate(mean: float, standard_error: float, independent: float = 50.0, half_width: float | None = None) -> Estimate:
    return Estimate(mean, standard_error, 100, independent, 2 * standard_error if half_width is None else half_width)


REFERENCE = estimate(10.0, 0.1)  # ± 0.2, resolved


def fidelity(value: float, half_width: float, resolved: bool = True, reference: Estimate = REFERENCE) -> PointError:
    other = estimate(reference.mean + value, 0.1)
    return PointError("solid fraction", "K1", reference, other,
                      Difference(value, half_width, value / reference.mean, resolved))


def test_difference_of_two_runs_combines_their_intervals_welch():
    # se 0.5 each, 50 independent samples each: error sqrt(0.5^2 + 0.5^2) = 0.70711, Welch dof =
    # 0.25 / (2 x 0.0625 / 49) = 98, t(0.975, 98) = 1.984467 (tables): half-width 1.40324
    errors = point_errors({("mass flow", "flux"): estimate(10.0, 0.5)}, {("mass flow", "flux"): estimate(11.0, 0.5)})
    (error,) = errors
    assert error.difference.value == pytest.approx(1.0)
    assert error.half_width == pytest.approx(1.984467 * math.sqrt(0.5), rel=1e-5)
    assert not error.significant                                  # 1.0 < 1.403: the interval covers zero
    assert error.bound == pytest.approx(1.0 + 1.40324, rel=1e-5)  # the largest error the interval allows
    assert error.lower == 0.0
    assert error.text().startswith("not resolved (within ± 1.4")
    assert "1.0" not in error.text() and "+1" not in error.text()   # the value itself is not printed


def test_bound_lower_and_relative_bound_by_hand():
    error = fidelity(1.0, 0.4)
    assert error.significant
    assert error.bound == pytest.approx(1.4) and error.lower == pytest.approx(0.6)
    assert error.relative_bound == pytest.approx(0.14)              # 1.4 / 10
    # the reference's interval covers zero: no relative scale
    vague = estimate(0.05, 0.1)
    assert math.isnan(fidelity(1.0, 0.4, reference=vague).relative_bound)


@pytest.mark.parametrize("tolerance, expected", [
    ("5%", FAILS),        # allowed 0.5 < lower 0.6: even the interval's lower end is beyond
    ("10%", UNDECIDED),   # allowed 1.0: between lower 0.6 and bound 1.4
    ("15%", MEETS),       # allowed 1.5 >= bound 1.4
    ("1.4", MEETS),       # absolute, equal to the bound
    ("0.59", FAILS),
])
def test_verdict_against_a_tolerance(tolerance, expected):
    assert verdict(fidelity(1.0, 0.4), Tolerance.parse(tolerance)) == expected


def test_unresolved_inputs_are_too_short_and_have_no_bound():
    error = fidelity(1.0, 0.4, resolved=False)
    assert math.isnan(error.bound)
    assert verdict(error, Tolerance.parse("50%")) == TOO_SHORT
    assert error.text() == "window too short: too few independent samples (or replicas)"


def test_sampling_point_error_is_its_bias_plus_its_own_half_width():
    truncated = estimate(10.3, 0.15, half_width=0.3)
    error = PointError("solid fraction", "K1", REFERENCE, truncated, None)
    assert error.offset == pytest.approx(0.3)                          # the window's bias
    assert error.bound == pytest.approx(0.6) and error.relative_bound == pytest.approx(0.06)
    assert error.lower == pytest.approx(0.0)                            # the bias is within its half-width
    assert verdict(error, Tolerance.parse("10%")) == MEETS and verdict(error, Tolerance.parse("5%")) == UNDECIDED
    assert error.text() == "window bias +0.3 (+3.0%), statistical ± 0.3"
    short = PointError("solid fraction", "K1", REFERENCE, estimate(10.3, 0.15, independent=5.0, half_width=0.3), None)
    assert verdict(short, Tolerance.parse("50%")) == TOO_SHORT and short.text().startswith("window too short")


@pytest.mark.parametrize("tolerance, expected", [("5%", FAILS), ("15%", UNDECIDED), ("20%", MEETS)])
def test_biased_short_window_cannot_meet_a_tolerance_its_mean_contradicts(tolerance, expected):
    # studies/accuracy/demo-replicas: sampling 0.25, domain flux 5.483 ± 0.075 kg/h (3 replicas) against the
    # reference's whole record 4.76 ± 0.15 kg/h: +15 %. Its half-width alone (1.4 %) would "meet" 5 %.
    reference = Estimate(4.76, 0.035, 300, 3.0, 0.15, replicas=3, method="replica means")
    point = Estimate(5.483, 0.0175, 75, 3.0, 0.075, replicas=3, method="replica means")
    (error,) = point_errors({("mass flow", "domain flux"): reference}, {("mass flow", "domain flux"): point}, sampling=True)
    assert error.offset == pytest.approx(0.723)
    assert error.lower == pytest.approx(0.648) and error.bound == pytest.approx(0.798)
    assert verdict(error, Tolerance.parse(tolerance)) == expected   # allowed 0.238, 0.714, 0.952 kg/h
    assert quantity_verdict([error], "mass flow", Tolerance.parse(tolerance)) == expected


def test_quantity_verdict_needs_every_scope():
    meets, undecided, fails = fidelity(0.1, 0.1), fidelity(1.0, 0.7), fidelity(2.0, 0.5)
    tolerance = Tolerance.parse("5%")   # allowed 0.5: bounds 0.2, 1.7 (lower 0.3), 2.5 (lower 1.5)
    assert quantity_verdict([meets], "solid fraction", tolerance) == MEETS
    assert quantity_verdict([meets, undecided], "solid fraction", tolerance) == UNDECIDED
    assert quantity_verdict([meets, undecided, fails], "solid fraction", tolerance) == FAILS
    assert quantity_verdict([meets], "speed", tolerance) == "not measured"


def test_cheapest_setting_that_meets_the_tolerance():
    tolerance = Tolerance.parse("5%")
    meets, undecided, fails = [fidelity(0.1, 0.1)], [fidelity(1.0, 0.7)], [fidelity(2.0, 0.5)]
    points = {"dt_fraction 0.1": (10.0, meets), "dt_fraction 0.2": (5.0, meets), "dt_fraction 0.3": (1.0, fails),
              "mesh_tolerance 2e-05": (0.5, undecided)}
    choice = cheapest(points, "solid fraction", tolerance)
    assert choice.label == "dt_fraction 0.2" and choice.cost == 5.0
    none = cheapest({"a": (1.0, fails), "b": (2.0, undecided), "c": (3.0, [fidelity(0.1, 0.1, resolved=False)])},
                    "solid fraction", tolerance)
    assert none.label is None
    assert none.message == "none resolved to this tolerance (1 fails, 1 undecided, 1 window too short)"


def test_recommended_time_step_needs_the_finer_points_to_confirm_the_reference():
    """A coarser (cheaper) point is offered only when it meets the tolerance against the reference
    and every finer (dearer) point shows the reference itself within it; otherwise the reference,
    or none with the verdicts that stop it."""
    tolerance = Tolerance.parse("5%")
    meets, undecided, fails = [fidelity(0.1, 0.1)], [fidelity(0.3, 0.4)], [fidelity(2.0, 0.5)]
    reference_cost = 10.0
    ladder = {"dt_fraction 0.05": (20.0, meets), "dt_fraction 0.2": (5.0, meets), "dt_fraction 0.3": (3.3, fails)}
    choice = recommend(ladder, reference_cost, "solid fraction", tolerance)
    assert (choice.label, choice.cost) == ("dt_fraction 0.2", 5.0)                  # 0.3 fails, 0.2 is next
    only_finer = recommend({"dt_fraction 0.05": (20.0, meets), "dt_fraction 0.2": (5.0, fails)}, reference_cost,
                           "solid fraction", tolerance)
    assert (only_finer.label, only_finer.cost) == ("reference", reference_cost)
    unconfirmed = recommend({"dt_fraction 0.05": (20.0, undecided), "dt_fraction 0.2": (5.0, meets)}, reference_cost,
                            "solid fraction", tolerance)
    assert unconfirmed.label is None and "dt_fraction 0.05 undecided" in unconfirmed.message
    assert recommend({"dt_fraction 0.2": (5.0, meets)}, reference_cost, "solid fraction", tolerance).label is None


@pytest.mark.parametrize("text", ["0%", "-5%", "abc", "nan", "0"])
def test_bad_tolerance_names_the_option(text):
    with pytest.raises(ValueError, match=f"--tolerance {text} is not allowed"):
        Tolerance.parse(text)


def test_tolerance_relative_and_absolute():
    assert Tolerance.parse("5%") == Tolerance(0.05, True)
    assert Tolerance.parse("0.002") == Tolerance(0.002, False)
    assert Tolerance.parse("5%").allowed(-0.2) == pytest.approx(0.01)


LOG = """LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)
    Step           Time    Atoms
       0              0      500
    1000          0.0025     500
Loop time of 10 on 2 procs for 1000 steps with 500 atoms, finish time x
    Step           Time    Atoms
    1000          0.0025     500
    4000          0.01       500
Loop time of 30 on 2 procs for 3000 steps with 500 atoms, finish time x
"""


def test_cost_from_the_log_by_hand(tmp_path):
    (tmp_path / "log.lammps").write_text(LOG)
    cost = run_cost(Run(tmp_path))
    assert cost.wall_seconds == 40 and cost.ranks == 2 and cost.core_seconds == 80
    assert cost.simulated_seconds == pytest.approx(0.01)
    assert cost.core_seconds_per_simulated_second == pytest.approx(8000)
    assert cost.particle_steps_per_second == pytest.approx(500 * 4000 / 40)
    assert cost.steps_per_simulated_second == pytest.approx(4000 / 0.01)
    half = cost.until(0.00625)   # half the second chunk (0.0025-0.01 s): 10 + 15 s of loop
    assert half.core_seconds == pytest.approx(2 * 25) and half.simulated_seconds == pytest.approx(0.00625)
    assert cost.until(0.001).core_seconds == pytest.approx(2 * 4)   # 0.4 of the first chunk


def test_cost_of_a_run_without_a_log_or_unfinished_is_an_error(tmp_path):
    with pytest.raises(ValueError, match="no log"):
        run_cost(Run(tmp_path))
    (tmp_path / "log.lammps").write_text(LOG.rsplit("Loop", 1)[0])   # cut in its last chunk
    with pytest.raises(ValueError, match="did not finish"):
        run_cost(Run(tmp_path))


def zones(kinds: list[str]) -> Zones:
    n = len(kinds)
    return Zones(tuple(kinds), np.arange(n) * 1.0, np.arange(n) + 1.0, np.ones(n))


def test_other_domain_zones_align_on_the_first_kneading_element():
    periodic = zones(["conveying"] + ["kneading"] * 6 + ["conveying"])
    full = zones(["conveying"] * 10 + ["kneading"] * 6 + ["conveying"] + ["kneading"] * 6 + ["conveying", "chopping"])
    labels = full.aligned_labels(periodic)
    assert labels[9] == "C1" and labels[10:16] == ["K1", "K2", "K3", "K4", "K5", "K6"] and labels[16] == "C2"
    assert labels[:9] == [None] * 9 and labels[17:] == [None] * 8
    assert periodic.aligned_labels(periodic) == periodic.labels


def test_several_scopes_need_simultaneous_intervals():
    # Bonferroni over 8 scopes: z(1 - 0.025/8) / z(0.975) = 2.73437 / 1.95996 = 1.39511 (tables)
    assert family_factor(1) == pytest.approx(1.0)
    assert family_factor(8) == pytest.approx(1.39511, rel=1e-5)
    # one of 8 scopes significant at 95 % (1.2 > 1.0) but not with 1.395 x 1.0: not resolved
    errors = [fidelity(1.2, 1.0)] + [fidelity(0.1, 1.0)] * 7
    assert errors[0].significant and resolved_scopes(errors, "solid fraction") == []
    strong = [fidelity(1.5, 1.0)] + [fidelity(0.1, 1.0)] * 7
    assert resolved_scopes(strong, "solid fraction") == strong[:1]
    # the tolerance verdict widens the same way: alone, bound 0.2 + 0.1 meets 3.2 % (0.32); with 8 scopes
    # 0.2 + 1.395 x 0.1 = 0.3395 > 0.32 and lower 0.2 - 0.1395 < 0.32: undecided
    one = [fidelity(0.2, 0.1)]
    assert quantity_verdict(one, "solid fraction", Tolerance.parse("3.2%")) == MEETS
    assert quantity_verdict(one * 8, "solid fraction", Tolerance.parse("3.2%")) == UNDECIDED


def test_points_change_one_setting_and_carry_the_reference(tmp_path):
    from tsg_cases.accuracy import Study, parse

    args = parse([str(tmp_path), "-v", "dt_fraction", "0.1", "-v", "stats_every", "60", "-v", "thermo_every", "600",
                  "-v", "t_sample", "0.02", "--ladder", "dt_fraction", "0.2", "--ladder", "d_mean", "0.0012",
                  "--ladder", "domain", "nonperiodic", "--domain-var", "t_run", "0.05", "--ladder", "np", "2",
                  "--ladder", "mesh_tolerance", "2e-05"])
    points = {p.label: p for p in Study(args).points()}

    def variables(label: str) -> dict[str, str]:
        argv = points[label].argv
        return {argv[k + 1]: argv[k + 2] for k, word in enumerate(argv) if word == "-v"}

    reference = variables("reference")
    assert reference == {"dt_fraction": "0.1", "stats_every": "60", "thermo_every": "600", "t_sample": "0.02"}
    # dt doubles: half the steps per output, the same interval in simulated time
    assert variables("dt_fraction 0.2") == {**reference, "dt_fraction": "0.2", "stats_every": "30", "thermo_every": "300"}
    # dt ∝ d_mean at a fixed PSD width: 60 x 1.0 / 1.2 = 50 steps
    assert variables("d_mean 0.0012") == {**reference, "d_mean": "0.0012", "stats_every": "50", "thermo_every": "500"}
    assert points["np 2"].argv[points["np 2"].argv.index("--np") + 1] == "2"
    assert "--mesh-tolerance" in points["mesh_tolerance 2e-05"].argv and "--mesh-tolerance" not in points["reference"].argv
    # another domain: the reference's physics (the periodic case's cohesion 0, not the non-periodic
    # default 1; the reference's -v values), its own run time, no periodic-only variables
    domain = points["domain nonperiodic"]
    assert domain.case == "nonperiodic" and domain.argv[0] == "nonperiodic"
    carried = variables("domain nonperiodic")
    assert carried["cohesion"] == "0" and carried["dt_fraction"] == "0.1" and carried["t_run"] == "0.05"
    assert "t_sample" not in carried and "t_startup" not in carried and "buffer" not in carried



def test_cost_of_replicas_adds_their_loop_times(tmp_path):
    for k, factor in enumerate((1, 2, 3)):
        (tmp_path / f"r{k}").mkdir()
        (tmp_path / f"r{k}" / "log.lammps").write_text(LOG.replace("Loop time of 10", f"Loop time of {10 * factor}"))
    cost = RunCost.of_replicas([run_cost(Run(tmp_path / f"r{k}")) for k in range(3)])
    assert cost.runs == 3 and cost.wall_seconds == pytest.approx(60 + 3 * 30)   # 10+20+30 and 3 x 30
    assert cost.core_seconds == pytest.approx(2 * 150)
    assert cost.core_seconds_per_simulated_second == pytest.approx(2 * 150 / (3 * 0.01))   # per run
    assert cost.particle_steps_per_second == pytest.approx(3 * 500 * 4000 / 150)
    assert cost.steps_per_simulated_second == pytest.approx(4000 / 0.01)
    assert cost.until(0.0025).core_seconds == pytest.approx(2 * 60) and cost.until(0.0025).runs == 3


def test_replicas_run_each_point_with_seeds_and_combine_their_windows(tmp_path):
    """--replicas 3: every run point is three runs (seeds 1-3) in <point>/seed-K; the analysis
    combines them by their window means; the sampling ladder truncates each reference replica."""
    import json

    from make_fixture import write_run   # tests/analysis/ is on PYTHONPATH (tests/CMakeLists.txt)
    from tsg_cases.accuracy import Study, parse

    study = tmp_path / "study"
    args = parse([str(study), "--replicas", "3", "--ladder", "dt_fraction", "0.15", "--ladder", "sampling", "0.5"])
    points = Study(args).points()
    reference, dt_point, sampling = points
    assert [d.relative_to(study).as_posix() for d in reference.run_dirs] == ["reference/seed-1", "reference/seed-2",
                                                                             "reference/seed-3"]
    assert [a[a.index("--seed") + 1] for a in dt_point.argvs] == ["1", "2", "3"]
    assert sampling.run_dirs == reference.run_dirs and sampling.argvs == []
    for number, (point, run_dir) in enumerate((p, d) for p in (reference, dt_point) for d in p.run_dirs):
        write_run(run_dir, dumps=None, meshes=False, seed=200 + number)
        steps, end = 1000 * np.arange(0, 41), sampling_ends(Run(run_dir), [1.0])[0]   # the log spans the record
        (run_dir / "log.lammps").write_text(
            "    Step           Time    Atoms\n" + "".join(f"{s} {s * end / 40000:g} 500\n" for s in steps)
            + "Loop time of 20 on 1 procs for 40000 steps with 500 atoms, finish time x\n")
        argv = point.argvs[point.run_dirs.index(run_dir)]
        (run_dir / "point.json").write_text(json.dumps({"argv": argv, "state": "done", "wall_seconds": 25.0}))
    s = Study(args)
    points = s.points()
    for p in points:
        if p.setting != "sampling":
            p.state = s.state(p)
    assert [p.state for p in points[:2]] == ["done", "done"] and points[0].wall_seconds == pytest.approx(75.0)
    s.analyse(points)
    assert points[0].cost is not None and points[0].cost.runs == 3 and points[0].cost.core_seconds == pytest.approx(60)
    errors = {(e.quantity, e.scope): e for e in points[1].errors}
    flux = errors[("mass flow", "domain flux Σ m v_x / L")]
    assert flux.reference.replicas == 3 and flux.value.replicas == 3
    # the sampling point: half of each replica's record, combined; its cost half the reference's
    half = {(e.quantity, e.scope): e for e in points[2].errors}[("mass flow", "domain flux Σ m v_x / L")]
    assert half.value.replicas == 3 and half.value.samples < flux.reference.samples
    assert points[2].cost is not None and points[2].cost.core_seconds < points[0].cost.core_seconds
    with pytest.raises(Exception, match="--seed 7 is not allowed with --replicas 3"):
        from tsg_cases.accuracy import run
        run(parse([str(study), "--replicas", "3", "--seed", "7"]))
