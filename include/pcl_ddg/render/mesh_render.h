#pragma once
/** \file
 * A small software renderer for pictures of results (README figures, quick looks on headless
 * machines): orthographic view, z-buffer, per-vertex colours interpolated across each triangle,
 * Lambert shading by the face normal (two-sided); point clouds as round splats, shaded by their
 * normals when they have them; written as PNG.
 */
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace pcl_ddg {

struct RenderOptions {
  int width = 800;
  int height = 800;
  double azimuth_degrees = 30.0;    ///< rotation about the up axis
  double elevation_degrees = 20.0;  ///< camera above the plane normal to up
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  /** Towards the camera at azimuth and elevation 0 (made normal to up); zero: a fixed axis
   *  normal to up (z, or x for an up near z). */
  Eigen::Vector3d front = Eigen::Vector3d::Zero();
  double point_radius_pixels = 0.0;  ///< splat radius for clouds; 0 = from the point count
};

/** The view that shows the most of an object: front along its smallest principal axis (the
 *  largest projected area), on the side its normals (3 x N, or empty) face on the whole, else
 *  the side of +z (or +y). Up: the vertical (+y; +z for geographic data) as seen from there,
 *  unless the view looks within 30 degrees of it; then the largest principal axis, or north (+y)
 *  on a geographic map seen from above. NaN positions are skipped. */
struct DefaultView {
  Eigen::Vector3d front, up;
  Eigen::Vector3d centre;  ///< of the finite positions, what the camera looks at
};
DefaultView defaultView(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& normals,
                        bool geographic);

/** The bounding box of the finite positions (empty if none). */
Eigen::AlignedBox3d finiteBounds(const Eigen::Matrix3Xd& positions);

/** Whether the finite positions' centre is more than 100 times their extent from the origin, as
 *  projected (UTM) coordinates are: with a LAS input, what makes data geographic. */
bool farFromOrigin(const Eigen::Matrix3Xd& positions);

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  ///< row-major, 3 bytes per pixel
};

/** Renders triangles (3 x T into positions) with per-vertex colours (3 x N, 0..255). */
Image renderMesh(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xi& triangles,
                 const Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic>& colors,
                 const RenderOptions& options = {});

/** Renders points (3 x N, NaN ones skipped) as splats with per-point colours; normals (3 x N, or
 *  empty) shade them two-sided, else nearer points are drawn lighter. */
Image renderPoints(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& normals,
                   const Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic>& colors,
                   const RenderOptions& options = {});

/** Writes a PNG through a temporary file (atomic); throws FileFormatException. */
void savePNG(const std::string& path, const Image& image);

}  // namespace pcl_ddg
