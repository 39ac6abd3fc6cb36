// One UV atlas for the quads of a Catmull–Clark cage, so that a displacement map over the cage
// is an ordinary texture that DCC tools and renderers apply through the cage's texture
// coordinates (issue 22; the per-face sample grid is Lee, Moreton & Hoppe 2000's, laid out as
// one image instead of per-face Ptex tiles, which few tools read).
//
// Layout. Quad f owns a square block of P = T + 2g texels (T samples per edge, g gutter texels
// on each side), block column f mod C, block row f div C counted from the image's BOTTOM
// (UV v = 0), C = ceil(sqrt(faces)) columns, R = ceil(faces / C) rows: an image of C·P x R·P
// texels. Sample (r, c) of quad f, i.e. limit-surface parameter (u, v) = (c/(T-1), r/(T-1)),
// is the texel at x = col·P + g + c, y = row·P + g + r (y from the bottom).
//
// Texel-centre convention. Texel (x, y) covers [x, x+1] x [y, y+1] and its value is the one at
// its centre, UV ((x + 0.5)/W, (y + 0.5)/H), with UV (0, 0) the image's bottom-left corner (the
// OBJ / Blender / RenderMan "st flipped" convention; in the EXR file, whose first scanline is
// the top, y = H - 1 - scanline). The cage's corner UVs are the centres of the tile's corner
// texels, so the quad's UVs span exactly its samples and a bilinear lookup at parameter (u, v)
// touches only the quad's own texels: at every subdivided vertex of a level-L Catmull–Clark
// refinement with T = 2^L + 1 it returns a stored sample exactly.
//
// Gutters. Filters wider than one texel (mipmaps, renderer filter widths) reach into the g
// texels around a tile; they hold the tile's values extrapolated linearly across its border
// (separably, so a gutter corner is the bilinear extrapolation of the corner cell), which
// continues the displacement to first order into the neighbouring quad instead of dropping to
// a constant or to another quad's unrelated values.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "spherekit/status.h"

namespace spherekit::convert {

struct CageUvAtlas {
  int faces = 0;    ///< cage quads
  int tile = 0;     ///< T: samples per quad edge (>= 2)
  int gutter = 0;   ///< g: padding texels on each side of a tile
  int columns = 0;  ///< C
  int rows = 0;     ///< R

  int pitch() const { return tile + 2 * gutter; }
  int width() const { return columns * pitch(); }
  int height() const { return rows * pitch(); }
  /// Texel column x of sample column c (may be -gutter .. tile-1+gutter) of quad f.
  int texel_x(int f, int c) const { return (f % columns) * pitch() + gutter + c; }
  /// Texel row y, counted from the image's bottom, of sample row r of quad f.
  int texel_y(int f, int r) const { return (f / columns) * pitch() + gutter + r; }
  /// UV (origin bottom-left) of the limit-surface parameter (u, v) in [0,1]^2 of quad f: the
  /// bilinear map of the quad onto its tile's sample centres.
  Eigen::Vector2d uv(int f, double u, double v) const;
};

/// The atlas for `faces` quads with T x T samples and g gutter texels.
/// Errors: InvalidArgument (faces < 1, tile < 2, gutter < 0 or > 64, image wider than 65536).
[[nodiscard]] Result<CageUvAtlas> cage_uv_atlas(int faces, int tile, int gutter);

/// The atlas image of per-quad sample tiles `values` (value of channel ch of sample (r, c) of
/// quad f at ((f * T + r) * T + c) * channels + ch, as DisplacementMap stores them), gutters
/// filled by linear extrapolation, texels of unused blocks 0. Scanline order top to bottom
/// (as EXR stores it): texel (x, y-from-bottom) at ((H - 1 - y) * W + x) * channels.
std::vector<float> cage_atlas_image(const CageUvAtlas& atlas, const std::vector<float>& values, int channels);

/// The samples of each quad read back from an atlas image (the inverse of cage_atlas_image on
/// the samples; gutters are ignored).
std::vector<float> cage_atlas_samples(const CageUvAtlas& atlas, const std::vector<float>& image, int channels);

}  // namespace spherekit::convert
