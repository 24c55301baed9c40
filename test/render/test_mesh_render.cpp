// The renderer and colour maps behind the README pictures.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <vector>

#include <stb_image.h>

#include "analytic_surfaces.h"
#include "pcl_ddg/render/color_bar.h"
#include "pcl_ddg/render/color_map.h"
#include "pcl_ddg/render/mesh_render.h"
#include "test_data.h"

namespace pcl_ddg {
namespace test {
namespace {

std::array<int, 3> pixel(const Image& image, int x, int y) {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * image.width + x);
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

TEST(MeshRender, NearerSurfaceHidesFartherOne) {
  // Two unit squares facing the camera (view along -z: azimuth 0, elevation 0, up y puts the
  // viewer on +z); the red one is nearer and smaller, the blue one behind and larger.
  Eigen::Matrix3Xd p(3, 8);
  p << -1, 1, 1, -1, -0.5, 0.5, 0.5, -0.5,  //
      -1, -1, 1, 1, -0.5, -0.5, 0.5, 0.5,   //
      0, 0, 0, 0, 1, 1, 1, 1;
  Eigen::Matrix3Xi t(3, 4);
  t << 0, 0, 4, 4, 1, 2, 5, 6, 2, 3, 6, 7;
  Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic> c(3, 8);
  c.leftCols(4).colwise() = Eigen::Matrix<std::uint8_t, 3, 1>(0, 0, 255);
  c.rightCols(4).colwise() = Eigen::Matrix<std::uint8_t, 3, 1>(255, 0, 0);
  RenderOptions o;
  o.width = o.height = 100;
  o.azimuth_degrees = 0;
  o.elevation_degrees = 0;
  const Image image = renderMesh(p, t, c, o);
  const auto centre = pixel(image, 50, 50);
  EXPECT_GT(centre[0], 100);
  EXPECT_EQ(centre[2], 0);
  const auto side = pixel(image, 15, 50);
  EXPECT_EQ(side[0], 0);
  EXPECT_GT(side[2], 100);
  EXPECT_EQ(pixel(image, 1, 1), (std::array<int, 3>{255, 255, 255}));  // margin stays background
}

int litPixels(const Image& image) {
  int lit = 0;
  for (std::size_t i = 0; i < image.rgb.size(); i += 3)
    lit += image.rgb[i] != 255 || image.rgb[i + 1] != 255 || image.rgb[i + 2] != 255;
  return lit;
}

TEST(MeshRender, CloudsAreSplatsShadedByTheirNormalsAndNaNPointsAreSkipped) {
  // A flat grid facing the camera, one NaN point among it.
  const SurfaceSample plane = makePlane({32, 0.0, 1});
  Eigen::Matrix3Xd points = plane.points;
  points(0, 7) = std::numeric_limits<double>::quiet_NaN();
  Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic> c(3, points.cols());
  c.setConstant(200);
  RenderOptions o;
  o.width = o.height = 100;
  o.azimuth_degrees = 0;
  o.elevation_degrees = 0;  // the viewer on +z, facing the plane
  const Image plain = renderPoints(points, Eigen::Matrix3Xd(), c, o);
  // The splats cover most of the square the grid spans (0.9 of the picture), not single pixels.
  EXPECT_GT(litPixels(plain), 0.6 * 90 * 90);
  // Normals along the view axis: Lambert shading differs from the depth cue of a flat plane.
  const Image lit = renderPoints(points, plane.normals, c, o);
  EXPECT_NE(pixel(lit, 50, 50), pixel(plain, 50, 50));
  // Normals tilted away from the light make it darker.
  const Eigen::Matrix3Xd grazing = Eigen::Vector3d(1, 0, 0).replicate(1, points.cols());
  EXPECT_LT(pixel(renderPoints(points, grazing, c, o), 50, 50)[0], pixel(lit, 50, 50)[0]);
}

// The PNG decodes (stb_image, not the writer) to the rendered bytes; the folder holds nothing
// else; a write that fails leaves the file that was there whole.
TEST(MeshRender, SavesAPngAtomically) {
  const SurfaceSample sphere = makeIcosphere(2);
  Eigen::Matrix<std::uint8_t, 3, Eigen::Dynamic> c(3, sphere.points.cols());
  c.setConstant(200);
  const std::string dir = scratchFolder("render");
  const std::string path = dir + "/sphere.png";
  const Image image = renderMesh(sphere.points, sphere.triangles, c);
  savePNG(path, image);
  int width = 0, height = 0, channels = 0;
  const auto decode = [&] {
    std::uint8_t* pixels = stbi_load(path.c_str(), &width, &height, &channels, 3);
    std::vector<std::uint8_t> bytes;
    if (pixels) bytes.assign(pixels, pixels + 3 * width * height);
    stbi_image_free(pixels);
    return bytes;
  };
  EXPECT_EQ(decode(), image.rgb);
  EXPECT_EQ(width, image.width);
  EXPECT_EQ(height, image.height);
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files += entry.exists();
  EXPECT_EQ(files, 1) << "a temporary file was left beside the picture";

  EXPECT_THROW(savePNG(path, Image{}), std::exception);  // nothing to encode
  EXPECT_EQ(decode(), image.rgb);
  EXPECT_THROW(savePNG(dir + "/missing/sphere.png", Image{}), std::exception);
}

TEST(ColorMap, DivergingIsSymmetricAboutZeroAndNaNIsGrey) {
  Eigen::VectorXd v(5);
  v << -2, 0, 1, std::numeric_limits<double>::quiet_NaN(), 2;
  const auto rgb = colorize(v, ColorMap::Diverging, {0.0, 100.0});
  EXPECT_GT(rgb(2, 0), rgb(0, 0));  // negative: blue
  EXPECT_GT(rgb(0, 4), rgb(2, 4));  // positive: red
  EXPECT_EQ(rgb(0, 1), rgb(2, 1));  // zero: neutral
  EXPECT_EQ(rgb.col(3), (Eigen::Matrix<std::uint8_t, 3, 1>(128, 128, 128)));
  // Symmetric: the range is [-m, m], m the largest magnitude, so -1 among {-1, 3} is a third of
  // the way from neutral to blue, not the blue end; -3 is the blue end as 3 is the red one.
  Eigen::VectorXd skewed(4);
  skewed << -1, 3, 0, -3;
  const ColorRange range = colorRange(skewed.head(2), ColorMap::Diverging, {0.0, 100.0});
  EXPECT_EQ(range.low, -3.0);
  EXPECT_EQ(range.high, 3.0);
  const auto ends = colorize((Eigen::VectorXd(2) << -3, 3).finished(), ColorMap::Diverging);
  const auto mixed = colorize(skewed, ColorMap::Diverging, {0.0, 100.0});
  EXPECT_EQ(mixed.col(3), ends.col(0));
  EXPECT_EQ(mixed.col(1), ends.col(1));
  EXPECT_NE(mixed.col(0), ends.col(0));
  EXPECT_EQ(mixed.col(2), rgb.col(1));  // zero stays neutral whatever the range
}

TEST(ColorMap, PercentilesClampOutliers) {
  Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(101, 0.0, 100.0);
  v[100] = 1e9;  // one outlier must not flatten the rest of the scale
  const auto rgb = colorize(v, ColorMap::Sequential, {0.0, 98.0});
  EXPECT_EQ(rgb.col(98), rgb.col(100));
  EXPECT_NE(rgb.col(0), rgb.col(50));
  EXPECT_NE(rgb.col(50), rgb.col(98));
}

// Points on an ellipsoid with semi-axes 3, 2, 1 along the columns of a rotation, far from the
// origin.
Eigen::Matrix3Xd ellipsoid(const Eigen::Matrix3d& rotation) {
  Eigen::Matrix3Xd points(3, 2000);
  for (int i = 0; i < 2000; ++i) {
    const double theta = std::acos(1.0 - 2.0 * (i + 0.5) / 2000.0), phi = 2.399963 * i;
    const Eigen::Vector3d unit(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                               std::cos(theta));
    points.col(i) = rotation * Eigen::Vector3d(3.0, 2.0, 1.0).cwiseProduct(unit) +
                    Eigen::Vector3d(5e5, 4e6, 100.0);
  }
  points(0, 7) = std::numeric_limits<double>::quiet_NaN();  // skipped
  return points;
}

// The default view looks along the shortest axis (the largest projected area), with the vertical
// up as seen from there, or the longest axis when the view looks along the vertical.
TEST(DefaultView, LooksAlongTheSmallestAxisWithTheVerticalOrTheLargestAxisUp) {
  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()) *
                                    Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()))
                                       .toRotationMatrix();
  const Eigen::Matrix3Xd points = ellipsoid(rotation);
  const DefaultView view = defaultView(points, Eigen::Matrix3Xd(), false);
  const Eigen::Vector3d smallest = rotation.col(2);
  EXPECT_GT(std::abs(view.front.dot(smallest)), 1.0 - 1e-6);
  EXPECT_GE(view.front.z(), 0.0);  // no normals: from the side of +z
  ASSERT_GT(std::abs(smallest.y()), 0.0);
  ASSERT_LT(std::abs(smallest.y()), 0.85);  // +y is more than 30 degrees from the view
  const Eigen::Vector3d y_seen = (Eigen::Vector3d::UnitY() - smallest.y() * smallest).normalized();
  EXPECT_GT(view.up.dot(y_seen), 1.0 - 1e-6);
  // Normals facing -front on the whole put the camera on their side, -front; facing front, on
  // front's.
  Eigen::Matrix3Xd normals = Eigen::Matrix3Xd::Zero(3, 2000);
  normals.col(3) = -view.front;
  EXPECT_LT(defaultView(points, normals, false).front.dot(view.front), -1.0 + 1e-9);
  normals.col(3) = view.front;
  EXPECT_GT(defaultView(points, normals, false).front.dot(view.front), 1.0 - 1e-9);
  // Seen along +y (its smallest axis): the largest axis (x) is up.
  const Eigen::Matrix3d lying =
      (Eigen::Matrix3d() << 1, 0, 0, 0, 0, 1, 0, -1, 0).finished();  // axes x, -z, y
  const DefaultView along_y = defaultView(ellipsoid(lying), Eigen::Matrix3Xd(), false);
  EXPECT_GT(std::abs(along_y.front.y()), 1.0 - 1e-6);
  EXPECT_GT(std::abs(along_y.up.x()), 1.0 - 1e-6);
  // Far from the origin for its size: geographic by position. +z up in a side view; a flat
  // terrain (smallest axis z) is a map seen from above, north (+y) up.
  EXPECT_TRUE(farFromOrigin(points));
  EXPECT_FALSE(farFromOrigin(points.colwise() - Eigen::Vector3d(5e5, 4e6, 100.0)));
  const Eigen::Matrix3d standing =
      (Eigen::Matrix3d() << 0, 1, 0, 0, 0, 1, 1, 0, 0).finished();  // axes z, x, y
  const DefaultView side = defaultView(ellipsoid(standing), Eigen::Matrix3Xd(), true);
  EXPECT_GT(std::abs(side.front.y()), 1.0 - 1e-6);
  EXPECT_GT(side.up.z(), 1.0 - 1e-6);
  Eigen::Matrix3Xd terrain = points;
  terrain.row(2) = 50.0 + 0.01 * points.row(0).array();
  const DefaultView above = defaultView(terrain, Eigen::Matrix3Xd(), true);
  EXPECT_GT(above.front.z(), 0.99);
  EXPECT_GT(above.up.y(), 0.99);
}

