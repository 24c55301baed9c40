"""A command run as a fresh process, measured as the end-to-end benches report it."""
import os
import subprocess
import sys
import tempfile
import time


def cold():
    """Whether the benches start each run cold (PCL_DDG_BENCH_COLD=1; needs root)."""
    return os.environ.get("PCL_DDG_BENCH_COLD") == "1"


def make_cold():
    """A freshly booted machine's state, as near as a running one gets: the file cache dropped
    (inputs, programs and libraries read from disk again) and, after free page reporting's delay
    (about 2 s), the memory it held given back to the host, so that touching it is a first touch
    again (on a VM whose virtio-balloon reports free pages: see machine_state)."""
    subprocess.run(["sync"], check=True)
    try:
        with open("/proc/sys/vm/drop_caches", "w") as f:
            f.write("3\n")
    except OSError as error:
        sys.exit("PCL_DDG_BENCH_COLD=1 needs root and a writable /proc/sys to drop the file "
                 f"cache: {error}")
    time.sleep(5)


def measured(command, environment=None):
    """Runs command as a fresh process: (wall seconds, its stdout, peak resident MB, minor page
    faults), the last two by /usr/bin/time -f '%M %R' (which forks the command from its own small
    process: a child forked from this Python would start with this Python's peak). Exits with the
    command's last lines of stderr if it fails. environment: the command's, if not this one's.
    With PCL_DDG_BENCH_COLD=1 each run starts cold (make_cold)."""
    if cold():
        make_cold()
    with tempfile.NamedTemporaryFile("r", suffix=".time") as report:
        start = time.perf_counter()
        run = subprocess.run(["/usr/bin/time", "-o", report.name, "-f", "%M %R", *command],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=environment)
        wall = time.perf_counter() - start
        if run.returncode != 0:
            sys.exit(f"{command[0]} failed ({run.returncode}): {run.stderr.decode()[-400:]}")
        peak_kb, faults = report.read().split()[-2:]
    return wall, run.stdout.decode(), int(peak_kb) / 1024.0, int(faults)


def environment(**settings):
    """This process's environment without the settings the tools' memory depends on
    (PCL_DDG_HUGE_PAGES, GLIBC_TUNABLES), with the given ones added: what a bench runs a tool in."""
    env = {k: v for k, v in os.environ.items() if k not in ("PCL_DDG_HUGE_PAGES", "GLIBC_TUNABLES")}
    env.update(settings)
    return env


def machine_state():
    """A line saying how long the machine has been up and what a first touch of a fresh 4 kB page
    costs now (64 MiB of private anonymous memory in 4 kB pages, one write a page, less the loop's
    own cost): in a freshly booted VM that is where a fault is dearest, and what the benches'
    page-fault counts are worth in time."""
    import mmap
    with open("/proc/uptime") as f:
        up_minutes = float(f.read().split()[0]) / 60
    size = 64 << 20
    pages = range(0, size, 4096)
    block = mmap.mmap(-1, size, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS)
    block.madvise(mmap.MADV_NOHUGEPAGE)
    start = time.perf_counter()
    for offset in pages:
        block[offset] = 1
    touch = time.perf_counter() - start
    start = time.perf_counter()
    for offset in pages:  # the same loop on pages now present: the loop's own cost
        block[offset] = 2
    touch -= time.perf_counter() - start
    block.close()
    return (f"machine: up {up_minutes:.0f} min; a first touch of a 4 kB page "
            f"{touch / len(pages) * 1e6:.2f} us; free pages reported to the host: "
            f"{free_page_reporting()}; runs start {'cold' if cold() else 'warm'}")


def free_page_reporting():
    """Whether a virtio-balloon device reports the guest's free pages to the host (feature bit
    5, VIRTIO_BALLOON_F_REPORTING), which then takes them back: memory a process frees is fresh
    again for the next (a free block of 2 MiB or more, which most of a freed large buffer is), as
    on a freshly booted VM. "no" elsewhere (bare metal included)."""
    import glob
    for features in glob.glob("/sys/bus/virtio/drivers/virtio_balloon/virtio*/features"):
        with open(features) as f:
            bits = f.read().strip()
        if len(bits) > 5 and bits[5] == "1":
            return "yes"
    return "no"
