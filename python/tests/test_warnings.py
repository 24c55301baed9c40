"""The tools' warnings reach Python: each result's warning (include/pcl_ddg/result_warnings.h) is
a pcl_ddg.PclDdgWarning at the user's own line, with the options spelled as Python's; the Dask
runner lists its run's in the summary and its log."""

import subprocess
import warnings

import numpy as np
import pytest

import pcl_ddg
from conftest import tools_dir


def terrain(n: int = 60, offset=(0.0, 0.0, 0.0), dtype=np.float64) -> np.ndarray:
    """A gently rolling height field of n x n points about 0.5 apart (jittered: no lattice)."""
    x, y = np.meshgrid(np.arange(n) * 0.5, np.arange(n) * 0.5)
    jitter = np.random.default_rng(7).uniform(-0.1, 0.1, (2,) + x.shape)
    x, y = x + jitter[0], y + jitter[1]
    z = 0.3 * np.sin(x / 4.0) + 0.2 * np.cos(y / 5.0)
    return (np.stack([x.ravel(), y.ravel(), z.ravel()], 1) + offset).astype(dtype)


def caught(call):
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        result = call()
    return result, [w for w in seen if issubclass(w.category, pcl_ddg.PclDdgWarning)]


def test_utm_floats_are_said_to_be_rounded_doubles_are_not():
    # float32 at UTM northings: multiples of 0.5 m, the points' spacing
    _, seen = caught(lambda: pcl_ddg.estimate_normals(
        terrain(offset=(5e5, 5e6, 200.0), dtype=np.float32), orient="up"))
    assert len(seen) == 1, [str(w.message) for w in seen]
    assert str(seen[0].message).startswith("the coordinates are rounded to 0.5 while the points "
                                           "are 0.4"), str(seen[0].message)
    _, seen = caught(lambda: pcl_ddg.estimate_normals(terrain(offset=(5e5, 5e6, 200.0)),
                                                      orient="up"))
    assert seen == []


def test_a_far_viewpoint_is_said_with_the_python_spelling_of_the_remedies():
    # the default viewpoint, the origin, 7 km from a 30 m terrain
    normals, seen = caught(lambda: pcl_ddg.estimate_normals(terrain(offset=(5e3, 5e3, 100.0))))
    assert len(seen) == 1
    message = str(seen[0].message)
    assert message.startswith("the viewpoint (0, 0, 0) is ")
    assert "viewpoint=(x, y, z)" in message and 'orient="up"' in message
    assert seen[0].filename == __file__  # the user's line, not the module's
    _, seen = caught(lambda: pcl_ddg.estimate_normals(terrain(offset=(5e3, 5e3, 100.0)),
                                                      orient="up"))
    assert seen == []


def test_points_without_an_estimate_are_counted_in_the_warning():
    points = terrain()
    points[[3, 77, 500]] = np.nan
    result, seen = caught(lambda: pcl_ddg.estimate_normals(points, orient="up"))
    assert (~result.valid).sum() == 3
    assert [str(w.message) for w in seen] == [
        "3 points without an estimate (non-finite, or too few neighbours): NaN"]
    _, seen = caught(lambda: pcl_ddg.principal_curvatures(points, orient="up"))
    assert [str(w.message)[:32] for w in seen] == ["3 points without an estimate (no"]


def test_mesh_normals_and_curvatures_warn_about_cancelling_faces():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    F = np.array([[0, 1, 2], [2, 1, 0], [1, 3, 2]])  # 0 lies on a triangle and its reverse
    result, seen = caught(lambda: pcl_ddg.vertex_normals(V, F))
    assert not result.valid[0]
    assert [str(w.message) for w in seen] == [
        "1 vertices without a normal (NaN), 1 of them because their face normals cancel "
        "(reversed duplicate faces?)"]
    _, seen = caught(lambda: pcl_ddg.curvatures(V, F))
    assert any("face normals cancel" in str(w.message) for w in seen)


def test_warnings_can_be_errors_or_silenced_by_their_category():
    points = terrain(offset=(5e3, 5e3, 100.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error", pcl_ddg.PclDdgWarning)
        with pytest.raises(pcl_ddg.PclDdgWarning):
            pcl_ddg.estimate_normals(points)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.simplefilter("ignore", pcl_ddg.PclDdgWarning)
        pcl_ddg.estimate_normals(points)  # nothing raised
    assert issubclass(pcl_ddg.PclDdgWarning, UserWarning)


def test_the_tool_says_the_same_words(tmp_path):
    """The module's messages are the tool's (one home: result_warnings.h), the remedies aside."""
    points = terrain(offset=(5e3, 5e3, 100.0))
    points[[3, 77]] = np.nan
    source = tmp_path / "terrain.ply"
    pcl_ddg.write(source, points, precision="double")
    run = subprocess.run([str(tools_dir() / "pcl_ddg_normals"), str(source),
                          str(tmp_path / "out.ply")], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    _, seen = caught(lambda: pcl_ddg.estimate_normals(points))
    for w in seen:
        text = str(w.message).replace("viewpoint=(x, y, z)", "-viewpoint x,y,z").replace(
            'orient="up"', "-orient up")
        assert "pcl_ddg_normals: warning: " + text in run.stderr, (text, run.stderr)
    assert len(seen) == 2


def test_a_user_module_named_like_the_package_gets_its_own_warnings(tmp_path, monkeypatch):
    """Only pcl_ddg and pcl_ddg.* are skipped to find the caller: pcl_ddg_helpers is the user's."""
    (tmp_path / "pcl_ddg_helpers.py").write_text(
        "import pcl_ddg\n"
        "def fit(points):\n"
        "    return pcl_ddg.estimate_normals(points)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import pcl_ddg_helpers

    _, seen = caught(lambda: pcl_ddg_helpers.fit(terrain(offset=(5e3, 5e3, 100.0))))
    assert len(seen) == 1 and seen[0].filename == str(tmp_path / "pcl_ddg_helpers.py")
