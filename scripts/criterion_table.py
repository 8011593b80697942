#!/usr/bin/env python3
"""Prints a Markdown table of criterion medians for one benchmark group.

usage: scripts/criterion_table.py GROUP [DIVISOR]
Reads target/criterion/GROUP/*/new/{estimates,benchmark}.json and prints the
median time per iteration divided by DIVISOR (or by the benchmark's own
throughput element count when DIVISOR is omitted), in ns.
"""
import json
import pathlib
import sys

group = sys.argv[1]
divisor = float(sys.argv[2]) if len(sys.argv) > 2 else None
root = pathlib.Path(__file__).resolve().parent.parent / "target" / "criterion" / group
rows = []
for d in sorted(root.iterdir()):
    est = d / "new" / "estimates.json"
    if not est.exists():
        continue
    median = json.loads(est.read_text())["median"]["point_estimate"]
    meta = json.loads((d / "new" / "benchmark.json").read_text())
    n = divisor or float((meta.get("throughput") or {}).get("Elements", 1))
    rows.append((meta.get("function_id") or d.name, median / n))
print(f"| {group} | ns |")
print("|---|---:|")
for name, ns in rows:
    print(f"| {name} | {ns:.1f} |")
