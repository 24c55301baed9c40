"""A command run as a fresh process, measured as the end-to-end benches report it."""
import subprocess
import sys
import tempfile
import time


def measured(command):
    """Runs command as a fresh process: (wall seconds, its stdout, peak resident MB, minor page
    faults), the last two by /usr/bin/time -f '%M %R' (which forks the command from its own small
    process: a child forked from this Python would start with this Python's peak). Exits with the
    command's last lines of stderr if it fails."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as report:
        start = time.perf_counter()
        run = subprocess.run(["/usr/bin/time", "-o", report.name, "-f", "%M %R", *command],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        wall = time.perf_counter() - start
        if run.returncode != 0:
            sys.exit(f"{command[0]} failed ({run.returncode}): {run.stderr.decode()[-400:]}")
        peak_kb, faults = report.read().split()[-2:]
    return wall, run.stdout.decode(), int(peak_kb) / 1024.0, int(faults)
