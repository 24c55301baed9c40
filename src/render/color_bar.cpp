#include "pcl_ddg/render/color_bar.h"

// stb_easy_font is static functions only; the bar uses two of them.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace pcl_ddg {
namespace {

void fill(Image& image, int x0, int y0, int x1, int y1, const std::array<std::uint8_t, 3>& rgb) {
  for (int y = std::max(y0, 0); y < std::min(y1, image.height); ++y) {
    for (int x = std::max(x0, 0); x < std::min(x1, image.width); ++x) {
      std::uint8_t* p = &image.rgb[(static_cast<std::size_t>(y) * image.width + x) * 3];
      p[0] = rgb[0];
      p[1] = rgb[1];
      p[2] = rgb[2];
    }
  }
}

/** Dark text at (x, y) (its top left), each font unit `scale` pixels; returns its width. */
int drawText(Image& image, int x, int y, const std::string& text, int scale) {
  std::vector<char> text_copy(text.begin(), text.end());
  text_copy.push_back('\0');
  std::vector<float> quads(text.size() * 270);  // stb_easy_font: ~270 floats per character
  const int count = stb_easy_font_print(0.0f, 0.0f, text_copy.data(), nullptr, quads.data(),
                                        static_cast<int>(quads.size() * sizeof(float)));
  for (int q = 0; q < count; ++q) {
    // 4 vertices of 16 bytes (x, y, z, colour) per quad: corners 0 and 2 are opposite.
    const float* v = &quads[static_cast<std::size_t>(q) * 16];
    fill(image, x + static_cast<int>(std::lround(v[0] * scale)),
         y + static_cast<int>(std::lround(v[1] * scale)),
         x + static_cast<int>(std::lround(v[8] * scale)),
         y + static_cast<int>(std::lround(v[9] * scale)), {30, 30, 30});
  }
  return stb_easy_font_width(text_copy.data()) * scale;
}

std::string label(const char* prefix, double value) {
  char text[48];
  std::snprintf(text, sizeof text, "%s%.3g", prefix, value);
  return text;
}

}  // namespace

Image withColorBar(const Image& picture, ColorMap map, const ColorRange& range,
                   const std::string& title) {
  const int strip = std::max(160, picture.height / 4);
  Image image;
  image.width = picture.width + strip;
  image.height = picture.height;
  image.rgb.assign(static_cast<std::size_t>(image.width) * image.height * 3, 255);
  for (int y = 0; y < picture.height; ++y) {
    std::copy_n(&picture.rgb[static_cast<std::size_t>(y) * picture.width * 3], picture.width * 3,
                &image.rgb[static_cast<std::size_t>(y) * image.width * 3]);
  }
  // Text a little under 2 % of the height (easy_font's capitals are 7 units tall).
  const int scale = std::max(1, picture.height / 400);
  const int line = 12 * scale;
  const int left = picture.width + strip / 8;
  // The title, in as many lines as the strip's width needs (split at '[' before the units).
  const int room = strip - strip / 8 - 2 * scale;
  int y = picture.height / 20;
  std::string rest = title;
  while (!rest.empty()) {
    std::size_t cut = rest.size();
    while (cut > 1 &&
           stb_easy_font_width(const_cast<char*>(rest.substr(0, cut).c_str())) * scale > room)
      --cut;
    if (cut < rest.size()) {
      const std::size_t bracket = rest.rfind(" [", cut);
      if (bracket != std::string::npos && bracket > 0) cut = bracket;
    }
    drawText(image, left, y, rest.substr(0, cut), scale);
    rest = rest.substr(cut);
    rest.erase(0, rest.find_first_not_of(' '));
    y += line;
  }
  // The bar: high at the top.
  const int top = y + line, bottom = picture.height - picture.height / 10;
  const int bar_width = std::max(8, strip / 6);
  for (int row = top; row < bottom; ++row) {
    const double t = 1.0 - static_cast<double>(row - top) / std::max(1, bottom - top - 1);
    fill(image, left, row, left + bar_width, row + 1, colorAt(map, t));
  }
  const int text_x = left + bar_width + 3 * scale;
  const int half_text = 4 * scale;
  drawText(image, text_x, top - half_text, label(">= ", range.high), scale);
  drawText(image, text_x, (top + bottom) / 2 - half_text, label("", 0.5 * (range.low + range.high)),
           scale);
  drawText(image, text_x, bottom - 1 - half_text, label("<= ", range.low), scale);
  return image;
}

}  // namespace pcl_ddg
