"""The committed type stubs match the module: regenerated with Debian's stubgen (python3-mypy)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import pcl_ddg

COMMITTED = Path(__file__).resolve().parents[1] / "pcl_ddg" / "_pcl_ddg.pyi"


def test_stubs_match_the_module(tmp_path):
    pytest.importorskip("mypy.stubgen", reason="stubgen needs python3-mypy")
    package = Path(pcl_ddg.__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(package))
    result = subprocess.run(
        [sys.executable, "-c", "from mypy.stubgen import main; main()", "-m", "pcl_ddg._pcl_ddg",
         "-o", str(tmp_path)], capture_output=True, text=True, env=env, timeout=300)
    assert result.returncode == 0, result.stderr
    generated = (tmp_path / "pcl_ddg" / "_pcl_ddg.pyi").read_text()
    assert generated == COMMITTED.read_text(), (
        "python/pcl_ddg/_pcl_ddg.pyi is stale: regenerate it with "
        "PYTHONPATH=build/python python3 -c 'from mypy.stubgen import main; main()' "
        "-m pcl_ddg._pcl_ddg -o python")
    assert (COMMITTED.parent / "py.typed").exists()
