"""Solid-fraction binning of a known arrangement, and per-element averaging of elements.txt blocks."""
import numpy as np
import pytest

from tsg_analysis.cross_section import (BORE_RADIUS, CENTRE_DISTANCE, grid_edges, inside_bore,
                                        solid_fraction_maps)
from tsg_analysis.dumps import ParticleFrame
from tsg_analysis.profiles import (aligned_positions, block_mask, domain_throughput, element_estimates,
                                   element_holdup_residence,
                                   holdup_residence, zone_residence_times)
from tsg_analysis.run import Run
from tsg_analysis.run_files import AnalysisInputError, ElementStatistics, ResidenceRecords, Zones

BIN = 1e-3
RADIUS = 3e-4
VOLUME = 4 / 3 * np.pi * RADIUS**3


def frame(x, y, z, radius=RADIUS):
    n = len(x)
    return ParticleFrame(0, {"x": np.asarray(x, float), "y": np.asarray(y, float), "z": np.asarray(z, float),
                             "radius": np.full(n, radius)})


def test_known_arrangement_gives_its_analytic_solid_fraction():
    y_edges, z_edges = grid_edges(BIN)
    # the bin whose lower corner is (-9 mm, -5 mm): on the bottom of screw 1's bore
    i, j = np.searchsorted(y_edges, -9e-3), np.searchsorted(z_edges, -5e-3)
    centre = (0.5 * (y_edges[i] + y_edges[i + 1]), 0.5 * (z_edges[j] + z_edges[j + 1]))
    conveying, kneading = [(0.0, 0.01), (0.02, 0.03)], [(0.01, 0.02)]
    frames = [
        frame([0.001, 0.005, 0.025, 0.015, 0.035], [centre[0]] * 5, [centre[1]] * 5),  # 3 conveying, 1 kneading
        frame([0.002, 0.012], [centre[0]] * 2, [centre[1]] * 2),  # 1 conveying, 1 kneading
    ]
    maps = solid_fraction_maps(frames, {"conveying": conveying, "kneading": kneading}, bin_size=BIN)
    bin_volume_conveying = BIN**2 * 0.02  # two 10 mm ranges
    assert maps["conveying"].solid_fraction[i, j] == pytest.approx(4 * VOLUME / (bin_volume_conveying * 2))
    assert maps["kneading"].solid_fraction[i, j] == pytest.approx(2 * VOLUME / (BIN**2 * 0.01 * 2))
    assert maps["conveying"].frames == 2 and maps["conveying"].axial_length == pytest.approx(0.02)
    others = np.nan_to_num(maps["conveying"].solid_fraction.copy())
    others[i, j] = 0
    assert not others.any()  # nothing leaks into other bins


def test_bins_outside_the_twin_bore_are_blank():
    maps = solid_fraction_maps([frame([0.001], [0.0], [0.0])], {"conveying": [(0.0, 0.01)]}, bin_size=BIN)
    m = maps["conveying"]
    y, z = np.meshgrid(0.5 * (m.y_edges[1:] + m.y_edges[:-1]), 0.5 * (m.z_edges[1:] + m.z_edges[:-1]), indexing="ij")
    inside = inside_bore(y, z)
    assert np.all(np.isnan(m.solid_fraction[~inside])) and np.all(np.isfinite(m.solid_fraction[inside]))
    # the free bore area is recovered by the bins to within the staircase of the circles
    half = CENTRE_DISTANCE / 2
    alpha = np.arccos(half / BORE_RADIUS)
    bore_area = 2 * ((np.pi - alpha) * BORE_RADIUS**2 + half * BORE_RADIUS * np.sin(alpha))
    assert inside.sum() * BIN**2 == pytest.approx(bore_area, rel=0.02)


def test_no_frames_is_an_input_error():
    with pytest.raises(AnalysisInputError, match="no dump frames"):
        solid_fraction_maps([], {"conveying": [(0.0, 0.01)]})


ZONES = Zones(("conveying", "kneading"), np.array([0.0, 0.02]), np.array([0.02, 0.025]), np.array([1e-5, 2e-6]))


def stats(timesteps, solid_fraction, speed, mass):
    values = np.stack([solid_fraction, speed, speed, np.ones_like(mass), mass], axis=-1)
    return ElementStatistics(np.asarray(timesteps), values)


