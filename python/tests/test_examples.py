"""The examples in python/examples run (each in a subprocess, writing into a temporary folder)."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))


@pytest.mark.parametrize("example", EXAMPLES, ids=[e.name for e in EXAMPLES])
def test_example_runs(example, tmp_path):
    result = subprocess.run([sys.executable, str(example), str(tmp_path)], capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.strip()
    # Every picture an example says it wrote is there; with matplotlib (Debian's, installed by the
    # README's test command) the bunny example draws one.
    written = [line.split(" ", 1)[1] for line in result.stdout.splitlines()
               if line.startswith("wrote ")]
    for path in written:
        assert Path(path).stat().st_size > 10000, path
    if example.name == "bunny.py" and importlib.util.find_spec("matplotlib"):
        assert any(path.endswith(".png") for path in written), result.stdout


def test_there_are_examples():
    assert EXAMPLES
