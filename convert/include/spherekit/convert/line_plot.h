// Line charts rendered to an 8-bit RGB image (for PNG files): the reconstruction-error and
// compression plots of `spherekit pca`. Axes with "nice" ticks (1, 2, 5 x 10^k; decades on a
// log axis), one polyline with markers per series, a legend, a title and axis labels in stb's
// easy_font (a vector font of axis-aligned quads, so no font files are needed). Non-finite
// points are skipped (a series breaks there). Deterministic pixels.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "spherekit/convert/png_image.h"
#include "spherekit/status.h"

namespace spherekit::convert {

struct PlotSeries {
  std::string label;                       ///< legend text (empty: not in the legend)
  std::vector<double> x, y;                ///< same length
  std::array<std::uint8_t, 3> color{31, 119, 180};
  int line_width = 2;                      ///< pixels (>= 1)
  bool markers = true;                     ///< a small square on every point
};

struct LinePlot {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  bool log_x = false;        ///< logarithmic x axis (x values must be > 0; others are skipped)
  bool y_from_zero = false;  ///< the y range includes 0
  int width = 800, height = 500;  ///< pixels, at least 200 x 150
};

/// Renders the plot. Errors: InvalidArgument (image smaller than 200 x 150 or larger than
/// 8192, a series whose x and y differ in length, no finite point at all).
[[nodiscard]] Result<Image8> render_line_plot(const LinePlot& plot);

}  // namespace spherekit::convert
