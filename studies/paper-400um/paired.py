"""A setting against the reference, paired by state (treatment-2.7g/, dt-paired-2.7g/). Each run of the
setting continues a state of the reference run at its own start time; over [start, start + WINDOW] it
and the reference are two continuations of one state, compared sample by sample
(tsg_analysis.paired: the difference series, whose interval leaves out what both runs share — the state
they start from and the screws' phase). The R states' differences are combined as replicas are
(uncertainty.replica_means: Student's t with R - 1 degrees of freedom, never narrower than the
difference series' own fluctuation allows).

    LC_ALL=C.UTF-8 .venv/bin/python studies/paper-400um/paired.py REFERENCE WINDOW RUN... [--skip S] \
        [--systematics NAME --setting SETTING --value VALUE --where DIR --window-text TEXT]

With --systematics the worst scope of each quantity goes to the registry the runner's summary and the
report quote (tsg_analysis/systematics.json; SETTING one of its settings, e.g. dt_fraction, VALUE the
runs' value of it, the reference's own read from its parameters).

Per key quantity (mass flow at the sensors and through the domain, per-element solid fraction, axial
velocity and speed): the reference's mean over the R windows, the run's mean paired difference +- its 95 %
half-width (both relative to the reference), "differs" when that interval excludes zero, the bound
|difference| + half-width (the setting is within a tolerance when the bound is), the per-state
differences, the largest 95 % half-width of one state's difference series, how many states' own
intervals exclude zero (in a null pair, where the true difference is zero, about 1 in 20), the largest of a single
window (how well one window resolves the quantity on its own, unpaired), and the mean difference over
the window's second half alone (the difference series starts at zero, the two runs sharing their
state: an effect that is still growing within the window shows there larger than over the whole
window, which then understates where the difference is going).
"""
from __future__ import annotations

import argparse

from tsg_analysis import systematics
from tsg_analysis.paired import continued_from, paired_study
from tsg_analysis.run import Run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("reference", help="the reference run (its states were kept from it)")
    parser.add_argument("window", type=float, help="s each state is compared over, from its start")
    parser.add_argument("runs", nargs="+", help="the setting's runs, one per state")
    parser.add_argument("--skip", type=float, default=0.0, metavar="S",
                        help="compare from S s after each state's start (default 0: the whole window)")
    parser.add_argument("--systematics", metavar="NAME", help="also add the rows to the systematics registry")
    parser.add_argument("--setting", choices=sorted(systematics.SETTINGS))
    parser.add_argument("--value", help="the runs' value of --setting")
    parser.add_argument("--where", help="the study's folder, as the registry names it")
    parser.add_argument("--window-text", help="how the study sampled, as the registry says it")
    args = parser.parse_args()
    reference = Run(args.reference)
    runs = [Run(path) for path in args.runs]
    rows = paired_study(reference, runs, args.window, args.skip)
    starts = ", ".join(f"{continued_from(r):.4f}" for r in runs)
    print(f"{' + '.join(args.runs)} against {args.reference}: {len(runs)} states ({starts} s), {args.window:g} s "
          f"each{f', compared from {args.skip:g} s after its start' if args.skip else ''}; "
          "95 % half-widths relative to the reference's mean, the differences combined as replica means "
          f"({len(runs) - 1} degrees of freedom)")
    print("| quantity | scope | reference | run - reference | differs | bound | per-state differences | "
          "one state's paired half-width | states differing | one window's half-width | second half: run - reference |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        scale = abs(row.reference)
        d = row.difference
        print(f"| {row.key[0]} | {row.key[1]} | {row.reference:.4g} | {d.mean / scale:+.1%} ± {d.half_width / scale:.1%} | "
              f"{'yes' if abs(d.mean) > d.half_width else 'no'} | {row.bound:.1%} | "
              f"{', '.join(f'{x.mean / scale:+.1%}' for x in row.per_state)} | {row.state_half_width / scale:.1%} | "
              f"{row.states_differing}/{len(row.per_state)} | {row.window_half_width / scale:.1%} | "
              f"{row.second_half / scale:+.1%} |")
    if args.systematics:
        if not (args.setting and args.value and args.where and args.window_text):
            parser.error("--systematics needs --setting, --value, --where and --window-text")
        entries = systematics.from_paired(rows, reference.parameters, args.systematics, args.where, args.window_text,
                                          args.setting, args.value)
        systematics.add(entries)
        print(f"{systematics.REGISTRY}: study {args.systematics}, {len(entries)} entries")


if __name__ == "__main__":
    main()
