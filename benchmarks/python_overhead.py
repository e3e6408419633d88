"""Calling overhead of the Python module: CPU time of Scene.run() on the quarter
car scene against `vdyn run` (medians of 5; the program's CPU time is its
child-process user+system time, which includes its start-up and file writing).

    PYTHONPATH=build/python python3 benchmarks/python_overhead.py build/bin/vdyn [N=5]
"""
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import vdyn

SCENE = "scenes/quarter_car_sine_road.json"


def cli_cpu(exe, out):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([exe, "run", SCENE, "--out", out, "--no-plots"], check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def python_cpu():
    t0 = time.process_time()
    vdyn.Scene.from_file(SCENE).run()
    return time.process_time() - t0


def main(exe, n=5):
    n = int(n)
    python_cpu()  # first call: library pages and registry, not overhead
    with tempfile.TemporaryDirectory() as out:
        cli = [cli_cpu(exe, out) for _ in range(n)]
    py = [python_cpu() for _ in range(n)]
    mc, mp = statistics.median(cli), statistics.median(py)
    print(f"vdyn run CPU   median of {n}: {mc:.4f} s  ({', '.join(f'{x:.4f}' for x in cli)})")
    print(f"Scene.run() CPU median of {n}: {mp:.4f} s  ({', '.join(f'{x:.4f}' for x in py)})")
    print(f"Scene.run() / vdyn run: {mp / mc:.4f} ({100 * (mp / mc - 1):+.2f} %); load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main(*sys.argv[1:])
