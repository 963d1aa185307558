/// @file image_grid.h
/// @brief Labelled image grids like the thesis's Figures 5-2 to 5-11: rows of images, each
/// row centred, each image with a text label in a band below it, an optional title band on
/// top (docs/raycast.md, "Grids").
///
/// Layout: the cells of a row are as wide as its widest image and the row as tall as its
/// tallest image plus the label band; the grid is as wide as its widest row; `padding`
/// pixels separate cells, rows and the border. Labels are drawn with OpenImageIO's
/// render_text in the font of label_font.h (black on the background), centred, in one size
/// per row: font_size, or smaller so that every label of the row fits its cell. Without OpenImageIO the grid keeps its layout but labels and title are not
/// drawn (label_grid_text() lists them for a sidecar file instead).
#pragma once

#include <string>
#include <vector>

#include "harness/render/image_buffer.h"

namespace sdf {

/// A value written under a colour bar: `at` in [0, 1] along the image's width.
struct GridTick {
    double at = 0;
    std::string text;
};

struct GridCell {
    ImageRgb image;
    std::string label;
    /// Tick values drawn centred under their marks in the bottom `tick_band` pixels of the
    /// image (a colour bar's, heat_map.h: colour_bar_with_ticks leaves that band white).
    std::vector<GridTick> ticks = {};
    int tick_band = 0;
};

using GridRow = std::vector<GridCell>;

struct GridStyle {
    std::string title;
    int padding = 12;
    int font_size = 20;   ///< label text height in pixels (the band is 1.6x as tall)
    int title_size = 26;
    float background = 1.0f;  ///< grey level of the canvas
};

/// Pixel rectangle of a cell's image and of its label band in the grid.
struct GridCellPlacement {
    int x = 0, y = 0, width = 0, height = 0;      ///< the image
    int label_x = 0, label_y = 0, label_width = 0, label_height = 0;
};

struct GridLayout {
    int width = 0, height = 0;
    int title_height = 0;
    std::vector<std::vector<GridCellPlacement>> cells;  ///< [row][column]
};

/// Where everything goes (no drawing): used by make_image_grid and by tests.
GridLayout layout_grid(const std::vector<GridRow>& rows, const GridStyle& style);

/// Draws the grid. With OpenImageIO, labels and the title are rendered (a missing font
/// throws, see find_label_font); without it they are left out.
ImageRgb make_image_grid(const std::vector<GridRow>& rows, const GridStyle& style);

/// The title and labels as text, one per line ("row r, column c: label"), for a sidecar.
std::string label_grid_text(const std::vector<GridRow>& rows, const GridStyle& style);

}  // namespace sdf
