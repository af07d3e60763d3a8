// crease-calibrate: camera calibration files (OpenCV FileStorage YAML, see
// plugins/camera_rig/camera_model.h).
//   crease-calibrate board --out board.png [--dpi 300]          printable ChArUco board
//   crease-calibrate intrinsics --out camK.yaml IMAGE...           intrinsics from board views
//   crease-calibrate extrinsics --out DIR --intrinsics cam0.yaml... --images img0.png...
//                     one image per camera of the board lying on the table: world = board
//   crease-calibrate rig --out DIR                                 the seed-000 synthetic rig
// Board options for all: --squares CxR (7x5) --square-mm 30 --marker-mm 22 --dictionary 4x4_50
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>

#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>

#include "plugins/camera_rig/calibration.h"
#include "plugins/camera_rig/camera_model.h"

namespace cv_ = crease::vision;

namespace {
cv::Mat read_gray(const std::string& path) {
  cv::Mat m = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (m.empty()) throw std::runtime_error(path + ": cannot read image");
  return m;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crease-calibrate: camera intrinsics and extrinsics (ChArUco)"};
  app.require_subcommand(1);
  cv_::CharucoSpec spec;
  std::string squares = "7x5";
  auto board_opts = [&](CLI::App* c) {
    c->add_option("--squares", squares, "board squares COLSxROWS")->capture_default_str();
    c->add_option("--square-mm", spec.square_mm, "square side, mm")->capture_default_str();
    c->add_option("--marker-mm", spec.marker_mm, "marker side, mm")->capture_default_str();
    c->add_option("--dictionary", spec.dictionary, "ArUco dictionary of the board")->capture_default_str();
  };
  std::string out;
  double dpi = 300;
  auto* board = app.add_subcommand("board", "write a printable ChArUco board image");
  board_opts(board);
  board->add_option("--out", out, "output PNG")->required();
  board->add_option("--dpi", dpi, "resolution")->capture_default_str();

  std::vector<std::string> images, intrinsics;
  int dist_count = 5;
  auto* intr = app.add_subcommand("intrinsics", "calibrate one camera from images of the board");
  board_opts(intr);
  intr->add_option("--out", out, "calibration file to write")->required();
  intr->add_option("--distortion", dist_count, "4, 5 or 8 coefficients")->capture_default_str();
  intr->add_option("images", images, "board images")->required();

  auto* extr = app.add_subcommand("extrinsics", "pose of every camera from one shared view of the board");
  board_opts(extr);
  extr->add_option("--out", out, "output directory for cam0.yaml, cam1.yaml, ...")->required();
  extr->add_option("--intrinsics", intrinsics, "calibration file per camera")->required();
  extr->add_option("--images", images, "one board image per camera, same order")->required();

  auto* rig = app.add_subcommand("rig", "write the default five-camera rig (seed 000) as cam0..cam4.yaml");
  rig->add_option("--out", out, "output directory")->required();
  CLI11_PARSE(app, argc, argv);

  try {
    std::smatch m;
    if (!std::regex_match(squares, m, std::regex(R"((\d+)x(\d+))")))
      throw std::invalid_argument("--squares '" + squares + "': expected COLSxROWS");
    spec.squares_x = std::stoi(m[1]);
    spec.squares_y = std::stoi(m[2]);
    if (*board) {
      if (!cv::imwrite(out, cv_::draw_charuco(spec, dpi / 25.4, static_cast<int>(dpi / 25.4 * spec.square_mm / 2))))
        throw std::runtime_error(out + ": write failed");
      std::printf("crease-calibrate: board %dx%d, %.1f mm squares -> %s (print at 100 %%)\n", spec.squares_x,
                  spec.squares_y, spec.square_mm, out.c_str());
    } else if (*intr) {
      std::vector<cv::Mat> imgs;
      for (const auto& p : images) imgs.push_back(read_gray(p));
      const auto r = cv_::calibrate_intrinsics(imgs, spec, dist_count);
      cv_::save_camera(r.camera, out);
      std::printf("crease-calibrate: %d of %zu images used, RMS %.3f px, fx %.1f fy %.1f -> %s\n", r.views_used,
                  imgs.size(), r.rms_px, r.camera.K(0, 0), r.camera.K(1, 1), out.c_str());
    } else if (*extr) {
      if (images.size() != intrinsics.size())
        throw std::invalid_argument(std::to_string(intrinsics.size()) + " calibration files but " +
                                    std::to_string(images.size()) + " images");
      std::filesystem::create_directories(out);
      for (std::size_t k = 0; k < images.size(); ++k) {
        cv_::Camera cam = cv_::load_camera(intrinsics[k]);
        double rms = 0;
        if (!cv_::board_extrinsics(read_gray(images[k]), spec, cam, &rms))
          throw std::runtime_error(images[k] + ": the board is not seen well enough (need 6 corners)");
        const std::string p = out + "/cam" + std::to_string(k) + ".yaml";
        cv_::save_camera(cam, p);
        const cv::Vec3d c = cam.centre_world();
        std::printf("cam%zu: centre (%.1f, %.1f, %.1f) mm, board RMS %.3f px -> %s\n", k, c[0], c[1], c[2], rms,
                    p.c_str());
      }
    } else if (*rig) {
      std::filesystem::create_directories(out);
      for (const auto& c : cv_::default_rig()) cv_::save_camera(c, out + "/" + c.name + ".yaml");
      std::printf("crease-calibrate: wrote 5 cameras to %s\n", out.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crease-calibrate: %s\n", e.what());
    return 1;
  }
  return 0;
}
