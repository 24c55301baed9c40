"""The GIL is released: four Python threads calling estimate_normals at once give the serial
results, and run at the same time."""

import os
import threading
import time

import numpy as np
import pytest

import pcl_ddg


def cloud(seed):
    rng = np.random.default_rng(seed)
    p = rng.standard_normal((120_000, 3))
    return p / np.linalg.norm(p, axis=1, keepdims=True) * (1 + 0.01 * rng.random((120_000, 1)))


def run_four(clouds):
    """The four calls at once; returns the results, the wall time and the ticks of a Python
    thread that ran meanwhile (only possible while the workers have released the GIL)."""
    results = [None] * 4
    ticks = [0]
    running = threading.Event()

    def work(i):
        results[i] = pcl_ddg.estimate_normals(clouds[i], k=16, threads=1)

    def ticker():
        while not running.is_set():
            ticks[0] += 1
            time.sleep(0.001)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    watcher = threading.Thread(target=ticker)
    start = time.perf_counter()
    watcher.start()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    seconds = time.perf_counter() - start
    running.set()
    watcher.join()
    return results, seconds, ticks[0]


def run_serial(clouds):
    start = time.perf_counter()
    results = [pcl_ddg.estimate_normals(points, k=16, threads=1) for points in clouds]
    return results, time.perf_counter() - start


def test_four_threads_give_the_serial_results_with_the_gil_released():
    clouds = [cloud(seed) for seed in range(4)]
    # One thread each inside the library, so that the overlap is the Python threads'.
    pcl_ddg.estimate_normals(clouds[0][:1000], k=16, threads=1)  # warm up
    serial, _ = run_serial(clouds)
    results, parallel_seconds, ticks = run_four(clouds)
    for ours, reference in zip(results, serial):
        np.testing.assert_array_equal(ours.normals, reference.normals)
        np.testing.assert_array_equal(ours.curvature, reference.curvature)
    # Python kept running during the computation (the GIL was free).
    assert ticks > 0.5 * parallel_seconds / 0.002


def test_four_threads_run_concurrently():
    cores = len(os.sched_getaffinity(0))
    if cores < 2:
        pytest.skip("one core: threads cannot overlap")
    # Wall time says nothing when other processes hold the cores (a shared CI machine).
    if os.getloadavg()[0] > cores - 1:
        pytest.skip(f"load average {os.getloadavg()[0]:.1f} on {cores} cores")
    clouds = [cloud(seed) for seed in range(4)]
    pcl_ddg.estimate_normals(clouds[0][:1000], k=16, threads=1)  # warm up
    _, serial_seconds = run_serial(clouds)
    _, parallel_seconds, _ = run_four(clouds)
    print(f"serial {serial_seconds:.3f} s, four threads {parallel_seconds:.3f} s")
    assert parallel_seconds < 0.9 * serial_seconds
