"""Shared fixtures: analytic surfaces generated here, the shared scans and the C++ tools; and the
skip policy (docs/testing.md, "Skips"): with CI=true a test that cannot run -- shared data, a tool
or a Python module missing -- fails, unless docs/testing.md allows that skip with its reason."""

import fnmatch
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
POLICY = "docs/testing.md, \"Skips\""

# The policy's own test (python/CMakeLists.txt, python_pytest_skip_policy) hides modules this way.
for _name in filter(None, os.environ.get("PCL_DDG_TEST_HIDE_MODULES", "").split(",")):
    sys.modules[_name.strip()] = None  # import raises ModuleNotFoundError


def in_ci() -> bool:
    """CI=true (set by CI services and by `bash .ci/bootstrap test`): no test may skip."""
    return os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no", "off")


def _explicit(variable: str):
    """The folder an environment variable names; None when it is unset or empty (CMake passes
    nothing when it found nothing)."""
    value = os.environ.get(variable, "").strip()
    return Path(value) if value else None


def shared_data() -> Path:
    """The shared data folder: $PCL_DDG_SHARED_DATA when set (and only it), else ../shared/data
    beside the repository or /work/shared/data. Missing: a skip, which fails under CI=true."""
    explicit = _explicit("PCL_DDG_SHARED_DATA")
    candidates = [explicit] if explicit else [ROOT.parent / "shared" / "data",
                                              Path("/work/shared/data")]
    for candidate in candidates:
        if (candidate / "CATALOG.md").exists():
            return candidate
    if explicit:
        pytest.skip(f"shared data not found: PCL_DDG_SHARED_DATA={explicit} holds no CATALOG.md")
    pytest.skip("shared data not found: PCL_DDG_SHARED_DATA is unset or empty (CMake found no "
                "folder: configure with -DPCL_DDG_SHARED_DATA_DIR=...) and no CATALOG.md in "
                + " or ".join(map(str, candidates)))


def tools_dir() -> Path:
    """The pcl_ddg_* programs: $PCL_DDG_TOOLS_DIR when set (and only it), else build/tools."""
    explicit = _explicit("PCL_DDG_TOOLS_DIR")
    candidate = explicit or ROOT / "build" / "tools"
    if (candidate / "pcl_ddg_normals").exists():
        return candidate
    pytest.skip(f"the pcl_ddg_* tools are not built: no pcl_ddg_normals in {candidate} (build "
                "with -DPCL_DDG_BUILD_TOOLS=ON, or set PCL_DDG_TOOLS_DIR)")


def run_tool(name: str, *args: str) -> None:
    result = subprocess.run([str(tools_dir() / name), *map(str, args)], capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, f"{name} {' '.join(map(str, args))}: {result.stderr}"


def icosphere(level: int, radius: float = 1.0):
    """An icosahedron subdivided `level` times, vertices on the sphere; outward faces."""
    t = (1.0 + 5.0 ** 0.5) / 2.0
    V = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
         [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    F = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    V = [np.array(v, float) / np.linalg.norm(v) for v in V]
    for _ in range(level):
        midpoints = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoints:
                m = V[a] + V[b]
                V.append(m / np.linalg.norm(m))
                midpoints[key] = len(V) - 1
            return midpoints[key]

        refined = []
        for a, b, c in F:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            refined += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        F = refined
    return radius * np.array(V), np.array(F, dtype=np.int32)


def random_mesh(n: int = 400, seed: int = 1):
    """A jittered grid over a wavy height field: irregular, obtuse triangles, a boundary."""
    rng = np.random.default_rng(seed)
    side = int(np.sqrt(n))
    u, v = np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float))
    u = u + rng.uniform(-0.3, 0.3, u.shape)
    v = v + rng.uniform(-0.3, 0.3, v.shape)
    V = np.stack([u.ravel(), v.ravel(), 0.3 * np.sin(u.ravel()) * np.cos(0.7 * v.ravel())], 1)
    F = []
    for i in range(side - 1):
        for j in range(side - 1):
            a, b, c, d = i * side + j, i * side + j + 1, (i + 1) * side + j, (i + 1) * side + j + 1
            F += [[a, b, d], [a, d, c]] if rng.random() < 0.5 else [[a, b, c], [b, d, c]]
    return V, np.array(F, dtype=np.int64)


