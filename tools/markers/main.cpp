// crease-markers: writes the printable marker sheet (sheet.pdf at true scale, sheet.png,
// sheet_back.png for double-sided layouts) and layout.yaml.
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>

#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>

#include "plugins/camera_rig/marker_layout.h"
#include "plugins/camera_rig/marker_sheet.h"

int main(int argc, char** argv) {
  CLI::App app{"crease-markers: printable AprilTag sheet and its layout"};
  std::string out_dir, grid = "5x7";
  crease::vision::LayoutSpec spec;
  double dpi = 300;
  app.add_option("--out", out_dir, "output directory")->required();
  app.add_option("--paper", spec.paper, "paper size: a4, a3, a5, letter")->capture_default_str();
  app.add_option("--dictionary", spec.dictionary, "tag family")->capture_default_str();
  app.add_option("--marker-mm", spec.marker_mm, "tag side incl. black border, mm")->capture_default_str();
  app.add_option("--grid", grid, "markers per face, COLSxROWS")->capture_default_str();
  app.add_flag("--double-sided", spec.double_sided, "distinct tags on the back face");
  app.add_option("--dpi", dpi, "resolution of sheet.png")->capture_default_str()->check(CLI::Range(50.0, 1200.0));
  CLI11_PARSE(app, argc, argv);

  std::smatch m;
  if (!std::regex_match(grid, m, std::regex(R"((\d+)x(\d+))"))) {
    std::fprintf(stderr, "crease-markers: --grid '%s': expected COLSxROWS, e.g. 5x7\n", grid.c_str());
    return 2;
  }
  spec.cols = std::stoi(m[1]);
  spec.rows = std::stoi(m[2]);
  try {
    namespace cv_ = crease::vision;
    std::filesystem::create_directories(out_dir);
    const auto layout = cv_::make_layout(spec);
    const double ppm = dpi / 25.4;
    const std::string base = out_dir + "/";
    cv_::save_layout(layout, base + "layout.yaml");
    cv_::write_sheet_pdf(layout, base + "sheet.pdf");
    if (!cv::imwrite(base + "sheet.png", cv_::render_page(layout, cv_::Face::kFront, ppm)))
      throw std::runtime_error(base + "sheet.png: write failed");
    if (spec.double_sided &&
        !cv::imwrite(base + "sheet_back.png", cv_::render_page(layout, cv_::Face::kBack, ppm)))
      throw std::runtime_error(base + "sheet_back.png: write failed");
    std::printf("crease-markers: %zu markers (%s, %.1f mm) on %s -> %s\n", layout.markers.size(),
                spec.dictionary.c_str(), spec.marker_mm, spec.paper.c_str(), out_dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crease-markers: %s\n", e.what());
    return 1;
  }
  return 0;
}
