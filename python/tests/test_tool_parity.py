"""Bit for bit against the C++ tools on the shared scans: the same file through pcl_ddg.read and
the module, or through the tool (written with -precision double, read back exactly)."""

import numpy as np
import pytest

import pcl_ddg
from conftest import run_tool, shared_data


def fields(path, *names):
    f = pcl_ddg.read(path).fields
    return [f[n] for n in names]


def stacked(path, names):
    return np.stack(fields(path, *names), axis=1)


@pytest.mark.parametrize("weighting", ["area", "uniform", "angle", "mean_curvature"])
def test_vertex_normals_equal_pcl_ddg_normals(tmp_path, weighting):
    source = shared_data() / "meshes" / "bunny.off"
    out = tmp_path / "normals.ply"
    run_tool("pcl_ddg_normals", source, out, "-method", weighting, "-precision", "double")
    mesh = pcl_ddg.read(source)
    n = pcl_ddg.vertex_normals(mesh.points, mesh.faces, weights=weighting)
    np.testing.assert_array_equal(n.normals, stacked(out, ["nx", "ny", "nz"]))


@pytest.mark.parametrize("scan", ["bunny.off", "bun_zipper_res3.ply", "tum_rabbit.vtk"])
def test_curvatures_equal_pcl_ddg_curvature(tmp_path, scan):
    source = shared_data() / "meshes" / scan
    out = tmp_path / "curvature.ply"
    run_tool("pcl_ddg_curvature", source, out, "-precision", "double")
    mesh = pcl_ddg.read(source)
    c = pcl_ddg.curvatures(mesh.points, mesh.faces)
    mean, gauss, k1, k2, area = fields(out, "mean_curvature", "gauss_curvature", "k1", "k2",
                                       "vertex_area")
    for ours, theirs in ((c.mean, mean), (c.gauss, gauss), (c.k1, k1), (c.k2, k2),
                         (c.area, area)):
        np.testing.assert_array_equal(ours, theirs)


def test_smooth_field_equals_pcl_ddg_curvature_smooth(tmp_path):
    source = shared_data() / "meshes" / "cow.off"
    out = tmp_path / "curvature.ply"
    run_tool("pcl_ddg_curvature", source, out, "-smooth", "2", "-precision", "double")
    mesh = pcl_ddg.read(source)
    c = pcl_ddg.curvatures(mesh.points, mesh.faces)
    smoothed = pcl_ddg.smooth_field(mesh.points, mesh.faces,
                                    np.stack([c.mean, c.gauss, c.k1, c.k2], 1), time=2.0)
    np.testing.assert_array_equal(
        smoothed, stacked(out, ["mean_curvature", "gauss_curvature", "k1", "k2"]))


@pytest.mark.parametrize("arguments", [[], ["-method", "explicit", "-iterations", "20"],
                                       ["-lambda_dt", "5", "-preserve", "volume",
                                        "-iterations", "3", "-update_mass"],
                                       ["-lambda_dt", "5", "-thickness_limit", "0"],
                                       ["-lambda_dt", "5", "-thickness_limit", "2"],
                                       ["-method", "taubin", "-lambda", "0.4", "-mu", "-0.45",
                                        "-iterations", "10"],
                                       ["-method", "explicit", "-weights", "cotan",
                                        "-average", "degree"]])
def test_smooth_equals_pcl_ddg_smooth(tmp_path, arguments):
    source = shared_data() / "meshes" / "bunny.off"
    out = tmp_path / "smooth.ply"
    run_tool("pcl_ddg_smooth", source, out, *arguments, "-precision", "double")
    mesh = pcl_ddg.read(source)
    keywords = {}
    for flag, value in zip(arguments[::1], arguments[1:] + [None]):
        if flag == "-method":
            keywords["method"] = value
        elif flag == "-iterations":
            keywords["iterations"] = int(value)
        elif flag == "-lambda_dt":
            keywords["lambda_dt"] = float(value)
        elif flag == "-preserve":
            keywords["preserve"] = value
        elif flag == "-update_mass":
            keywords["update_mass"] = True
        elif flag == "-lambda":
            keywords["lambda_"] = float(value)
        elif flag == "-mu":
            keywords["mu"] = float(value)
        elif flag == "-thickness_limit":
            keywords["thickness_limit"] = float(value)
        elif flag in ("-weights", "-average"):
            keywords[flag[1:]] = value
    smoothed = pcl_ddg.smooth(mesh.points, mesh.faces, **keywords)
    np.testing.assert_array_equal(smoothed, pcl_ddg.read(out).points)


@pytest.mark.parametrize("arguments", [["-method", "pca"], ["-method", "quadric"],
                                       ["-method", "robust"],
                                       ["-method", "pca", "-radius", "0.01"],
                                       ["-method", "pca", "-orient", "mst"]])
