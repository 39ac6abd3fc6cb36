// A minimal line-chart rasterizer (see line_plot.h). Text comes from stb_easy_font, which
// emits axis-aligned quads for each glyph; they are filled as rectangles, scaled by an
// integer factor. Lines are drawn with a square brush stepped along the segment.
#include "spherekit/convert/line_plot.h"

#include <stb/stb_easy_font.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace spherekit::convert {
namespace {

using Color = std::array<std::uint8_t, 3>;

class Canvas {
 public:
  explicit Canvas(Image8& image) : image_(image) {}

  void fill_rect(int x0, int y0, int x1, int y1, const Color& c) {  // [x0, x1) x [y0, y1)
    x0 = std::max(x0, 0);
    y0 = std::max(y0, 0);
    x1 = std::min(x1, image_.width);
    y1 = std::min(y1, image_.height);
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) std::copy(c.begin(), c.end(), image_.at(x, y));
  }

  void line(double x0, double y0, double x1, double y1, int width, const Color& c) {
    const double len = std::hypot(x1 - x0, y1 - y0);
    const int steps = std::max(1, static_cast<int>(std::ceil(len * 2)));  // half-pixel steps: no gaps
    const int lo = -(width - 1) / 2, hi = width / 2 + 1;
    for (int s = 0; s <= steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      const int x = static_cast<int>(std::lround(x0 + t * (x1 - x0))), y = static_cast<int>(std::lround(y0 + t * (y1 - y0)));
      fill_rect(x + lo, y + lo, x + hi, y + hi, c);
    }
  }

  /// Text with its top-left corner at (x, y), glyph pixels `scale` x `scale`.
  void text(int x, int y, const std::string& s, int scale, const Color& c) {
    std::vector<char> buffer(s.size() * 300 + 1000);  // easy_font needs ~270 bytes a character
    std::string copy = s;
    const int quads = stb_easy_font_print(0, 0, copy.data(), nullptr, buffer.data(), static_cast<int>(buffer.size()));
    for (int q = 0; q < quads; ++q) {
      const float* v0 = reinterpret_cast<const float*>(buffer.data() + (4 * q) * 16);
      const float* v2 = reinterpret_cast<const float*>(buffer.data() + (4 * q + 2) * 16);
      fill_rect(x + static_cast<int>(std::lround(v0[0] * scale)), y + static_cast<int>(std::lround(v0[1] * scale)),
                x + static_cast<int>(std::lround(v2[0] * scale)), y + static_cast<int>(std::lround(v2[1] * scale)), c);
    }
  }

  static int text_width(const std::string& s, int scale) {
    std::string copy = s;
    return stb_easy_font_width(copy.data()) * scale;
  }

 private:
  Image8& image_;
};

/// Tick values: multiples of 1, 2 or 5 x 10^k covering [lo, hi] with about 4..10 ticks.
std::vector<double> nice_ticks(double lo, double hi) {
  const double span = hi - lo;
  const double raw = span / 6;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (span / step <= 8) break;
  }
  std::vector<double> out;
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + step * 1e-9; t += step) out.push_back(std::abs(t) < step * 1e-9 ? 0 : t);
  return out;
}

