#!/usr/bin/env python3
"""Mesh health under large implicit smoothing steps, for each weight-update policy.

Three implicit cotangent steps of 2 h^2 with the volume preserved (pcl_ddg.smooth), on coarse
genus-2..4 surfaces with thin handles built here (chains of 2-4 fused tori, tube radius 0.15 or
0.25 of the ring radius, marched by VTK's flying edges and decimated to 2250 faces per handle by
quadric decimation or DecimatePro) and on the shared scans. Per policy it prints the slivers
created (triangles whose smallest corner fell below 1 deg, as a share of the faces) and how much
the surface was smoothed: the mean normal component of the umbrella vector (mean of the
neighbours minus the vertex), after over before.

    PYTHONPATH=build/python python3 bench/bench_smoothing_health.py [../shared/data/meshes]

Needs python3-vtk9 (Debian) for the synthetic surfaces.
"""
import os
import sys
import time

import numpy as np
import scipy.sparse as sp

import pcl_ddg

POLICIES = {  # pcl_ddg.smooth keywords: the library's WeightUpdate and thickness limit
    "default (frozen, thickness limit 0.5)": {},
    "frozen, no limit": {"thickness_limit": 0.0},
    "update_mass": {"update_mass": True},
    "rebuild_weights": {"rebuild_weights": True},
}
SCANS = ["bumpy.off", "bunny.off", "cow.off", "rocker-arm.off", "horse.ply"]


def fused_tori(handles, tube, decimation, faces_per_handle=2250, spacing=0.02):
    """Closed genus-`handles` surface: unit rings 1.9 apart along x, smoothly fused."""
    import vtk
    from vtk.util import numpy_support

    centres = np.arange(handles) * 1.9
    pad = tube + 0.1
    xs = np.arange(-1 - pad, centres[-1] + 1 + pad, spacing)
    ys = np.arange(-1 - pad, 1 + pad, spacing)
    zs = np.arange(-pad, pad, spacing)
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    f = None
    for c in centres:
        d = np.sqrt((np.sqrt((X - c) ** 2 + Y**2) - 1.0) ** 2 + Z**2) - tube
        if f is None:
            f = d
        else:  # polynomial smooth minimum, blend width 0.05
            k = 0.05
            t = np.clip(0.5 + 0.5 * (d - f) / k, 0.0, 1.0)
            f = d * (1 - t) + f * t - k * t * (1 - t)
    image = vtk.vtkImageData()
    image.SetDimensions(len(xs), len(ys), len(zs))
    image.SetSpacing(spacing, spacing, spacing)
    image.SetOrigin(xs[0], ys[0], zs[0])
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(f.ravel(order="F"), deep=True))
    surface = vtk.vtkFlyingEdges3D()
    surface.SetInputData(image)
    surface.SetValue(0, 0.0)
    surface.ComputeNormalsOff()
    clean = vtk.vtkCleanPolyData()
    clean.SetInputConnection(surface.GetOutputPort())
    clean.Update()
    dense = clean.GetOutput()
    if decimation == "quadric":
        decimate = vtk.vtkQuadricDecimation()
    else:
        decimate = vtk.vtkDecimatePro()
        decimate.PreserveTopologyOn()
    decimate.SetInputData(dense)
    decimate.SetTargetReduction(1.0 - handles * faces_per_handle / dense.GetNumberOfPolys())
    decimate.Update()
    out = decimate.GetOutput()
    V = numpy_support.vtk_to_numpy(out.GetPoints().GetData()).astype(float)
    F = numpy_support.vtk_to_numpy(out.GetPolys().GetData()).reshape(-1, 4)[:, 1:]
    return V, F.astype(np.int64)


def smallest_angles(V, F):
    """Smallest corner of every triangle, degrees."""
    corners = []
    for i in range(3):
        a = V[F[:, (i + 1) % 3]] - V[F[:, i]]
        b = V[F[:, (i + 2) % 3]] - V[F[:, i]]
        cos = np.einsum("ij,ij->i", a, b) / (
            np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1) + 1e-300
        )
        corners.append(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    return np.min(corners, axis=0)


def umbrella_normal(V, F):
    """Mean |(mean of the neighbours - vertex) . n| over the vertices with neighbours."""
    n = len(V)
    rows = np.concatenate([F[:, 0], F[:, 1], F[:, 2], F[:, 1], F[:, 2], F[:, 0]])
    cols = np.concatenate([F[:, 1], F[:, 2], F[:, 0], F[:, 0], F[:, 1], F[:, 2]])
    A = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    A.data[:] = 1.0  # distinct neighbours
    degree = np.asarray(A.sum(axis=1)).ravel()
    used = degree > 0
    U = A @ V / np.maximum(degree, 1)[:, None] - V
    face_normals = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    normals = np.zeros_like(V)
    for i in range(3):
        np.add.at(normals, F[:, i], face_normals)
    normals /= np.linalg.norm(normals, axis=1)[:, None] + 1e-300
    return np.mean(np.abs(np.einsum("ij,ij->i", U, normals))[used])


def measure(name, V, F):
    before = smallest_angles(V, F) < 1.0
    roughness = umbrella_normal(V, F)
    cells = []
    for keywords in POLICIES.values():
        try:
            W = pcl_ddg.smooth(
                V, F, lambda_dt=2.0, iterations=3, preserve="volume", **keywords
            )
        except (ValueError, pcl_ddg.SurfaceCollapseError) as e:
            cells.append("error: %s" % str(e)[:30])
            continue
        created = np.count_nonzero((smallest_angles(W, F) < 1.0) & ~before)
        cells.append(
            "%5.2f %% | %.2f" % (100.0 * created / len(F), umbrella_normal(W, F) / roughness)
        )
    print("| %-24s | %6d | %s |" % (name, len(F), " | ".join(cells)), flush=True)


def main():
    scans = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "..", "shared", "data", "meshes"
    )
    start = time.time()
    header = " | ".join("%s: slivers | umbrella" % p for p in POLICIES)
    print("| mesh | faces | %s |" % header)
    print("|---|---|" + "---|---|" * len(POLICIES))
    for decimation in ("quadric", "pro"):
        for tube in (0.15, 0.25):
            for handles in (2, 3, 4):
                V, F = fused_tori(handles, tube, decimation)
                measure("genus %d, tube %.2f, %s" % (handles, tube, decimation), V, F)
    for scan in SCANS:
        mesh = pcl_ddg.read(os.path.join(scans, scan))
        measure(scan, np.asarray(mesh.points, float)[:, :3], np.asarray(mesh.faces))
    print("(%.0f s)" % (time.time() - start))


if __name__ == "__main__":
    main()
