#pragma once
// Drawing plots into an RGB image (written as PNG by the caller): dots, boxes, lines and text in
// a 5 × 7 pixel font of the digits, lower-case letters and a few signs (upper case drawn as lower).
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "io/volume_writers.hpp"

namespace angiosynth {

// A 5 × 7 pixel font for the few characters a plot needs (rows top down, bit 4 leftmost).
inline const std::map<char, std::array<std::uint8_t, 7>>& plotFont() {
  static const std::map<char, std::array<std::uint8_t, 7>> f{{'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
                                                             {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
                                                             {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
                                                             {'3', {0x1E, 0x01, 0x01, 0x0E, 0x01, 0x01, 0x1E}},
                                                             {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
                                                             {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
                                                             {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
                                                             {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
                                                             {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
                                                             {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
                                                             {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
                                                             {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
                                                             {' ', {0, 0, 0, 0, 0, 0, 0}},
                                                             {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
                                                             {'e', {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
                                                             {'c', {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}},
                                                             {'a', {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}},
                                                             {'l', {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
                                                             {'d', {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F}},
                                                             {'i', {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}},
                                                             {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D}},
                                                             {'s', {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}},
                                                             {'v', {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04}},
                                                             {'o', {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}},
                                                             {'x', {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}},
                                                             {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}},
                                                             {'b', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1E}},
                                                             {'f', {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}},
                                                             {'g', {0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E}},
                                                             {'h', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}},
                                                             {'j', {0x02, 0x00, 0x06, 0x02, 0x02, 0x12, 0x0C}},
                                                             {'k', {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}},
                                                             {'m', {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11}},
                                                             {'p', {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10}},
                                                             {'q', {0x00, 0x00, 0x0D, 0x13, 0x0F, 0x01, 0x01}},
                                                             {'t', {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}},
                                                             {'w', {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A}},
                                                             {'y', {0x00, 0x00, 0x11, 0x11, 0x0F, 0x01, 0x0E}},
                                                             {'z', {0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F}},
                                                             {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}},
                                                             {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}},
                                                             {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
                                                             {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
                                                             {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
                                                             {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}}};
  return f;
}

struct PlotCanvas {
  Image8 img;  // RGB, white
  PlotCanvas(int w, int h) {
    img.width = w, img.height = h, img.channels = 3;
    img.pixels.assign(std::size_t(w) * h * 3, 255);
  }
  void dot(int x, int y, std::uint32_t rgb) {
    if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
    auto* p = &img.pixels[(std::size_t(y) * img.width + x) * 3];
    p[0] = std::uint8_t(rgb >> 16), p[1] = std::uint8_t(rgb >> 8), p[2] = std::uint8_t(rgb);
  }
  void box(int x0, int y0, int x1, int y1, std::uint32_t rgb) {
    for (int y = std::min(y0, y1); y <= std::max(y0, y1); ++y)
      for (int x = std::min(x0, x1); x <= std::max(x0, x1); ++x) dot(x, y, rgb);
  }
  void line(int x0, int y0, int x1, int y1, std::uint32_t rgb, int width) {
    const int n = std::max({std::abs(x1 - x0), std::abs(y1 - y0), 1});
    for (int s = 0; s <= n; ++s) {
      const int x = x0 + (x1 - x0) * s / n, y = y0 + (y1 - y0) * s / n;
      box(x - width / 2, y - width / 2, x + (width - 1) / 2, y + (width - 1) / 2, rgb);
    }
  }
  // Text at scale 2, left edge x (or centred on x), top y; `vertical` runs bottom up.
  void text(const std::string& s, int x, int y, bool centred = false, bool vertical = false) {
    const int scale = 2, advance = 6 * scale, len = int(s.size()) * advance;
    if (centred) (vertical ? y : x) += (vertical ? len : -len) / 2;
    for (std::size_t c = 0; c < s.size(); ++c) {
      auto it = plotFont().find(s[c]);
      if (it == plotFont().end()) it = plotFont().find(char(std::tolower(static_cast<unsigned char>(s[c]))));
      if (it == plotFont().end()) continue;
      for (int row = 0; row < 7; ++row)
        for (int col = 0; col < 5; ++col) {
          if (!((it->second[std::size_t(row)] >> (4 - col)) & 1)) continue;
          const int u = int(c) * advance + col * scale, v = row * scale;
          if (vertical)
            box(x + v, y - u, x + v + scale - 1, y - u - scale + 1, 0x000000);
          else
            box(x + u, y + v, x + u + scale - 1, y + v + scale - 1, 0x000000);
        }
    }
  }
};

// A number as a plot labels it (%g).
inline std::string plotLabel(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

}  // namespace angiosynth
