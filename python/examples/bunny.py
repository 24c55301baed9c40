#!/usr/bin/env python3
"""Normals, curvature, neighbourhoods and smoothing of the bundled bunny (data/bunny.ply).

    PYTHONPATH=build/python python3 python/examples/bunny.py [out_folder]

Prints what it finds; with matplotlib installed (Debian: python3-matplotlib) it also saves
bunny_curvature.png (mean curvature, coloured, and the normals) into out_folder.
"""

import os
import sys

import numpy as np

import pcl_ddg

HERE = os.path.dirname(os.path.abspath(__file__))
BUNNY = os.path.join(HERE, "..", "..", "data", "bunny.ply")


def main(out_folder):
    mesh = pcl_ddg.read(BUNNY)
    V, F = mesh.points, mesh.faces
    report = pcl_ddg.mesh_report(V, F)
    print(f"bunny: {report['vertices']} vertices, {report['faces']} faces, "
          f"{report['boundary_loops']} boundary loops, genus {report['genus']}")

    # Normals from the faces, and fitted to 16 neighbours: on the mesh (rings) and in space.
    faces = pcl_ddg.vertex_normals(V, F, weights="area")
    rings = pcl_ddg.estimate_normals(V, faces=F, k=16)
    comparison = pcl_ddg.compare_neighbourhoods(V, F, k=16)
    agree = np.abs(np.einsum("ij,ij->i", faces.normals, rings.normals))
    print(f"area normals vs pca on mesh rings: median angle "
          f"{np.degrees(np.arccos(np.clip(np.median(agree), -1, 1))):.2f} deg")
    print(f"mesh rings vs kd-tree neighbourhoods: mean {comparison.summary['mean']:.2f} deg, "
          f"{100 * comparison.summary['share_over_30']:.1f} % of the vertices over 30 deg")

    # Curvature, raw and smoothed by a short heat flow.
    c = pcl_ddg.curvatures(V, F)
    smooth_mean = pcl_ddg.smooth_field(V, F, c.mean, time=2.0)
    lo, hi = np.nanpercentile(c.mean, [5, 95])
    print(f"mean curvature 5-95 %: {lo:.1f} .. {hi:.1f}; smoothed: "
          f"{np.nanpercentile(smooth_mean, 5):.1f} .. {np.nanpercentile(smooth_mean, 95):.1f}")
    print(f"Gauss-Bonnet: sum K dA = {np.nansum(c.gauss * c.area) / np.pi:.4f} pi")

    # Implicit smoothing of the positions: one step of 2 h^2, the boundary (if any) fixed.
    smoothed = pcl_ddg.smooth(V, F, lambda_dt=2.0, fix_boundary=True)
    print(f"smoothing moved the vertices by {np.linalg.norm(smoothed - V, axis=1).mean():.3g} "
          f"(mean edge length {report['mean_edge_length']:.3g}) on average")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no picture")
        return 0
    os.makedirs(out_folder, exist_ok=True)
    # Plotted with y up (the scan's up axis), the same view and equal axes in both panels.
    X, Y, Z = V[:, 0], V[:, 2], V[:, 1]
    figure = plt.figure(figsize=(11, 5.5))
    for panel in (1, 2):
        ax = figure.add_subplot(1, 2, panel, projection="3d")
        ax.set_box_aspect((np.ptp(X), np.ptp(Y), np.ptp(Z)))
        ax.view_init(elev=15, azim=-70)
        ax.set_axis_off()
        if panel == 1:
            points = ax.scatter(X, Y, Z, c=np.clip(smooth_mean, lo, hi), cmap="coolwarm", s=4)
            figure.colorbar(points, ax=ax, shrink=0.6, label="mean curvature H (1 / length)")
            ax.set_title("mean curvature (cotan, heat-smoothed)")
        else:
            # Every few vertices' normal, 1.2 mean edge lengths long.
            step = max(1, V.shape[0] // 350)
            P, N = V[::step], faces.normals[::step]
            ax.scatter(X, Y, Z, c="lightgray", s=2)
            ax.quiver(P[:, 0], P[:, 2], P[:, 1], N[:, 0], N[:, 2], N[:, 1],
                      length=1.2 * report["mean_edge_length"], color="tab:blue", linewidth=0.6)
            ax.set_title("area-weighted vertex normals")
    figure.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.92, wspace=0.05)
    path = os.path.join(out_folder, "bunny_curvature.png")
    figure.savefig(path, dpi=100)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "out"))
