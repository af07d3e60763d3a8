// Printable marker sheet: raster pages (PNG, renderer textures) and a vector PDF.
#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "plugins/camera_rig/marker_layout.h"

namespace crease::vision {

// The page of one face as printed (the back page as seen from the back), 8-bit grey,
// white paper, black cells, at px_per_mm. Cell edges are area-antialiased, so pixel (x, y)
// covers sheet [x, x+1) / px_per_mm: its centre is at ((x + 0.5) / px_per_mm).
cv::Mat render_page(const MarkerLayout& layout, Face face, double px_per_mm);

// Texture of one face in FRONT sheet coordinates (renderer input): the front page itself,
// or the back page mirrored in u so that texel (x, y) is the physical point behind front (x, y).
cv::Mat face_texture(const MarkerLayout& layout, Face face, double px_per_mm);

// Writes a vector PDF (one page per face, true scale at 100 %): each run of black cells is a
// filled rectangle. Throws crease::Error naming the file on a write error.
void write_sheet_pdf(const MarkerLayout& layout, const std::string& path);

}  // namespace crease::vision
