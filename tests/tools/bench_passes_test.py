#!/usr/bin/env python3
"""tools/scripts/bench_passes.py reports what bench measured: each round's figures are bench's
own (flow / floor is that run's material over its floor), each build's median lies in its range
and is the median of its rounds, the ratios are the medians' quotients, and a build that cannot
run, a NAME=BINARY without its name and a program that is not siviflow end it with exit 1.

usage: python3 -B bench_passes_test.py SIVIFLOW SOURCE WORK [--env VAR=VALUE ...]   (script_main.py)
"""
import os
import re
import statistics
import sys

from script_main import run_main, test_setup

ROUNDS = 3
NUMBER = r"([0-9.]+)"


def figures(text):
    """{label: value} of a "label value, label value" list."""
    return {label.strip(): float(value) for label, value in
            re.findall(r"([a-z /-]+?) " + NUMBER + r"(?:,|$)", text.strip())}


def ratio_slack(num, den):
    """How far a printed ratio may lie from the ratio of its printed terms: each is rounded to
    3 decimals (0.0005), and a pass of tens of microseconds at 96x54 makes that a percent."""
    ratio = num / den
    return ratio * (0.0005 / num + 0.0005 / den) + 0.0005 + 1e-9


def main():
    siviflow, _, work, bench_passes = test_setup("bench_passes")
    labels = [label for label, _ in bench_passes.FIGURES]
    failures = []
    status, printed = run_main(bench_passes, [
        "--rounds", str(ROUNDS), "--size", "96x54", "--frames", "3", f"a={siviflow}",
        f"b={siviflow}"])
    if status != 0:
        sys.exit(f"bench_passes.py failed ({status}):\n{printed}")
    rounds = {"a": [], "b": []}
    for name, text in re.findall(r"^round \d+: (a|b): (.*)$", printed, re.MULTILINE):
        values = figures(text)
        if sorted(values) != sorted(labels):
            failures.append(f"round line of {name} holds {sorted(values)}")
            continue
        ratio = values["flow material"] / values["flow floor"]
        if abs(values["flow / floor"] - ratio) > ratio_slack(values["flow material"], values["flow floor"]):
            failures.append(f"{name}: flow / floor {values['flow / floor']}, material / floor {ratio}")
        rounds[name].append(values)
    if [len(rounds["a"]), len(rounds["b"])] != [ROUNDS, ROUNDS]:
        failures.append(f"rounds reported: {len(rounds['a'])} and {len(rounds['b'])}")
    medians = {}
    for name in "ab":
        line = re.search(rf"^{name}: (.*)$", printed, re.MULTILINE)
        if line is None:
            failures.append(f"no summary of {name}")
            continue
        summary = re.findall(r"([a-z /-]+?) " + NUMBER + r" \(" + NUMBER + "-" + NUMBER + r"\)",
                             line.group(1))
        medians[name] = {label.strip("; "): float(median) for label, median, _, _ in summary}
        for label, median, low, high in summary:
            label = label.strip("; ")
            median, low, high = float(median), float(low), float(high)
            ran = [values[label] for values in rounds[name]]
            if not low <= median <= high:
                failures.append(f"{name} {label}: median {median} outside {low}-{high}")
            if abs(median - statistics.median(ran)) > 1e-3 or abs(low - min(ran)) > 1e-3:
                failures.append(f"{name} {label}: {median} ({low}-{high}) from rounds {ran}")
        if sorted(medians[name]) != sorted(labels):
            failures.append(f"summary of {name} holds {sorted(medians[name])}")
    ratios = re.search(r"^b / a: (.*)$", printed, re.MULTILINE)
    if ratios is None or len(medians) != 2:
        failures.append("no ratios of b over a")
    else:
        for label, value in figures(ratios.group(1)).items():
            expected = medians["b"][label] / medians["a"][label]
            if abs(value - expected) > ratio_slack(medians["b"][label], medians["a"][label]):
                failures.append(f"b / a {label}: {value}, the medians give {expected}")
    # /bin/true stands for a program that is not siviflow; a sanitizer's preload is for siviflow.
    os.environ.pop("LD_PRELOAD", None)
    for arguments, needle in [
            ([f"a={work / 'no-such-siviflow'}"], "a: cannot run"),
            (["=" + siviflow], "each build is NAME=BINARY"),
            (["a=/bin/true"], "a: /bin/true bench --json printed no pass times")]:
        status, said = run_main(bench_passes, ["--rounds", "1", "--size", "96x54"] + arguments)
        if status != 1 or needle not in said:
            failures.append(f"{arguments}: exit {status}, {said!r}")
    if failures:
        sys.exit("\n".join(failures))
    print(f"{ROUNDS} rounds of two builds: figures, medians, ranges and ratios as bench measured")


if __name__ == "__main__":
    main()
