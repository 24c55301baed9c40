"""Ctrl-C stops a long library call promptly: the library's loops ask Python about every 0.1 s
(include/pcl_ddg/interruption.h), the call raises KeyboardInterrupt and leaves no thread of its
own running. Each case runs in a subprocess that interrupts itself (SIGINT, as Ctrl-C sends),
so that a call that ignores it fails by its timeout instead of hanging the run."""

import pytest

from conftest import python_subprocess

SETUP = """
import os, signal, threading, time
import numpy as np, pcl_ddg
P = np.random.default_rng(0).random((20000, 3))
N = np.tile([0.0, 0.0, 1.0], (len(P), 1))
"""

# Each call takes a minute or more on a 2-core machine when not interrupted.
CALLS = {
    "estimate_normals": "pcl_ddg.estimate_normals(P, k=19000)",
    "principal_curvatures": "pcl_ddg.principal_curvatures(P, k=19000)",
    "robust_normals": "pcl_ddg.robust_normals(P, k=19000)",
    "orient_normals": "pcl_ddg.orient_normals(P, N, k=3000)",
}


@pytest.mark.parametrize("name", sorted(CALLS))
def test_ctrl_c_interrupts_within_a_fraction_of_a_second(name):
    script = SETUP + f"""
before = threading.active_count()
threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
start = time.monotonic()
try:
    {CALLS[name]}
    print("FINISHED", time.monotonic() - start)
except KeyboardInterrupt:
    elapsed = time.monotonic() - start
    time.sleep(0.05)  # the timer's thread ends
    print("INTERRUPTED", elapsed, threading.active_count() - before)
"""
    result = python_subprocess(script, timeout=60)
    assert result.returncode == 0, result.stderr
    words = result.stdout.split()
    assert words[0] == "INTERRUPTED", result.stdout
    # 0.5 s until the signal, then at most one poll interval and the point being fitted
    assert float(words[1]) < 1.5, result.stdout
    assert int(words[2]) == 0, result.stdout  # no thread left behind

