"""The GIL is released: four Python threads calling estimate_normals at once give the serial
results, Python runs meanwhile, the calls progress together (no lock serialises them) and they
run at the same instant on different cores.

Measured with each worker thread's own CPU clock (`time.pthread_getcpuclockid`), which the main
thread samples while the four are inside the call, not with wall times: a machine loaded by
other processes (a 2-core CI running `ctest -j2`) slows every thread down but cannot make two
calls progress together, or two threads gain more CPU time than the wall time between two
samples, when the GIL or a lock lets only one of them run at a time."""

import os
import threading
import time

import numpy as np
import pytest

import pcl_ddg

PAST_CONVERSION = 0.02  # CPU seconds: a call has converted its arguments (about 2 ms) and computes


def cloud(seed):
    rng = np.random.default_rng(seed)
    p = rng.standard_normal((120_000, 3))
    return p / np.linalg.norm(p, axis=1, keepdims=True) * (1 + 0.01 * rng.random((120_000, 1)))


def run_four(clouds, lock=None):
    """The four calls at once, one Python thread each (one thread each inside the library, so
    that any overlap is the Python threads'); with `lock`, each call holds it (a serialised run:
    the measurement's control). Returns a dict: the results; `ticks` of a Python thread that ran
    meanwhile (only possible while the workers have released the GIL); `seconds` of wall time;
    `cpu`, each worker's CPU seconds in its call; `samples`, the main thread's while all four
    were inside the call: (wall time before, wall time after, each worker's CPU seconds in its
    call so far, read in between). None when one call returned before another began (a thread
    starved by the machine's load): then none is taken."""
    results, cpu_seconds, cpu_start = [None] * 4, [0.0] * 4, [0.0] * 4
    state = [0] * 4  # 0 before its call, 1 inside, 2 returned (or raised)
    errors = []
    ready = threading.Barrier(5)
    finished = threading.Event()  # the workers stay alive (their clocks valid) until sampled
    ticks = [0]

    def work(i):
        ready.wait()
        try:
            cpu_start[i] = time.thread_time()  # the clock the main thread samples
            state[i] = 1
            if lock is None:
                results[i] = pcl_ddg.estimate_normals(clouds[i], k=16, threads=1)
            else:
                with lock:
                    results[i] = pcl_ddg.estimate_normals(clouds[i], k=16, threads=1)
            cpu_seconds[i] = time.thread_time() - cpu_start[i]
        except BaseException as error:  # raised again by the main thread
            errors.append(error)
        finally:
            state[i] = 2
            finished.wait()

    def ticker():
        while not finished.is_set():
            ticks[0] += 1
            time.sleep(0.001)

    workers = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    watcher = threading.Thread(target=ticker)
    for t in workers:
        t.start()
    clocks = [time.pthread_getcpuclockid(t.ident) for t in workers]
    samples = []
    watcher.start()
    start = time.perf_counter()
    ready.wait()
    try:
        while 0 in state and 2 not in state:  # until all four are inside, or one has returned
            time.sleep(0.0005)
        while True:
            before = time.perf_counter()
            cpu = [time.clock_gettime(c) - s for c, s in zip(clocks, cpu_start)]
            after = time.perf_counter()
            if state != [1] * 4:  # one has left its call: this sample may count its epilogue
                break
            samples.append((before, after, cpu))
            time.sleep(0.001)
        while state != [2] * 4:
            time.sleep(0.001)
        seconds = time.perf_counter() - start
    finally:
        finished.set()
        for t in workers:
            t.join()
        watcher.join()
    if errors:
        raise errors[0]
    return {"results": results, "ticks": ticks[0], "seconds": seconds, "cpu": cpu_seconds,
            "samples": samples}


def progress_together(samples):
    """The most CPU time two of the four had both spent in their calls at one moment while all
    four were inside: at most the conversion of a call's arguments (about 2 ms) when a lock or
    the GIL lets one call compute at a time, most of a call when they compute concurrently,
    whatever the load."""
    return max((sorted(cpu)[-2] for _, _, cpu in samples), default=0.0)


