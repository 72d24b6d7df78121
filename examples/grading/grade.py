#!/usr/bin/env python3
"""Runs a campaign file's scenarios with `hiltwin hil` and prints what each criterion measured.

A stand-in for `hiltwin test` (issue 38) used to measure the numbers behind the bounds of
campaigns/relbot_course.toml (README.md): it reads the campaign with tomllib, runs every
scenario as the `hil` command the campaign's keys stand for, measures it with measure.py's
definitions (those of cli/runs/include/hiltwin/runs/campaign_criteria.h) and prints one JSON
line per scenario with measured values, bounds and pass/fail. It knows the keys the shipped
campaign uses and refuses the others; `hiltwin test` is the tool, this is its cross-check.

Usage: grade.py HILTWIN CAMPAIGN.toml WORK_DIR [--controller SPEC] [--filter SUBSTRING]
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import time

import tomllib

sys.dont_write_bytecode = True  # no __pycache__ in the source tree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import measure  # noqa: E402

SCENARIO_KEYS = {"name", "kind", "clock", "mode", "controller", "setpoint", "input", "twin_rate_hz",
                 "ecs_rate_hz", "duration_s", "link_faults", "twin_overruns", "params", "criteria"}
DEFAULTS = {"kind": "hil", "clock": "virtual", "mode": "closedloop", "controller": "pid",
            "setpoint": "closedloop", "input": "openloop", "twin_rate_hz": 4000.0,
            "ecs_rate_hz": 1000.0, "duration_s": 0.0, "link_faults": [], "twin_overruns": [],
            "params": {}}


def scenarios(campaign_path):
    with open(campaign_path, "rb") as f:
        campaign = tomllib.load(f)
    defaults = dict(DEFAULTS, **campaign.get("defaults", {}))
    for scenario in campaign["scenario"]:
        unknown = set(scenario) - SCENARIO_KEYS
        if unknown:
            raise SystemExit("grade.py does not know the keys %s" % sorted(unknown))
        merged = dict(defaults, **scenario)
        merged["criteria"] = dict(defaults.get("criteria", {}), **scenario.get("criteria", {}))
        yield merged


def parameter_file(params, work_dir, root):
    """The RELbot parameter file with the scenario's overrides, "section.key" = value."""
    text = open(os.path.join(root, "relbot", "relbot.toml")).read()
    for dotted, value in params.items():
        section, key = dotted.split(".")
        pattern = r"(\[%s\][^\[]*?\n%s = )[^\n]*" % (re.escape(section), re.escape(key))
        text, count = re.subn(pattern, lambda m: m.group(1) + repr(float(value)), text, 1, re.S)
        if count != 1:
            raise SystemExit("no key %s in relbot/relbot.toml" % dotted)
    path = os.path.join(work_dir, "params.toml")
    open(path, "w").write(text)
    return path


def hil_command(hiltwin, s, folder, work_dir, root):
    def near(path):  # a campaign's relative paths are read from its folder
        return path if path in ("closedloop", "openloop") else os.path.join(folder, path)
    cmd = [hiltwin, "hil", "--clock", s["clock"], "--no-progress", "--mode", s["mode"],
           "--twin-rate", str(s["twin_rate_hz"]), "--ecs-rate", str(s["ecs_rate_hz"]),
           "--log-dir", os.path.join(work_dir, "logs"),
           "--report", os.path.join(work_dir, "report.json")]
    if s["mode"] == "closedloop":
        cmd += ["--controller", s["controller"], "--setpoint", near(s["setpoint"])]
    else:
        cmd += ["--input", near(s["input"])]
    if s["duration_s"] > 0:
        cmd += ["--duration", str(s["duration_s"])]
    if s["params"]:
        cmd += ["--config", parameter_file(s["params"], work_dir, root)]
    for fault in s["link_faults"]:
        cmd += ["--twin-arg=--inject-link-fault", "--twin-arg=" + fault]
    for overrun in s["twin_overruns"]:
        cmd += ["--twin-arg=--inject-overrun", "--twin-arg=" + overrun]
    return cmd


def credibility(hiltwin, c, folder, log_dir):
    cmd = [hiltwin, "assess", "--json",
           "--sim", "%s/ecs.csv:%s" % (log_dir, c.get("compare_column", "wheel_right_m")),
           "--exp", "%s:%s" % (os.path.join(folder, c["reference_file"]), c["reference_column"])]
    if "credibility_max_delay_s" in c:
        cmd += ["--max-delay", str(c["credibility_max_delay_s"])]
    assessed = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return json.loads(assessed.stdout)["total"]


VERDICT_ORDER = ["PASS", "FLAGGED", "ABORTED", "NONE", ""]
CRITERIA = [("verdict", "verdict"), ("tracking_max_m", "tracking_max_m"),
            ("tracking_rms_m", "tracking_rms_m"), ("final_error_m", "final_error_m"),
            ("settling_time_s", "settling_time_s"), ("overshoot_pct", "overshoot_pct"),
            ("duty_saturation_pct", "duty_saturation_pct"),
            ("missed_deadlines", "missed_deadlines"), ("credibility_min", "credibility")]


def judge(c, m):
    results = []
    for bound_key, measure_key in CRITERIA:
        if bound_key not in c:
            continue
        value, bound = m.get(measure_key), c[bound_key]
        if value is None:
            passed = False
        elif bound_key == "verdict":
            passed = VERDICT_ORDER.index(value) <= VERDICT_ORDER.index(bound)
        elif bound_key == "credibility_min":
            passed = value >= bound
        else:
            passed = value <= bound
        results.append({"criterion": bound_key, "measured": value, "bound": bound,
                        "pass": passed})
    return results


def run_scenario(hiltwin, s, folder, work_root, root):
    work_dir = os.path.join(work_root, s["name"])
    os.makedirs(work_dir, exist_ok=True)
    started = time.monotonic()
    subprocess.run(hil_command(hiltwin, s, folder, work_dir, root), capture_output=True)
    wall_s = time.monotonic() - started
    c = s["criteria"]
    log_dir = os.path.join(work_dir, "logs")
    m = measure.measure(os.path.join(work_dir, "report.json"), log_dir,
                        "settling_time_s" in c or "overshoot_pct" in c,
                        c.get("settling_band_pct", 2.0))
    m["verdict"] = max((m["twin_verdict"] or "", m["ecs_verdict"] or ""),
                       key=VERDICT_ORDER.index)
    if "credibility_min" in c:
        m["credibility"] = credibility(hiltwin, c, folder, log_dir)
    results = judge(c, m)
    return {"scenario": s["name"], "wall_s": round(wall_s, 2),
            "pass": all(r["pass"] for r in results), "criteria": results}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("hiltwin")
    parser.add_argument("campaign")
    parser.add_argument("work_dir")
    parser.add_argument("--controller", help="replaces every scenario's controller")
    parser.add_argument("--filter", default="")
    args = parser.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    folder = os.path.dirname(os.path.abspath(args.campaign))
    for s in scenarios(args.campaign):
        if args.filter not in s["name"]:
            continue
        if args.controller:
            s["controller"] = args.controller
        result = run_scenario(os.path.abspath(args.hiltwin), s, folder,
                              os.path.abspath(args.work_dir), root)
        print(json.dumps(result, default=lambda x: None if math.isnan(x) else x), flush=True)


if __name__ == "__main__":
    main()
