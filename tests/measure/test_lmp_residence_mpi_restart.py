"""fix residence/time (with fix massflow/planes alongside) on 1, 2 and 4 ranks, and split by a
restart: the sorted records must be identical, line for line. Sums over ranks (mass flow, the mean
residence time) may differ in the last bits with the summation order, and are compared to 1e-12."""
import numpy as np
import pytest

from measure_cases import (BASE, RESTART_BASE, ZONES, Mover, lanes, particles_include, record_lines, variables,
                           zones_text)
from tsg_harness import run_lmp

DT = 1e-4
THERMO = ("thermo_style custom step atoms " + " ".join(f"f_rt[{k}]" for k in range(1, 10)) +
          " f_mf[1] f_mf[2]\nthermo_modify format float %.15g\nthermo 1000\n")


def busy_movers(periodic: bool) -> list[Mover]:
    """40 particles, speeds 0.03 ... 0.3 m/s both ways; with ranks along x they keep migrating."""
    grid = lanes(40)
    movers = []
    for k in range(40):
        v = (0.03 + 0.007 * k) * (-1 if k % 5 == 4 else 1)
        x0 = 0.0015 + (0.0023 * k if periodic else 0.0009 * k)
        movers.append(Mover(x0, v, *grid[k]))
    return movers


def periodic_text(part: str, nsteps: int) -> str:
    """part: 'whole', 'first' (writes the restart) or 'second' (reads it)."""
    fixes = ("fix integr all nve/sphere\n"
             "fix rt all residence/time zones zones.txt records records.txt periodic 0.0 analysis 0.005 0.095 "
             "flush 700 append yes\n"
             "fix mf all massflow/planes planes 2 0.0 0.06 window 1500 file massflow.txt append yes\n"
             f"timestep {DT}\n" + THERMO)
    if part == "second":
        return RESTART_BASE + fixes + f"run {nsteps}\n"
    text = BASE + "include particles.include\n" + fixes
    if part == "whole":
        # deletion between runs as well, so that 'deleted' records are compared too
        return text + (f"run {nsteps // 2}\nregion cut block 0.052 0.068 -0.01 0.01 -0.01 0.01 units box\n"
                       f"delete_atoms region cut compress no\nrun {nsteps - nsteps // 2}\n")
    return text + f"run {nsteps}\nwrite_restart state.restart\n"


def open_text(nsteps: int) -> str:
    return (BASE + "include particles.include\nfix integr all nve/sphere\n"
            "fix rt all residence/time zones zones.txt records records.txt inlet 0.004 outlet 0.085 flush 700\n"
            "fix mf all massflow/planes planes 2 0.02 0.06 window 1500 file massflow.txt\n"
            f"timestep {DT}\n" + THERMO + f"run {nsteps}\n")


def assert_close_tables(lines, reference, what):
    assert len(lines) == len(reference) > 0, what
    a = np.array([[float(v) for v in l.split()] for l in lines])
    b = np.array([[float(v) for v in l.split()] for l in reference])
    np.testing.assert_array_equal(a[:, :2], b[:, :2], err_msg=what)   # step, time
    np.testing.assert_allclose(a[:, 2:], b[:, 2:], rtol=0, atol=1e-12 * np.abs(b[:, 2:]).max(), err_msg=what)


