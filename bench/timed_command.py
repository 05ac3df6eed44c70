"""One command's wall time and peak memory, for the benches that time whole rsibr commands
(bench/real_size.py, bench/process_size.py)."""
import os
import subprocess
import sys
import time


def timed_run(cmd, who):
    """Wall seconds and peak RSS (MiB) of one command (wait4's rusage of that child alone); exits
    with "WHO: COMMAND failed" and its stderr when it fails."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    err = p.stderr.read().decode()
    p.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{who}: {' '.join(cmd)} failed:\n{err}")
    return wall, usage.ru_maxrss / 1024.0
