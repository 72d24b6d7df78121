#!/usr/bin/env python3
"""Reads a nextpnr-ice40 --report JSON and fails unless Fmax(clk) >= 100 MHz and
Fmax(spi_sclk) >= 31.25 MHz; prints Fmax and the resource use (docs/fpga.md quotes them)."""
import json
import sys

NEEDED = {"clk": 100.0, "spi_sclk": 31.25}


def main() -> int:
    if len(sys.argv) != 2:
        print("usage: check_timing.py REPORT.json", file=sys.stderr)
        return 2
    with open(sys.argv[1], encoding="utf-8") as f:
        report = json.load(f)
    ok = True
    fmax = report.get("fmax", {})
    for name, need in NEEDED.items():
        found = [v for k, v in fmax.items() if k.split("$")[0] == name]
        if not found:
            print(f"FAIL {name}: no Fmax in the report")
            ok = False
            continue
        achieved = found[0]["achieved"]
        verdict = "ok  " if achieved >= need else "FAIL"
        ok = ok and achieved >= need
        print(f"{verdict} {name}: Fmax {achieved:.2f} MHz (needs {need} MHz)")
    for cell, use in sorted(report.get("utilization", {}).items()):
        if use["used"]:
            print(f"     {cell}: {use['used']} / {use['available']}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
