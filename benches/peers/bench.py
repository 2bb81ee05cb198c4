#!/usr/bin/env python3
"""Times each peer setting over several whole-process runs (wall clock,
min / median) and prints a markdown table of times, event values and their
errors. Used by run.sh; settings by environment:
  RUNS (default 5)             runs per AUTO setting (after one warm-up)
  PYEL_RUNS (default 1)        runs per PyElastica setting (after one warm-up)
  NTST (default "50 100 200")  AUTO meshes timed
  REF_NTST (default 400)       AUTO mesh of the converged reference (run once)
  PYEL_N (default "100 200")   PyElastica element counts ("" to skip)
  OMP_NUM_THREADS              AUTO-07p's OpenMP threads (run.sh sets 1 unless given)
"""
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
AUTO = [sys.executable, os.path.join(HERE, "auto07p", "run_auto.py")]
PYEL = [sys.executable, os.path.join(HERE, "pyelastica", "appendix_d.py")]
# knotrod (discrete elastic rods, N = 200): docs/performance.md, issue 20
DER = {"W2": 0.81835, "X": 0.96399, "W1": 0.77393, "BP": 0.75126, "LP": 0.73927}
ORDER = ["W2", "X", "W1", "BP", "LP"]


def timed(cmd, runs, warmup=1):
    walls, out = [], None
    for k in range(warmup + runs):
        t = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True)
        w = time.perf_counter() - t
        if p.returncode != 0:
            sys.stderr.write(p.stderr)
            raise SystemExit("failed: %s" % " ".join(cmd))
        out = json.loads(p.stdout.strip().splitlines()[-1])
        if k >= warmup:
            walls.append(w)
    return min(walls), statistics.median(walls), len(walls), out


def auto_version():
    try:
        v = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "auto-07p"],
                           capture_output=True, text=True).stdout
        return "AUTO-07p " + v
    except OSError:
        return "AUTO-07p"


def main():
    runs = int(os.environ.get("RUNS", 5))
    pyel_runs = int(os.environ.get("PYEL_RUNS", 1))
    ntsts = [int(x) for x in os.environ.get("NTST", "50 100 200").split()]
    ref_ntst = int(os.environ.get("REF_NTST", 400))
    pyel_n = [int(x) for x in os.environ.get("PYEL_N", "100 200").split()]
    tmp = os.environ.get("PEERS_OUT", os.path.join(HERE, "auto07p", "out"))

    # converged reference: AUTO at REF_NTST, once
    ref = json.loads(subprocess.run(AUTO + ["--ntst", str(ref_ntst), "--dir", os.path.join(tmp, "ref")],
                                    capture_output=True, text=True, check=True).stdout.splitlines()[-1])
    R = ref["events"]
    ver = auto_version()
    rows = []
    for ntst in ntsts:
        for lean in (True, False):
            cmd = AUTO + ["--ntst", str(ntst), "--dir", os.path.join(tmp, "%s%d" % ("lean" if lean else "full", ntst))]
            if lean:
                cmd.append("--lean")
            tmin, tmed, n, out = timed(cmd, runs)
            setting = "NCOL=4 NTST=%d, %s threads, %s" % (ntst, os.environ.get("OMP_NUM_THREADS", "all"), "LP+BP only (no solutions stored)" if lean
                                              else "all events (every step stored + post-processing)")
            rows.append((ver, setting, tmin, tmed, n, out["events"]))
    print("### Events φ/2π (reference: AUTO-07p NCOL=4 NTST=%d; error = value − reference)\n" % ref_ntst)
    print("| tool | version | setting | runs | wall min (s) | wall median (s) | " +
          " | ".join(ORDER) + " |")
    print("|" + "---|" * (6 + len(ORDER)))
    print("| AUTO-07p | %s | NCOL=4 NTST=%d (reference, 1 run) | 1 | – | – | %s |" % (
        ver.split()[-1], ref_ntst, " | ".join("%.9f" % R[k] if k in R else "–" for k in ORDER)))
    for tool, setting, tmin, tmed, n, ev in rows:
        cells = []
        for k in ORDER:
            cells.append("%.9f (%+.1e)" % (ev[k], ev[k] - R[k]) if k in ev and k in R else "–")
        print("| AUTO-07p | %s | %s | %d | %.2f | %.2f | %s |" % (tool.split()[-1], setting, n, tmin, tmed,
                                                                " | ".join(cells)))
    print("| knotrod | – | DER N=200 (docs/performance.md) | – | – | – | %s |" % " | ".join(
        "%.5f (%+.1e)" % (DER[k], DER[k] - R[k]) if k in R else "%.5f" % DER[k] for k in ORDER))

    if pyel_n:
        n0, m0 = ref["n0"], ref["m0"]
        print("\n### Appendix D equilibrium (φ/2π = 0.802): n(0), m(0); reference AUTO-07p NTST=%d\n" % ref_ntst)
        print("| tool | version | setting | runs | wall min (s) | wall median (s) | steps | n(0) | m(0) | "
              "max abs err n(0) | max abs err m(0) |")
        print("|" + "---|" * 11)
        fmt = lambda v: "[" + ", ".join("%.4f" % x for x in v) + "]"
        print("| AUTO-07p | %s | collocation NTST=%d | – | – | – | – | %s | %s | – | – |" % (
            ver.split()[-1], ref_ntst, fmt(n0), fmt(m0)))
        for N in pyel_n:
            tmin, tmed, n, out = timed(PYEL + ["--n", str(N)], pyel_runs)
            en = max(abs(a - b) for a, b in zip(out["n0"], n0))
            em = max(abs(a - b) for a, b in zip(out["m0"], m0))
            print("| PyElastica | %s | N=%d, damped PositionVerlet dt=%.2g, tol %g%s | %d | %.1f | %.1f | %d | %s | %s | %.3f | %.4f |" % (
                out["version"], N, out["dt"], out["tol"], "" if out["converged"] else " (NOT converged)",
                n, tmin, tmed, out["steps"], fmt(out["n0"]), fmt(out["m0"]), en, em))


if __name__ == "__main__":
    main()
