#include "harness/render/image_grid.h"

#include <algorithm>
#include <stdexcept>

#include "harness/render/image_io.h"
#include "harness/render/label_font.h"

#if SDF_HAVE_OIIO
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#endif

namespace sdf {
namespace {

int label_band(const GridStyle& s) { return (s.font_size * 8 + 4) / 5; }
int title_band(const GridStyle& s) { return s.title.empty() ? 0 : (s.title_size * 8 + 4) / 5; }

#if SDF_HAVE_OIIO
/// The largest size <= `size` (down to 6) at which `text` is at most `width` pixels wide.
int fitting_size(const std::string& text, int size, int width, const std::string& font) {
    for (; size > 6; --size) {
        const OIIO::ROI r = OIIO::ImageBufAlgo::text_size(text, size, font);
        if (r.defined() && r.width() <= width) break;
    }
    return size;
}

/// Draws `text` centred at (cx, baseline y) on the grid, black.
void draw_text(OIIO::ImageBuf& buf, int cx, int y, const std::string& text, int size, const std::string& font) {
    const float black[3] = {0.0f, 0.0f, 0.0f};
    if (!OIIO::ImageBufAlgo::render_text(buf, cx, y, text, size, font, black, OIIO::ImageBufAlgo::TextAlignX::Center,
                                          OIIO::ImageBufAlgo::TextAlignY::Baseline))
        throw std::runtime_error("image grid: cannot render label '" + text + "' with font " + font + ": " +
                                 buf.geterror());
}
#endif

}  // namespace

GridLayout layout_grid(const std::vector<GridRow>& rows, const GridStyle& style) {
    GridLayout g;
    const int pad = style.padding, band = label_band(style);
    // Cells are as wide as the widest image of their row; the grid as wide as its widest row
    std::vector<int> cell_w(rows.size(), 0);
    for (size_t r = 0; r < rows.size(); ++r) {
        for (const GridCell& c : rows[r]) cell_w[r] = std::max(cell_w[r], c.image.width);
        g.width = std::max(g.width, int(rows[r].size()) * cell_w[r] + int(rows[r].size() + 1) * pad);
    }
    if (g.width == 0) throw std::invalid_argument("image grid: no images");
    g.title_height = title_band(style);
    int y = pad + g.title_height;
    for (size_t r = 0; r < rows.size(); ++r) {
        int row_h = 0;
        for (const GridCell& c : rows[r]) row_h = std::max(row_h, c.image.height);
        const int row_w = int(rows[r].size()) * cell_w[r] + int(rows[r].size() + 1) * pad;
        const int x0 = (g.width - row_w) / 2;  // centred row
        std::vector<GridCellPlacement> placed;
        for (size_t i = 0; i < rows[r].size(); ++i) {
            GridCellPlacement p;
            const int cx = x0 + pad + int(i) * (cell_w[r] + pad);
            p.width = rows[r][i].image.width;
            p.height = rows[r][i].image.height;
            p.x = cx + (cell_w[r] - p.width) / 2;
            p.y = y + (row_h - p.height) / 2;
            p.label_x = cx;
            p.label_y = y + row_h;
            p.label_width = cell_w[r];
            p.label_height = band;
            placed.push_back(p);
        }
        g.cells.push_back(placed);
        y += row_h + band + pad;
    }
    g.height = y;
    return g;
}

ImageRgb make_image_grid(const std::vector<GridRow>& rows, const GridStyle& style) {
    const GridLayout g = layout_grid(rows, style);
    ImageRgb canvas(g.width, g.height, style.background);
    for (size_t r = 0; r < rows.size(); ++r)
        for (size_t c = 0; c < rows[r].size(); ++c) blit(canvas, rows[r][c].image, g.cells[r][c].x, g.cells[r][c].y);
#if SDF_HAVE_OIIO
    const std::string font = find_label_font();
    OIIO::ImageBuf buf(OIIO::ImageSpec(canvas.width, canvas.height, 3, OIIO::TypeDesc::FLOAT), canvas.data.data());
    if (!style.title.empty())
        draw_text(buf, g.width / 2, style.padding + (g.title_height + style.title_size) / 2 - style.title_size / 5,
                  style.title, fitting_size(style.title, style.title_size, g.width - 2 * style.padding, font), font);
    for (size_t r = 0; r < rows.size(); ++r) {
        // One size per row: the largest <= font_size at which every label fits its cell
        int size = style.font_size;
        for (size_t c = 0; c < rows[r].size(); ++c)
            if (!rows[r][c].label.empty())
                size = std::min(size, fitting_size(rows[r][c].label, style.font_size, g.cells[r][c].label_width - 4, font));
        for (size_t c = 0; c < rows[r].size(); ++c) {
            const GridCellPlacement& p = g.cells[r][c];
            const GridCell& cell = rows[r][c];
            const int tick_size = std::min(style.font_size, cell.tick_band * 4 / 5);
            for (const GridTick& t : cell.ticks)
                draw_text(buf, p.x + int(t.at * (p.width - 1) + 0.5), p.y + p.height - cell.tick_band / 5, t.text,
                          tick_size, font);
            if (rows[r][c].label.empty()) continue;
            draw_text(buf, p.label_x + p.label_width / 2, p.label_y + (p.label_height + size) / 2 - 2, rows[r][c].label,
                      size, font);
        }
    }
#endif
    return canvas;
}

std::string label_grid_text(const std::vector<GridRow>& rows, const GridStyle& style) {
    std::string text = style.title.empty() ? "" : "title: " + style.title + "\n";
    for (size_t r = 0; r < rows.size(); ++r)
        for (size_t c = 0; c < rows[r].size(); ++c)
            text += "row " + std::to_string(r + 1) + ", column " + std::to_string(c + 1) + ": " + rows[r][c].label + "\n";
    return text;
}

}  // namespace sdf
