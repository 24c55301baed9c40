#pragma once
// A small software renderer for pictures of results (README figures, quick looks on headless
// machines): orthographic view, z-buffer, per-vertex colours interpolated across each triangle,
// Lambert shading by the face normal (two-sided), written as PNG.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace pcl_ddg {

struct RenderOptions {
  int width = 800;
  int height = 800;
  double azimuth_degrees = 30.0;    ///< rotation about the up (y) axis
  double elevation_degrees = 20.0;  ///< camera above the horizontal plane
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
};

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  ///< row-major, 3 bytes per pixel
};

/** Renders triangles (3 x T into positions) with per-vertex colours (3 x N, 0..255). */
Image renderMesh(const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xi& triangles,
                 const Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic>& colors,
                 const RenderOptions& options = {});

/** Writes a PNG through a temporary file (atomic); throws FileFormatException. */
void savePNG(const std::string& path, const Image& image);

}  // namespace pcl_ddg
