"""The systematic errors an accuracy study measured, quoted beside a run's statistical error for the
settings it used: read from accuracy.json (errors relative to the reference's mean, the worst scope
per quantity), kept in a registry, matched to a run's time step, particle size and mesh tolerance;
"not measured" where no study ran a setting."""
import json

import pytest
from tsg_analysis import systematics
from tsg_analysis.parameters import RunParameters


def error(quantity, scope, reference, value, half_width):
    bound = abs(value - reference) + half_width
    return {"quantity": quantity, "scope": scope, "reference": {"mean": reference},
            "difference": {"value": value - reference, "half_width": half_width},
            "significant": abs(value - reference) > half_width, "bound": bound, "relative_bound": bound / reference}


@pytest.fixture
def study(tmp_path):
    points = [
        {"setting": "reference", "value": "", "state": "done", "errors": []},
        {"setting": "dt_fraction", "value": "0.1", "state": "done",
         "errors": [error("mass flow", "domain flux", 3.0, 2.94, 0.09),                 # −2 % ± 3 %
                    error("solid fraction", "K1", 0.040, 0.042, 0.001),                 # +5 % ± 2.5 %: the worst
                    error("solid fraction", "K2", 0.040, 0.0404, 0.001)]},
        {"setting": "sampling", "value": "0.5", "state": "done", "errors": []},          # not a setting of a run
        {"setting": "dt_fraction", "value": "0.05", "state": "failed (exit 1)", "errors": []},
    ]
    (tmp_path / "accuracy.json").write_text(json.dumps({
        "case": "periodic", "scale": "demo", "points": points,
        "reference": {"settings": {"dt_fraction": "0.2", "d_mean": "0.001", "mesh_tolerance": "4e-06"}}}))
    return tmp_path


def parameters(dt_fraction: str, d_mean: float = 0.001) -> RunParameters:
    return RunParameters(600.0, 1263.0, d_mean, "params.json", {"dt_fraction": dt_fraction}, case="periodic",
                         scale="demo", mesh_tolerance=4e-6)


def test_a_study_gives_each_quantity_its_worst_scope_relative_to_the_reference(study):
    entries = systematics.from_accuracy(study, "dt-steady", "0.5 s from steady states")
    assert [(e.setting, e.value, e.reference, e.quantity) for e in entries] == [
        ("dt_fraction", "0.1", "0.2", "mass flow"), ("dt_fraction", "0.1", "0.2", "solid fraction")]
    flow, fraction = entries
    assert flow.relative == pytest.approx(-0.02) and flow.relative_half_width == pytest.approx(0.03)
    assert not flow.significant and flow.relative_bound == pytest.approx(0.05)
    assert fraction.scope == "K1" and fraction.relative == pytest.approx(0.05) and fraction.significant


def test_a_run_sees_what_was_measured_for_its_settings_and_what_was_not(study, tmp_path):
    registry = tmp_path / "registry.json"
    systematics.add(systematics.from_accuracy(study, "dt-steady", "0.5 s from steady states"), registry)
    systematics.add(systematics.from_accuracy(study, "dt-steady", "again"), registry)     # replaced, not doubled
    entries = systematics.load(registry)
    assert len(entries) == 2 and {e.window for e in entries} == {"again"}
    at_reference = "\n".join(systematics.lines_for(parameters("0.2"), entries))
    assert "time step 0.2 of the Rayleigh time: 0.1 instead changes mass flow -2.0% ± 3.0%" in at_reference
    assert "mean diameter 0.001 m: not measured at demo scale" in at_reference
    assert "mesh tolerance 4e-06 m: not measured" in at_reference
    at_point = "\n".join(systematics.lines_for(parameters("0.1"), entries))
    assert "time step 0.1 of the Rayleigh time: against 0.2 (the study's reference) it changes solid fraction +5.0%" in at_point
    other = "\n".join(systematics.lines_for(parameters("0.3"), entries))
    assert "time step 0.3 of the Rayleigh time: not measured" in other


def test_a_study_without_reference_settings_is_refused(tmp_path):
    (tmp_path / "accuracy.json").write_text(json.dumps({"case": "periodic", "scale": "demo", "points": [],
                                                        "reference": {"argv": []}}))
    with pytest.raises(systematics.AnalysisInputError, match="no reference settings"):
        systematics.from_accuracy(tmp_path, "old", "window")