def test_cloud_normals_equal_pcl_ddg_normals(tmp_path, arguments):
    source = shared_data() / "clouds" / "milk.pcd"
    out = tmp_path / "normals.pcd"
    run_tool("pcl_ddg_normals", source, out, *arguments, "-precision", "double")
    cloud = pcl_ddg.read(source)
    keywords = {"method": arguments[1]}
    if "-radius" in arguments:
        keywords["radius"] = 0.01
    if "-orient" in arguments:
        keywords["orient"] = "mst"  # the tool without -viewpoint: the tree seeded up
    else:
        keywords["viewpoint"] = cloud.viewpoint
    r = pcl_ddg.estimate_normals(cloud.points, **keywords)
    np.testing.assert_array_equal(r.normals, stacked(out, ["normal_x", "normal_y", "normal_z"]))
    np.testing.assert_array_equal(r.curvature, fields(out, "curvature")[0])
    if arguments[1] == "robust":
        robust = pcl_ddg.robust_normals(cloud.points, viewpoint=cloud.viewpoint)
        np.testing.assert_array_equal(robust.normals, r.normals)
        np.testing.assert_array_equal(robust.scale, fields(out, "scale")[0])
        np.testing.assert_array_equal(robust.confidence, fields(out, "confidence")[0])


def test_mesh_ring_normals_equal_pcl_ddg_normals(tmp_path):
    source = shared_data() / "meshes" / "bunny.off"
    out = tmp_path / "normals.ply"
    run_tool("pcl_ddg_normals", source, out, "-method", "quadric", "-precision", "double")
    mesh = pcl_ddg.read(source)
    r = pcl_ddg.estimate_normals(mesh.points, method="quadric", faces=mesh.faces)
    np.testing.assert_array_equal(r.normals, stacked(out, ["nx", "ny", "nz"]))


def test_grid_normals_equal_pcl_ddg_normals_on_an_organized_frame(tmp_path):
    source = shared_data() / "clouds" / "table_scene_mug_stereo_textured.pcd"
    out = tmp_path / "normals.pcd"
    run_tool("pcl_ddg_normals", source, out, "-precision", "double")
    cloud = pcl_ddg.read(source)
    r = pcl_ddg.grid_normals(cloud.grid, viewpoint=cloud.viewpoint)
    np.testing.assert_array_equal(r.normals.reshape(-1, 3),
                                  stacked(out, ["normal_x", "normal_y", "normal_z"]))


def test_grid_normals_of_a_double_frame_measure_ranges_from_the_camera(tmp_path):
    """A flat wall 5.125 m in front of a camera at the origin, float64 pixels that floats do not
    hold: fitted about its local origin (the wall's centre), its depth jumps are still measured
    on ranges from the camera (a range from the local origin, near 0 at the centre, cut the
    pixels there off: NaN in a diamond around the axis). Every pixel faces the camera, and the
    tool reads the same frame from a double PCD to the same bits."""
    v, u = np.mgrid[0:240, 0:320]
    spacing = 0.00976
    frame = np.dstack([(u - 160) * spacing, (v - 120) * spacing, np.full(u.shape, 5.125)])
    assert np.any(frame.astype(np.float32) != frame)  # the doubles are needed
    r = pcl_ddg.grid_normals(frame)
    assert r.valid.all()
    np.testing.assert_allclose(r.normals.reshape(-1, 3), [[0.0, 0.0, -1.0]] * frame[..., 0].size,
                               rtol=0, atol=1e-9)
    source, out = tmp_path / "wall.pcd", tmp_path / "normals.pcd"
    pcl_ddg.write(source, frame, precision="double")
    run_tool("pcl_ddg_normals", source, out, "-precision", "double")
    np.testing.assert_array_equal(r.normals.reshape(-1, 3),
                                  stacked(out, ["normal_x", "normal_y", "normal_z"]))


def test_principal_curvatures_equal_pcl_ddg_curvature_quadric(tmp_path):
    source = shared_data() / "clouds" / "milk.pcd"
    out = tmp_path / "curvature.pcd"
    run_tool("pcl_ddg_curvature", source, out, "-method", "quadric", "-precision", "double")
    cloud = pcl_ddg.read(source)
    c = pcl_ddg.principal_curvatures(cloud.points, viewpoint=cloud.viewpoint)
    k1, k2 = fields(out, "k1", "k2")
    np.testing.assert_array_equal(c.k1, k1)
    np.testing.assert_array_equal(c.k2, k2)
    np.testing.assert_array_equal(
        c.direction1, stacked(out, ["k1_direction_x", "k1_direction_y", "k1_direction_z"]))


def test_compare_neighbourhoods_equals_the_tool(tmp_path):
    source = shared_data() / "meshes" / "bunny.off"
    out = tmp_path / "compare.ply"
    run_tool("pcl_ddg_compare_neighbourhoods", source, out, "-precision", "double")
    mesh = pcl_ddg.read(source)
    c = pcl_ddg.compare_neighbourhoods(mesh.points, mesh.faces)
    angle, overlap = fields(out, "angle_difference", "overlap")
    np.testing.assert_array_equal(c.angle_difference, angle)
    np.testing.assert_array_equal(c.overlap, overlap)
