#pragma once
// A minimal PNG reader for the plot tests (what pngcairo writes: 8-bit RGB or
// RGBA, not interlaced, as Chromium's screenshots too; zlib and the five row
// filters) and counts of drawn
// pixels per panel of a gnuplot multiplot grid.
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace vdyn::test {

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;  ///< width x height x 3
  /// The pixel (x, y): its red, green, blue.
  const unsigned char* at(int x, int y) const { return &rgb[3 * (std::size_t(y) * width + x)]; }
  bool isLineColour(int x, int y) const {
    // gnuplot's first line colour, dark violet (148, 0, 211), and its
    // anti-aliased edge: red and blue well above green.
    const unsigned char* p = &rgb[3 * (std::size_t(y) * width + x)];
    return p[2] > 120 && p[0] > 80 && p[1] < 80;
  }
  /// A saturated pixel: any of gnuplot's line colours, not the black text,
  /// the grey grid and markers or the white background.
  bool isColoured(int x, int y) const {
    const unsigned char* p = &rgb[3 * (std::size_t(y) * width + x)];
    const int hi = std::max({p[0], p[1], p[2]}), lo = std::min({p[0], p[1], p[2]});
    return hi - lo > 90;
  }
  /// Saturated pixels in [x0, x1) x [y0, y1).
  int countColoured(int x0, int y0, int x1, int y1) const {
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) n += isColoured(x, y);
    return n;
  }
  /// Line-colour pixels in [x0, x1) x [y0, y1).
  int count(int x0, int y0, int x1, int y1) const {
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) n += isLineColour(x, y);
    return n;
  }
};

/// Chromium's screenshots are read the same way (test_animation).
using PngImage = Image;

inline std::uint32_t be32(const unsigned char* p) { return (std::uint32_t(p[0]) << 24) | (p[1] << 16) | (p[2] << 8) | p[3]; }

/// Reads an 8-bit RGB or RGBA, non-interlaced PNG (what pngcairo writes).
inline Image readPng(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<unsigned char> f((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (f.size() < 8 || f[1] != 'P' || f[2] != 'N' || f[3] != 'G') throw std::runtime_error(path + ": not a PNG");
  Image im;
  int channels = 0;
  std::vector<unsigned char> idat;
  for (std::size_t i = 8; i + 8 <= f.size();) {
    const std::uint32_t len = be32(&f[i]);
    const std::string type(f.begin() + i + 4, f.begin() + i + 8);
    const unsigned char* d = &f[i + 8];
    if (type == "IHDR") {
      im.width = int(be32(d)), im.height = int(be32(d + 4));
      if (d[8] != 8 || d[12] != 0 || (d[9] != 2 && d[9] != 6)) throw std::runtime_error(path + ": unsupported PNG");
      channels = d[9] == 2 ? 3 : 4;
    } else if (type == "IDAT") {
      idat.insert(idat.end(), d, d + len);
    }
    i += 12 + len;
  }
  const std::size_t stride = std::size_t(im.width) * channels;
  std::vector<unsigned char> raw((stride + 1) * im.height);
  uLongf n = raw.size();
  if (uncompress(raw.data(), &n, idat.data(), idat.size()) != Z_OK || n != raw.size())
    throw std::runtime_error(path + ": bad image data");
  std::vector<unsigned char> cur(stride), prev(stride, 0);
  im.rgb.resize(std::size_t(im.width) * im.height * 3);
  for (int y = 0; y < im.height; ++y) {
    const unsigned char filter = raw[y * (stride + 1)];
    const unsigned char* r = &raw[y * (stride + 1) + 1];
    for (std::size_t x = 0; x < stride; ++x) {
      const int a = x >= std::size_t(channels) ? cur[x - channels] : 0, b = prev[x],
                c = x >= std::size_t(channels) ? prev[x - channels] : 0;
      int v = r[x];
      switch (filter) {
        case 1: v += a; break;
        case 2: v += b; break;
        case 3: v += (a + b) / 2; break;
        case 4: {
          const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
          v += (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
          break;
        }
        default: break;
      }
      cur[x] = static_cast<unsigned char>(v);
    }
    for (int x = 0; x < im.width; ++x)
      for (int k = 0; k < 3; ++k) im.rgb[3 * (std::size_t(y) * im.width + x) + k] = cur[std::size_t(x) * channels + k];
    prev.swap(cur);
  }
  return im;
}

/// Line-colour pixels of each cell of a rows x cols grid below a title band.
inline std::vector<int> panelCounts(const Image& im, int rows, int cols, int titleBand = 50) {
  std::vector<int> n;
  const int h = (im.height - titleBand) / rows, w = im.width / cols;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) n.push_back(im.count(c * w, titleBand + r * h, (c + 1) * w, titleBand + (r + 1) * h));
  return n;
}

}  // namespace vdyn::test
