#include "plugins/camera_rig/marker_sheet.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/assert.h"

namespace crease::vision {

namespace {

// Cell grid (including the black border) of a tag, 1 = black.
cv::Mat tag_cells(const cv::aruco::Dictionary& dict, int id) {
  const int n = dict.markerSize;
  cv::Mat bits = cv::aruco::Dictionary::getBitsFromByteList(dict.bytesList.rowRange(id, id + 1), n);
  cv::Mat cells(n + 2, n + 2, CV_8U, cv::Scalar(1));
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) cells.at<uchar>(r + 1, c + 1) = bits.at<uchar>(r, c) ? 0 : 1;
  return cells;
}

// Page-frame placement of a marker on its own face (back: un-mirror to page coordinates).
cv::Point2d page_top_left(const MarkerLayout& L, const MarkerPlacement& m) {
  const double h = L.marker_mm / 2;
  const double cu = m.face == Face::kFront ? m.centre_mm.x : L.sheet_w_mm - m.centre_mm.x;
  return {cu - h, m.centre_mm.y - h};
}

double overlap(double a0, double a1, double b0, double b1) {
  return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

}  // namespace

cv::Mat render_page(const MarkerLayout& L, Face face, double ppm) {
  crease::require_input(ppm > 0, "render_page: px_per_mm must be positive");  // crease-markers --dpi
  const auto dict = dictionary_by_name(L.dictionary);
  const int W = static_cast<int>(std::lround(L.sheet_w_mm * ppm));
  const int H = static_cast<int>(std::lround(L.sheet_h_mm * ppm));
  cv::Mat page(H, W, CV_32F, cv::Scalar(0.0f));  // black coverage fraction
  const int nc = dict->markerSize + 2;
  const double cell = L.marker_mm / nc;
  for (const auto& m : L.markers) {
    if (m.face != face) continue;
    const cv::Mat cells = tag_cells(*dict, m.id);
    const cv::Point2d tl = page_top_left(L, m);
    // Exact area coverage: pixel [x, x+1) x [y, y+1) against each black cell.
    for (int r = 0; r < nc; ++r) {
      for (int c = 0; c < nc; ++c) {
        if (!cells.at<uchar>(r, c)) continue;
        const double u0 = (tl.x + c * cell) * ppm, u1 = u0 + cell * ppm;
        const double v0 = (tl.y + r * cell) * ppm, v1 = v0 + cell * ppm;
        const int x0 = std::max(0, static_cast<int>(std::floor(u0)));
        const int x1 = std::min(W - 1, static_cast<int>(std::ceil(u1)));
        const int y0 = std::max(0, static_cast<int>(std::floor(v0)));
        const int y1 = std::min(H - 1, static_cast<int>(std::ceil(v1)));
        for (int y = y0; y <= y1; ++y) {
          const double oy = overlap(y, y + 1, v0, v1);
          if (oy <= 0) continue;
          float* row = page.ptr<float>(y);
          for (int x = x0; x <= x1; ++x) row[x] += static_cast<float>(oy * overlap(x, x + 1, u0, u1));
        }
      }
    }
  }
  cv::Mat out;
  page.convertTo(out, CV_8U, -255.0, 255.0);  // saturates coverage > 1
  return out;
}

cv::Mat face_texture(const MarkerLayout& L, Face face, double ppm) {
  cv::Mat page = render_page(L, face, ppm);
  if (face == Face::kBack) cv::flip(page, page, 1);
  return page;
}

void write_sheet_pdf(const MarkerLayout& L, const std::string& path) {
  const auto dict = dictionary_by_name(L.dictionary);
  const double pt = 72.0 / 25.4;  // PDF points per mm
  const double pw = L.sheet_w_mm * pt, ph = L.sheet_h_mm * pt;
  const int nc = dict->markerSize + 2;
  const double cell = L.marker_mm / nc;
  std::vector<Face> faces = {Face::kFront};
  for (const auto& m : L.markers)
    if (m.face == Face::kBack) {
      faces.push_back(Face::kBack);
      break;
    }

  // Content streams: PDF y runs up from the bottom-left; sheet v runs down from the top.
  std::vector<std::string> contents;
  for (Face face : faces) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(4);
    s << "0 g\n";
    for (const auto& m : L.markers) {
      if (m.face != face) continue;
      const cv::Mat cells = tag_cells(*dict, m.id);
      const cv::Point2d tl = page_top_left(L, m);
      for (int r = 0; r < nc; ++r) {
        for (int c = 0; c < nc;) {
          if (!cells.at<uchar>(r, c)) {
            ++c;
            continue;
          }
          int e = c;
          while (e < nc && cells.at<uchar>(r, e)) ++e;
          const double x = (tl.x + c * cell) * pt;
          const double y = ph - (tl.y + (r + 1) * cell) * pt;
          s << x << ' ' << y << ' ' << (e - c) * cell * pt << ' ' << cell * pt << " re\n";
          c = e;
        }
      }
    }
    s << "f\n";
    contents.push_back(s.str());
  }

  // Objects: 1 catalog, 2 pages, then per page: page object, content stream.
  std::vector<std::string> objs;
  objs.push_back("<< /Type /Catalog /Pages 2 0 R >>");
  std::ostringstream kids;
  for (std::size_t i = 0; i < faces.size(); ++i) kids << (3 + 2 * i) << " 0 R ";
  objs.push_back("<< /Type /Pages /Kids [ " + kids.str() + "] /Count " +
                 std::to_string(faces.size()) + " >>");
  char box[128];
  std::snprintf(box, sizeof box, "[0 0 %.4f %.4f]", pw, ph);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    objs.push_back(std::string("<< /Type /Page /Parent 2 0 R /MediaBox ") + box +
                   " /Resources << >> /Contents " + std::to_string(4 + 2 * i) + " 0 R >>");
    objs.push_back("<< /Length " + std::to_string(contents[i].size()) + " >>\nstream\n" +
                   contents[i] + "endstream");
  }
  std::string pdf = "%PDF-1.4\n%\xE2\xE3\xCF\xD3\n";
  std::vector<std::size_t> offsets;
  for (std::size_t i = 0; i < objs.size(); ++i) {
    offsets.push_back(pdf.size());
    pdf += std::to_string(i + 1) + " 0 obj\n" + objs[i] + "\nendobj\n";
  }
  const std::size_t xref = pdf.size();
  pdf += "xref\n0 " + std::to_string(objs.size() + 1) + "\n0000000000 65535 f \n";
  for (std::size_t off : offsets) {
    char line[32];
    std::snprintf(line, sizeof line, "%010zu 00000 n \n", off);
    pdf += line;
  }
  pdf += "trailer\n<< /Size " + std::to_string(objs.size() + 1) + " /Root 1 0 R >>\nstartxref\n" +
         std::to_string(xref) + "\n%%EOF\n";
  std::ofstream f(path, std::ios::binary);
  if (!f) throw crease::Error(path + ": cannot open for writing");
  f.write(pdf.data(), static_cast<std::streamsize>(pdf.size()));
  if (!f) throw crease::Error(path + ": write failed");
}

}  // namespace crease::vision
