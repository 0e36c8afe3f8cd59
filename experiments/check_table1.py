#!/usr/bin/env python3
"""Checks bars on a `handcentric table1` result (DIR/table1.json); exit 1 naming each bar missed.

    check_table1.py table1.json --min hand_centric:flow:100:ood_success:0.8 \
                                --max absolute:flow:100:ood_success:0.3

A bar is METHOD:HEAD:DEMOS:FIELD:VALUE, checked on the mean over training seeds. A bar whose
row or field is missing fails (a table that lacks the cell has not shown the claim).
"""
import argparse
import json
import sys


def bar(text):
    parts = text.split(":")
    if len(parts) != 5:
        raise argparse.ArgumentTypeError(f"bar '{text}' is not METHOD:HEAD:DEMOS:FIELD:VALUE")
    method, head, demos, field, value = parts
    return method, head, int(demos), field, float(value)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("table")
    parser.add_argument("--min", type=bar, action="append", default=[],
                        help="value must be >= this")
    parser.add_argument("--max", type=bar, action="append", default=[],
                        help="value must be <= this")
    args = parser.parse_args()
    with open(args.table) as f:
        rows = json.load(f)["rows"]
    failures = []
    bars = [(b, ">=") for b in args.min] + [(b, "<=") for b in args.max]
    for (method, head, demos, field, value), op in bars:
        values = [r[field] for r in rows
                  if r["method"] == method and r["head"] == head and r["demos"] == demos
                  and r.get(field) is not None]
        name = f"{method}/{head} at {demos} demos, {field}"
        if not values:
            failures.append(f"{name}: no result")
            continue
        mean = sum(values) / len(values)
        ok = mean >= value if op == ">=" else mean <= value
        print(f"{name} = {mean:.2f} (bar {op} {value}): {'ok' if ok else 'MISSED'}")
        if not ok:
            failures.append(f"{name} = {mean:.2f}, bar {op} {value}")
    if failures:
        print("check_table1: bars missed: " + "; ".join(failures), file=sys.stderr)
        return 1
    print(f"check_table1: all {len(bars)} bars hold")
    return 0


if __name__ == "__main__":
    sys.exit(main())