@pytest.mark.parametrize("periodic", [True, False], ids=["periodic", "open"])
def test_same_records_on_1_2_and_4_ranks(tmp_path, periodic):
    movers = busy_movers(periodic)
    files = {"zones.txt": zones_text(), "particles.include": particles_include(movers)}
    results = {}
    for nprocs in (1, 2, 4):
        text = periodic_text("whole", 12000) if periodic else open_text(12000)
        run = run_lmp(text, tmp_path / f"np{nprocs}", nprocs=nprocs, variables=variables(periodic, px=nprocs),
                      files=files)
        run.assert_clean()
        assert f"{nprocs} by 1 by 1 MPI processor grid" in run.log
        results[nprocs] = (sorted(record_lines(tmp_path / f"np{nprocs}" / "records.txt")),
                           record_lines(tmp_path / f"np{nprocs}" / "massflow.txt"),
                           {k: list(v) for k, v in run.thermo[-1].items()})
    lines, flow, thermo = results[1]
    reasons = {l.split()[4] for l in lines}
    assert reasons == ({"pass", "deleted"} if periodic else {"outlet", "lost"}), reasons
    assert len(lines) >= 20
    for nprocs in (2, 4):
        assert results[nprocs][0] == lines, f"records differ between 1 and {nprocs} ranks"
        assert_close_tables(results[nprocs][1], flow, f"mass flow, 1 and {nprocs} ranks")
        for column, values in thermo.items():
            np.testing.assert_allclose(results[nprocs][2][column], values, rtol=1e-12, atol=1e-12 * max(map(abs, values)),
                                       err_msg=f"thermo {column}, 1 and {nprocs} ranks")
    print(f"[ measured ] {'periodic' if periodic else 'open'}: {len(lines)} records "
          f"({', '.join(sorted(reasons))}), identical on 1, 2 and 4 ranks")


def records_close(lines, reference, what):
    """Same particles, reasons and order; times equal to 1e-12 s."""
    assert len(lines) == len(reference), what
    for a, b in zip(lines, reference):
        fa, fb = a.split(), b.split()
        assert (fa[0], fa[4]) == (fb[0], fb[4]), f"{what}: {a} vs {b}"
        np.testing.assert_allclose([float(v) for v in fa[1:4] + fa[5:]], [float(v) for v in fb[1:4] + fb[5:]],
                                   rtol=0, atol=1e-12, err_msg=what)


@pytest.mark.parametrize("ranks", [(1, 1), (2, 2), (2, 4)], ids=["np1", "np2", "np2-then-np4"])
def test_a_run_split_by_a_restart_equals_the_uninterrupted_run(tmp_path, ranks):
    movers = busy_movers(True)
    files = {"zones.txt": zones_text(), "particles.include": particles_include(movers)}
    first_ranks, second_ranks = ranks
    # uninterrupted: one run of 12000 steps
    whole = periodic_text("first", 12000).replace("write_restart state.restart\n", "")
    straight = run_lmp(whole, tmp_path / "whole", nprocs=first_ranks, variables=variables(True, px=first_ranks),
                       files=files)
    # the same process doing `run 6000` twice (what LIGGGHTS's clock gives for a continued run)
    twice = periodic_text("first", 6000).replace("write_restart state.restart\n", "run 6000\n")
    continued = run_lmp(twice, tmp_path / "twice", nprocs=first_ranks, variables=variables(True, px=first_ranks),
                        files=files)
    # split: 6000 steps, restart file, a fresh lmp reads it and runs 6000 more, appending
    split_dir = tmp_path / "split"
    run_lmp(periodic_text("first", 6000), split_dir, nprocs=first_ranks,
            variables=variables(True, px=first_ranks), files=files)
    second = run_lmp(periodic_text("second", 6000), split_dir, nprocs=second_ranks,
                     variables=variables(True, px=second_ranks), input_name="in.second")
    second.assert_clean()
    assert "Resetting per-atom state of Fix rt" in second.log
    assert "Resetting global state of Fix rt" in second.log

    whole_lines = record_lines(tmp_path / "whole" / "records.txt")
    twice_lines = record_lines(tmp_path / "twice" / "records.txt")
    split_lines = record_lines(split_dir / "records.txt")
    assert len(whole_lines) >= 30
    # passes that straddle the restart carry their entry time and zone times across it
    assert any(float(l.split()[1]) < 0.6 < float(l.split()[2]) for l in whole_lines)
    # bit for bit what the continued run gives; to the last bits of the clock what one run gives
    assert split_lines == twice_lines
    records_close(split_lines, whole_lines, "split vs uninterrupted")
    header = [l for l in (split_dir / "records.txt").read_text().splitlines() if l.startswith("#")]
    assert header.count("# tsg-dem residence records v1") == 1, "append must not repeat the header"
    assert_close_tables(record_lines(split_dir / "massflow.txt"), record_lines(tmp_path / "whole" / "massflow.txt"),
                        "mass flow, split and whole run")
    a, b = straight.thermo[-1], second.thermo[-1]
    for column in [f"rt[{k}]" for k in range(1, 10)] + ["mf[1]", "mf[2]"]:
        assert b[column][-1] == pytest.approx(a[column][-1], rel=1e-12, abs=1e-15), column
    assert continued.thermo[-1]["rt[1]"][-1] == a["rt[1]"][-1]


