#!/usr/bin/env python3
"""Joins grade.py's results for several controllers into README.md's table.

Usage: table.py NAME=RESULTS.jsonl [NAME=RESULTS.jsonl ...]
One row per scenario and criterion: the bound, then each controller's measured value, a
failed criterion marked **FAIL**; a last row per controller sums the scenarios it passed.
"""
import json
import math
import sys


def shown(value, criterion):
    if isinstance(value, str) or value is None:
        return str(value)
    if math.isinf(value):
        return "never"
    if criterion.endswith("_m"):
        return "%.4g mm" % (value * 1000.0)
    if criterion == "credibility_min":
        return "%.7f" % value
    return "%.4g" % value


def main():
    names, runs = [], []
    for argument in sys.argv[1:]:
        name, path = argument.split("=", 1)
        names.append(name)
        runs.append([json.loads(line) for line in open(path)])
    print("| scenario | criterion | bound | " + " | ".join(names) + " |")
    print("|---|---|---|" + "---|" * len(names))
    for index, first in enumerate(runs[0]):
        for row, criterion in enumerate(first["criteria"]):
            cells = []
            for run in runs:
                result = run[index]["criteria"][row]
                text = shown(result["measured"], result["criterion"])
                cells.append(text if result["pass"] else "**FAIL** " + text)
            bound = shown(criterion["bound"], criterion["criterion"])
            scenario = first["scenario"] if row == 0 else ""
            print("| %s | %s | %s | %s |" % (scenario, criterion["criterion"], bound,
                                             " | ".join(cells)))
    passed = ["%d of %d" % (sum(r["pass"] for r in run), len(run)) for run in runs]
    print("| **scenarios passed** | | | " + " | ".join(passed) + " |")


if __name__ == "__main__":
    main()
