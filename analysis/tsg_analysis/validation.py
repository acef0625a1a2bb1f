"""What the seed paper reports for its sensitivity matrix, and our runs' directions beside it.

Morrissey, Hanley & Ooi 2021, Section 4 (mass flow in the periodic system at fixed hold-up, Fig. 18)
and Sections 3.2–3.4 (per-element directions, Figs. 13–16). Directions are the sign of a variant's
difference from the reference: +1 higher, −1 lower, 0 "almost no change" (the paper's words).
`directions(rows)` sets ours beside them: a difference counts only when it is significant
(its 95 % interval excludes zero; uncertainty.Difference), otherwise "not resolved".
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .model import AXIAL_VELOCITY, DOMAIN_FLUX, MASS_FLOW, SOLID_FRACTION
from .profiles import domain_flux
from .run import Run
from .run_files import AnalysisInputError
from .uncertainty import Estimate, detect_start, replica_means

# Section 4: mass flow (kg/h) at MFS_1/MFS_2 of the periodic system; the reference is the full
# granulator's 14.4 kg/h, reproduced as 14.4–14.6 by the periodic reference.
PAPER_MASS_FLOW: dict[str, tuple[float, float]] = {
    "reference": (14.4, 14.6),
    "restitution-0.1": (14.4, 14.6),       # "almost no change" (low restitution)
    "psd-sigma-0.2": (14.4, 14.6),         # "almost no change" (size distribution)
    "restitution-0.9": (13.7, 14.1),       # "slightly reducing"
    "static-friction-0.1": (20.0, 20.5),   # "just over 20 kg/h" (≈ +5 kg/h)
    "rolling-friction-0.2": (12.0, 13.3),  # "approximately 12–13.3 kg/h"
    "cohesion-high": (3.5, 4.5),           # "reduced by just over 10 kg/h" (Fig. 18: about 4)
}

CONVEYING = ("C1", "C2")
KNEADING = ("K1", "K2", "K3", "K4", "K5", "K6")
FIRST_KNEADING = ("K1", "K2")


@dataclass(frozen=True)
class Claim:
    variant: str
    quantity: str
    scopes: tuple[str, ...]
    direction: int  # +1, −1, 0
    source: str  # where the paper says it

    @property
    def label(self) -> str:
        names = {CONVEYING: "conveying", KNEADING: "kneading", FIRST_KNEADING: "K1–K2", CONVEYING + KNEADING: "all elements"}
        scope = names.get(self.scopes, ", ".join(self.scopes))
        return f"{self.quantity} {scope}"


def _mass_flow_claims() -> list[Claim]:
    low, high = PAPER_MASS_FLOW["reference"]
    claims = []
    for variant, (a, b) in PAPER_MASS_FLOW.items():
        if variant != "reference":
            direction = 0 if (a, b) == (low, high) else (1 if a > high else -1)
            claims.append(Claim(variant, MASS_FLOW, (DOMAIN_FLUX,), direction, "Sec. 4, Fig. 18"))
    return claims


PAPER_CLAIMS: list[Claim] = [
    *_mass_flow_claims(),
    Claim("restitution-0.9", SOLID_FRACTION, KNEADING, +1, "Sec. 4: slightly higher on kneading elements"),
    Claim("restitution-0.9", AXIAL_VELOCITY, KNEADING, -1, "Sec. 3.2, Fig. 13: reduced axial velocity, kneading"),
    Claim("static-friction-0.1", SOLID_FRACTION, KNEADING, -1, "Sec. 3.3, Fig. 14: lower, particularly kneading"),
    Claim("static-friction-0.1", SOLID_FRACTION, CONVEYING, -1, "Sec. 3.3, Fig. 14: lower across all elements"),
    Claim("static-friction-0.1", AXIAL_VELOCITY, KNEADING, +1, "Sec. 3.3, Fig. 14: larger μs,pg retards flow"),
    Claim("rolling-friction-0.2", SOLID_FRACTION, FIRST_KNEADING, +1, "Sec. 3.3, Fig. 15: held up on K1, K2"),
    Claim("rolling-friction-0.2", AXIAL_VELOCITY, CONVEYING + KNEADING, -1, "Sec. 3.3, Fig. 15: lower on all elements"),
    Claim("cohesion-high", SOLID_FRACTION, FIRST_KNEADING, +1, "Sec. 3.4, Fig. 16: up on the first two kneading"),
    Claim("cohesion-high", SOLID_FRACTION, CONVEYING, -1, "Sec. 3.4, Fig. 16: down on conveying (fixed mass)"),
    Claim("cohesion-high", AXIAL_VELOCITY, KNEADING, -1, "Sec. 3.4, Fig. 16: longitudinal velocity decreases"),
    # the particle–particle-only and particle–geometry-only variations (Figs. 13–15)
    Claim("e_pp-0.9", SOLID_FRACTION, CONVEYING + KNEADING, 0, "Sec. 3.2, Fig. 13: χpp 0.9 has little effect"),
    Claim("e_pg-0.9", AXIAL_VELOCITY, KNEADING, -1, "Sec. 3.2, Fig. 13: χpg up, axial velocity down"),
    Claim("mus_pg-0.1", SOLID_FRACTION, KNEADING, -1, "Sec. 3.3, Fig. 14: lower μs,pg, lower solid fraction"),
    Claim("mus_pg-0.1", AXIAL_VELOCITY, KNEADING, +1, "Sec. 3.3, Fig. 14: larger μs,pg retards flow"),
    Claim("mur_pp-0.2", SOLID_FRACTION, FIRST_KNEADING, +1, "Sec. 3.3, Fig. 15: held up on K1, K2 (either μr)"),
    Claim("mur_pg-0.2", SOLID_FRACTION, FIRST_KNEADING, +1, "Sec. 3.3, Fig. 15: held up on K1, K2 (either μr)"),
    Claim("mur_pp-0.2", AXIAL_VELOCITY, CONVEYING + KNEADING, -1, "Sec. 3.3, Fig. 15: lower on all elements"),
    Claim("mur_pg-0.2", AXIAL_VELOCITY, CONVEYING + KNEADING, -1, "Sec. 3.3, Fig. 15: lower on all elements"),
]


@dataclass(frozen=True)
class PairClaim:
    """A claim of Figs. 13–15 that sets two variations side by side: `first` and `second` fall into
    one group ("same": their difference is not significant and its interval narrower than the gap
    between the groups, `other_group`'s change from the reference, element by element), or `first` moves the
    quantity further from the reference than `second` does ("further": first − second significant in
    the direction of first's own change)."""

    first: str
    second: str
    relation: str  # "same" | "further"
    quantity: str
    scopes: tuple[str, ...]
    source: str
    other_group: str = ""  # "same": a variant of the other group

    @property
    def label(self) -> str:
        return Claim(self.first, self.quantity, self.scopes, 0, self.source).label

    @property
    def pair(self) -> str:
        """The variant name of the first − second comparison rows."""
        return f"{self.first} − {self.second}"


PAIR_CLAIMS: list[PairClaim] = [
    PairClaim("mus_pp-0.1", "reference", "same", SOLID_FRACTION, CONVEYING + KNEADING,
              "Sec. 3.3, Fig. 14: two groups, distinguished by μs,pg", "mus_pg-0.1"),
    PairClaim("mus_pp-0.1", "reference", "same", AXIAL_VELOCITY, CONVEYING + KNEADING,
              "Sec. 3.3, Fig. 14: the two groups even more apparent in axial velocity", "mus_pg-0.1"),
    PairClaim("e_pg-0.9", "e_pp-0.9", "further", SOLID_FRACTION, CONVEYING + KNEADING,
              "Sec. 3.2, Fig. 13: the particle–geometry χ is the more influential"),
    PairClaim("mus_pg-0.1", "static-friction-0.1", "same", SOLID_FRACTION, CONVEYING + KNEADING,
              "Sec. 3.3, Fig. 14: two groups, distinguished by μs,pg", "reference"),
    PairClaim("mus_pg-0.1", "static-friction-0.1", "same", AXIAL_VELOCITY, CONVEYING + KNEADING,
              "Sec. 3.3, Fig. 14: the two groups even more apparent in axial velocity", "reference"),
    PairClaim("mur_pp-0.2", "mur_pg-0.2", "further", AXIAL_VELOCITY, CONVEYING + KNEADING,
              "Sec. 3.3, Fig. 15: axial velocity reduced more by μr,pp than by μr,pg"),
    PairClaim("rolling-friction-0.2", "mur_pp-0.2", "further", AXIAL_VELOCITY, CONVEYING + KNEADING,
              "Sec. 3.3, Fig. 15: both together, the largest reduction"),
]


@dataclass(frozen=True)
class Verdict:
    claim: Claim
    ours: str  # "+", "−", "not resolved", "mixed", "window too short", "no data"
    agrees: str  # "yes", "no", "not resolved", "partly"
    detail: str  # the differences, scope by scope


def _sign(value: float) -> str:
    return "+" if value > 0 else "−"


def directions(rows: Sequence, claims: Sequence[Claim] = PAPER_CLAIMS) -> list[Verdict]:
    """Each claim against the comparison rows (summary.ComparisonRow) of its variant."""
    verdicts = []
    for claim in claims:
        found = [r for r in rows if r.variant == claim.variant and r.quantity == claim.quantity and r.scope in claim.scopes]
        if not found:
            verdicts.append(Verdict(claim, "no data", "not resolved", "variant not run"))
            continue
        signs = [("?" if not r.difference.inputs_resolved else _sign(r.difference.value) if r.difference.significant
                  else "·") for r in found]
        detail = ", ".join(f"{r.scope} {r.difference.relative:+.0%}" + (
            "" if r.difference.significant else " (n.s.)" if r.difference.inputs_resolved else " (too short)")
            for r in found)
        resolved = {s for s in signs if s in ("+", "−")}
        if all(s == "?" for s in signs):
            ours = "window too short"
        elif not resolved:
            ours = "not resolved"
        elif len(resolved) == 2:
            ours = "mixed"
        else:
            ours = resolved.pop()
        expected = {1: "+", -1: "−", 0: None}[claim.direction]
        if ours == "window too short":
            agrees = "not resolved"
        elif claim.direction == 0:
            agrees = ("yes" if "?" not in signs else "partly") if ours == "not resolved" else "no"
        elif ours == expected:
            agrees = "yes" if all(s == expected for s in signs) else "partly"
        elif ours == "not resolved":
            agrees = "not resolved"
        else:
            agrees = "no" if ours != "mixed" else "partly"
        verdicts.append(Verdict(claim, ours, agrees, detail))
    return verdicts


def pair_verdicts(rows: Sequence, pair_rows: Sequence, claims: Sequence[PairClaim] = PAIR_CLAIMS) -> list[Verdict]:
    """Each pair claim against `pair_rows` (summary.compare_runs of `first` against `second`,
    variant named PairClaim.pair) and, for "further", first's own change in `rows` (against the
    reference). Verdicts carry a Claim of `first` with direction 0 ("same") or its change's sign."""
    verdicts = []
    for claim in claims:
        found = [r for r in pair_rows if r.variant == claim.pair and r.quantity == claim.quantity and r.scope in claim.scopes]
        own = {r.scope: r.difference for r in rows if r.variant == claim.first and r.quantity == claim.quantity}
        # the other group's change from the reference (the reference itself is 0 from the first group's)
        group = claim.other_group if claim.other_group != "reference" else claim.first
        gaps = {r.scope: r.difference for r in rows if r.variant == group and r.quantity == claim.quantity}
        stand_in = Claim(claim.pair, claim.quantity, claim.scopes, 0, claim.source)
        if not found:
            verdicts.append(Verdict(stand_in, "no data", "not resolved", "a variant not run"))
            continue
        marks = []
        for r in found:
            d = r.difference
            if not d.inputs_resolved:
                marks.append("?")
            elif claim.relation == "same":
                # one group only where the pair's interval is narrower than first's own change from the
                # reference (the gap to the other group); a wide interval decides nothing
                gap = gaps.get(r.scope)
                marks.append("no" if d.significant else "yes" if gap is not None and d.half_width < abs(gap.value) else "·")
            elif not d.significant or r.scope not in own or not own[r.scope].significant:
                marks.append("·")
            else:
                marks.append("yes" if (d.value > 0) == (own[r.scope].value > 0) else "no")
        detail = ", ".join(f"{r.scope} {r.difference.value / r.reference.mean:+.0%} ± {r.difference.half_width / r.reference.mean:.0%}"
                           if r.reference.mean else f"{r.scope} {r.difference.value:+.3g} ± {r.difference.half_width:.2g}"
                           for r in found)
        decided = [m for m in marks if m in ("yes", "no")]
        if not decided:
            ours, agrees = ("window too short" if all(m == "?" for m in marks) else "not resolved"), "not resolved"
        else:
            ours = (f"holds on {marks.count('yes')}, contradicted on {marks.count('no')}, undecided on "
                    f"{len(marks) - len(decided)} of {len(marks)}")
            agrees = "yes" if marks.count("yes") == len(marks) else "no" if not marks.count("yes") else "partly"
        verdicts.append(Verdict(stand_in, ours, agrees, detail))
    return verdicts


def pair_markdown(verdicts: Sequence[Verdict], claims: Sequence[PairClaim] = PAIR_CLAIMS) -> str:
    relation = {c.pair + c.quantity: c.relation for c in claims}
    lines = ["| first − second | quantity | paper | ours (elements; at 95 %) | agrees | "
             "first − second per element (relative to second ± 95 %) | paper's words |", "|---|---|---|---|---|---|---|"]
    for v in verdicts:
        said = {"same": "one group", "further": "first changes it more"}[relation.get(v.claim.variant + v.claim.quantity, "same")]
        lines.append(f"| {v.claim.variant} | {v.claim.label} | {said} | {v.ours} | {v.agrees} | {v.detail} | {v.claim.source} |")
    return "\n".join(lines) + "\n"


def directions_markdown(verdicts: Sequence[Verdict]) -> str:
    arrow = {1: "+", -1: "−", 0: "no change"}
    lines = ["| variant | quantity | paper | ours | agrees | our differences (relative; n.s.: not significant; too short: "
             "too few replicas or independent samples) | paper's words |",
             "|---|---|---|---|---|---|---|"]
    for v in verdicts:
        lines.append(f"| {v.claim.variant} | {v.claim.label} | {arrow[v.claim.direction]} | {v.ours} | {v.agrees} | "
                     f"{v.detail} | {v.claim.source} |")
    return "\n".join(lines) + "\n"


STEADY_WITHIN = 0.5  # the steady window keeps at least this share of a run's record


def steady_start(run: Run) -> float | None:
    """When the run's domain flux Σ m v_x / L becomes stationary (s): the start-up detection of
    uncertainty.detect_start with the origin in the first STEADY_WITHIN of the record; None for a
    record under 10 blocks."""
    _, ends = run.block_times
    flux = domain_flux(run.elements, run.zones, np.ones(len(ends), bool))
    return detect_start(flux, ends, STEADY_WITHIN)


def flux_parts(runs: Sequence[Run], parts: int = 2, start: float | None = None) -> list[Estimate]:
    """The domain flux Σ m v_x / L over `parts` consecutive, equal shares of each run's element
    blocks (those that begin at or after `start` s when given), each share combined over the
    replicas (window means): whether a difference from the reference persists or fades as the
    start-up does, and whether the flux has stopped drifting."""
    if parts < 1:
        raise ValueError(f"parts {parts}: at least 1")
    means: list[list[float]] = [[] for _ in range(parts)]
    for run in runs:
        begins, ends = run.block_times
        chosen = np.flatnonzero(run.blocks(start))
        if len(chosen) < 2 * parts:
            raise AnalysisInputError(f"{run.path}: {len(chosen)} element blocks"
                                     + (f" from {start} s" if start is not None else "")
                                     + f", too few to split in {parts} parts of at least 2")
        for k, share in enumerate(np.array_split(chosen, parts)):
            flux = run.key_estimates(float(begins[share[0]]), float(ends[share[-1]]))
            means[k].append(flux[(MASS_FLOW, DOMAIN_FLUX)].mean)
    return [replica_means([_point(m) for m in part]) for part in means]


def _point(mean: float) -> Estimate:
    return Estimate(mean, math.nan, 1, 1.0, math.nan)


def parts_markdown(parts: dict[str, list[Estimate]]) -> str:
    """Per setting: the flux in each part of the window (replica means ± 95 %) and its change from
    the reference's in the same part."""
    count = max(len(values) for values in parts.values())
    lines = ["| setting | " + " | ".join(f"flux, part {k + 1} (kg/h) | vs reference" for k in range(count)) + " |",
             "|---|" + "---|---|" * count]
    reference = parts.get("reference")
    for name, values in parts.items():
        cells = []
        for k, value in enumerate(values):
            change = "" if reference is None or name == "reference" else \
                f"{value.mean / reference[k].mean - 1:+.0%}"
            cells += [value.text(), change]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
