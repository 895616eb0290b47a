#!/usr/bin/env python3
"""Summarize the `sim` criterion benchmarks as the Markdown tables of BENCHMARKS.md.

Run after the benches (`cargo bench -p sim --bench dynamics`, `... scaling`, `... runs`):

    python3 sim/benches/summarize.py [TARGET_DIR]      # default: ./target

Reads criterion's `TARGET_DIR/criterion/<group>/<id...>/new/estimates.json` and uses
`median.point_estimate` (ns) everywhere; ratios are of those medians. Benchmarks that have
not been run are shown as "-". Standard library only.
"""

import json
import math
import sys
from pathlib import Path

ROOT = Path(sys.argv[1] if len(sys.argv) > 1 else "target") / "criterion"
NS = [5, 10, 20, 30, 50, 75, 100]
FIT_NS = [n for n in NS if 20 <= n <= 100]
RUN_SECONDS = 5.0  # simulated time of every `paper_run` case


def median(bench_id):
    """Median of `group/id` in ns, or None if it has not been run."""
    p = ROOT / bench_id / "new" / "estimates.json"
    if not p.exists():
        return None
    return json.loads(p.read_text())["median"]["point_estimate"]


def fmt_time(ns):
    if ns is None:
        return "-"
    for unit, scale in (("s", 1e9), ("ms", 1e6), ("µs", 1e3)):
        if ns >= scale:
            return f"{ns / scale:.3g} {unit}"
    return f"{ns:.3g} ns"


def ratio(a, b):
    return None if a is None or b is None else a / b


def fmt_ratio(r, suffix="x"):
    return "-" if r is None else f"{r:.2f}{suffix}"


def fit_exponent(times):
    """Least-squares slope of log t against log n over FIT_NS."""
    pts = [(math.log(n), math.log(times[n])) for n in FIT_NS if times.get(n)]
    if len(pts) < 2:
        return None
    mx = sum(x for x, _ in pts) / len(pts)
    my = sum(y for _, y in pts) / len(pts)
    return sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def main():
    # paper arm kernels and right-hand sides
    ids = [
        "paper_arm/rnea", "paper_arm/crba", "paper_arm/walker_orin",
        "paper_arm/forward/crba-schur", "paper_arm/forward/crba-kkt",
        "paper_arm/forward/walker-orin-schur", "paper_arm/forward/walker-orin-kkt",
        "paper_rhs/two-elbow", "paper_rhs/one-elbow", "paper_rhs/no-elbow",
        "paper_rhs/two-elbow-crba-kkt", "paper_rhs/two-elbow-walker-orin-schur",
        "paper_rhs/two-elbow-walker-orin-kkt",
    ]
    m = {i: median(i) for i in ids}
    print("### Paper arm (10 joints), `--bench dynamics`\n")
    print(table(["benchmark", "median"], [[f"`{i}`", fmt_time(m[i])] for i in ids]))

    print("\n### Ratios (same run)\n")
    rows = [
        ("mass matrix: Walker–Orin / CRBA", m["paper_arm/walker_orin"], m["paper_arm/crba"]),
        ("forward dynamics, 2 contacts, Schur: Walker–Orin / CRBA",
         m["paper_arm/forward/walker-orin-schur"], m["paper_arm/forward/crba-schur"]),
        ("constrained RHS (two-elbow), Schur: Walker–Orin / CRBA",
         m["paper_rhs/two-elbow-walker-orin-schur"], m["paper_rhs/two-elbow"]),
        ("constrained RHS (two-elbow): paper plant (WO + KKT) / default (CRBA + Schur)",
         m["paper_rhs/two-elbow-walker-orin-kkt"], m["paper_rhs/two-elbow"]),
        ("forward dynamics, CRBA: KKT / Schur",
         m["paper_arm/forward/crba-kkt"], m["paper_arm/forward/crba-schur"]),
        ("forward dynamics, Walker–Orin: KKT / Schur",
         m["paper_arm/forward/walker-orin-kkt"], m["paper_arm/forward/walker-orin-schur"]),
        ("constrained RHS (two-elbow), CRBA: KKT / Schur",
         m["paper_rhs/two-elbow-crba-kkt"], m["paper_rhs/two-elbow"]),
        ("mass matrix by Walker–Orin (n = 10 RNEA calls at q̇ = 0) / one RNEA",
         m["paper_arm/walker_orin"], m["paper_arm/rnea"]),
    ]
    print(table(["ratio", "value"], [[name, fmt_ratio(ratio(a, b))] for name, a, b in rows]))

    # scaling
    algos = ["rnea", "crba", "walker_orin", "forward"]
    t = {a: {n: median(f"scaling_{a}/{n}") for n in NS} for a in algos}
    print("\n### Chain length, `--bench scaling` (median; in brackets the cost per joint, t / n)\n")
    rows = []
    for n in NS:
        row = [str(n)]
        for a in algos:
            x = t[a][n]
            row.append("-" if x is None else f"{fmt_time(x)} ({fmt_time(x / n)})")
        wo_crba = ratio(t["walker_orin"][n], t["crba"][n])
        row.append(fmt_ratio(wo_crba))
        rows.append(row)
    print(table(["n", "RNEA", "CRBA", "Walker–Orin", "forward (CRBA + Schur, 2 contacts)", "WO / CRBA"], rows))
    print(f"\nFitted exponent p of t ∝ n^p (least squares on log–log, n = {FIT_NS[0]} … {FIT_NS[-1]}):\n")
    fits = []
    for a in algos:
        p = fit_exponent(t[a])
        fits.append([a, "-" if p is None else f"{p:.2f}"])
    print(table(["algorithm", "p"], fits))

    # whole runs
    print(f"\n### Whole runs, `--bench runs` ({RUN_SECONDS:g} s simulated, two-elbow)\n")
    rows = []
    for case in ["two-elbow-dopri45", "two-elbow-rk4", "two-elbow-paper-baseline"]:
        x = median(f"paper_run/{case}")
        rows.append([f"`paper_run/{case}`", fmt_time(x),
                     "-" if x is None else f"{RUN_SECONDS / (x * 1e-9):.2f}"])
    print(table(["benchmark", "median", "simulated / wall time"], rows))
    base = median("paper_run/two-elbow-paper-baseline")
    for case in ["two-elbow-rk4", "two-elbow-dopri45"]:
        r = ratio(base, median(f"paper_run/{case}"))
        print(f"\npaper baseline / {case}: {fmt_ratio(r)}")


if __name__ == "__main__":
    main()