@pytest.fixture(scope="session")
def bunny():
    import pcl_ddg

    return pcl_ddg.read(shared_data() / "meshes" / "bunny.off")


def python_subprocess(code: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=timeout, env=dict(os.environ))


@pytest.fixture
def tool():
    return run_tool


# The skip policy. Each skip is checked against the table of docs/testing.md's "Skips allowed in
# CI": its test (a pattern of file::name) and a text its reason contains. Under CI=true any other
# skip or xfail of a test is turned into a failure, and one of a whole module (an importorskip at
# its top, which leaves nothing to fail) fails the session; outside CI they stay skips, listed at
# the end and reported to ctest as a skipped python_pytest.

def allowed_skips():
    """(test pattern, reason text) pairs of docs/testing.md's table; none without the file."""
    try:
        text = (ROOT / "docs" / "testing.md").read_text()
    except OSError:
        return []
    section = re.search(r"^#+ Skips allowed in CI\s*$(.*?)(?=^#)", text + "\n#", re.M | re.S)
    pairs = []
    for line in section.group(1).splitlines() if section else []:
        cells = [c.strip().strip("`").strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 2 and "::" in cells[0]:
            pairs.append((cells[0], cells[1].strip("`")))
    return pairs


def _short_id(nodeid: str) -> str:
    """A node id from the test file's name on, whatever folder pytest was started in."""
    path, _, rest = nodeid.partition("::")
    return Path(path).name + ("::" + rest if rest else "")


def _skip_reason(report) -> str:
    if hasattr(report, "wasxfail"):
        return f"xfail: {report.wasxfail}"
    if isinstance(report.longrepr, tuple):
        return str(report.longrepr[2]).removeprefix("Skipped: ")
    return str(report.longrepr)


def _policy(config):
    if not hasattr(config, "_pcl_ddg_skips"):
        config._pcl_ddg_skips = {"allowed": [], "refused": [], "skipped": [],
                                 "table": allowed_skips()}
    return config._pcl_ddg_skips


def _judge(config, nodeid, reason):
    """Records a skip; True when it must fail (CI=true, not allowed by docs/testing.md)."""
    policy = _policy(config)
    entry = (_short_id(nodeid), reason)
    if not in_ci():
        policy["skipped"].append(entry)
        return False
    if any(fnmatch.fnmatchcase(entry[0], test) and text in reason
           for test, text in policy["table"]):
        policy["allowed"].append(entry)
        return False
    policy["refused"].append(entry)
    return True


@pytest.hookimpl(hookwrapper=True, tryfirst=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if report.skipped and _judge(item.config, report.nodeid, _skip_reason(report)):
        reason = _skip_reason(report)
        if hasattr(report, "wasxfail"):
            del report.wasxfail
        report.outcome = "failed"
        report.longrepr = (f"could not run: {reason}\nCI=true: a test that cannot run fails, it "
                           f"does not skip ({POLICY}).")


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    outcome = yield
    report = outcome.get_result()
    if report.skipped:  # a module skipped whole (an importorskip at its top): nothing to fail
        _judge(collector.config, report.nodeid, _skip_reason(report))


def pytest_sessionfinish(session):
    refused = _policy(session.config)["refused"]
    if refused and session.exitstatus in (pytest.ExitCode.OK, pytest.ExitCode.NO_TESTS_COLLECTED):
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    policy = _policy(config)
    write = terminalreporter.write_line
    if policy["refused"]:
        terminalreporter.section("skips refused: CI=true", sep="=", red=True, bold=True)
        write(f"{len(policy['refused'])} test(s) or module(s) could not run, which fails the run "
              f"under CI=true ({POLICY}):")
        for nodeid, reason in sorted(policy["refused"]):
            write(f"  {nodeid}: {reason}")
    if policy["allowed"]:
        terminalreporter.section("skips allowed in CI by docs/testing.md", sep="=")
        for nodeid, reason in sorted(policy["allowed"]):
            write(f"  {nodeid}: {reason}")
    if policy["skipped"]:
        terminalreporter.section("skipped tests (CI=true would fail on them)", sep="=",
                                 yellow=True)
        for nodeid, reason in sorted(policy["skipped"]):
            write(f"  {nodeid}: {reason}")
        if exitstatus == pytest.ExitCode.OK:  # python/CMakeLists.txt: ctest shows "Skipped"
            write(f"PCL_DDG_PYTEST_SKIPPED: {len(policy['skipped'])} test(s) did not run")