TEST(ColorBar, AStripBesideThePictureWithTheMapHighAtTheTopAndDarkLabels) {
  Image picture;
  picture.width = 300;
  picture.height = 400;
  picture.rgb.assign(static_cast<std::size_t>(300) * 400 * 3, 90);
  const Image bar = withColorBar(picture, ColorMap::Diverging, {-2.5, 2.5}, "k1 [1/length]");
  ASSERT_EQ(bar.height, 400);
  ASSERT_GE(bar.width, 300 + 100);
  // The picture is kept as it was, pixel for pixel.
  for (int y = 0; y < 400; y += 7) {
    for (int x = 0; x < 300; x += 7) EXPECT_EQ(pixel(bar, x, y), (std::array<int, 3>{90, 90, 90}));
  }
  // In the strip: a column whose colours run from the map's high end (red, top) through its
  // middle to its low end (blue, bottom), and dark text beside and above it.
  int bar_column = -1, dark = 0;
  for (int x = 300; x < bar.width && bar_column < 0; ++x) {
    for (int y = 0; y < bar.height; ++y) {
      const std::array<int, 3> c = pixel(bar, x, y);
      if (c[0] == 180 && c[1] == 4 && c[2] == 38) {  // the diverging map's red end
        bar_column = x;
        break;
      }
    }
  }
  ASSERT_GE(bar_column, 0) << "no red end of the map in the strip";
  std::vector<std::array<int, 3>> column;
  for (int y = 0; y < bar.height; ++y) {
    const std::array<int, 3> c = pixel(bar, bar_column, y);
    // The bar's pixels: neither the background nor the (dark grey) text above it.
    if (c != std::array<int, 3>{255, 255, 255} && c != std::array<int, 3>{30, 30, 30})
      column.push_back(c);
  }
  ASSERT_GT(column.size(), 200u);
  EXPECT_EQ(column.front(), (std::array<int, 3>{180, 4, 38}));
  EXPECT_EQ(column.back(), (std::array<int, 3>{59, 76, 192}));
  EXPECT_NEAR(column[column.size() / 2][0], column[column.size() / 2][2], 6);  // neutral: r = b
  for (int y = 0; y < bar.height; ++y) {
    for (int x = 300; x < bar.width; ++x) dark += pixel(bar, x, y)[0] < 60;
  }
  EXPECT_GT(dark, 200) << "no text in the strip";
}

}  // namespace
}  // namespace test
}  // namespace pcl_ddg
