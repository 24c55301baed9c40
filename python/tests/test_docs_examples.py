"""The Python examples of the docs run, and type-check against the module's shipped types.

Every ```python block of PAGES is one script, complete on its own: as a user pastes it into a
file and runs it from the repository's root. Each is written to a temporary folder and run with
this interpreter (sys.executable; CMake's is Debian's /usr/bin/python3) with PYTHONPATH the folder
of the pcl_ddg under test, in a temporary working directory holding a copy of the bundled data/
(so "data/bunny.ply" names what it names in a clone, and what a script writes stays there),
within TIMEOUT seconds: a hang (a Dask LocalCluster started without its __main__ guard) fails,
and the script's whole process group is killed. Then mypy checks all of them as a user's code is
checked against the installed package (found through PYTHONPATH: its py.typed, _pcl_ddg.pyi and
typed __init__.py; errors inside the package are the package's own and not reported here): no
error allowed, each reported at its page and line.

Convention: a block that is not a complete script (a fragment continuing another, pseudo-code) is
preceded, on the line before its fence (blank lines allowed between), by the HTML comment
`<!-- not run: REASON -->`, invisible in the rendered page: it is neither run nor type-checked,
and the reason must be given. Blocks never run concatenated.
"""

import os
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path
from typing import List, NamedTuple

import pytest

import pcl_ddg
from conftest import ROOT

PAGES = ["README.md", "docs/python.md", "docs/distributed.md"]
TIMEOUT = 120  # seconds per script; each takes a few
FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<fence>```+|~~~+)[ \t]*(?P<info>[^\s`]*)")
NOT_RUN = re.compile(r"^\s*<!--\s*not run:(?P<reason>.*?)-->\s*$")
PYTHON = {"python", "py", "python3"}


class Block(NamedTuple):
    page: str  # relative to the repository
    line: int  # of the block's first code line, 1-based
    code: str
    not_run: str  # the marker's reason; "" for a block that runs

    @property
    def name(self) -> str:
        return f"{self.page}:{self.line}"

    @property
    def script(self) -> str:
        """A file name of its own, from the page and line (docs_python_md_58.py)."""
        return re.sub(r"\W", "_", f"{self.page}_{self.line}").lower() + ".py"


def python_blocks(page: str) -> List[Block]:
    lines = (ROOT / page).read_text(encoding="utf-8").splitlines()
    blocks, i = [], 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if not opening:
            i += 1
            continue
        indent, fence = opening["indent"], opening["fence"]
        end = i + 1
        while end < len(lines) and not re.match(rf"^[ \t]*{re.escape(fence)}[ \t]*$", lines[end]):
            end += 1
        if opening["info"].lower() in PYTHON:
            before = i - 1
            while before >= 0 and not lines[before].strip():
                before -= 1
            marker = NOT_RUN.match(lines[before]) if before >= 0 else None
            body = [line[len(indent):] if line.startswith(indent) else line
                    for line in lines[i + 1:end]]
            blocks.append(Block(page, i + 2, "\n".join(body) + "\n",
                                marker["reason"].strip() or "(none)" if marker else ""))
        i = end + 1
    return blocks


BLOCKS = [block for page in PAGES for block in python_blocks(page)]
RUN = [block for block in BLOCKS if not block.not_run]


def module_path() -> str:
    """The folder holding the pcl_ddg under test (build/python from ctest or the docs' command)."""
    return str(Path(pcl_ddg.__file__).resolve().parents[1])


def script_environment() -> dict:
    env = dict(os.environ, PYTHONPATH=module_path())
    env.pop("MYPYPATH", None)  # it would make mypy check the package as our own source
    return env


def bundled_data() -> Path:
    """data/ of the repository ($PCL_DDG_BUNDLED_DATA_DIR, which CMake passes, when set)."""
    explicit = os.environ.get("PCL_DDG_BUNDLED_DATA_DIR", "").strip()
    return Path(explicit) if explicit else ROOT / "data"


def run(command: List[str], cwd: Path, timeout: float) -> subprocess.CompletedProcess:
    """command in a process group of its own; on timeout the whole group (a LocalCluster's
    spawned workers too) is killed and the test fails with what it printed."""
    process = subprocess.Popen(command, cwd=cwd, env=script_environment(), text=True,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               start_new_session=True)
    try:
        output, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        output, _ = process.communicate()
        pytest.fail(f"{' '.join(command)}: still running after {timeout} s (killed); its last "
                    f"output:\n{output[-3000:]}")
    finally:
        try:
            os.killpg(process.pid, signal.SIGKILL)  # nothing it started outlives the test
        except ProcessLookupError:
            pass
    return subprocess.CompletedProcess(command, process.returncode, output, "")


def test_the_pages_have_python_examples():
    for page in PAGES:
        assert (ROOT / page).is_file(), page
    assert {block.page for block in RUN} >= {"docs/python.md", "docs/distributed.md"}
    for block in BLOCKS:
        assert block.not_run != "(none)", f"{block.name}: '<!-- not run: -->' without a reason"


@pytest.mark.parametrize("block", RUN, ids=[block.name for block in RUN])
def test_example_runs(block, tmp_path):
    if re.search(r"^\s*(import|from)\s+pcl_ddg\.distributed\b", block.code, re.M):
        pytest.importorskip("distributed", reason="the Dask example needs python3-distributed")
    work = tmp_path / "work"
    shutil.copytree(bundled_data(), work / "data", ignore=shutil.ignore_patterns("*.png"))
    script = tmp_path / block.script
    script.write_text(block.code)
    result = run([sys.executable, str(script)], work, TIMEOUT)
    assert result.returncode == 0, f"{block.name} failed:\n{result.stdout[-6000:]}"


def test_examples_type_check(tmp_path):
    pytest.importorskip("mypy", reason="type-checking the examples needs python3-mypy")
    scripts = tmp_path / "scripts"
    scripts.mkdir()
    by_script = {}
    for block in RUN:
        (scripts / block.script).write_text(block.code)
        by_script[block.script] = block
    assert by_script
    result = run([sys.executable, "-m", "mypy", "--config-file", "", "--no-color-output",
                  "--no-error-summary", "--show-error-codes", "--cache-dir",
                  str(tmp_path / "mypy_cache"), *sorted(by_script)], scripts, 600)

    def at_page_line(match: re.Match) -> str:  # docs_python_md_58.py:4: -> docs/python.md:61:
        block = by_script[match[1]]
        return f"{block.page}:{block.line + int(match[2]) - 1}:"

    report = re.sub(r"^(\S+\.py):(\d+):", at_page_line, result.stdout.strip(), flags=re.M)
    assert not report, f"mypy on the docs' examples:\n{report}"
    assert result.returncode == 0, f"mypy exited {result.returncode} without a report"
