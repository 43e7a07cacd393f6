"""Cost of the Python front: what calling vrw from Python adds to the Rust library's work.

    target/venv/bin/python python/bench/overhead.py [--rounds 3] [--repeat 15] [--skip-cargo]

1. `find_gait` from Python against the same search through the Rust library: `vrw.find_gait(vrw.Params())`
   timed here (median of --repeat calls) against the criterion benchmark `gait/job`
   (`cargo bench --bench walk -- gait/job`), which times `vrw::app::compute_gait` on the same defaults, the
   function the binding calls. The target is an overhead below 5 %. On a shared machine the load changes
   from minute to minute, so the two are measured alternately for --rounds rounds and compared round by
   round (the median of the per-round ratios; the best rounds too). Both run on one thread
   (RAYON_NUM_THREADS=1 unless set), so other processes on the machine disturb them less.
2. A 100-point sweep from Python against the command line's `sweep.csv`: `vrw sweep --points 100` and
   `vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(1, 300, 100))`, compared value by value at full
   precision (the CSV writes the shortest text that reads back to the same float), with both wall times.

Run from the repository root after `scripts/test-all` (which builds the extension and target/release/vrw).
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("RAYON_NUM_THREADS", "1")  # before the first parallel section of vrw

import vrw  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python" / "tests"))
from conftest import assert_table_equals_csv  # noqa: E402


def rust_gait_seconds():
    """Median time of the criterion benchmark `gait/job` [s] (its `bencher` output is in ns/iter)."""
    done = subprocess.run(
        ["cargo", "bench", "--bench", "walk", "--", "gait/job", "--output-format", "bencher"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    match = re.search(r"gait/job\s+\.\.\. bench:\s+([\d,]+) ns/iter", done.stdout)
    if not match:
        raise RuntimeError(f"no gait/job result in:\n{done.stdout}\n{done.stderr}")
    return int(match.group(1).replace(",", "")) * 1e-9


def python_gait_seconds(repeat):
    params = vrw.Params()
    vrw.find_gait(params)  # warm-up
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        gait = vrw.find_gait(params)
        times.append(time.perf_counter() - start)
        assert gait["status"] == "found"
    return statistics.median(times), min(times)


def sweep_100():
    cli = ROOT / "target" / "release" / "vrw"
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        subprocess.run(
            [str(cli), "sweep", "--points", "100", "--out", out], check=True, capture_output=True
        )
        cli_seconds = time.perf_counter() - start
        start = time.perf_counter()
        result = vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(1, 300, 100))
        python_seconds = time.perf_counter() - start
        assert_table_equals_csv(result["sweep"], Path(out) / "sweep.csv")
    return cli_seconds, python_seconds, result["seconds"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--skip-cargo", action="store_true", help="skip the criterion benchmark")
    args = parser.parse_args()

    python, rust = [], []
    for _ in range(args.rounds):
        python.append(python_gait_seconds(args.repeat)[0])
        if not args.skip_cargo:
            rust.append(rust_gait_seconds())
    ms = " / ".join
    print(f"find_gait from Python, median of {args.repeat} calls per round: {ms(f'{t * 1e3:.2f}' for t in python)} ms")
    if rust:
        print(f"compute_gait in Rust (criterion gait/job) per round: {ms(f'{t * 1e3:.2f}' for t in rust)} ms")
        paired = 100 * (statistics.median(p / r for p, r in zip(python, rust)) - 1)
        best = 100 * (min(python) / min(rust) - 1)
        print(
            f"overhead of the Python front: {paired:+.2f} % (median of the rounds' ratios), "
            f"{best:+.2f} % (best rounds); RAYON_NUM_THREADS={os.environ['RAYON_NUM_THREADS']}"
        )

    cli_seconds, python_seconds, parts = sweep_100()
    print(
        f"100-point sweep: command line {cli_seconds:.2f} s (with thresholds and Fig. 2), "
        f"Python {python_seconds:.2f} s (sweep {parts[0]:.2f} s, thresholds {parts[1]:.2f} s); "
        "sweep.csv matches exactly"
    )


if __name__ == "__main__":
    main()
