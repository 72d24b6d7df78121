#!/usr/bin/env python3
"""Measures one `hiltwin hil` run the way `hiltwin test` grades it (campaign_criteria.h).

Usage: measure.py REPORT.json LOG_DIR [--step [BAND_PCT]]
Prints one JSON object: the report's verdicts and tracking figures, the missed deadlines of
both sides, the share of ECS cycles at full duty (|duty| >= 0.999 on either wheel), and, when
--step is given (the setpoint holds a step: its largest jump between two samples is the
step), settling time and overshoot of the worse
wheel: settling is the time from the step until |wheel - target| stays within BAND_PCT
(default 2) % of the step to the end of the log; overshoot is the largest excursion beyond the
target in % of the step.
"""
import csv
import json
import math
import os
import sys


def read_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {key: [float(row[key]) for row in rows] for key in rows[0]}


def step_response(time_s, setpoint_m, position_m, band_pct):
    jumps = [abs(setpoint_m[i + 1] - setpoint_m[i]) for i in range(len(setpoint_m) - 1)]
    at = max(range(len(jumps)), key=jumps.__getitem__)
    if jumps[at] == 0.0:
        raise ValueError("the setpoint has no step")
    step_m = setpoint_m[at + 1] - setpoint_m[at]
    target_m = setpoint_m[at + 1]
    step_time_s = time_s[at + 1]
    after = range(at + 1, len(time_s))
    beyond = [(position_m[i] - target_m) * math.copysign(1.0, step_m) for i in after]
    overshoot_pct = max(0.0, max(beyond)) / abs(step_m) * 100.0
    band_m = band_pct / 100.0 * abs(step_m)
    last_outside = None
    for i in after:
        if abs(position_m[i] - target_m) > band_m:
            last_outside = i
    if last_outside is None:
        settling_s = 0.0
    elif last_outside == len(time_s) - 1:
        settling_s = math.inf
    else:
        settling_s = time_s[last_outside + 1] - step_time_s
    return {"step_time_s": step_time_s, "step_m": step_m, "overshoot_pct": overshoot_pct,
            "settling_time_s": settling_s}


def measure(report_path, log_dir, with_step, band_pct=2.0):
    """The figures of one hil run: its report (--report) and its ECS log (--log-dir)."""
    report = json.load(open(report_path))
    log = read_columns(os.path.join(log_dir, "ecs.csv"))
    saturated = sum(1 for left, right in zip(log["duty_left"], log["duty_right"])
                    if max(abs(left), abs(right)) >= 0.999)
    twin, ecs = report.get("twin", {}), report.get("ecs", {})
    out = {
        "twin_verdict": twin.get("verdict"),
        "ecs_verdict": ecs.get("verdict"),
        "exit_code": report.get("exit_code"),
        "tracking_max_m": max(report["tracking_error_max_m"].values())
        if report.get("tracking_error_max_m") else None,  # open loop: no setpoint, no figure
        "tracking_rms_m": report.get("tracking_error_rms_m"),
        "final_error_m": report.get("final_error_m"),
        "missed_deadlines": twin.get("deadline_misses", 0) + ecs.get("deadline_misses", 0),
        "duty_saturation_pct": 100.0 * saturated / len(log["duty_left"]),
        "link_errors": report.get("link_errors"),
    }
    for wheel in ("left", "right") if with_step else ():
        response = step_response(log["time_s"], log["setpoint_%s_m" % wheel],
                                 log["wheel_%s_m" % wheel], band_pct)
        for key in ("overshoot_pct", "settling_time_s"):
            out[key] = max(out.get(key, -math.inf), response[key])
    return out


def main():
    with_step = len(sys.argv) > 3 and sys.argv[3] == "--step"
    band_pct = float(sys.argv[4]) if len(sys.argv) > 4 else 2.0
    print(json.dumps(measure(sys.argv[1], sys.argv[2], with_step, band_pct)))


if __name__ == "__main__":
    main()
