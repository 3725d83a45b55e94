#!/usr/bin/python3
"""Start-up time of `g2p` and `import g2p`, against /bin/true and a bare interpreter (#63).

    /usr/bin/python3 scripts/bench_startup.py [--build build] [--before DIR] [--runs 31]

Runs each command --runs times, interleaved (so a busy machine slows all alike), and prints the
median and the minimum. --before DIR: also an older build's `g2p` copied to DIR with its
libg2p*.so* beside it (run with LD_LIBRARY_PATH=DIR), for a before/after ratio
(docs/performance.md, "Start-up").
"""
import argparse
import os
import statistics
import subprocess
import time


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--before", metavar="DIR")
    ap.add_argument("--runs", type=int, default=31)
    a = ap.parse_args()
    here = dict(os.environ)
    cmds = {"/bin/true": (["/bin/true"], here),
            "g2p --version": ([os.path.join(a.build, "bin", "g2p"), "--version"], here),
            "python3 -c pass": (["python3", "-c", "pass"], here),
            "import g2p": (["python3", "-c", "import g2p"],
                           dict(here, PYTHONPATH=os.path.join(a.build, "python")))}
    if a.before:
        binary = os.path.join(a.before, "g2p.bin" if os.path.exists(os.path.join(a.before, "g2p.bin")) else "g2p")
        cmds["g2p --version (before)"] = ([binary, "--version"], dict(here, LD_LIBRARY_PATH=a.before))
    times = {k: [] for k in cmds}
    for _ in range(a.runs):
        for name, (cmd, env) in cmds.items():
            start = time.perf_counter()
            subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, check=True)
            times[name].append(time.perf_counter() - start)
    for name, t in times.items():
        print("%-24s median %.3f s  min %.3f s" % (name, statistics.median(t), min(t)))


if __name__ == "__main__":
    main()