std::string tick_label(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

Result<Image8> render_line_plot(const LinePlot& plot) {
  if (plot.width < 200 || plot.height < 150 || plot.width > 8192 || plot.height > 8192)
    return Status(ErrorCode::InvalidArgument, "plot size " + std::to_string(plot.width) + " x " +
                                                  std::to_string(plot.height) + " outside 200 x 150 .. 8192 x 8192");
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  auto usable = [&](double x, double y) { return std::isfinite(x) && std::isfinite(y) && (!plot.log_x || x > 0); };
  for (const PlotSeries& s : plot.series) {
    if (s.x.size() != s.y.size())
      return Status(ErrorCode::InvalidArgument, "plot series '" + s.label + "': x and y differ in length");
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!usable(s.x[i], s.y[i])) continue;
      const double x = plot.log_x ? std::log10(s.x[i]) : s.x[i];
      xmin = std::min(xmin, x);
      xmax = std::max(xmax, x);
      ymin = std::min(ymin, s.y[i]);
      ymax = std::max(ymax, s.y[i]);
    }
  }
  if (!(xmin <= xmax)) return Status(ErrorCode::InvalidArgument, "plot has no finite point");
  if (plot.y_from_zero) {
    ymin = std::min(ymin, 0.0);
    ymax = std::max(ymax, 0.0);
  }
  // Degenerate ranges get a unit (or 10 %) extent; a 5 % margin keeps markers off the frame.
  if (xmax - xmin <= 0) { xmin -= 0.5; xmax += 0.5; }
  if (ymax - ymin <= 0) { const double d = ymax != 0 ? 0.1 * std::abs(ymax) : 1; ymin -= d; ymax += d; }
  const double ypad = 0.05 * (ymax - ymin), xpad = 0.03 * (xmax - xmin);
  if (!(plot.y_from_zero && ymin == 0)) ymin -= ypad;
  ymax += ypad;
  xmin -= xpad;
  xmax += xpad;

  Image8 image = Image8::filled(plot.width, plot.height, {255, 255, 255});
  Canvas c(image);
  const Color black{0, 0, 0}, grid{225, 225, 225}, grey{90, 90, 90};
  const int left = 80, right = plot.width - 20, top = 50, bottom = plot.height - 60;
  auto px = [&](double x) { return left + (x - xmin) / (xmax - xmin) * (right - left); };
  auto py = [&](double y) { return bottom - (y - ymin) / (ymax - ymin) * (bottom - top); };

  // Grid and ticks.
  std::vector<double> xt;
  if (plot.log_x) {
    for (double e = std::floor(xmin); e <= std::ceil(xmax); e += 1)
      for (double m : {1.0, 2.0, 5.0})
        if (const double v = e + std::log10(m); v >= xmin && v <= xmax) xt.push_back(v);
  } else {
    xt = nice_ticks(xmin, xmax);
  }
  for (double t : xt) {
    const int x = static_cast<int>(std::lround(px(t)));
    c.line(x, top, x, bottom, 1, grid);
    const std::string label = tick_label(plot.log_x ? std::pow(10.0, t) : t);
    c.text(x - Canvas::text_width(label, 1) / 2, bottom + 6, label, 1, grey);
  }
  for (double t : nice_ticks(ymin, ymax)) {
    const int y = static_cast<int>(std::lround(py(t)));
    c.line(left, y, right, y, 1, grid);
    const std::string label = tick_label(t);
    c.text(left - 6 - Canvas::text_width(label, 1), y - 3, label, 1, grey);
  }
  c.line(left, top, left, bottom, 1, black);
  c.line(left, bottom, right, bottom, 1, black);
  c.text(left, 12, plot.title, 2, black);
  c.text(left, top - 14, plot.y_label, 1, black);
  c.text((left + right) / 2 - Canvas::text_width(plot.x_label, 1) / 2, bottom + 26, plot.x_label, 1, black);

  // Series, then the legend on top.
  for (const PlotSeries& s : plot.series) {
    bool have_prev = false;
    double prev_x = 0, prev_y = 0;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!usable(s.x[i], s.y[i])) {
        have_prev = false;
        continue;
      }
      const double x = px(plot.log_x ? std::log10(s.x[i]) : s.x[i]), y = py(s.y[i]);
      if (have_prev) c.line(prev_x, prev_y, x, y, std::max(1, s.line_width), s.color);
      if (s.markers) {
        const int mx = static_cast<int>(std::lround(x)), my = static_cast<int>(std::lround(y));
        c.fill_rect(mx - 3, my - 3, mx + 4, my + 4, s.color);
      }
      have_prev = true;
      prev_x = x;
      prev_y = y;
    }
  }
  int row = top + 8;
  for (const PlotSeries& s : plot.series) {
    if (s.label.empty()) continue;
    const int w = Canvas::text_width(s.label, 1);
    c.fill_rect(right - w - 40, row - 2, right - 4, row + 10, {255, 255, 255});
    c.line(right - w - 34, row + 4, right - w - 16, row + 4, std::max(1, s.line_width), s.color);
    c.text(right - w - 10, row, s.label, 1, black);
    row += 14;
  }
  return image;
}

}  // namespace spherekit::convert
