"""read / write: exact round trips, fields, colours, organized clouds, errors."""

import numpy as np
import pytest

import pcl_ddg
from conftest import icosphere, shared_data


@pytest.mark.parametrize("extension", ["ply", "pcd"])
def test_round_trip_is_exact(tmp_path, extension):
    V, F = icosphere(2)
    V = V + 1e5  # far from the origin: float would lose the digits
    rng = np.random.default_rng(0)
    fields = {"normals": V / np.linalg.norm(V, axis=1, keepdims=True),
              "quality": rng.random(V.shape[0]),
              "rgb": rng.integers(0, 256, (V.shape[0], 3), dtype=np.uint8)}
    path = tmp_path / f"mesh.{extension}"
    pcl_ddg.write(path, V, F if extension == "ply" else None, fields)
    back = pcl_ddg.read(path)
    np.testing.assert_array_equal(back.points, V)
    assert back.points.dtype == np.float64 and back.precision == "double"
    np.testing.assert_array_equal(back.fields["quality"], fields["quality"])
    np.testing.assert_array_equal(back.fields["rgb"], fields["rgb"])
    names = ("nx", "ny", "nz") if extension == "ply" else ("normal_x", "normal_y", "normal_z")
    np.testing.assert_array_equal(np.stack([back.fields[n] for n in names], 1), fields["normals"])
    if extension == "ply":
        np.testing.assert_array_equal(back.faces, F)
    else:
        assert back.faces is None


def test_float_precision_when_lossless(tmp_path):
    V = np.arange(30, dtype=np.float32).reshape(10, 3)
    pcl_ddg.write(tmp_path / "a.ply", V)
    back = pcl_ddg.read(tmp_path / "a.ply")
    assert back.precision == "float"
    np.testing.assert_array_equal(back.points, V)


def test_organized_cloud_and_viewpoint(tmp_path):
    xyz = np.random.default_rng(1).random((4, 5, 3))
    xyz[0, 0] = np.nan
    pcl_ddg.write(tmp_path / "grid.pcd", xyz, viewpoint=[1, 2, 3])
    back = pcl_ddg.read(tmp_path / "grid.pcd")
    assert back.organized_shape == (4, 5)
    np.testing.assert_array_equal(back.grid, xyz)
    np.testing.assert_array_equal(back.viewpoint, [1, 2, 3])


def test_shared_scans_read():
    # Counts from the shared data's CATALOG.md (measured there with other tools).
    data = shared_data()
    office = pcl_ddg.read(data / "clouds" / "office1.pcd")
    assert office.organized_shape == (480, 640) and office.faces is None
    assert office.points.shape == (307200, 3)
    assert office.fields["rgb"].dtype == np.uint8 and office.fields["rgb"].shape == (307200, 3)
    # A Kinect frame: a pixel has a whole point or none (NaN x y z), and most have one.
    finite = np.isfinite(office.points)
    assert np.array_equal(finite.all(axis=1), finite.any(axis=1))
    assert 0.5 * 307200 < finite.all(axis=1).sum() < 307200
    np.testing.assert_array_equal(office.grid.reshape(-1, 3), office.points)
    igea = pcl_ddg.read(data / "meshes" / "igea.ply")  # faces as one tristrips element
    assert igea.points.shape == (134345, 3) and len(igea.faces) == 268686
    assert np.isfinite(igea.points).all()
    assert int(np.max(igea.faces)) < len(igea.points) and int(np.min(igea.faces)) >= 0
    grid = pcl_ddg.read(data / "meshes" / "bun045_rangegrid_tri.ply")
    assert grid.points.shape == (40097, 3) and len(grid.faces) == 79057
    assert np.isfinite(grid.points).all()
    # its 6 unused vertices (CATALOG.md): every other vertex is a corner of some triangle
    assert len(grid.points) - len(np.unique(np.asarray(grid.faces))) == 6


def test_file_errors_are_oserrors(tmp_path):
    with pytest.raises(FileNotFoundError):
        pcl_ddg.read(tmp_path / "missing.ply")
    (tmp_path / "bad.ply").write_text("ply\nformat nonsense\n")
    with pytest.raises(OSError):
        pcl_ddg.read(tmp_path / "bad.ply")
    (tmp_path / "x.xyz2").write_text("1 2 3\n")
    with pytest.raises(OSError):
        pcl_ddg.read(tmp_path / "x.xyz2")
    with pytest.raises(OSError):
        pcl_ddg.write(tmp_path / "no_such_folder" / "a.ply", np.zeros((3, 3)))


@pytest.mark.parametrize("encoding", ["binary", "ascii"])
def test_faces_as_an_array_write_the_bytes_of_the_same_faces_as_polygons(tmp_path, encoding):
    """An (m, k) array is written from its block (no pcl::Vertices per face): the same file as
    the same faces given as a list of polygons, which goes through PCL's polygons."""
    V, F = icosphere(2)
    quads = np.array([[0, 1, 2, 3], [4, 5, 6, 7]])
    for faces in (F, F.astype(np.uint16), quads):
        a, b = tmp_path / "array.ply", tmp_path / "list.ply"
        pcl_ddg.write(a, V, faces, encoding=encoding)
        pcl_ddg.write(b, V, [list(map(int, f)) for f in faces], encoding=encoding)
        assert a.read_bytes() == b.read_bytes()
        back = pcl_ddg.read(a)
        np.testing.assert_array_equal(np.asarray(back.faces), faces)
    with pytest.raises(ValueError, match="face 7 names vertex 162, outside 0..161"):
        bad = F.copy()
        bad[7, 1] = len(V)
        pcl_ddg.write(tmp_path / "bad.ply", V, bad)
    assert not (tmp_path / "bad.ply").exists()


def test_paths_as_bytes_and_path_objects(tmp_path):
    V, F = icosphere(1)
    for path in (bytes(tmp_path / "a.ply"), tmp_path / "b.ply", str(tmp_path / "c.ply")):
        pcl_ddg.write(path, V, F)
        np.testing.assert_array_equal(pcl_ddg.read(path).points, V)
