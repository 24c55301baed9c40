"""The examples in python/examples run (each in a subprocess, writing into a temporary folder)."""

import importlib.util
import re
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))


def ascii_ply(path: Path):
    """Vertex and face counts and the triangles of an ASCII PLY of triangles, parsed here."""
    lines = path.read_text().splitlines()
    end = lines.index("end_header")
    counts = {line.split()[1]: int(line.split()[2]) for line in lines[:end]
              if line.startswith("element ")}
    first_face = end + 1 + counts["vertex"]
    faces = np.array([[int(v) for v in line.split()[1:]]
                      for line in lines[first_face:first_face + counts["face"]]])
    return counts["vertex"], faces


def check_bunny_report(stdout: str):
    """The numbers bunny.py prints, against data/bunny.ply parsed here: its counts, and
    Gauss-Bonnet (the angle defects sum to 2 pi chi exactly, boundary vertices included, chi =
    V - E + F of the referenced vertices) with genus and boundary loops (chi = 2 - 2g - b)."""
    vertices, faces = ascii_ply(Path(__file__).resolve().parents[2] / "data" / "bunny.ply")
    assert faces.shape[1] == 3
    edges = np.unique(np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]],
                                              faces[:, [2, 0]]]), axis=1), axis=0)
    chi = len(np.unique(faces)) - len(edges) + len(faces)
    report = re.search(r"^bunny: (\d+) vertices, (\d+) faces, (\d+) boundary loops, genus (-?\d+)$",
                       stdout, re.M)
    assert report, stdout
    v, f, loops, genus = (int(g) for g in report.groups())
    assert (v, f) == (vertices, len(faces))
    if genus >= 0:  # closed (the report gives no genus otherwise)
        assert loops == 0 and 2 - 2 * genus == chi, (genus, loops, chi)
    else:
        assert loops > 0
    gauss_bonnet = re.search(r"^Gauss-Bonnet: sum K dA = (-?[0-9.]+) pi$", stdout, re.M)
    assert gauss_bonnet, stdout
    assert float(gauss_bonnet.group(1)) == pytest.approx(2 * chi, abs=1e-4)


@pytest.mark.parametrize("example", EXAMPLES, ids=[e.name for e in EXAMPLES])
def test_example_runs(example, tmp_path):
    result = subprocess.run([sys.executable, str(example), str(tmp_path)], capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.strip()
    if example.name == "bunny.py":
        check_bunny_report(result.stdout)
    # Every picture an example says it wrote is there, a PNG of the size its figure asks for
    # (bunny.py: 11 x 5.5 inches at 100 dpi); with matplotlib (Debian's, installed by the README's
    # test command) the bunny example draws one.
    written = [line.split(" ", 1)[1] for line in result.stdout.splitlines()
               if line.startswith("wrote ")]
    for path in written:
        data = Path(path).read_bytes()
        assert len(data) > 10000, path
        if path.endswith(".png"):
            assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR", path
            width, height = struct.unpack(">II", data[16:24])
            if example.name == "bunny.py":
                assert (width, height) == (1100, 550), path
    if example.name == "bunny.py" and importlib.util.find_spec("matplotlib"):
        assert any(path.endswith(".png") for path in written), result.stdout


def test_there_are_examples():
    assert EXAMPLES