def test_velocities_are_mass_weighted_and_blocks_follow_the_window():
    s = stats([100, 200, 300],
              np.array([[0.9, 0.9], [0.1, 0.2], [0.3, 0.4]]),
              np.array([[9.0, 9.0], [1.0, 2.0], [3.0, 0.0]]),
              np.array([[5, 5], [10, 30], [30, 0]], dtype=float))
    estimates, used = element_estimates(s, ZONES, block_mask(s, 100))  # block 100 covers steps 0-100
    assert used.sum() == 2
    np.testing.assert_allclose([e.mean for e in estimates["solid_fraction"]], [0.2, 0.3])
    np.testing.assert_allclose([e.mean for e in estimates["mean_speed"]], [(10 * 1 + 30 * 3) / 40, 2.0])
    assert not any(e.resolved for e in estimates["mean_speed"])  # two blocks: no interval claimed
    assert list(block_mask(s, None)) == [True, True, True]
    assert list(block_mask(s, 100, 200)) == [False, True, False]   # block 300 ends after step 200
    with pytest.raises(AnalysisInputError, match="no block inside"):
        element_estimates(s, ZONES, block_mask(s, 1000))


def test_holdup_over_throughput_is_littles_law():
    # constant hold-up 3 g + 1 g moving at 0.1 and 0.05 m/s through 20 + 5 mm: flux (3e-3·0.1 + 1e-3·0.05)/0.025
    blocks = 200
    rng = np.random.default_rng(5)
    mass = np.tile([3e-3, 1e-3], (blocks, 1)) * (1 + 0.01 * rng.normal(size=(blocks, 2)))
    velocity = np.tile([0.1, 0.05], (blocks, 1)) * (1 + 0.01 * rng.normal(size=(blocks, 2)))
    values = np.stack([np.full_like(mass, 0.1), velocity, velocity, np.ones_like(mass), mass], axis=-1)
    s = ElementStatistics(np.arange(1, blocks + 1) * 100, values)
    times = s.timesteps * 1e-5
    used = np.ones(blocks, bool)
    flux = (3e-3 * 0.1 + 1e-3 * 0.05) / 0.025  # kg/s
    residence = holdup_residence(s, ZONES, used, times)
    assert residence["total"].mean == pytest.approx(4e-3 / flux, rel=0.01)
    assert residence["kneading"].mean == pytest.approx(1e-3 / flux, rel=0.01)
    assert residence["total"].resolved and residence["total"].half_width < 0.01 * residence["total"].mean
    assert domain_throughput(s, ZONES, used, times).mean == pytest.approx(flux * 3600, rel=0.01)
    # per element (the report's residence profile without complete records): m_e / Q, summing to the total
    per_element = element_holdup_residence(s, ZONES, used, times)
    assert [e.mean for e in per_element] == pytest.approx([3e-3 / flux, 1e-3 / flux], rel=0.01)
    assert sum(e.mean for e in per_element) == pytest.approx(residence["total"].mean, rel=1e-9)


def test_fixture_profiles_recover_the_prescribed_values(periodic_run):
    from make_fixture import ELEMENT_VALUES, STEADY_FROM, DT

    run_dir, _ = periodic_run
    run = Run(run_dir)
    zones = run.zones
    estimates, _ = element_estimates(run.elements, zones, block_mask(run.elements, STEADY_FROM / DT))
    expected = np.array([ELEMENT_VALUES[kind] for kind in zones.kind])
    np.testing.assert_allclose([e.mean for e in estimates["solid_fraction"]], expected[:, 0])
    np.testing.assert_allclose([e.mean for e in estimates["mean_axial_velocity"]], expected[:, 2])


def test_zone_residence_times_and_mismatch():
    records = ResidenceRecords(np.arange(3), np.zeros(3), np.ones(3), np.ones(3), np.array(["outlet"] * 3),
                               {}, np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]]))
    np.testing.assert_allclose([e.mean for e in zone_residence_times(records, ZONES, np.array([True, True, False]))],
                               [2.0, 3.0])
    three = Zones(("conveying",) * 3, np.zeros(3), np.ones(3), np.ones(3))
    with pytest.raises(AnalysisInputError, match="2 zone columns but zones.txt 3 zones"):
        zone_residence_times(records, three, np.ones(3, bool))


def test_runs_align_on_their_first_kneading_element():
    full = Zones(("conveying", "kneading", "conveying", "kneading", "conveying"), *np.ones((3, 5)))
    periodic = Zones(("conveying", "conveying", "kneading", "conveying"), *np.ones((3, 4)))
    positions = aligned_positions([full, periodic])
    assert list(positions[0]) == [1, 2, 3, 4, 5] and list(positions[1]) == [0, 1, 2, 3]
