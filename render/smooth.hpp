// Display-only smoothing of a cell field: bilinear interpolation between cell centres inside the
// material, on a finer image, so shear bands read as bands rather than staircases. Cells without
// material stay empty (NaN), so the free surface keeps its cell outline instead of blurring into
// the air. The stored data is not touched.
#pragma once
#include <vector>

namespace furrow::render {

// `values`: nx*ny cell values, row-major (i fastest), NaN where there is no material. Returns
// (nx*factor) x (ny*factor) values: a fine pixel is NaN when its cell is; otherwise the bilinear
// blend of the (up to) four nearest cell centres, weights renormalized over those with material.
// With `log`, blends log10 of the values (strain rate is drawn on a log scale; values must be > 0).
// factor 1 returns the input. Throws std::invalid_argument for a size mismatch or factor < 1.
std::vector<float> upsample_within_material(const std::vector<float>& values, int nx, int ny, int factor, bool log);

}  // namespace furrow::render
