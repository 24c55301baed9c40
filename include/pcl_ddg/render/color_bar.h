#pragma once
/** \file
 * A colour bar beside a picture of a field: a strip on the right with the field's name (and
 * units), the colour map from the top (high) to the bottom (low) and the values of its ends and
 * middle. The ends are the clamped range (ColorRange): values beyond them have the end colours,
 * so their labels read ">=" and "<=". Text is stb_easy_font's built-in vector font.
 */
#include <string>

#include "pcl_ddg/render/color_map.h"
#include "pcl_ddg/render/mesh_render.h"

namespace pcl_ddg {

/** The picture widened by the bar's strip (a quarter of its height, at least 160 pixels). */
Image withColorBar(const Image& picture, ColorMap map, const ColorRange& range,
                   const std::string& title);

}  // namespace pcl_ddg
