#!/usr/bin/env python3
"""Throughput on a shared machine (benchmark, not a test): BenchSPH, BenchElasticSolid and BenchApproximation
run idle, beside one busy process (`sha256sum /dev/zero`, the default environment: no OMP_* or
MESHFREE_NUM_THREADS variable) and on one thread; prints a Markdown table with the ratios.

Target (issue 16): busy >= 0.8 x idle x (fraction of cores left free) -- on 2 cores with one busy process,
>= 0.4 x idle -- and never below the 1-thread figure.

Usage: bench_shared_machine.py [--bin build/bin] [--before DIR_WITH_OLD_BINARIES] [--reps 2]
With --before, the same table is measured for the binaries in DIR first (e.g. copies made before a change),
so both tables come from the same minutes of the same machine.
"""
import argparse
import os
import re
import subprocess
import sys
import time


def clean_env(threads=None):
    env = {k: v for k, v in os.environ.items() if not k.startswith("OMP_") and k != "MESHFREE_NUM_THREADS"}
    if threads:
        env["MESHFREE_NUM_THREADS"] = str(threads)
        env["OMP_NUM_THREADS"] = str(threads)  # binaries built before Common/Parallel.h read this one
    return env


def parse_sph(text):
    rows = {}
    for line in text.splitlines():
        f = line.split()
        if len(f) == 5 and f[0].isdigit() and f[0] in ("16384", "65536"):
            rows["SPH %s particles (particle-steps/s)" % f[0]] = float(f[3])
    return rows


def parse_solid(text):
    rows = {}
    for line in text.splitlines():
        m = re.match(r"symplectic\s+(\w+)\s+contacts (on|off)\s*:\s*(\d+) phyxels.*?, ([0-9.e+]+) phyxel-steps/s", line)
        if m and m.group(2) == "on":
            rows["Solid %s basis, %s phyxels (phyxel-steps/s)" % (m.group(1), m.group(3))] = float(m.group(4))
    return rows


def parse_approximation(text):
    rows = {}
    for line in text.splitlines():
        m = re.search(r"evaluations, (\d+) thread\(s\): [0-9.]+ s = ([0-9.e+]+) evaluations/s", line)
        if m and m.group(1) != "1":  # the all-threads row (with one thread allowed it is the only row)
            rows["MLS degree 2, 2D (evaluations/s)"] = float(m.group(2))
        elif m and "MLS degree 2, 2D (evaluations/s)" not in rows:
            rows["MLS degree 2, 2D (evaluations/s)"] = float(m.group(2))
    return rows


BENCHES = [
    ("BenchSPH", ["0.01"], parse_sph),
    ("BenchElasticSolid", ["30", "10"], parse_solid),
    ("BenchApproximation", ["1000000"], parse_approximation),
]


def run_all(bindir, env, reps):
    best = {}
    for name, args, parse in BENCHES:
        for _ in range(reps):
            out = subprocess.run([os.path.join(bindir, name)] + args, env=env, capture_output=True, text=True,
                                 check=True).stdout
            for key, value in parse(out).items():
                best[key] = max(best.get(key, 0.0), value)
    return best


def measure(bindir, reps):
    results = {}
    results["idle"] = run_all(bindir, clean_env(), reps)
    results["1 thread"] = run_all(bindir, clean_env(threads=1), reps)
    busy = subprocess.Popen(["sha256sum", "/dev/zero"], stdout=subprocess.DEVNULL)
    try:
        time.sleep(1.0)
        results["busy"] = run_all(bindir, clean_env(), reps)
    finally:
        busy.kill()
        busy.wait()
    return results


def table(title, results, cores):
    free = (cores - 1) / cores
    lines = ["### " + title, "",
             "| case | idle | 1 thread | beside 1 busy process | busy / idle | target %.2f x idle | busy / 1 thread |"
             % (0.8 * free), "|---|---|---|---|---|---|---|"]
    for key in results["idle"]:
        idle, one, busy = results["idle"][key], results["1 thread"].get(key, 0.0), results["busy"].get(key, 0.0)
        ok = busy >= 0.8 * free * idle and busy >= one
        lines.append("| %s | %.3g | %.3g | %.3g | %.2f | %s | %.2f |" % (
            key, idle, one, busy, busy / idle, "met" if ok else "missed", busy / one if one else 0.0))
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bin", default=os.path.join(os.path.dirname(__file__), "..", "..", "build", "bin"))
    parser.add_argument("--before", help="directory with the binaries of the version to compare with")
    parser.add_argument("--reps", type=int, default=2, help="runs per case; the best is kept (default 2)")
    a = parser.parse_args()
    cores = os.cpu_count() or 1
    print("%d cores; load average before: %s" % (cores, open("/proc/loadavg").read().split()[:3]), flush=True)
    if a.before:
        print(table("before (%s)" % a.before, measure(a.before, a.reps), cores), flush=True)
        print()
    print(table("now (%s)" % os.path.normpath(a.bin), measure(a.bin, a.reps), cores), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
