#!/usr/bin/env python3
"""The log SLAM judged over many logs and drift seeds (issue 21; BENCHMARKS.md, "Log replay").

A single drift seed's relation error on one log moves by centimetres with which loop closures a
small change lets the replay find. So a setting is judged on every log at several drift seeds:
this script replays them with `log_relations` (`SLAMLAB_DRIFT_SEED`, `SLAMLAB_LOG_SLAM`) and prints
each log's mean relation error over all pairs (m) over the seeds, and the mean over the logs.

  python3 tests/bench/log_seeds.py [--settings K=V,...] [--seeds 21,1,2,3] [--unseen DIR]
                                   [--save OUT.json] [--against BASE.json] [--jobs 2]

The five logs of ../shared/data/carmen (or $SLAMLAB_DATA/carmen) always run; --unseen DIR adds
every corrected log in DIR/carmen that is not one of them (nine were taken from the public
`acschaefer/ple` repository, `data/carmen`; they are read from where they lie, never copied into
this repository). The raw MIT CSAIL log has its robot's own odometry, which no seed touches: it
is replayed once and its figure counted at every seed. --save keeps every log's figure at every seed; --against a saved run also counts the
log-seeds better and worse by more than 5 mm (the lottery shows as many of both).
Build first: cargo build --release -p slamlab --examples --features real-data
"""
import argparse
import concurrent.futures
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXE = os.path.join(ROOT, "target", "release", "examples", "log_relations")
SHARED = ["mit-csail.clf.gz", "intel-corrected.log.gz", "aces-corrected.log.gz",
          "csail-corrected.log.gz", "freiburg-079-corrected.log.gz"]
MARGIN_M = 0.005


def run(log, data, seed, settings):
    """The `all` relation error (m) of one log at one seed."""
    env = dict(os.environ, SLAMLAB_DRIFT_SEED=str(seed), SLAMLAB_LOG_SLAM=settings)
    if data:
        env["SLAMLAB_DATA"] = data
    out = subprocess.run([EXE, log], env=env, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"log_relations {log} (seed {seed}) failed:\n{out.stderr}")
    for line in out.stdout.splitlines():
        if line.startswith("  all"):
            return float(line.split()[1])
    sys.exit(f"log_relations {log} (seed {seed}) printed no 'all' line:\n{out.stdout}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--settings", default="")
    ap.add_argument("--seeds", default="21,1,2,3")
    ap.add_argument("--unseen", help="a directory with carmen/*-corrected.log.gz")
    ap.add_argument("--save")
    ap.add_argument("--against")
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args()
    if not os.path.exists(EXE):
        sys.exit(f"{EXE} is missing: cargo build --release -p slamlab --examples --features real-data")
    seeds = [int(s) for s in a.seeds.split(",")]
    logs = [(log, None) for log in SHARED]
    if a.unseen:
        folder = os.path.join(a.unseen, "carmen")
        logs += [(f, a.unseen) for f in sorted(os.listdir(folder))
                 if f.endswith("-corrected.log.gz") and f not in SHARED]
    # A raw log replays its robot's own odometry: the drift seed does not
    # touch it, so it runs once and its figure stands for every seed.
    def drifted(log):
        return log.endswith("-corrected.log.gz")
    runs = [(log, data, seed) for log, data in logs
            for seed in (seeds if drifted(log) else seeds[:1])]
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        errors = list(pool.map(lambda r: run(r[0], r[1], r[2], a.settings), runs))
    result = {}
    for (log, _, seed), e in zip(runs, errors):
        for s in ([seed] if drifted(log) else seeds):
            result.setdefault(log, {})[str(s)] = e
    base = None
    if a.against:
        with open(a.against) as f:
            base = json.load(f)
    print(f"settings: {a.settings or '(defaults)'}; seeds {a.seeds}")
    print(f"{'log':40} {'mean m':>8}" + (f" {'against':>8}" if base else ""))
    for log, by_seed in result.items():
        mean = statistics.mean(by_seed.values())
        other = statistics.mean(base[log].values()) if base and log in base else None
        print(f"{log:40} {mean:8.3f}" + (f" {other:8.3f}" if other is not None else ""))
    means = [statistics.mean(v.values()) for v in result.values()]
    print(f"{'mean over ' + str(len(means)) + ' logs':40} {statistics.mean(means):8.4f}")
    if base:
        pairs = [(base[log][s], e) for log, v in result.items() for s, e in v.items()
                 if log in base and s in base[log]]
        better = sum(e < b - MARGIN_M for b, e in pairs)
        worse = sum(e > b + MARGIN_M for b, e in pairs)
        print(f"log-seeds better by over {MARGIN_M} m: {better}, worse: {worse}, of {len(pairs)}")
    if a.save:
        with open(a.save, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
