#!/usr/bin/env python3
"""docs/status.md from the JSON that tools/scripts/status.sh measured.

    python3 tools/scripts/status_table.py DIR > docs/status.md

DIR holds one folder per character: bake.json (sinew-bake --json), bench.json
(sinew-bench --json) and run.txt (name, what, date, cores, the two commands). The page
is a function of those files alone, so a test can check that docs/status.md is what
they give. A figure a file lacks prints as a dash.
"""
import json
import os
import sys


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"status_table.py: {path}: {e}")


def run_info(path):
    info = {}
    with open(path) as f:
        for line in f:
            key, sep, value = line.rstrip("\n").partition("=")
            if sep:
                info[key] = value
    return info


def fig(d, key, fmt):
    v = d.get(key)
    if v is None or isinstance(v, (list, dict)):
        return "–"
    return fmt.format(v)


def row(name, bake, bench):
    beyond = bake.get("heldout_beyond_training")
    beyond = str(len(beyond)) if isinstance(beyond, list) else "–"
    return "| {} | {} | {} | {} | {} / {} | {} | {} | {} | {} | {} / {} | {} | {} | {} |".format(
        name,
        fig(bake, "tets", "{:,}"),
        fig(bake, "rank", "{}"),
        fig(bake, "cubature_tets", "{}"),
        fig(bake, "err_train", "{:.4f}"),
        fig(bake, "err_heldout", "{:.3f}"),
        beyond,
        fig(bench, "sub_ms", "{:.3f}"),
        fig(bench, "dqs_ms", "{:.4f}"),
        fig(bench, "cost_vs_dqs", "{:.1f}"),
        fig(bench, "allocs_in_step", "{}"),
        fig(bench, "locks_in_step", "{}"),
        fig(bench, "failed_steps", "{}"),
        fig(bake, "bake_seconds", "{:.0f}"),
        {"whole_clip": "the whole clip", "as_measured": "as measured"}.get(bake.get("shipped"), "–"),
    )


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: status_table.py DIR")
    top = sys.argv[1]
    names = sorted(n for n in os.listdir(top) if os.path.isfile(os.path.join(top, n, "run.txt")))
    if not names:
        sys.exit(f"status_table.py: no measured character in {top}")
    runs = {n: run_info(os.path.join(top, n, "run.txt")) for n in names}
    out = [
        "# Status",
        "",
        "Where each character stands, as `tools/scripts/status.sh` last measured it (this page",
        "is written by `tools/scripts/status_table.py` from the JSON in `docs/status/`; do not",
        "edit it by hand). Errors are the share of the full-space correction the blob misses",
        "(0: the reference, 1: no better than plain skinning), on the motion it trained on and",
        "on the motion it held out. Cost is the runtime's step against plain dual-quaternion",
        "skinning of the same surface, measured in the same run; allocations and locks are",
        "counted inside the step. A character whose only clip is split is measured on the",
        "split, then baked again on the whole clip: the blob benchmarked is that one, and the",
        "bake's seconds are the measured bake's. The measurements of the way here are in",
        "`docs/notes/`.",
        "",
        "| character | tets | rank | cubature tets | error train / held-out | joints beyond training | step ms | skinning ms | cost vs skinning | allocations / locks | failed steps | bake s | blob trained on |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for n in names:
        d = os.path.join(top, n)
        out.append(row(n, load(os.path.join(d, "bake.json")), load(os.path.join(d, "bench.json"))))
    out += ["", "## What was measured", ""]
    for n in names:
        r = runs[n]
        out += [
            f"- **{n}**: {r.get('what', '')} ({r.get('date', '?')}, {r.get('cores', '?')} cores"
            + (f", load average {r['load']} when it started" if "load" in r else "")
            + ")",
            f"  - `{r.get('bake', '')}`",
            f"  - `{r.get('bench', '')}`",
        ]
    out += ["", "DATA is the shared assets' folder (`../shared/data`); B is the blob the bake wrote."]
    print("\n".join(out))


main()