def parallel_seconds(samples):
    """CPU seconds the workers computing (past their arguments' conversion) gained beyond one
    core, summed over the sampling windows: a lower bound of the time two calls computed at the
    same instant. Between two samples a thread gains at most the wall time from the first's
    start to the second's end, so the sum is 0 when they never did."""
    excess = 0.0
    for (before, _, cpu0), (_, after, cpu1) in zip(samples, samples[1:]):
        gained = sum(b - a for a, b in zip(cpu0, cpu1) if a >= PAST_CONVERSION)
        excess += max(0.0, gained - (after - before))
    return excess


@pytest.fixture(scope="module")
def clouds():
    points = [cloud(seed) for seed in range(4)]
    pcl_ddg.estimate_normals(points[0][:1000], k=16, threads=1)  # warm up
    return points


def test_four_threads_give_the_serial_results_with_the_gil_released(clouds):
    """Python kept running during the computation (the GIL was free): a ticker thread, and the
    main thread's samples while all four were inside the call (a held GIL allows one between two
    calls, at most). Each run gives the serial results; a run where the machine's load starved a
    thread is repeated (up to 5), since a held GIL would fail every one."""
    serial = [pcl_ddg.estimate_normals(points, k=16, threads=1) for points in clouds]
    for _ in range(5):
        run = run_four(clouds)
        for ours, reference in zip(run["results"], serial):
            np.testing.assert_array_equal(ours.normals, reference.normals)
            np.testing.assert_array_equal(ours.curvature, reference.curvature)
        if run["ticks"] > 0.5 * run["seconds"] / 0.002 and len(run["samples"]) >= 10:
            break
    assert run["ticks"] > 0.5 * run["seconds"] / 0.002, (run["ticks"], run["seconds"])
    assert len(run["samples"]) >= 10, len(run["samples"])


def test_four_calls_progress_together(clouds):
    """No lock inside the call: the calls compute at the same time (interleaved, on a loaded or a
    one-core machine), two of them a quarter of their work done at once, all four inside. Up to
    5 runs (a starved thread can delay it; a lock or a held GIL prevents it in every run)."""
    serialised = run_four(clouds, lock=threading.Lock())
    call = min(serialised["cpu"])
    # The control: calls serialised by a lock show only the others' argument conversions.
    assert progress_together(serialised["samples"]) < PAST_CONVERSION
    for runs in range(1, 6):
        together = progress_together(run_four(clouds)["samples"])
        if together > max(0.25 * call, PAST_CONVERSION):
            break
    print(f"one call {call:.3f} s of CPU; four threads: two {together:.3f} s into their calls at "
          f"once (run {runs})")
    assert together > max(0.25 * call, PAST_CONVERSION)


def test_four_threads_run_in_parallel(clouds):
    """On two cores or more the four calls run at the same instant: the CPU time they gained
    beyond one core, 0 when a lock or the GIL serialises them, reaches a tenth of a call's (ten
    times an argument conversion). Other processes holding the cores make such moments rarer,
    so the runs are repeated (up to 20) until they add up."""
    cores = len(os.sched_getaffinity(0))
    if cores < 2:
        pytest.skip("one core: threads cannot run at the same instant")
    call = None
    overlap, runs = 0.0, 0
    while runs < 20:
        run = run_four(clouds)
        runs += 1
        call = min(run["cpu"]) if call is None else min(call, *run["cpu"])
        overlap += parallel_seconds(run["samples"])
        if overlap > 0.1 * call:
            break
    print(f"{overlap:.3f} s of CPU beyond one core in {runs} run(s) of four calls of {call:.3f} s;"
          f" load average {os.getloadavg()[0]:.1f} on {cores} cores")
    assert overlap > 0.1 * call, (overlap, call, runs)
