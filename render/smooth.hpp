// Display-only smoothing of a cell field: bilinear interpolation between cell centres inside the
// material, on a finer image, so a field reads as a field rather than a mosaic of cells. The
// material's edge is where the bilinear blend of the material indicator (1 in cells with material)
// crosses one half: it follows the cells' outline within half a cell, without the staircase, and
// never blurs colour into the air. The stored data is not touched.
#pragma once
#include <vector>

namespace furrow::render {

// `values`: nx*ny cell values, row-major (i fastest), NaN where there is no material. Returns
// (nx*factor) x (ny*factor) values: a fine pixel is NaN where the bilinear weights of the four
// nearest cell centres with material sum below one half; otherwise the blend of those centres,
// weights renormalized over them.
// With `log`, blends log10 of the values (strain rate is drawn on a log scale; values must be > 0).
// factor 1 returns the input. Throws std::invalid_argument for a size mismatch or factor < 1.
std::vector<float> upsample_within_material(const std::vector<float>& values, int nx, int ny, int factor, bool log);

}  // namespace furrow::render
