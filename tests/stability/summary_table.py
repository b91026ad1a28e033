#!/usr/bin/env python3
"""Prints the summary the long stability cases wrote (summary.tsv: one tab-separated row per
case and invariant: case, scheme, invariant, worst value, limit) as the Markdown table of
docs/stability.md. Exits 1 when the file is missing or empty (no long case ran).

Usage: summary_table.py SUMMARY_TSV"""
import sys


def main():
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__.split("\n\n")[-1] + "\n")
        return 2
    try:
        with open(sys.argv[1]) as f:
            rows = [line.rstrip("\n").split("\t") for line in f if line.strip()]
    except OSError as exc:
        sys.stderr.write("summary_table.py: %s\n" % exc)
        return 1
    if not rows:
        sys.stderr.write("summary_table.py: %s is empty\n" % sys.argv[1])
        return 1
    print("| case | scheme | invariant | worst | limit |")
    print("|---|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