def test_checking_only_particles_near_edges_changes_nothing(tmp_path):
    # With `neigh_modify delay 0 every 1 check yes` (all tests here) the fixes look only at the
    # particles within one skin of a cell edge or sensor between neighbour-list builds; with
    # `check no` (a build every step) they look at every particle every step. Same records (to the
    # last bits: LIGGGHTS wraps positions into the box at every build, so x differs by rounding).
    movers = busy_movers(True)
    files = {"zones.txt": zones_text(), "particles.include": particles_include(movers)}
    outputs = {}
    for check in ("yes", "no"):
        text = periodic_text("whole", 8000).replace("every 1 check yes", f"every 1 check {check}")
        run_lmp(text, tmp_path / check, nprocs=2, variables=variables(True, px=2), files=files)
        outputs[check] = (record_lines(tmp_path / check / "records.txt"),
                          record_lines(tmp_path / check / "massflow.txt"))
    assert len(outputs["yes"][0]) >= 15
    records_close(outputs["yes"][0], outputs["no"][0], "records, check yes / no")
    assert_close_tables(outputs["yes"][1], outputs["no"][1], "mass flow, check yes / no")


def test_restart_without_append_keyword_continues_both_files(tmp_path):
    # The second part gives no 'append' keyword and a zones file with the same zones written
    # differently (comments, number format): the fixes know they continue from a restart file, so
    # they append to records.txt and massflow.txt, whose first part stays byte for byte, and the
    # whole equals the records of the uninterrupted run.
    movers = busy_movers(True)
    files = {"zones.txt": zones_text(), "particles.include": particles_include(movers)}
    straight = periodic_text("first", 12000).replace("write_restart state.restart\n", "")
    run_lmp(straight, tmp_path / "whole", variables=variables(True), files=files)
    split = tmp_path / "split"
    run_lmp(periodic_text("first", 6000), split, variables=variables(True), files=files)
    first_records = (split / "records.txt").read_bytes()
    first_flow = (split / "massflow.txt").read_bytes()
    assert len(record_lines(split / "records.txt")) >= 2
    reformatted = "# the same zones, written by hand\n" + "\n".join(
        f"{i}  {kind}  {a * 1000:g}e-3 {b * 1000:g}e-3 {v:.3e}" for i, kind, a, b, v in ZONES) + "\n"
    (split / "zones.txt").write_text(reformatted)
    second = periodic_text("second", 6000).replace(" append yes", "")
    assert "append" not in second
    run_lmp(second, split, variables=variables(True), input_name="in.second")
    records, flow = (split / "records.txt").read_bytes(), (split / "massflow.txt").read_bytes()
    assert records.startswith(first_records) and len(records) > len(first_records)
    assert flow.startswith(first_flow) and len(flow) > len(first_flow)
    header = [l for l in records.decode().splitlines() if l.startswith("#")]
    assert header.count("# tsg-dem residence records v1") == 1
    records_close(record_lines(split / "records.txt"), record_lines(tmp_path / "whole" / "records.txt"),
                  "split without 'append' vs uninterrupted")
    assert_close_tables(record_lines(split / "massflow.txt"), record_lines(tmp_path / "whole" / "massflow.txt"),
                        "mass flow, split without 'append' and whole run")
