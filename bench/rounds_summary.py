#!/usr/bin/env python3
"""Summary of interleaved rounds of diefill against a reference code (compare_liggghts.sh,
compare_lammps.sh), as JSON on stdout.

    bench/rounds_summary.py CSV REFERENCE DIEFILL_JSON [--note KEY=VALUE]... [--difference TEXT]...

CSV has the columns repeat,code,threads,particle_steps_per_s (code: REFERENCE or diefill);
DIEFILL_JSON is one round's `diefill bench liggghts --json` (grains, bytes per grain). For each
thread count: median, min, max and the largest deviation from the median of each code; the ratio
diefill/REFERENCE of the medians (ratio_T); and the ratio within each round, where both codes ran
side by side (ratio_per_round_T: median and min over the rounds). Notes (numbers where they
parse as numbers) and differences from diefill's scene are added as given.
"""
import argparse
import csv
import json
import os
import statistics


def spread(values):
    values = sorted(values)
    med = statistics.median(values)
    return {"median": med, "min": values[0], "max": values[-1], "runs": len(values),
            "largest_deviation_from_median": max(abs(x / med - 1) for x in values)}


def cpu_name():
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                return " ".join(line.split(":", 1)[1].split())
    return ""


def value(text):
    try:
        return json.loads(text)
    except ValueError:
        return text


def main():
    p = argparse.ArgumentParser()
    p.add_argument("csv")
    p.add_argument("reference")
    p.add_argument("diefill_json")
    p.add_argument("--note", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--difference", action="append", default=[], metavar="TEXT")
    a = p.parse_args()
    rows = list(csv.DictReader(open(a.csv)))
    first = json.load(open(a.diefill_json))["cases"][0]
    out = {"scene": a.csv, "cores": len(os.sched_getaffinity(0)), "cpu": cpu_name(), "grains": first["grains"],
           "bytes_per_particle": first["runs"][-1].get("bytes_per_particle")}
    for note in a.note:
        key, _, text = note.partition("=")
        out[key] = value(text)
    # rate[code][threads][repeat]
    rate = {}
    for r in rows:
        rate.setdefault(r["code"], {}).setdefault(int(r["threads"]), {})[r["repeat"]] = float(r["particle_steps_per_s"])
    threads = sorted(set(rate[a.reference]) & set(rate["diefill"]))
    for code in (a.reference, "diefill"):
        for t in threads:
            out[f"{code}_{t}"] = spread(rate[code][t].values())
    for t in threads:
        out[f"ratio_{t}"] = out[f"diefill_{t}"]["median"] / out[f"{a.reference}_{t}"]["median"]
    for t in threads:
        ref, die = rate[a.reference][t], rate["diefill"][t]
        per_round = [die[k] / ref[k] for k in ref if k in die]
        out[f"ratio_per_round_{t}"] = {"median": statistics.median(per_round), "min": min(per_round),
                                       "rounds": len(per_round)}
    if a.difference:
        out["differences"] = a.difference
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
